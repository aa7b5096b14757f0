"""Free (torque-free) motion of the debris bodies and their joints, in Exudyn.

The phase before any contact: the chaser only watches. The bodies and joints are the same
Exudyn items as in the coupled impact (:mod:`multibody.impact`), without net or contact,
integrated with RK44 and Lie-group updates of the rotation vectors; there is no user
function, so the whole run stays in Exudyn's C++ core.
"""
from __future__ import annotations

import exudyn as exu
import numpy as np

from multibody.assembly import RigidBodySpec
from multibody.hinge import add_penalty_joint
from multibody.health import HealthWatch
from multibody.impact import add_rigid_bodies, checked_post_step, explicit_settings, solve_checked
from multibody.maths.rotations import rotation_matrix_from_rotation_vector


def free_motion(bodies: list[RigidBodySpec], joints, sample_times, step: float = 1e-3,
                rest_body_to_lvlh=None, rest_com_lvlh=None):
    """Integrate the bodies without external forces and sample their states.

    Parameters
    ----------
    bodies, joints : the assembly's rigid bodies and joints at t = 0 (LVLH).
    sample_times : (k,) float   Increasing times (s), multiples of ``step``.
    step : float                RK44 step (s); 1e-3 s keeps a 2.3 rad/s tumble's energy within 1e-10.
    rest_body_to_lvlh : list of (3, 3) float, optional
        Per body, the attitude (body->LVLH) in which the joints are unloaded; default: the initial one.
    rest_com_lvlh : list of (3,) float, optional
        Per body, the CoM (m, LVLH) in which the joints are unloaded; default: the initial one.

    Returns
    -------
    dict with ``time`` (k,), ``body_com_lvlh``, ``body_velocity_lvlh`` (k, nb, 3),
    ``body_to_lvlh`` (k, nb, 3, 3) and ``body_omega_body`` (k, nb, 3) (rad/s, body frame).
    """
    sample_times = np.asarray(sample_times, float)
    sc = exu.SystemContainer()
    mbs = sc.AddSystem()
    nodes, objects = add_rigid_bodies(mbs, bodies)
    rest_body_to_lvlh = rest_body_to_lvlh or [b.body_to_lvlh for b in bodies]
    rest_com_lvlh = rest_com_lvlh or [b.com_lvlh for b in bodies]
    for joint in joints:
        add_penalty_joint(mbs, joint, bodies, objects, rest_body_to_lvlh[joint.child], rest_com_lvlh[joint.child], step)
    mbs.Assemble()
    index = [mbs.GetNodeODE2Index(nd) for nd in nodes]
    states = {key: [] for key in ("time", "body_com_lvlh", "body_velocity_lvlh", "body_to_lvlh", "body_omega_body")}
    next_sample = [0]

    def record(mbs_, t):
        while next_sample[0] < len(sample_times) and t >= sample_times[next_sample[0]] - 0.5 * step:
            q = mbs_.systemData.GetODE2Coordinates()
            qt = mbs_.systemData.GetODE2Coordinates_t()
            states["time"].append(sample_times[next_sample[0]])
            states["body_com_lvlh"].append([b.com_lvlh + q[i:i + 3] for b, i in zip(bodies, index)])
            states["body_velocity_lvlh"].append([qt[i:i + 3] for i in index])
            states["body_to_lvlh"].append([rotation_matrix_from_rotation_vector(np.array(q[i + 3:i + 6])) for i in index])
            states["body_omega_body"].append([qt[i + 3:i + 6] for i in index])
            next_sample[0] += 1
        return True

    record(mbs, 0.0)
    watch = HealthWatch(f"at the step {step:g} s the free motion lost stability: check the joint stiffness "
                        f"against the step and the initial rates for extreme values")
    mbs.SetPostStepUserFunction(checked_post_step(watch, record))
    settings = explicit_settings(step, int(round(sample_times[-1] / step)))
    solve_checked(mbs, settings, exu.DynamicSolverType.RK44, watch)
    return {key: np.array(value, float) for key, value in states.items()}
