"""Which cut-off? The joints' load spectra and the filtered peaks against the cut-off, offline, from runs recorded every step.

    python3 bench/load_filter_sweep.py CASE CACHE [--cutoffs 1,2,3,5,10,20] [--orders 2,4] [--window 0.6]

CACHE holds bench_peak_convergence runs recorded at one sample a step (``--output-rate 10000`` with a 1e-4 s step;
step / 2 is then sampled every other step), one replica per variant. Prints, from the baseline, each joint's share of
the load variance (t >= 0.25 s) in frequency bands, then for each order and cut-off each location's peak in the
first ``--window`` s (before the replicas part) through :mod:`multibody.load_filter` (the same filter the run applies
every step, here applied to the every-step samples) and each variant's change against the baseline.
"""
from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

import numpy as np

from multibody.load_filter import butterworth_sections, filter_signal
from riskassess.cases.impact import validate_case
from riskassess.models.impact import model_inputs, weak_locations
from structures.weak_location import judged_demands

BANDS_HZ = ((0, 2), (2, 10), (10, 20), (20, 100), (100, 500), (500, 5000))


def band_shares(values, interval: float) -> tuple[list, float]:
    """Share of each of :data:`BANDS_HZ` in the variance of ``values`` (one-sided power spectrum), and the frequency
    (Hz) of the strongest line."""
    x = values - values.mean()
    power, freq = np.abs(np.fft.rfft(x)) ** 2, np.fft.rfftfreq(x.size, interval)
    return ([power[(freq >= lo) & (freq < hi)].sum() / power.sum() for lo, hi in BANDS_HZ],
            float(freq[1:][np.argmax(power[1:])]))


def filtered(loads, cutoff_hz: float, order: int, interval: float):
    """(k, nj, 3) loads through the Butterworth of ``order`` at ``cutoff_hz``, axis by axis."""
    sections = butterworth_sections(cutoff_hz, interval, order)
    out = np.empty_like(loads)
    for j in range(loads.shape[1]):
        for d in range(3):
            out[:, j, d] = filter_signal(sections, np.ascontiguousarray(loads[:, j, d]))
    return out


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case")
    parser.add_argument("cache")
    parser.add_argument("--cutoffs", default="1,2,3,5,10,20")
    parser.add_argument("--orders", default="2,4")
    parser.add_argument("--window", type=float, default=0.6, help="end of the early (deterministic) window (s)")
    args = parser.parse_args()
    case_path = Path(args.case).resolve()
    case = validate_case(tomllib.loads(case_path.read_text().replace('release = "low"', 'release = "never"', 1)),
                         case_path)
    assembly = model_inputs(case, case_path.parent).assembly
    locations = weak_locations(case, assembly)
    runs = {}
    for path in sorted(p for p in Path(args.cache).glob("*-0.npz")):
        with np.load(path) as data:
            runs[path.stem.rsplit("-", 1)[0]] = dict(data)
    base = runs["baseline"]
    t = base["time"]
    interval = float(np.median(np.diff(t)))
    late = t >= 0.25
    print(f"share of the load variance per band, t >= 0.25 s, baseline sampled at {1 / interval:.0f} Hz")
    for j, joint in enumerate(assembly.joints):
        for kind in ("moment", "force"):
            for axis in range(3):
                shares, strongest = band_shares(base[kind][late, j, axis], interval)
                label = f"h{axis + 1}" if kind == "moment" else "xyz"[axis]
                print(f"  {joint.name:18s} {kind} {label}: strongest {strongest:7.1f} Hz; "
                      + " ".join(f"{lo}-{hi} Hz {s:5.1%}" for (lo, hi), s in zip(BANDS_HZ, shares)))
    for order in (int(o) for o in args.orders.split(",")):
        for cutoff in (float(c) for c in args.cutoffs.split(",")):
            print(f"order {order}, {cutoff:g} Hz: peak in t < {args.window:g} s, baseline and change per variant")
            peaks = {}
            for variant, run in runs.items():
                dt = float(np.median(np.diff(run["time"])))
                force, moment = filtered(run["force"], cutoff, order, dt), filtered(run["moment"], cutoff, order, dt)
                early = run["time"] < args.window
                for loc in locations:
                    demand = judged_demands(loc, run["time"], force[:, loc.joint], moment[:, loc.joint])
                    for criterion in loc.criteria():
                        peaks.setdefault(f"{loc.name}/{criterion}", {})[variant] = float(demand[criterion][early].max())
            for key, values in peaks.items():
                b = values["baseline"]
                print(f"  {key:34s} {b:10.4g} | " + " | ".join(f"{v}: {x / b - 1:+.1%}" for v, x in values.items()
                                                              if v != "baseline"))


if __name__ == "__main__":
    main()
