"""Wrong-model benchmark (issue 26, item 2): the model check of `riskassess perceive` on the intact and
the damaged featured debris, and the model-free track it falls back to. Observation phase only (no
collision run): the figures of the check, the fit of the tumble and their errors against the real debris.

    python bench/bench_model_check.py [--variants intact damaged bent antenna com] [--seeds 0 1]
                                      [--observation 20]

Variants of cases/featured_debris_perception_damaged.toml: 'damaged' as shipped (array bent 15 deg,
antenna lost, CoM 5 cm off), 'bent' / 'antenna' / 'com' one damage alone, 'intact' no damage. Times are
CPU (process) seconds, the machine being shared.
"""
from __future__ import annotations

import argparse
import time
import tomllib
from pathlib import Path

import numpy as np
import open3d as o3d

from perception.free_flight import fit_free_motion
from perception.motion import NotObservable
from perception.registration import DebrisTracker, known_shape_model
from perception.shape import half_turn_symmetry_transforms
from riskassess.cases.impact import validate_case
from riskassess.stages import perceive

CASE = Path(__file__).parents[1] / "cases" / "featured_debris_perception_damaged.toml"


def variant_raw(variant: str, observation: float, seed: int) -> dict:
    """The shipped damaged case's content with one variant of its damage (module docstring)."""
    raw = tomllib.loads(CASE.read_text())
    raw["perception"].update(observation_time=observation, seed=seed)
    damage = raw["perception"]["truth_damage"]
    if variant == "intact":
        del raw["perception"]["truth_damage"]
    elif variant != "damaged":
        keep = {"bent": "bends", "antenna": "missing_shapes", "com": "center_of_mass_shift"}[variant]
        for key, empty in (("bends", []), ("missing_shapes", []), ("center_of_mass_shift", [0.0, 0.0, 0.0])):
            if key != keep:
                damage[key] = empty
    return raw


def observe(variant: str, observation: float, seed: int) -> dict:
    """The stage's observation phase with the model (and its fall back): figures as a dict."""
    case = validate_case(variant_raw(variant, observation, seed), CASE)
    scene = perceive.Scene.from_case(case, CASE.parent)
    p = case.perception
    reg = p.registration
    cpu = time.process_time()
    with o3d.utility.VerbosityContextManager(o3d.utility.VerbosityLevel.Error):
        transforms = half_turn_symmetry_transforms(scene.model_mesh_target, 0.5 * reg.voxel)
        tracker = DebrisTracker(reg.voxel, reg.max_correspondence, reg.model_frames,
                                *known_shape_model(scene.model_mesh_target, reg.voxel, p.seed),
                                symmetries_body=transforms, seed=p.seed)
        frames = perceive.Frames()
        state, check = perceive.observe_tumble(scene, tracker, frames, [t[:3, :3] for t in transforms],
                                               np.random.default_rng(p.seed), None, perceive.EARLY_CHECK_FRAMES)
        target_to_body = np.eye(4)
        if check.mismatch:
            tracker, target_to_body = perceive.track_model_free(scene, frames)
    out = {"variant": variant, "seed": seed, "check": check, "cpu_s": time.process_time() - cpu,
           "tracked_with": "scan-to-map" if check.mismatch else "model"}
    ok = np.array([a.ok for a in tracker.alignments])
    cpu_frames = np.array([a.cpu_seconds for a in tracker.alignments])[1:]
    out["registered"] = f"{ok.sum()}/{len(ok)}"
    out["registration_cpu_ms"] = (1e3 * cpu_frames.mean(), 1e3 * np.median(cpu_frames))
    out["rotation_error_deg"] = np.degrees(np.nanmean(np.array(frames.rotation_error, float)))
    try:
        before = fit_free_motion(tracker, perceive._good(tracker, np.array(frames.phase) == 0), frames.time)
        if check.mismatch:
            perceive._check_model_free_track(before)
        else:
            out.update(perceive._model_center_of_mass_offset(scene, before))
        answer = perceive.estimates(scene, before, None, None, state, target_to_body,
                                    "first_scan" if check.mismatch else "target")
        out.update(answer)
    except NotObservable as exc:
        out["not_observable"] = str(exc)
    return out


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--variants", nargs="+", default=["intact", "damaged"],
                        choices=("intact", "damaged", "bent", "antenna", "com"))
    parser.add_argument("--seeds", type=int, nargs="+", default=[0])
    parser.add_argument("--observation", type=float, default=20.0)
    args = parser.parse_args()
    print("| variant | seed | registered with the model / frames judged (30 when found wrong early, all otherwise) | returns off the model, median / p90 (%) "
          "| model surface unseen, median / p90 (%) | verdict | tracked with | frames registered | "
          "registration CPU ms/frame mean / median | attitude error mean (deg) | CoM error (mm) | inertia ratio errors (%) "
          "| D / F errors (%) | L direction (deg) | CoM vs model (mm) | CPU s |")
    print("|" + "---|" * 16)
    for variant in args.variants:
        for seed in args.seeds:
            o = observe(variant, args.observation, seed)
            c = o["check"]
            ratio = o.get("inertia_ratio_error_percent")
            offset = o.get("model_center_of_mass_offset_m")
            print(f"| {variant} | {seed} | {c.registered}/{c.frames} | {100 * c.unexplained_median:.1f} / "
                  f"{100 * c.unexplained_p90:.1f} | {100 * c.unseen_median:.1f} / {100 * c.unseen_p90:.1f} | "
                  f"{'mismatch' if c.mismatch else 'match'} | {o['tracked_with']} | {o['registered']} | "
                  f"{o['registration_cpu_ms'][0]:.0f} / {o['registration_cpu_ms'][1]:.0f} | {o['rotation_error_deg']:.2f} | "
                  + (f"{1e3 * o['center_of_mass_error_m']:.1f} | {ratio[0]:+.2f}, {ratio[1]:+.2f} | "
                     f"{o['normalized_kinetic_energy_error_percent']:+.2f} / {o['normalized_angular_momentum_error_percent']:+.2f} | "
                     f"{o['angular_momentum_direction_error_deg']:.2f} | "
                     if ratio is not None else f"not observable: {o.get('not_observable')} | | | | ")
                  + (f"{1e3 * np.linalg.norm(offset):.0f} |" if offset is not None else " |") + f" {o['cpu_s']:.0f} |",
                  flush=True)
            if c.mismatch:
                print(f"|   reasons: {'; '.join(c.reasons)} |", flush=True)


if __name__ == "__main__":
    main()
