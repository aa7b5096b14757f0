"""Lumped-mass (multi-spring-damper) net: topology, thread properties and thread forces.

Cuadrat-Grzybowski & Gill 2024, Section 2.2: the square net of side :math:`L` has
:math:`N\\times N` nodes carrying the thread mass evenly, joined by massless
Kelvin-Voigt threads that only pull (eq. 1); four bullets hang on the corners.
Optional bending stiffness (the paper's recommendation 2) adds a rotational spring
between consecutive collinear threads.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numba import njit, uint64

from multibody.jit_cache import NO_REFCOUNTS
from multibody.relative_motion import velocity_field


@dataclass(frozen=True)
class NetTopology:
    """Arrays describing a net; every position is in the LVLH frame (m).

    Attributes
    ----------
    positions : (n, 3) float   Initial node positions (m), net nodes first, bullets last.
    masses : (n,) float         Node masses (kg).
    radii : (n,) float          Contact radii (m).
    threads : (m, 2) int        Node pairs joined by a thread.
    rest_lengths : (m,) float   Unstretched thread lengths (m).
    stiffness : (m,) float      Axial stiffness EA/l0 (N/m).
    damping : (m,) float        Axial damping (N s/m).
    bending_triples : (b, 3) int  Node triples (a, b, c) along one thread line, b in the middle.
    bending_stiffness : (b,) float  Rotational stiffness at b (N m/rad), zero when off.
    nodes_per_side : int
    n_bullets : int
    """

    positions: np.ndarray
    masses: np.ndarray
    radii: np.ndarray
    threads: np.ndarray
    rest_lengths: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    bending_triples: np.ndarray
    bending_stiffness: np.ndarray
    nodes_per_side: int
    n_bullets: int

    @property
    def n_nodes(self) -> int:
        return len(self.masses)


def single_node_net(position_lvlh, mass: float, radius: float) -> NetTopology:
    """A "net" of one free node and no threads: where a model needs a net and has none
    (the sequential method's driven debris, analytic tests).

    Parameters
    ----------
    position_lvlh : (3,) float
        The node's position (m), LVLH.
    mass : float
        Its mass (kg).
    radius : float
        Its contact radius (m).
    """
    return NetTopology(
        positions=np.atleast_2d(np.asarray(position_lvlh, float)), masses=np.array([float(mass)]),
        radii=np.array([float(radius)]), threads=np.zeros((0, 2), np.int64), rest_lengths=np.zeros(0),
        stiffness=np.zeros(0), damping=np.zeros(0), bending_triples=np.zeros((0, 3), np.int64),
        bending_stiffness=np.zeros(0), nodes_per_side=1, n_bullets=0)


def square_grid_threads(nodes_per_side: int) -> np.ndarray:
    """Thread node pairs of a square mesh, row-major node numbering: (2 N (N-1), 2) int.

    Parameters
    ----------
    nodes_per_side : int
        N of the N x N grid.
    """
    idx = np.arange(nodes_per_side**2).reshape(nodes_per_side, nodes_per_side)
    along_first = np.c_[idx[:-1, :].ravel(), idx[1:, :].ravel()]
    along_second = np.c_[idx[:, :-1].ravel(), idx[:, 1:].ravel()]
    return np.vstack([along_first, along_second])


def square_grid_bending_triples(nodes_per_side: int) -> np.ndarray:
    """Triples of consecutive nodes along each thread line: (2 N (N-2), 3) int.

    Parameters
    ----------
    nodes_per_side : int
        N of the N x N grid.
    """
    idx = np.arange(nodes_per_side**2).reshape(nodes_per_side, nodes_per_side)
    first = np.c_[idx[:-2, :].ravel(), idx[1:-1, :].ravel(), idx[2:, :].ravel()]
    second = np.c_[idx[:, :-2].ravel(), idx[:, 1:-1].ravel(), idx[:, 2:].ravel()]
    return np.vstack([first, second])


def thread_node_mass(side_length, nodes_per_side, diameter, density):
    """Net node mass (kg): total thread mass spread evenly over the nodes (paper Sec. 2.2.2).

    Parameters
    ----------
    side_length : float
        Side of the square net (m).
    nodes_per_side : int
        N of the N x N grid.
    diameter : float
        Thread diameter (m).
    density : float
        Thread material density (kg/m^3).
    """
    mesh = side_length / (nodes_per_side - 1)
    n_threads = 2 * nodes_per_side * (nodes_per_side - 1)
    area = np.pi * diameter**2 / 4.0
    return n_threads * mesh * area * density / nodes_per_side**2


def in_plane_axes(direction):
    """Two unit vectors spanning the net plane, normal to the launch ``direction`` (LVLH).

    The first axis is LVLH x (radial) projected on the plane, or LVLH z when the
    launch is radial.

    Parameters
    ----------
    direction : (3,) float
        Launch direction (any length), LVLH (or any frame: the axes come in the same frame, the
        first from its x axis).

    Returns
    -------
    e1, e2 : (3,) float
        Unit vectors, same frame; (e1, e2, direction) is right-handed.
    """
    direction_unit = np.asarray(direction, float) / np.linalg.norm(direction)
    seed_axis = np.array([1.0, 0.0, 0.0]) if abs(direction_unit[0]) < 0.9 else np.array([0.0, 0.0, 1.0])
    e1 = seed_axis - (seed_axis @ direction_unit) * direction_unit
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(direction_unit, e1)


def bowl_net_positions(net: NetTopology, direction, sag: float, mouth: float = 1.0) -> np.ndarray:
    """Node positions of a net arriving as a bowl: its centre trailing its corners by ``sag``.

    A net pulled open by leading corner masses does not arrive flat (its deployment's drag of the bullets
    on the mesh; the seed paper's net is ejected and "deployment energy damping" precedes its impact, Sec. 3.5).
    The offset along ``direction`` is a paraboloid in each node's distance rho from the grid centre,
    -sag (1 - (rho / rho_corner)^2) (bullets beyond the corners lead slightly); the in-plane offsets are scaled
    by ``mouth``, or less where the sag needs it, so that no thread is longer than its rest length: the bowl
    starts without tension.

    Parameters
    ----------
    net : NetTopology
        A flat net (:func:`flat_square_net`), positions LVLH (m).
    direction : (3,) float
        Launch direction, LVLH (-), normal to the flat net.
    sag : float
        Depth of the bowl (m), the centre trailing the corners; 0 with ``mouth`` 1 gives the flat positions (to
        round-off).
    mouth : float
        Largest in-plane scale (-), in (0, 1]: a mouth not fully open.

    Returns
    -------
    (n, 3) float
        Node positions, LVLH (m).

    Raises
    ------
    ValueError
        When the sag is too deep for any thread to keep its rest length (sag >= ~ rho_corner / 2).
    """
    direction = np.asarray(direction, float) / np.linalg.norm(direction)
    grid = net.positions[: net.nodes_per_side ** 2]
    centre = grid.mean(axis=0)
    offset = net.positions - centre
    in_plane = offset - np.outer(offset @ direction, direction)
    rho = np.linalg.norm(in_plane, axis=1)
    axial = -sag * (1.0 - (rho / rho[: len(grid)].max()) ** 2)
    a, b = net.threads[:, 0], net.threads[:, 1]
    room = net.rest_lengths ** 2 - (axial[a] - axial[b]) ** 2
    if room.min() <= 0.0:
        raise ValueError(f"a bowl of sag {sag:g} m is too deep for this net: a thread would be longer than its rest "
                         "length at any opening (allowed: below about a third of the side length)")
    span = np.linalg.norm(in_plane[a] - in_plane[b], axis=1)
    scale = min(float(mouth), float(np.sqrt((room / span ** 2).min())))
    return centre + scale * in_plane + np.outer(offset @ direction + axial, direction)


def flat_square_net(center, direction, side_length, nodes_per_side, node_mass, node_radius,
                    thread_axial_rigidity, thread_damping, bullet_mass, bullet_radius,
                    bullet_tether_length, bending_rigidity=0.0) -> NetTopology:
    """A fully spread square net, normal to ``direction``, with a bullet on each corner.

    Parameters
    ----------
    center, direction : (3,) float
        Net centre (m) and launch direction, LVLH (the towing net passes the debris body frame:
        positions come out in the frame given).
    side_length : float
        Side of the square of net nodes (m).
    nodes_per_side : int
        N of the N x N node grid.
    node_mass, node_radius : float
        Mass (kg) and contact radius (m) of each net node.
    bullet_mass, bullet_radius : float
        Mass (kg) and contact radius (m) of each corner bullet.
    thread_axial_rigidity : float
        EA of a thread (N); a thread of rest length l gets stiffness EA / l.
    thread_damping : float
        Axial damping of every thread (N s/m).
    bullet_tether_length : float
        Length of the thread from a corner node to its bullet, along the net diagonal (m).
    bending_rigidity : float
        EI of a thread (N m^2); 0 leaves the net without bending stiffness.
    """
    e1, e2 = in_plane_axes(direction)
    mesh = side_length / (nodes_per_side - 1)
    s = np.linspace(-side_length / 2, side_length / 2, nodes_per_side)
    a, b = np.meshgrid(s, s, indexing="ij")
    grid = np.asarray(center, float) + a.reshape(-1, 1) * e1 + b.reshape(-1, 1) * e2
    threads = square_grid_threads(nodes_per_side)
    rest = np.full(len(threads), mesh)

    n = nodes_per_side
    corners = np.array([0, n - 1, n * (n - 1), n * n - 1])
    outward = grid[corners] - np.asarray(center, float)
    outward /= np.linalg.norm(outward, axis=1, keepdims=True)
    bullets = grid[corners] + bullet_tether_length * outward
    bullet_ids = n * n + np.arange(4)
    threads = np.vstack([threads, np.c_[corners, bullet_ids]])
    rest = np.r_[rest, np.full(4, bullet_tether_length)]

    positions = np.vstack([grid, bullets])
    masses = np.r_[np.full(n * n, node_mass), np.full(4, bullet_mass)]
    radii = np.r_[np.full(n * n, node_radius), np.full(4, bullet_radius)]
    triples = square_grid_bending_triples(n)
    return NetTopology(
        positions=positions, masses=masses, radii=radii,
        threads=threads.astype(np.int64), rest_lengths=rest,
        stiffness=thread_axial_rigidity / rest,
        damping=np.full(len(rest), float(thread_damping)),
        bending_triples=triples.astype(np.int64),
        bending_stiffness=np.full(len(triples), bending_rigidity / mesh),
        nodes_per_side=n, n_bullets=4,
    )


def net_kinetic_energy_relative_to_body(masses, positions, velocities, body_com, body_velocity, omega):
    """Kinetic energy of the net's motion relative to a rigid body (J): each node's velocity less the body's
    velocity field at the node's position, what the net carries beyond moving rigidly with the body.

    .. math::

        T_{rel} = \\tfrac12 \\sum_i m_i \\, \\lVert v_i - v_c - \\omega \\times (x_i - x_c) \\rVert^2

    A net (or a part of it) that moves rigidly with the body contributes nothing, whatever the body's spin: a net
    wrapped on a spinning stage and turning with it carries kinetic energy about its own CoM that is no flapping
    (the towing model's switch, :mod:`multibody.tow_switch`), and a net settled on the debris ends the capture
    (:mod:`structures.capture_window`).

    Parameters
    ----------
    masses : (n,) float
        Node masses (kg).
    positions : (k, n, 3) or (n, 3) float
        Node positions (m) at k instants, in one frame (LVLH in the impact model, ECI in the towing model).
    velocities : (k, n, 3) or (n, 3) float
        Node velocities (m/s) relative to that frame's axes.
    body_com, body_velocity : (k, 3) or (3,) float
        The body's centre of mass (m) and its velocity (m/s), same frame.
    omega : (k, 3) or (3,) float
        The body's angular velocity relative to that frame's axes (rad/s), expressed in it.

    Returns
    -------
    (k,) float or float
        The energy at each instant (J).
    """
    x = np.asarray(positions, float)
    single = x.ndim == 2
    x = x[None] if single else x
    v = np.asarray(velocities, float).reshape(x.shape)
    c, vc, w = (np.asarray(a, float).reshape(-1, 3) for a in (body_com, body_velocity, omega))
    m = np.asarray(masses, float)
    if m.shape != (x.shape[1],):
        raise ValueError(f"masses must have shape ({x.shape[1]},) like the nodes. Got {m.shape} instead")
    relative = v - velocity_field(x, c, vc, w)
    energy = 0.5 * np.einsum("n,kni,kni->k", m, relative, relative)
    return float(energy[0]) if single else energy


@njit(cache=True, inline="always")
def tension_only_kelvin_voigt(stretch, rate, stiffness, damping):
    """Tension (N) of a thread or tether that pulls only: a Kelvin-Voigt spring-damper while
    stretched and pulling, zero when slack or when the damper would push.

    .. math:: T = \\begin{cases} \\max(0,\\; k s + c \\dot s) & s > 0 \\\\ 0 & s \\le 0 \\end{cases}

    Cuadrat-Grzybowski & Gill 2024 eq. (1); the same law is the main tether and sub-tethers
    of Boonrath, Singh & Botta 2024, eqs. (5a) and (14a).

    The damper reads the rate of the stretch, :math:`\\dot s = \\dot l - \\dot l_0`: for a thread of fixed natural
    length the length's rate; for one a reel shortens (the closing loop, :mod:`multibody.closing_winch`; the main
    tether, :mod:`multibody.tether_spool`) the length's rate less the reel's, so that a thread reeled in at constant
    stretch takes no damper force (until 2026-11-28, helper loop23, the callers passed :math:`\\dot l`: the reel-in
    itself was damped, and booked as dissipation).

    Parameters
    ----------
    stretch : float
        Length minus natural length, :math:`s = l - l_0` (m).
    rate : float
        Rate of change of the stretch, :math:`\\dot s = \\dot l - \\dot l_0` (m/s).
    stiffness, damping : float
        :math:`k` (N/m) and :math:`c` (N s/m).
    """
    if stretch <= 0.0:
        return 0.0
    return max(0.0, stiffness * stretch + damping * rate)


@njit(cache=True, inline="always")
def kelvin_voigt_dissipated_power(tension, stretch, rate, stiffness):
    """Power (W) a stretched tension-only thread (:func:`tension_only_kelvin_voigt`) takes out of the motion
    and does not store: what the nodes give it less its spring energy's rate.

    .. math:: P = T \\dot s - k s \\dot s =
              \\begin{cases} c \\dot s^2 & T > 0 \\\\ -k s \\dot s & T = 0 \\end{cases}, \\qquad s = l - l_0

    With a fixed natural length :math:`\\dot s = \\dot l`. With a reeled one (:math:`\\dot l_0 \\ne 0`) the power
    the nodes give the thread is :math:`T \\dot l`, the reel gives it :math:`-T \\dot l_0 + \\tfrac12 \\dot k s^2`
    (:func:`reel_damper_power` is its damper share; the rest is the change of the spring's energy at fixed
    positions, which the reels book, :class:`multibody.closing_winch.TrapezoidWork`), and the spring's energy
    changes by :math:`k s \\dot s + \\tfrac12 \\dot k s^2`: what is left is this :math:`P`.

    The second case is a stretched thread shortening faster than :math:`k (l - l_0) / c`: the damper would push,
    the law clips the tension to zero, and the spring energy it gives up is lost (as the contact law books
    the stored energy a fast separation clips, :func:`multibody.contact.contact_over_step`). Until 2026-11-27
    (helper thread14) only :math:`c \\dot l^2` was booked: a thread stretched 1 cm and let go at rest (1000 N/m,
    10 N s/m, two 0.04 kg nodes) closed its energy balance to -58.6 % of its stored energy, whatever the step.

    Parameters
    ----------
    tension : float
        The law's tension (N), >= 0.
    stretch : float
        :math:`s = l - l_0` (m), > 0 (a slack thread takes no power).
    rate : float
        :math:`\\dot s = \\dot l - \\dot l_0` (m/s).
    stiffness : float
        :math:`k` (N/m).
    """
    return (tension - stiffness * stretch) * rate


def reel_damper_power(tension, stretch, stiffness, rest_rate):
    """Power (W) a reel puts into a tension-only thread (:func:`tension_only_kelvin_voigt`) through the damper's
    share of the tension, while it changes the thread's natural length at ``rest_rate``.

    .. math:: P_\\text{reel} = -T \\dot l_0 + \\tfrac12 \\dot k s^2
              = \\underbrace{-k s \\dot l_0 + \\tfrac12 \\dot k s^2}_\\text{spring: } \\partial E / \\partial t
              \\;\\underbrace{-\\,(T - k s)\\,\\dot l_0}_\\text{this function}

    The reel holds the whole tension :math:`T` (spring and damper) and hauls the line in at :math:`-\\dot l_0`; the
    spring's share is the change of the elastic energy at fixed positions (the reels book it by the trapezoid rule,
    :class:`multibody.closing_winch.TrapezoidWork`, the stiffness's change with :math:`l_0` included), this is the
    rest. With :func:`kelvin_voigt_dissipated_power` it closes the balance kinetic + elastic + dissipated - reel work.
    NumPy arrays or floats, elementwise.

    Parameters
    ----------
    tension : float or (m,) float
        The law's tension (N), >= 0, at the evaluation.
    stretch : float or (m,) float
        :math:`s = l - l_0` of a pulling thread (m), 0 for a slack one.
    stiffness : float or (m,) float
        :math:`k` (N/m).
    rest_rate : float or (m,) float
        :math:`\\dot l_0` (m/s), negative while the reel hauls in.
    """
    return -(tension - stiffness * stretch) * rest_rate


@njit(cache=True)
def add_thread_forces(x, v, threads, rest_lengths, stiffness, damping, force, rest_rates=None):
    """Add tension-only Kelvin-Voigt thread forces to ``force``; return (elastic J, damping W).

    .. math:: T = \\max(0,\\; k (l - l_0) + c (\\dot l - \\dot l_0)) \\quad \\text{for } l > l_0

    Parameters
    ----------
    x, v : (n, 3) float
        Node positions (m) and velocities (m/s), LVLH (inertial in the full-net tow: any one frame).
    threads : (m, 2) int
        Node pairs joined by a thread.
    rest_lengths, stiffness, damping : (m,) float
        Natural length (m), stiffness (N/m) and damping (N s/m) of each thread.
    force : (n, 3) float
        Accumulator (N), frame of ``x``.
    rest_rates : (m,) float, optional
        Rate of each natural length (m/s) for threads a reel shortens (the full-net tow's closing loop,
        :mod:`multibody.net_towing`): the damper reads the stretch's rate l' - l0'
        (:func:`tension_only_kelvin_voigt`). None: every natural length fixed (the same arithmetic as before).

    Returns
    -------
    elastic_energy : float
        :math:`\\sum \\tfrac12 k (l-l_0)^2` over stretched threads (J), paper eq. (17).
    damping_power : float
        Power the threads dissipate (W): :func:`kelvin_voigt_dissipated_power`.
    """
    elastic = 0.0
    power = 0.0
    for t in range(threads.shape[0]):
        a = threads[t, 0]
        b = threads[t, 1]
        # Scalar arithmetic on purpose: numba sends small-array products to BLAS.
        dx = x[b, 0] - x[a, 0]
        dy = x[b, 1] - x[a, 1]
        dz = x[b, 2] - x[a, 2]
        squared = dx * dx + dy * dy + dz * dz
        if squared <= rest_lengths[t] * rest_lengths[t]:
            continue  # slack: no square root needed
        length = np.sqrt(squared)
        stretch = length - rest_lengths[t]
        if stretch <= 0.0:
            continue
        # one division and three products (the direction's last bit may differ from three divisions;
        # the vectorized pass below does the same, so the two stay equal to the bit)
        inverse_length = 1.0 / length
        ex = dx * inverse_length
        ey = dy * inverse_length
        ez = dz * inverse_length
        rate = (v[b, 0] - v[a, 0]) * ex + (v[b, 1] - v[a, 1]) * ey + (v[b, 2] - v[a, 2]) * ez
        if rest_rates is not None:
            rate -= rest_rates[t]   # the stretch's rate (numba prunes the branch when None is passed)
        elastic += 0.5 * stiffness[t] * stretch * stretch
        tension = tension_only_kelvin_voigt(stretch, rate, stiffness[t], damping[t])
        power += kelvin_voigt_dissipated_power(tension, stretch, rate, stiffness[t])
        if tension <= 0.0:
            continue
        force[a, 0] += tension * ex
        force[a, 1] += tension * ey
        force[a, 2] += tension * ez
        force[b, 0] -= tension * ex
        force[b, 1] -= tension * ey
        force[b, 2] -= tension * ez
    return elastic, power


#: Longest gap (threads) bridged by padding when runs of :func:`thread_runs` are merged: a square grid's
#: rows of threads along the second index end one node short of the next row's start.
MAX_RUN_GAP = 8
#: Rest length (m) of a padding thread: never taut (its square, 1e300, stays finite), so it adds an exact zero.
PADDING_REST_LENGTH = 1e150


class ThreadRuns(NamedTuple):
    """The thread list regrouped for a vectorized pass (:func:`add_thread_forces_runs`), padded threads
    included (P of them in all, >= m).

    A run is a stretch of threads whose two nodes both advance by one node per thread (a grid's
    column or row of threads), so the run's node coordinates are contiguous slices of coordinate-major
    (3, n) arrays. Short gaps between runs of the same node offset are filled with padding threads that
    never pull (rest length :data:`PADDING_REST_LENGTH`, no stiffness, no damping), so a square net is
    two runs and the four bullet tethers.
    """

    runs: np.ndarray          # (R, 4) int64: first padded thread, its node a, threads in the run, b - a
    rest_lengths: np.ndarray  # (P,) (m)
    stiffness: np.ndarray     # (P,) (N/m)
    damping: np.ndarray       # (P,) (N s/m)
    rest_rates: np.ndarray    # (P,) (m/s) rate of each natural length: a reel's (the closing loop,
                              # multibody.closing_winch), 0.0 for every other thread; the damper reads l' - l0'


def thread_runs(threads, rest_lengths, stiffness, damping) -> ThreadRuns:
    """:class:`ThreadRuns` of a thread list, in the list's order (so the forces a node receives add up
    in the same order as in :func:`add_thread_forces`, and the results are the same to the bit).

    Parameters
    ----------
    threads : (m, 2) int
        Node pairs joined by a thread.
    rest_lengths, stiffness, damping : (m,) float
        Natural length (m), stiffness (N/m) and damping (N s/m) of each thread.
    """
    threads = np.asarray(threads, np.int64).reshape(-1, 2)
    runs, rest, k, c = [], [], [], []
    for t, (a, b) in enumerate(threads):
        if runs:
            _, a0, count, offset = runs[-1]
            gap = a - (a0 + count)
            if b - a == offset and 0 <= gap <= MAX_RUN_GAP and offset != 0:
                rest += [PADDING_REST_LENGTH] * gap
                k += [0.0] * gap
                c += [0.0] * gap
                runs[-1][2] = count + gap + 1
                rest.append(rest_lengths[t])
                k.append(stiffness[t])
                c.append(damping[t])
                continue
        runs.append([len(rest), int(a), 1, int(b - a)])
        rest.append(rest_lengths[t])
        k.append(stiffness[t])
        c.append(damping[t])
    return ThreadRuns(np.array(runs, np.int64).reshape(-1, 4), np.array(rest, float), np.array(k, float),
                      np.array(c, float), np.zeros(len(rest)))


@njit(cache=True, inline="always")
def _run_tensions(x, v, a0, b0, first, count, rest, stiffness, damping, rest_rates, work):
    """The law of :func:`add_thread_forces` on one run, branch-free so that it vectorizes: per thread the
    force on its node a (N, ``work[0:3]``), its elastic energy (J, ``work[3]``) and dissipated power (W,
    ``work[4]``), exact zeros for a slack one. The damper reads the stretch's rate, the length's rate less
    ``rest_rates`` (m/s; exact zeros for a thread of fixed natural length, so its arithmetic is the length's rate's
    to the bit: x - 0.0 == x). Unsigned indices: numba adds no negative-index wrap-around to them, which would keep
    the loop scalar."""
    a_start, b_start, t_start = uint64(a0), uint64(b0), uint64(first)
    for j_signed in range(count):
        j = uint64(j_signed)
        a, b, t = a_start + j, b_start + j, t_start + j
        dx = x[0, b] - x[0, a]
        dy = x[1, b] - x[1, a]
        dz = x[2, b] - x[2, a]
        squared = dx * dx + dy * dy + dz * dz
        rest_t = rest[t]
        taut = squared > rest_t * rest_t
        length = np.sqrt(squared)
        divisor = length if taut else 1.0  # a slack thread's direction is not used (and may be 0 / 0)
        # one division and three products: the loop is bound by its divisions (a square root and three
        # divisions per thread took about two thirds of it)
        inverse_length = 1.0 / divisor
        ex = dx * inverse_length
        ey = dy * inverse_length
        ez = dz * inverse_length
        stretch = length - rest_t
        rate = ((v[0, b] - v[0, a]) * ex + (v[1, b] - v[1, a]) * ey + (v[2, b] - v[2, a]) * ez) - rest_rates[t]
        pulling = taut & (stretch > 0.0)
        tension = max(0.0, stiffness[t] * stretch + damping[t] * rate)  # tension_only_kelvin_voigt
        tension = tension if pulling else 0.0
        # the stretch of a pulling thread, 0 for a slack one: the energies below are then exact zeros without a
        # select of their own. Selecting each energy (``... if pulling else 0.0``) cost 2.5x the whole pass (35 x 35
        # net, 2384 threads: 15.6 against 6.1 us before thread14's booking and 7.4 us this way; the compiled net
        # step 50 -> 36 us, bench/bench_kernel_step.py; docs/model.md "Speed"), although both forms vectorize.
        pulled = stretch if pulling else 0.0
        work[0, t] = tension * ex
        work[1, t] = tension * ey
        work[2, t] = tension * ez
        work[3, t] = 0.5 * stiffness[t] * pulled * pulled
        work[4, t] = kelvin_voigt_dissipated_power(tension, pulled, rate, stiffness[t])


@njit(cache=True, inline="always")
def _scatter(force, node0, work, first, count, sign):
    """force[:, node0 + j] += sign * work[0:3, first + j] for the run's threads j (one end of the run)."""
    node_start, t_start = uint64(node0), uint64(first)
    for d in range(3):
        if sign > 0.0:
            for j_signed in range(count):
                j = uint64(j_signed)
                force[d, node_start + j] += work[d, t_start + j]
        else:
            for j_signed in range(count):
                j = uint64(j_signed)
                force[d, node_start + j] -= work[d, t_start + j]


# error_model="numpy": with Python's, every division checks for zero and the loop stays scalar
@njit(cache=True, error_model="numpy", **NO_REFCOUNTS)  # no reference counts (jit_cache.NO_REFCOUNTS)
def add_thread_forces_runs(x, v, runs, force, work):
    """:func:`add_thread_forces` on coordinate-major arrays, run by run (:class:`ThreadRuns`): the same
    forces to the bit and the energies to round-off (:func:`sum_reassociated`), faster (the tension loop
    vectorizes).

    Parameters
    ----------
    x, v : (3, n) float
        Node positions (m) and velocities (m/s), coordinate-major, one frame.
    runs : ThreadRuns
    force : (3, n) float
        Accumulator (N), coordinate-major.
    work : (5, P) float
        Work space: per padded thread the force on its node a (3 rows), elastic energy, damping power.

    Returns
    -------
    elastic_energy, damping_power : float
        As :func:`add_thread_forces` (J, W).
    """
    run_table = runs.runs
    rest, stiffness, damping, rest_rates = runs.rest_lengths, runs.stiffness, runs.damping, runs.rest_rates
    for r in range(run_table.shape[0]):
        first, a0, count, offset = run_table[r, 0], run_table[r, 1], run_table[r, 2], run_table[r, 3]
        b0 = a0 + offset
        _run_tensions(x, v, a0, b0, first, count, rest, stiffness, damping, rest_rates, work)
        # A node meets a run at most twice: as end b of an earlier thread than the one it is end a of
        # when the offset is positive. Adding the run's b ends first (a later pass the a ends) keeps
        # each node's sum in the thread list's order, so it equals the sequential loop's to the bit.
        if offset > 0:
            _scatter(force, b0, work, first, count, -1.0)
            _scatter(force, a0, work, first, count, 1.0)
        else:
            _scatter(force, a0, work, first, count, 1.0)
            _scatter(force, b0, work, first, count, -1.0)
    # the energies' totals (padding adds exact zeros): partial sums, not the thread list's order (below)
    return sum_reassociated(work[3]), sum_reassociated(work[4])


# fastmath "reassoc" only (no other fast-math licence), and only here: the compiler may split the sum into
# partial sums, so the loop vectorizes instead of waiting on one addition after the other (offline, 2 x 2451
# padded threads: 1.15 us a step for the two sequential sums against 0.15 us; docs/model.md, Speed, helper
# "speed10"). The totals then differ from the sequential sum's at round-off (a few ulp of the total); they
# are recorded energies, read by nothing that feeds the dynamics.
@njit(cache=True, fastmath={"reassoc"})
def sum_reassociated(values):
    """Sum (in the values' unit) of ``values`` ((m,) float), in an order the compiler picks (partial sums)."""
    total = 0.0
    for t in range(values.shape[0]):
        total += values[t]
    return total


def thread_tension_strain(x, v, threads, rest_lengths, stiffness, damping):
    """Tension (N) and engineering strain (-) of every thread, the law of :func:`add_thread_forces`.

    Vectorised over snapshots for exports and reports (the simulation uses the kernel).

    Parameters
    ----------
    x, v : (..., n, 3) float
        Node positions (m) and velocities (m/s), LVLH (any one frame).
    threads : (m, 2) int
        Node pairs joined by a thread.
    rest_lengths, stiffness, damping : (m,) float
        Natural length (m), stiffness (N/m) and damping (N s/m) of each thread.

    Returns
    -------
    tension : (..., m) float
        :math:`\max(0, k(l-l_0) + c\dot l)` on stretched threads, 0 on slack ones (N).
    strain : (..., m) float
        :math:`(l - l_0)/l_0`; negative on slack threads (-).
    """
    x = np.asarray(x, float)
    v = np.asarray(v, float)
    d = x[..., threads[:, 1], :] - x[..., threads[:, 0], :]
    length = np.linalg.norm(d, axis=-1)
    stretch = length - rest_lengths
    rate = np.einsum("...i,...i->...", v[..., threads[:, 1], :] - v[..., threads[:, 0], :], d) / length
    tension = np.where(stretch > 0.0, np.maximum(stiffness * stretch + damping * rate, 0.0), 0.0)
    return tension, stretch / rest_lengths


@njit(cache=True)
def add_bending_forces(x, triples, bending_stiffness, force):
    """Add forces of rotational springs between consecutive threads; return their energy (J).

    Energy :math:`E = k_b (1 - \\hat e_1\\cdot\\hat e_2)`, which is :math:`\\tfrac12 k_b\\theta^2`
    for small kink angles :math:`\\theta`; the forces are its exact negative gradient,
    so they conserve momentum and energy.

    Parameters
    ----------
    x : (n, 3) float
        Node positions (m), LVLH (any one frame).
    triples : (b, 3) int
        Node triples (a, b, c) along one thread line, b in the middle.
    bending_stiffness : (b,) float
        Rotational stiffness at b (N m/rad); 0 skips the triple.
    force : (n, 3) float
        Accumulator (N), frame of ``x``.
    """
    energy = 0.0
    for t in range(triples.shape[0]):
        kb = bending_stiffness[t]
        if kb == 0.0:
            continue
        a = triples[t, 0]
        b = triples[t, 1]
        c = triples[t, 2]
        d1 = x[b] - x[a]
        d2 = x[c] - x[b]
        l1 = np.sqrt(d1 @ d1)
        l2 = np.sqrt(d2 @ d2)
        e1 = d1 / l1
        e2 = d2 / l2
        cosine = e1 @ e2
        energy += kb * (1.0 - cosine)
        fa = -kb * (e2 - cosine * e1) / l1
        fc = kb * (e1 - cosine * e2) / l2
        force[a] += fa
        force[c] += fc
        force[b] -= fa + fc
    return energy
