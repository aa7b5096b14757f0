"""The surface a registered scan shows and a scan-made map lacks: what grows the map after a confirmed
re-acquisition (:class:`perception.registration.DebrisTracker`'s ``grow_map``).

Why: a map made from one side of the debris has no faces the observation never saw. On the featured debris
(model-free, seed 3) the bus' -x face was unseen in the 20 s observation; after the net turned the debris it
came into view, and between 2.9 and 4.7 s 20-22 % of the true pose's scan lay more than 3 cm from the map
(81-91 % of it on that face), so the truth scored a tight fitness of 0.64-0.72 against the check's 0.8 while
the bus' half turn, which puts the mapped +x face there, scored 0.93-0.98 (docs/perception.md, "The
re-acquisition's candidates, the propagation's limit and the moments' 1-sigma").

The rule is the map's first build's (:func:`perception.scan_to_map.track_scans`): a scan shows new surface
when more than 1 - MAP_COVERED of its points lie beyond the fine correspondence distance (a third of the
coarse one) of the map; the new points are thinned to one mean per voxel and put on the plane fitted to
their 4-voxel neighbourhood with its normal (:func:`perception.normals.surface_planes`). One addition: only
points within MAP_GROWTH_REACH coarse correspondence distances of the map join it, so that new surface
adjoins the surface mapped (a face turning into view grows from its edges, frame by frame) and a net
thread's return decimetres off the debris that the net gate missed does not.
"""
from __future__ import annotations

import numpy as np
import open3d as o3d
from scipy.spatial import cKDTree

from perception.normals import surface_planes

#: A scan shows new surface when fewer than this share of its points lie within the fine correspondence
#: distance of the map: perception.scan_to_map.MAP_COVERED, the map's first build (a test checks they agree;
#: scan_to_map imports the registration module, so the value is not imported from there).
MAP_GROWTH_COVERED = 0.95
#: New points join the map only within this many coarse correspondence distances of it [assumed: the coarse
#: ICP's own reach, 0.1 m on the featured debris; a 1.0 x 1.6 m face then fills in over ~5-8 frames].
MAP_GROWTH_REACH = 1.0
#: Neighbours of a new point's plane fit, and its radius in voxels (as the map's first build, surface_map).
PLANE_NEIGHBOURS = 30
PLANE_RADIUS_VOXELS = 4


def unmapped_surface(points_body, map_points_body, map_tree, voxel, max_correspondence):
    """The surface of a registered scan that the map lacks, as map points with their normals.

    Parameters
    ----------
    points_body : (n, 3) float        The scan's points at its registered pose (m, frame B).
    map_points_body : (m, 3) float    The map (m, frame B).
    map_tree : scipy.spatial.cKDTree  Nearest-point index of ``map_points_body``.
    voxel : float                     Map spacing (m).
    max_correspondence : float        Coarse ICP correspondence distance (m); the fine one is a third of it.

    Returns
    -------
    points : (p, 3) float    New map points (m, frame B), voxel means moved onto their fitted planes; p = 0
                             when the scan shows no new surface (module docstring).
    normals : (p, 3) float   Their unit normals (frame B; signs arbitrary, as the map's).
    """
    points_body = np.asarray(points_body, float).reshape(-1, 3)
    gap = map_tree.query(points_body, distance_upper_bound=MAP_GROWTH_REACH * max_correspondence)[0]
    unmapped = points_body[np.isfinite(gap) & (gap > max_correspondence / 3)]
    if len(unmapped) <= (1 - MAP_GROWTH_COVERED) * len(points_body):
        return np.zeros((0, 3)), np.zeros((0, 3))
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(unmapped))
    means = np.asarray(cloud.voxel_down_sample(voxel).points)
    radius = PLANE_RADIUS_VOXELS * voxel
    near = np.isfinite(cKDTree(means).query(map_points_body, distance_upper_bound=radius)[0])
    planes, normals = surface_planes(np.vstack([map_points_body[near], means]), radius, PLANE_NEIGHBOURS)
    return planes[-len(means):], normals[-len(means):]
