"""Are the judged load peaks physics or numerics? Each weak location's peak demands against the
joint penalty stiffness and damping, the step and the output rate, over replicas, read as recorded
and through the structure's first mode.

    python3 bench/bench_peak_convergence.py [CASE] [--end-time T] [--replicas R] [--first-mode HZ]
                                            [--mode HZ | --mode LOW,HIGH ...] [--skip S] [--cache DIR]
                                            [--workers N] [--markdown]
                                            [--store STORE --sample N [--velocity V]] [--peak-times LOCATION]
                                            [--quantile Q ...] [--variants V1,V2,...]
                                            [--load-filter HZ] [--joint-filter JOINT:HZ ...]

Runs the case (default ``cases/envisat_small.toml``) with joint release off (every peak is then the
demand the intact joint carries, not cut at a release) at a baseline and one change at a time:

- step halved (the automatic penalty stiffness follows the step: its modes sit at 0.5 / step rad/s,
  so this is also 4x stiffer joints where the stiffness is not capped; with ``--first-mode`` the joints
  keep the structure's mode), or quartered (``step/4``, only when named in ``--variants``);
- penalty stiffness / 4 at the same step (``multibody.hinge.PENALTY_STEP_FACTOR`` halved and both
  stiffness caps / 4, in the worker only: every automatic joint axis rings at half its frequency), or,
  with ``--first-mode``, the structure's first mode / 2;
- penalty damping 0.1 of critical instead of 0.05 (every joint's ``penalty_damping_ratio``; 0.2 makes
  the explicit run diverge with the automatic penalty);
- output rate doubled (the peak between samples).

Each configuration runs ``R`` replicas whose launch velocity differs by k x 1e-7 (k = 0..R-1), far
below any physical uncertainty: the net's contacts make the capture sensitive to its initial state,
so a single run's peak is one sample of a spread. The raw joint reactions of every run are kept in
``--cache`` (default: a folder under the system's temporary directory named for the case), so
readings can be compared without running again.

``--store STORE --sample N`` runs Monte Carlo sample ``N`` of a store written by ``bench/bench_safe_velocity.py``
(its uncertain inputs and launch velocity, or ``--velocity``; the replicas' offsets on that velocity) instead of
the case's nominal inputs: a run of a safe-velocity row, variant by variant. ``--peak-times LOCATION`` prints,
per reading, variant and replica, that location's judged peak (after the skip), its time and its utilization
against the allowable's low end.

``--against CACHE`` adds the baseline runs of another cache (the same case with one physical input
changed, e.g. ``--member-damping 0.05``) as one more column.

Readings: "as recorded" (the stiff joint's reaction, as the verdict judges a location without
``structural_mode_hz``) and, for each ``--mode``, the reaction read through the structure's first mode
(:mod:`structures.modal_load`, damping ``--mode-damping``; a range LOW,HIGH is judged by the envelope
over it, as a location with ``structural_mode_hz = [LOW, HIGH]``). Windows: the first ``--skip`` s
(default: the case's ``skip_initial``) and the rest, and the whole run. Prints, per reading, window,
location and criterion, the baseline's median peak over the replicas, its spread (max - min) / median,
and each variant's change of the median with a 90 % bootstrap interval (replicas resampled): "ok" when
the change and its interval are within +-5 %, "NOT CONVERGED" when the interval lies beyond, "unresolved"
when the interval straddles 5 % (more replicas needed). ``--quantile 0.9`` compares the 0.9 quantile of the
peak over the replicas the same way (for a chaotic capture the distribution of the peak is what can converge,
and a verdict's probability rests on its upper tail, not on one run). Prints the CPU time per run and the load.
``--variants`` runs only some configurations, replica by replica over them (a study stopped early stays
balanced), and reports the others missing.

``--load-filter HZ`` (``structures.load_filter_hz``) and ``--joint-filter JOINT:HZ`` (a joint's ``load_filter_hz``)
run the joints' load filter (:mod:`multibody.load_filter`: a 2nd-order Butterworth on every step's load, before the
output's decimation) and add the reading "through the step filter": the filtered loads the verdict then judges
(a joint without a cut-off reads raw there). The raw loads of the same runs stay the "as recorded" reading.
"""
from __future__ import annotations

import argparse
import hashlib
import json
import os
import re
import sys
import tempfile
import time
import tomllib
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import replace
from pathlib import Path

import numpy as np

import multibody.hinge as hinge
from multibody.health import SimulationFailed
from riskassess.cases.impact import validate_case
from riskassess.models.impact import model_inputs, weak_locations
from riskassess.stages.run import run_case
from structures.modal_load import mode_grid
from structures.reproducibility import REPRODUCIBLE_TOLERANCE, TWIN_OFFSET, parting_time
from riskassess.sweep.spec import case_with
from structures.weak_location import judged_demands

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script, also when imported
from bench_safe_velocity_history import sample_overrides  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
TOLERANCE = REPRODUCIBLE_TOLERANCE
#: Relative launch-velocity offset between replicas: far below any physical uncertainty.
REPLICA_OFFSET = TWIN_OFFSET
VARIANTS = ("baseline", "step/2", "stiffness/4", "damping 0.1", "output 2x", "step/4")
#: Automatic penalty of the shipped model, restored in each worker before a variant changes it.
AUTOMATIC_PENALTY = (hinge.PENALTY_STEP_FACTOR, hinge.PENALTY_TRANSLATIONAL_CAP, hinge.PENALTY_ROTATIONAL_CAP)
BOOTSTRAP_DRAWS = 2000
#: Series kept beside the joint reactions, to trace where a peak comes from (bench/peak_sources.py): the contact force
#: and moment on each body, the bodies' motion, the joints' relative motion and the energies.
HISTORY_KEYS = ("contact_force_lvlh", "contact_moment_lvlh", "body_com_lvlh", "body_velocity_lvlh", "body_omega_body",
                "body_to_lvlh", "joint_rotation_joint", "joint_rate_joint", "energy_net_kinetic", "energy_total",
                "energy_dissipated_contact", "energy_dissipated_threads", "energy_dissipated_joints")


def _sub(pattern: str, change, text: str) -> str:
    new, count = re.subn(pattern, change, text, count=1, flags=re.M)
    if count != 1:
        raise SystemExit(f"the case has no line matching {pattern!r}: cannot build this variant")
    return new


def case_text(text: str, variant: str, replica: int, first_mode: float | None) -> str:
    """The case of one variant and replica, as TOML text."""
    joint_extra = []
    if first_mode:
        joint_extra.append(f"first_mode_hz = {first_mode / 2 if variant == 'stiffness/4' else first_mode:g}")
    if variant == "damping 0.1":
        joint_extra.append("penalty_damping_ratio = 0.1")
    if joint_extra:         # numerical joints only: a member's springs and damping are the structure's
        blocks = text.split("[[target.joints]]")
        text = "[[target.joints]]".join(blocks[:1] + [
            b if re.search(r"^member\s*=", b, flags=re.M) else
            re.sub(r'^(kind = "(revolute|clamped)".*)$', lambda m: "\n".join([m.group(1)] + joint_extra), b,
                   count=1, flags=re.M)
            for b in blocks[1:]])
    if variant in ("step/2", "step/4"):
        divisor = 2 if variant == "step/2" else 4
        text = _sub(r"^step = ([0-9.e-]+)", lambda m: f"step = {float(m.group(1)) / divisor:g}", text)
    if variant == "output 2x":
        text = _sub(r"^output_rate = ([0-9.e]+)", lambda m: f"output_rate = {2 * float(m.group(1)):g}", text)
    return _sub(r"^velocity = ([0-9.e+-]+)",
                lambda m: f"velocity = {float(m.group(1)) * (1 + replica * REPLICA_OFFSET)!r}", text)


def with_members(text: str, specs: list[str], modulus: float, shear_modulus: float, damping: float) -> str:
    """The case text with each ``JOINT:LENGTH`` joint carrying its member's compliance (``member`` on the joint):
    the section and beam axis of the weak location on that joint, ``LENGTH`` (m), the moduli (Pa) and the
    member's damping ratio."""
    locations = tomllib.loads(text)["structures"]["weak_locations"]
    for spec in specs:
        joint, length = spec.split(":")
        location = next((loc for loc in locations if loc["joint"] == joint and "section" in loc), None)
        if location is None:
            raise SystemExit(f"--member {spec}: no weak location with a section on joint '{joint}'")
        section = ", ".join(f"{k} = {json.dumps(v)}" for k, v in location["section"].items())
        member = (f'member = {{ length = {float(length)!r}, section = {{ {section} }}, modulus = {modulus!r}, '
                  f'shear_modulus = {shear_modulus!r}, beam_axis = {json.dumps(location["beam_axis"])}, '
                  f'source = "bench --member {spec}: the weak location\'s section" }}\n'
                  f'penalty_damping_ratio = {damping!r}')
        text = _sub(rf'^name = "{re.escape(joint)}".*$', lambda m: m.group(0) + "\n" + member, text)
    return text


def with_load_filters(text: str, cutoff_hz: float | None, joint_specs: list[str]) -> str:
    """The case text with ``structures.load_filter_hz = cutoff_hz`` (when given) and each ``JOINT:HZ`` joint's own
    ``load_filter_hz`` (:mod:`multibody.load_filter`)."""
    if cutoff_hz:
        text = _sub(r'^release = "never".*$', lambda m: m.group(0) + f"\nload_filter_hz = {cutoff_hz!r}", text)
    for spec in joint_specs:
        joint, hz = spec.split(":")
        text = _sub(rf'^name = "{re.escape(joint)}".*$', lambda m: m.group(0) + f"\nload_filter_hz = {float(hz)!r}",
                    text)
    return text


def with_rotation_modes(text: str, specs: list[str]) -> str:
    """The case text with each ``JOINT:H1,H2,H3`` joint's rotations carrying the structure's modes (Hz; ``-`` keeps
    an axis's automatic penalty): ``rotation_modes`` on the joint (:func:`multibody.hinge.joint_stiffness_joint_frame`),
    damping 2 % of critical, its ``source`` naming this option (an engineering estimate, docs/structures.md)."""
    for spec in specs:
        joint, values = spec.split(":")
        axes = ", ".join(f"{axis}_hz = {float(v)!r}" for axis, v in zip(("h1", "h2", "h3"), values.split(","))
                         if v != "-")
        modes = (f'rotation_modes = {{ {axes}, damping_ratio = 0.02, '
                 f'source = "bench --rotation-modes {spec}: engineering estimate" }}')
        text = _sub(rf'^name = "{re.escape(joint)}".*$', lambda m: m.group(0) + "\n" + modes, text)
    return text


def replica_overrides(overrides: dict, replica: int, velocity: float | None) -> dict:
    """A store sample's overrides (dotted key -> SI value) for one replica: its launch velocity (m/s; or
    ``velocity``) times 1 + replica x REPLICA_OFFSET, as :func:`case_text` offsets the case's own."""
    if not overrides:
        return {}
    nominal = overrides["launch.velocity"] if velocity is None else velocity
    return overrides | {"launch.velocity": nominal * (1 + replica * REPLICA_OFFSET)}


def simulate(text: str, base_dir: str, stiffness_scale: float, out: str, overrides: dict | None = None) -> str:
    """Run one case text (with ``overrides``, dotted key -> SI value, applied to it) and keep its raw joint
    reactions in ``out`` (.npz: time, force, moment, cpu); returns ``out``, or the failure message of a run the
    model cannot finish."""
    if Path(out).exists():
        return out
    factor, cap_t, cap_r = AUTOMATIC_PENALTY          # every automatic joint axis scaled, capped or not
    hinge.PENALTY_STEP_FACTOR = factor * np.sqrt(stiffness_scale)
    hinge.PENALTY_TRANSLATIONAL_CAP, hinge.PENALTY_ROTATIONAL_CAP = cap_t * stiffness_scale, cap_r * stiffness_scale
    start = time.process_time()
    with tempfile.TemporaryDirectory(dir=base_dir) as tmp:      # mesh and data paths stay relative
        case = Path(tmp) / "case.toml"
        case.write_text(text)
        validated = validate_case(case_with(tomllib.loads(text), overrides), case) if overrides else None
        try:
            run_case(case, Path(tmp) / "run", case=validated)
        except SimulationFailed as exc:     # a variant the model cannot run is a finding, not a crash
            return f"failed: {exc}"
        with np.load(Path(tmp) / "run" / "timeseries.npz") as data:
            filtered = ({"force_filtered": data["joint_force_filtered_joint"],
                         "moment_filtered": data["joint_moment_filtered_joint"]}
                        if "joint_force_filtered_joint" in data else {})
            history = {key: data[key] for key in HISTORY_KEYS if key in data}
            np.savez(out + ".tmp.npz", time=data["time"], force=data["joint_force_joint"],
                     moment=data["joint_moment_joint"], cpu=time.process_time() - start, **filtered, **history)
    os.replace(out + ".tmp.npz", out)
    return out


def histories(locations, run, modes, damping: float, in_dynamics: set, filtered: bool = False) -> dict:
    """{"location / criterion": demand history} of one run's joint reactions (``filtered``: through the step
    filter, :mod:`multibody.load_filter`), read through ``modes`` (Hz; empty: as recorded); a location whose joint
    carries its member (``in_dynamics``, joint indices) is always read as recorded (its compliance is already in the
    run)."""
    t, force, moment = run["time"], run["force"], run["moment"]
    if filtered:
        force, moment = run["force_filtered"], run["moment_filtered"]
    out = {}
    for loc in locations:
        own = () if loc.joint in in_dynamics else tuple(modes)
        loc = replace(loc, structural_modes_hz=own, structural_damping_ratio=damping)
        series = judged_demands(loc, t, force[:, loc.joint], moment[:, loc.joint])
        for criterion in loc.criteria():
            out[f"{loc.name} / {criterion}"] = series[criterion]
    return out


def window_peaks(time, series, skip: float, parting: float, margin: float = 0.0) -> dict:
    """The peak of one demand in each window (``nan`` for an empty one): before the replicas part
    (deterministic; from t = 0; ending ``margin`` s before the parting), after they part and after ``skip``
    (chaotic), after ``skip`` (judged)."""
    # window edges half a sample off the sample times: runs at other steps sum their sample times with other
    # round-off (0.242 as 0.24199999999998967 or just above), and a load rising at the edge (the net reaching the
    # array at 0.24 s) then put one more sample into one run's window: +155 % "with step / 2" that was one sample
    half = 0.5 * float(np.median(np.diff(time))) if len(time) > 1 else 0.0
    before, after = time < parting - max(half, margin), time >= max(skip, parting) - half
    windows = {"deterministic": before, "chaotic": after, "judged": time >= skip - half}
    return {w: float(series[m].max()) if m.any() else float("nan") for w, m in windows.items()}


def quantile_change(base: np.ndarray, variant: np.ndarray, rng, q: float = 0.5) -> tuple[float, float, float]:
    """Change of the ``q`` quantile over the replicas (variant / baseline - 1) and its 90 % bootstrap interval (both
    sets resampled). The quantile interpolates linearly between order statistics (numpy's default, Hyndman & Fan
    type 7): with ``n`` replicas the 0.9 quantile lies between the two largest values when ``n`` <= 11, so it
    resolves the upper tail only as far as that many draws do."""
    change = np.quantile(variant, q) / np.quantile(base, q) - 1.0
    b = rng.choice(base, (BOOTSTRAP_DRAWS, base.size))
    v = rng.choice(variant, (BOOTSTRAP_DRAWS, variant.size))
    draws = np.quantile(v, q, axis=1) / np.quantile(b, q, axis=1) - 1.0
    low, high = np.percentile(draws, [5, 95])
    return change, low, high


def median_change(base: np.ndarray, variant: np.ndarray, rng) -> tuple[float, float, float]:
    """Change of the median (variant / baseline - 1) and its 90 % bootstrap interval."""
    return quantile_change(base, variant, rng, 0.5)


def quantile_precision(base: np.ndarray, rng, q: float = 0.5) -> float:
    """Half-width of the 90 % bootstrap interval of the baseline's ``q`` quantile, relative to it: how well the
    replicas know that quantile at all."""
    draws = np.quantile(rng.choice(base, (BOOTSTRAP_DRAWS, base.size)), q, axis=1) / np.quantile(base, q) - 1.0
    low, high = np.percentile(draws, [5, 95])
    return float(max(-low, high))


def statistic_name(q: float) -> str:
    """'median' or e.g. 'q90' for the 0.9 quantile."""
    return "median" if q == 0.5 else f"q{100 * q:g}"


def verdict(change: float, low: float, high: float) -> str:
    """'ok' within the tolerance; 'within statistical error' when the interval holds 0 but not the
    tolerance (the replicas do not resolve a change of that size, none is seen); 'NOT CONVERGED' when the
    interval lies beyond the tolerance; 'unresolved' otherwise (a change is seen, smaller than or straddling
    the tolerance)."""
    if max(abs(low), abs(high), abs(change)) <= TOLERANCE:
        return "ok"
    if low > TOLERANCE or high < -TOLERANCE:
        return "NOT CONVERGED"
    if low <= 0.0 <= high:
        return "within statistical error"
    return "unresolved"


MARKS = {"ok": "", "within statistical error": " ~", "unresolved": " ?", "NOT CONVERGED": " **x**"}


def reading_table(results: dict, replicas: int, locations, modes, damping, skip: float, in_dynamics: set,
                  margin: float = 0.0, filtered: bool = False) -> dict:
    """{key: {"parting": s, "peaks": {variant: [{window: peak} per replica]}}} for one reading."""
    ran = {v: [results[(v, r)] for r in range(replicas) if not isinstance(results[(v, r)], str)] for v in VARIANTS}
    runs = {v: [histories(locations, run, modes, damping, in_dynamics, filtered) for run in ran[v]]
            for v in VARIANTS if ran[v]}
    base_time = ran["baseline"][0]["time"]
    table = {}
    for key in runs["baseline"][0]:
        parting = min(parting_time(base_time, [h[key] for h in runs["baseline"]]), float(base_time[-1]) + 1.0)
        table[key] = {"parting": parting, "peaks": {
            v: [window_peaks(run["time"], h[key], skip, parting, margin) for run, h in zip(ran[v], runs[v])]
            for v in runs}}
    return table


def report(results: dict, replicas: int, locations, readings: dict, skip: float, in_dynamics: set,
           markdown: bool = False, margin: float = 0.0, quantiles: tuple = (0.5,)) -> None:
    """Per reading, location and criterion: when the replicas part, and in each window, for each quantile of the
    peak over the replicas (``quantiles``; 0.5: the median), the baseline's value [range], its spread and
    precision, each variant's change of that quantile with its bootstrap interval and verdict (``markdown``: one
    table for docs/structures.md)."""
    rng = np.random.default_rng(0)
    names = [v for v in VARIANTS if v != "baseline"
             and any(not isinstance(results[(v, r)], str) for r in range(replicas))]
    only_median = tuple(quantiles) == (0.5,)
    if markdown:
        print(f"\n| reading | location / criterion | window | baseline {'median' if only_median else 'value'} [range] | "
              f"spread | {'median' if only_median else 'value'} known to | " + " | ".join(names) + " |")
        print("|" + "---|" * (6 + len(names)))
    members = {f"{loc.name} / " for loc in locations if loc.joint in in_dynamics}
    for index, (reading, (modes, damping, filtered)) in enumerate(readings.items()):
        table = reading_table(results, replicas, locations, modes, damping, skip, in_dynamics, margin, filtered)
        counts = dict.fromkeys(MARKS, 0)
        if not markdown:
            print(f"\n=== reading: {reading} (locations whose joint carries its member: as recorded)")
        for key, row in table.items():
            member = any(key.startswith(m) for m in members)
            if markdown and member and index > 0:       # a member's location reads the same in every reading
                continue
            for window in ("deterministic", "chaotic") if markdown else ("deterministic", "chaotic", "judged"):
                values = np.array([p[window] for p in row["peaks"]["baseline"]])
                if np.isnan(values).any():
                    continue
                label = {"deterministic": f"deterministic, t < {row['parting'] - margin:.3f} s",
                         "chaotic": f"chaotic, t >= {max(skip, row['parting']):.2f} s",
                         "judged": f"judged, t >= {skip:g} s"}[window]
                for q in quantiles:
                    value = np.quantile(values, q)
                    cells = []
                    for n in names:
                        variant = np.array([p[window] for p in row["peaks"][n]])
                        change, low, high = quantile_change(values, variant, rng, q)
                        state = verdict(change, low, high)
                        counts[state] += 1
                        cells.append(f"{change:+.0%} [{low:+.0%}, {high:+.0%}]{MARKS[state]}")
                    stat = "" if only_median else f", {statistic_name(q)}"
                    spread = (values.max() - values.min()) / np.median(values) if value else float("nan")
                    known = quantile_precision(values, rng, q) if value else float("nan")
                    if markdown:
                        print(f"| {'member in the dynamics' if member else reading} | {key} | {label}{stat} | "
                              f"{value:.3g} [{values.min():.3g}, {values.max():.3g}] | "
                              f"{spread:.0%} | +-{known:.0%} | " + " | ".join(cells) + " |")
                    else:
                        print(f"  {key:36s} {label + stat:26s} {f'{value:.4g} [{values.min():.3g}, {values.max():.3g}]':>30s} "
                              f"{spread:6.0%} +-{known:4.0%}  " + "  ".join(f"{n}: {c}" for n, c in zip(names, cells)))
        if not markdown:
            print(f"  {reading}: " + ", ".join(f"{c} {s}" for s, c in counts.items())
                  + f" (tolerance {TOLERANCE:.0%}; spread = (max - min) / median over the replicas; "
                    "[90 % bootstrap interval]; 'known to': half-width of the baseline value's interval)")


def peak_times(results: dict, replicas: int, locations, readings: dict, skip: float, in_dynamics: set,
               name: str) -> None:
    """Per reading, variant and replica: the judged peak (after ``skip``) of location ``name``, its time, its
    utilization against the allowable's low end (each criterion) and the joint's recorded moment there (N m, joint
    frame axes h1, h2, h3: which axis carries the peak)."""
    location = next((loc for loc in locations if loc.name == name), None)
    if location is None:
        raise SystemExit(f"--peak-times: no weak location '{name}' (known: {', '.join(l.name for l in locations)})")
    print(f"\n{name}: judged peak (t >= {skip:g} s), its time and utilization (peak / allowable low end)")
    for reading, (modes, damping, filtered) in readings.items():
        for (variant, replica), run in results.items():
            if isinstance(run, str):
                continue
            for key, series in histories([location], run, modes, damping, in_dynamics, filtered).items():
                criterion = key.split(" / ")[1]
                judged = np.where(run["time"] >= skip, series, -np.inf)
                k = int(np.argmax(judged))
                low = location.criteria()[criterion].low
                moment_joint = run["moment_filtered" if filtered else "moment"][k, location.joint]
                print(f"  {reading:34s} {variant:12s} r{replica}  {criterion}: {series[k]:8.1f} at {run['time'][k]:.3f} s, "
                      f"utilization {series[k] / low:.3f}; moment h1 h2 h3 {moment_joint[0]:+.0f} "
                      f"{moment_joint[1]:+.0f} {moment_joint[2]:+.0f} N m")


def parse_mode(text: str) -> tuple[str, np.ndarray]:
    """'2' or '0.5,2' -> (label, grid of modes in Hz)."""
    values = [float(v) for v in text.split(",")]
    low, high = values[0], values[-1]
    label = f"through a {low:g} Hz mode" if low == high else f"envelope over first modes {low:g}-{high:g} Hz"
    return label, mode_grid(low, high)


def main() -> None:
    global VARIANTS     # --against adds a column
    parser = argparse.ArgumentParser()
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_small.toml"))
    parser.add_argument("--end-time", type=float, default=None)
    parser.add_argument("--replicas", type=int, default=4)
    parser.add_argument("--first-mode", type=float, default=None, help="every joint's first_mode_hz (Hz)")
    parser.add_argument("--mode", action="append", default=[], help="read the loads through this first mode (Hz) "
                                                                     "or the envelope over LOW,HIGH (Hz)")
    parser.add_argument("--mode-damping", type=float, default=0.02, help="damping ratio of --mode (-)")
    parser.add_argument("--skip", type=float, default=None, help="first window (s); default: the case's skip_initial")
    parser.add_argument("--cache", default=None, help="folder of the runs' raw joint reactions")
    parser.add_argument("--workers", type=int, default=1)
    parser.add_argument("--markdown", action="store_true", help="one markdown table (docs/structures.md)")
    parser.add_argument("--member", action="append", default=[], metavar="JOINT:LENGTH",
                        help="give this clamped joint its member's compliance: the section of its weak location, "
                             "LENGTH (m) and --member-moduli (docs/structures.md)")
    parser.add_argument("--member-moduli", default="114e9,44e9", help="E,G of --member (Pa); default Ti-6Al-4V")
    parser.add_argument("--member-damping", type=float, default=0.02, help="damping ratio of --member (-)")
    parser.add_argument("--output-rate", type=float, default=None, help="baseline output rate (Hz)")
    parser.add_argument("--report-only", action="store_true", help="report the runs the cache holds, run nothing")
    parser.add_argument("--edge-margin", type=float, default=0.0,
                        help="end the deterministic window this long (s) before the replicas part: a strike arriving "
                             "at the parting (its arrival moves by a fraction of a sample with the step) then does "
                             "not decide that window's peak")
    parser.add_argument("--against", default=None, metavar="CACHE",
                        help="also report the baseline runs of another cache (a physical change, e.g. "
                             "--member-damping) as one more column, judged in this cache's windows")
    parser.add_argument("--store", default=None, help="run a Monte Carlo sample of this safe-velocity store")
    parser.add_argument("--sample", type=int, default=0, help="the store's sample (with --store)")
    parser.add_argument("--velocity", type=float, default=None, help="launch velocity (m/s) instead of the store's")
    parser.add_argument("--peak-times", default=None, metavar="LOCATION",
                        help="print this location's judged peak, time and utilization per variant and replica")
    parser.add_argument("--quantile", type=float, action="append", default=[], metavar="Q",
                        help="also compare this quantile (0 < Q < 1) of the peak over the replicas, e.g. 0.9 (what a "
                             "verdict's probability uses: the upper tail, not one run)")
    parser.add_argument("--load-filter", type=float, default=None, metavar="HZ",
                        help="structures.load_filter_hz: every joint's loads through a 2nd-order Butterworth at HZ, "
                             "run every step (adds the reading 'through the step filter')")
    parser.add_argument("--joint-filter", action="append", default=[], metavar="JOINT:HZ",
                        help="this joint's own load_filter_hz (overrides --load-filter for it)")
    parser.add_argument("--rotation-modes", action="append", default=[], metavar="JOINT:H1,H2,H3",
                        help="give this joint's rotations the structure's modes (Hz; '-' keeps an axis's automatic "
                             "penalty): rotation_modes on the joint, 2 %% damping")
    parser.add_argument("--variants", default=",".join(v for v in VARIANTS if v != "step/4"),
                        help="comma list of the configurations to run (default: all but step/4, which costs about four "
                             "baseline runs); the others are reported missing")
    args = parser.parse_args()
    case_path = Path(args.case).resolve()
    text = case_path.read_text()
    if 'release = "low"' not in text:      # otherwise the peaks would be cut at each joint's release
        raise SystemExit(f"{args.case}: expected release = \"low\" in [structures] to switch it off")
    text = text.replace('release = "low"', 'release = "never"', 1)
    if args.member:
        modulus, shear_modulus = (float(v) for v in args.member_moduli.split(","))
        text = with_members(text, args.member, modulus, shear_modulus, args.member_damping)
    if args.output_rate:
        text = _sub(r"^output_rate = [0-9.e]+", f"output_rate = {args.output_rate:g}", text)
    if args.end_time:
        text = _sub(r"^end_time = [0-9.e]+", f"end_time = {args.end_time:g}", text)
    text = with_load_filters(text, args.load_filter, args.joint_filter)
    text = with_rotation_modes(text, args.rotation_modes)
    overrides = sample_overrides(Path(args.store), args.sample) if args.store else {}
    if args.velocity is not None and not overrides:
        raise SystemExit("--velocity: with --store only (the case's own velocity is its [launch] velocity)")
    if overrides:
        print(f"{args.store}, sample {args.sample}: {replica_overrides(overrides, 0, args.velocity)}")
    tag = hashlib.sha256(f"{text}{args.first_mode}{replica_overrides(overrides, 0, args.velocity)}".encode()
                         ).hexdigest()[:12]
    cache = Path(args.cache or Path(tempfile.gettempdir()) / f"peak-convergence-{case_path.stem}-{tag}")
    cache.mkdir(parents=True, exist_ok=True)
    jobs = {(v, r): (case_text(text, v, r, args.first_mode), str(case_path.parent),
                     0.25 if v == "stiffness/4" and not args.first_mode else 1.0,
                     str(cache / f"{v.replace('/', '_').replace(' ', '_')}-{r}.npz"),
                     replica_overrides(overrides, r, args.velocity))
            for v in VARIANTS for r in range(args.replicas)}
    start, load = time.perf_counter(), os.getloadavg()[0]
    chosen = set(args.variants.split(","))
    if not chosen <= set(VARIANTS) or "baseline" not in chosen:
        raise SystemExit(f"--variants: a comma list of {', '.join(VARIANTS)}, with baseline")
    if args.report_only or chosen != set(VARIANTS):   # what the cache holds (a partial table while runs go on)
        if not args.report_only:
            with ProcessPoolExecutor(args.workers) as pool:
                # replica by replica over the variants (the pool takes them in this order): a study stopped early
                # keeps the variants' counts even
                order = sorted((k for k in jobs if k[0] in chosen), key=lambda k: (k[1], VARIANTS.index(k[0])))
                futures = {pool.submit(simulate, *jobs[key]): key for key in order}
                for future in as_completed(futures):
                    print(f"{futures[future]} {future.result()}", flush=True)
        results = {key: job[3] if Path(job[3]).exists() else "missing: not run yet" for key, job in jobs.items()}
    else:
        with ProcessPoolExecutor(args.workers) as pool:
            futures = {pool.submit(simulate, *job): key for key, job in jobs.items()}
            results = {}
            for future in as_completed(futures):
                results[futures[future]] = future.result()
                print(f"{len(results)}/{len(jobs)} {futures[future]} done, {time.perf_counter() - start:.0f} s wall, "
                      f"load {os.getloadavg()[0]:.1f}", flush=True)
    if args.against:        # another cache's baselines as one more column (its runs must exist)
        column = f"against {Path(args.against).name}"
        VARIANTS = VARIANTS + (column,)
        for r in range(args.replicas):
            path = Path(args.against) / f"baseline-{r}.npz"
            results[(column, r)] = str(path) if path.exists() else "missing: not in the other cache"
    results = {k: (v if v.startswith(("failed", "missing")) else dict(np.load(v))) for k, v in results.items()}
    cpu = [float(v["cpu"]) for v in results.values() if not isinstance(v, str)]
    print(f"{args.case}, release off, joints: "
          + (f"first_mode_hz = {args.first_mode:g}" if args.first_mode else
             "automatic penalty where the case gives no first_mode_hz, member or rotation_modes")
          + (f", members {', '.join(args.member)} (E, G = {args.member_moduli} Pa, damping {args.member_damping:g})"
             if args.member else "")
          + (f", output {args.output_rate:g} Hz" if args.output_rate else "")
          + f"; {len(jobs)} runs ({args.replicas} replicas each; cache {cache}) in "
          f"{time.perf_counter() - start:.0f} s wall on {args.workers} workers, load average {load:.1f} -> "
          f"{os.getloadavg()[0]:.1f}; CPU per run {np.median(cpu) if cpu else float('nan'):.1f} s (median, "
          f"as measured when each run was made)")
    for key, value in results.items():
        if isinstance(value, str):
            print(f"{key[0]} replica {key[1]}: {value}")
    case = validate_case(tomllib.loads(text), case_path)      # the case as run (with any --member)
    locations = weak_locations(case, model_inputs(case, case_path.parent).assembly)
    skip = case.structures.skip_initial if args.skip is None else args.skip
    readings = {"as recorded": ((), 0.0, False)}
    if args.load_filter or args.joint_filter:
        cutoffs = ", ".join([f"{args.load_filter:g} Hz" if args.load_filter else "raw"]
                            + [f"{spec.split(':')[0]} {float(spec.split(':')[1]):g} Hz" for spec in args.joint_filter])
        readings[f"through the step filter ({cutoffs})"] = ((), 0.0, True)
    readings.update({label: (tuple(grid), args.mode_damping, False) for label, grid in map(parse_mode, args.mode)})
    in_dynamics = {i for i, j in enumerate(case.target.joints) if j.member is not None}
    if any(not 0.0 < q < 1.0 for q in args.quantile):
        raise SystemExit(f"--quantile: a fraction between 0 and 1, got {args.quantile}")
    quantiles = (0.5,) + tuple(q for q in args.quantile if q != 0.5)
    report(results, args.replicas, locations, readings, skip, in_dynamics, args.markdown, args.edge_margin, quantiles)
    if args.peak_times:
        peak_times(results, args.replicas, locations, readings, skip, in_dynamics, args.peak_times)


if __name__ == "__main__":
    main()
