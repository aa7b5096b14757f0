"""``internal_energy_dissipation``: nutation damping by an internal damper; angular momentum conserved.

A spherical viscous damper (Hughes, *Spacecraft Attitude Dynamics*, Sec. 7.3): a rotor of
isotropic inertia J_d at the main body's CoM, coupled to it by a viscous torque. In B:

.. math::
    \\tau_{body} = c\\,(\\omega_d - \\omega),\\qquad
    J_d(\\dot\\omega_d + \\omega\\times\\omega_d) = -c\\,(\\omega_d - \\omega),\\qquad c = J_d / T_d

Body and damper together conserve the angular momentum; the energy decays, the tumble drifts
towards the major axis. Parameters: the damper inertia J_d and its time constant T_d.
"""
from __future__ import annotations

import numpy as np
from numba import njit

from multibody.linalg3 import cross3
from riskassess.diagnosis.dynamics import LAW_SIGNATURE, L_E, L_TM, X_E, X_W
from riskassess.diagnosis.effects.base import Effect, Parameter
from riskassess.diagnosis.scenario import plant_of
from riskassess.diagnosis.towing_dynamics import TOWING_LAW_SIGNATURE, XE_DAMPER
from multibody.towing_kernel import DEBRIS


@njit(cache=True)
def damper_torque(omega_body, omega_damper, inertia, time_constant):
    """Torque on the body (N m, B) from the damper rotating at ``omega_damper`` (rad/s, B)."""
    return inertia / time_constant * (omega_damper - omega_body)


@njit(LAW_SIGNATURE, cache=True)
def law(t, x, p, env, load):
    w = x[X_W:X_W + 3]
    wd = x[X_E:X_E + 3]
    torque = damper_torque(w, wd, p[0], p[1])
    load[L_TM:L_TM + 3] += torque
    load[L_E:L_E + 3] += -torque / p[0] - cross3(w, wd) if p[0] > 0 else -cross3(w, wd)


@njit(TOWING_LAW_SIGNATURE, cache=True)
def towing_law(t, q, v, p, work, xe, h, load):
    """The damper in the towed debris; its rate (``XE_DAMPER``, debris frame) advanced by explicit
    Euler over the step (h / T_d <= 0.05 at the fit's 50 ms limit and T_d >= 1 s)."""
    w = v[DEBRIS + 3:DEBRIS + 6]
    wd = xe[XE_DAMPER:XE_DAMPER + 3]
    torque = damper_torque(w, wd, p[0], p[1])
    load[DEBRIS + 3:DEBRIS + 6] += torque
    if h > 0.0 and p[0] > 0.0:
        xe[XE_DAMPER:XE_DAMPER + 3] += h * (-torque / p[0] - cross3(w, wd))


class InternalEnergyDissipation(Effect):
    id = "internal_energy_dissipation"
    extra_state = True
    title = "nutation damping by internal energy dissipation (spherical viscous damper)"
    channels = ("omega_x", "omega_y", "omega_z", "q_w")
    scenarios = ("tumbling_rigid", "hinged_appendage", "towing")
    law = staticmethod(law)
    towing_law = staticmethod(towing_law)

    def parameter_specs(self, case, channels=None):
        j_min = float(np.linalg.eigvalsh(plant_of(case).inertia_main)[0])
        return [Parameter("damper_inertia", "kg m^2", "inertia of the damper rotor", 0.01 * j_min, 0.0, 0.2 * j_min),
                Parameter("time_constant", "s", "damper time constant J_d / c", 30.0, 1.0, 3000.0)]

    def starts(self, specs):
        return [np.array([specs[0].typical, 10.0]), np.array([specs[0].typical, 100.0])]

    def stiffness_rate(self, plant, specs):
        return 1.0 / specs[1].lower

    def add_to_exudyn(self, builder, values, names):
        if values[0] > 0:
            builder.add_damper(values[0], values[0] / values[1])


EFFECT = InternalEnergyDissipation()
