"""Perception benchmark on Tang et al. (2023)'s scenario, pre-collision stage.

Runs the case's free tumble in Exudyn, ray-casts the C-Fans-256-like LiDAR at 10 Hz,
registers every scan with Open3D (frame-to-model, known shape), fits the CoM line and the
torque-free motion, and prints per-frame registration time and rotation error, CoM error and
inertia-ratio error against the truth, for growing observation times.

    python bench/bench_perception.py [--time 60] [--case cases/tang2023_debris_perception.toml]

Not yet covered (issue 6 still open): the collision stage (net-node tracking, mass and C
from momentum).
"""
from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.spatial.transform import Rotation

from multibody.free_motion import free_motion
from perception.euler_poinsot import TorqueFreeFit, normalized_inertia_linear, principal_frame
from perception.lidar import LidarSpec, cast
from perception.motion import center_of_mass_line, rates_from_attitudes
from perception.registration import DebrisTracker
from riskassess.assemble import model_inputs
from riskassess.case import load_case


def sensor_frame(lidar) -> np.ndarray:
    """sensor->world rotation from the case's boresight and up vectors."""
    x = np.asarray(lidar.boresight_lvlh, float)
    x /= np.linalg.norm(x)
    z = np.asarray(lidar.up_lvlh, float) - (np.asarray(lidar.up_lvlh, float) @ x) * x
    z /= np.linalg.norm(z)
    return np.c_[x, np.cross(z, x), z]


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default="cases/tang2023_debris_perception.toml")
    parser.add_argument("--time", type=float, default=None, help="observation time (s); default: the case's")
    args = parser.parse_args()
    case = load_case(args.case)
    p = case.perception
    duration = args.time or p.observation_time
    inputs = model_inputs(case)
    debris = [b for k, b in enumerate(inputs.assembly.bodies) if k != inputs.assembly.chaser][0]
    lidar = p.lidar
    spec = LidarSpec(lidar.fov_azimuth, lidar.fov_elevation, lidar.resolution_azimuth,
                     lidar.resolution_elevation, lidar.range_noise, lidar.rate, lidar.max_range)
    times = np.arange(int(round(duration * lidar.rate)) + 1) / lidar.rate
    start = time.perf_counter()
    states = free_motion([debris], [], times)
    print(f"Exudyn free tumble {duration:g} s: {time.perf_counter() - start:.2f} s wall")

    direction = np.asarray(case.launch.direction, float) / np.linalg.norm(case.launch.direction)
    sensor = debris.com_lvlh - p.hold_distance * direction
    sensor_to_world = sensor_frame(lidar)
    mesh = debris.meshes_body[0]
    tracker = DebrisTracker(p.registration.voxel, p.registration.max_correspondence, p.registration.model_frames,
                            model_points_body=mesh.sample(20000))
    rng = np.random.default_rng(p.seed)
    cast_time, errors, registration = 0.0, [], []
    for k, t in enumerate(times):
        rot, com = states["body_to_lvlh"][k, 0], states["body_com_lvlh"][k, 0]
        tic = time.perf_counter()
        vertices = (mesh.vertices @ rot.T + com - sensor) @ sensor_to_world
        scan = cast(spec, [(vertices, mesh.faces)], t, rng)
        cast_time += time.perf_counter() - tic
        alignment = tracker.update(t, scan.points_sensor @ sensor_to_world.T + sensor, sensor)
        registration.append(alignment.seconds)
        symmetric = [rot @ np.diag(d) for d in ([1, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1])]
        errors.append(min(Rotation.from_matrix(alignment.body_to_world[:3, :3] @ s.T).magnitude() for s in symmetric))
    errors = np.degrees(errors)
    ok = np.array([a.ok for a in tracker.alignments])
    print(f"frames {len(times)}, checked ok {ok.mean() * 100:.1f} %, ray casting {1e3 * cast_time / len(times):.1f} ms/frame")
    print(f"registration: first frame (global search) {1e3 * registration[0]:.0f} ms, then "
          f"{1e3 * np.mean(registration[1:]):.1f} ms/frame mean, {1e3 * np.percentile(registration[1:], 95):.1f} ms p95")
    print(f"rotation error: mean {errors.mean():.2f} deg, p95 {np.percentile(errors, 95):.2f} deg, max {errors.max():.2f} deg")

    truth_moments = np.sort(np.linalg.eigvalsh(debris.inertia_body))[::-1]
    truth_ratios = truth_moments / truth_moments[-1]
    poses = np.array([a.body_to_world for a in tracker.alignments])
    for span in (10.0, 20.0, 30.0, 60.0, 120.0, 300.0):
        if span > duration + 1e-9:
            break
        use = (times <= span + 1e-9) & ok
        tic = time.perf_counter()
        line = center_of_mass_line(times[use], poses[use, :3, :3], poses[use, :3, 3])
        com_true = states["body_com_lvlh"][use, 0]
        com_error = np.linalg.norm(line.position_world(times[use]) - com_true, axis=1).mean()
        attitudes = Rotation.from_matrix(poses[use, :3, :3])
        omega, omega_dot = rates_from_attitudes(times[use], attitudes)
        moments0, axes0 = principal_frame(normalized_inertia_linear(omega, omega_dot))
        weights = []
        for a in np.array(tracker.alignments)[use]:
            info = a.information if np.linalg.matrix_rank(a.information) == 6 else np.eye(6) * 1e4
            cov = np.linalg.inv(info)[:3, :3]
            weights.append(np.linalg.cholesky(np.linalg.inv(cov)).T)
        weights = np.array(weights)
        weights[0] = np.mean(weights[1:], axis=0)
        fit = TorqueFreeFit().fit(times[use], attitudes, weights, omega[0], moments0, axes0)
        ratio_error = (fit.moments_[:2] / truth_ratios[:2] - 1) * 100
        print(f"{span:5.0f} s: CoM error {1e3 * com_error:.1f} mm (scale {0.9:.1f} m: {com_error / 0.9 * 100:.2f} %), "
              f"linear start J1/J2 err {((moments0[:2] / truth_ratios[:2] - 1) * 100).round(2)} %, "
              f"fit J1/J2 err {ratio_error.round(3)} % (1 sigma {(fit.moments_std_ / truth_ratios[:2] * 100).round(3)} %), "
              f"weighted rms {fit.residual_rms_:.2f}, {time.perf_counter() - tic:.1f} s")


if __name__ == "__main__":
    main()
