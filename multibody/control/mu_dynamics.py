"""Planar dynamics of a tether-net carried by two maneuverable units (MUs).

Liu & Poddar, "Space debris capturing tether-net system simplified as a 2-D problem"
(the seed paper ``maneuverable-units-2d-guidance``). Two models, one per case study:

* **rigid rod** (case study 1, eqs. 1-3): two MUs of constant mass ``m`` joined by a massless
  rigid rod of length ``L``; state of the centre of mass (CoM) and of the rod angle.
* **independent units** (case study 2, eqs. 11-12): two free point masses whose mass falls
  with the thrust they give (fuel-rate constant ``k``).

Frame: the paper's global planar frame ("world", x-y plane), the debris at a fixed point of it.
Every function here is written once for both backends: it takes NumPy floats/arrays or CasADi
symbols and returns the same kind, so the collocation model (CasADi) and the independent
re-simulation (SciPy on NumPy) evaluate the very same expressions.
"""
from __future__ import annotations

import casadi as ca
import numpy as np

#: State layout of the rigid-rod model (paper Sec. 2.1): CoM position and velocity, rod angle and rate.
ROD_STATE = ("x_com", "vx_com", "y_com", "vy_com", "phi", "phi_dot")
#: Control layout of both models: thrust magnitudes (N) of MU1 and MU2 and the cosine and sine of
#: each thrust angle. The guidance solves for the direction cosines (a unit vector, no 2 pi
#: ambiguity: unbounded angles wandered by multiples of 2 pi and stalled IPOPT); the angles of the
#: paper are ``atan2(sin, cos)`` (:func:`thrust_angles`).
CONTROLS = ("thrust_1", "thrust_2", "cos_theta_1", "sin_theta_1", "cos_theta_2", "sin_theta_2")
#: State layout of one independent MU (paper Sec. 3): position, velocity (world frame) and mass.
UNIT_STATE = ("x", "y", "vx", "vy", "mass")


def _is_symbolic(*values) -> bool:
    return any(isinstance(v, (ca.SX, ca.MX, ca.DM)) for v in values)


def _lib(*values):
    """The math library for these values: CasADi for symbols, NumPy otherwise."""
    return ca if _is_symbolic(*values) else np


def _stack(components):
    """A column vector (CasADi) or a 1-D array (NumPy, trailing axes kept) of the components."""
    if _is_symbolic(*components):
        return ca.vertcat(*components)
    return np.stack(np.broadcast_arrays(*components))


def controls_from_angles(thrust_1, thrust_2, theta_1, theta_2):
    """:data:`CONTROLS` from thrust magnitudes (N) and angles (rad), stacked (6, ...).

    Parameters
    ----------
    thrust_1, thrust_2 : float or array
        Thrust magnitudes of MU1 and MU2 (N).
    theta_1, theta_2 : float or array
        Their thrust angles (rad), as the model defines them (from the rod, clockwise, for the
        rigid rod; from the world x axis, counter-clockwise, for independent units).
    """
    lib = _lib(theta_1, theta_2)
    return _stack([thrust_1, thrust_2, lib.cos(theta_1), lib.sin(theta_1), lib.cos(theta_2), lib.sin(theta_2)])


def thrust_angles(controls):
    """Thrust angles (rad) of MU1 and MU2 in [0, 2 pi) from :data:`CONTROLS` (NumPy).

    Parameters
    ----------
    controls : (6,) or (6, n) float
        :data:`CONTROLS` (N, N, -, -, -, -).
    """
    return (np.mod(np.arctan2(controls[3], controls[2]), 2 * np.pi),
            np.mod(np.arctan2(controls[5], controls[4]), 2 * np.pi))


def rod_thrust_world(thrust, cos_theta, sin_theta, phi):
    """World-frame components of an MU's thrust in the rigid-rod model (paper Sec. 2.1).

    .. math:: F_x = F\\cos(\\theta - \\phi), \\qquad F_y = -F\\sin(\\theta - \\phi)

    i.e. the thrust points at the world angle :math:`\\phi - \\theta`: :math:`\\theta` is
    measured clockwise from the rod direction.

    Parameters
    ----------
    thrust : float or array  Thrust magnitude (N).
    cos_theta, sin_theta : float or array  Cosine and sine of the thrust-vectoring angle
                             :math:`\\theta` from the rod, clockwise (-).
    phi : float or array     Rod angle from the world x axis, counter-clockwise (rad).

    Returns
    -------
    fx, fy : World-frame components (N).
    """
    lib = _lib(thrust, cos_theta, phi)
    c, s = lib.cos(phi), lib.sin(phi)
    return thrust * (cos_theta * c + sin_theta * s), -thrust * (sin_theta * c - cos_theta * s)


def rod_moment_of_inertia(mass, length):
    """Moment of inertia of two point masses ``mass`` (kg) at the ends of a massless rod of
    ``length`` (m) about their CoM (kg m^2): :math:`I = 2 m (L/2)^2 = m L^2 / 2` (paper Sec. 2.1).

    Parameters
    ----------
    mass : float or symbol
        Mass of one MU (kg).
    length : float or symbol
        Rod length (m).
    """
    return mass * length**2 / 2.0


def rigid_rod_rhs(state, controls, mass, length):
    """Time derivative of the rigid-rod state (paper eqs. 1-3).

    .. math::
        \\ddot x = \\frac{F_{1x}+F_{2x}}{2m},\\quad \\ddot y = \\frac{F_{1y}+F_{2y}}{2m},\\quad
        \\ddot\\phi = \\frac{\\tau}{I} = \\frac{1}{mL}\\big[(F_{2y}-F_{1y})\\cos\\phi-(F_{2x}-F_{1x})\\sin\\phi\\big]

    The angular equation is :math:`\\tau / I` with the paper's own torque
    :math:`\\tau = \\tfrac L2[\\ldots]` and inertia :math:`I = mL^2/2`; the printed eq. (3)
    carries a factor :math:`2/(mL)`, twice that ratio (see docs/approach.md).

    Parameters
    ----------
    state : (6,) or (6, n)   :data:`ROD_STATE`, world frame (m, m/s, rad, rad/s).
    controls : (6,) or (6, n)  :data:`CONTROLS` (N, N, -, -, -, -).
    mass : float   Mass of one MU (kg).
    length : float Rod length L (m).

    Returns
    -------
    (6,) or (6, n): d(state)/dt in the same backend as the inputs.
    """
    _, vx, _, vy, phi, phi_dot = (state[i] for i in range(6))
    f1, f2, c1, s1, c2, s2 = (controls[i] for i in range(6))
    f1x, f1y = rod_thrust_world(f1, c1, s1, phi)
    f2x, f2y = rod_thrust_world(f2, c2, s2, phi)
    lib = _lib(state, controls)
    torque = length / 2.0 * ((f2y - f1y) * lib.cos(phi) - (f2x - f1x) * lib.sin(phi))
    return _stack([vx, (f1x + f2x) / (2.0 * mass), vy, (f1y + f2y) / (2.0 * mass), phi_dot,
                   torque / rod_moment_of_inertia(mass, length)])


def rod_unit_positions(state, length):
    """World positions (m) of MU1 and MU2 from the rigid-rod state (paper Sec. 2.1):
    :math:`X_{1,2} = X_{com} \\mp \\tfrac L2(\\cos\\phi, \\sin\\phi)`. Returns (x1, y1, x2, y2).

    Parameters
    ----------
    state : (6,) or (6, n)
        :data:`ROD_STATE`, world frame (m, m/s, rad, rad/s).
    length : float
        Rod length (m).
    """
    lib = _lib(state)
    x_world, y_world, phi = state[0], state[2], state[4]
    dx_world, dy_world = length / 2.0 * lib.cos(phi), length / 2.0 * lib.sin(phi)
    return x_world - dx_world, y_world - dy_world, x_world + dx_world, y_world + dy_world


def unit_rhs(state, thrust, cos_theta, sin_theta, fuel_rate):
    """Time derivative of one variable-mass MU (paper eqs. 11-12, continuous form).

    .. math:: \\ddot x = \\frac{T}{m}\\cos\\theta,\\quad \\ddot y = \\frac{T}{m}\\sin\\theta,
              \\quad \\dot m = -k T

    Parameters
    ----------
    state : (5,) or (5, n)  :data:`UNIT_STATE`, world frame (m, m, m/s, m/s, kg).
    thrust : float or array  Thrust magnitude T (N).
    cos_theta, sin_theta : float or array  Cosine and sine of the thrust angle from the world
                             x axis, counter-clockwise (-).
    fuel_rate : float        k, fuel mass per thrust impulse (kg/(N s)).
    """
    _, _, vx, vy, mass = (state[i] for i in range(5))
    return _stack([vx, vy, thrust / mass * cos_theta, thrust / mass * sin_theta,
                   -fuel_rate * thrust])


def independent_units_rhs(state, controls, fuel_rate):
    """Time derivative of two independent MUs (paper case study 2).

    Parameters
    ----------
    state : (10,) or (10, n)
        MU1's :data:`UNIT_STATE` followed by MU2's, world frame (m, m/s, kg).
    controls : (6,) or (6, n)
        :data:`CONTROLS` (N, N, -, -, -, -); angles from the world x axis, counter-clockwise.
    fuel_rate : float
        k, fuel mass per thrust impulse (kg/(N s)).
    """
    f1, f2, c1, s1, c2, s2 = (controls[i] for i in range(6))
    first = unit_rhs(state[0:5], f1, c1, s1, fuel_rate)
    second = unit_rhs(state[5:10], f2, c2, s2, fuel_rate)
    if _is_symbolic(first, second):
        return ca.vertcat(first, second)
    return np.concatenate([first, second])


def independent_unit_positions(state):
    """World positions (m) of MU1 and MU2 from the two-unit state: (x1, y1, x2, y2).

    Parameters
    ----------
    state : (10,) or (10, n)
        MU1's :data:`UNIT_STATE` followed by MU2's, world frame (m, m/s, kg).
    """
    return state[0], state[1], state[5], state[6]


class RigidRodMUs:
    """Case study 1 as a model for the guidance: two constant-mass MUs on a rigid rod.

    Parameters
    ----------
    mass : float       Mass of one MU (kg).
    length : float     Rod length L (m).
    fuel_rate : float  k (kg/(N s)); the rod model has constant mass, the fuel is reported as
                       :math:`k\\int (F_1+F_2)\\,dt` for comparison with case study 2.
    """

    kind = "rigid_rod"
    state_names = ROD_STATE
    n_states = 6
    velocity_indices = (1, 3, 5)
    position_indices = ()          # MU positions are not states: no box on them
    mass_indices = ()

    def __init__(self, mass: float, length: float, fuel_rate: float):
        self.mass, self.length, self.fuel_rate = mass, length, fuel_rate

    def rhs(self, state, controls):
        """:func:`rigid_rod_rhs` of this model.

        Parameters
        ----------
        state : (6,) or (6, n)
            :data:`ROD_STATE`, world frame (m, m/s, rad, rad/s).
        controls : (6,) or (6, n)
            :data:`CONTROLS` (N, N, -, -, -, -).
        """
        return rigid_rod_rhs(state, controls, self.mass, self.length)

    def unit_positions(self, state):
        """World positions (m) of MU1 and MU2: (x1, y1, x2, y2) (:func:`rod_unit_positions`).

        Parameters
        ----------
        state : (6,) or (6, n)
            :data:`ROD_STATE`, world frame (m, m/s, rad, rad/s).
        """
        return rod_unit_positions(state, self.length)

    def mouth_center(self, state):
        """Mouth centre (m, world): the CoM, the middle of the rod.

        Parameters
        ----------
        state : (6,) or (6, n)
            :data:`ROD_STATE`, world frame (m, m/s, rad, rad/s).
        """
        return state[0], state[2]

    def unit_masses(self, state):
        """Masses of MU1 and MU2 (kg): constant, broadcast to the state's shape.

        Parameters
        ----------
        state : (6,) or (6, n)
            :data:`ROD_STATE`, world frame (m, m/s, rad, rad/s).
        """
        return self.mass + 0.0 * state[0], self.mass + 0.0 * state[0]


class IndependentMUs:
    """Case study 2 as a model for the guidance: two independent variable-mass MUs.

    Parameters
    ----------
    fuel_rate : float  k (kg/(N s)), paper eq. (11).
    """

    kind = "independent_units"
    state_names = tuple(f"{n}_1" for n in UNIT_STATE) + tuple(f"{n}_2" for n in UNIT_STATE)
    n_states = 10
    velocity_indices = (2, 3, 7, 8)
    position_indices = (0, 1, 5, 6)
    mass_indices = (4, 9)

    def __init__(self, fuel_rate: float):
        self.fuel_rate = fuel_rate

    def rhs(self, state, controls):
        """:func:`independent_units_rhs` of this model.

        Parameters
        ----------
        state : (10,) or (10, n)
            MU1's then MU2's :data:`UNIT_STATE`, world frame (m, m/s, kg).
        controls : (6,) or (6, n)
            :data:`CONTROLS` (N, N, -, -, -, -).
        """
        return independent_units_rhs(state, controls, self.fuel_rate)

    def unit_positions(self, state):
        """World positions (m) of MU1 and MU2: (x1, y1, x2, y2).

        Parameters
        ----------
        state : (10,) or (10, n)
            MU1's then MU2's :data:`UNIT_STATE`, world frame (m, m/s, kg).
        """
        return independent_unit_positions(state)

    def mouth_center(self, state):
        """Mouth centre (m, world): the midpoint of the two MUs (paper eq. 14).

        Parameters
        ----------
        state : (10,) or (10, n)
            MU1's then MU2's :data:`UNIT_STATE`, world frame (m, m/s, kg).
        """
        x1_world, y1_world, x2_world, y2_world = independent_unit_positions(state)
        return (x1_world + x2_world) / 2.0, (y1_world + y2_world) / 2.0

    def unit_masses(self, state):
        """Current masses of MU1 and MU2 (kg), from the state.

        Parameters
        ----------
        state : (10,) or (10, n)
            MU1's then MU2's :data:`UNIT_STATE`, world frame (m, m/s, kg).
        """
        return state[4], state[9]
