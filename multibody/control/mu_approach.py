"""Optimal net-approach guidance of two maneuverable units by direct collocation.

The seed paper (Liu & Poddar, ``maneuverable-units-2d-guidance``) brings the mouth centre of a
tether-net carried by two MUs onto a debris' centre without an MU entering the keep-out circle,
minimizing fuel (fixed final time), time, or both; its own solutions use a forward-Euler
transcription (eqs. 11, 13) in MATLAB ``fmincon``. Here:

* **Transcription**: Hermite-Simpson collocation, separated form (Betts 2010, *Practical Methods
  for Optimal Control*, Sec. 4.6.2), on ``N`` equal intervals of the normalized time
  :math:`\\zeta = t / t_f \\in [0, 1]`; states and controls at the nodes and the interval
  midpoints, so the dynamics :math:`dX/d\\zeta = t_f f(X, u)` is 4th-order accurate and the
  controls are piecewise quadratic.
* **Free final time** by that time scaling (paper Sec. 2.4): :math:`t_f` is a decision variable.
* **Path constraints** (keep-out circle, paper eqs. 5-6 and 17; mouth width, eq. 15) at every
  node and midpoint; the keep-out radius is enlarged by a small ``keep_out_margin`` there so that
  the continuous trajectory, checked by :func:`resimulate`, keeps r_o between the points too.
* **Solver**: IPOPT through CasADi (exact Hessian by algorithmic differentiation).

The thrust angles are solved for as direction cosines (a unit vector per MU, the whole circle of
eq. 8 without a cut at 0 or the 2 pi ambiguity); results report them in [0, 2pi).
"""
from __future__ import annotations

import time

import casadi as ca
import numpy as np

from multibody.control.mu_dynamics import CONTROLS, controls_from_angles, rod_moment_of_inertia
from multibody.control.mu_mesh import (SPLIT, Resimulation, collocation_points, interpolated_start,  # noqa: F401 (re-exported)
                             interval_widths, local_errors, node_fractions, point_fractions, refine_mesh, resimulate)
from multibody.control.mu_problem import ApproachProblem, ApproachSolution

NU = len(CONTROLS)

#: IPOPT settings: tolerance well below the figures compared (1e-4 relative on time and fuel).
#: bound_push/bound_frac: start close to the bounds (the thrust sits on its bounds in every
#: answer here); measured 123 instead of 544 iterations on case study 2, minimum time.
IPOPT_OPTIONS = {"ipopt.print_level": 0, "print_time": False, "ipopt.sb": "yes", "ipopt.tol": 1e-9,
                 "ipopt.max_iter": 1000, "ipopt.bound_push": 1e-6, "ipopt.bound_frac": 1e-6}
#: IPOPT settings added for a solve on a refined mesh, which starts at the previous answer: a small
#: initial barrier parameter keeps IPOPT near it.
WARM_OPTIONS = {"ipopt.mu_init": 1e-6}
#: Solver statuses that count as a solution.
SUCCESS = ("Solve_Succeeded", "Solved_To_Acceptable_Level")


def _symbolic_rhs(model):
    x = ca.SX.sym("x", model.n_states)
    u = ca.SX.sym("u", NU)
    return ca.Function("rhs", [x, u], [model.rhs(x, u)])


def _path_constraints(problem: ApproachProblem, x, width: bool = True):
    """Keep-out (and, with ``width``, mouth width) expressions at one point, with their bounds."""
    x1, y1, x2, y2 = problem.model.unit_positions(x)
    xo, yo = problem.debris_center
    clearance = (problem.keep_out_radius + problem.keep_out_margin) ** 2
    g = [(x1 - xo) ** 2 + (y1 - yo) ** 2, (x2 - xo) ** 2 + (y2 - yo) ** 2]
    lower, upper = [clearance, clearance], [np.inf, np.inf]
    if width and problem.width_bounds is not None:
        g.append((x2 - x1) ** 2 + (y2 - y1) ** 2)
        lower.append(problem.width_bounds[0] ** 2)   # no margin: the MUs may start on the bound
        upper.append(problem.width_bounds[1] ** 2)
    return g, lower, upper


class _Transcription:
    """Decision variables, constraints and their bounds of the Hermite-Simpson NLP."""

    def __init__(self, problem: ApproachProblem, width: bool = True):
        self.problem, self.width = problem, width
        n, nx = problem.intervals, problem.model.n_states
        self.X = ca.SX.sym("X", nx, n + 1)
        self.Xm = ca.SX.sym("Xm", nx, n)
        self.U = ca.SX.sym("U", NU, n + 1)
        self.Um = ca.SX.sym("Um", NU, n)
        self.tf = ca.SX.sym("tf") if problem.final_time is None else ca.SX(problem.final_time)
        self.g, self.lbg, self.ubg = [], [], []

    @property
    def w(self):
        parts = [ca.vec(self.X), ca.vec(self.Xm), ca.vec(self.U), ca.vec(self.Um)]
        return ca.vertcat(*parts, *([self.tf] if self.problem.final_time is None else []))

    def add(self, expr, lower, upper):
        expr = ca.vec(ca.vertcat(*expr)) if isinstance(expr, list) else ca.vec(expr)
        self.g.append(expr)
        self.lbg += list(np.broadcast_to(lower, expr.shape[0]))
        self.ubg += list(np.broadcast_to(upper, expr.shape[0]))

    def dynamics(self):
        """Hermite-Simpson defects (Betts 2010 eqs. 4.103-4.104) in normalized time."""
        n, nx = self.problem.intervals, self.problem.model.n_states
        f = _symbolic_rhs(self.problem.model).map(n + 1)
        fm = _symbolic_rhs(self.problem.model).map(n)
        h = ca.repmat(ca.DM(interval_widths(self.problem)).T, nx, 1)
        F = self.tf * f(self.X, self.U)
        Fm = self.tf * fm(self.Xm, self.Um)
        xk, xk1 = self.X[:, :-1], self.X[:, 1:]
        self.add(xk1 - xk - h / 6.0 * (F[:, :-1] + 4.0 * Fm + F[:, 1:]), 0.0, 0.0)
        self.add(self.Xm - (xk + xk1) / 2.0 - h / 8.0 * (F[:, :-1] - F[:, 1:]), 0.0, 0.0)

    def path(self):
        """Path constraints at every midpoint and every node but the fixed initial one
        (:func:`check_initial_state` checks that before the solve)."""
        p = self.problem
        points = [self.X[:, k] for k in range(1, p.intervals + 1)] + [self.Xm[:, k] for k in range(p.intervals)]
        for x in points:
            g, lower, upper = _path_constraints(p, x, self.width)
            self.add(g, lower, upper)

    def unit_directions(self):
        """Each thrust direction (cos, sin) a unit vector, at every node and midpoint."""
        for u in (self.U, self.Um):
            self.add(u[2, :] ** 2 + u[3, :] ** 2, 1.0, 1.0)
            self.add(u[4, :] ** 2 + u[5, :] ** 2, 1.0, 1.0)

    def boundary(self):
        p = self.problem
        self.add(self.X[:, 0] - p.initial_state, 0.0, 0.0)
        cx, cy = p.model.mouth_center(self.X[:, -1])
        self.add([cx - p.debris_center[0], cy - p.debris_center[1]], 0.0, 0.0)
        if p.final_at_rest:
            self.add([self.X[i, -1] for i in p.model.velocity_indices], 0.0, 0.0)

    def impulse(self):
        """Both MUs' thrust impulse (N s), Simpson's rule on the nodes and midpoints."""
        h = ca.DM(interval_widths(self.problem)).T
        s, sm = self.U[0, :] + self.U[1, :], self.Um[0, :] + self.Um[1, :]
        return self.tf / 6.0 * ca.sum2(h * (s[:, :-1] + 4.0 * sm + s[:, 1:]))

    def smoothing(self):
        """Tie-breaking penalty: sum of squared jumps of the controls between consecutive points
        (thrust over its upper bound, direction cosines as they are). Minimum fuel leaves the
        directions free wherever the thrust sits at its lower bound, and the last node's control
        barely matters; without it IPOPT returned directions that flip between points, which no
        integrator can follow (2.3 m end miss of the re-simulated minimum-fuel path)."""
        u = ca.horzcat(*[ca.vertcat(self.U[:, k], self.Um[:, k]) for k in range(self.problem.intervals)])
        sequence = ca.horzcat(ca.reshape(u, NU, 2 * self.problem.intervals), self.U[:, -1])
        scale = ca.DM([1.0 / self.problem.thrust_bounds[1]] * 2 + [1.0] * 4)
        jumps = (sequence[:, 1:] - sequence[:, :-1]) * ca.repmat(scale, 1, 2 * self.problem.intervals)
        return self.problem.control_smoothing * ca.sumsqr(jumps)

    def cost(self):
        return self.objective() + self.smoothing()

    def objective(self):
        p = self.problem
        if p.objective == "min_fuel":
            return self.impulse()          # same minimizer as the fuel k * impulse, better scaled
        if p.objective == "min_time":
            return self.tf
        if p.objective == "combined":
            return p.time_weight * self.tf + p.impulse_weight * self.impulse()
        raise ValueError(f"objective must be 'min_fuel', 'min_time' or 'combined'. Got {p.objective!r} instead")


def _variable_bounds(problem: ApproachProblem):
    """lbx, ubx of (X, Xm, U, Um[, tf]) in the order of :attr:`_Transcription.w`."""
    n, model = problem.intervals, problem.model
    x_lo, x_hi = np.full(model.n_states, -np.inf), np.full(model.n_states, np.inf)
    if problem.position_bounds is not None:
        x_lo[list(model.position_indices)], x_hi[list(model.position_indices)] = problem.position_bounds
    if problem.min_unit_mass is not None:
        x_lo[list(model.mass_indices)] = problem.min_unit_mass
    # no bounds on the direction cosines: |c| <= 1 together with c^2 + s^2 = 1 is degenerate (LICQ)
    u_lo = np.r_[problem.thrust_bounds[0], problem.thrust_bounds[0], np.full(4, -np.inf)]
    u_hi = np.r_[problem.thrust_bounds[1], problem.thrust_bounds[1], np.full(4, np.inf)]
    lo = [np.tile(x_lo, n + 1), np.tile(x_lo, n), np.tile(u_lo, n + 1), np.tile(u_lo, n)]
    hi = [np.tile(x_hi, n + 1), np.tile(x_hi, n), np.tile(u_hi, n + 1), np.tile(u_hi, n)]
    if problem.final_time is None:
        lo.append([problem.final_time_bounds[0]])
        hi.append([problem.final_time_bounds[1]])
    return np.concatenate(lo), np.concatenate(hi)


def _facing_angle(approach_world, reference_angle):
    """The angle perpendicular to ``approach_world`` (2,) closest to ``reference_angle`` (rad)
    modulo pi: the mouth across the way to the debris, turned as little as possible."""
    normal = np.arctan2(approach_world[1], approach_world[0]) + np.pi / 2.0
    return normal + np.pi * np.round((reference_angle - normal) / np.pi)


def _progress(zeta, final_at_rest):
    """Normalized path progress s(zeta), 0 -> 1: constant acceleration from rest (free end) or the
    smooth rest-to-rest cubic."""
    return 3.0 * zeta**2 - 2.0 * zeta**3 if final_at_rest else zeta**2


def straight_line_guess(problem: ApproachProblem):
    """Initial guess: the formation's centre moves on the straight line to the debris while the
    mouth turns across the approach direction, both along :func:`_progress`; the controls are
    the thrusts this motion needs (clipped to the bounds), so the guess nearly satisfies the
    dynamics. (A guess with constant velocities from the rest start left IPOPT hundreds of
    iterations from the answer.)

    Parameters
    ----------
    problem : ApproachProblem
        The optimal-control problem (SI, world frame).

    Returns
    -------
    states : (nx, 2N+1) float
        States on the nodes and midpoints interleaved, world frame (``model.state_names``).
    controls : (6, 2N+1) float
        :data:`~multibody.control.mu_dynamics.CONTROLS` at the same points.
    tf : float
        Final time of the guess (s).
    """
    tf = problem.final_time or problem.final_time_guess
    t = tf * point_fractions(problem)
    model, x0 = problem.model, np.asarray(problem.initial_state, float)
    x1, y1, x2, y2 = model.unit_positions(x0)
    center0_world = np.array([x1 + x2, y1 + y2]) / 2.0
    approach_world = np.asarray(problem.debris_center, float) - center0_world
    angle0 = np.arctan2(y2 - y1, x2 - x1)
    s = _progress(t / tf, problem.final_at_rest)
    angle = angle0 + s * (_facing_angle(approach_world, angle0) - angle0)
    center_world = center0_world[:, None] + s * approach_world[:, None]
    half = np.hypot(x2 - x1, y2 - y1) / 2.0
    if problem.width_bounds is not None:
        half = np.clip(half, *np.asarray(problem.width_bounds) / 2.0)
    if model.kind == "rigid_rod":
        return _rod_guess(problem, t, center_world, angle) + (tf,)
    offset_world = half * np.array([np.cos(angle), np.sin(angle)])
    return _units_guess(problem, t, center_world - offset_world, center_world + offset_world,
                        x0[[4, 9]]) + (tf,)


def _derivative(values, t):
    return np.gradient(values, t, axis=-1)


def _thrust_for(force_world, bounds):
    """Thrust magnitude (clipped to ``bounds``, N) and world angle (unwrapped, rad) of forces (2, n)."""
    return np.clip(np.hypot(*force_world), *bounds), np.unwrap(np.arctan2(force_world[1], force_world[0]))


def _rod_guess(problem, t, center_world, angle):
    model = problem.model
    velocity_world, rate = _derivative(center_world, t), _derivative(angle, t)
    acceleration_world, angular_acceleration = _derivative(velocity_world, t), _derivative(rate, t)
    normal_world = np.array([-np.sin(angle), np.cos(angle)])
    # F1 + F2 = 2 m a (eqs. 1-2); (F2 - F1) . n = 2 I phi'' / L (eq. 3), F2 - F1 along n
    couple_world = (rod_moment_of_inertia(model.mass, model.length) * angular_acceleration / model.length
                    * normal_world)
    thrust_1, angle_1_world = _thrust_for(model.mass * acceleration_world - couple_world, problem.thrust_bounds)
    thrust_2, angle_2_world = _thrust_for(model.mass * acceleration_world + couple_world, problem.thrust_bounds)
    states = np.array([center_world[0], velocity_world[0], center_world[1], velocity_world[1], angle, rate])
    return states, controls_from_angles(thrust_1, thrust_2, angle - angle_1_world, angle - angle_2_world)


def _units_guess(problem, t, path_1_world, path_2_world, initial_masses):
    k = problem.model.fuel_rate
    states, controls = [], [[], [], [], []]
    for i, (path_world, mass0) in enumerate(zip((path_1_world, path_2_world), initial_masses)):
        velocity_world = _derivative(path_world, t)
        thrust, angle_world = _thrust_for(mass0 * _derivative(velocity_world, t), problem.thrust_bounds)
        spent = np.r_[0.0, np.cumsum((thrust[1:] + thrust[:-1]) / 2.0 * np.diff(t))]
        states += [path_world[0], path_world[1], velocity_world[0], velocity_world[1], mass0 - k * spent]
        controls[i], controls[2 + i] = thrust, angle_world
    return np.array(states), controls_from_angles(*controls)


def _guess_vector(problem: ApproachProblem):
    states, controls, tf = straight_line_guess(problem)
    parts = [states[:, ::2], states[:, 1::2], controls[:, ::2], controls[:, 1::2]]
    vector = np.concatenate([p.ravel(order="F") for p in parts])
    return np.r_[vector, tf] if problem.final_time is None else vector


def _solve_nlp(problem: ApproachProblem, width: bool, start, options=None):
    """One IPOPT solve from the decision vector ``start``; returns (transcription, result, stats, s)."""
    tr = _Transcription(problem, width)
    tr.dynamics()
    tr.path()
    tr.unit_directions()
    tr.boundary()
    nlp = {"x": tr.w, "f": tr.cost(), "g": ca.vertcat(*tr.g)}
    solver = ca.nlpsol("approach", "ipopt", nlp, {**IPOPT_OPTIONS, **(options or {})})
    lbx, ubx = _variable_bounds(problem)
    tic, cpu = time.perf_counter(), time.process_time()
    out = solver(x0=start, lbx=lbx, ubx=ubx, lbg=tr.lbg, ubg=tr.ubg)
    stats = dict(solver.stats(), cpu_s=time.process_time() - cpu)
    return tr, out, stats, time.perf_counter() - tic


def _widths_hold(problem: ApproachProblem, tr, out) -> bool:
    """The mouth width of a solve without the width constraints is within bounds at every node
    and midpoint."""
    states = ca.Function("states", [tr.w], [ca.horzcat(tr.X, tr.Xm)])(out["x"])
    x1, y1, x2, y2 = problem.model.unit_positions(np.array(states, float))
    width = np.hypot(x2 - x1, y2 - y1)
    low, high = problem.width_bounds
    return bool(np.all(width >= low - 1e-9) and np.all(width <= high + 1e-9))


def _solve_once(problem: ApproachProblem, start, deferred: bool, options=None):
    """IPOPT on one mesh from ``start``, with the width constraints deferred as :func:`solve` says.
    Returns (transcription, result, {iterations, solves, solve_s, cpu_s, status})."""
    tr, out, stats, solve_s = _solve_nlp(problem, not deferred, start, options)
    tally = {"iterations": int(stats["iter_count"]), "solves": 1, "solve_s": solve_s, "cpu_s": stats["cpu_s"]}
    if deferred and not _widths_hold(problem, tr, out):
        tr, out, stats, more_s = _solve_nlp(problem, True, np.array(out["x"], float).ravel(), options)
        tally = {"iterations": tally["iterations"] + int(stats["iter_count"]), "solves": 2,
                 "solve_s": tally["solve_s"] + more_s, "cpu_s": tally["cpu_s"] + stats["cpu_s"]}
    tally["status"] = stats["return_status"]
    return tr, out, tally


def _solution(problem: ApproachProblem, tr, out, tally: dict) -> ApproachSolution:
    values = ca.Function("values", [tr.w], [tr.X, tr.Xm, tr.U, tr.Um, tr.tf, tr.impulse(), tr.objective(),
                                            tr.smoothing()])(out["x"])
    X, Xm, U, Um, tf, impulse, objective, penalty = (np.array(v, float) for v in values)
    tf = float(tf.squeeze())
    return ApproachSolution(problem, tally["status"], tally["status"] in SUCCESS, tally["iterations"],
                            tally["solve_s"], tf, float(objective.squeeze()), float(impulse.squeeze()),
                            tf * node_fractions(problem), X, U, Xm, Um,
                            {"nlp_solves": tally["solves"], "smoothing_penalty": float(penalty.squeeze()),
                             "cpu_s": tally["cpu_s"], "mesh_refinements": 0})


def solve(problem: ApproachProblem) -> ApproachSolution:
    """Transcribe and solve the problem with IPOPT, refining the mesh where the controls, replayed
    open loop, miss the collocated states (:func:`refine_mesh`); the solution says whether IPOPT
    succeeded.

    The mouth-width constraints (eq. 15) are added only when needed: a first solve leaves them
    out, and when its widths are within bounds at every point it is the answer (a local optimum
    that satisfies constraints left out is a local optimum with them); otherwise a second solve
    with them starts from the first. Reason: the paper's MUs start exactly at the minimum width,
    so these constraints are weakly active near the start (zero multipliers on the bound), which
    cost IPOPT 2-4 times the wall time (measured on case study 2: minimum time 0.75 s against
    3.6 s, combined 1.5 s against 3.9 s). Not for min_fuel (see below).

    Parameters
    ----------
    problem : ApproachProblem
        The optimal-control problem (SI, world frame).

    Returns
    -------
    ApproachSolution
        The last mesh's solution; ``success`` says whether IPOPT converged.
    """
    # min_fuel: every direction profile at the lowest thrust is optimal, so the answer without the
    # width constraints is an arbitrary point of that set and a poor start (measured 435 against
    # 108 iterations): solve it with them at once.
    deferred = problem.width_bounds is not None and problem.objective != "min_fuel"
    solution = _solution(problem, *_solve_once(problem, _guess_vector(problem), deferred))
    for _ in range(problem.mesh_rounds):
        refined = refine_mesh(solution)
        if refined is None or not solution.success:
            break
        tr, out, tally = _solve_once(refined, interpolated_start(solution, refined), deferred, WARM_OPTIONS)
        previous, solution = solution, _solution(refined, tr, out, tally)
        solution.iterations += previous.iterations
        solution.solve_s += previous.solve_s
        for key in ("nlp_solves", "cpu_s", "mesh_refinements"):
            solution.extras[key] += previous.extras[key]
        solution.extras["mesh_refinements"] += 1
    return solution


def constraint_report(problem: ApproachProblem, states, controls) -> dict:
    """Smallest margins of every constraint along a trajectory; a negative margin is a violation.

    Parameters
    ----------
    problem : ApproachProblem
        The optimal-control problem (SI, world frame).
    states : (nx, M) float
        States along the trajectory, world frame (``model.state_names``).
    controls : (6, M) float
        :data:`~multibody.control.mu_dynamics.CONTROLS` at the same times.

    Returns
    -------
    dict
        JSON-ready margins, keys ending in their unit (m, N, kg).
    """
    x1, y1, x2, y2 = problem.model.unit_positions(states)
    xo, yo = problem.debris_center
    clearance = np.minimum(np.hypot(x1 - xo, y1 - yo), np.hypot(x2 - xo, y2 - yo))
    cx, cy = problem.model.mouth_center(states[:, -1])
    report = {"keep_out_margin_m": float(clearance.min() - problem.keep_out_radius),
              "min_unit_debris_distance_m": float(clearance.min()),
              "thrust_margin_N": float(min((controls[:2] - problem.thrust_bounds[0]).min(),
                                           (problem.thrust_bounds[1] - controls[:2]).min())),
              "final_mouth_miss_m": float(np.hypot(cx - xo, cy - yo))}
    width = np.hypot(x2 - x1, y2 - y1)
    report["width_range_m"] = [float(width.min()), float(width.max())]
    if problem.width_bounds is not None:
        report["width_margin_m"] = float(min(width.min() - problem.width_bounds[0],
                                             problem.width_bounds[1] - width.max()))
    if problem.min_unit_mass is not None:
        masses = np.array(problem.model.unit_masses(states))
        report["mass_margin_kg"] = float(masses.min() - problem.min_unit_mass)
    if problem.final_at_rest:
        report["final_speed_max"] = float(np.abs(states[list(problem.model.velocity_indices), -1]).max())
    return report
