"""A weak location (a joint, or a cut near it) and its checks against the co-simulated loads.

Loads come from the joint reactions the run records (``joint_force_joint``,
``joint_moment_joint``: the load the parent exerts on the child at the joint point, joint
frame h1, h2, h3). A cut at ``offset`` from the joint point, on the child side, carries the
same force and the moment transported to it, M_cut = M_joint - r x F: the inertia and the
contact load of the short segment between joint and cut are neglected (keep cuts close to
the joint, or put a joint at the cut).

Each location has one or more criteria, each a demand time series against an
:class:`~structures.criteria.Allowable`, and a failure mode:

* ``normal_stress`` (Pa, mode "normal"): axial + bending, Euler-Bernoulli, at the section;
* ``shear_stress`` (Pa, mode "shear"): torsion + transverse shear at the section;
* ``moment`` (N m, mode "normal"): resultant of the joint-frame moment components in
  ``moment_axes`` (the seed paper judges the hinge-panel interface by M_h1 and M_h3
  against 200-1000 N m, Sec. 3.3.3);
* ``force`` (N, mode "shear"): resultant joint force.

With the structure's first mode given (``structural_modes_hz``, a value or a range), the judged loads are
the recorded (stiff-joint) reaction passed through that mode (:mod:`structures.modal_load`); a range is
judged by the envelope over its modes, so the verdict holds for any first mode in it.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from structures.criteria import Allowable, combined_likelihood, first_exceedance_time
from structures.modal_load import OnlineModalLoad, modal_loads
from structures.sections import SectionProperties, section_stresses

CRITERION_MODE = {"normal_stress": "normal", "shear_stress": "shear", "moment": "normal", "force": "shear"}
CRITERION_UNIT = {"normal_stress": "Pa", "shear_stress": "Pa", "moment": "N m", "force": "N"}


@dataclass(frozen=True)
class WeakLocation:
    """One weak location, with everything in the joint frame (SI)."""

    name: str
    joint: int                            # index of the joint whose reaction loads it
    section_to_joint: np.ndarray          # (3, 3): columns are section axes 1 (beam), 2, 3 in the joint frame
    offset_joint: np.ndarray              # (3,) cut point minus joint point, joint frame (m)
    section: SectionProperties | None = None
    ultimate_normal: Allowable | None = None
    ultimate_shear: Allowable | None = None
    allowable_moment: Allowable | None = None
    allowable_force: Allowable | None = None
    moment_axes: tuple = (0, 1, 2)       # joint-frame components judged by allowable_moment
    structural_modes_hz: tuple = ()      # modes (Hz) the loads are read through; empty: as recorded
    structural_damping_ratio: float = 0.02   # their damping, fraction of critical (-)
    load_filter_hz: float = 0.0          # cut-off (Hz) of the joint's load filter (multibody.load_filter); 0: none
    load_filter_order: int = 4           # its order (2 or 4)

    def criteria(self) -> dict:
        """Criterion name -> allowable, for the criteria this location has."""
        out = {"normal_stress": self.ultimate_normal if self.section is not None else None,
               "shear_stress": self.ultimate_shear if self.section is not None else None,
               "moment": self.allowable_moment, "force": self.allowable_force}
        return {k: v for k, v in out.items() if v is not None}


def internal_loads_section_frame(location: WeakLocation, force_joint, moment_joint):
    """Internal force (N, V2, V3) and moment (T, M2, M3) at the cut, section frame; (k, 3) each.

    Parameters
    ----------
    location : WeakLocation
        Gives the cut offset (m, joint frame) and the section axes in the joint frame.
    force_joint : (k, 3) or (3,) float
        Joint reaction force (N), joint frame.
    moment_joint : (k, 3) or (3,) float
        Joint reaction moment at the joint point (N m), joint frame.

    Returns
    -------
    force_section : (k, 3) float
        (N, V2, V3) (N), section frame.
    moment_section : (k, 3) float
        (T, M2, M3) at the cut, M_cut = M_joint - r x F (N m), section frame.
    """
    f = np.atleast_2d(np.asarray(force_joint, float))
    m = np.atleast_2d(np.asarray(moment_joint, float)) - np.cross(location.offset_joint, f)
    rot = location.section_to_joint
    return f @ rot, m @ rot


def demands(location: WeakLocation, force_joint, moment_joint) -> dict:
    """Demand time series per criterion ((k,) arrays, SI), plus the section's stress breakdown.

    Parameters
    ----------
    location : WeakLocation
        The location (section, moment axes).
    force_joint : (k, 3) float
        Joint reaction force (N), joint frame.
    moment_joint : (k, 3) float
        Joint reaction moment (N m), joint frame.

    Returns
    -------
    dict of (k,) float
        ``moment`` (N m) and ``force`` (N); with a section also ``normal_stress``,
        ``shear_stress``, ``von_mises_stress``, ``bending_stress``, ``axial_stress``,
        ``torsion_stress`` and ``transverse_shear_stress`` (Pa).
    """
    out = {}
    f = np.atleast_2d(np.asarray(force_joint, float))
    m = np.atleast_2d(np.asarray(moment_joint, float))
    if location.section is not None:
        f_sec, m_sec = internal_loads_section_frame(location, f, m)
        stresses = section_stresses(location.section, f_sec, m_sec)
        out.update({"normal_stress": stresses["normal"], "shear_stress": stresses["shear"],
                    "von_mises_stress": stresses["von_mises"], "bending_stress": stresses["bending"],
                    "axial_stress": stresses["axial"], "torsion_stress": stresses["torsion"],
                    "transverse_shear_stress": stresses["transverse_shear"]})
    out["moment"] = np.linalg.norm(m[:, list(location.moment_axes)], axis=1)
    out["force"] = np.linalg.norm(f, axis=1)
    return out


def joint_loads(location: WeakLocation, series: dict) -> tuple:
    """The joint loads the location is judged on: its joint's filtered loads (``joint_force_filtered_joint``,
    ``joint_moment_filtered_joint``, :mod:`multibody.load_filter`) when it has ``load_filter_hz``, else the raw
    reaction (``joint_force_joint``, ``joint_moment_joint``).

    Parameters
    ----------
    location : WeakLocation
    series : dict
        Recorded series (:mod:`multibody.recorder`).

    Returns
    -------
    force_joint, moment_joint : (k, 3) float
        (N, N m), joint frame.
    """
    if location.load_filter_hz:
        if "joint_force_filtered_joint" not in series:
            raise KeyError(f"weak location '{location.name}' is judged on its joint's loads through a "
                           f"{location.load_filter_hz:g} Hz filter, but the run recorded no filtered loads")
        return (series["joint_force_filtered_joint"][:, location.joint],
                series["joint_moment_filtered_joint"][:, location.joint])
    return series["joint_force_joint"][:, location.joint], series["joint_moment_joint"][:, location.joint]


def judged_demands(location: WeakLocation, time, force_joint, moment_joint) -> dict:
    """The demands the location is judged by: :func:`demands` of the recorded loads or, with
    ``structural_modes_hz``, the envelope (largest value at each sample) over those modes of the demands of
    the loads each mode carries (:func:`structures.modal_load.modal_loads`).

    Parameters
    ----------
    location : WeakLocation
        The location.
    time : (k,) float
        Sample times (s), uniformly spaced when the location has modes.
    force_joint : (k, 3) float
        Recorded joint reaction force (N), joint frame.
    moment_joint : (k, 3) float
        Recorded joint reaction moment (N m), joint frame.

    Returns
    -------
    dict of (k,) float
        As :func:`demands`.
    """
    if not location.structural_modes_hz:
        return demands(location, force_joint, moment_joint)
    modes, zeta = location.structural_modes_hz, location.structural_damping_ratio
    force = modal_loads(time, force_joint, modes, zeta)
    moment = modal_loads(time, moment_joint, modes, zeta)
    n, k = force.shape[:2]
    stacked = demands(location, force.reshape(n * k, 3), moment.reshape(n * k, 3))
    return {name: values.reshape(n, k).max(axis=0) for name, values in stacked.items()}


def assess(location: WeakLocation, time, force_joint, moment_joint, skip_until=0.0, policy="low") -> dict:
    """Verdict of one location over a load history.

    Loads before ``skip_until`` (s) are not judged (the seed paper omits about 0.25 s of
    initial impact loads that have no time to propagate). ``policy`` picks the value of a
    range allowable that decides pass/fail and the margin ("low", "nominal", "high");
    the likelihood always uses the whole range.

    Parameters
    ----------
    location : WeakLocation
        The location to judge.
    time : (k,) float
        Sample times (s).
    force_joint : (k, 3) float
        Joint reaction force (N), joint frame.
    moment_joint : (k, 3) float
        Joint reaction moment (N m), joint frame.
    skip_until : float
        Start of the judged window (s).
    policy : {"low", "nominal", "high"}
        Value of a range allowable that decides.

    Returns
    -------
    dict
        ``name``, ``reading`` (:func:`reading`), ``criteria`` (per criterion: peak, its time (s), allowable,
        margin, likelihood, first exceedance (s), ...; read through structural modes also ``recorded_peak`` and
        ``recorded_peak_time_s``, the stiff joint's own), ``fails``, ``fails_normal``, ``fails_shear``, ``judged``,
        ``likelihood`` (None when not judged), ``first_exceedance_s`` and, with a section,
        ``peak_von_mises_stress_Pa``.
    """
    time = np.asarray(time, float)
    series = judged_demands(location, time, force_joint, moment_joint)
    judged = time >= skip_until
    result = {"name": location.name, "criteria": {}}
    recorded = demands(location, force_joint, moment_joint) if location.structural_modes_hz else series
    for name, allowable in location.criteria().items():
        result["criteria"][name] = _criterion_verdict(name, allowable, time, series[name], judged, skip_until, policy)
        # beside a modal reading, the stiff joint's own peak, so a reader sees what the mode took out
        values = recorded[name][judged]
        if location.structural_modes_hz and values.size and np.isfinite(values).all():
            k = int(np.flatnonzero(judged)[np.argmax(values)])
            result["criteria"][name].update(recorded_peak=float(recorded[name][k]), recorded_peak_time_s=float(time[k]))
    result["reading"] = reading(location)
    crit = result["criteria"].values()
    result["fails_normal"] = any(c["fails"] for c in crit if c["mode"] == "normal")
    result["fails_shear"] = any(c["fails"] for c in crit if c["mode"] == "shear")
    result["fails"] = result["fails_normal"] or result["fails_shear"]
    # no judged sample, or a demand that is not a number: nothing to stand on (never a "pass")
    result["judged"] = all(c["peak"] is not None for c in crit)
    result["likelihood"] = combined_likelihood([c["likelihood"] for c in crit]) if result["judged"] else None
    times = [c["first_exceedance_s"] for c in crit if c["first_exceedance_s"] is not None]
    result["first_exceedance_s"] = min(times) if times else None
    if "von_mises_stress" in series:
        vm = series["von_mises_stress"][judged]
        result["peak_von_mises_stress_Pa"] = float(vm.max()) if vm.size and np.isfinite(vm).all() else None
    return result


def reading(location: WeakLocation) -> str:
    """How the location's loads are read, in words (``reading`` in structures.json)."""
    modes = location.structural_modes_hz
    order = {2: "2nd", 4: "4th"}.get(location.load_filter_order, f"order-{location.load_filter_order}")
    filtered = (f"through a {order}-order Butterworth low-pass at {location.load_filter_hz:g} Hz run every step on "
                f"the joint's load (the penalty joint's own modes removed)") if location.load_filter_hz else ""
    if not modes:
        return filtered or "as recorded (the stiff joint's reaction)"
    span = f"{modes[0]:.3g} Hz" if len(modes) == 1 else f"every first mode in {modes[0]:.3g}-{modes[-1]:.3g} Hz (envelope)"
    return ((filtered + ", then " if filtered else "")
            + f"through the structure's first mode: {span}, damping {location.structural_damping_ratio:.3g} of critical")


def _criterion_verdict(name, allowable, time, demand, judged, skip_until, policy) -> dict:
    """One criterion over the judged samples; peak, margin and likelihood None without judged,
    finite demands (the location's verdict is then indeterminate, never a pass)."""
    values = demand[judged]
    threshold = allowable.threshold(policy)
    out = {"mode": CRITERION_MODE[name], "unit": CRITERION_UNIT[name], "allowable": [allowable.low, allowable.high],
           "decisive_allowable": threshold,
           "first_exceedance_s": first_exceedance_time(time, demand, threshold, skip_until)}
    if not values.size or not np.isfinite(values).all():
        return {**out, "peak": None, "peak_time_s": None, "margin_of_safety": None, "fails": False,
                "likelihood": None}
    k = int(np.flatnonzero(judged)[np.argmax(values)])
    peak = float(demand[k])
    return {**out, "peak": peak, "peak_time_s": float(time[k]),
            "margin_of_safety": allowable.margin_of_safety(peak, policy), "fails": bool(peak >= threshold),
            "likelihood": allowable.likelihood_of_failure(peak), **history_around_peak(time, demand, k)}


#: Half-width of the demand history kept around a reported peak (s): a few periods of the
#: slowest joint modes that ring after a strike (tens of Hz), so a reader sees whether the peak is
#: a single-sample spike or a sustained load.
PEAK_HISTORY_HALF_WIDTH_S = 0.025
#: Most samples kept in that window (denser output is thinned, the peak sample always kept).
PEAK_HISTORY_SAMPLES = 101


def history_around_peak(time, demand, k: int) -> dict:
    """The demand around its peak sample ``k``: ``peak_history`` {"time_s", "demand"} over
    +-:data:`PEAK_HISTORY_HALF_WIDTH_S`, and ``peak_width_s``, how long the demand stays at or above
    half the peak around it (a spike of one sample gives one sample interval).

    Parameters
    ----------
    time : (k,) float
        Sample times (s).
    demand : (k,) float
        Demand series, in the criterion's SI unit (Pa, N m or N).
    k : int
        Index of the peak sample.

    Returns
    -------
    dict
        ``peak_width_s`` (s) and ``peak_history`` with ``time_s`` (s) and ``demand`` (SI) lists.
    """
    window = np.flatnonzero(np.abs(time - time[k]) <= PEAK_HISTORY_HALF_WIDTH_S)
    thin = max(1, -(-window.size // PEAK_HISTORY_SAMPLES))
    kept = np.union1d(window[(window - k) % thin == 0], [k])
    above = np.abs(demand) >= 0.5 * abs(demand[k])
    start = k - int(np.argmin(above[k::-1])) if not above[:k + 1].all() else 0
    stop = k + int(np.argmin(above[k:])) if not above[k:].all() else len(time)
    interval = float(np.median(np.diff(time))) if len(time) > 1 else 0.0
    return {"peak_width_s": float(max(stop - start - 1, 1) * interval),
            "peak_history": {"time_s": time[kept].tolist(), "demand": np.asarray(demand)[kept].tolist()}}


def exceeds_now(location: WeakLocation, force_joint, moment_joint, policy="low"):
    """The first criterion (name, demand) whose demand reaches its decisive allowable for one
    sample of joint loads ((3,) each, or (n, 3): the loads of n modes, judged by their largest
    demand), or None: what a run checks to release a joint.

    Parameters
    ----------
    location : WeakLocation
        The location to check.
    force_joint : (3,) or (n, 3) float
        Joint reaction force at this sample (N), joint frame.
    moment_joint : (3,) or (n, 3) float
        Joint reaction moment at this sample (N m), joint frame.
    policy : {"low", "nominal", "high"}
        Value of a range allowable that decides.

    Returns
    -------
    tuple of (str, float) or None
        Criterion name and its demand (Pa, N m or N).
    """
    series = demands(location, np.reshape(force_joint, (-1, 3)), np.reshape(moment_joint, (-1, 3)))
    for name, allowable in location.criteria().items():
        demand = float(np.max(series[name]))
        if demand >= allowable.threshold(policy):
            return name, demand
    return None


def online_modal_loads(location: WeakLocation, interval_s: float) -> OnlineModalLoad | None:
    """The per-sample modal filter a run feeds with this location's joint loads ([force, moment] as one
    (2, 3) sample), or None when the location judges the loads as recorded.

    Parameters
    ----------
    location : WeakLocation
        The location.
    interval_s : float
        The run's output interval (s).

    Returns
    -------
    OnlineModalLoad or None
    """
    if not location.structural_modes_hz:
        return None
    return OnlineModalLoad(location.structural_modes_hz, location.structural_damping_ratio, interval_s)
