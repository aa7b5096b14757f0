"""Main-tether control over the Table 3 rate range: open-loop ramp against MRAC-1 and MRAC-2
(multibody/control/mrac.py) on the lower-order towing model or the full-net model, in Exudyn
(cases/zenit2_towing.toml).

    python bench/bench_tow_control.py [--case cases/zenit2_towing.toml] [--rates training|validation|all]
                                      [--plant lower-order|full-net] [--max-rates N] [--plots DIR]
                                      [--rate DEG_S ...] [--desired Z_D] [--laws ramp mrac1 mrac2]
                                      [--results FILE.jsonl]

``--plots DIR`` writes ``DIR/control_<plant>.png`` (tension, elongation with the target, debris rate of the
three laws at the first rate; riskassess.products.towing_plots.plot_control) and ``DIR/control_<plant>.npz``
(those series); DIR is created and an existing figure is not overwritten.

The full-net plant (multibody/net_towing.py, from the wrapped start) takes ~40 s a run: use --max-rates, or
``--rate`` to name the spin rates (deg/s) instead of a Table 3 set. ``--desired`` sets the MRAC desired elongation
z_d (m) instead of the case's ``mrac.desired_elongation``; ``--laws`` picks the laws. The figure and series are named
``control_<plant>_<rate>deg_s[_zd<z_d>].png`` when ``--rate`` or ``--desired`` is given. ``--results FILE.jsonl``
appends one JSON line per finished run (its figures, CPU time, load average), so that a long set can be resumed:
a (plant, law, rate, z_d) already in the file is not run again, and its row is printed from the file.

For every thrust law and spin rate prints (riskassess.products.towing_figures.tautness): the engagement time t_e (first
sample with main-tether tension > 1 N: before it the sub-tethers are still slack and only P hangs
on the main tether),
the smallest main-tether tension after t_e (> 0: taut), the slack time after t_e, the peak
tension, the final elongation and its RMS error over the last 100 s against the MRAC reference
model's steady elongation (riskassess.products.towing_figures.reference_elongation), the mean elongation over the last
100 s and the fraction of the time after t_on the command sits at the saturation; then per law the range over the rates.
"""
from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

from multibody.control.mrac import abstracted_tether, actuator_range, steady_thrust
from multibody.net_towing import run_exudyn as run_full_net
from multibody.towing import run_exudyn
from riskassess.cases.impact import load_model
from riskassess.products import results
from riskassess.products.towing_figures import reference_elongation, tautness
from riskassess.products.towing_plots import plot_control, plot_control_plants
from riskassess.models.towing import towing_model
from riskassess.models.towing_fullnet import full_net_model, wrapped_net
from riskassess.cases.towing import TowingCase

def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default="cases/zenit2_towing.toml")
    parser.add_argument("--rates", choices=("training", "validation", "all"), default="training")
    parser.add_argument("--plant", choices=("lower-order", "full-net"), default="lower-order")
    parser.add_argument("--max-rates", type=int, default=None)
    parser.add_argument("--plots", type=Path, default=None)
    parser.add_argument("--rate", type=float, nargs="+", default=None, help="spin rates (deg/s) instead of --rates")
    parser.add_argument("--desired", type=float, default=None, help="MRAC desired elongation z_d (m)")
    parser.add_argument("--laws", nargs="+", choices=("ramp", "mrac1", "mrac2"), default=("ramp", "mrac1", "mrac2"))
    parser.add_argument("--results", default=None, help="JSON-lines file of finished runs (resumable)")
    parser.add_argument("--near-slack", type=Path, nargs="+", default=None,
                        help="print, per law of these control_*.npz files, the share of samples after engagement with "
                             "T_MT < 1 N, the debris spin at the end and the elongation's mean over the last 100 s; "
                             "run nothing")
    parser.add_argument("--side-by-side", action="store_true",
                        help="only draw DIR/control_plants_<rate>.png from the lower-order and full-net series in "
                             "--plots DIR (written by earlier runs of this bench with the same --rate/--desired)")
    args = parser.parse_args()
    if args.near_slack:
        for path in args.near_slack:
            near_slack(path)
        return
    case = load_model(args.case, TowingCase)
    if args.desired is not None:
        case = case.model_copy(update=dict(mrac=case.mrac.model_copy(update=dict(desired_elongation=args.desired))))
    rates = {"training": case.rates.training_deg_s, "validation": case.rates.validation_deg_s,
             "all": sorted(case.rates.training_deg_s + case.rates.validation_deg_s)}[args.rates][:args.max_rates]
    rates = rates if args.rate is None else args.rate
    tag = args.plant + (f"_{rates[0]:g}deg_s" if args.rate is not None or args.desired is not None else "") + \
        (f"_zd{args.desired:g}" if args.desired is not None else "")
    if args.side_by_side:
        side_by_side(args.plots, tag.split("_", 1)[1], f"{rates[0]:g} deg/s, z_d = {case.mrac.desired_elongation:g} m",
                     reference_elongation(case))
        return
    if args.plots is not None and (args.plots / f"control_{tag}.png").exists():
        parser.error(f"--plots: {args.plots / f'control_{tag}.png'} exists; give another folder")
    done = {}
    if args.results is not None and os.path.exists(args.results):
        with open(args.results, encoding="utf-8") as handle:
            done = {r["key"]: r for r in map(json.loads, filter(str.strip, handle))}
    wrapped = wrapped_net(case) if args.plant == "full-net" else None
    z_d = case.mrac.desired_elongation

    def run(law, rate):
        if args.plant == "full-net":
            return run_full_net(full_net_model(law, rate, wrapped=wrapped)).series()
        return run_exudyn(towing_model(law, rate)).series()

    desired = reference_elongation(case)
    print(f"plant: {args.plant}; MRAC target: the reference model's steady elongation {desired:.4f} m (eq. 13, z_d = "
          f"{case.mrac.desired_elongation} m); the ramp has no target (its error shown for comparison)")
    print(f"{'law':6} {'rate deg/s':>10} {'t_e s':>7} {'min T N':>9} {'slack s':>8} {'peak T N':>9} "
          f"{'z_end m':>8} {'z_100 m':>8} {'rms(z-z_m) m':>12} {'sat':>5} {'cpu s':>7}")
    figures = {kind: [] for kind in args.laws}
    shown = {}
    for kind in figures:
        law = case.model_copy(update=dict(thrust=case.thrust.model_copy(update=dict(kind=kind))))
        for rate in rates:
            key = f"{args.case}|{args.plant}|{kind}|{rate:g}|{z_d:g}"
            if key in done:
                r = done[key]
                f, z_100, saturated, cpu = r["tautness"], r["mean_last_100_s_m"], r["saturated"], r["cpu_s"]
                print(f"{kind:6} {rate:10.2f} (from {args.results}: run at load {r['load']:.1f})")
                figures[kind].append((f, z_100, saturated))
                continue
            start = time.process_time()
            series = run(law, rate)
            cpu = time.process_time() - start
            f = tautness(series, desired)
            t, z = series["time"], series["main_tether_elongation"]
            z_100 = float(z[t > t[-1] - 100.0].mean())
            on = t >= case.thrust.t_on
            saturated = saturated_share(law, series["thrust"][on])
            if args.results is not None:
                record = {"key": key, "plant": args.plant, "law": kind, "rate_deg_s": rate, "desired_m": z_d,
                          "target_m": desired, "tautness": f, "mean_last_100_s_m": z_100, "saturated": saturated,
                          "mean_tension_last_100_s_N": float(series["main_tether_tension"][t > t[-1] - 100.0].mean()),
                          "debris_rate_end_deg_s": float(np.degrees(np.linalg.norm(series["debris_omega_body"][-1]))),
                          "cpu_s": cpu, "load": os.getloadavg()[0]}
                with open(args.results, "a", encoding="utf-8") as handle:
                    handle.write(json.dumps(record) + "\n")
            print(f"{kind:6} {rate:10.2f} {f['engaged_at_s']:7.1f} {f['min_tension_after_engagement_N']:9.3f} "
                  f"{f['slack_after_engagement_s']:8.1f} {f['peak_tension_N']:9.2f} {f['final_elongation_m']:8.4f} "
                  f"{z_100:8.4f} {f['rms_elongation_error_m']:12.4f} {saturated:5.2f} {cpu:7.1f}", flush=True)
            figures[kind].append((f, z_100, saturated))
            if rate == rates[0]:
                shown[kind] = series
    print(f"\n| plant, law | final elongation (m) | mean elongation, last 100 s (m) | RMS error to {desired:.3f} m, "
          f"last 100 s (m) | peak tension (N) | slack after engagement (s) | saturated |")
    print("|---|---|---|---|---|---|---|")
    for kind, rows in figures.items():
        def span(values, fmt):
            return f"{min(values):{fmt}}-{max(values):{fmt}}" if len(values) > 1 else f"{values[0]:{fmt}}"
        print(f"| {args.plant}, {kind} | {span([f['final_elongation_m'] for f, _, _ in rows], '.4f')} | "
              f"{span([z for _, z, _ in rows], '.4f')} | {span([f['rms_elongation_error_m'] for f, _, _ in rows], '.4f')} | "
              f"{span([f['peak_tension_N'] for f, _, _ in rows], '.0f')} | "
              f"{span([f['slack_after_engagement_s'] for f, _, _ in rows], '.1f')} | {span([s for _, _, s in rows], '.2f')} |")
    if args.plots is not None and shown:
        args.plots.mkdir(parents=True, exist_ok=True)
        keys = ("time", "main_tether_tension", "main_tether_elongation", "debris_omega_body", "thrust")
        results.atomic_write_npz(args.plots / f"control_{tag}.npz",
                                 {f"{kind}/{key}": series[key] for kind, series in shown.items() for key in keys})
        plot_control(shown, args.plots / f"control_{tag}.png",
                     f"{args.plant} plant, {rates[0]} deg/s, z_d = {z_d:g} m: " + ", ".join(shown), desired)
        print(f"figure: {args.plots / f'control_{tag}.png'}")


def near_slack(path: Path) -> None:
    """Print per law of a ``control_*.npz`` file (this bench's series) the share of the samples after engagement
    (first T_MT > 1 N) with T_MT < 1 N: on the full net a slack tether still carries the central node's pull (a few
    tenths of a newton), which the tautness figures' T <= 0 does not count; the debris spin at the end (deg/s), the
    elongation's mean and its RMS error to 0.04 m... over the last 100 s (m).

    Parameters
    ----------
    path : Path
        A ``control_<plant>_....npz`` written by this bench.
    """
    with np.load(path) as data:
        for law in dict.fromkeys(key.split("/")[0] for key in data.files):
            t, tension = data[f"{law}/time"], data[f"{law}/main_tether_tension"]
            z, spin = data[f"{law}/main_tether_elongation"], np.linalg.norm(data[f"{law}/debris_omega_body"][-1])
            after = t >= t[np.argmax(tension > 1.0)]
            last = t > t[-1] - 100.0
            print(f"{path.name:40s} {law:6s} T < 1 N after engagement {np.mean(tension[after] < 1.0):.3f}; spin at "
                  f"{t[-1]:.0f} s {np.degrees(spin):.2f} deg/s; z last 100 s mean {z[last].mean():.4f} m")


def saturated_share(case, thrust) -> float:
    """Share of the samples at which the command sits at its saturation: for the ramp its plateau
    (``thrust.max_force``), for the MRAC laws either edge of their actuator range [u_min, u_max]
    (``multibody.control.mrac.actuator_range``: ``mrac.thrust_band`` or ``mrac.min_thrust`` / ``mrac.max_thrust``,
    default -+``thrust.max_force``: the paper's symmetric sat).

    Parameters
    ----------
    case : TowingCase
        The case the run was made with (``thrust.kind`` picks the rule).
    thrust : (k,) float
        Thrust samples after t_on (N).
    """
    f_max = case.thrust.max_force
    if case.thrust.kind == "ramp":
        return float(np.mean(thrust >= f_max * (1 - 1e-9)))
    mt = case.main_tether
    k_abstracted, _ = abstracted_tether(case, [mt.stiffness, mt.damping])
    low, high = actuator_range(case, steady_thrust(k_abstracted, case.mrac.desired_elongation))
    return float(np.mean((thrust >= high - 1e-9 * f_max) | (thrust <= low + 1e-9 * f_max)))


def side_by_side(folder: Path, tag: str, title: str, target: float) -> None:
    """``folder/control_plants_<tag>.png``: the lower-order and the full-net runs of one rate and z_d next to
    each other (riskassess.products.towing_plots.plot_control_plants), from this bench's ``.npz`` files.

    Parameters
    ----------
    folder : Path
        The ``--plots`` folder holding ``control_lower-order_<tag>.npz`` and ``control_full-net_<tag>.npz``.
    tag : str
        ``<rate>deg_s[_zd<z_d>]``.
    title : str
        Figure title.
    target : float
        MRAC target elongation (m).
    """
    plants = {}
    for plant in ("lower-order", "full-net"):
        with np.load(folder / f"control_{plant}_{tag}.npz") as data:
            laws = dict.fromkeys(key.split("/")[0] for key in data.files)
            plants[plant] = {law: {key.split("/")[1]: data[key] for key in data.files if key.startswith(law + "/")}
                             for law in laws}
    path = folder / f"control_plants_{tag}.png"
    plot_control_plants(plants, path, title, target)
    print(f"figure: {path}")


if __name__ == "__main__":
    main()
