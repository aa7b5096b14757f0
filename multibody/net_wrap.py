"""The towing net: a square lumped-mass net with corner masses and a closing mechanism, and its
prepared wrapped state around the Zenit-2 cylinder (Boonrath, Singh & Botta 2024, Sec. 2.1, 4.1).

Topology from :func:`multibody.net.flat_square_net` (N x N nodes, corner masses on the corners);
the closing mechanism is a loop of tension-only threads laced through the four corner masses and
two perimeter nodes per side (twelve lacing points, Sec. 2.1), appended as the last
:data:`~multibody.closing.N_CLOSING` threads (:mod:`multibody.closing`, shared with the impact model);
shortening their natural length closes the net.

The wrapped state (:func:`drape_and_close`) is made by the model itself, in the debris frame with
the debris held still: the net starts flat above the cylinder's side facing the chaser,
falls onto it under a pseudo-gravity towards the axis and drapes over it, the closing loop is reeled in
to ``closed_fraction`` of its length, then the pseudo-gravity is removed and the net settles under
drag. Every node ends outside the cylinder, threads at or below their natural length except where
the closed loop pulls. Positions in the debris frame (origin at the debris CoM, m).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import njit

from multibody.closing import N_CLOSING, append_closing_loop, closing_stiffness
from multibody.net import NetTopology, flat_square_net
from multibody.net_towing_kernel import (ACC_SIZE, CYL_HALF, CYL_RADIUS, CYL_Z, DebrisBody, DebrisMotion, NetThreads,
                                         TetherEnd, cylinder_distance, net_forces)


@dataclass(frozen=True)
class TowingNet:
    """Net topology with its closing loop (SI; positions in the frame they were built in).

    Attributes
    ----------
    topology : NetTopology           Net nodes, corner masses last; threads end with the closing loop.
    central : int                    Node the main tether attaches to (the net's central node).
    closing_rest_open : (12,) float  Natural lengths of the closing threads before closing (m).
    closing_rest_closed : (12,) float  Their natural lengths once closed (m).
    closing_axial_rigidity : float   EA of the closing thread (N).
    """

    topology: NetTopology
    central: int
    closing_rest_open: np.ndarray
    closing_rest_closed: np.ndarray
    closing_axial_rigidity: float

    def closing_stiffness(self, rest):
        """Stiffness EA/l0 (N/m) of each closing thread at natural lengths ``rest``.

        Parameters
        ----------
        rest : (12,) float
            Natural lengths of the closing threads (m).
        """
        return closing_stiffness(self.closing_axial_rigidity, rest)


def towing_net(side_length, nodes_per_side, net_mass, corner_mass, node_radius, corner_radius, thread_axial_rigidity,
               thread_damping, closing_axial_rigidity, closed_fraction, center_body, normal_body) -> TowingNet:
    """A flat net of ``net_mass`` centred at ``center_body`` with its normal ``normal_body``, corner
    masses one mesh length out along the diagonals, closing loop appended open (natural lengths =
    straight distances between lacing points).

    Parameters
    ----------
    side_length : float
        Side of the square net (m).
    nodes_per_side : int
        N of the N x N node grid.
    net_mass : float
        Whole net, corner masses included (kg).
    corner_mass : float
        Each of the four corner masses (kg).
    node_radius, corner_radius : float
        Contact radii of a net node and of a corner mass (m).
    thread_axial_rigidity : float
        EA of a net thread (N).
    thread_damping : float
        Axial damping of every thread (N s/m).
    closing_axial_rigidity : float
        EA of the closing thread (N).
    closed_fraction : float
        Closed loop length over its open length (-).
    center_body : (3,) float
        Net centre (m), debris body frame.
    normal_body : (3,) float
        Net normal (any length), debris body frame.

    Returns
    -------
    TowingNet
        Positions in the debris body frame (m).
    """
    n = nodes_per_side
    node_mass = (net_mass - 4.0 * corner_mass) / (n * n)
    if node_mass <= 0.0:
        raise ValueError(f"corner masses 4 x {corner_mass} kg leave nothing of the net mass {net_mass} kg for the nodes")
    mesh = side_length / (n - 1)
    net = flat_square_net(center_body, normal_body, side_length, n, node_mass, node_radius, thread_axial_rigidity,
                          thread_damping, corner_mass, corner_radius, mesh)
    topology, rest_open = append_closing_loop(net, closing_axial_rigidity, thread_damping)
    rest_closed = closed_fraction * rest_open
    return TowingNet(topology, (n // 2) * n + n // 2, rest_open, rest_closed, float(closing_axial_rigidity))


@dataclass(frozen=True)
class DrapeSchedule:
    """Pseudo-time schedule of the wrapping (s, m/s^2, 1/s): fall and drape, reel in, settle."""

    fall: float = 4.0
    reel: float = 6.0
    settle: float = 6.0
    pseudo_gravity: float = 2.0
    drag: float = 3.0
    step: float = 1e-4


@njit(cache=True)
def _drape(x_body, v_body, masses, radii, threads, rest, stiffness, damping, central, rest_open, rest_closed, ea,
           geometry, law, up_body, fall, reel, settle, gravity, drag, h):
    n_closing = rest_open.shape[0]
    first = threads.shape[0] - n_closing
    f, lag = np.zeros_like(x_body), np.zeros_like(x_body)
    acc, work = np.zeros(ACC_SIZE), np.zeros(21)
    zeros3, big = np.zeros(3), 1e30
    rot, tether = np.eye(3), np.zeros(3)
    inverse = np.zeros((3, 3))
    far_body = 1e9 * up_body  # the (force-free) main tether's other end
    n_steps = int((fall + reel + settle) / h)
    fixed_rest = np.zeros(len(rest))
    for k in range(n_steps):
        t = k * h
        ramp = min(1.0, max(0.0, (t - fall) / reel))
        for c in range(n_closing):
            rest[first + c] = rest_open[c] + ramp * (rest_closed[c] - rest_open[c])
            stiffness[first + c] = ea / rest[first + c]
        # the wrap's reel is a pseudo-time procedure (a drape, not a motion), so its dampers keep reading l'
        net_forces(x_body, v_body, lag, NetThreads(masses, radii, threads, rest, stiffness, damping, fixed_rest),
                   zeros3, 0.0,
                   central, TetherEnd(tether, far_body, zeros3, zeros3), DebrisMotion(zeros3, rot, zeros3, zeros3),
                   DebrisBody(big, inverse, geometry, law), h, f, acc, work)
        g = gravity if t < fall + reel else 0.0
        for i in range(x_body.shape[0]):
            for a in range(3):
                f[i, a] -= masses[i] * g * up_body[a]
                v_body[i, a] += h * (f[i, a] / masses[i] - drag * v_body[i, a])
                x_body[i, a] += h * v_body[i, a]
    v_body[:] = 0.0


def drape_and_close(net: TowingNet, geometry, contact_law, up_body, schedule: DrapeSchedule = DrapeSchedule()) -> np.ndarray:
    """The wrapped node positions after draping ``net`` and closing it (module doc). The net's
    threads end at the closed natural lengths.

    Parameters
    ----------
    net : TowingNet
        Built flat on the ``up_body`` side of the cylinder, debris body frame.
    geometry : (3,) float
        The cylinder: [radius, half length, axial centre z] (m), debris body frame.
    contact_law : (k,) float
        The kernel's contact array (:mod:`multibody.net_towing_kernel`).
    up_body : (3,) float
        Unit vector from the cylinder towards the flat net, debris body frame; the pseudo-gravity
        acts along ``-up_body``.
    schedule : DrapeSchedule
        Pseudo-time schedule (s, m/s^2, 1/s).

    Returns
    -------
    (n, 3) float
        Node positions (m), debris body frame.
    """
    top = net.topology
    x_body = np.array(top.positions, float)
    v_body = np.zeros_like(x_body)
    rest, stiffness = top.rest_lengths.copy(), top.stiffness.copy()
    _drape(x_body, v_body, top.masses, top.radii, top.threads, rest, stiffness, top.damping, net.central,
           net.closing_rest_open, net.closing_rest_closed, net.closing_axial_rigidity, np.asarray(geometry, float),
           np.asarray(contact_law, float), np.asarray(up_body, float), schedule.fall, schedule.reel, schedule.settle, schedule.pseudo_gravity,
           schedule.drag, schedule.step)
    return x_body


def wrap_summary(x_body, net: TowingNet, geometry) -> dict:
    """Shape figures of a wrapped net (debris frame): smallest node clearance to the cylinder (m),
    largest thread strain (-), how far the central node sits from the cylinder axis (m).

    Parameters
    ----------
    x_body : (n, 3) float
        Node positions (m), debris body frame.
    net : TowingNet
        The net (radii, threads, closed natural lengths).
    geometry : (3,) float
        The cylinder: [radius, half length, axial centre z] (m), debris body frame.

    Returns
    -------
    dict
        JSON-ready figures (keys end in their unit; ``central_node_body`` in m, debris body frame).
    """
    top = net.topology
    clear = [cylinder_distance(p_body[0], p_body[1], p_body[2], np.asarray(geometry, float))[0] - r
             for p_body, r in zip(x_body, top.radii)]
    length = np.linalg.norm(x_body[top.threads[:, 1]] - x_body[top.threads[:, 0]], axis=1)
    rest = np.r_[top.rest_lengths[:-N_CLOSING], net.closing_rest_closed]
    strain = length / rest - 1.0
    return {"min_clearance_m": float(min(clear)), "max_net_strain": float(strain[:-N_CLOSING].max()),
            "max_closing_strain": float(strain[-N_CLOSING:].max()),
            "central_node_body": x_body[net.central].tolist(),
            "geometry": {"radius": float(geometry[CYL_RADIUS]), "half_length": float(geometry[CYL_HALF]),
                         "z_center": float(geometry[CYL_Z])}}
