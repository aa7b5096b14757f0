"""Run summary: peaks, debris velocity change, hinge extremes and the conservation checks.

Reference figures of Cuadrat-Grzybowski & Gill 2024 (Sec. 3.2-3.3) are carried along so a
run can be read against them; the differences are explained in docs/model.md (the paper
holds the debris fixed while the net hits, we do not).
"""
from __future__ import annotations

import numpy as np

#: Seed paper figures, decoupled (fixed-wall) simulation, 20 m/s, Envisat mock-up.
PAPER_REFERENCE = {
    "peak_contact_force_N": 12e3,           # Sec. 3.2, at the ASAR impact
    "peak_contact_moment_Nm": 160e3,        # Sec. 3.2, yaw
    "hinge_moment_h1_Nm": 4e3,              # Sec. 3.3.3, sustained from 0.25 s
    "hinge_moment_h3_Nm": 5e3,
    "debris_along_track_velocity_analytic_m_s": 0.032,  # Sec. 3.3.1
    "debris_along_track_velocity_simulated_m_s": 0.028,
}
#: Loads before this time have no time to propagate into the structure (paper Sec. 3.3.3).
TRANSIENT_SKIP_S = 0.25


def contact_totals_debris(series):
    """Total contact force (N) and moment about the debris CoM (N m), LVLH, over time.

    Parameters
    ----------
    series : dict of str to numpy.ndarray
        Recorder series (:mod:`multibody.recorder`): ``contact_force_lvlh``, ``contact_moment_lvlh``,
        ``body_com_lvlh`` (k, nb, 3) and ``debris_com_lvlh`` (k, 3).

    Returns
    -------
    force : (k, 3) float
        Sum of the contact forces on all bodies (N), LVLH.
    moment : (k, 3) float
        Their moment about the debris CoM (N m), LVLH.
    """
    force = series["contact_force_lvlh"].sum(axis=1)
    com = series["debris_com_lvlh"]
    arms = series["body_com_lvlh"] - com[:, None, :]
    moment = (series["contact_moment_lvlh"] + np.cross(arms, series["contact_force_lvlh"])).sum(axis=1)
    return force, moment


def momentum_exchange_velocity(assembly) -> np.ndarray:
    """Debris velocity (m/s, LVLH) if net and debris ended with one common velocity.

    Parameters
    ----------
    assembly : multibody.assembly.ImpactAssembly
        The assembly at its initial state: net node masses (kg) and velocities (m/s, LVLH), body
        masses and CoM velocities (m/s, LVLH).

    Returns
    -------
    (3,) float
        Velocity of the common centre of mass (m/s), LVLH.
    """
    net_momentum = (assembly.net.masses[:, None] * assembly.net_velocity).sum(axis=0)
    body_momentum = sum(b.mass * b.velocity_lvlh for b in assembly.bodies)
    total_mass = assembly.net.masses.sum() + sum(b.mass for b in assembly.bodies)
    return (net_momentum + body_momentum) / total_mass


def _peak(t, values):
    norm = np.linalg.norm(values, axis=-1)
    k = int(norm.argmax())
    return {"value": float(norm[k]), "time_s": float(t[k]), "vector": values[k].tolist()}


def joint_extremes(series, joints, skip=TRANSIENT_SKIP_S):
    """Per joint, the largest angle, rate, reaction moment and force of a run.

    Parameters
    ----------
    series : dict of str to numpy.ndarray
        Recorder series: ``time`` (k,) s and ``joint_rotation_joint``, ``joint_rate_joint``,
        ``joint_force_joint``, ``joint_moment_joint`` (k, nj, 3), joint frame.
    joints : sequence of multibody.assembly.JointSpec
        The joints in the series' order (``name``, ``kind``).
    skip : float
        Time (s) before which moments count as transient (:data:`TRANSIENT_SKIP_S`).

    Returns
    -------
    dict
        Joint name -> ``kind``, ``max_abs_angle_rad`` (hinge angle, component 1, revolute only),
        ``max_abs_rate_rad_s``, ``max_abs_moment_joint_Nm`` and ``max_abs_force_joint_N`` (3 per-axis
        maxima, joint frame) and ``max_abs_moment_after_transient_Nm`` (None when the run is
        shorter than ``skip``).
    """
    t = series["time"]
    later = t >= skip
    out = {}
    for j, joint in enumerate(joints):
        moment = series["joint_moment_joint"][:, j]
        force = series["joint_force_joint"][:, j]
        angle = series["joint_rotation_joint"][:, j, 1]
        out[joint.name] = {
            "kind": joint.kind,
            "max_abs_angle_rad": float(np.abs(angle).max()) if joint.kind == "revolute" else None,
            "max_abs_rate_rad_s": float(np.abs(series["joint_rate_joint"][:, j, 1]).max()),
            "max_abs_moment_joint_Nm": np.abs(moment).max(axis=0).tolist(),
            "max_abs_force_joint_N": np.abs(force).max(axis=0).tolist(),
            "max_abs_moment_after_transient_Nm": (np.abs(moment[later]).max(axis=0).tolist()
                                                  if later.any() else None),
        }
    return out


def conservation_checks(series, mean_motion):
    """Relative drift of energy balance and (without orbit) of momentum.

    Parameters
    ----------
    series : dict of str to numpy.ndarray
        Recorder series: ``energy_total`` (k,) J, ``momentum_linear_lvlh`` (k, 3) kg m/s,
        ``momentum_angular_lvlh`` (k, 3) kg m^2/s.
    mean_motion : float
        Orbital mean motion (rad/s); 0 without orbit, the only case where momentum is conserved.

    Returns
    -------
    dict
        ``energy_balance_relative_drift`` (-), and without orbit ``linear_momentum_relative_drift``
        (-) and ``angular_momentum_drift_kg_m2_s``.
    """
    e = series["energy_total"]
    checks = {"energy_balance_relative_drift": float(np.abs(e - e[0]).max() / max(abs(e[0]), 1e-300))}
    if mean_motion == 0.0:
        p = series["momentum_linear_lvlh"]
        h = series["momentum_angular_lvlh"]
        checks["linear_momentum_relative_drift"] = float(
            np.linalg.norm(p - p[0], axis=1).max() / max(np.linalg.norm(p[0]), 1e-300))
        checks["angular_momentum_drift_kg_m2_s"] = float(np.linalg.norm(h - h[0], axis=1).max())
    return checks


def run_summary(recorder, assembly, case_name: str) -> dict:
    """Summary of one run.

    ``debris_velocity_change_final_third_mean_lvlh_m_s`` averages the debris velocity over
    the last third of the run: once the net has wrapped, net and debris trade momentum back
    and forth (the net swings on the debris), and the mean is what the momentum-exchange
    estimate predicts.

    Parameters
    ----------
    recorder : multibody.recorder.Recorder
        The finished run's recorder (series, wall time, health).
    assembly : multibody.assembly.ImpactAssembly
        The run's assembly (initial state, bodies, joints, solver, mean motion).
    case_name : str
        The case's ``name``.

    Returns
    -------
    dict
        The content of ``summary.json`` (units in the key names, vectors in LVLH unless named).
    """
    s = recorder.series
    t = s["time"]
    force, moment = contact_totals_debris(s)
    dv = s["debris_velocity_lvlh"][-1] - s["debris_velocity_lvlh"][0]
    estimate = momentum_exchange_velocity(assembly) - s["debris_velocity_lvlh"][0]
    solver = assembly.solver
    summary = {
        "case": case_name,
        "simulated_time_s": float(t[-1]),
        "steps": solver.n_steps,
        "step_s": solver.step,
        "integrator": solver.integrator,
        "wall_time_s": recorder.wall_time,
        "steps_per_second": solver.n_steps / recorder.wall_time if recorder.wall_time else None,
        "peak_contact_force_N": _peak(t, force),
        "peak_contact_moment_about_debris_com_Nm": _peak(t, moment),
        "peak_contact_force_per_body_N": {
            b.name: _peak(t, s["contact_force_lvlh"][:, k]) for k, b in enumerate(assembly.bodies)},
        "debris_velocity_change_lvlh_m_s": dv.tolist(),
        "debris_velocity_change_final_third_mean_lvlh_m_s": (
            s["debris_velocity_lvlh"][t >= 2.0 * t[-1] / 3.0].mean(axis=0) - s["debris_velocity_lvlh"][0]).tolist(),
        "momentum_exchange_estimate_lvlh_m_s": estimate.tolist(),
        "debris_final_omega_body_rad_s": s["body_omega_body"][-1, 0].tolist(),
        "joints": joint_extremes(s, assembly.joints),
        "checks": conservation_checks(s, assembly.mean_motion),
        "health": recorder.health.summary(),
        "paper_reference": PAPER_REFERENCE,
    }
    winch = getattr(recorder.system, "closing", None)
    if winch is not None:   # the net's closing mechanism: trigger, reel-in and the winch's work (J)
        summary["closing"] = winch.summary()
    spool = getattr(recorder.system, "tether", None)
    if spool is not None:   # the main tether: brake, reel, peak tension (N) and what the chaser's thrusters held
        summary["tether"] = spool.summary()
    return summary


def sequential_summary(wall_recorder, wall_assembly, recorder, assembly, coupled_assembly, case_name: str) -> dict:
    """Summary of a sequential run (``simulation.coupling = "sequential"``): the driven debris' run
    as :func:`run_summary` gives it, with the momentum-exchange estimate of the case's real net
    (``coupled_assembly``: the driven run has no net) and the driven run's own energy balance (the
    recorded loads are external, so its momentum is not a check), plus the wall run's figures
    under ``wall_run``: the contact force and moment peaks on the fixed target (the paper's Figs. 6
    and 7) and its conservation checks (net and wall form a closed system).

    Parameters
    ----------
    wall_recorder : multibody.recorder.Recorder
        Recorder of the net on the fixed target.
    wall_assembly : multibody.assembly.ImpactAssembly
        Its assembly.
    recorder : multibody.recorder.Recorder
        Recorder of the free debris driven by the recorded loads.
    assembly : multibody.assembly.ImpactAssembly
        Its assembly (no net).
    coupled_assembly : multibody.assembly.ImpactAssembly
        The case's coupled assembly (real net), for the momentum-exchange estimate only.
    case_name : str
        The case's ``name``.

    Returns
    -------
    dict
        The content of ``summary.json``, with ``coupling`` and ``wall_run``.
    """
    summary = run_summary(recorder, assembly, case_name)
    s = recorder.series
    estimate = momentum_exchange_velocity(coupled_assembly) - s["debris_velocity_lvlh"][0]
    summary["momentum_exchange_estimate_lvlh_m_s"] = estimate.tolist()
    # the driven run starts at rest: its balance is relative to the wall run's reference energy (the
    # net's launch energy), the health check's own measure
    summary["checks"] = {"energy_balance_relative_drift": recorder.health.summary()["energy_max_drift"]}
    summary["coupling"] = "sequential"
    w = wall_recorder.series
    force, moment = contact_totals_debris(w)
    summary["wall_run"] = {
        "peak_contact_force_N": _peak(w["time"], force),
        "peak_contact_moment_about_debris_com_Nm": _peak(w["time"], moment),
        "wall_time_s": wall_recorder.wall_time,
        "checks": conservation_checks(w, wall_assembly.mean_motion),
        "health": wall_recorder.health.summary(),
    }
    return summary
