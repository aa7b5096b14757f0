"""How often does the node fit associate a net return with its true thread? A synthetic net (7 x 7 nodes, 0.5 m
mesh as the featured case's, 4 mm threads, bulged) seen 2-3 m ahead by the paper's LiDAR with 2 cm range noise; the
node fit (`perception.net_tracking.fit_net_nodes`, the stage's prior, rim held at the true rim as the stage holds
it at the rod tips) started from a prediction slid in the net's plane by a fraction of a mesh (the slip percep20
measured in the stage: the carried prediction keeps a grid one mesh off). Printed per slide: the share of the
returns within 1 cm of a true thread that the fit's last association puts on that thread, and the seen nodes'
rms error.

    python bench/perception_net_association.py [--seeds 0 1 2 3 4]
"""
from __future__ import annotations

import argparse

import numpy as np

from multibody.net import square_grid_threads
from perception.lidar import LidarSpec, cast
from perception.net_tracking import NetPrior, fit_net_nodes, nearest_segments, thread_mesh

SIDE, N = 3.0, 7          # m, nodes per side: 0.5 m mesh, the featured net's
RADIUS = 0.002            # m, thread radius (Tang et al. 2023 Table 2)
DEG = np.pi / 180
LIDAR = LidarSpec(150 * DEG, 30 * DEG, 0.09 * DEG, 0.12 * DEG, 0.02, 10.0)   # the paper's Table 3


def net(distance, bulge, slide=np.zeros(2)):
    """Node positions (N*N, 3), sensor frame (m): the net plane at ``distance`` along +x, bulged by ``bulge``
    at its centre, the interior slid in its plane by ``slide`` (m; the rim stays)."""
    u, v = np.meshgrid(np.linspace(-SIDE / 2, SIDE / 2, N), np.linspace(-SIDE / 2, SIDE / 2, N), indexing="ij")
    x = distance + bulge * np.cos(np.pi * u / SIDE) * np.cos(np.pi * v / SIDE)
    positions = np.c_[x.ravel(), u.ravel(), v.ravel()]
    interior = ~rim_mask(positions)
    positions[interior, 1:] += slide
    return positions


def rim_mask(positions) -> np.ndarray:
    edge = SIDE / 2 - 1e-9
    return (np.abs(positions[:, 1]) > edge) | (np.abs(positions[:, 2]) > edge)


def matched_share(seed, slide_m, lengths=False, iterations=4) -> tuple[float, float]:
    """Share of the true-thread returns associated with their own thread by the fit, and the seen nodes' rms
    error (m), for a prediction slid by ``slide_m`` (m) along the net's rows; ``lengths``: the fit given the
    threads' rest lengths (the truth's, a taut net)."""
    threads = square_grid_threads(N)
    truth = net(2.5, 0.3)
    predicted = net(2.5, 0.0, np.array([slide_m, 0.0]))
    scan = cast(LIDAR, [thread_mesh(truth, threads, RADIUS)], 0.0, np.random.default_rng(seed)).points_sensor
    true_thread, _, distance = nearest_segments(scan, truth, threads)
    on_net = distance < 0.01 + 3 * LIDAR.range_noise      # every return of a thread (noise 2 cm along the ray)
    rim = np.flatnonzero(rim_mask(truth))
    rest = np.linalg.norm(truth[threads[:, 1]] - truth[threads[:, 0]], axis=1) if lengths else None
    fit = fit_net_nodes(scan, predicted, threads, NetPrior(point=0.02), anchors=(rim, truth[rim]), iterations=iterations,
                        rest_lengths=rest)
    fitted_thread, _, _ = nearest_segments(scan[on_net], fit.positions_world, threads)
    error = np.linalg.norm(fit.positions_world - truth, axis=1)[fit.observed]
    return float(np.mean(fitted_thread == true_thread[on_net])), float(np.sqrt(np.mean(error**2)))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[0, 1, 2, 3, 4])
    parser.add_argument("--lengths", action="store_true", help="give the fit the threads' rest lengths")
    parser.add_argument("--iterations", type=int, default=4, help="the fit's re-associations (the stage's: 4)")
    args = parser.parse_args()
    for slide in (0.0, 0.1, 0.2, 0.25, 0.3, 0.5):
        rows = [matched_share(seed, slide, args.lengths, args.iterations) for seed in args.seeds]
        shares, errors = np.array(rows).T
        print(f"prediction slid {slide:.2f} m ({slide / 0.5:.1f} mesh): returns on their true thread "
              f"{100 * shares.min():.0f}-{100 * shares.max():.0f} % (mean {100 * shares.mean():.0f} %), seen nodes "
              f"{100 * errors.min():.1f}-{100 * errors.max():.1f} cm rms off (seeds {args.seeds})", flush=True)


if __name__ == "__main__":
    main()
