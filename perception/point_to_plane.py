"""Point-to-plane alignment terms: residuals, Tukey-weighted normal equations and information.

A scan point q (frame B, posed) matched to the model point m with unit normal n has the
residual r = n.(q - m); its gradient with respect to a small left rotation/translation
(rotation vector, translation) of the pose is J = [(q x n), n]. One Gauss-Newton step of the
robust alignment solves (sum w J^T J) x = -sum w J^T r with Tukey weights
w = (1 - (r / k)^2)^2 for |r| < k, 0 beyond (Zhang 1994; Rusinkiewicz & Levoy 2001).
"""
from __future__ import annotations

import numpy as np
from numba import njit


def point_to_plane_information(points_body, normals, sigma) -> np.ndarray:
    """Information (6, 6) of a point-to-plane alignment of scan points (n, 3) (B frame) on model
    planes with normals (n, 3), residual scatter ``sigma`` (m): J^T J / sigma^2.

    Parameters
    ----------
    points_body : (n, 3) float
        Posed scan points (m, frame B).
    normals : (n, 3) float
        Unit normals of their matched model points (frame B).
    sigma : float
        Point-to-plane residual scatter, 1 sigma (m).

    Returns
    -------
    (6, 6) float
        Information of (rotation vector, translation), left perturbation, frame B
        (1/rad^2, 1/(rad m), 1/m^2 blocks).
    """
    jac = plane_jacobian(points_body, normals)
    return jac.T @ jac / sigma**2


def plane_jacobian(points_body, normals) -> np.ndarray:
    """Rows [(q x n), n] (n, 6); the cross product written out (np.cross costs more than the product on small arrays).

    Parameters
    ----------
    points_body : (n, 3) float
        Posed scan points q (m, frame B).
    normals : (n, 3) float
        Unit normals n of their matched model points (frame B).

    Returns
    -------
    (n, 6) float
        d r / d (rotation vector (rad), translation (m)): m/rad for the first three columns,
        - for the last three.
    """
    q, n = points_body, normals
    return np.column_stack([q[:, 1] * n[:, 2] - q[:, 2] * n[:, 1], q[:, 2] * n[:, 0] - q[:, 0] * n[:, 2],
                            q[:, 0] * n[:, 1] - q[:, 1] * n[:, 0], n])


@njit(cache=True)
def tukey_normal_equations(points_body, nearest, model_points, model_normals, tukey_k):
    """Hessian (6, 6), gradient (6,) = sum w J^T r, the weight sum and the number of weighted
    residuals, of the Tukey-weighted
    point-to-plane residuals of scan points (n, 3) matched to model points ``nearest`` (n,)
    (index len(model_points): unmatched, skipped); ``tukey_k`` (m) the weight's cut-off.

    Parameters
    ----------
    points_body : (n, 3) float
        Posed scan points (m, frame B).
    nearest : (n,) int
        Row of each point's matched model point; len(model_points) when unmatched.
    model_points : (k, 3) float
        Model points (m, frame B).
    model_normals : (k, 3) float
        Their unit normals (frame B).
    tukey_k : float
        Residual (m) beyond which a point gets weight 0.

    Returns
    -------
    hessian : (6, 6) float
        sum w J^T J over (rotation vector, translation), frame B.
    gradient : (6,) float
        sum w J^T r.
    weight_sum : float
        sum w (-).
    count : int
        Residuals with nonzero weight.
    """
    hessian = np.zeros((6, 6))
    gradient = np.zeros(6)
    weight_sum = 0.0
    count = 0
    jac = np.empty(6)
    for i in range(len(points_body)):
        j = nearest[i]
        if j >= len(model_points):
            continue
        q, m, n = points_body[i], model_points[j], model_normals[j]
        r = n[0] * (q[0] - m[0]) + n[1] * (q[1] - m[1]) + n[2] * (q[2] - m[2])
        u = r / tukey_k
        if u * u >= 1.0:
            continue
        w = (1.0 - u * u) ** 2
        jac[0] = q[1] * n[2] - q[2] * n[1]
        jac[1] = q[2] * n[0] - q[0] * n[2]
        jac[2] = q[0] * n[1] - q[1] * n[0]
        jac[3], jac[4], jac[5] = n[0], n[1], n[2]
        for a in range(6):
            gradient[a] += w * jac[a] * r
            for b in range(a, 6):
                hessian[a, b] += w * jac[a] * jac[b]
        weight_sum += w
        count += 1
    for a in range(6):
        for b in range(a):
            hessian[a, b] = hessian[b, a]
    return hessian, gradient, weight_sum, count
