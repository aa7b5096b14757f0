"""Torque-free rigid-body rotation (Euler-Poinsot) and its fit to a measured attitude sequence.

Frames: **T** principal-axis body frame; **B** the body frame of the registration model
(its axes are those of the world frame at the first scan); **W** the world frame the
attitudes are measured in (inertial; LVLH without orbit).

The paper (Tang et al. 2023, eq. 18) fits the normalized inertia to angular rates and
accelerations obtained by central differences of registered poses. Here that linear fit
(:func:`normalized_inertia_linear`) only gives the starting point; the estimate is the
maximum-likelihood fit of the whole torque-free trajectory to the measured attitudes
(:class:`TorqueFreeFit`), which needs no differentiation of noisy poses.
"""
from __future__ import annotations

import numpy as np
from numba import njit
from scipy.linalg import block_diag
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

from multibody.maths.rk4 import rk4_integrator
from perception.motion import integrated_autocorrelation_time


@njit(cache=True)
def _euler_rate(omega, j):
    """dω/dt of a torque-free body, principal frame: J ω' = -ω x J ω (Euler's equations)."""
    return np.array([(j[1] - j[2]) * omega[1] * omega[2] / j[0],
                     (j[2] - j[0]) * omega[2] * omega[0] / j[1],
                     (j[0] - j[1]) * omega[0] * omega[1] / j[2]])


@njit(cache=True)
def _torque_free_rate(t, x, j):
    """d/dt of the state x = [q (4), ω (3)] of a torque-free body with principal moments ``j``: dq/dt =
    q ⊗ (0, ω)/2 (q = [w, x, y, z] principal->world, ω rad/s principal frame) and Euler's equations
    (:func:`_euler_rate`, written out: one allocation per evaluation); ``t`` (s) is not read."""
    w, a, b, c = x[0], x[1], x[2], x[3]
    o0, o1, o2 = x[4], x[5], x[6]
    out = np.empty(7)
    out[0] = 0.5 * (-a * o0 - b * o1 - c * o2)
    out[1] = 0.5 * (w * o0 + b * o2 - c * o1)
    out[2] = 0.5 * (w * o1 + c * o0 - a * o2)
    out[3] = 0.5 * (w * o2 + a * o1 - b * o0)
    out[4] = (j[1] - j[2]) * o1 * o2 / j[0]
    out[5] = (j[2] - j[0]) * o2 * o0 / j[1]
    out[6] = (j[0] - j[1]) * o0 * o1 / j[2]
    return out


#: The shared RK4 (multibody/maths/rk4.py) with :func:`_torque_free_rate` bound in.
_rk4 = rk4_integrator(_torque_free_rate, 0)


@njit(cache=True)
def propagate_torque_free(q0, omega0, principal_moments, times, max_step):
    """Attitude quaternions (k, 4) [w, x, y, z] principal->world and rates (k, 3) (rad/s,
    principal frame) at ``times`` (s, increasing, ``times[0]`` the initial time), by the shared RK4
    (:func:`multibody.maths.rk4.rk4_integrator`) with steps no longer than ``max_step`` (s), the quaternion
    renormalised every step.

    Parameters
    ----------
    q0 : (4,) float
        Initial attitude quaternion [w, x, y, z], principal->world, unit norm.
    omega0 : (3,) float
        Initial angular rate (rad/s, principal frame).
    principal_moments : (3,) float
        Principal moments; only their ratios matter (normalized [J1, J2, 1] here, or kg m^2).
    times : (k,) float
        Output times (s), increasing; ``times[0]`` is the time of ``q0`` and ``omega0``.
    max_step : float
        Largest RK4 step (s).

    Returns
    -------
    qs : (k, 4) float
        Quaternions [w, x, y, z] principal->world at ``times``.
    omegas : (k, 3) float
        Angular rates (rad/s, principal frame) at ``times``.
    """
    x0 = np.empty(7)
    x0[0:4], x0[4:7] = q0, omega0
    states = _rk4((principal_moments,), x0, times[0], times, max_step)
    return np.ascontiguousarray(states[:, 0:4]), np.ascontiguousarray(states[:, 4:7])


def rotations_from_wxyz(q) -> Rotation:
    """Rotations from scalar-first quaternions (SciPy's are scalar-last).

    Parameters
    ----------
    q : (k, 4) float
        Unit quaternions [w, x, y, z]; the frames they map between are kept as they are.

    Returns
    -------
    Rotation
        The k rotations.
    """
    return Rotation.from_quat(np.asarray(q)[:, [1, 2, 3, 0]])


def normalized_inertia_linear(omega_body, omega_dot_body) -> np.ndarray:
    """Normalized inertia (3, 3), scaled to trace 3, body frame, from
    rates (k, 3) and accelerations (k, 3) through the torque-free Euler equation
    J ω' + ω x J ω = 0, linear and homogeneous in the six entries of J (Tang et al. 2023,
    eq. 18): the right singular vector of the smallest singular value.

    Parameters
    ----------
    omega_body : (k, 3) float
        Angular rates (rad/s, body frame B).
    omega_dot_body : (k, 3) float
        Angular accelerations at the same instants (rad/s^2, body frame B).

    Returns
    -------
    (3, 3) float
        Symmetric normalized inertia (-, trace 3, body frame B).
    """
    w = np.asarray(omega_body, float)
    a = np.asarray(omega_dot_body, float)
    # J = [[j0, j3, j4], [j3, j1, j5], [j4, j5, j2]]
    basis = [np.diag([1.0, 0, 0]), np.diag([0, 1.0, 0]), np.diag([0, 0, 1.0])]
    for (r, c) in ((0, 1), (0, 2), (1, 2)):
        e = np.zeros((3, 3))
        e[r, c] = e[c, r] = 1.0
        basis.append(e)
    columns = [a @ e.T + np.cross(w, w @ e.T) for e in basis]   # (k, 3) each
    matrix = np.stack([c.ravel() for c in columns], axis=1)
    _, _, vt = np.linalg.svd(matrix, full_matrices=False)
    j = sum(coef * e for coef, e in zip(vt[-1], basis))
    if np.trace(j) < 0:
        j = -j
    return 3.0 * j / np.trace(j)


def principal_frame(normalized_inertia) -> tuple[np.ndarray, np.ndarray]:
    """Principal moments (3,) divided by the smallest, sorted so the last is 1 (the paper's
    C axis is the minimum), and the rotation T->B (3, 3) whose columns are the principal axes.

    Parameters
    ----------
    normalized_inertia : (3, 3) float
        Symmetric inertia in frame B, in any scale (e.g. from :func:`normalized_inertia_linear`).

    Returns
    -------
    moments : (3,) float
        [A/C, B/C, 1] (-), largest first.
    principal_to_body : (3, 3) float
        Rotation T->B (a proper rotation, det +1).
    """
    values, vectors = np.linalg.eigh(normalized_inertia)
    order = np.argsort(values)[::-1]
    values, vectors = values[order], vectors[:, order]
    if np.linalg.det(vectors) < 0:
        vectors[:, 2] *= -1
    return values / values[-1], vectors


class TorqueFreeFit:
    """Maximum-likelihood torque-free motion through measured attitudes (scikit-learn style).

    Parameters
    ----------
    moments : (3,) float or None   Known normalized principal moments [J1, J2, 1]; None: estimate.
    principal_to_body : (3, 3) float or None  Known rotation T->B; None: estimate (needs ``moments`` None).
    max_step : float               RK4 step limit of the propagation (s).
    first_span : float             Length of the first fitted span (s); doubled until all data are in.

    Attributes (after :meth:`fit`)
    ------------------------------
    moments_ : (3,) float           [A/C, B/C, 1], normalized principal moments (Tang et al. 2023, eq. 19).
    principal_to_body_ : (3, 3)     T->B.
    omega0_principal_ : (3,) float  Rate at ``times[0]`` (rad/s), principal frame.
    time0_ : float                  ``times[0]`` (s), the time of the fitted initial state.
    principal_to_world0_ : (3, 3)   T->W at ``times[0]``.
    residual_rms_ : float           Weighted RMS of the attitude residuals (-; 1 when the weights are right).
    covariance_ : (p, p) float      Parameter covariance (J^T J)^-1 scaled by the residual variance
                                    and by the residuals' correlation time.
    correlation_time_ : float       Integrated autocorrelation time of the residuals (frames).
    jacobian_ : (3k, p) float       Jacobian of the weighted residuals at the optimum.
    weights_ : (k, 3, 3) float      The weights fitted with (1/rad).
    weighted_residuals_ : (k, 3)    Weighted attitude residuals W_k e_k (-).
    attitude_covariance_scale_ : float   After :meth:`add_attitude_covariance`: the scale it applied (-).
    """

    def __init__(self, moments=None, principal_to_body=None, max_step=0.01, first_span=5.0):
        self.moments = moments
        self.principal_to_body = principal_to_body
        self.max_step = max_step
        self.first_span = first_span

    # -- parameter vector ------------------------------------------------------------
    def _unpack(self, p):
        t2w = Rotation.from_rotvec(p[:3]) * self._t2w_ref
        omega = p[3:6]
        if self.moments is None:
            moments = np.array([np.exp(p[6]), np.exp(p[7]), 1.0])
            t2b = (Rotation.from_rotvec(p[8:11]) * self._t2b_ref).as_matrix()
        else:
            moments = np.asarray(self.moments, float)
            t2b = np.asarray(self.principal_to_body, float)
        return t2w, omega, moments, t2b

    def predict_body_to_world(self, times) -> Rotation:
        """Attitudes B->W at ``times`` (s) of the fitted motion.

        Parameters
        ----------
        times : (k,) float
            Times (s) on the clock of the ``times`` given to :meth:`fit`, increasing, the first
            being the fit's ``times[0]`` (the propagation starts there).

        Returns
        -------
        Rotation
            The k attitudes body B -> world W.
        """
        t2w, omega, moments, t2b = self._unpack(self._p)
        return self._body_to_world(t2w, omega, moments, t2b, np.asarray(times, float))

    def _body_to_world(self, t2w, omega, moments, t2b, times):
        q0 = t2w.as_quat()[[3, 0, 1, 2]]
        qs, _ = propagate_torque_free(q0, omega, moments, times, self.max_step)
        return rotations_from_wxyz(qs) * Rotation.from_matrix(t2b.T)

    def _residuals(self, p, times, measured_inv, weights):
        t2w, omega, moments, t2b = self._unpack(p)
        predicted = self._body_to_world(t2w, omega, moments, t2b, times)
        error = (measured_inv * predicted).as_rotvec()             # B frame, small
        return np.einsum("kij,kj->ki", weights, error).ravel()

    def _bounds(self, size):
        """Moments ratios kept within [1/2, 2] of the smallest: a rigid body's principal moments
        obey the triangle inequality (each at most the sum of the others), so no ratio between
        them exceeds 2; the bound stops short spans from wandering into a degenerate top."""
        lower, upper = np.full(size, -np.inf), np.full(size, np.inf)
        if self.moments is None:
            lower[6:8], upper[6:8] = np.log(0.5), np.log(2.0)
        return lower, upper

    # -- fitting ---------------------------------------------------------------------
    def fit(self, times, body_to_world: Rotation, weights, omega0_body, moments0=None, principal_to_body0=None):
        """Fit the motion through the attitudes.

        Parameters
        ----------
        times : (k,) float              (s)
        body_to_world : Rotation (k,)   Measured attitudes B->W.
        weights : (k, 3, 3) float       Square roots of the attitude information (1/rad), B frame.
        omega0_body : (3,) float        Starting rate at ``times[0]`` (rad/s), B frame.
        moments0 : (3,) float           Starting [A/C, B/C, 1] (-); ignored when ``moments`` is known.
        principal_to_body0 : (3, 3)     Starting rotation T->B; ignored when ``moments`` is known.

        Returns
        -------
        TorqueFreeFit
            ``self``, with the fitted attributes set.
        """
        times = np.asarray(times, float)
        if self.moments is None:
            self._t2b_ref = Rotation.from_matrix(principal_to_body0)
            t2b = principal_to_body0
        else:
            t2b = np.asarray(self.principal_to_body, float)
        self._t2w_ref = body_to_world[0] * Rotation.from_matrix(t2b)
        p0 = np.r_[np.zeros(3), t2b.T @ omega0_body]
        if self.moments is None:
            # The rate-based starting ratios can fall outside the bounds on short or noisy spans, and are
            # undefined (not positive) for a debris that does not turn: then start from a sphere (ratios 1).
            with np.errstate(invalid="ignore", divide="ignore"):
                ratios0 = np.log(np.asarray(moments0[:2], float))
            ratios0 = np.clip(np.where(np.isfinite(ratios0), ratios0, 0.0), np.log(0.5) + 1e-3, np.log(2.0) - 1e-3)
            p0 = np.r_[p0, ratios0, np.zeros(3)]
        measured_inv = body_to_world.inv()
        # Continuation: the attitude error of a wrong inertia grows with time, so a long span
        # seen at once has many local minima; fit a short span, then double it.
        span = min(self.first_span, times[-1] - times[0])
        while True:
            use = times <= times[0] + span + 1e-9
            result = least_squares(self._residuals, p0, args=(times[use], measured_inv[use], weights[use]),
                                   bounds=self._bounds(p0.size), x_scale="jac")
            p0 = result.x
            if use.all():
                break
            span *= 2.0
        self._p = result.x
        self.time0_ = float(times[0])
        t2w, omega, moments, t2b = self._unpack(result.x)
        self.moments_, self.principal_to_body_ = moments, t2b
        self.omega0_principal_, self.principal_to_world0_ = omega, t2w.as_matrix()
        dof = max(result.fun.size - result.x.size, 1)
        self.residual_rms_ = float(np.sqrt(result.fun @ result.fun / dof))
        jac = result.jac
        # Scan-to-scan correlated registration errors: scale the white-noise covariance by the
        # residuals' integrated autocorrelation time.
        self.correlation_time_ = integrated_autocorrelation_time(result.fun.reshape(-1, 3))
        self.covariance_ = np.linalg.pinv(jac.T @ jac) * self.residual_rms_**2 * self.correlation_time_
        self.jacobian_, self.weights_ = jac, np.asarray(weights, float)
        self.weighted_residuals_ = result.fun.reshape(-1, 3)
        return self

    def add_attitude_covariance(self, attitude_covariance) -> TorqueFreeFit:
        """Add to ``covariance_`` what errors of the measured attitudes correlated from frame to frame give the
        fitted parameters, through the least squares' linear response (such errors do not show as scatter about
        the fit, which is all ``covariance_`` knows; e.g. frames posed to shared partner scans,
        :meth:`perception.scan_to_scan.ReposedFrames.attitude_covariance`).

        A body-side change e_k of measured attitude k changes its weighted residual by W_k e_k, and the
        parameters by the least-squares response (first order about the optimum):

        .. math:: \\Sigma_p \\mathrel{+}= s\\, G \\Sigma_e G^T,\\qquad G = (J^T J)^{+} J^T W,\\qquad
                  s = \\max\\Big(1, \\frac{\\sum_k |e_k|^2 / (3k - p)}{\\sum_k \\operatorname{tr} \\Sigma_{e,kk} / (3k)}\\Big)

        The scale s (``attitude_covariance_scale_``) makes the given covariance account at least for the scatter of
        the attitudes about the fit (e_k: the residuals, rad), never shrinks it (the Particle Data Group's scale
        factor, as :data:`perception.momentum.MISFIT_CHI2`): a covariance estimated from too few or mutually
        correlated samples under-states the frames' errors, and the residuals are a lower bound of them.

        Parameters
        ----------
        attitude_covariance : (3k, 3k) float   Covariance of the fitted frames' attitude errors (rad^2; body-side
                                               rotation vectors, frame B), in the order of the fit's frames.

        Returns
        -------
        TorqueFreeFit
            ``self``, ``covariance_`` enlarged, ``attitude_covariance_scale_`` set.
        """
        jac = self.jacobian_
        weights = block_diag(*self.weights_)
        attitude_covariance = np.asarray(attitude_covariance, float)
        if attitude_covariance.shape != weights.shape:
            raise ValueError(f"attitude_covariance must be ({weights.shape[0]}, {weights.shape[0]}) for the fit's "
                             f"{len(self.weights_)} frames. Got {attitude_covariance.shape} instead.")
        errors = np.linalg.solve(self.weights_, self.weighted_residuals_[..., None])[..., 0]   # rad, B
        modelled = np.trace(attitude_covariance) / attitude_covariance.shape[0]
        observed = np.sum(errors**2) / max(attitude_covariance.shape[0] - jac.shape[1], 1)
        self.attitude_covariance_scale_ = float(max(1.0, observed / modelled)) if modelled > 0 else 1.0
        gain = np.linalg.pinv(jac.T @ jac) @ jac.T @ weights
        self.covariance_ = self.covariance_ + self.attitude_covariance_scale_ * gain @ attitude_covariance @ gain.T
        return self

    def rate_body_at(self, time) -> np.ndarray:
        """Angular velocity (3,) (rad/s, body frame B) of the fitted motion at ``time`` (s, not before
        the fit's first time).

        Parameters
        ----------
        time : float
            Time (s) on the clock of the ``times`` given to :meth:`fit`, at or after ``times[0]``.

        Returns
        -------
        (3,) float
            The rate (rad/s, body frame B).
        """
        t2w, omega, moments, t2b = self._unpack(self._p)
        _, omegas = propagate_torque_free(t2w.as_quat()[[3, 0, 1, 2]], omega, moments,
                                          np.array([self.time0_, max(float(time), self.time0_)]), self.max_step)
        return t2b @ omegas[-1]

    def spin_momentum_per_c(self) -> tuple[np.ndarray, np.ndarray]:
        """The fitted motion's spin angular momentum per unit C, h = R_T->W diag(J1, J2, 1) omega_T
        (3,) (rad/s, world frame; constant in torque-free motion), and its covariance (3, 3)
        propagated from the parameter covariance (finite-difference Jacobian)."""
        def spin(p):
            t2w, omega, moments, _ = self._unpack(p)
            return t2w.as_matrix() @ (moments * omega)

        h = spin(self._p)
        jac = np.empty((3, self._p.size))
        for i in range(self._p.size):
            step = 1e-6 * max(1.0, abs(self._p[i]))
            shifted = self._p.copy()
            shifted[i] += step
            jac[:, i] = (spin(shifted) - h) / step
        return h, jac @ self.covariance_ @ jac.T

    @property
    def moments_std_(self) -> np.ndarray:
        """1-sigma of [A/C, B/C] (-), from the covariance (delta method on the log parameters)."""
        if self.moments is not None:
            return np.zeros(2)
        return self.moments_[:2] * np.sqrt(np.diag(self.covariance_)[6:8])
