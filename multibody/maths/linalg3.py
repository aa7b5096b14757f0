"""3-vector and 3x3-matrix products for compiled kernels, written out in scalars.

numba hands ``@`` on small arrays to BLAS (about 1 us a call), which dominated the towing
kernel; these loops cost a few ns. Arguments are float64 arrays of shape (3,) or (3, 3).
"""
from __future__ import annotations

import numpy as np
from numba import njit


@njit(cache=True, inline="always")
def dot3(a, b):
    """Scalar product a . b of two 3-vectors.

    Parameters
    ----------
    a, b : (3,) float
        Vectors in one and the same frame (any unit).
    """
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def cross3(a, b):
    """Cross product a x b of two 3-vectors.

    Parameters
    ----------
    a, b : (3,) float
        Vectors in one and the same right-handed frame (any unit).

    Returns
    -------
    (3,) float
        a x b, same frame, unit of a times unit of b.
    """
    out = np.empty(3)
    out[0] = a[1] * b[2] - a[2] * b[1]
    out[1] = a[2] * b[0] - a[0] * b[2]
    out[2] = a[0] * b[1] - a[1] * b[0]
    return out


@njit(cache=True, inline="always")
def matvec3(m, x):
    """m x for a (3, 3) matrix.

    Parameters
    ----------
    m : (3, 3) float
        Matrix, typically a rotation a->b (columns: a's axes in b's components).
    x : (3,) float
        Vector, frame a.

    Returns
    -------
    (3,) float
        m x, frame b.
    """
    out = np.empty(3)
    for i in range(3):
        out[i] = m[i, 0] * x[0] + m[i, 1] * x[1] + m[i, 2] * x[2]
    return out


@njit(cache=True, inline="always")
def mattvec3(m, x):
    """m^T x for a (3, 3) matrix.

    Parameters
    ----------
    m : (3, 3) float
        Matrix, typically a rotation a->b (columns: a's axes in b's components).
    x : (3,) float
        Vector, frame b.

    Returns
    -------
    (3,) float
        m^T x, frame a (for a rotation, the inverse map of :func:`matvec3`).
    """
    out = np.empty(3)
    for i in range(3):
        out[i] = m[0, i] * x[0] + m[1, i] * x[1] + m[2, i] * x[2]
    return out


@njit(cache=True, inline="always")
def matmat3(a, b):
    """a b for (3, 3) matrices.

    Parameters
    ----------
    a, b : (3, 3) float
        Typically rotations b: x->y and a: y->z (columns: source axes in target components).

    Returns
    -------
    (3, 3) float
        a b, the rotation x->z.
    """
    out = np.empty((3, 3))
    for i in range(3):
        for k in range(3):
            out[i, k] = a[i, 0] * b[0, k] + a[i, 1] * b[1, k] + a[i, 2] * b[2, k]
    return out


@njit(cache=True, inline="always")
def mattmat3(a, b):
    """a^T b for (3, 3) matrices.

    Parameters
    ----------
    a, b : (3, 3) float
        Typically rotations a: y->z and b: x->z (columns: source axes in target components).

    Returns
    -------
    (3, 3) float
        a^T b, the rotation x->y.
    """
    out = np.empty((3, 3))
    for i in range(3):
        for k in range(3):
            out[i, k] = a[0, i] * b[0, k] + a[1, i] * b[1, k] + a[2, i] * b[2, k]
    return out


@njit(cache=True)
def solve3(a, b):
    """x with a x = b for a (3, 3) matrix (Cramer's rule; a must be regular).

    Parameters
    ----------
    a : (3, 3) float
        Regular matrix (e.g. a Newton matrix, kg).
    b : (3,) float
        Right-hand side (e.g. a residual impulse, N s).

    Returns
    -------
    (3,) float
        Solution x, in the frame and unit b / a.
    """
    c00 = a[1, 1] * a[2, 2] - a[1, 2] * a[2, 1]
    c01 = a[1, 2] * a[2, 0] - a[1, 0] * a[2, 2]
    c02 = a[1, 0] * a[2, 1] - a[1, 1] * a[2, 0]
    inv_det = 1.0 / (a[0, 0] * c00 + a[0, 1] * c01 + a[0, 2] * c02)
    out = np.empty(3)
    out[0] = (b[0] * c00 + b[1] * (a[0, 2] * a[2, 1] - a[0, 1] * a[2, 2]) + b[2] * (a[0, 1] * a[1, 2] - a[0, 2] * a[1, 1])) * inv_det
    out[1] = (b[0] * c01 + b[1] * (a[0, 0] * a[2, 2] - a[0, 2] * a[2, 0]) + b[2] * (a[0, 2] * a[1, 0] - a[0, 0] * a[1, 2])) * inv_det
    out[2] = (b[0] * c02 + b[1] * (a[0, 1] * a[2, 0] - a[0, 0] * a[2, 1]) + b[2] * (a[0, 0] * a[1, 1] - a[0, 1] * a[1, 0])) * inv_det
    return out
