"""Surface normals of a point cloud by local principal component analysis.

The normal at a point is the direction of least spread of its neighbours: the eigenvector of the
smallest eigenvalue of their covariance (Hoppe et al. 1992), the neighbours being the ``max_nn``
points nearest to it within ``radius`` -- Open3D's ``estimate_normals`` with
``KDTreeSearchParamHybrid(radius, max_nn)``, without its orientation step (the sign of a normal is
arbitrary here as there: the point-to-plane terms use it squared or in pairs with itself).

Why our own: the scan-to-map track (:mod:`perception.scan_to_map`) estimates the normals of its
~20 000-point map at every map rebuild, and Open3D took ~110-150 ms of one core for it (4.7 us a
point), more than all the frame's ICP. Here the neighbours come from a cell list
(:class:`perception.nearest_grid.CellList`) and the eigenvector from the closed form of a
symmetric 3 x 3 matrix (trigonometric eigenvalues, then the largest cross product of two rows of
C - lambda I), compiled with numba.

The same fit gives each point's projection on its plane (the plane through the neighbours' mean,
:func:`surface_planes`): the map of noisy scans thinned to voxel means is a slab a few voxels thick
about the surface, and the ICP's residuals are taken to the projections (docs/perception.md, "Which
property of the scan-made map").
"""
from __future__ import annotations

import math

import numpy as np
from numba import njit

from perception.nearest_grid import CellList


def surface_normals(points, radius, max_nn=30) -> np.ndarray:
    """Unit normals (n, 3) of points (n, 3) (m) on a surface: PCA of the ``max_nn`` nearest points
    within ``radius`` (m), the point itself included. Fewer than 3 neighbours give (0, 0, 1) (as Open3D).

    Parameters
    ----------
    points : (n, 3) float
        Surface points (m, any frame).
    radius : float
        Neighbourhood radius (m).
    max_nn : int
        Most neighbours used (the nearest).

    Returns
    -------
    (n, 3) float
        Unit normals, same frame; signs arbitrary.
    """
    return surface_planes(points, radius, max_nn)[1]


def surface_planes(points, radius, max_nn=30, views=None) -> tuple[np.ndarray, np.ndarray]:
    """The plane fitted (PCA) to each point's ``max_nn`` nearest within ``radius`` (m): the point moved
    along the plane's normal onto it, and the unit normal (:func:`surface_normals`). With ``views``,
    the plane is refitted to the neighbours seen from the point's own side (:func:`fill_planes`).

    Parameters
    ----------
    points : (n, 3) float
        Surface points (m, any frame).
    radius : float
        Neighbourhood radius (m).
    max_nn : int
        Most neighbours used (the nearest).
    views : (n, 3) float, optional
        Each point's mean direction towards the sensor that saw it (unit or shorter, same frame); None or
        zero rows: the side is unknown and every neighbour is kept.

    Returns
    -------
    plane_points : (n, 3) float
        Each point projected on its fitted plane (the plane through its neighbours' mean), m, same frame;
        the point itself where no plane is defined (fewer than 3 neighbours, isotropic spread).
    normals : (n, 3) float
        Unit normals, same frame; signs arbitrary.
    """
    cells = CellList(points, radius / SHELLS, radius)
    sorted_normals = np.empty_like(cells.sorted_points)
    sorted_planes = np.empty_like(cells.sorted_points)
    known = np.zeros(len(points), np.bool_)
    views = np.zeros_like(cells.sorted_points) if views is None else np.ascontiguousarray(np.asarray(views, float)[cells.order])
    fill_planes(np.arange(len(points)), cells.sorted_points, cells.low, cells.cell, cells.shape, cells.starts,
                cells.largest_cell, float(radius), int(max_nn), sorted_normals, sorted_planes, known, views)
    normals, plane_points = np.empty_like(sorted_normals), np.empty_like(sorted_planes)
    normals[cells.order] = sorted_normals
    plane_points[cells.order] = sorted_planes
    return plane_points, normals


#: Cell edge of :func:`surface_normals`' neighbour search as a share of the radius (any edge gives the
#: same neighbours, :func:`fill_normals`): measured on a 49 000-point 3 cm map (12 cm radius, 30
#: neighbours), 3 cm cells took 0.41-0.46 s and 12 cm cells 0.44-0.46 s: the time is in the distances
#: and the selection, not the cells. The radius itself keeps the grid small (64 times fewer cells than 3 cm).
SHELLS = 1


@njit(cache=True)
def fill_normals(rows, points, low, cell, shape, starts, largest_cell, radius, max_nn, normals, known):
    """:func:`fill_planes`' normals alone (the projections are computed and dropped)."""
    fill_planes(rows, points, low, cell, shape, starts, largest_cell, radius, max_nn, normals, np.empty_like(normals),
                known, np.zeros_like(points))


@njit(cache=True)
def fill_planes(rows, points, low, cell, shape, starts, largest_cell, radius, max_nn, normals, plane_points, known,
                views):
    """Normals and projections on the fitted planes (:func:`surface_planes`) of the cell-sorted points ``points[rows]`` not yet ``known``, into ``normals`` (rows of
    ``points``, the arrays of a :class:`perception.nearest_grid.CellList`), as :func:`surface_normals`:
    PCA of the ``max_nn`` nearest points within ``radius`` (m). The neighbours are gathered in growing
    shells of cells (3 x 3 x 3, then 5 x 5 x 5, ...) until ``max_nn`` lie within the searched shells'
    half width (the nearest ``max_nn`` of all, then, are among them) or the shells cover the radius:
    the same neighbours whatever the cell edge, so the scan-to-map track computes a map point's normal
    on its ICP index, only once a scan point is matched to it.

    Own side: a surface is seen only from outside, so the returns of a point's own face were taken with the
    sensor on the side its outward normal points to, and those of the far face of a thin part (the 5 cm solar
    array, inside the 12 cm neighbourhood) from the other side. When ``views`` are known, the plane is fitted
    again to the neighbours whose view direction lies on the same side of the first fit's plane as the point's
    own (``(n . v_j) (n . v_point) >= 0``: a 90 deg cut on the oriented normals, no tuned distance). A cut on the
    offset along the normal cannot separate the faces: one face's own voxel means spread 27-28 mm rms about it
    (the featured debris' map at its true poses, 2 cm range noise), more than half the array's 50 mm
    (docs/perception.md, "The thin array's two faces"). On that case's 20 s observation the array's far face is
    never seen, and the rule moves no point by more than a few tenths of a mm rms.

    Parameters
    ----------
    rows : (k,) int
        Rows of ``points`` whose normal is wanted; rows >= len(points) (no match) are skipped.
    points, low, cell, shape, starts, largest_cell
        The cell list's ``sorted_points`` (m), ``low``, ``cell``, ``shape``, ``starts``, ``largest_cell``.
    radius : float
        Neighbourhood radius (m).
    max_nn : int
        Most neighbours used (the nearest).
    normals : (n, 3) float
        In/out: unit normals by row of ``points``; signs arbitrary.
    plane_points : (n, 3) float
        In/out: each row's point moved along its normal onto the plane through its neighbours' mean (m).
    known : (n,) bool
        In/out: which rows of ``normals`` and ``plane_points`` are computed.
    views : (n, 3) float
        Each row's mean direction towards the sensor (any length; zero: side unknown, all neighbours kept).
    """
    shells = max(int(np.ceil(radius / cell)), 1)
    size = (2 * shells + 1) ** 3 * largest_cell
    found_d2 = np.empty(size)
    found = np.empty(size, np.int64)
    radius2 = radius * radius
    for row in rows:
        if row >= len(points) or known[row]:
            continue
        count = 0
        c0 = int(np.floor((points[row, 0] - low[0]) / cell))
        c1 = int(np.floor((points[row, 1] - low[1]) / cell))
        c2 = int(np.floor((points[row, 2] - low[2]) / cell))
        for r in range(1, shells + 1):
            count = _gather_shell(points, row, c0, c1, c2, r, shape, starts, radius2, found_d2, found, count)
            reach2 = min((r * cell) ** 2, radius2)
            within = 0
            for i in range(count):
                if found_d2[i] <= reach2:
                    within += 1
            if within >= max_nn:
                break
        if count > max_nn:
            _select_nearest(found_d2, found, count, max_nn)
            count = max_nn
        m0, m1, m2 = _least_spread_direction(points, found, count, normals[row])
        own = _own_side_first(views, row, normals[row], found, count)
        if 3 <= own < count:
            m0, m1, m2 = _least_spread_direction(points, found, own, normals[row])
        offset = ((points[row, 0] - m0) * normals[row, 0] + (points[row, 1] - m1) * normals[row, 1]
                  + (points[row, 2] - m2) * normals[row, 2])
        if not math.isfinite(offset):   # no plane: the point stays
            offset = 0.0
        for a in range(3):
            plane_points[row, a] = points[row, a] - offset * normals[row, a]
        known[row] = True


@njit(cache=True)
def _own_side_first(views, row, normal, found, count):
    """Reorder found[:count] so that the neighbours seen from ``row``'s side of the plane with ``normal``
    come first (view direction ``views[j]`` with ``(normal . views[j]) (normal . views[row]) >= 0``); their
    number (``count`` when the row's side is unknown)."""
    side = normal[0] * views[row, 0] + normal[1] * views[row, 1] + normal[2] * views[row, 2]
    if side == 0.0:
        return count
    own = 0
    for i in range(count):
        j = found[i]
        if side * (normal[0] * views[j, 0] + normal[1] * views[j, 1] + normal[2] * views[j, 2]) >= 0.0:
            found[i], found[own] = found[own], j
            own += 1
    return own


@njit(cache=True, inline="always")
def _gather_shell(points, k, c0, c1, c2, r, shape, starts, radius2, found_d2, found, count):
    """Append to found / found_d2 (from ``count``) the points within ``radius2`` (squared, m^2) in the
    cells of shell ``r`` about cell (c0, c1, c2) (shell 1: the 27 cells about it); the new count."""
    x, y, z = points[k, 0], points[k, 1], points[k, 2]
    for a in range(max(c0 - r, 0), min(c0 + r + 1, shape[0])):
        for b in range(max(c1 - r, 0), min(c1 + r + 1, shape[1])):
            row = (a * shape[1] + b) * shape[2]
            inner = abs(a - c0) < r and abs(b - c1) < r   # only the two end cells are new
            for c in range(max(c2 - r, 0), min(c2 + r + 1, shape[2])):
                if inner and abs(c - c2) < r and r > 1:
                    continue
                for j in range(starts[row + c], starts[row + c + 1]):
                    d2 = (points[j, 0] - x) ** 2 + (points[j, 1] - y) ** 2 + (points[j, 2] - z) ** 2
                    if d2 <= radius2:
                        found_d2[count] = d2
                        found[count] = j
                        count += 1
    return count


@njit(cache=True)
def _select_nearest(d2, rows, count, kept):
    """Reorder d2[:count] (and rows alike) so that its ``kept`` smallest come first (quickselect)."""
    lo, hi = 0, count - 1
    target = kept - 1
    while lo < hi:
        pivot = d2[(lo + hi) // 2]
        i, j = lo, hi
        while i <= j:
            while d2[i] < pivot:
                i += 1
            while d2[j] > pivot:
                j -= 1
            if i <= j:
                d2[i], d2[j] = d2[j], d2[i]
                rows[i], rows[j] = rows[j], rows[i]
                i += 1
                j -= 1
        if target <= j:
            hi = j
        elif target >= i:
            lo = i
        else:
            break


@njit(cache=True)
def _least_spread_direction(points, rows, count, out):
    """Eigenvector of the smallest eigenvalue of the covariance of points[rows[:count]] into ``out`` (3,);
    returns the points' mean (m0, m1, m2), NaN when no plane is defined (fewer than 3 points, isotropic
    spread: ``out`` is (0, 0, 1))."""
    out[0], out[1], out[2] = 0.0, 0.0, 1.0
    if count < 3:
        return math.nan, math.nan, math.nan
    m0 = m1 = m2 = 0.0
    for i in range(count):
        j = rows[i]
        m0 += points[j, 0]
        m1 += points[j, 1]
        m2 += points[j, 2]
    m0, m1, m2 = m0 / count, m1 / count, m2 / count
    a00 = a01 = a02 = a11 = a12 = a22 = 0.0
    for i in range(count):
        j = rows[i]
        x, y, z = points[j, 0] - m0, points[j, 1] - m1, points[j, 2] - m2
        a00 += x * x
        a01 += x * y
        a02 += x * z
        a11 += y * y
        a12 += y * z
        a22 += z * z
    scale = max(a00, a11, a22, abs(a01), abs(a02), abs(a12))
    if scale <= 0.0:
        return math.nan, math.nan, math.nan
    a00, a01, a02, a11, a12, a22 = a00 / scale, a01 / scale, a02 / scale, a11 / scale, a12 / scale, a22 / scale
    # smallest eigenvalue, trigonometric form (Smith 1961)
    q = (a00 + a11 + a22) / 3.0
    p1 = a01 * a01 + a02 * a02 + a12 * a12
    p2 = (a00 - q) ** 2 + (a11 - q) ** 2 + (a22 - q) ** 2 + 2.0 * p1
    if p2 <= 1e-30:
        return math.nan, math.nan, math.nan   # isotropic: no preferred direction
    p = math.sqrt(p2 / 6.0)
    b00, b11, b22 = (a00 - q) / p, (a11 - q) / p, (a22 - q) / p
    b01, b02, b12 = a01 / p, a02 / p, a12 / p
    r = 0.5 * (b00 * (b11 * b22 - b12 * b12) - b01 * (b01 * b22 - b12 * b02) + b02 * (b01 * b12 - b11 * b02))
    phi = math.acos(min(max(r, -1.0), 1.0)) / 3.0
    smallest = q + 2.0 * p * math.cos(phi + 2.0 * math.pi / 3.0)
    # its eigenvector: orthogonal to the rows of A - smallest I; the largest cross product of two rows
    u0, u1, u2 = a00 - smallest, a01, a02
    v0, v1, v2 = a01, a11 - smallest, a12
    w0, w1, w2 = a02, a12, a22 - smallest
    best_norm2 = 0.0
    for pair in range(3):
        if pair == 0:
            c0, c1, c2 = u1 * v2 - u2 * v1, u2 * v0 - u0 * v2, u0 * v1 - u1 * v0
        elif pair == 1:
            c0, c1, c2 = u1 * w2 - u2 * w1, u2 * w0 - u0 * w2, u0 * w1 - u1 * w0
        else:
            c0, c1, c2 = v1 * w2 - v2 * w1, v2 * w0 - v0 * w2, v0 * w1 - v1 * w0
        norm2 = c0 * c0 + c1 * c1 + c2 * c2
        if norm2 > best_norm2:
            best_norm2 = norm2
            norm = math.sqrt(norm2)
            out[0], out[1], out[2] = c0 / norm, c1 / norm, c2 / norm
    return m0, m1, m2
