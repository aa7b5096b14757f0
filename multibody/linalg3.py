"""3-vector and 3x3-matrix products for compiled kernels, written out in scalars.

numba hands ``@`` on small arrays to BLAS (about 1 us a call), which dominated the towing
kernel; these loops cost a few ns. Arguments are float64 arrays of shape (3,) or (3, 3).
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def dot3(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def cross3(a, b):
    out = np.empty(3)
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]
    return out


@njit(cache=True, inline="always")
def matvec3(m, x):
    """m x for a (3, 3) matrix."""
    out = np.empty(3)
    for i in range(3):
        out[i] = m[i, 0] * x[0] + m[i, 1] * x[1] + m[i, 2] * x[2]
    return out


@njit(cache=True, inline="always")
def mattvec3(m, x):
    """m^T x for a (3, 3) matrix."""
    out = np.empty(3)
    for i in range(3):
        out[i] = m[0, i] * x[0] + m[1, i] * x[1] + m[2, i] * x[2]
    return out


@njit(cache=True, inline="always")
def matmat3(a, b):
    """a b for (3, 3) matrices."""
    out = np.empty((3, 3))
    for i in range(3):
        for k in range(3):
            out[i, k] = a[i, 0] * b[0, k] + a[i, 1] * b[1, k] + a[i, 2] * b[2, k]
    return out


@njit(cache=True, inline="always")
def mattmat3(a, b):
    """a^T b for (3, 3) matrices."""
    out = np.empty((3, 3))
    for i in range(3):
        for k in range(3):
            out[i, k] = a[0, i] * b[0, k] + a[1, i] * b[1, k] + a[2, i] * b[2, k]
    return out


@njit(cache=True)
def solve3(a, b):
    """x with a x = b for a (3, 3) matrix (Cramer's rule; a must be regular)."""
    c00 = a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]
    c01 = a[1, 2] * a[2, 0] - a[1, 0] * a[2, 2]
    c02 = a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]
    inv_det = 1.0 / (a[0, 0] * c00 + a[0, 1] * c01 + a[0, 2] * c02)
    out = np.empty(3)
    out[0] = (b[0] * c00 + b[1] * (a[0, 2] * a[2, 1] - a[0, 1] * a[2, 2]) + b[2] * (a[0, 1] * a[1, 2] - a[0, 2] * a[1, 1])) * inv_det
    out[1] = (b[0] * c01 + b[1] * (a[0, 0] * a[2, 2] - a[0, 2] * a[2, 0]) + b[2] * (a[0, 2] * a[1, 0] - a[0, 0] * a[1, 2])) * inv_det
    out[2] = (b[0] * c02 + b[1] * (a[0, 1] * a[2, 0] - a[0, 0] * a[2, 1]) + b[2] * (a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0])) * inv_det
    return out
