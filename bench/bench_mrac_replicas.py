"""MRAC-1 and MRAC-2 on both plants, several perturbed starts per setting (issue 27: on the full net at 20.44 deg/s
the tow sits at the slack edge and is chaotic, so single runs cannot rank settings).

    python bench/bench_mrac_replicas.py --plant full-net --rate 20.44 10.71 --laws mrac2 mrac1 --replicas 3 \\
        --label notch --set mrac.breathing_notch=true --results bench/results/mrac_replicas.jsonl
    python bench/bench_mrac_replicas.py --table bench/results/mrac_replicas.jsonl       # the summary, run nothing

Replica j (0, 1, ...) starts the debris at the spin rate x (1 + j x ``--perturbation``) (default 1e-3: 0.02 deg/s at
20.44 deg/s, inside any perception estimate's error; replica 0 is the nominal start); everything else is the case's
(``cases/zenit2_towing.toml``, full net from the wrapped start, 25-300 s) with ``--set section.key=value`` overrides
of ``[mrac]`` / ``[thrust]`` (as in bench/bench_mrac_probe.py), named ``--label``. Each finished run appends one JSON
line to ``--results`` (resumable: a run already there is not repeated) and its series (time, tension, elongation,
thrust, debris spin, chaser-debris CoM distance; every output sample) to ``<results stem>/<label>_<plant>_<law>_<rate>_<j>.npz``.

Per run: mean elongation over the last 100 s and its RMS error to the desired elongation (``mrac.desired_elongation``,
the reference model's steady elongation with ``settle_at_desired``; with ``mrac.tow_point_offset`` the governed one at
the run's spin rate), slack time after engagement (T_MT <= 0, s), the
near-slack share (T_MT < 1 N after engagement: on the full net a slack tether still carries the node's pull of a few
tenths of a newton), peak tension, debris spin at the end (deg/s), CPU time and load. ``--table`` prints per (label,
plant, law, rate) the mean over the replicas and, in brackets, their range.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from multibody.net_towing import run_exudyn as run_full_net
from multibody.towing import run_exudyn
from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase
from riskassess.models.towing import towing_model
from riskassess.models.towing_fullnet import full_net_model, wrapped_net
from riskassess.products import results
from riskassess.products.towing_figures import reference_elongation, tautness
sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script, also when imported
from bench_mrac_probe import overridden  # noqa: E402

COLUMNS = (("mean_last_100_s_m", "mean z (m)", ".4f"), ("rms_error_m", "RMS z - z_d (m)", ".4f"),
           ("slack_s", "slack (s)", ".1f"), ("near_slack_share", "T < 1 N", ".2f"),
           ("peak_tension_N", "peak T (N)", ".0f"), ("thrust_peak_N", "peak F (N)", ".0f"),
           ("at_thrust_peak_share", "F at its peak, 100-300 s", ".2f"),
           ("spin_end_deg_s", "spin end (deg/s)", ".2f"))
#: Columns of runs with the lateral station-keeping law (``--set lateral.enabled=true``), printed when a row has them.
LATERAL_COLUMNS = (("thrust_mean_last_100_s_N", "mean F, last 100 s (N)", ".1f"),
                   ("lateral_mean_last_100_s_N", "mean lateral F, last 100 s (N)", ".1f"),
                   ("lateral_peak_N", "peak lateral F (N)", ".1f"),
                   ("lateral_error_rms_last_100_s_m", "chaser off the debris' omega axis, RMS last 100 s (m)", ".3f"))


def figures(series: dict, target: float) -> dict:
    """The run's figures (module doc) from a tow's series (SI).

    Parameters
    ----------
    series : dict
        ``time`` (k,) s, ``main_tether_tension`` (k,) N, ``main_tether_elongation`` (k,) m, ``debris_omega_body`` (k, 3)
        rad/s.
    target : float
        Desired elongation (m).

    Returns
    -------
    dict
    """
    f = tautness(series, target)
    t, tension, z = series["time"], series["main_tether_tension"], series["main_tether_elongation"]
    after = t >= f["engaged_at_s"]
    last = t > t[-1] - 100.0
    return {"mean_last_100_s_m": float(z[last].mean()), "rms_error_m": f["rms_elongation_error_m"],
            "slack_s": f["slack_after_engagement_s"], "near_slack_share": float(np.mean(tension[after] < 1.0)),
            "peak_tension_N": f["peak_tension_N"],
            "spin_end_deg_s": float(np.degrees(np.linalg.norm(series["debris_omega_body"][-1]))),
            "end_time_s": float(t[-1]), **thrust_figures(t, series["thrust"]), **lateral_figures(series)}


def lateral_figures(series: dict) -> dict:
    """Tether-axis thrust and lateral station-keeping force (N) over the last 100 s (mean magnitude) and over the
    run (peak), and the RMS distance (m) of the chaser from the line through the debris CoM along its angular
    velocity over the last 100 s (the series hold no inertia: omega stands for the angular momentum H the
    ``momentum_axis`` target uses, exact while omega lies in the body x-y plane, I_x = I_y; a nutation tilts them
    apart).

    Parameters
    ----------
    series : dict
        A full-net tow's series (:meth:`multibody.net_towing.NetTowResult.series`).
    """
    t = series["time"]
    last = t > t[-1] - 100.0
    out = {"thrust_mean_last_100_s_N": float(series["thrust"][last].mean())}
    if "lateral_thrust_inertial" not in series:
        return out
    side = np.linalg.norm(series["lateral_thrust_inertial"], axis=1)
    rot_d = series["debris_to_inertial"]
    axis = np.einsum("kij,kj->ki", rot_d, series["debris_omega_body"])     # H is along omega: I_x = I_y, omega in x-y
    axis /= np.linalg.norm(axis, axis=1)[:, None]
    d = series["chaser_com_inertial"] - series["debris_com_inertial"]
    off = d - np.sum(d * axis, axis=1)[:, None] * axis
    return {**out, "lateral_mean_last_100_s_N": float(side[last].mean()), "lateral_peak_N": float(side.max()),
            "lateral_error_rms_last_100_s_m": float(np.sqrt(np.mean(np.sum(off[last] ** 2, axis=1))))}


def thrust_figures(t, thrust) -> dict:
    """Peak thrust (N) and the share of the samples over 100-300 s at it (within 1e-6 N): the share of the time the
    command sits at the actuator's upper bound when it saturates, ~0 when it does not.

    Parameters
    ----------
    t : (k,) float
        Time (s).
    thrust : (k,) float
        Thrust (N).
    """
    peak = float(thrust.max())
    late = t >= 100.0
    return {"thrust_peak_N": peak, "at_thrust_peak_share": float(np.mean(thrust[late] >= peak - 1e-6))}


def with_thrust_figures(record: dict, folder: Path) -> dict:
    """A results line with the thrust figures, taken from its stored series when the line predates them."""
    if "thrust_peak_N" in record and "thrust_mean_last_100_s_N" in record:
        return record
    d = np.load(folder / f"{record['label']}_{record['plant']}_{record['law']}_{record['rate_deg_s']:g}_{record['replica']}.npz")
    t, thrust = d["time"], d["thrust"]
    return {**thrust_figures(t, thrust), "thrust_mean_last_100_s_N": float(thrust[t > t[-1] - 100.0].mean()), **record}


def at_spin(case: TowingCase, spin_rate_deg_s: float) -> TowingCase:
    """``case`` with the debris spinning at ``spin_rate_deg_s`` (deg/s), the rate the run is made at (as the model
    builders set it for the thrust law)."""
    return case.model_copy(update=dict(debris=case.debris.model_copy(update=dict(spin_rate_deg_s=spin_rate_deg_s))))


def table(path: Path) -> None:
    """Print the replicas' summary of a results file (module doc).

    Parameters
    ----------
    path : Path
        A ``--results`` file of this bench.
    """
    with open(path, encoding="utf-8") as handle:
        rows = [with_thrust_figures(json.loads(line), path.with_suffix("")) for line in handle if line.strip()]
    groups = {}
    for r in rows:
        groups.setdefault((r["label"], r["plant"], r["law"], r["rate_deg_s"]), []).append(r)
    columns = COLUMNS + (LATERAL_COLUMNS if any("lateral_peak_N" in r for r in rows) else ())
    names = " | ".join(name for _, name, _ in columns)
    print(f"| setting | plant | law | rate (deg/s) | runs | {names} | CPU s a run |")
    print("|---" * (6 + len(columns)) + "|")
    order = sorted(groups.items(), key=lambda kv: (kv[0][0], kv[0][1], kv[0][3], kv[0][2]))
    for (label, plant, law, rate), runs in order:
        cells = []
        for key, _, fmt in columns:
            v = np.array([r.get(key, np.nan) for r in runs], float)
            if np.isnan(v).all():
                cells.append("-")     # a run without the lateral law
                continue
            cells.append(f"{v.mean():{fmt}} [{v.min():{fmt}}, {v.max():{fmt}}]" if len(v) > 1 else f"{v[0]:{fmt}}")
        cpu = np.mean([r["cpu_s"] for r in runs])
        print(f"| {label} | {plant} | {law} | {rate:g} | {len(runs)} | " + " | ".join(cells) + f" | {cpu:.0f} |")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default="cases/zenit2_towing.toml")
    parser.add_argument("--plant", choices=("lower-order", "full-net"), default="full-net")
    parser.add_argument("--rate", type=float, nargs="+", default=[20.44, 10.71], help="spin rates (deg/s)")
    parser.add_argument("--laws", nargs="+", choices=("ramp", "mrac1", "mrac2"), default=("mrac2", "mrac1"))
    parser.add_argument("--replicas", type=int, default=3)
    parser.add_argument("--first-replica", type=int, default=0,
                        help="run replicas first..replicas-1 only (another process runs the lower ones)")
    parser.add_argument("--perturbation", type=float, default=1e-3, help="relative spin-rate step between replicas")
    parser.add_argument("--label", default="shipped")
    parser.add_argument("--set", nargs="*", default=[])
    parser.add_argument("--results", type=Path, default=None)
    parser.add_argument("--table", type=Path, default=None, help="print the summary of this results file, run nothing")
    args = parser.parse_args()
    if args.table is not None:
        table(args.table)
        return
    if args.results is None:
        parser.error("--results is required unless --table")
    case = overridden(load_model(args.case, TowingCase), args.set)
    done = set()
    if args.results.exists():
        with open(args.results, encoding="utf-8") as handle:
            done = {json.loads(line)["key"] for line in handle if line.strip()}
    folder = args.results.with_suffix("")
    folder.mkdir(parents=True, exist_ok=True)
    wrapped = wrapped_net(case) if args.plant == "full-net" else None
    for rate in args.rate:
        for law in args.laws:
            for j in range(args.first_replica, args.replicas):
                key = f"{args.label}|{args.plant}|{law}|{rate:g}|{j}"
                if key in done:
                    continue
                run_case = overridden(case, [f"thrust.kind={json.dumps(law)}"])
                spin = rate * (1.0 + j * args.perturbation)
                target = reference_elongation(at_spin(run_case, spin))   # mrac.tow_point_offset governs it by spin
                load0, start = os.getloadavg()[0], time.process_time()
                if args.plant == "full-net":
                    series = run_full_net(full_net_model(run_case, spin, wrapped=wrapped)).series()
                else:
                    series = run_exudyn(towing_model(run_case, spin)).series()
                cpu = time.process_time() - start
                record = {"key": key, "label": args.label, "set": args.set, "plant": args.plant, "law": law,
                          "rate_deg_s": rate, "replica": j, "spin_start_deg_s": spin, "target_m": target,
                          **figures(series, target), "cpu_s": cpu, "load": [load0, os.getloadavg()[0]]}
                keys = ("time", "main_tether_tension", "main_tether_elongation", "thrust", "debris_omega_body",
                        "lateral_thrust_inertial")
                separation = np.linalg.norm(series["debris_com_inertial"] - series["chaser_com_inertial"], axis=1)
                results.atomic_write_npz(folder / f"{args.label}_{args.plant}_{law}_{rate:g}_{j}.npz",
                                         {**{k: series[k] for k in keys if k in series}, "separation": separation})
                with open(args.results, "a", encoding="utf-8") as handle:
                    handle.write(json.dumps(record) + "\n")
                print(f"{key}: " + ", ".join(f"{name} {record[k]:{fmt}}" for k, name, fmt in COLUMNS) +
                      f"; {cpu:.0f} s CPU, load {load0:.1f}", flush=True)


if __name__ == "__main__":
    main()
