"""Which side of the debris' thin part (the featured debris' 5 cm solar array) the observation's scans see, and
where the map's points of its faces sit: raw voxel means, projected on the plane of all 30 nearest (percep14),
projected on the plane of the neighbours seen from the point's own side (:func:`perception.normals.fill_planes`).

The observation's scans of one seed (the stage's, ``observe_tumble_model_free``) are mapped at their **true**
poses into the target frame, so what is measured is the map's construction alone, not the track's errors; each
map point keeps its mean direction towards the sensor (:func:`perception.scan_to_map.voxel_means`), which tells
the face it was seen on. Printed: how many of the part's map points were seen from each side, each face's mean
offset from the mesh face (outward positive) and rms, the bus' two largest faces as a control, and every map
point's distance to the mesh::

    python bench/perception_thin_faces.py --seeds 3 4     # ~10 s CPU a seed (the observation's ray casting)

(docs/perception.md, "The thin array's two faces").
"""
from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

import numpy as np

from perception.normals import surface_planes
from perception.scan_to_map import thinned_scan, views_towards, voxel_means
from riskassess.cases.impact import load_case
from riskassess.stages.perceive import Frames, Scene, observe_tumble_model_free

CASE = Path(__file__).resolve().parents[1] / "cases" / "featured_debris_perception_model_free.toml"
RIM = 0.06   # m, margin from a face's rims (two voxels): points there belong to the edge faces too


def boxes(case_path):
    """[(size (3,), center (3,))] of the case's boxes (m, target frame), the thinnest first."""
    target = tomllib.loads(Path(case_path).read_text())["target"]
    found = [(np.asarray(s["size"], float), np.asarray(s["center"], float))
             for body in target["bodies"] for s in body["shapes"] if s["kind"] == "box"]
    return sorted(found, key=lambda box: min(box[0]))


def true_pose_map(scene, frames, voxel):
    """Voxel means (p, 3) of the observation's thinned scans at their true poses (m, target frame) and their mean
    views towards the sensor (p, 3), target frame."""
    com_target = scene.truth["com_target"]
    points, views = [], []
    for scan, (sensor_world, _), rot, com in zip(frames.scans, frames.sensor_poses, frames.true_target_to_world,
                                                 frames.true_com_world):
        thin = thinned_scan(scan, voxel)
        origin_world = com - rot @ com_target
        points.append((thin - origin_world) @ rot)
        views.append(views_towards(thin, sensor_world) @ rot)
    return voxel_means(np.vstack(points), voxel, np.vstack(views))


def face_rows(points_target, views_target, size, center, axis, sign):
    """Map points over the face of a box with outward normal ``sign`` along ``axis``, away from its rims, seen
    from that face's side; their outward offsets from the face (m) by the caller."""
    local = points_target - center
    rows = (np.abs(sign * local[:, axis] - size[axis] / 2) < 0.1) & (sign * views_target[:, axis] > 0)
    for a in range(3):
        if a != axis:
            rows &= np.abs(local[:, a]) < size[a] / 2 - RIM
    return rows, sign * local[:, axis] - size[axis] / 2


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[3])
    parser.add_argument("--case", type=Path, default=CASE)
    args = parser.parse_args()
    base = load_case(args.case)
    voxel = base.perception.registration.voxel
    (part_size, part_center), (bus_size, bus_center) = boxes(args.case)[:2]
    thin_axis = int(np.argmin(part_size))
    for seed in args.seeds:
        case = base.model_copy(update={"perception": base.perception.model_copy(update={"seed": seed})})
        scene = Scene.from_case(case, args.case.parent, str(args.case))
        frames = Frames()
        observe_tumble_model_free(scene, frames, np.random.default_rng(seed))
        means, views = true_pose_map(scene, frames, voxel)
        maps = {"voxel means": means, "all 30 nearest": surface_planes(means, 4 * voxel, 30)[0],
                "own side": surface_planes(means, 4 * voxel, 30, views)[0]}
        print(f"seed {seed}: {len(frames.scans)} observation frames, {len(means)} map points (true poses, target frame)")
        for name, size, center, axes in (("thin part", part_size, part_center, [thin_axis]),
                                         ("bus", bus_size, bus_center, [int(np.argmax(bus_size))])):
            for axis in axes:
                for sign in (1, -1):
                    rows, _ = face_rows(means, views, size, center, axis, sign)
                    line = f"  {name} face {'+-'[sign < 0]}{'xyz'[axis]}: {rows.sum()} map points seen from its side"
                    for label, points in maps.items():
                        offset = face_rows(points, views, size, center, axis, sign)[1][rows]
                        if rows.any():
                            line += f"; {label} {1e3 * offset.mean():+.1f} mm (rms {1e3 * np.sqrt(np.mean(offset ** 2)):.1f})"
                    print(line)
        for label, points in maps.items():
            distance = scene.mesh_target.nearest.on_surface(points)[1]
            print(f"  every map point, {label}: distance to the mesh rms {1e3 * np.sqrt(np.mean(distance ** 2)):.1f} mm, "
                  f"median {1e3 * np.median(distance):.1f} mm")


if __name__ == "__main__":
    main()
