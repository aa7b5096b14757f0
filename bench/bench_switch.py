"""The quasi-steady switch on a recorded full-net tow (docs/towing.md, "Switch to the lower-order model").

    python bench/bench_switch.py FULL_RUN [--spin-rate DEG_S] [--switched SWITCHED_RUN]

FULL_RUN is the folder of a full-net ``riskassess tow`` run that did not switch (``towing.npz`` with the main-tether
tension and the net's kinetic energies). Prints, per debris revolution (blocks of 360 / spin rate ending at the last
sample; the spin rate defaults to the run's case, ``case.toml``): the mean, smallest and largest main-tether tension
and the mean kinetic energy of the net relative to the debris and about its own CoM; then when each form of the
criterion (multibody.tow_switch.switch_time) would have switched on these series: sample-wise over 5 s (the form
before this stop), and per revolution over two and three revolutions, with either energy.

``--switched SWITCHED_RUN``: a run of the same case with the switch on (its ``towing.npz`` joins the full-net samples
to the switch and the lower-order ones after it). Checks that the full-net samples before the switch are the same in
both runs, then compares the lower-order continuation with the full-net run over the rest: RMSE of the chaser-debris
vector r_D/C (m) and of the angular velocities (rad/s, body frames), mean and RMSE of the main-tether tension (N),
final distance and spin.
"""
from __future__ import annotations

import argparse
import json
import tomllib
from pathlib import Path

import numpy as np

from multibody.tow_switch import SwitchCriterion, block_means, switch_time


def revolutions(series: dict, period: float) -> None:
    """Print the per-revolution table (markdown rows).

    Parameters
    ----------
    series : dict
        ``time`` (s), ``main_tether_tension`` (N), ``net_kinetic_energy_relative_to_debris`` and
        ``net_internal_kinetic_energy`` (J).
    period : float
        Block length (s): one debris revolution.
    """
    t, tension = series["time"], series["main_tether_tension"]
    relative, internal = series["net_kinetic_energy_relative_to_debris"], series["net_internal_kinetic_energy"]
    n = int((t[-1] - t[0]) // period)
    means = [block_means(t, x, t[-1], period, n)[::-1] for x in (tension, relative, internal)]
    print("| revolution (s) | mean T_MT (N) | T_MT min-max (N) | net energy relative to the debris, mean (J) | "
          "about its own CoM, mean (J) |\n|---|---|---|---|---|")
    for j in range(n):
        a = t[-1] - (n - j) * period
        inside = (t > a + 1e-9) & (t <= a + period + 1e-9)
        print(f"| {a:.1f}-{a + period:.1f} | {means[0][j]:.1f} | {tension[inside].min():.2g}-{tension[inside].max():.0f} | "
              f"{means[1][j]:.1f} | {means[2][j]:.1f} |")


def criteria(series: dict, period: float, earliest: float) -> None:
    """Print when each form of the criterion would switch on the recorded series.

    Parameters
    ----------
    series : dict
        As :func:`revolutions`.
    period : float
        One debris revolution (s).
    earliest : float
        No switch before this time (s).
    """
    t, tension = series["time"], series["main_tether_tension"]
    energies = {"relative to the debris": series["net_kinetic_energy_relative_to_debris"],
                "about the net's CoM": series["net_internal_kinetic_energy"]}
    forms = {"sample-wise, 5 s (before this stop)": (0.0, 5.0),
             "per revolution, two revolutions": (period, 2 * period),
             "per revolution, three revolutions (shipped default)": (period, 3 * period)}
    for label, (averaging, window) in forms.items():
        for name, energy in energies.items():
            c = SwitchCriterion(earliest=earliest, window=window, kinetic_energy_max=0.5, tension_rel_tol=0.2,
                                averaging=averaging)
            when = switch_time(t, energy, tension, c)
            print(f"{label}, energy {name}: " + ("never" if when is None else f"switch at {when:.1f} s"))


def compare(full: dict, switched_folder: Path) -> None:
    """Print the lower-order continuation against the full-net run after the switch.

    Parameters
    ----------
    full : dict
        The full-net run's series.
    switched_folder : Path
        Folder of the run with the switch on.
    """
    joined = dict(np.load(switched_folder / "towing.npz"))
    record = json.loads((switched_folder / "towing.json").read_text())["switch"]
    if record is None:
        print(f"{switched_folder}: the switch did not fire")
        return
    t_switch = record["time_s"]
    before_full, before_joined = full["time"] <= t_switch + 1e-6, joined["time"] <= t_switch + 1e-6
    same = all(np.array_equal(full[k][before_full], joined[k][before_joined])
               for k in ("time", "main_tether_tension", "debris_com_inertial", "chaser_omega_body", "debris_omega_body"))
    after_full, after_joined = ~before_full, ~before_joined
    n = min(after_full.sum(), after_joined.sum())
    a = {k: full[k][after_full][:n] for k in full if np.ndim(full[k]) and len(full[k]) == len(full["time"])}
    b = {k: joined[k][after_joined][:n] for k in a if k in joined}
    print(f"switch at {t_switch:.2f} s (main-tether elongation {record.get('main_tether_elongation_m', float('nan')):.4f} m, "
          f"debris velocity change {record['debris_velocity_change_m_s']:.2e} m/s); full-net samples before it the same "
          f"in both runs: {same}; compared over {n} samples, {a['time'][0]:.1f}-{a['time'][-1]:.1f} s")
    r_full = a["debris_com_inertial"] - a["chaser_com_inertial"]
    r_low = b["debris_com_inertial"] - b["chaser_com_inertial"]
    rms = lambda d: float(np.sqrt(np.mean(np.sum(np.atleast_2d(d.T).T ** 2, axis=-1)))) if d.ndim > 1 else \
        float(np.sqrt(np.mean(d ** 2)))
    print(f"r_D/C RMSE {rms(r_full - r_low):.3f} m; |r_D/C| at the end: full net {np.linalg.norm(r_full[-1]):.3f} m, "
          f"lower-order {np.linalg.norm(r_low[-1]):.3f} m")
    for key in ("chaser_omega_body", "debris_omega_body"):
        print(f"{key} RMSE {rms(a[key] - b[key]):.4f} rad/s; |omega| at the end: full net "
              f"{np.degrees(np.linalg.norm(a[key][-1])):.3f}, lower-order {np.degrees(np.linalg.norm(b[key][-1])):.3f} deg/s")
    ta, tb = a["main_tether_tension"], b["main_tether_tension"]
    print(f"T_MT mean: full net {ta.mean():.1f} N, lower-order {tb.mean():.1f} N; RMSE {rms(ta - tb):.1f} N "
          f"(full-net RMS about its own mean {ta.std():.1f} N)")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("full_run", type=Path)
    parser.add_argument("--spin-rate", type=float, default=None, help="deg/s (default the run's case.toml)")
    parser.add_argument("--switched", type=Path, default=None)
    args = parser.parse_args()
    full = dict(np.load(args.full_run / "towing.npz"))
    case = tomllib.loads((args.full_run / "case.toml").read_text())
    rate = args.spin_rate or case["debris"]["spin_rate_deg_s"]
    period = 360.0 / rate
    print(f"{args.full_run}: {full['time'][0]:.1f}-{full['time'][-1]:.1f} s; one revolution {period:.2f} s")
    revolutions(full, period)
    criteria(full, period, case["thrust"]["t_on"])
    if args.switched is not None:
        compare(full, args.switched)


if __name__ == "__main__":
    main()
