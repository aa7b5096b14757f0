"""Where the net's closing loop lies against the debris, from a kept run folder's net snapshots:

    python3 bench/bench_closing_loop_geometry.py DIR T [T ...] [--array solar_array --body main_body]

At each time T (s; the nearest net snapshot, 50 Hz): the loop's length (m, the sum of its 12 segments) and each
segment's smallest distance (m) to the box of ``--array`` and of ``--body`` (the segment sampled at 60 points, the box
in its body frame from the recorded attitude and CoM). The boxes are the envisat_small mock-up's (the solar array
5.0 x 0.05 x 14.3 m, the main body 3.375 x 3.75 x 7.875 m, each centred on its body's CoM); segments in
:func:`multibody.closing.closing_threads` order.
"""
from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from multibody.closing import closing_threads

#: Half extents (m) of the envisat_small mock-up's boxes, body frame, centred on the body's CoM (its case file).
HALF_EXTENTS = {"solar_array": np.array([5.0, 0.05, 14.3]) / 2, "main_body": np.array([3.375, 3.75, 7.875]) / 2}
SAMPLES = 60   # points per segment


def segment_box_distance(a_lvlh, b_lvlh, com_lvlh, body_to_lvlh, half) -> float:
    """Smallest distance (m) of the segment a-b (LVLH, m) to a box of half extents ``half`` (m) centred at ``com_lvlh``."""
    points = a_lvlh + np.linspace(0.0, 1.0, SAMPLES)[:, None] * (b_lvlh - a_lvlh)
    points_body = (points - com_lvlh) @ body_to_lvlh
    return float(np.linalg.norm(np.maximum(np.abs(points_body) - half, 0.0), axis=1).min())


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("folder", type=Path)
    parser.add_argument("times", nargs="+", type=float)
    parser.add_argument("--array", default="solar_array")
    parser.add_argument("--body", default="main_body")
    args = parser.parse_args(argv)
    net, series = np.load(args.folder / "net.npz"), np.load(args.folder / "timeseries.npz")
    names = [str(n) for n in series["body_names"]]
    n = int(round(np.sqrt(len(net["masses"]) - int(net["n_bullets"]))))
    threads = closing_threads(n)
    for t_query in args.times:
        k = int(np.argmin(np.abs(net["time"] - t_query)))
        t, x_lvlh = float(net["time"][k]), net["positions_lvlh"][k]
        j = int(np.argmin(np.abs(series["time"] - t)))
        length = np.linalg.norm(x_lvlh[threads[:, 1]] - x_lvlh[threads[:, 0]], axis=1).sum()
        text = []
        for name in (args.array, args.body):
            b = names.index(name)
            distances = [segment_box_distance(x_lvlh[p], x_lvlh[q], series["body_com_lvlh"][j, b],
                                              series["body_to_lvlh"][j, b], HALF_EXTENTS[name]) for p, q in threads]
            text.append(f"to {name} {np.round(distances, 2).tolist()}")
        print(f"t={t:.2f} loop length {length:.1f} m; segment distance (m) " + "; ".join(text))


if __name__ == "__main__":
    main()
