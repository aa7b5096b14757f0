"""The impact model's main tether: the net's central node tied to the chaser, which holds station at an anchor
point fixed in LVLH (its thrusters hold it there, the towing seed's pre-tow phase: Boonrath, Singh & Botta 2024,
Sec. 2.2 and 4.1, where the chaser waits at station while the net wraps).

The tether is a tension-only Kelvin-Voigt line (:func:`multibody.net.tension_only_kelvin_voigt`, the towing
model's main tether law, Boonrath et al. eq. (5a); the same pure function, imported) from the anchor to one net
node:

.. math:: \\mathbf F_\\text{node} = -T\\,\\mathbf u, \\quad T = \\max(0,\\,k (l - l_0) + c\\,(\\dot l - \\dot l_0))\\;(l > l_0),
          \\quad \\mathbf u = (\\mathbf x_\\text{node} - \\mathbf x_\\text{anchor}) / l,

and the chaser feels :math:`+T\\mathbf u` (what its thrusters must hold). The anchor does not move, so the
tether's power on the node is :math:`-T\\dot l`; its spring holds :math:`\\tfrac12 k (l - l_0)^2` and its damper
takes :func:`multibody.net.kelvin_voigt_dissipated_power` out of the motion (booked per step with the Verlet
evaluation state's rate, as the net's threads are). The damper reads the stretch's rate: while the spool reels in,
:math:`\\dot l_0` is its rate (:data:`REST_RATE`), and the reel's work through the damper's share of the tension
is the spool's to book (:mod:`multibody.tether_spool`).

Pure functions on SI floats and NumPy arrays (the anchor, the tethered node, the spool's schedule) and one
compiled force pass (:func:`add_tether_force`) that :mod:`multibody.kernel_net` calls inside the net's step; the
spool that brakes and reels the line in is :mod:`multibody.tether_spool`.
"""
from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np
from numba import njit

from multibody.net import kelvin_voigt_dissipated_power, tension_only_kelvin_voigt

#: Layout of :attr:`NetTether.state` (one float array, written by the spool and the force pass): natural length
#: (m), stiffness (N/m), damping (N s/m), on (1.0) or paying out (0.0), then the force pass's outputs at the last
#: evaluation: tension (N), length (m), elastic energy (J), dissipated energy so far (J), force on the chaser
#: (3 components, N, LVLH); last the natural length's rate (m/s, the spool's while it reels in, else 0).
REST, STIFFNESS, DAMPING, ON, TENSION, LENGTH, ELASTIC, DISSIPATED, FORCE_ON_CHASER, REST_RATE, STATE_SIZE = (
    0, 1, 2, 3, 4, 5, 6, 7, 8, 11, 12)


class NetTether(NamedTuple):
    """The main tether as the compiled net step reads it.

    Attributes
    ----------
    node : (1,) int64        The tethered net node; -1: no tether (the step skips the pass).
    anchor_lvlh : (3,) float The chaser's tether exit point (m), LVLH; fixed (a station-keeping chaser).
    state : (STATE_SIZE,) float  Spool settings and outputs, laid out as :data:`REST` ... :data:`FORCE_ON_CHASER`.
    """

    node: np.ndarray
    anchor_lvlh: np.ndarray
    state: np.ndarray


def no_tether() -> NetTether:
    """:class:`NetTether` with none (the default path: the net step skips the pass)."""
    return NetTether(np.full(1, -1, np.int64), np.zeros(3), np.zeros(STATE_SIZE))


def net_tether(node: int, anchor_lvlh, damping: float) -> NetTether:
    """A tether from net node ``node`` to ``anchor_lvlh`` ((3,) m, LVLH) with damping ``damping`` (N s/m), paying
    out (off) until its spool brakes (:mod:`multibody.tether_spool`)."""
    state = np.zeros(STATE_SIZE)
    state[DAMPING] = float(damping)
    return NetTether(np.full(1, int(node), np.int64), np.asarray(anchor_lvlh, float).reshape(3).copy(), state)


def central_node(nodes_per_side: int) -> int:
    """The net node at the centre of the square grid (row-major, :func:`multibody.net.flat_square_net`): the
    middle node for an odd ``nodes_per_side``; for an even one there is none, and this is the grid node
    (n/2, n/2), one of the four nearest the centre (half a mesh off it along each side)."""
    n = int(nodes_per_side)
    return (n // 2) * n + n // 2


def anchor_point(net_center_lvlh, direction_lvlh, standoff: float) -> np.ndarray:
    """(3,) The chaser's anchor (m, LVLH): ``standoff`` (m) back along the launch direction ``direction_lvlh``
    ((3,) unit) from the net's centre at launch ``net_center_lvlh`` ((3,) m)."""
    direction = np.asarray(direction_lvlh, float)
    return np.asarray(net_center_lvlh, float) - float(standoff) * direction / np.linalg.norm(direction)


def reeled_rest_length(rest_braked: float, rate: float, elapsed: float, reel_in: float) -> float:
    """The natural length (m) a spool reeling in at ``rate`` (m/s) from ``rest_braked`` (m, at the brake) has after
    ``elapsed`` (s): shorter by ``rate * elapsed``, at most by ``reel_in`` (m), then held."""
    return rest_braked - min(reel_in, rate * max(elapsed, 0.0))


def tether_elastic_energy(length: float, rest: float, stiffness: float) -> float:
    """Elastic energy (J) of the tether at ``length`` (m) with natural length ``rest`` (m) and stiffness (N/m):
    :math:`\\tfrac12 k \\max(0, l - l_0)^2`."""
    stretch = max(length - rest, 0.0)
    return 0.5 * stiffness * stretch * stretch


@njit(cache=True)
def add_tether_force(x_soa, v_soa, tether, force_soa, step):
    """Add the tether's pull on its node to ``force_soa`` and write its outputs into ``tether.state`` (module doc).

    Parameters
    ----------
    x_soa, v_soa : (3, n) float
        Node positions (m) and velocities (m/s), LVLH, coordinate-major (the Verlet evaluation state).
    tether : NetTether
    force_soa : (3, n) float
        Node force accumulator (N), LVLH, coordinate-major.
    step : float
        The step (s) over which the dissipated power is booked.
    """
    s, i, anchor = tether.state, tether.node[0], tether.anchor_lvlh
    d0, d1, d2 = x_soa[0, i] - anchor[0], x_soa[1, i] - anchor[1], x_soa[2, i] - anchor[2]
    length = math.sqrt(d0 * d0 + d1 * d1 + d2 * d2)
    s[LENGTH] = length
    s[TENSION] = s[ELASTIC] = s[FORCE_ON_CHASER] = s[FORCE_ON_CHASER + 1] = s[FORCE_ON_CHASER + 2] = 0.0
    stretch = length - s[REST]
    if s[ON] == 0.0 or stretch <= 0.0:
        return          # paying out, or slack: no force, no energy
    u0, u1, u2 = d0 / length, d1 / length, d2 / length
    rate = (v_soa[0, i] * u0 + v_soa[1, i] * u1 + v_soa[2, i] * u2) - s[REST_RATE]   # the stretch's rate
    k = s[STIFFNESS]
    tension = tension_only_kelvin_voigt(stretch, rate, k, s[DAMPING])
    force_soa[0, i] -= tension * u0
    force_soa[1, i] -= tension * u1
    force_soa[2, i] -= tension * u2
    s[TENSION] = tension
    s[FORCE_ON_CHASER], s[FORCE_ON_CHASER + 1], s[FORCE_ON_CHASER + 2] = tension * u0, tension * u1, tension * u2
    s[ELASTIC] = 0.5 * k * stretch * stretch
    s[DISSIPATED] += kelvin_voigt_dissipated_power(tension, stretch, rate, k) * step
