"""What the LiDAR's rays say about a posed model: where the model would block a measured return (free space),
where it lies in the field of view with no return near it (unseen), and the visible side's centroid.

These are the checks :class:`perception.registration.DebrisTracker` applies to every alignment (its module
docstring says why its own checks, and the limits :data:`perception.registration.MAX_FREE_SPACE_VIOLATION`,
:data:`perception.registration.MAX_UNSEEN`). Pure functions of points in one named frame (world or body).
"""
from __future__ import annotations

import numpy as np


def free_space_violation(points_world, model_world, sensor_world, bin_angle, margin, model_normals_world=None,
                         sample_spacing=0.0, lateral_bins=0) -> float:
    """Share of viewing directions (bins of ``bin_angle`` rad seen from the sensor) holding
    scan returns where a model point lies more than ``margin`` (m) in front of the nearest return.

    With the model's unit normals ``model_normals_world`` (n, 3) the margin of each model point
    grows by the depth its surface spans over one ``sample_spacing`` (m, the scan's point spacing):
    ``sample_spacing * tan(incidence)``. The nearest return in a bin may sit one sample further out
    along a surface that runs almost along the rays (the limb), tens of cm deeper at 20-30 m;
    without this, correct poses failed on limb bins beyond ~20 m (violation 0.09 at 20 m, 0.22 at
    30 m; 0.003 and 0.02 with it). The model's own incidence is used, so a wrong pose that puts the
    model's face where the scan's limb is still violates.

    Parameters
    ----------
    points_world : (n, 3) float
        Scan returns (m, world frame).
    model_world : (k, 3) float
        Model points at the pose under test (m, world frame).
    sensor_world : (3,) float
        Sensor position (m, world frame); the bins are elevation/azimuth about the world axes
        as seen from it.
    bin_angle : float
        Angular size of a viewing-direction bin (rad).
    margin : float
        Depth (m) by which a model point must lie in front of the nearest return to count.
    model_normals_world : (k, 3) float, optional
        Unit outward normals of the model points (world frame).
    sample_spacing : float
        The scan's point spacing (m); used only with ``model_normals_world``.
    lateral_bins : int
        A model point blocks only if it lies in front of the nearest return of its own bin and of
        every bin holding returns within this many bins about it (0: its own bin alone; see
        :data:`perception.registration.MAP_LATERAL_BINS`).

    Returns
    -------
    float
        Share (0 to 1) of the bins holding returns in which the model blocks a return.
    """
    def bins(points):
        d = points - sensor_world
        r = np.sqrt(np.einsum("ij,ij->i", d, d))
        el = np.arcsin(np.clip(d[:, 2] / r, -1, 1))
        az = np.arctan2(d[:, 1], d[:, 0])
        return np.floor(el / bin_angle).astype(np.int64) * 1_000_003 + np.floor(az / bin_angle).astype(np.int64), r

    scan_bin, scan_range = bins(points_world)
    model_bin, model_range = bins(model_world)
    margins = np.full(len(model_world), float(margin))
    if model_normals_world is not None:
        ray = (model_world - sensor_world) / model_range[:, None]
        cos_incidence = np.clip(np.abs(np.einsum("ij,ij->i", ray, model_normals_world)), 0.05, 1.0)
        margins += sample_spacing * np.sqrt(1.0 - cos_incidence**2) / cos_incidence
    order = np.lexsort((scan_range, scan_bin))             # by bin, nearest return first
    first = np.r_[True, np.diff(scan_bin[order]) != 0]
    seen_bin, nearest = scan_bin[order][first], scan_range[order][first]
    slot = np.clip(np.searchsorted(seen_bin, model_bin), 0, len(seen_bin) - 1)
    seen = np.where(seen_bin[slot] == model_bin, nearest[slot], np.inf)
    neighbours = seen.copy()   # the nearest return over the bin and the bins about it
    for up in range(-lateral_bins, lateral_bins + 1):
        for side in range(-lateral_bins, lateral_bins + 1):
            if up == 0 and side == 0:
                continue
            key = model_bin + up * 1_000_003 + side
            slot = np.clip(np.searchsorted(seen_bin, key), 0, len(seen_bin) - 1)
            neighbours = np.minimum(neighbours, np.where(seen_bin[slot] == key, nearest[slot], np.inf))
    blocked = np.unique(model_bin[np.isfinite(seen) & (model_range < neighbours - margins)])
    return len(blocked) / max(len(seen_bin), 1)


def unseen_model_share(model_world, returns_world, sensor_world, sensor_to_world, field_of_view, bin_angle) -> float:
    """Share of the viewing directions the posed model covers, inside the sensor's field of view,
    that hold no return in their bin or the 8 bins around it: the LiDAR looked there and its rays
    met nothing, so a model surface there contradicts the scan (the free space beside the body, which
    :func:`free_space_violation`, judging only bins with returns, cannot see).

    A half turn of a box-like body fits the seen side as well as the truth but puts its far parts
    (an array, the bus' other end) where the rays passed: on the featured debris after the net
    contact (dumped frames 0.1-6.1 s, 2-16 m) the truth scored at most 0.002, the map's half turns
    about its principal axes refined by ICP 0.003-0.56 (mostly above 0.03), one of which passed the
    other checks (tight fitness 0.83, violation 0.033) with 0.149. The one-bin dilation keeps the
    limb bins, partly covered by the body, from counting.

    Parameters
    ----------
    model_world : (k, 3) float
        Model points at the pose under test (m, world frame).
    returns_world : (n, 3) float
        Every return of the frame (m, world frame): debris, net, anything.
    sensor_world : (3,) float
        Sensor origin (m, world frame).
    sensor_to_world : (3, 3) float
        Sensor -> world rotation (sensor frame of :mod:`perception.lidar`: boresight +x, up +z).
    field_of_view : (2,) float
        Full field of view (rad): azimuth, elevation.
    bin_angle : float
        Angular size of a viewing-direction bin (rad), several ray spacings.

    Returns
    -------
    float
        Share (0 to 1) of the model's bins inside the field of view (shrunk by two bins) with no
        return in the 3 x 3 bins about them; 0 when the model covers none.
    """
    def bins(points):
        d = (np.asarray(points, float) - sensor_world) @ sensor_to_world
        r = np.sqrt(np.einsum("ij,ij->i", d, d))
        return np.arcsin(np.clip(d[:, 2] / r, -1, 1)), np.arctan2(d[:, 1], d[:, 0])

    elevation, azimuth = bins(model_world)
    inside = ((np.abs(elevation) < 0.5 * field_of_view[1] - 2 * bin_angle)
              & (np.abs(azimuth) < 0.5 * field_of_view[0] - 2 * bin_angle))
    row = 1_000_003   # key = elevation bin * row + azimuth bin
    model_keys = np.unique(np.floor(elevation[inside] / bin_angle).astype(np.int64) * row
                           + np.floor(azimuth[inside] / bin_angle).astype(np.int64))
    if not len(model_keys):
        return 0.0
    elevation, azimuth = bins(returns_world)
    return_keys = np.unique(np.floor(elevation / bin_angle).astype(np.int64) * row
                            + np.floor(azimuth / bin_angle).astype(np.int64))
    seen = np.zeros(len(model_keys), bool)
    for up in (-1, 0, 1):
        for side in (-1, 0, 1):
            seen |= np.isin(model_keys + up * row + side, return_keys)
    return float(1.0 - seen.mean())


def visible_side_centroid(points_body, view_body, cell) -> np.ndarray:
    """Centroid of the points (n, 3) (m, frame B) a distant viewer looking along ``view_body``
    sees: per ``cell`` (m) square across the view, the points within one cell of the front-most (a
    depth buffer; parallel projection, a few cm off at 2-6 m). Needs no normals (a map's estimated
    normals have no consistent sign).

    Parameters
    ----------
    points_body : (n, 3) float
        Model points (m, frame B).
    view_body : (3,) float
        Unit viewing direction, from the viewer towards the body (frame B).
    cell : float
        Size of the depth buffer's squares (m).

    Returns
    -------
    (3,) float
        Centroid of the seen points (m, frame B).
    """
    helper = np.eye(3)[int(np.argmin(np.abs(view_body)))]
    across = np.cross(view_body, helper)
    across /= np.linalg.norm(across)
    up = np.cross(view_body, across)
    depth = points_body @ view_body
    key = (np.floor(points_body @ across / cell).astype(np.int64) * 1_000_003
           + np.floor(points_body @ up / cell).astype(np.int64))
    order = np.lexsort((depth, key))
    first = np.r_[True, np.diff(key[order]) != 0]
    front = np.repeat(depth[order][first], np.diff(np.r_[np.flatnonzero(first), len(order)]))
    return points_body[order[depth[order] <= front + cell]].mean(axis=0)
