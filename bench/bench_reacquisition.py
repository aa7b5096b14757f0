"""The perception stage on one case and seed, with a line per collision frame: what the debris
registration accepted after the net contact, how far from the truth, and what each frame cost.

    python bench/bench_reacquisition.py [--case cases/featured_debris_perception_model_free.toml] [--seed 0]
                                        [--observation 20] [--until 12]

Per collision frame: time (s), accepted (1/0), returns offered, the attitude error (deg) of the
frame's pose against the truth -- also for a pose not accepted (a rejected search result or a chain
frame still pending), marked so -- its tight fitness, free-space violation and unseen-model share,
the chains being followed, the frames a confirmed chain revised (with their errors), whether the
frame hit the search budget, and the frame's CPU time (s). At the end: the stage's wall and CPU
time (``time.process_time``, all threads) with the load average before and after, and the answer's
estimates (docs/perception.md, "Search budget").

``--until`` stops the collision phase's registration after that time (s) by offering no returns
(cheap failed frames): a partial run for a quick look; the estimates are then those of a shortened
free flight.
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np

from perception.shape import rotation_error
from riskassess.cases.impact import validate_case
from riskassess.stages import perceive

KEYS = ("not_observable", "free_flight_after_s", "mass_error_signed_percent", "principal_moments_error_percent",
        "inertia_ratio_error_percent", "search_budget", "tracking", "registration_cpu_ms_median",
        "collision_registration_ms_per_frame", "observation_time_s", "wall_s")


def log_collision_frames(until):
    """Wrap the stage's frame registration: print a line per collision frame."""
    register = perceive._register

    def _register(tracker, frames, t, phase, points, sensor_world, true_rot, true_com, symmetries,
                  target_to_body=np.eye(3), all_returns=None, sensor_to_world=None):
        if phase == 1 and t > until:
            points = points[:0]
        cpu = time.process_time()
        register(tracker, frames, t, phase, points, sensor_world, true_rot, true_com, symmetries, target_to_body,
                 all_returns, sensor_to_world)
        if phase != 1:
            return
        cpu = time.process_time() - cpu
        alignment = tracker.alignments[-1]
        truth = true_rot @ target_to_body.T
        error = np.degrees(rotation_error(alignment.body_to_world[:3, :3], truth, symmetries))
        revised = [f"{frames.time[i]:.1f}:{np.degrees(frames.rotation_error[i]):.1f}" for i in tracker.revised]
        print(f"t {t:5.1f} ok {int(alignment.ok)} n {len(points):6d} err {error:6.1f}{'' if alignment.ok else '*'} "
              f"fit {alignment.tight_fitness:.2f} viol {alignment.free_space_violation:.3f} unseen {alignment.unseen:.3f} "
              f"chains {len(getattr(tracker, '_chains', []))} rev {revised} "
              f"budget {int(getattr(alignment, 'over_budget', False))} cpu {cpu:.2f}", flush=True)

    perceive._register = _register


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", type=Path, default=Path("cases/featured_debris_perception_model_free.toml"))
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--observation", type=float, default=None, help="observation time (s); default the case's")
    parser.add_argument("--until", type=float, default=np.inf, help="register collision frames up to this time (s)")
    args = parser.parse_args()
    raw = tomllib.loads(args.case.read_text())
    raw["perception"]["seed"] = args.seed
    if args.observation is not None:
        raw["perception"]["observation_time"] = args.observation
    case = validate_case(raw, args.case)
    log_collision_frames(args.until)
    print(f"# {args.case} seed {args.seed}; '*' = pose not accepted (error of the rejected or pending pose)", flush=True)
    load_before = os.getloadavg()
    wall, cpu = time.perf_counter(), time.process_time()
    with tempfile.TemporaryDirectory() as out:
        answer = perceive.perceive_case(args.case, Path(out) / "run", case=case)
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    print(f"stage wall {wall:.1f} s, CPU {cpu:.1f} s, load {load_before[0]:.1f} before / {os.getloadavg()[0]:.1f} after")
    for key in KEYS:
        print(key, answer.get(key))


if __name__ == "__main__":
    main()
