"""The optimal-control problem of a maneuverable-unit approach case
(:class:`~riskassess.cases.approach.ApproachCase` -> :class:`multibody.control.mu_problem.ApproachProblem`)."""
from __future__ import annotations

import numpy as np

from multibody.control.mu_approach import constraint_report
from multibody.control.mu_dynamics import IndependentMUs, RigidRodMUs
from multibody.control.mu_problem import ApproachProblem
from riskassess.cases.approach import ApproachCase
from riskassess.cases.impact import CaseError


def build_problem(case: ApproachCase, source: str = "case") -> ApproachProblem:
    """The optimal-control problem of a validated case; CaseError for an impossible start.

    Parameters
    ----------
    case : ApproachCase
        The validated approach case (positions in m and velocities in m/s in the 2-D world frame,
        masses in kg, thrust bounds in N).
    source : str
        What the case came from (its file name), named in errors.

    Returns
    -------
    multibody.control.mu_problem.ApproachProblem
        Initial state x0: rigid rod [x_com, vx_com, y_com, vy_com, phi, phi_dot] (m, m/s, rad,
        rad/s); independent units [r1 (2,), v1 (2,), m1, r2, v2, m2] (m, m/s, kg), world frame.

    Raises
    ------
    CaseError
        When an MU starts inside the keep-out circle plus margin or outside the width bounds.
    """
    m, obj = case.model, case.objective
    if m.kind == "rigid_rod":
        model = RigidRodMUs(m.mass, m.length, m.fuel_rate)
        x0 = np.array([m.com_position[0], m.com_velocity[0], m.com_position[1], m.com_velocity[1], m.rod_angle,
                       m.rod_rate])
        widths, positions, min_mass = None, None, None
    else:
        model = IndependentMUs(m.fuel_rate)
        x0 = np.r_[m.unit_1_position, m.unit_1_velocity, m.initial_mass, m.unit_2_position, m.unit_2_velocity,
                   m.initial_mass]
        widths = None if m.width_min is None else (m.width_min, m.width_max)
        positions = None if m.position_min is None else (m.position_min, m.position_max)
        min_mass = m.min_mass
    free = {} if obj.kind == "min_fuel" else dict(final_time_bounds=(obj.final_time_min, obj.final_time_max),
                                                  final_time_guess=obj.final_time_guess)
    problem = ApproachProblem(
        model, x0, obj.kind, np.asarray(case.debris.center, float), case.debris.keep_out_radius,
        (case.thrust.min, case.thrust.max), case.collocation.intervals,
        final_time=obj.final_time if obj.kind == "min_fuel" else None,
        time_weight=getattr(obj, "time_weight", 1.0), impulse_weight=getattr(obj, "impulse_weight", 1.0),
        width_bounds=widths, position_bounds=positions, min_unit_mass=min_mass,
        final_at_rest=case.collocation.final_at_rest, keep_out_margin=case.collocation.keep_out_margin,
        control_smoothing=case.collocation.control_smoothing, **free)
    _check_start(problem, source)
    return problem


def _check_start(problem: ApproachProblem, source: str) -> None:
    """The initial state must satisfy the path constraints (the NLP fixes it)."""
    start = constraint_report(problem, problem.initial_state[:, None], np.zeros((6, 1)) + problem.thrust_bounds[0])
    if start["keep_out_margin_m"] < problem.keep_out_margin:
        raise CaseError(f"{source}: model: an MU starts {start['min_unit_debris_distance_m']:.4g} m from the debris "
                        f"centre, inside debris.keep_out_radius + collocation.keep_out_margin")
    if problem.width_bounds is not None and start["width_margin_m"] < 0:
        raise CaseError(f"{source}: model: the MUs start {start['width_range_m'][0]:.4g} m apart, outside "
                        f"width_min..width_max = {problem.width_bounds[0]:g}..{problem.width_bounds[1]:g} m")
