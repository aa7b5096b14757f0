"""The lower-order towing model of a towing case (Boonrath, Singh & Botta 2024).

:func:`towing_model` turns the validated case (:mod:`riskassess.cases.towing`) into a
:class:`multibody.towing.TowingModel` for a given debris spin rate and sub-tether decision vector
``s = [log10 k_ST, l_ST0, log10 c_ST, m_P/m_net]`` (eq. 22); :func:`case_thrust_law` is the case's thrust
law, shared with the full-net model (:mod:`riskassess.models.towing_fullnet`). The stage
``riskassess tow`` that runs them and writes the run folder is :mod:`riskassess.stages.tow`.
"""
from __future__ import annotations

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from multibody.control.attitude import sampled_boundary_layer
from multibody.maths.rotations import quaternion_to_matrix
from multibody.control.mrac import abstracted_tether, command_elongation
from multibody.control.thrust_budget import governed_elongation
from multibody.control.thrust_laws import LAWS
from multibody.towing import TowingModel
from riskassess.cases.towing import TowingCase

def case_decision_vector(case: TowingCase) -> np.ndarray:
    """The case's own sub-tether parameters as s (eq. 22).

    Parameters
    ----------
    case : TowingCase
        A validated towing case.

    Returns
    -------
    (4,) float
        [log10 k_ST (k_ST in N/m), l_ST0 (m), log10 c_ST (c_ST in N s/m; 1e-300 stands in for 0),
        m_P/m_net (-)].
    """
    st = case.sub_tethers
    return np.array([np.log10(st.stiffness), st.natural_length, np.log10(max(st.damping, 1e-300)),
                     st.connection_mass_fraction])


def connection_point_start(debris_com, debris_to_inertial, attach_body, toward, rest_length) -> np.ndarray:
    """Initial connection point (m, inertial): on the line from the debris CoM towards ``toward``
    (the main tether's chaser end), where the farthest sub-tether attachment is exactly
    ``rest_length`` away (all sub-tethers just slack or taut); the point nearest to all
    attachments when ``rest_length`` cannot reach them.

    Parameters
    ----------
    debris_com : (3,) float
        Debris CoM, inertial (m).
    debris_to_inertial : (3, 3) float
        Debris attitude, rotation debris body -> inertial.
    attach_body : (n, 3) float
        Sub-tether attachment points relative to the debris CoM, debris body frame (m).
    toward : (3,) float
        Main-tether attachment on the chaser, inertial (m).
    rest_length : float
        Sub-tether natural length l_ST0 (m).

    Returns
    -------
    (3,) float
        Connection point P, inertial (m).
    """
    axis = (toward - debris_com) / np.linalg.norm(toward - debris_com)
    points = debris_com + attach_body @ debris_to_inertial.T

    def reach(d):
        return np.linalg.norm(debris_com + d * axis - points, axis=1).max() - rest_length

    span = np.linalg.norm(toward - debris_com)
    nearest = minimize_scalar(reach, bounds=(0.0, span), method="bounded").x
    if reach(nearest) >= 0.0:
        return debris_com + nearest * axis
    return debris_com + brentq(reach, nearest, span, xtol=1e-12) * axis


def case_thrust_law(case: TowingCase, tether, z0, z_rate0, spin_rate_deg_s=None):
    """The case's thrust law (a plug-in of :mod:`multibody.control.thrust_laws`), its parameters and
    initial state, for a tow at ``spin_rate_deg_s`` (the laws' breathing notch, ``mrac.breathing_notch``, sits at
    twice it).

    Parameters
    ----------
    case : TowingCase
        A validated towing case (``[thrust]``, the law's ``CASE_SECTIONS``, chaser mass).
    tether : (3,) or (6,) float
        Main tether first: k_MT (N/m), c_MT (N s/m), ...; only the first two are read.
    z0 : float
        Initial main-tether elongation (m).
    z_rate0 : float
        Initial elongation rate (m/s).
    spin_rate_deg_s : float or None
        The tow's debris spin rate (deg/s), the GNC's estimate; default ``debris.spin_rate_deg_s``.

    Returns
    -------
    law : module
        The law's plug-in module (``NAME``, ``ALONG_BODY_Z``, compiled ``command``).
    params : (p,) float
        The law's constants (its module doc).
    state : (q,) float
        Its initial state.
    """
    law = LAWS[case.thrust.kind]
    if spin_rate_deg_s is not None:
        case = case.model_copy(update=dict(debris=case.debris.model_copy(update=dict(spin_rate_deg_s=spin_rate_deg_s))))
    params, state = law.arrays(case, tether, z0, z_rate0)
    return law, params, state


def reference_command(case: TowingCase) -> float:
    """The elongation command z_d of the MRAC reference model (eq. 13) (m): ``mrac.desired_elongation``
    itself, or, with ``mrac.settle_at_desired``, z_d (k_MT + K_P) / K_P, the command whose static
    balance :math:`k_{MT} z_m = K_P (z_d - z_m)` puts the reference at the desired elongation.

    Parameters
    ----------
    case : TowingCase
        A validated towing case (``[mrac]``, main-tether stiffness k_MT in N/m).

    Returns
    -------
    float
        z_d (m).
    """
    m, mt = case.mrac, case.main_tether
    k_mt, _ = abstracted_tether(case, [mt.stiffness, mt.damping])
    return command_elongation(governed_elongation(case, k_mt), k_mt, m.k_p, m.settle_at_desired)


def towing_model(case: TowingCase, spin_rate_deg_s: float | None = None, s=None, step: float | None = None,
                 end_time: float | None = None) -> TowingModel:
    """The lower-order model of ``case`` with the debris spinning at ``spin_rate_deg_s`` (default: the
    case's) and sub-tethers ``s`` (default: the case's). The step is the case's (or ``step``),
    reduced to a divisor of the output interval. The connection point is implicit
    (:mod:`multibody.connection_point`), so the step does not depend on ``s``. The case's ``[lateral]`` law is
    not part of this model (its chaser has no lateral thrust; both elongation laws hold z_d on it without one,
    docs/towing.md, "MRAC on both plants"): the model is the same with the law on or off.

    Parameters
    ----------
    case : TowingCase
        A validated towing case (states in the inertial frame, Earth-centred).
    spin_rate_deg_s : float or None
        Debris spin rate about ``debris.spin_axis_body`` (deg/s, the case's unit; converted to rad/s).
    s : (4,) float or None
        Sub-tether decision vector [log10 k_ST, l_ST0 (m), log10 c_ST, m_P/m_net] (eq. 22).
    step : float or None
        Integration step (s).
    end_time : float or None
        End of the run (s).

    Returns
    -------
    multibody.towing.TowingModel
    """
    s = case_decision_vector(case) if s is None else np.asarray(s, float)
    sim, ch, de = case.simulation, case.chaser, case.debris
    mt = case.main_tether
    tether = np.array([mt.stiffness, mt.damping, mt.natural_length, 10.0 ** s[0], 10.0 ** s[2], s[1]])
    masses = np.array([case.net_mass * s[3], ch.mass, de.nominal_mass + case.net_mass * (1.0 - s[3])])
    rot = np.array([quaternion_to_matrix(np.asarray(b.attitude_quaternion, float)) for b in (ch, de)])
    com = np.array([ch.position_inertial, de.position_inertial], float)
    attach_debris = np.asarray(case.sub_tethers.attachment_points_body, float)
    rate = np.deg2rad(de.spin_rate_deg_s if spin_rate_deg_s is None else spin_rate_deg_s)
    omega = np.array([ch.angular_velocity_body, rate * np.asarray(de.spin_axis_body) / np.linalg.norm(de.spin_axis_body)])
    a_point = com[0] + rot[0] @ np.asarray(ch.tether_attachment_body, float)
    p0 = connection_point_start(com[1], rot[1], attach_debris, a_point, s[1])
    if case.sub_tethers.connection_point_start_inertial is not None:
        p0 = np.asarray(case.sub_tethers.connection_point_start_inertial, float)
    v_p0 = np.asarray(de.velocity_inertial) + rot[1] @ np.cross(omega[1], rot[1].T @ (p0 - com[1]))
    z0 = np.linalg.norm(p0 - a_point) - mt.natural_length
    law, params, state = case_thrust_law(case, tether, z0, 0.0, np.rad2deg(rate))
    model = TowingModel(
        masses=masses, inertia_body=np.array([np.diag(ch.principal_inertia), np.diag(de.principal_inertia)], float),
        attach_chaser_body=np.asarray(ch.tether_attachment_body, float), attach_debris_body=attach_debris,
        tether=tether, mu=sim.mu, attitude=np.zeros(8), thrust_law=law.NAME, thrust_along_body_z=law.ALONG_BODY_Z,
        thrust_params=params, thrust_state=state,
        positions=np.array([p0, com[0], com[1]]), velocities=np.array([v_p0, ch.velocity_inertial, de.velocity_inertial], float),
        body_to_inertial=rot, omega_body=omega, start_time=sim.start_time,
        end_time=sim.end_time if end_time is None else end_time, step=sim.step if step is None else step,
        output_interval=sim.output_interval)
    model.step = sim.output_interval / np.ceil(sim.output_interval / model.step - 1e-9)
    ac = case.attitude_control
    model.attitude = np.r_[float(ac.enabled), ac.k_gain, ac.gain,
                           sampled_boundary_layer(ac.boundary_layer, np.asarray(ac.gain, float), model.step)]
    return model
