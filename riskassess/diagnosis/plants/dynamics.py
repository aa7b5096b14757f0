"""Fast compiled model of the diagnosis scenarios: rigid body, or main body + hinged appendage.

The fit needs hundreds of simulations per candidate effect, so the equations are integrated
here with a fixed-step RK4 in numba; :mod:`riskassess.diagnosis.exudyn_model` builds the same scenario in
Exudyn (penalty hinge, user-function loads) and ``tests/diagnosis/test_dynamics.py`` checks
that the two agree.

Equations (generalized speeds u = (omega_B, hinge rate); Kane's method). The two bodies move
about the system CoM as the main body plus a relative particle of the reduced mass
m_r = m_m m_a / M at d = p + s(theta) (appendage CoM minus main CoM, B):

.. math::
    \\mathbf M(\\theta)\\,\\dot u = \\mathbf f(t, x),\\quad
    \\mathbf M = P_m^T J_m P_m + P_a^T J_a P_a + m_r J_w^T J_w,

with P_m = [I | 0], P_a = [I | a] (partial angular velocities of main body and appendage),
J_w = [-[d] | a x s] (partial velocities of the relative particle); f holds the gyroscopic
and velocity-product terms, the hinge torque -k theta - c theta' (+ effects), the per-body
point-mass tidal (Clohessy-Wiltshire) force on the relative particle and the effects' loads.
The system CoM follows the linearised relative orbit in the inertial frame I (= LVLH at
t = 0): :math:`\\ddot\\rho = n^2 (3 (\\hat r\\cdot\\rho)\\hat r - \\rho) + F/M`, with
:math:`\\hat r = (\\cos nt, \\sin nt, 0)` the chaser's radial direction; this is the
Clohessy-Wiltshire equation (seed paper eq. (9)) written in non-rotating axes.

State x: the base state (``BASE_STATE_SIZE``): quaternion B->I [w, x, y, z], omega_B (rad/s),
hinge angle (rad), hinge rate (rad/s), system CoM rho_I (m), its velocity (m/s); then the effects' own
states, allocated when the model is built (:func:`initial_state`): each effect declares how many it
needs and their values at t = 0 (``Effect.extra_states``, ``Effect.initial_extra_states``), and its
block follows the base state (a pair's second effect's block follows the first's,
:mod:`riskassess.diagnosis.composite`). The core knows nothing of what they mean.

Effect laws are numba functions ``law(t, x, p, env, load, xe, xe_rate)`` that ADD to ``load``
(``LOAD_SIZE``): torque on the main body (B, N m), torque on the appendage (B, N m), hinge
torque on the appendage about the axis (N m), force on the system CoM (I, N). ``xe`` is the law's
own block of the state (a view, index 0 its first state) and ``xe_rate`` the same block of the
derivative, to which it adds its states' rates. ``env`` holds the plant's constants (layout ``E_*``).
"""
from __future__ import annotations

import numpy as np
from numba import njit, types

from multibody.maths.rk4 import rk4_integrator
from multibody.maths.rotations import quaternion_from_matrix, quaternion_to_matrix
from riskassess.diagnosis.plants.plant import Plant

_VECTOR = types.float64[::1]
#: numba signature of an effect law ``law(t, x, p, env, load, xe, xe_rate)``; laws are compiled eagerly
#: with it so that one compiled integrator (taking the law as a first-class function) serves every effect.
LAW_SIGNATURE = types.void(types.float64, _VECTOR, _VECTOR, _VECTOR, _VECTOR, _VECTOR, _VECTOR)
_LAW = types.FunctionType(LAW_SIGNATURE)

# state layout: the base state; the effects' own states follow from BASE_STATE_SIZE (X_EXTRA)
X_Q, X_W, X_TH, X_THD, X_R, X_V, X_EXTRA = 0, 4, 7, 8, 9, 12, 15
BASE_STATE_SIZE = X_EXTRA
# load layout
L_TM, L_TA, L_TH, L_F = 0, 3, 6, 7
LOAD_SIZE = 10
# env layout
E_N, E_INC, E_U0, E_RADIUS, E_MM, E_MA, E_JM, E_JA, E_AXIS, E_HINGE, E_S0, E_K, E_C, E_HINGED = (
    0, 1, 2, 3, 4, 5, 6, 15, 24, 27, 30, 33, 34, 35)
ENV_SIZE = 36


def environment(plant: Plant) -> np.ndarray:
    """The ``env`` array of a plant (layout ``E_*``).

    Parameters
    ----------
    plant : Plant
        The scenario's plant (SI).

    Returns
    -------
    env : (ENV_SIZE,) float
        Mean motion (rad/s), inclination and argument of latitude at t = 0 (rad), orbit radius (m),
        masses (kg), inertias (kg m^2, row-major, B axes), hinge axis (-), hinge point and appendage
        CoM offsets (m, B), spring (N m/rad), damper (N m s/rad), hinged flag (0/1).
    """
    env = np.zeros(ENV_SIZE)
    env[[E_N, E_INC, E_U0, E_RADIUS, E_MM, E_MA, E_K, E_C, E_HINGED]] = (
        plant.mean_motion, plant.inclination, plant.latitude0, plant.orbit_radius, plant.mass_main,
        plant.mass_appendage, plant.stiffness, plant.damping, float(plant.hinged))
    env[E_JM:E_JM + 9] = plant.inertia_main.ravel()
    env[E_JA:E_JA + 9] = plant.inertia_appendage.ravel()
    env[E_AXIS:E_AXIS + 3] = plant.axis
    env[E_HINGE:E_HINGE + 3] = plant.hinge_main
    env[E_S0:E_S0 + 3] = plant.appendage_from_hinge
    return env


def initial_state(plant: Plant, extra_states=()) -> np.ndarray:
    """State at t = 0: the tracked point and the CoM velocity in LVLH give the system CoM in I; the
    effects' own states follow the base state.

    Parameters
    ----------
    plant : Plant
        The scenario's plant (initial attitude B -> I, omega_B, hinge angle and rate, tracked point
        and CoM velocity in LVLH at t = 0).
    extra_states : (e,) float, optional
        The effect's own states at t = 0 (``Effect.initial_extra_states``; a pair's: the first
        effect's, then the second's), each in its own unit; default none.

    Returns
    -------
    x0 : (BASE_STATE_SIZE + e,) float
        Layout ``X_*``, then ``extra_states`` from ``X_EXTRA``; the CoM velocity is the inertial one,
        v_LVLH + n z x rho (m/s, I).
    """
    extra_states = np.asarray(extra_states, float)
    x = np.zeros(BASE_STATE_SIZE + extra_states.size)
    x[X_Q:X_Q + 4] = quaternion_from_matrix(np.ascontiguousarray(plant.attitude0))
    x[X_W:X_W + 3] = plant.omega0
    x[X_TH], x[X_THD] = plant.hinge_angle0, plant.hinge_rate0
    share = plant.mass_appendage / plant.total_mass
    main_com = plant.position0 - plant.attitude0 @ plant.origin_main
    offset = plant.hinge_main + axis_rotation(plant.axis, plant.hinge_angle0) @ plant.appendage_from_hinge
    rho = main_com + plant.attitude0 @ (share * offset)
    x[X_R:X_R + 3] = rho
    x[X_V:X_V + 3] = plant.velocity0 + np.cross([0.0, 0.0, plant.mean_motion], rho)
    x[X_EXTRA:] = extra_states
    return x


# ------------------------------------------------------------------------------ kinematics
@njit(cache=True)
def observe(states, times, env, origin_main):
    """Channels (k, 12) from states: omega_B (3), quaternion B->LVLH(t) (4), tracked point in LVLH
    (3), hinge angle and rate; see :mod:`riskassess.diagnosis.observation`.

    Parameters
    ----------
    states : (k, n) float
        Fast-model states, layout ``X_*`` (the effects' states after the base state are not read).
    times : (k,) float
        Their times (s) from t = 0.
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    origin_main : (3,) float
        Tracked point (target-frame origin) minus main CoM, B (m).

    Returns
    -------
    channels : (k, 12) float
        omega_B (rad/s), quaternion B -> LVLH(t) (scalar first, -), tracked point, LVLH(t) (m),
        hinge angle (rad) and rate (rad/s).
    """
    n = env[E_N]
    share = env[E_MA] / (env[E_MM] + env[E_MA])
    out = np.empty((states.shape[0], 12))
    for k in range(states.shape[0]):
        x = states[k]
        c, s = np.cos(0.5 * n * times[k]), np.sin(0.5 * n * times[k])    # I -> LVLH: -n t about z
        w, a, b, d = x[0], x[1], x[2], x[3]
        out[k, 3:7] = (c * w + s * d, c * a + s * b, c * b - s * a, c * d - s * w)
        offset = origin_main.copy()
        if env[E_HINGED] != 0.0:
            offset -= share * appendage_state(env, x[X_TH])[1]
        p = x[X_R:X_R + 3] + quaternion_to_matrix(x[0:4]) @ offset
        cn, sn = np.cos(n * times[k]), np.sin(n * times[k])
        out[k, 7], out[k, 8], out[k, 9] = cn * p[0] + sn * p[1], -sn * p[0] + cn * p[1], p[2]
        out[k, 0:3] = x[X_W:X_W + 3]
        out[k, 10], out[k, 11] = x[X_TH], x[X_THD]
    return out


@njit(cache=True)
def axis_rotation(axis, angle):
    """Rodrigues: rotation by ``angle`` (rad) about the unit ``axis``.

    Parameters
    ----------
    axis : (3,) float
        Unit rotation axis (-), in the frame the matrix acts in.
    angle : float
        Rotation angle (rad), right-handed.

    Returns
    -------
    rotation : (3, 3) float
        Rotated frame -> reference frame (e.g. appendage at ``angle`` -> B for the hinge axis).
    """
    c, s = np.cos(angle), np.sin(angle)
    out = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            out[i, j] = (1.0 - c) * axis[i] * axis[j] + (c if i == j else 0.0)
    out[0, 1] -= s * axis[2]
    out[0, 2] += s * axis[1]
    out[1, 0] += s * axis[2]
    out[1, 2] -= s * axis[0]
    out[2, 0] -= s * axis[1]
    out[2, 1] += s * axis[0]
    return out


@njit(cache=True)
def appendage_state(env, angle):
    """Appendage CoM from the hinge s (m), from the main CoM d (m), and its inertia (kg m^2), all B.

    Parameters
    ----------
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    angle : float
        Hinge angle (rad).

    Returns
    -------
    s : (3,) float
        Appendage CoM minus hinge point, B (m).
    d : (3,) float
        Appendage CoM minus main CoM, B (m).
    inertia : (3, 3) float
        Appendage inertia about its CoM, B axes (kg m^2).
    """
    rot = axis_rotation(env[E_AXIS:E_AXIS + 3], angle)
    s = rot @ env[E_S0:E_S0 + 3]
    inertia = rot @ env[E_JA:E_JA + 9].reshape(3, 3) @ rot.T
    return s, env[E_HINGE:E_HINGE + 3] + s, inertia


@njit(cache=True)
def radial_inertial(n, t):
    """Chaser radial unit vector (LVLH x) at time t, expressed in I (-).

    Parameters
    ----------
    n : float
        Mean motion (rad/s).
    t : float
        Time (s) from t = 0.

    Returns
    -------
    r_hat_inertial : (3,) float
        (cos nt, sin nt, 0), I (-).
    """
    return np.array([np.cos(n * t), np.sin(n * t), 0.0])


# ------------------------------------------------------------------------------ equations
@njit(cache=True)
def solve_spd(m, f):
    """Solution of m u = f for a small symmetric positive definite m (Cholesky, in place on copies).

    Parameters
    ----------
    m : (n, n) float
        Symmetric positive definite matrix (here the Kane mass matrix, kg m^2).
    f : (n,) float
        Right-hand side (here generalized forces, N m).

    Returns
    -------
    u : (n,) float
        m^-1 f (here generalized accelerations, rad/s^2).
    """
    n = f.shape[0]
    low = np.zeros((n, n))
    for i in range(n):
        for j in range(i + 1):
            acc = m[i, j]
            for k in range(j):
                acc -= low[i, k] * low[j, k]
            low[i, j] = np.sqrt(acc) if i == j else acc / low[j, j]
    y = np.empty(n)
    for i in range(n):
        acc = f[i]
        for k in range(i):
            acc -= low[i, k] * y[k]
        y[i] = acc / low[i, i]
    for i in range(n - 1, -1, -1):
        acc = y[i]
        for k in range(i + 1, n):
            acc -= low[k, i] * y[k]
        y[i] = acc / low[i, i]
    return y


# 3-vectors as tuples and 3 x 3 matrices as row-major 9-sequences (t-prefixed helpers, also used by the
# effect laws): the hot path allocates nothing but the load, the derivative and the 4 x 4 system (the
# allocating version cost 7x more per evaluation with the hinge).
@njit(cache=True, inline="always")
def tcross(a, b):
    """Cross product a x b of two 3-vectors in the same frame, as a tuple.

    Parameters
    ----------
    a, b : (3,) float or 3-tuple
        Vectors, one frame.

    Returns
    -------
    c : tuple of 3 float
        a x b, same frame.
    """
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


@njit(cache=True, inline="always")
def tdot(a, b):
    """Dot product a . b of two 3-vectors in the same frame.

    Parameters
    ----------
    a, b : (3,) float or 3-tuple
        Vectors, one frame.

    Returns
    -------
    dot : float
    """
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, inline="always")
def tlin(ca, a, cb, b):
    """ca a + cb b.

    Parameters
    ----------
    ca, cb : float
        Coefficients.
    a, b : (3,) float or 3-tuple
        Vectors, one frame.

    Returns
    -------
    c : tuple of 3 float
        Same frame.
    """
    return (ca * a[0] + cb * b[0], ca * a[1] + cb * b[1], ca * a[2] + cb * b[2])


@njit(cache=True, inline="always")
def tmv(m, v):
    """Matrix times vector, m v, with m a row-major 9-sequence.

    Parameters
    ----------
    m : (9,) float or 9-tuple
        3 x 3 matrix, row-major (a rotation a -> b, or an inertia).
    v : (3,) float or 3-tuple
        Vector (frame a).

    Returns
    -------
    w : tuple of 3 float
        m v (frame b).
    """
    return (m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
            m[6] * v[0] + m[7] * v[1] + m[8] * v[2])


@njit(cache=True, inline="always")
def tmtv(m, v):
    """Transposed matrix times vector, m^T v, with m a row-major 9-sequence.

    Parameters
    ----------
    m : (9,) float or 9-tuple
        3 x 3 matrix, row-major (a rotation a -> b).
    v : (3,) float or 3-tuple
        Vector (frame b).

    Returns
    -------
    w : tuple of 3 float
        m^T v (frame a).
    """
    return (m[0] * v[0] + m[3] * v[1] + m[6] * v[2], m[1] * v[0] + m[4] * v[1] + m[7] * v[2],
            m[2] * v[0] + m[5] * v[1] + m[8] * v[2])


@njit(cache=True, inline="always")
def quaternion_rows(q):
    """Rotation matrix of a unit quaternion, row-major 9-tuple.

    Parameters
    ----------
    q : (4,) float
        Unit quaternion [w, x, y, z], scalar first (here B -> I).

    Returns
    -------
    rows : tuple of 9 float
        The matrix (B -> I: maps B components to I components), row-major.
    """
    w, x, y, z = q[0], q[1], q[2], q[3]
    return (1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y),
            2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
            2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y))


@njit(cache=True, inline="always")
def axis_rows(a, angle):
    """Rodrigues rotation about a unit axis, row-major 9-tuple (:func:`axis_rotation` without allocating).

    Parameters
    ----------
    a : (3,) float or 3-tuple
        Unit axis (-), here the hinge axis in B.
    angle : float
        Rotation angle (rad), here the hinge angle.

    Returns
    -------
    rows : tuple of 9 float
        Appendage -> B at that hinge angle, row-major.
    """
    c, s = np.cos(angle), np.sin(angle)
    k = 1.0 - c
    return (k * a[0] * a[0] + c, k * a[0] * a[1] - s * a[2], k * a[0] * a[2] + s * a[1],
            k * a[1] * a[0] + s * a[2], k * a[1] * a[1] + c, k * a[1] * a[2] - s * a[0],
            k * a[2] * a[0] - s * a[1], k * a[2] * a[1] + s * a[0], k * a[2] * a[2] + c)


@njit(cache=True, inline="always")
def sandwich(rot, inertia, v):
    """rot inertia rot^T v: the appendage's inertia (given at zero angle) applied in B.

    Parameters
    ----------
    rot : 9-tuple
        Appendage -> B rotation, row-major (:func:`axis_rows`).
    inertia : (9,) float
        Appendage inertia about its CoM at zero angle, B axes, row-major (kg m^2).
    v : (3,) float or 3-tuple
        Angular velocity or direction, B (rad/s or -).

    Returns
    -------
    w : tuple of 3 float
        J_a(theta) v, B (kg m^2 times the unit of ``v``).
    """
    return tmv(rot, tmv(inertia, tmtv(rot, v)))


@njit(cache=True)
def _rotation_rates(t, x, env, load, rot):
    """(omega_B', hinge acceleration) from the Kane equations (4 x 4; 3 x 3 without appendage);
    ``rot`` is B -> I as a row-major 9-tuple."""
    w = (x[X_W], x[X_W + 1], x[X_W + 2])
    jm = env[E_JM:E_JM + 9]
    rhs_w = tlin(1.0, (load[L_TM], load[L_TM + 1], load[L_TM + 2]), -1.0, tcross(w, tmv(jm, w)))
    hinged = env[E_HINGED] != 0.0
    m = np.zeros((4, 4) if hinged else (3, 3))
    f = np.empty(4 if hinged else 3)
    for i in range(3):
        for j in range(3):
            m[i, j] = jm[3 * i + j]
    if not hinged:
        f[0], f[1], f[2] = rhs_w
        u = solve_spd(m, f)
        return (u[0], u[1], u[2]), 0.0
    a = (env[E_AXIS], env[E_AXIS + 1], env[E_AXIS + 2])
    theta, rate = x[X_TH], x[X_THD]
    ra = axis_rows(a, theta)
    ja0 = env[E_JA:E_JA + 9]
    s = tmv(ra, (env[E_S0], env[E_S0 + 1], env[E_S0 + 2]))
    d = (env[E_HINGE] + s[0], env[E_HINGE + 1] + s[1], env[E_HINGE + 2] + s[2])
    mr = env[E_MM] * env[E_MA] / (env[E_MM] + env[E_MA])
    n = env[E_N]
    axs = tcross(a, s)
    r_b = tmtv(rot, (np.cos(n * t), np.sin(n * t), 0.0))
    om = tlin(1.0, w, rate, a)
    w_rel = tlin(1.0, tcross(w, d), rate, axs)
    kappa_w = tlin(1.0, tlin(rate, tcross(w, axs), rate * rate, tcross(a, axs)), 1.0, tcross(w, w_rel))
    f_rel = tlin(mr * n * n, tlin(3.0 * tdot(r_b, d), r_b, -1.0, d), -mr, kappa_w)
    t_app = tlin(1.0, tlin(1.0, (load[L_TA], load[L_TA + 1], load[L_TA + 2]), -rate, sandwich(ra, ja0, tcross(w, a))),
                 -1.0, tcross(om, sandwich(ra, ja0, om)))
    tau_h = -env[E_K] * theta - env[E_C] * rate + load[L_TH]
    dd = tdot(d, d)
    for j in range(3):
        e = (1.0 if j == 0 else 0.0, 1.0 if j == 1 else 0.0, 1.0 if j == 2 else 0.0)
        column = sandwich(ra, ja0, e)
        for i in range(3):
            m[i, j] += column[i] - mr * d[i] * d[j] + (mr * dd if i == j else 0.0)
    ja_a = sandwich(ra, ja0, a)
    b = tlin(1.0, ja_a, mr, tcross(d, axs))
    for i in range(3):
        m[i, 3] = b[i]
        m[3, i] = b[i]
    m[3, 3] = tdot(a, ja_a) + mr * tdot(axs, axs)
    moment = tlin(1.0, tlin(1.0, rhs_w, 1.0, t_app), 1.0, tcross(d, f_rel))
    f[0], f[1], f[2] = moment
    f[3] = tdot(a, t_app) + tau_h + tdot(axs, f_rel)
    u = solve_spd(m, f)
    return (u[0], u[1], u[2]), u[3]


@njit(_VECTOR(types.float64, _VECTOR, _LAW, _VECTOR, _VECTOR), cache=True)
def derivative(t, x, law, p, env):
    """dx/dt of the state (layout ``X_*``, then the effect's own states) with the effect ``law`` and its
    parameters ``p``.

    Parameters
    ----------
    t : float
        Time (s) from t = 0.
    x : (BASE_STATE_SIZE + e,) float
        State, layout ``X_*`` (see the module doc), then the effect's ``e`` own states.
    law : compiled function
        Effect load law ``law(t, x, p, env, load, xe, xe_rate)`` (``LAW_SIGNATURE``); it is handed the
        state's and the derivative's blocks from ``X_EXTRA`` as ``xe`` and ``xe_rate``.
    p : (j,) float
        The law's parameters.
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.

    Returns
    -------
    dx : (BASE_STATE_SIZE + e,) float
        Time derivative of every state, in its unit per second.
    """
    load = np.zeros(LOAD_SIZE)
    dx = np.zeros(x.shape[0])
    law(t, x, p, env, load, x[X_EXTRA:], dx[X_EXTRA:])
    q = x[X_Q:X_Q + 4]
    w = (x[X_W], x[X_W + 1], x[X_W + 2])
    dx[0] = -0.5 * (q[1] * w[0] + q[2] * w[1] + q[3] * w[2])
    dx[1] = 0.5 * (q[0] * w[0] + q[2] * w[2] - q[3] * w[1])
    dx[2] = 0.5 * (q[0] * w[1] + q[3] * w[0] - q[1] * w[2])
    dx[3] = 0.5 * (q[0] * w[2] + q[1] * w[1] - q[2] * w[0])
    dw, dd = _rotation_rates(t, x, env, load, quaternion_rows(q))
    dx[X_W], dx[X_W + 1], dx[X_W + 2] = dw
    dx[X_TH] = x[X_THD]
    dx[X_THD] = dd
    n = env[E_N]
    r_hat = (np.cos(n * t), np.sin(n * t), 0.0)
    rho = (x[X_R], x[X_R + 1], x[X_R + 2])
    tidal = tlin(3.0 * n * n * tdot(r_hat, rho), r_hat, -n * n, rho)
    mass = env[E_MM] + env[E_MA]
    for i in range(3):
        dx[X_R + i] = x[X_V + i]
        dx[X_V + i] = tidal[i] + load[L_F + i] / mass
    return dx


#: The shared RK4 (multibody/maths/rk4.py) with :func:`derivative` bound in: a direct call per stage.
_rk4 = rk4_integrator(derivative, X_Q)


@njit(types.float64[:, ::1](_LAW, _VECTOR, _VECTOR, _VECTOR, _VECTOR, types.float64), cache=True)
def integrate(law, p, env, x0, times, max_step):
    """States at ``times`` (s, non-decreasing, >= 0) from ``x0`` at t = 0, by the shared RK4
    (:func:`multibody.maths.rk4.rk4_integrator` of :func:`derivative`) with steps no longer than ``max_step`` (s);
    the quaternion is renormalised every step.

    Parameters
    ----------
    law : compiled function
        Effect load law (``LAW_SIGNATURE``); :func:`no_load` for the nominal model.
    p : (j,) float
        The law's parameters (at least one entry).
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    x0 : (BASE_STATE_SIZE + e,) float
        State at t = 0 (:func:`initial_state`, with the effect's own states).
    times : (k,) float
        Output times (s).
    max_step : float
        Longest RK4 step (s).

    Returns
    -------
    states : (k, BASE_STATE_SIZE + e) float
        Layout ``X_*``, then the effect's states.
    """
    return _rk4((law, p, env), x0, 0.0, times, max_step)


@njit(LAW_SIGNATURE, cache=True)
def no_load(t, x, p, env, load, xe, xe_rate):
    """The nominal model: no effect.

    Parameters
    ----------
    t : float
        Time (s) from the record's t = 0.
    x : (BASE_STATE_SIZE + e,) float
        Fast-model state, layout ``X_*`` of :mod:`riskassess.diagnosis.plants.dynamics` (quaternion B -> I,
        omega_B (rad/s), hinge angle (rad) and rate (rad/s), CoM rho_I (m) and velocity (m/s)), then
        the effects' own states.
    p : (j,) float
        Not used.
    env : (ENV_SIZE,) float
        Plant constants, layout ``E_*``.
    load : (LOAD_SIZE,) float
        Loads, layout ``L_*``, added to in place: nothing.
    xe, xe_rate : (0,) float
        The law's own states and their rates: none.
    """
    return


def angular_momentum_inertial(plant: Plant, states) -> np.ndarray:
    """Angular momentum of the bodies about the system CoM, I (kg m^2/s), (k, 3); without the
    effects' states (a damper's momentum is added by its effect's tests).

    Parameters
    ----------
    plant : Plant
        The scenario's plant.
    states : (k, n) or (n,) float
        States, layout ``X_*`` (the effects' states, after the base state, are not read).

    Returns
    -------
    h_inertial : (k, 3) float
        Main body and appendage angular momentum about the system CoM, I (kg m^2/s).
    """
    env = environment(plant)
    out = []
    for x in np.atleast_2d(states):
        rot = quaternion_to_matrix(x[X_Q:X_Q + 4])
        w = x[X_W:X_W + 3]
        h = plant.inertia_main @ w
        if plant.hinged:
            s, d, ja = appendage_state(env, x[X_TH])
            mr = plant.mass_main * plant.mass_appendage / plant.total_mass
            h = h + ja @ (w + x[X_THD] * plant.axis) + mr * np.cross(d, np.cross(w, d) + x[X_THD] * np.cross(plant.axis, s))
        out.append(rot @ h)
    return np.array(out)
