"""Keep what the perception stage's momentum step was made of, for experiments offline
(bench/perception_substitution.py): the tracker's alignments, the frames' truth, the net track, the
collision run's record and design, the fits before and after and the origin.

    nice -n 10 python bench/bench_perception.py --case cases/featured_debris_perception_model_free.toml \
        --models none --seeds 0 1 2 3 4 --save DIR --capture runs/captures

writes ``runs/captures/<model>_obs<observation>_seed<N>.pkl`` (pickle of a dict) beside each answer. The
pickles are a few MB each and not committed (runs/ is ignored).
"""
from __future__ import annotations

import os
import pickle

import numpy as np

from riskassess.stages import perceive


def capture_hooks(store: dict):
    """Wrap the stage's observation, collision, fit, net-momentum and momentum-step calls so that their
    inputs land in ``store`` (cleared by the caller between runs). The wrapped calls return what the
    stage's own return: the answer does not change."""
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
        keep_collision_inputs(store, tracker)
        track = collide(scene, tracker, frames, *args, **kwargs)
        store["candidate_log"] = tracker.candidate_log
        store["frames"] = {name: list(getattr(frames, name)) for name in
                           ("time", "phase", "n_points", "rotation_error", "true_target_to_world", "true_com_world")}
        store["truth"] = scene.truth
        return track

    def fit_free_motion(tracker, indices, times, *args):
        motion = fit(tracker, indices, times, *args)
        store.setdefault("fits", []).append({"indices": list(indices), "args": args, "motion": motion})
        store["alignments"], store["model_points_body"] = tracker.alignments, tracker.model_points_body
        return motion

    def others_momentum_after(assembly, recorder, track, frame_times, origin):
        store.update(assembly=_assembly_parts(assembly), series=dict(recorder.series), net=dict(recorder.net),
                     track=track, origin=origin)
        return others_after(assembly, recorder, track, frame_times, origin)

    def momentum_step(before, after, others_before, others_after_, origin):
        store.update(others_before=others_before, others_after=others_after_)
        return step(before, after, others_before, others_after_, origin)

    perceive.fit_free_motion = fit_free_motion
    perceive.observe_tumble = observe_tumble
    perceive.observe_tumble_model_free = observe_tumble_model_free
    perceive.observe_collision = observe_collision
    perceive.others_momentum_after = others_momentum_after
    perceive.momentum_step = momentum_step


def keep_collision_inputs(store: dict, tracker) -> None:
    """The tracker as the collision phase starts (its settings, map and alignments) and, through a
    wrapper of this tracker's ``update``, every collision frame's registration inputs, into ``store``;
    the tracker's candidate log switched on. Enough to replay the collision phase's registration offline
    (bench/perception_reacquire_candidates.py); the wrapped ``update`` returns what the tracker's does."""
    store["collision_tracker"] = {
        "settings": {"voxel": tracker.voxel, "max_correspondence": tracker.max_correspondence,
                     "model_frames": tracker.model_frames, "seed": tracker.seed,
                     "free_space_lateral_bins": tracker.free_space_lateral_bins,
                     "search_cpu_per_frame": tracker.search_cpu_per_frame,
                     "search_cpu_per_run": tracker.search_cpu_per_run, "continuity_turn": tracker.continuity_turn,
                     "chain_missed_frames": tracker.chain_missed_frames, "grow_map": tracker.grow_map},
        "map_points_body": np.array(tracker.model_points_body), "map_normals_body": np.array(tracker._model_normals),
        "alignments": list(tracker.alignments), "search_cpu_spent": tracker.search_cpu_spent}
    updates = store["collision_updates"] = []
    tracker.candidate_log = []
    update = tracker.update

    def recorded_update(time_s, points_world, sensor_world, **kwargs):
        updates.append({"time": time_s, "points_world": np.array(points_world), "sensor_world": np.array(sensor_world),
                        "field_of_view": tracker.field_of_view, "ray_spacing": tracker.ray_spacing,
                        **{key: (None if value is None else np.array(value)) for key, value in kwargs.items()}})
        return update(time_s, points_world, sensor_world, **kwargs)

    tracker.update = recorded_update


def _assembly_parts(assembly):
    """What the momentum step reads of the collision run's assembly (chaser design and launch state,
    net masses, launch positions, velocities and threads), as plain arrays."""
    chaser = assembly.bodies[assembly.chaser]
    return {"chaser_index": assembly.chaser,
            "chaser": {name: getattr(chaser, name) for name in
                       ("mass", "inertia_body", "com_lvlh", "velocity_lvlh", "body_to_lvlh", "omega_body")},
            "net_masses": assembly.net.masses, "net_positions": assembly.net.positions,
            "net_velocity": assembly.net_velocity, "net_threads": assembly.net.threads}


def write_capture(path, store: dict, answer: dict) -> None:
    """Pickle what ``store`` holds (what pickles; the rest is named on stdout) and the answer, atomically."""
    kept = {"answer": answer}
    for key, value in store.items():
        try:
            pickle.dumps(value)
            kept[key] = value
        except Exception as exc:   # noqa: BLE001 -- keep what pickles, say what did not
            print(f"{path}: {key} not kept ({exc})", flush=True)
    path.parent.mkdir(parents=True, exist_ok=True)
    temporary = path.with_suffix(".tmp")
    with open(temporary, "wb") as f:
        pickle.dump(kept, f)
    os.replace(temporary, path)


def main() -> None:
    """``python3 bench/perception_capture.py [bench_perception.py's arguments]``: bench/bench_perception.py with
    ``--capture runs/captures`` unless a ``--capture`` folder is given (the module doc)."""
    import sys

    import bench_perception

    if "--capture" not in sys.argv[1:]:
        sys.argv += ["--capture", "runs/captures"]
    bench_perception.main()


if __name__ == "__main__":
    main()
