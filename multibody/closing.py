"""The net's closing mechanism: a loop of tension-only threads laced through the four corner masses and two
perimeter nodes per side, reeled in by a winch (Boonrath, Singh & Botta 2024, Sec. 2.1; the same mechanism as
in their earlier capture work, refs. [9, 12] there).

Pure functions on SI floats and NumPy arrays, shared by the towing model (:mod:`multibody.net_wrap`,
:mod:`multibody.net_towing`) and the impact model (:mod:`multibody.closing_winch`): the loop's topology, its
reeling schedule, its stiffness and the elastic energy it holds (what the winch's work changes).

The loop is :data:`N_CLOSING` threads appended after the net's own, closing the polygon of lacing points
(:func:`closing_loop`). Each is a tension-only Kelvin-Voigt thread (:func:`multibody.net.tension_only_kelvin_voigt`)
of natural length :math:`l_0(t)` and stiffness :math:`EA / l_0(t)`; the winch shortens :math:`l_0` linearly from
the open lengths (the straight distances between lacing points in the net's starting shape) to
``closed_fraction`` of them (:func:`reeled_rest_lengths`).

**The winch's work.** A thread of stretch :math:`s = l - l_0` holds :math:`E = \\tfrac12 (EA/l_0) s^2`. With the
nodes held still, shortening :math:`l_0` changes :math:`E` by

.. math:: \\delta W = E(x, l_0 + \\delta l_0) - E(x, l_0)
          \\approx -\\Big(T_e + \\tfrac12 \\frac{EA}{l_0^2} s^2\\Big)\\,\\delta l_0, \\qquad T_e = \\frac{EA}{l_0} s,

the work the winch does on the net (positive while it reels in against tension: the reel-in rate times the
tension, plus the change of the stiffness with the length). The nodes' motion under the thread force changes
:math:`E` by the rest (the kinetic energy's exchange), so kinetic + elastic + dissipated - winch work is constant.
"""
from __future__ import annotations

import numpy as np

from multibody.net import NetTopology

#: Threads of the closing loop (four corner masses and eight perimeter nodes, Sec. 2.1).
N_CLOSING = 12


def closing_loop(nodes_per_side: int) -> np.ndarray:
    """The twelve lacing points in order around the perimeter (node indices; the corner masses are
    :func:`~multibody.net.flat_square_net`'s bullets n^2 .. n^2+3 on grid corners 0, n-1, n(n-1), n^2-1).

    Parameters
    ----------
    nodes_per_side : int
        N of the N x N net.

    Returns
    -------
    (12,) int
        Node indices of the lacing points, in order around the perimeter.
    """
    n = nodes_per_side
    j1 = int(round((n - 1) / 3))
    j2 = n - 1 - j1
    cm = n * n + np.arange(4)
    return np.array([cm[0], j1, j2, cm[1], j1 * n + n - 1, j2 * n + n - 1, cm[3], (n - 1) * n + j2,
                     (n - 1) * n + j1, cm[2], j2 * n, j1 * n])


def closing_threads(nodes_per_side: int) -> np.ndarray:
    """(12, 2) int: the loop's threads, each lacing point to the next around the perimeter (the last back to
    the first).

    Parameters
    ----------
    nodes_per_side : int
        N of the N x N net.
    """
    loop = closing_loop(nodes_per_side)
    return np.c_[loop, np.roll(loop, -1)]


def closing_stiffness(axial_rigidity: float, rest):
    """Stiffness EA / l0 (N/m) of each closing thread at natural lengths ``rest`` (m); ``axial_rigidity`` EA (N)."""
    return axial_rigidity / np.asarray(rest)


def append_closing_loop(net: NetTopology, axial_rigidity: float, damping: float) -> tuple[NetTopology, np.ndarray]:
    """``net`` with the closing loop appended as its last :data:`N_CLOSING` threads, open: natural lengths the
    straight distances between the lacing points in ``net.positions`` (so the loop starts without tension).

    Parameters
    ----------
    net : NetTopology
        A square net with four corner masses (:func:`multibody.net.flat_square_net`), positions in any one frame (m).
    axial_rigidity : float
        EA of the closing thread (N).
    damping : float
        Axial damping of each closing thread (N s/m).

    Returns
    -------
    topology : NetTopology
        The net with the loop's threads last.
    rest_open : (12,) float
        The loop's open natural lengths (m).
    """
    if net.n_bullets != 4:
        raise ValueError(f"the closing loop is laced through four corner masses; this net has {net.n_bullets}")
    pairs = closing_threads(net.nodes_per_side)
    rest_open = np.linalg.norm(net.positions[pairs[:, 1]] - net.positions[pairs[:, 0]], axis=1)
    topology = NetTopology(
        positions=net.positions, masses=net.masses, radii=net.radii,
        threads=np.vstack([net.threads, pairs]).astype(np.int64), rest_lengths=np.r_[net.rest_lengths, rest_open],
        stiffness=np.r_[net.stiffness, axial_rigidity / rest_open],
        damping=np.r_[net.damping, np.full(N_CLOSING, float(damping))],
        bending_triples=net.bending_triples, bending_stiffness=net.bending_stiffness,
        nodes_per_side=net.nodes_per_side, n_bullets=net.n_bullets)
    return topology, rest_open


def reel_fraction(t: float, start: float, duration: float) -> float:
    """How far the loop is reeled in at time ``t`` (-): 0 before ``start``, linear to 1 over ``duration``, 1
    after (times in s)."""
    return min(1.0, max(0.0, (t - start) / duration))


def reeled_rest_lengths(rest_open, rest_closed, fraction: float):
    """The loop's natural lengths (m) reeled in by ``fraction`` (:func:`reel_fraction`) from ``rest_open`` to
    ``rest_closed`` ((12,) float, m)."""
    return rest_open + fraction * (rest_closed - rest_open)


def loop_elastic_energy(x, threads, rest, axial_rigidity: float) -> float:
    """Elastic energy (J) of the closing threads: sum of 1/2 (EA / l0) (l - l0)^2 over the stretched ones.

    Parameters
    ----------
    x : (n, 3) float
        Node positions (m), any one frame.
    threads : (12, 2) int
        The loop's node pairs.
    rest : (12,) float
        Their natural lengths (m).
    axial_rigidity : float
        EA (N).
    """
    length = np.linalg.norm(x[threads[:, 1]] - x[threads[:, 0]], axis=1)
    stretch = np.maximum(length - rest, 0.0)
    return float(np.sum(0.5 * axial_rigidity / rest * stretch * stretch))
