"""Mesh of the net-approach collocation (:mod:`multibody.control.mu_approach`; the problem and
solution in :mod:`multibody.control.mu_problem`) and the open-loop check of
its controls: interval widths, the Hermite-Simpson control interpolation (piecewise quadratic
through node, midpoint, node), the independent SciPy re-simulation, the local error of each
interval and the mesh refinement it drives.

Why the refinement: an optimal thrust is bang-off-bang; a switch inside an interval cannot be
followed by the quadratic control, and replayed open loop the resulting velocity error grows over
the coast (case study 1, initial condition 1, combined objective: 10.7 cm end miss on 200 equal
intervals). Splitting the intervals whose local error is over a tolerance and solving again from
the previous answer puts nodes near the switches (Betts 2010, *Practical Methods for Optimal
Control*, Sec. 4.7).
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.integrate import solve_ivp

from multibody.control.mu_dynamics import CONTROLS
from multibody.control.mu_problem import ApproachProblem, ApproachSolution

NU = len(CONTROLS)

def interval_widths(problem: ApproachProblem) -> np.ndarray:
    """Interval widths (N,) in normalized time zeta = t / t_f (-).

    Parameters
    ----------
    problem : ApproachProblem
        The optimal-control problem (SI, world frame).
    """
    if problem.mesh is None:
        return np.full(problem.intervals, 1.0 / problem.intervals)
    return np.asarray(problem.mesh, float)


def node_fractions(problem: ApproachProblem) -> np.ndarray:
    """Normalized node times (N+1,) (-), 0 to 1.

    Parameters
    ----------
    problem : ApproachProblem
        The optimal-control problem (SI, world frame).
    """
    if problem.mesh is None:
        return np.linspace(0.0, 1.0, problem.intervals + 1)
    return np.r_[0.0, np.cumsum(interval_widths(problem))]


def point_fractions(problem: ApproachProblem) -> np.ndarray:
    """Normalized times (2N+1,) (-) of the nodes and midpoints interleaved. (On the uniform mesh
    exactly ``linspace``: the initial guess's thrust angles where the guessed force vanishes are
    arctan2 of rounding noise, and their change by other roundings cost 93 -> 212 iterations.)

    Parameters
    ----------
    problem : ApproachProblem
        The optimal-control problem (SI, world frame).
    """
    if problem.mesh is None:
        return np.linspace(0.0, 1.0, 2 * problem.intervals + 1)
    nodes = node_fractions(problem)
    points = np.empty(2 * problem.intervals + 1)
    points[::2], points[1::2] = nodes, (nodes[:-1] + nodes[1:]) / 2.0
    return points


def local_errors(solution: ApproachSolution, rtol: float = 1e-9) -> np.ndarray:
    """Local error of each interval (N,) (-): the interval's interpolated controls
    (:func:`quadratic_controls`) integrated from its collocated start node, against the collocated
    end node, :math:`\\max_i |\\Delta x_i| / (1 + \\max_t |x_i|)` (the relative error of Betts
    2010, Sec. 4.7.1, with a DOP853 solution in place of his quadrature). All intervals are
    integrated at once in their local time tau in [0, 1]. A thrust switch inside an interval,
    which the quadratic control cannot follow, shows up here.

    Parameters
    ----------
    solution : ApproachSolution
        A collocation solution (SI, world frame).
    rtol : float
        DOP853's relative (and absolute) tolerance (-).
    """
    nx, n = solution.states.shape[0], solution.problem.intervals
    u0, um, u1 = solution.controls[:, :-1], solution.mid_controls, solution.controls[:, 1:]
    h, model, bounds = np.diff(solution.t), solution.problem.model, solution.problem.thrust_bounds

    def rhs(tau, y):
        return (h * model.rhs(y.reshape(nx, n), quadratic_controls(u0, um, u1, tau, bounds))).ravel()

    end = solve_ivp(rhs, (0.0, 1.0), solution.states[:, :-1].ravel(), method="DOP853", rtol=rtol, atol=rtol)
    scale = 1.0 + np.abs(np.c_[solution.states, solution.mid_states]).max(axis=1)
    return np.max(np.abs(end.y[:, -1].reshape(nx, n) - solution.states[:, 1:]) / scale[:, None], axis=0)


#: Sub-intervals an interval over :attr:`ApproachProblem.mesh_tolerance` is split into.
SPLIT = 8


def refine_mesh(solution: ApproachSolution) -> ApproachProblem | None:
    """The problem on a mesh whose intervals with a local error (:func:`local_errors`) over
    ``mesh_tolerance`` are split into :data:`SPLIT` equal ones; None when no interval is over it.

    Parameters
    ----------
    solution : ApproachSolution
        A collocation solution (SI, world frame).
    """
    problem = solution.problem
    errors = local_errors(solution)
    if errors.max() <= problem.mesh_tolerance:
        return None
    widths = interval_widths(problem)
    counts = np.where(errors > problem.mesh_tolerance, SPLIT, 1)
    mesh = np.repeat(widths / counts, counts)
    return replace(problem, mesh=tuple(mesh), intervals=len(mesh))


def interpolated_start(solution: ApproachSolution, refined: ApproachProblem):
    """Decision vector on ``refined``'s mesh, linear in time between the solution's nodes and
    midpoints, direction cosines renormalized.

    Parameters
    ----------
    solution : ApproachSolution
        A collocation solution (SI, world frame).
    refined : ApproachProblem
        The same problem on the refined mesh (:func:`refine_mesh`).

    Returns
    -------
    (n_w,) float
        States, midpoint states, controls, midpoint controls (column-major), then t_f (s) when free.
    """
    t, states, controls = collocation_points(solution)
    zeta = point_fractions(refined)
    states = np.array([np.interp(zeta, t / solution.final_time, row) for row in states])
    controls = np.array([np.interp(zeta, t / solution.final_time, row) for row in controls])
    for i in (2, 4):
        controls[i:i + 2] /= np.hypot(controls[i], controls[i + 1])
    parts = [states[:, ::2], states[:, 1::2], controls[:, ::2], controls[:, 1::2]]
    vector = np.concatenate([p.ravel(order="F") for p in parts])
    return np.r_[vector, solution.final_time] if refined.final_time is None else vector


def quadratic_controls(u_start, u_mid, u_end, tau, thrust_bounds):
    """Controls on one interval at local times ``tau`` in [0, 1]: the quadratic through the node,
    midpoint and node values (the Hermite-Simpson control), thrust clipped to its bounds (the
    quadratic overshoots at a thrust switch), directions renormalized to unit vectors.
    Values (6,) and ``tau`` (M,), or values (6, M) of M intervals and one ``tau``: returns (6, M).

    Parameters
    ----------
    u_start, u_mid, u_end : (6,) or (6, M) float
        :data:`~multibody.control.mu_dynamics.CONTROLS` at the interval's start node, midpoint and
        end node (N, N, -, -, -, -).
    tau : float or (M,) float
        Local time in the interval, 0 to 1 (-).
    thrust_bounds : (2,) float
        Thrust magnitude bounds (N).
    """
    tau = np.atleast_1d(tau)
    basis = (2 * (tau - 0.5) * (tau - 1.0), -4 * tau * (tau - 1.0), 2 * tau * (tau - 0.5))
    u = sum(np.reshape(v, (NU, -1)) * b for v, b in zip((u_start, u_mid, u_end), basis))
    u[:2] = np.clip(u[:2], *thrust_bounds)
    for i in (2, 4):
        u[i:i + 2] /= np.hypot(u[i], u[i + 1])
    return u


@dataclass
class Resimulation:
    """The solution's controls integrated by SciPy (independent of the collocation equations):
    ``t`` (M,) (s), ``states`` (n_states, M), ``controls`` (6, M)."""

    t: np.ndarray
    states: np.ndarray
    controls: np.ndarray


def _interval_rhs(solution: ApproachSolution, k: int):
    """dX/dt on interval k with its quadratic controls (:func:`quadratic_controls`)."""
    t0, h = solution.t[k], solution.t[k + 1] - solution.t[k]
    u0, um, u1 = solution.controls[:, k], solution.mid_controls[:, k], solution.controls[:, k + 1]
    model, bounds = solution.problem.model, solution.problem.thrust_bounds
    return lambda t, state: model.rhs(state, quadratic_controls(u0, um, u1, (t - t0) / h, bounds)[:, 0])


def resimulate(solution: ApproachSolution, points_per_interval: int = 20, rtol: float = 1e-10) -> Resimulation:
    """Integrate the NumPy dynamics from the initial state with the interpolated controls
    (:func:`quadratic_controls`), interval by interval (DOP853), sampled ``points_per_interval``
    times per interval: the fine check of the constraints between the collocation points.

    Parameters
    ----------
    solution : ApproachSolution
        A collocation solution (SI, world frame).
    points_per_interval : int
        Samples per interval (-).
    rtol : float
        DOP853's relative (and absolute) tolerance (-).
    """
    n, bounds = solution.problem.intervals, solution.problem.thrust_bounds
    x = np.asarray(solution.problem.initial_state, float)
    ts, xs, us = [], [], []
    for k in range(n):
        span = (solution.t[k], solution.t[k + 1])
        local = np.linspace(*span, points_per_interval + 1)[:points_per_interval + (k == n - 1)]
        sol = solve_ivp(_interval_rhs(solution, k), span, x, method="DOP853", t_eval=local, rtol=rtol, atol=rtol,
                        dense_output=True)
        ts.append(sol.t)
        xs.append(sol.y)
        us.append(quadratic_controls(solution.controls[:, k], solution.mid_controls[:, k],
                                      solution.controls[:, k + 1], (sol.t - span[0]) / (span[1] - span[0]), bounds))
        x = sol.sol(span[1])
    return Resimulation(np.concatenate(ts), np.hstack(xs), np.hstack(us))


def collocation_points(solution: ApproachSolution):
    """Times (2N+1,) (s), states and controls at the nodes and midpoints in time order.

    Parameters
    ----------
    solution : ApproachSolution
        A collocation solution (SI, world frame).

    Returns
    -------
    t : (2N+1,) float
        Times (s).
    states : (nx, 2N+1) float
        States, world frame.
    controls : (6, 2N+1) float
        :data:`~multibody.control.mu_dynamics.CONTROLS`.
    """
    n = solution.problem.intervals
    t = solution.final_time * point_fractions(solution.problem)
    states = np.empty((solution.states.shape[0], 2 * n + 1))
    controls = np.empty((solution.controls.shape[0], 2 * n + 1))
    states[:, ::2], states[:, 1::2] = solution.states, solution.mid_states
    controls[:, ::2], controls[:, 1::2] = solution.controls, solution.mid_controls
    return t, states, controls
