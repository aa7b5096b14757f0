"""Report sections of the structures stage: the verdict, loads against allowables, stresses
against strengths (from structures.json and structures.npz of the run folder)."""
from __future__ import annotations

import numpy as np

from riskassess.products.report.blocks import Figure, Note, Section, Table
from riskassess.products.plotting import allowable_band, legend, mark_release, panels, plain, shade_not_judged
from riskassess.products.results import RunFolder
from riskassess.products.tables import STATE_TEXT, VERDICT_COLUMNS, format_margin, format_vector, verdict_rows

NOT_ASSESSED = ("Not assessed: the case declares no weak locations. Add [[structures.weak_locations]] to the case "
                "(docs/case-format.md) and run it again to get failure verdicts and released pieces.")


def _not_assessed(run: RunFolder) -> bool:
    """The case declares no weak locations, so the run has no structures results to miss."""
    return not run.has("structures.json") and run.case.get("structures") is None


def verdict_section(run: RunFolder) -> Section:
    """The verdict: secondary debris yes / no / indeterminate, the released pieces and one row per
    weak location and criterion.

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``structures.json``; ``case.json`` to tell a case without weak
        locations).

    Returns
    -------
    Section
    """
    if _not_assessed(run):
        return Section("verdict", "Verdict: secondary debris", [Note(NOT_ASSESSED, "warning")])
    verdict = run.structures  # MissingData names the file when a case with weak locations lacks it
    pieces = verdict["released_pieces"]
    failing = [loc["name"] for loc in verdict["locations"] if loc["fails"]]
    state = verdict.get("debris_state") or ("debris" if verdict["secondary_debris"] else "no_debris")
    if state == "debris":
        headline = Note(f"SECONDARY DEBRIS: {len(pieces)} piece(s) released"
                        + (f"; failing locations: {', '.join(failing)}" if failing else ""), "alarm")
    elif state == "indeterminate":
        headline = Note("INDETERMINATE: the run gives no evidence for a verdict, so it cannot say that the capture "
                        "is safe. " + "; ".join(verdict.get("indeterminate_reasons") or []), "alarm")
    else:
        headline = Note("No secondary debris: every weak location holds with its decisive allowable.", "info")
    blocks = [headline]
    if pieces:
        blocks.append(Table(
            ["piece (bodies)", "released at (s)", "by", "mass (kg)", "size (m)", "at end", "velocity rel. chaser "
             "(m/s, LVLH)", "spin (rad/s)"],
            [["+".join(p["bodies"]), f"{p['release_time_s']:.3f}", f"{p['location']} ({p['criterion']})",
              f"{p['mass_kg']:.4g}", " x ".join(f"{e:.3g}" for e in p["size_m"]),
              "inside the net" if p["inside_net_at_end"] else "OUTSIDE the net",
              format_vector(p["velocity_relative_to_chaser_lvlh_m_s"]), f"{p['spin_rate_rad_s']:.3g}"]
             for p in pieces], "Released pieces (size: oriented bounding box of the piece's shapes)"))
    rows = verdict_rows(verdict)
    columns = [c for c in VERDICT_COLUMNS if c != "released piece"]
    blocks.append(Table(columns, [[STATE_TEXT[r["state"]] if c == "fails?" else r[c] for c in columns]
                                  for r in rows],
                        f"Weak locations: peak demand after {verdict['skip_initial_s']:g} s against the allowable; "
                        f"range allowables decide at their '{verdict['release_policy']}' value. Margin of safety = "
                        f"allowable / demand - 1.",
                        alarm_rows={k for k, r in enumerate(rows) if r["state"] != "holds"}, css_class="verdict"))
    conditions = [loc["condition"] for loc in verdict["locations"] if loc.get("condition")]
    if conditions:
        blocks.append(Note("What each verdict rests on: " + " ".join(conditions)))
    passed = [pass_through_text(loc) for loc in verdict["locations"] if loc.get("thread_pass_through")]
    if passed:
        blocks.append(Note("Net threads through the structure (contact acts on the net's nodes only, so a thread "
                           "whose nodes lie either side of a thin part passes through it without a force; bound: "
                           "twice each such thread's tension at its crossing, at the 'net_output_rate' snapshots): "
                           + " ".join(passed), "warning"))
    if verdict.get("capture_window"):
        blocks.append(Note(capture_window_text(verdict["capture_window"]),
                           "info" if verdict["capture_window"]["settled"] else "warning"))
    elif verdict.get("judged_window"):
        blocks.append(Note(fixed_window_text(verdict["judged_window"]), "warning"))
    blocks.append(Note("Likelihood: probability of failure with the allowable uniformly distributed over its "
                       "range. For a released location it is a lower bound ('>='), because the joint carries "
                       "nothing after its release."))
    return Section("verdict", "Verdict: secondary debris", blocks)


def fixed_window_text(window: dict) -> str:
    """One sentence on the judged window of a run with ``structures.window = "fixed"``: what its answer is
    conditional on (``window`` is the verdict's ``judged_window``)."""
    return (f"Judged window: fixed, 0 to {window['end_time_s']:.2f} s (structures.window = 'fixed'): the case states "
            f"that nothing after its end time loads the target (for example the net closed or in tow by then). "
            f"Loads after it are not judged and the capture was not checked to be over; with the default window "
            f"('capture') a location that held would need the capture over to say so.")


def capture_window_text(window: dict) -> str:
    """One sentence on the judged window of a run with ``structures.window = "capture"``: when the capture was over
    (or that it was not by the end time), the net's relative energy and the keys.

    Parameters
    ----------
    window : dict
        The verdict's ``capture_window`` (:func:`structures.capture_window.capture_window`).

    Returns
    -------
    str
    """
    keys = (f"(the net's kinetic energy relative to {window['reference_body']}, its rigid motion removed, below "
            f"{window['energy_threshold_J']:g} J and no judged running peak rising, both for {window['hold_s']:g} s)")
    energy = "unknown" if window["net_energy_relative_end_J"] is None else f"{window['net_energy_relative_end_J']:.3g} J"
    if window["settled"]:
        return (f"Judged window: the whole capture, over at t_s = {window['settled_at_s']:.2f} s {keys}; the run "
                f"{'stopped' if window.get('stopped_early') else 'ended'} at {window['end_time_s']:.2f} s with "
                f"{energy} relative energy.")
    return (f"Judged window: the capture was NOT over when the run reached its end time {window['end_time_s']:.2f} s "
            f"{keys}: relative energy {energy}, the last rise of a judged peak at "
            f"{window['last_rise_s'] if window['last_rise_s'] is not None else float('nan'):.2f} s; no location that "
            f"held can say so (indeterminate).")


def pass_through_text(loc: dict) -> str:
    """One sentence on the threads that passed through what a location carries, and what their load could do.

    Parameters
    ----------
    loc : dict
        The location's verdict entry, with ``thread_pass_through`` (:func:`structures.thread_gaps.pass_through_check`).

    Returns
    -------
    str
    """
    check = loc["thread_pass_through"]
    effect = (f"could take {', '.join(check['could_exceed'])} past the allowable" if check["could_exceed"] else
              "is absorbed by its margin")
    if check["could_exceed"] and loc["state"] == "holds":
        effect += " (not judged: structures.thread_pass_through = \"ignore\")"
    return (f"{loc['name']}: up to {check['most_threads']} threads through {', '.join(check['bodies'])} from "
            f"{check['first_s']:.2f} to {check['last_s']:.2f} s, their load at most {check['force_bound_N']:.3g} N and "
            f"{check['moment_bound_Nm']:.3g} N m about the joint, {effect} (demand plus bound up to "
            f"{check['worst_ratio']:.2f} of the allowable).")


def _mpa(value) -> str:
    """A stress (Pa) in MPa; '-' when the run judged none (indeterminate location)."""
    return "-" if value is None else f"{value / 1e6:.4g}"


def _margin(value) -> str:
    return "-" if value is None else format_margin(value)


def _locations_with(verdict: dict, criteria: set) -> list[dict]:
    return [loc for loc in verdict["locations"] if criteria & set(loc["criteria"])]


def while_joined(t, demand, loc: dict) -> np.ndarray:
    """The demand (any unit) with NaN after the location's release: a released load path carries
    nothing, and a plotted 0 would read as a measured zero load.

    Parameters
    ----------
    t : (k,) float
        Sample times (s).
    demand : (k,) float
        The demand at those times.
    loc : dict
        The location's verdict entry (``released_at_s``, s or None).

    Returns
    -------
    (k,) float
        A copy of ``demand``, NaN after the release.
    """
    demand = np.asarray(demand, float).copy()
    if loc["released_at_s"] is not None:
        demand[np.asarray(t) > loc["released_at_s"]] = np.nan   # the sample that broke it stays
    return demand


def _decorate(ax, verdict: dict, loc: dict, time_end: float) -> None:
    shade_not_judged(ax, verdict["skip_initial_s"])
    if loc["released_at_s"] is not None:
        mark_release(ax, loc["released_at_s"])
    ax.set_xlim(0.0, time_end)


def joint_loads_section(run: RunFolder) -> Section:
    """Moment and force demands of every weak location that has a moment or force allowable.

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``structures.json``, ``structures.npz``: ``time`` (k,) s and
        ``<location>/moment`` (N m), ``<location>/force`` (N)).

    Returns
    -------
    Section
    """
    title = "Hinge and joint loads against allowables"
    if _not_assessed(run):
        return Section("joint-loads", title, [Note(NOT_ASSESSED, "warning")])
    verdict, series = run.structures, run.structures_series
    t = series["time"]
    units = {"moment": "N m", "force": "N"}
    judged = [(loc, name) for loc in verdict["locations"] for name in units if name in loc["criteria"]]
    if not judged:
        return Section("joint-loads", title, [Note("No weak location has a moment or force allowable.")])
    fig, axes = panels(len(judged), 1.9)
    for ax, (loc, name) in zip(axes, judged):
        c = loc["criteria"][name]
        ax.plot(t, while_joined(t, run.key(series, f"{loc['name']}/{name}"), loc), color="k",
                label=f"{name} demand")
        allowable_band(ax, *c["allowable"], c["decisive_allowable"], 1.0, units[name])
        _decorate(ax, verdict, loc, t[-1])
        ax.set_ylabel(f"{name} ({units[name]})")
        ax.set_title(plain(f"{loc['name']} (joint {loc['joint']})"))
        legend(ax)
    return Section("joint-loads", title, [Figure.from_matplotlib(
        "fig-joint-loads", "Demand of each location with a moment or force allowable (the resultant of the "
        "judged joint-frame components) against its allowable range; grey: initial transient not judged; the curve "
        "ends where the location is released (red dotted).", fig)])


def stresses_section(run: RunFolder) -> Section:
    """Peak normal and shear stress (MPa in the figure) at each section against the material's
    strengths, and the peak stresses with their margins.

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``structures.json``, ``structures.npz``: ``time`` (k,) s and
        ``<location>/normal_stress``, ``<location>/shear_stress`` (Pa)).

    Returns
    -------
    Section
    """
    title = "Stresses against strengths"
    if _not_assessed(run):
        return Section("stresses", title, [Note(NOT_ASSESSED, "warning")])
    verdict, series = run.structures, run.structures_series
    t = series["time"]
    locations = _locations_with(verdict, {"normal_stress", "shear_stress"})
    if not locations:
        return Section("stresses", title, [Note("No weak location has a cross-section and material.")])
    fig, axes = panels(len(locations), 1.9)
    colors = {"normal_stress": "tab:blue", "shear_stress": "tab:purple"}
    rows = []
    for ax, loc in zip(axes, locations):
        floor = np.inf
        for name, color in colors.items():
            c = loc["criteria"][name]
            demand = while_joined(t, run.key(series, f"{loc['name']}/{name}"), loc) / 1e6
            ax.plot(t, np.maximum(demand, 1e-9), color=color, label=f"{name.replace('_', ' ')}")
            ax.axhspan(c["allowable"][0] / 1e6, c["allowable"][1] / 1e6, color=color, alpha=0.12, lw=0)
            ax.axhline(c["decisive_allowable"] / 1e6, color=color, ls="--", lw=1.0,
                       label=f"{c['mode']} strength {c['decisive_allowable'] / 1e6:.4g} MPa")
            floor = min(floor, c["allowable"][0] / 1e6 * 1e-4)
        ax.set_yscale("log")
        ax.set_ylim(bottom=floor)
        _decorate(ax, verdict, loc, t[-1])
        ax.set_ylabel("stress (MPa)")
        ax.set_title(plain(f"{loc['name']} (joint {loc['joint']})"))
        legend(ax)
        normal, shear = loc["criteria"]["normal_stress"], loc["criteria"]["shear_stress"]
        rows.append([loc["name"], _mpa(normal["peak"]), _mpa(shear["peak"]), _mpa(loc.get("peak_von_mises_stress_Pa")),
                     f"{_margin(normal['margin_of_safety'])} / {_margin(shear['margin_of_safety'])}"])
    return Section("stresses", title, [
        Figure.from_matplotlib("fig-stresses", "Peak normal (axial + bending) and shear (torsion + transverse) "
                               "stress at each section, log axis, against the material's ultimate strength "
                               "(shaded: the given range; dashed: the decisive value).", fig),
        Table(["location", "peak normal (MPa)", "peak shear (MPa)", "peak von Mises (MPa)",
               "margin normal / shear"], rows, "Peak stresses after the initial transient"),
    ])
