"""Synthetic scanning LiDAR: ray-cast triangle meshes with Open3D.

A scan is one frame of a grid sensor (a C-Fans-256-like imager: a rectangular field of view
sampled at a fixed angular resolution). Each ray returns the first surface it meets
(occlusion comes with the ray casting), its range perturbed by Gaussian noise.

Sensor frame ("sensor"): boresight +x, azimuth measured about +z (from +x towards +y),
elevation towards +z. A ray at azimuth ``az`` and elevation ``el`` has the direction
``[cos el cos az, cos el sin az, sin el]``.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import open3d as o3d


@dataclass(frozen=True)
class LidarSpec:
    """A scanning LiDAR.

    Attributes
    ----------
    fov_azimuth, fov_elevation : float        Full field of view (rad).
    resolution_azimuth, resolution_elevation : float  Angular step between rays (rad).
    range_noise : float                       Range noise, 1 sigma (m), taken constant over range.
    rate : float                              Frames per second (Hz).
    max_range : float                         Returns beyond it are dropped (m).
    """

    fov_azimuth: float
    fov_elevation: float
    resolution_azimuth: float
    resolution_elevation: float
    range_noise: float
    rate: float
    max_range: float = 200.0

    @property
    def shape(self) -> tuple[int, int]:
        """(rows, columns) of the full ray grid: elevation x azimuth."""
        return (int(np.floor(self.fov_elevation / self.resolution_elevation)) + 1,
                int(np.floor(self.fov_azimuth / self.resolution_azimuth)) + 1)

    def angles(self) -> tuple[np.ndarray, np.ndarray]:
        """Elevation (rows,) and azimuth (columns,) of the ray grid (rad), sensor frame."""
        rows, cols = self.shape
        return (-0.5 * self.fov_elevation + self.resolution_elevation * np.arange(rows),
                -0.5 * self.fov_azimuth + self.resolution_azimuth * np.arange(cols))


def sensor_to_platform(boresight, up) -> np.ndarray:
    """Rotation sensor -> platform frame (3, 3) of a sensor whose boresight (+x) and up (+z,
    made orthogonal to the boresight) are given in the platform frame.

    Parameters
    ----------
    boresight : (3,) float
        Boresight direction (any length, platform frame: LVLH or world in the pipeline).
    up : (3,) float
        Direction of the sensor's +z (platform frame), not parallel to ``boresight``.

    Returns
    -------
    (3, 3) float
        Rotation sensor -> platform; its columns are the sensor axes in the platform frame.
    """
    x = np.asarray(boresight, float) / np.linalg.norm(boresight)
    z = np.asarray(up, float) - (np.asarray(up, float) @ x) * x
    z /= np.linalg.norm(z)
    return np.c_[x, np.cross(z, x), z]


def direction_sensor(elevation, azimuth) -> np.ndarray:
    """Unit ray directions (..., 3), sensor frame, for broadcastable angle arrays (rad).

    Parameters
    ----------
    elevation : float or array
        Elevation towards +z (rad, sensor frame).
    azimuth : float or array
        Azimuth about +z from +x towards +y (rad), broadcastable with ``elevation``.
    """
    el, az = np.broadcast_arrays(elevation, azimuth)
    return np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=-1)


def angles_of(points_sensor) -> tuple[np.ndarray, np.ndarray]:
    """Elevation and azimuth (rad) of points (n, 3), sensor frame.

    Parameters
    ----------
    points_sensor : (n, 3) float
        Points (m, sensor frame).

    Returns
    -------
    elevation, azimuth : (n,) float
        Angles (rad) as in :func:`direction_sensor`.
    """
    p = np.asarray(points_sensor, float)
    return np.arctan2(p[:, 2], np.hypot(p[:, 0], p[:, 1])), np.arctan2(p[:, 1], p[:, 0])


def rays_towards(spec: LidarSpec, centers_sensor, radii) -> np.ndarray:
    """The sensor's rays (m, 6: origin, direction), sensor frame, that can meet spheres.

    Only grid rays inside the angular window of the bounding spheres are kept: a ray outside
    cannot hit, so the scan equals a full-grid scan at a fraction of the cost.

    Parameters
    ----------
    spec : LidarSpec                The sensor (field of view, resolution).
    centers_sensor : (k, 3) float   Bounding-sphere centres (m), sensor frame.
    radii : (k,) float              Their radii (m).
    """
    elevation, azimuth = spec.angles()
    windows = []
    for center, radius in zip(np.atleast_2d(centers_sensor), np.atleast_1d(radii)):
        distance = np.linalg.norm(center)
        if distance <= radius:  # the sensor is inside the sphere: every ray may hit
            return _ray_array(elevation, azimuth)
        half = np.arcsin(radius / distance)
        el0, az0 = angles_of(center[None])
        el0, az0 = el0[0], az0[0]
        half_az = half / max(np.cos(abs(el0) + half), 1e-6) if abs(el0) + half < 0.5 * np.pi else np.pi
        windows.append((np.abs(elevation - el0) <= half,
                        np.abs(np.angle(np.exp(1j * (azimuth - az0)))) <= half_az))
    if not windows:
        return np.zeros((0, 6))
    blocks = [_ray_array(elevation[rows], azimuth[cols]) for rows, cols in windows]
    rays = np.concatenate(blocks)
    if len(blocks) == 1:
        return rays
    # overlapping windows repeat rays; keep each once
    _, unique = np.unique(np.round(rays[:, 3:] * 1e9).astype(np.int64), axis=0, return_index=True)
    return rays[np.sort(unique)]


def _ray_array(elevation, azimuth) -> np.ndarray:
    d = direction_sensor(elevation[:, None], azimuth[None, :]).reshape(-1, 3)
    return np.hstack([np.zeros_like(d), d])


@dataclass
class Scan:
    """One LiDAR frame.

    Attributes
    ----------
    time : float                 (s)
    points_sensor : (n, 3) float  Returns (m), sensor frame, range noise included.
    label : (n,) int             Which mesh each return came from (index into the scene's meshes);
                                 ground truth for tests, never used by the estimators.
    """

    time: float
    points_sensor: np.ndarray
    label: np.ndarray


def cast(spec: LidarSpec, meshes_sensor, time: float, rng: np.random.Generator) -> Scan:
    """Scan meshes given in the sensor frame.

    Parameters
    ----------
    spec : LidarSpec             The sensor.
    meshes_sensor : list of (vertices (v, 3) float, faces (f, 3) int)   In metres, sensor frame.
    time : float                 Time stamp of the frame (s), stored in the :class:`Scan`.
    rng : numpy Generator        Range noise.
    """
    scene = o3d.t.geometry.RaycastingScene()
    centers, radii = [], []
    for vertices, faces in meshes_sensor:
        vertices = np.asarray(vertices, np.float32)
        scene.add_triangles(o3d.core.Tensor(vertices), o3d.core.Tensor(np.asarray(faces, np.uint32)))
        lo, hi = vertices.min(0), vertices.max(0)
        centers.append(0.5 * (lo + hi))
        radii.append(0.5 * np.linalg.norm(hi - lo) + 1e-6)
    rays = rays_towards(spec, np.array(centers), np.array(radii))
    if len(rays) == 0:
        return Scan(time, np.zeros((0, 3)), np.zeros(0, int))
    hits = scene.cast_rays(o3d.core.Tensor(rays.astype(np.float32)))
    distance = hits["t_hit"].numpy().astype(float)
    hit = np.isfinite(distance) & (distance <= spec.max_range)
    measured = distance[hit] + spec.range_noise * rng.standard_normal(hit.sum())
    points = rays[hit, 3:] * measured[:, None]
    return Scan(time, points, hits["geometry_ids"].numpy()[hit].astype(int))
