"""The structures stage of a run: every weak location judged, every released piece reported."""
from __future__ import annotations

import numpy as np

from structures.capture_window import capture_gap
from structures.indeterminacy import Indeterminacy, mark
from structures.release import ReleaseEvent, released_pieces
from structures.reproducibility import TWIN_OFFSET, twin_label
from structures.thread_gaps import pass_through_check, pass_through_reason
from structures.weak_location import WeakLocation, assess, joint_loads, judged_demands

#: The three answers to "does this capture create secondary debris?" (``debris_state`` in
#: structures.json, the CLI, the report and the sweep store). ``secondary_debris`` carries the
#: same as True / False / None: None is "indeterminate" (a failed or diverged run, or no judged
#: evidence), which no consumer may read as "no debris".
DEBRIS, NO_DEBRIS, INDETERMINATE = "debris", "no_debris", "indeterminate"
DEBRIS_STATES = (DEBRIS, NO_DEBRIS, INDETERMINATE)


#: A verdict needs at least this many judged samples (after ``skip_initial``): a peak read from
#: fewer is not a load history (a run whose end_time was below skip_initial, or an
#: output rate of 1e-300 Hz, judged nothing and said "pass").
MIN_JUDGED_SAMPLES = 10
#: Longest sample interval a verdict accepts (s). Joint loads are sampled, not averaged, so a
#: coarser rate misses peaks: the penalty joints ring at hundreds of Hz and their single-sample
#: peaks move by several per cent even between 1e-4 s steps (docs/model.md, "Step size").
#: 100 Hz is a floor for a verdict, not a recommendation; the shipped cases sample at 1 kHz.
MAX_SAMPLE_INTERVAL_S = 1e-2
#: Largest energy-balance drift (fraction of the launch energy) a run with the threads' own contact on
#: (``contact.thread_segments``) may have and still say a location holds. The thread contact is not yet
#: energy-consistent at fast strikes (docs/model.md, "Contact": 2.4 % on envisat_small's 2 m/s run where node
#: contact alone closes to 0.03 %), and a run can gain energy the health check's 5 % lets through; 1 % is the
#: drift a converged node-contact run stays within (the step study, multibody/health.py). Past it the run's
#: loads carry a numerical error node contact would not have, so "holds" is not shown: indeterminate.
THREAD_CONTACT_DRIFT_LIMIT = 0.01


def evidence_gaps(time, contact_force_debris_lvlh, skip_until: float) -> list[Indeterminacy]:
    """Why the recorded samples cannot support a structural verdict (empty when they can): (rule, reason) pairs,
    rules ``too_few_judged_samples``, ``coarse_sampling``, ``no_capture_load``.

    Parameters
    ----------
    time : (k,) float
        Sample times (s).
    contact_force_debris_lvlh : (k, nd, 3) float
        Net contact force on each debris body (N, LVLH), averaged over each output interval.
    skip_until : float
        Loads before this time are not judged (s).

    Returns
    -------
    list of structures.indeterminacy.Indeterminacy
    """
    time = np.asarray(time, float)
    judged = time >= skip_until
    gaps = []
    if judged.sum() < MIN_JUDGED_SAMPLES:
        end = time[-1] if time.size else 0.0
        gaps.append(Indeterminacy("too_few_judged_samples",
                                  f"{int(judged.sum())} samples after skip_initial = {skip_until:g} s (the run ends at "
                                  f"{end:g} s); a verdict needs at least {MIN_JUDGED_SAMPLES}"))
    if time.size > 1 and np.max(np.diff(time)) > MAX_SAMPLE_INTERVAL_S * (1 + 1e-9):
        gaps.append(Indeterminacy("coarse_sampling",
                                  f"samples up to {np.max(np.diff(time)):.3g} s apart; a verdict needs at least "
                                  f"{1 / MAX_SAMPLE_INTERVAL_S:g} Hz (simulation.output_rate) to see the load peaks"))
    force = np.asarray(contact_force_debris_lvlh, float)
    if judged.any() and not np.any(np.linalg.norm(force[judged], axis=-1) > 0.0):
        gaps.append(Indeterminacy("no_capture_load",
                                  f"no contact between the net and the debris after skip_initial = {skip_until:g} s: "
                                  f"the judged window holds no capture load"))
    return gaps


def thread_contact_energy_gap(energy_drift: float | None) -> Indeterminacy | None:
    """Why a run with the threads' own contact on cannot say "holds" (rule ``thread_contact_energy``): its energy
    balance drifted past :data:`THREAD_CONTACT_DRIFT_LIMIT`, or was not recorded; None when within it.

    Parameters
    ----------
    energy_drift : float or None
        The run's largest energy-balance drift, a fraction of its reference energy (summary.json's
        ``checks.energy_balance_relative_drift``); None or NaN when not known.

    Returns
    -------
    structures.indeterminacy.Indeterminacy or None
    """
    if energy_drift is not None and energy_drift <= THREAD_CONTACT_DRIFT_LIMIT:
        return None
    drift = "not recorded" if energy_drift is None else f"{100 * energy_drift:.3g} %"
    return Indeterminacy("thread_contact_energy",
                         f"the threads' own contact (contact.thread_segments) is on and the energy balance drifted "
                         f"{drift} (a verdict with it needs at most {100 * THREAD_CONTACT_DRIFT_LIMIT:g} %): energy "
                         f"the integration made or lost may be in the loads; where it came from is not told by the "
                         f"drift alone (the threads' strikes, docs/model.md 'Contact', or a closing loop's reel-in, "
                         f"'The closing's energy dip'); a re-run at half simulation.step tells whether the step made it")


def location_state(result: dict, gaps: list[Indeterminacy]) -> tuple[str, list[Indeterminacy]]:
    """('fails' | 'holds' | 'indeterminate', why) of one judged location. An exceedance seen
    is a failure whatever else is missing; a pass needs judged, finite loads and no evidence gap.

    Parameters
    ----------
    result : dict
        The location's verdict (:func:`structures.weak_location.assess`) with ``released_at_s``
        (s, or None) added.
    gaps : list of Indeterminacy
        Evidence gaps of the run (:func:`evidence_gaps`); empty when the samples can support a
        verdict.

    Returns
    -------
    state : {"fails", "holds", "indeterminate"}
    why : list of structures.indeterminacy.Indeterminacy
        Why the state is indeterminate (rule ``non_finite_loads`` for loads that are not finite, or the
        evidence gaps); empty otherwise.
    """
    if result["fails"] or result["released_at_s"] is not None:
        return "fails", []
    if not result["judged"]:
        return "indeterminate", list(gaps) or [Indeterminacy("non_finite_loads", "load samples that are not finite")]
    if gaps:
        return "indeterminate", list(gaps)
    return "holds", []


def structures_verdict(locations: list[WeakLocation], series: dict, assembly, events: list[ReleaseEvent],
                       net_positions_final, skip_until: float, policy: str, pass_throughs=None,
                       judge_pass_throughs: bool = True, thread_contact_drift: float | None = None,
                       thread_segments: bool = False, capture: dict | None = None) -> dict:
    """JSON-ready verdict: per location the criteria, margins, likelihood and any release, and the
    answer ``debris_state`` (:data:`DEBRIS_STATES`) with the reasons when it is indeterminate.

    Parameters
    ----------
    locations : list of WeakLocation
        The weak locations to judge.
    series : dict
        Recorded series (:mod:`multibody.recorder`): ``time`` (k,) s, ``contact_force_lvlh``
        (k, nb, 3) N LVLH, ``joint_force_joint`` (k, nj, 3) N and ``joint_moment_joint``
        (k, nj, 3) N m in each joint frame, and the body states :func:`released_pieces` reads.
    assembly : multibody.assembly.ImpactAssembly
        The simulated assembly (joint names, debris bodies).
    events : list of ReleaseEvent
        The run's releases (empty without release).
    net_positions_final : (n, 3) float
        Net node positions at the end of the run, LVLH (m).
    skip_until : float
        Loads before this time are not judged (s).
    policy : {"low", "nominal", "high", "never"}
        The case's release policy; "never" judges range allowables at their low end.
    pass_throughs : list of multibody.thread_crossing.PassThroughSnapshot, optional
        Threads that passed through the bodies (:func:`multibody.thread_crossing.pass_through_history`):
        a location that holds is indeterminate when their load could have taken it past its allowable
        (:mod:`structures.thread_gaps`); each location's figures go to ``thread_pass_through``.
    judge_pass_throughs : bool, optional
        False: report ``thread_pass_through`` without changing any state (the case's
        ``structures.thread_pass_through = "ignore"``).
    thread_contact_drift : float or None, optional
        The run's largest energy-balance drift (fraction of the reference energy; None: not recorded).
    thread_segments : bool, optional
        The run had the threads' own contact on (``contact.thread_segments``): a location that holds is
        indeterminate when ``thread_contact_drift`` is past :data:`THREAD_CONTACT_DRIFT_LIMIT`
        (:func:`thread_contact_energy_gap`).
    capture : dict, optional
        With ``structures.window = "capture"``: :func:`structures.capture_window.capture_window` of the run. A
        location that has not failed is indeterminate (rule ``capture_not_over``) when the run reached its end time
        before the capture was over; the dict goes to ``capture_window``.

    Returns
    -------
    dict
        ``skip_initial_s``, ``release_policy``, ``locations`` (one verdict each), ``released_pieces``,
        ``debris_state``, ``secondary_debris`` (True / False / None) and ``indeterminate_reasons``; each
        location's ``indeterminate_reason`` comes with its ``indeterminate_rules``
        (:mod:`structures.indeterminacy`).
    """
    time = series["time"]
    released_at = {e.location: e for e in events}
    gaps = evidence_gaps(time, series["contact_force_lvlh"][:, list(assembly.debris_indices)], skip_until)
    energy_gap = thread_contact_energy_gap(thread_contact_drift) if thread_segments else None
    unsettled = capture_gap(capture) if capture is not None else None
    rows = []
    judged_at = policy if policy != "never" else "low"     # without release, range allowables judge low
    for loc in locations:
        result = assess(loc, time, *joint_loads(loc, series), skip_until, judged_at)
        result["joint"] = assembly.joints[loc.joint].name
        event = released_at.get(loc.name)
        result["released_at_s"] = event.time if event else None
        # After a release the location carries nothing, so its peak (and likelihood) only
        # covers the loads up to the release: a lower bound of what the intact joint would see.
        result["likelihood_is_lower_bound"] = event is not None
        state, found = location_state(result, gaps)
        check = (pass_through_check(loc, result, pass_throughs, assembly, series, skip_until)
                 if pass_throughs and result["judged"] else None)
        result["thread_pass_through"] = check
        if judge_pass_throughs and state == "holds" and check and check["could_exceed"]:
            state, found = "indeterminate", [pass_through_reason(check)]
        if energy_gap is not None and state != "fails":
            state, found = "indeterminate", found + [energy_gap]
        if unsettled is not None and state != "fails":       # a hold seen over part of the capture is not a hold
            state, found = "indeterminate", found + [unsettled]
        mark(result, state, found)
        result["peak_window"] = "unchecked"        # deterministic or chaotic once a twin run checks it (apply_twin)
        result["condition"] = condition_sentence(result, judged_at)
        rows.append(result)
    pieces = released_pieces(events, assembly, series, net_positions_final)
    states = [r["state"] for r in rows]
    if pieces or "fails" in states:
        answer = DEBRIS
    elif "indeterminate" in states:
        answer = INDETERMINATE
    else:
        answer = NO_DEBRIS
    out = {"skip_initial_s": skip_until, "release_policy": policy,
           "thread_pass_through": "bound" if judge_pass_throughs else "ignore", "locations": rows, "released_pieces": pieces,
           "debris_state": answer, "secondary_debris": {DEBRIS: True, NO_DEBRIS: False}.get(answer),
           "indeterminate_reasons": sorted({r["indeterminate_reason"] for r in rows if r["indeterminate_reason"]})}
    if capture is not None:
        out["capture_window"] = capture
    return out


def apply_twin(verdict: dict, locations: list[WeakLocation], series: dict, twin_series: dict | None,
               skip_until: float, policy: str, note: str = "") -> dict:
    """Label every judged peak of ``verdict`` deterministic or chaotic against a twin run (the same case, launch
    speed x (1 + :data:`structures.reproducibility.TWIN_OFFSET`)), and never let a chaotic peak read as safe: a
    location that holds on a peak its twin does not reproduce, or that its twin exceeds, is indeterminate (one
    draw of a chaotic capture answers nothing; ``assess --monte-carlo`` gives P(secondary debris)).

    Parameters
    ----------
    verdict : dict
        :func:`structures_verdict` of the run (updated in place and returned).
    locations : list of WeakLocation
        The weak locations it judged.
    series, twin_series : dict
        Recorded series of the run and of its twin (``time``, ``joint_force_joint``, ``joint_moment_joint``);
        ``twin_series`` None when the twin did not run (``note`` says why): holding locations are then
        indeterminate, since their peaks could not be checked.
    skip_until : float
        Loads before this time are not judged (s).
    policy : str
        The release policy the run judged at ("low", "nominal", "high"; "never" judges at "low").
    note : str
        Why the twin did not run (when ``twin_series`` is None).

    Returns
    -------
    dict
        ``verdict`` with ``twin`` (whether it ran, its launch-speed factor, a note), per criterion ``twin``
        (``reproduced``, ``parting_time_s``, ``twin_peak``, ``window``) and per location ``peak_window``.
    """
    verdict["twin"] = {"ran": twin_series is not None, "launch_velocity_factor": 1.0 + TWIN_OFFSET, "note": note}
    judged_at = policy if policy != "never" else "low"
    for loc, row in zip(locations, verdict["locations"]):
        reasons, windows = [], []
        if twin_series is not None:
            mine = judged_demands(loc, series["time"], *joint_loads(loc, series))
            theirs = judged_demands(loc, twin_series["time"], *joint_loads(loc, twin_series))
        for name, criterion in row["criteria"].items():
            if criterion["peak"] is None:
                continue
            if twin_series is None:
                criterion["twin"] = None
                windows.append("unchecked")
                continue
            label = twin_label(series["time"], mine[name], theirs[name], skip_until)
            criterion["twin"] = label
            windows.append(label["window"])
            if label["twin_peak"] >= criterion["decisive_allowable"]:
                reasons.append(Indeterminacy("twin_exceeds", f"its twin run exceeds its {name.replace('_', ' ')} "
                                                             f"allowable"))
            elif not label["reproduced"]:
                reasons.append(Indeterminacy(
                    "chaotic_peak", f"its {name.replace('_', ' ')} peak at {criterion['peak_time_s']:.3g} s is one draw "
                                    f"of a chaotic capture (a twin run {TWIN_OFFSET:g} apart in launch speed parts at "
                                    f"{label['parting_time_s']:.3g} s and peaks "
                                    f"{label['twin_peak'] / criterion['peak'] - 1:+.0%} from it)"))
        row["peak_window"] = ("unchecked" if "unchecked" in windows else "chaotic" if "chaotic" in windows
                              else "deterministic" if windows else None)
        if row["state"] != "holds":
            row["condition"] = condition_sentence(row, judged_at)
            continue
        if twin_series is None:
            reasons.append(Indeterminacy("twin_not_run", f"its peaks could not be checked against a twin run ({note})"))
        if reasons:
            mark(row, "indeterminate", reasons, suffix="; P(secondary debris) needs assess --monte-carlo")
        row["condition"] = condition_sentence(row, judged_at)
    states = [r["state"] for r in verdict["locations"]]
    if verdict["debris_state"] == NO_DEBRIS and "indeterminate" in states:
        verdict["debris_state"], verdict["secondary_debris"] = INDETERMINATE, None
    verdict["indeterminate_reasons"] = sorted({r["indeterminate_reason"] for r in verdict["locations"]
                                               if r["indeterminate_reason"]})
    return verdict


def _display_unit(unit: str) -> tuple[float, str]:
    """(divisor, unit) people read a quantity in: stresses in MPa, loads in their SI unit."""
    return (1e6, "MPa") if unit == "Pa" else (1.0, unit)


def _quantity(value: float, unit: str) -> str:
    """A demand or allowable (SI ``unit``) as people read it."""
    scale, shown = _display_unit(unit)
    return f"{value / scale:.4g} {shown}"


def _span(low: float, high: float, unit: str) -> str:
    """A range allowable (SI ``unit``) as people read it: "200-1000 N m", "950-3500 MPa"."""
    scale, shown = _display_unit(unit)
    return f"{low / scale:.4g}-{high / scale:.4g} {shown}"


def _decisive_criterion(result: dict):
    """(name, criterion) that decides the location: the judged one with the largest likelihood of
    failure, ties broken by the smallest margin; None when nothing was judged."""
    judged = [(n, c) for n, c in result["criteria"].items() if c["peak"] is not None]
    if not judged:
        return None
    return max(judged, key=lambda nc: (nc[1]["likelihood"], -nc[1]["margin_of_safety"]))


def condition_sentence(result: dict, policy: str) -> str:
    """One sentence that states a location's deterministic result and the condition it rests on, so
    that "fails" and a small likelihood cannot be read as a contradiction: the run judges a range
    allowable at the release policy's value, the likelihood is P(allowable < peak) over the range.

    Example: "solar_array_hinge breaks if its hinge moment allowable is below 223 N m (this run's peak,
    at 0.41 s): P >= 3 % for an allowable uniform over 200-1000 N m; this run judges at the low
    end (200 N m): fails." ``>=`` marks a released location (its loads after release are unknown).

    Parameters
    ----------
    result : dict
        One location's verdict (:func:`structures.weak_location.assess` with ``state``,
        ``indeterminate_reason`` and ``released_at_s`` added): criteria with peak (SI), time (s),
        allowable range, likelihood and margin.
    policy : str
        The release policy's end of a range allowable that decided the run: "low", "nominal", "high".

    Returns
    -------
    str
    """
    name = result["name"]
    if result["state"] == "indeterminate":
        return f"{name}: indeterminate ({result['indeterminate_reason']}); no condition can be stated."
    decisive = _decisive_criterion(result)
    if decisive is None:
        return f"{name}: nothing judged; no condition can be stated."
    criterion, c = decisive
    unit, low, high = c["unit"], *c["allowable"]
    peak = _quantity(c["peak"], unit)
    when = f"this run's peak, at {c['peak_time_s']:.3g} s" + (", up to its release" if result["released_at_s"] is not None
                                                       else "")
    if result.get("reading", "").startswith("through"):     # a modal reading says so where the number is read
        when += f", read {result['reading']}"
    if (c.get("twin") or {}).get("reproduced"):
        when += f", reproduced by a twin run {TWIN_OFFSET:g} apart in launch speed"
    verb = "fails" if result["state"] == "fails" else "holds"
    # a hold resting on one run's peak: say that a late peak may be one draw of a chaotic capture
    caveat = (" Unchecked for chaos: a late peak of one run is one draw (structures.twin checks it; assess "
              "--monte-carlo gives P)." if verb == "holds" and result.get("peak_window") == "unchecked" else "")
    if high > low:
        bound = ">=" if result["released_at_s"] is not None else "="
        return (f"{name} breaks if its {criterion.replace('_', ' ')} allowable is below {peak} ({when}): "
                f"P {bound} {c['likelihood']:.0%} for an allowable uniform over {_span(low, high, unit)}; "
                f"this run judges at the {policy} end "
                f"({_quantity(c['decisive_allowable'], unit)}): {verb}.{caveat}")
    return (f"{name} {verb}: its {criterion.replace('_', ' ')} reached {peak} ({when}) against an allowable of "
            f"{_quantity(low, unit)} (margin {c['margin_of_safety']:+.2f}).{caveat}")


def demand_series(locations: list[WeakLocation], series: dict) -> dict:
    """Per location and demand, the judged time series (SI; through the location's structural modes when it
    has them, :func:`structures.weak_location.judged_demands`), keyed ``<location>/<demand>``, for the run folder.

    Parameters
    ----------
    locations : list of WeakLocation
        The weak locations.
    series : dict
        Recorded series: ``time`` (k,) s, ``joint_force_joint`` (k, nj, 3) N and
        ``joint_moment_joint`` (k, nj, 3) N m, joint frame.

    Returns
    -------
    dict of (k,) float
        ``time`` (s) and every demand of every location (Pa, N m or N).
    """
    out = {"time": series["time"]}
    for loc in locations:
        for name, values in judged_demands(loc, series["time"], *joint_loads(loc, series)).items():
            out[f"{loc.name}/{name}"] = np.asarray(values)
    return out
