"""The thread contact's candidate pairs (multibody/segment_candidates.py): CPU time of each piece of the broad phase
per evaluation, in compiled loops (no Python call per evaluation), on a scene of the 15 x 15 capture's size.

    python3 bench/bench_segment_candidates.py [--repeat 200000] [--seed 0]

Scene: 229 nodes and 420 threads (random node pairs) in a 3 m cube, three boxes on three bodies (a 1 x 0.6 x 0.4 m
box, a 1 x 1 x 0.05 m plate, a 0.8 m cube), five bodies; step 1e-4 s. Prints us per call of: the speed bounds and
bounding spheres (``segment_pairs._near_shapes``), the test that the list still holds (``_candidates_hold``), and a
rebuild (skin 0: a build at every call), with the pairs listed, and the load average.
"""
from __future__ import annotations

import argparse
import os
import time

import numpy as np
from numba import njit

from multibody.contact_segment import segment_buffers
from multibody.kernel import BodyStates, ShapeArrays
from multibody.segment_candidates import _candidates_hold, refresh_candidates
from multibody.segment_pairs import _near_shapes


@njit
def _near_shapes_loop(k, x, v, force, mass, lag, seg, states, shapes, step):
    for _ in range(k):
        _near_shapes(x, v, force, mass, lag, seg, states, shapes, step)


@njit
def _hold_loop(k, x, seg, states, shapes, step):
    held = 0
    for _ in range(k):
        held += _candidates_hold(x, seg, states, shapes, step)
    return held


@njit
def _refresh_loop(k, x, threads, radius, seg, states, shapes, step):
    for _ in range(k):
        refresh_candidates(x, threads, radius, seg, states, shapes, step)


def scene(rng):
    """(x, v, threads, radius, states, shapes) of the module doc's scene."""
    n, m, nb = 229, 420, 5
    x, v = rng.uniform(-1.2, 1.8, (3, n)), rng.uniform(-1.0, 1.0, (3, n))
    threads = np.stack([rng.integers(0, n, m), rng.integers(0, n, m)], 1).astype(np.int64)
    box_min = np.array([[-0.5, -0.3, -0.2], [0.6, -0.5, -0.025], [-0.4, -0.4, -0.4]])
    box_max = np.array([[0.5, 0.3, 0.2], [1.6, 0.5, 0.025], [0.4, 0.4, 0.4]])
    shapes = ShapeArrays(np.zeros((0, 3, 3)), np.zeros((0, 3)), np.array([0, 1, 2], np.int64),
                         np.zeros((3, 2), np.int64), box_min, box_max, np.ones(3, np.int64))
    attitude = np.stack([np.linalg.qr(rng.normal(size=(3, 3)))[0] for _ in range(nb)])
    states = BodyStates(attitude, rng.uniform(-1.0, 1.0, (nb, 3)), np.zeros((nb, 3)), np.zeros((nb, 3)), attitude,
                        np.zeros((nb, 3)))
    return x, v, threads, np.full(n, 0.001), states, shapes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=200000)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    x, v, threads, radius, states, shapes = scene(np.random.default_rng(args.seed))
    n, step = x.shape[1], 1e-4
    seg = segment_buffers(len(threads), n, 3, states.com_lvlh.shape[0], True)
    force, mass, lag = np.zeros((3, n)), np.ones(n), np.zeros((3, n))
    _near_shapes(x, v, force, mass, lag, seg, states, shapes, step)
    refresh_candidates(x, threads, radius, seg, states, shapes, step)

    def per_call(loop, *loop_args):
        loop(10, *loop_args)
        start = time.process_time()
        loop(args.repeat, *loop_args)
        return 1e6 * (time.process_time() - start) / args.repeat

    print(f"load {os.getloadavg()[0]:.2f}; us per call (CPU), {args.repeat} calls in a compiled loop")
    near = per_call(_near_shapes_loop, x, v, force, mass, lag, seg, states, shapes, step)
    print(f"speed bounds and bounding spheres (_near_shapes): {near:.3f}")
    print(f"the list still holds (_candidates_hold): {per_call(_hold_loop, x, seg, states, shapes, step):.3f}")
    seg.candidate_scalar[0] = 0.0
    build = per_call(_refresh_loop, x, threads, radius, seg, states, shapes, step)
    print(f"a build (skin 0: every call): {build:.3f}, {seg.candidate_count[0]} of {3 * len(threads)} pairs listed; "
          f"load {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
