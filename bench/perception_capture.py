"""Run the perception stage on one seed and keep what its momentum step was made of, for experiments
offline (bench/perception_substitution.py): the tracker's alignments, the frames' truth, the net track,
the collision run's record and assembly, the fits before and after and the origin.

    nice -n 10 python bench/perception_capture.py --case cases/featured_debris_perception_model_free.toml \
        --seeds 1 3 --out bench/results/capture

writes ``OUT/<model>_seed<N>.pkl`` (pickle of a dict) and the stage's answer beside it
(``OUT/<model>_seed<N>.json``); a seed whose file exists is skipped. The collision run is simulated once
for all seeds (bench_perception.reuse_collision_runs). The pickles are large (~100 MB) and not committed.
"""
from __future__ import annotations

import argparse
import os
import pickle
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_perception import _save, reuse_collision_runs  # noqa: E402

from riskassess.cases.impact import validate_case  # noqa: E402
from riskassess.stages import perceive  # noqa: E402


def capture_hooks(store: dict):
    """Wrap the stage's fit, net-momentum and momentum-step calls so their inputs land in ``store``."""
    fit, others_after, step = perceive.fit_free_motion, perceive.others_momentum_after, perceive.momentum_step
    observe, collide = perceive.observe_tumble_model_free, perceive.observe_collision
    observe_known = perceive.observe_tumble

    def observe_tumble(scene, tracker, frames, *args, **kwargs):
        state, check = observe_known(scene, tracker, frames, *args, **kwargs)
        store.update(state_at_zero=state, target_to_body=np.eye(4))   # the mesh's frame is B
        return state, check

    def observe_tumble_model_free(scene, frames, rng, progress=None):
        state, tracker, target_to_body = observe(scene, frames, rng, progress)
        store.update(state_at_zero=state, target_to_body=target_to_body)
        return state, tracker, target_to_body

    def observe_collision(scene, tracker, frames, *args, **kwargs):
        track = collide(scene, tracker, frames, *args, **kwargs)
        store["frames"] = {name: list(getattr(frames, name)) for name in
                           ("time", "phase", "n_points", "rotation_error", "true_target_to_world", "true_com_world")}
        return track

    def fit_free_motion(tracker, indices, times, *args):
        motion = fit(tracker, indices, times, *args)
        store.setdefault("fits", []).append({"indices": list(indices), "args": args, "motion": motion})
        store["tracker"] = tracker
        return motion

    def others_momentum_after(assembly, recorder, track, frame_times, origin):
        store.update(assembly=assembly, series=dict(recorder.series), net=dict(recorder.net), track=track, origin=origin)
        return others_after(assembly, recorder, track, frame_times, origin)

    def momentum_step(before, after, others_before, others_after_, origin):
        store.update(others_before=others_before, others_after=others_after_)
        return step(before, after, others_before, others_after_, origin)

    perceive.fit_free_motion = fit_free_motion
    perceive.observe_tumble_model_free = observe_tumble_model_free
    perceive.observe_tumble = observe_tumble
    perceive.observe_collision = observe_collision
    perceive.others_momentum_after = others_momentum_after
    perceive.momentum_step = momentum_step


def _assembly_parts(assembly):
    """What the momentum step reads of the collision run's assembly (chaser design and launch state,
    net masses, launch positions, velocities and threads), as plain arrays."""
    if assembly is None:
        return None
    chaser = assembly.bodies[assembly.chaser]
    return {"chaser_index": assembly.chaser,
            "chaser": {name: getattr(chaser, name) for name in
                       ("mass", "inertia_body", "com_lvlh", "velocity_lvlh", "body_to_lvlh", "omega_body")},
            "net_masses": assembly.net.masses, "net_positions": assembly.net.positions,
            "net_velocity": assembly.net_velocity, "net_threads": assembly.net.threads}


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default="cases/featured_debris_perception_model_free.toml")
    parser.add_argument("--seeds", type=int, nargs="+", default=[1])
    parser.add_argument("--model", choices=("known", "none"), default="none")
    parser.add_argument("--observation", type=float, default=None)
    parser.add_argument("--out", type=Path, required=True)
    args = parser.parse_args()
    reuse_collision_runs()
    path = Path(args.case)
    raw = tomllib.loads(path.read_text())
    args.out.mkdir(parents=True, exist_ok=True)
    store: dict = {}
    capture_hooks(store)
    for seed in args.seeds:
        target = args.out / f"{args.model}_seed{seed}.pkl"
        if target.exists():
            print(f"seed {seed}: {target} exists, skipped", flush=True)
            continue
        raw["perception"].update(seed=seed, model=args.model)
        if args.observation:
            raw["perception"]["observation_time"] = args.observation
        store.clear()
        cpu, load = time.process_time(), os.getloadavg()[0]
        case = validate_case(raw, path)
        with tempfile.TemporaryDirectory() as out:
            answer = perceive.perceive_case(path, out, case=case)
        answer["bench_cpu_s"], answer["bench_load"] = time.process_time() - cpu, [load, os.getloadavg()[0]]
        answer["bench_seed"], answer["bench_observation_s"] = seed, raw["perception"]["observation_time"]
        tracker = store.pop("tracker", None)
        store["alignments"] = tracker.alignments if tracker is not None else None
        store["model_points_body"] = tracker.model_points_body if tracker is not None else None
        scene = perceive.Scene.from_case(case, path.parent, str(path))
        store["truth"] = scene.truth
        store["assembly"] = _assembly_parts(store.get("assembly"))
        store["answer"] = answer
        kept = {}
        for key, value in store.items():
            try:
                pickle.dumps(value)
                kept[key] = value
            except Exception as exc:   # noqa: BLE001 -- keep what pickles, say what did not
                print(f"seed {seed}: {key} not kept ({exc})", flush=True)
        with open(target.with_suffix(".tmp"), "wb") as f:
            pickle.dump(kept, f)
        os.replace(target.with_suffix(".tmp"), target)
        _save(target.with_suffix(".json"), answer)
        print(f"seed {seed}: {answer['bench_cpu_s']:.0f} s CPU, load {answer['bench_load']}, moments "
              f"{answer.get('principal_moments_error_percent')}, {answer['not_observable']}", flush=True)


if __name__ == "__main__":
    main()
