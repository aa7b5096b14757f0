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
    cells = CellList(points, radius)
    sorted_normals = _normals(cells.sorted_points, cells.low, cells.cell, cells.shape, cells.starts,
                              float(radius), int(max_nn))
    normals = np.empty_like(sorted_normals)
    normals[cells.order] = sorted_normals
    return normals


@njit(cache=True)
def _normals(points, low, cell, shape, starts, radius, max_nn):
    """Normals of cell-sorted points (rows of ``points``), neighbours from the 27 cells around each
    (cell >= radius): every point within ``radius`` gathered, the ``max_nn`` nearest of them moved
    to the front (:func:`_select_nearest`)."""
    n = len(points)
    out = np.empty((n, 3))
    largest_cell = 0
    for i in range(len(starts) - 1):
        largest_cell = max(largest_cell, starts[i + 1] - starts[i])
    found_d2 = np.empty(27 * largest_cell)
    found = np.empty(27 * largest_cell, np.int64)
    radius2 = radius * radius
    for k in range(n):
        count = 0
        x, y, z = points[k, 0], points[k, 1], points[k, 2]
        c0 = int(np.floor((x - low[0]) / cell))
        c1 = int(np.floor((y - low[1]) / cell))
        c2 = int(np.floor((z - low[2]) / cell))
        for a in range(max(c0 - 1, 0), min(c0 + 2, shape[0])):
            for b in range(max(c1 - 1, 0), min(c1 + 2, shape[1])):
                row = (a * shape[1] + b) * shape[2]
                for j in range(starts[row + max(c2 - 1, 0)], starts[row + min(c2 + 2, shape[2])]):
                    d2 = (points[j, 0] - x) ** 2 + (points[j, 1] - y) ** 2 + (points[j, 2] - z) ** 2
                    if d2 <= radius2:
                        found_d2[count] = d2
                        found[count] = j
                        count += 1
        if count > max_nn:
            _select_nearest(found_d2, found, count, max_nn)
            count = max_nn
        _least_spread_direction(points, found, count, out[k])
    return out


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
    """Eigenvector of the smallest eigenvalue of the covariance of points[rows[:count]] into ``out`` (3,)."""
    out[0], out[1], out[2] = 0.0, 0.0, 1.0
    if count < 3:
        return
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
        return
    a00, a01, a02, a11, a12, a22 = a00 / scale, a01 / scale, a02 / scale, a11 / scale, a12 / scale, a22 / scale
    # smallest eigenvalue, trigonometric form (Smith 1961)
    q = (a00 + a11 + a22) / 3.0
    p1 = a01 * a01 + a02 * a02 + a12 * a12
    p2 = (a00 - q) ** 2 + (a11 - q) ** 2 + (a22 - q) ** 2 + 2.0 * p1
    if p2 <= 1e-30:
        return   # isotropic spread: no preferred direction
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
