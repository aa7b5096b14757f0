"""The full-net towing model of a towing case (``simulation.model = "full-net"``; Boonrath, Singh & Botta
2024, Sec. 2.1, 4.1): the case's ``[full_net]`` table turned into a
:class:`multibody.net_towing.FullNetModel` started from the prepared wrapped state or from the net's
ejection (``full_net.start = "capture"``, :func:`capture_start`). The run and its
folder: :mod:`riskassess.stages.tow_fullnet`.

Wrapped start (docs/towing.md): at ``simulation.start_time`` the debris has the Table 2 state and
spins at the given rate about ``debris.spin_axis_body``; the net (draped and closed around it by
:func:`multibody.net_wrap.drape_and_close`, the same shape for every rate) turns with it; the chaser
keeps its Table 2 velocity and attitude but sits on the line from the central node towards its
Table 2 attachment point, the main tether at its natural length minus ``full_net.main_tether_slack``.
"""
from __future__ import annotations


import numpy as np

from multibody.control.attitude import sampled_boundary_layer
from multibody.control.lateral import lateral_params
from multibody.maths.rotations import quaternion_to_matrix, rotation_matrix_from_rotation_vector
from multibody.net_towing import FullNetModel
from multibody.net_wrap import drape_and_close, towing_net
from multibody.tow_switch import SwitchCriterion, lower_order_state
from riskassess.models.towing import case_decision_vector, case_thrust_law, towing_model
from riskassess.cases.towing import TowingCase

#: Height of the flat net above the cylinder before draping (m).
DROP_HEIGHT = 0.3


def debris_geometry(case: TowingCase) -> np.ndarray:
    """Cylinder [radius, half length, axial centre z_body] (m): d_D and L_D of Table 1; the geometric
    centre sits where the sub-tether attachments' axial asymmetry puts it (Table 1: z = -5.717 and
    5.283 for L_D = 11 m give -0.217 m: the CoM is 0.217 m towards +z_body, Sec. 4.1).

    Parameters
    ----------
    case : TowingCase
        A towing case (debris diameter and length, sub-tether attachments in the debris body frame).

    Returns
    -------
    (3,) float
        Radius (m), half length (m), axial centre along z, debris body frame (m).
    """
    z = np.asarray(case.sub_tethers.attachment_points_body, float)[:, 2]
    return np.array([case.debris.diameter / 2.0, case.debris.length / 2.0, 0.5 * (z.min() + z.max())])


def contact_law(case: TowingCase) -> np.ndarray:
    """The kernel's contact array of the node-debris contact (:mod:`multibody.net_towing_kernel`).

    Parameters
    ----------
    case : TowingCase
        A towing case with a ``[full_net.contact]`` table.

    Returns
    -------
    (6,) float
        k_n (N/m^n), n (-), d_n = 1.5 alpha k_n (Hunt-Crossley, alpha in s/m), mu_s (-), mu_k (-),
        V_t0 (m/s).
    """
    c = case.full_net.contact
    return np.array([c.stiffness, c.exponent, 1.5 * c.hunt_crossley_alpha * c.stiffness, c.mu_static, c.mu_kinetic,
                     c.transition_speed])


def _bodies(case: TowingCase):
    ch, de = case.chaser, case.debris
    rot = np.array([quaternion_to_matrix(np.asarray(b.attitude_quaternion, float)) for b in (ch, de)])
    com = np.array([ch.position_inertial, de.position_inertial], float)
    return rot, com


def wrapped_net(case: TowingCase):
    """The net and its wrapped node positions (n, 3) (m, debris frame): built flat on the cylinder's
    side that faces the chaser's attachment point, draped and closed. Returns (TowingNet, x_body).

    Parameters
    ----------
    case : TowingCase
        A towing case with a ``[full_net]`` table.

    Returns
    -------
    net : multibody.net_wrap.TowingNet
        The net, closing loop at its closed lengths.
    x_body : (n, 3) float
        Wrapped node positions relative to the debris CoM, debris body frame (m).
    """
    fn = case.full_net
    geometry = debris_geometry(case)
    rot, com = _bodies(case)
    a_point = com[0] + rot[0] @ np.asarray(case.chaser.tether_attachment_body, float)
    up = rot[1].T @ (a_point - com[1])
    up[2] = 0.0
    up /= np.linalg.norm(up)
    center = up * (geometry[0] + DROP_HEIGHT) + np.array([0.0, 0.0, geometry[2]])
    net = towing_net(fn.side_length, fn.nodes_per_side, case.net_mass, fn.corner_mass, fn.node_radius, fn.corner_radius,
                     fn.thread_axial_rigidity, fn.thread_damping, fn.closing_axial_rigidity, fn.closed_fraction, center,
                     -up)
    x_body = drape_and_close(net, geometry, contact_law(case), up)
    top = net.topology
    top.rest_lengths[-len(net.closing_rest_closed):] = net.closing_rest_closed  # the loop stays closed
    top.stiffness[-len(net.closing_rest_closed):] = net.closing_stiffness(net.closing_rest_closed)
    return net, x_body


def wrapped_start(case: TowingCase, net, x_body, spin_rate_deg_s: float):
    """Initial state of the wrapped start (module doc): node positions and velocities (n, 3)
    (m, m/s, inertial), chaser CoM (m, inertial), debris angular velocity (rad/s, body).

    Parameters
    ----------
    case : TowingCase
        A towing case (chaser and debris states, inertial frame).
    net : multibody.net_wrap.TowingNet
        The wrapped net (:func:`wrapped_net`).
    x_body : (n, 3) float
        Wrapped node positions relative to the debris CoM, debris body frame (m).
    spin_rate_deg_s : float
        Debris spin rate about ``debris.spin_axis_body`` (deg/s).

    Returns
    -------
    nodes : (n, 3) float
        Node positions, inertial (m).
    velocities : (n, 3) float
        Node velocities, inertial (m/s), turning with the debris.
    chaser : (3,) float
        Chaser CoM, inertial (m).
    omega : (3,) float
        Debris angular velocity, debris body frame (rad/s).
    """
    rot, com = _bodies(case)
    de = case.debris
    omega = np.deg2rad(spin_rate_deg_s) * np.asarray(de.spin_axis_body, float) / np.linalg.norm(de.spin_axis_body)
    nodes = com[1] + x_body @ rot[1].T
    velocities = np.asarray(de.velocity_inertial, float) + np.cross(omega, x_body) @ rot[1].T
    arm = rot[0] @ np.asarray(case.chaser.tether_attachment_body, float)
    node = nodes[net.central]
    direction = (com[0] + arm - node) / np.linalg.norm(com[0] + arm - node)
    chaser = node + (case.main_tether.natural_length - case.full_net.main_tether_slack) * direction - arm
    return nodes, velocities, chaser, omega


def capture_start(case: TowingCase, spin_rate_deg_s: float):
    """Initial state of the capture start at t = 0 (Sec. 2.1, 4.1): chaser and debris at their
    Table 2 states (v_D/C = 0), the debris spinning about ``debris.spin_axis_body``; the open net
    flat, normal to r_D/C (the unit vector from the chaser's tether attachment to the debris CoM),
    centred ``full_net.launch_offset`` ahead of the attachment, every node moving at the chaser's
    velocity plus ``full_net.launch_speed`` along r_D/C. Returns (TowingNet, node positions (n, 3)
    (m, inertial), node velocities (n, 3) (m/s, inertial), chaser CoM (m, inertial), debris angular
    velocity (rad/s, body)).

    Parameters
    ----------
    case : TowingCase
        A towing case with ``full_net.start = "capture"`` (launch offset in m, launch speed in m/s).
    spin_rate_deg_s : float
        Debris spin rate about ``debris.spin_axis_body`` (deg/s).
    """
    fn, de = case.full_net, case.debris
    rot, com = _bodies(case)
    a_point = com[0] + rot[0] @ np.asarray(case.chaser.tether_attachment_body, float)
    direction = (com[1] - a_point) / np.linalg.norm(com[1] - a_point)
    net = towing_net(fn.side_length, fn.nodes_per_side, case.net_mass, fn.corner_mass, fn.node_radius, fn.corner_radius,
                     fn.thread_axial_rigidity, fn.thread_damping, fn.closing_axial_rigidity, fn.closed_fraction,
                     a_point + fn.launch_offset * direction, direction)
    nodes = net.topology.positions.copy()
    velocities = np.tile(np.asarray(case.chaser.velocity_inertial, float) + fn.launch_speed * direction, (len(nodes), 1))
    omega = np.deg2rad(spin_rate_deg_s) * np.asarray(de.spin_axis_body, float) / np.linalg.norm(de.spin_axis_body)
    return net, nodes, velocities, com[0], omega


def full_net_model(case: TowingCase, spin_rate_deg_s: float | None = None, wrapped=None, end_time=None, step=None,
                   substeps=None, run_start=None) -> FullNetModel:
    """The full-net model of ``case`` at ``spin_rate_deg_s`` (default: the case's): from the wrapped
    state at ``simulation.start_time`` (``wrapped`` = (net, x_body) of :func:`wrapped_net`, computed
    if not given) or, with ``full_net.start = "capture"``, from the net's ejection at t = 0
    (:func:`capture_start`; ``wrapped`` is not used).

    Parameters
    ----------
    case : TowingCase
        A towing case with a ``[full_net]`` table.
    spin_rate_deg_s : float or None
        Debris spin rate about ``debris.spin_axis_body`` (deg/s).
    wrapped : tuple (TowingNet, (n, 3) float) or None
        A wrapped net and its node positions (m, debris body frame), to reuse across runs.
    end_time : float or None
        End of the run (s); default the case's.
    step : float or None
        Integration step (s); default ``full_net.step``; reduced to a divisor of the output interval.
    substeps : int or None
        Net substeps per step; default ``full_net.substeps``.
    run_start : riskassess.models.towing_from_run.RunStart or None
        With ``full_net.start = "run"``: the impact run's end state in the towing frame (net, nodes, debris
        state; ``spin_rate_deg_s`` is then not used: the debris turns as the run left it).

    Returns
    -------
    multibody.net_towing.FullNetModel
    """
    fn, sim, ch, de = case.full_net, case.simulation, case.chaser, case.debris
    rate = de.spin_rate_deg_s if spin_rate_deg_s is None else spin_rate_deg_s
    rot, com = _bodies(case)
    debris_v = np.asarray(de.velocity_inertial, float)
    if fn.start == "capture":
        net, nodes, velocities, chaser, omega = capture_start(case, rate)
        start, closing_duration = 0.0, fn.closing_duration
    elif fn.start == "run":
        if run_start is None:
            raise ValueError("full_net.start = 'run' needs the impact run's end state (towing_from_run.impact_run_start)")
        net, nodes, velocities = run_start.net, run_start.node_positions, run_start.node_velocities
        chaser, omega, start, closing_duration = com[0], run_start.debris_omega_body, run_start.time, fn.closing_duration
        rot[1], com[1], debris_v = run_start.debris_to_inertial, run_start.debris_position, run_start.debris_velocity
    else:
        net, x_body = wrapped if wrapped is not None else wrapped_net(case)
        nodes, velocities, chaser, omega = wrapped_start(case, net, x_body, rate)
        start, closing_duration = sim.start_time, None
    mt = case.main_tether
    tether = np.array([mt.stiffness, mt.damping, mt.natural_length])
    a_point = chaser + rot[0] @ np.asarray(ch.tether_attachment_body, float)
    z0 = np.linalg.norm(nodes[net.central] - a_point) - mt.natural_length
    law, params, state = case_thrust_law(case, tether, z0, 0.0, np.degrees(np.linalg.norm(omega)))  # the tow's spin
    h = fn.step if step is None else step
    h = sim.output_interval / np.ceil(sim.output_interval / h - 1e-9)
    ac = case.attitude_control
    return FullNetModel(
        net=net, node_positions=nodes, node_velocities=velocities, masses=np.array([ch.mass, de.nominal_mass]),
        inertia_body=np.array([np.diag(ch.principal_inertia), np.diag(de.principal_inertia)], float),
        attach_chaser_body=np.asarray(ch.tether_attachment_body, float), main_tether=tether,
        geometry=debris_geometry(case), contact_law=contact_law(case), mu=sim.mu,
        attitude=np.r_[float(ac.enabled), ac.k_gain, ac.gain,
                       sampled_boundary_layer(ac.boundary_layer, np.asarray(ac.gain, float), h)],
        thrust_law=law.NAME, thrust_along_body_z=law.ALONG_BODY_Z, thrust_params=params, thrust_state=state,
        positions=np.array([chaser, com[1]]), velocities=np.array([ch.velocity_inertial, debris_v], float),
        body_to_inertial=rot, omega_body=np.array([ch.angular_velocity_body, omega], float),
        start_time=start, end_time=sim.end_time if end_time is None else end_time, step=h,
        substeps=fn.substeps if substeps is None else substeps, output_interval=sim.output_interval,
        net_output_interval=fn.net_output_interval, closing_time=fn.closing_time, closing_duration=closing_duration,
        switch=switch_criterion(case), lateral=case_lateral(case))


def case_lateral(case: TowingCase) -> np.ndarray:
    """The case's ``[lateral]`` law as the kernel takes it (:func:`multibody.control.lateral.lateral_params`; zeros
    when off or when ``thrust.kind`` is not one of ``lateral.thrust_laws``), acting from ``thrust.t_on``."""
    la = case.lateral
    acting = la.enabled and case.thrust.kind in la.thrust_laws
    return lateral_params(acting, la.target, la.natural_frequency_rad_s, la.damping_ratio, la.max_force,
                          case.thrust.t_on, case.chaser.mass)


def switch_criterion(case: TowingCase):
    """The case's quasi-steady criterion (:class:`multibody.tow_switch.SwitchCriterion`), or None when
    ``full_net.switch_to_lower_order`` is off.

    Parameters
    ----------
    case : TowingCase
        A towing case with a ``[full_net]`` table.

    Returns
    -------
    multibody.tow_switch.SwitchCriterion or None
        Earliest switch (s; default ``thrust.t_on``), window (s; default three averaging blocks, 5 s when
        sample-wise), calm-net energy bound (J), variation bound (-), averaging block (s; default one debris
        spin period, 360 / ``debris.spin_rate_deg_s``).
    """
    fn = case.full_net
    if not fn.switch_to_lower_order:
        return None
    earliest = case.thrust.t_on if fn.switch_earliest is None else fn.switch_earliest
    averaging = fn.switch_averaging if fn.switch_averaging is not None else 360.0 / case.debris.spin_rate_deg_s
    window = fn.switch_window if fn.switch_window is not None else (3.0 * averaging if averaging > 0 else 5.0)
    return SwitchCriterion(earliest=float(earliest), window=float(window), kinetic_energy_max=fn.switch_kinetic_energy,
                           tension_rel_tol=fn.switch_tension_variation, averaging=float(averaging))


def net_start_state(full_model, state: dict) -> dict:
    """What a lower-order run needs of a full-net state (``NetTowResult.switch`` or ``.state_at``), in
    arrays (cacheable): time (s), chaser and debris CoM (m) and velocity (m/s), attitudes (body ->
    inertial), angular velocities (2, 3) (rad/s, body frames), the central node's position (m) and velocity
    (m/s), the net's mass (kg) and momentum (N s), the thrust law's state. Inertial frame.

    Parameters
    ----------
    full_model : multibody.net_towing.FullNetModel
        The full-net run's model.
    state : dict
        ``time``, ``q``, ``v`` (12,), ``node_positions``, ``node_velocities`` (n, 3), ``thrust_state``.

    Returns
    -------
    dict
    """
    q, v, central = state["q"], state["v"], full_model.net.central
    masses = full_model.net.topology.masses
    return {"start_time": float(state["time"]), "body_masses": np.asarray(full_model.masses, float),
            "chaser_com": full_model.positions[0] + q[0:3], "debris_com": full_model.positions[1] + q[6:9],
            "chaser_velocity": v[0:3].copy(), "debris_velocity": v[6:9].copy(),
            "body_to_inertial": np.array([rotation_matrix_from_rotation_vector(q[b:b + 3]) for b in (3, 9)]),
            "omega_body": np.array([v[3:6], v[9:12]]),
            "node_position": np.array(state["node_positions"][central], float),
            "node_velocity": np.array(state["node_velocities"][central], float),
            "net_mass": float(masses.sum()), "net_momentum": masses @ state["node_velocities"],
            "thrust_state": np.array(state["thrust_state"], float)}


def lower_order_from_net(case: TowingCase, start: dict, spin_rate_deg_s: float | None = None, s=None,
                         end_time: float | None = None, step: float | None = None):
    """The lower-order model started from a full-net state (:func:`net_start_state`;
    :func:`multibody.tow_switch.lower_order_state`: chaser and debris copied, P at the central node with its
    velocity, the debris velocity keeping the system's momentum), with the case's sub-tethers or ``s``.

    Parameters
    ----------
    case : TowingCase
        The towing case.
    start : dict
        :func:`net_start_state`.
    spin_rate_deg_s : float or None
        Only used to build the model before its state is replaced (deg/s).
    s : (4,) float or None
        Sub-tether decision vector (eq. 22); default the case's.
    end_time : float or None
        End of the lower-order run (s); default the case's.
    step : float or None
        Its step (s); default the case's.

    Returns
    -------
    model : multibody.towing.TowingModel
        Starting at ``start["start_time"]``.
    balance : dict
        The momentum balance of :func:`multibody.tow_switch.lower_order_state` plus the start time (s),
        the main-tether elongation (m) and the sub-tether elongations (m) at the start.
    """
    s = case_decision_vector(case) if s is None else np.asarray(s, float)
    model = towing_model(case, spin_rate_deg_s, s, end_time=end_time, step=step)
    p_pos, p_vel, debris_v, balance = lower_order_state(
        start["body_masses"], start["net_mass"], start["net_momentum"], start["node_position"], start["node_velocity"],
        start["chaser_velocity"], start["debris_velocity"], s[3])
    rot = np.asarray(start["body_to_inertial"], float)
    model.positions = np.array([p_pos, start["chaser_com"], start["debris_com"]], float)
    model.velocities = np.array([p_vel, start["chaser_velocity"], debris_v], float)
    model.body_to_inertial = rot
    model.omega_body = np.array(start["omega_body"], float)
    model.start_time = float(start["start_time"])
    model.thrust_state = np.array(start["thrust_state"], float)
    a_point = model.positions[1] + rot[0] @ model.attach_chaser_body
    points = model.positions[2] + model.attach_debris_body @ rot[1].T
    balance = {**balance, "time_s": model.start_time,
               "main_tether_elongation_m": float(np.linalg.norm(p_pos - a_point) - model.tether[2]),
               "sub_tether_elongations_m": (np.linalg.norm(points - p_pos, axis=1) - model.tether[5]).tolist()}
    return model, balance


def lower_order_after_switch(case: TowingCase, full, s=None, end_time: float | None = None):
    """The lower-order model that continues a full-net run stopped at quasi-steady state
    (:func:`lower_order_from_net` of ``full.switch``).

    Parameters
    ----------
    case : TowingCase
        The towing case.
    full : multibody.net_towing.NetTowResult
        The full-net run, stopped by its switch criterion (``full.switch`` set).
    s : (4,) float or None
        Sub-tether decision vector (eq. 22); default the case's.
    end_time : float or None
        End of the lower-order run (s); default the case's.

    Returns
    -------
    model : multibody.towing.TowingModel
    balance : dict
        :func:`lower_order_from_net`'s.
    """
    if full.switch is None:
        raise ValueError("the full-net run did not reach quasi-steady state: nothing to switch from")
    return lower_order_from_net(case, net_start_state(full.model, full.switch), s=s, end_time=end_time)
