"""The figures every towing run reports, lower-order or full-net (SI): main-tether tension and
tautness, separation, body rates (:func:`run_figures`)."""
from __future__ import annotations

import numpy as np

from multibody.control.mrac import abstracted_tether, reference_steady_elongation
from riskassess.cases.towing import TowingCase
from riskassess.models.towing import reference_command

#: Main-tether tension (N) from which the tether counts as engaged: before it the sub-tethers are still
#: slack and only the connection point hangs on the main tether.
ENGAGED_N = 1.0


def reference_elongation(case: TowingCase) -> float | None:
    """Where the MRAC laws steer the elongation (m): the steady state of their reference model
    (:func:`multibody.control.mrac.reference_steady_elongation`); None without an [mrac] section.

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        The towing case (main-tether stiffness, ``[mrac]`` gains, reference command).
    """
    if case.mrac is None:
        return None
    mt = case.main_tether
    k_mt, _ = abstracted_tether(case, [mt.stiffness, mt.damping])
    return reference_steady_elongation(k_mt, case.mrac.k_p, reference_command(case))


def tautness(series: dict, target_elongation: float | None) -> dict:
    """Main-tether figures after engagement (first sample with tension > :data:`ENGAGED_N`): smallest
    tension and slack time (taut: > 0 N and 0 s), peak tension, final elongation and its RMS error
    against ``target_elongation`` over the last 100 s (None without a target) (SI).

    Parameters
    ----------
    series : dict of str to numpy.ndarray
        A tow's series: ``time`` (k,) s, ``main_tether_tension`` (k,) N,
        ``main_tether_elongation`` (k,) m.
    target_elongation : float or None
        The elongation the controller steers to (m), from :func:`reference_elongation`.

    Returns
    -------
    dict
        ``engaged_at_s``, ``min_tension_after_engagement_N``, ``slack_after_engagement_s``,
        ``peak_tension_N``, ``final_elongation_m``, ``target_elongation_m``,
        ``rms_elongation_error_m``.
    """
    t, tension, z = series["time"], series["main_tether_tension"], series["main_tether_elongation"]
    engaged = np.nonzero(tension > ENGAGED_N)[0]
    k = engaged[0] if len(engaged) else len(t) - 1
    dt = np.diff(t, prepend=t[0])
    late = t >= t[-1] - 100.0
    return {"engaged_at_s": float(t[k]), "min_tension_after_engagement_N": float(tension[k:].min()),
            "slack_after_engagement_s": float(np.sum(dt[k:][tension[k:] <= 0.0])),
            "peak_tension_N": float(tension.max()), "final_elongation_m": float(z[-1]),
            "target_elongation_m": target_elongation,
            "rms_elongation_error_m": None if target_elongation is None else
            float(np.sqrt(np.mean((z[late] - target_elongation) ** 2)))}


def run_figures(case: TowingCase, series: dict, model) -> dict:
    """The figures every towing run reports, lower-order or full-net (SI): main-tether peak, final
    tension, slack while thrusting and :func:`tautness`; separation; chaser peak and debris final
    rate; step and step count. ``model`` is the run's model (``omega_body``, ``step``, times).

    Parameters
    ----------
    case : riskassess.cases.towing.TowingCase
        The towing case.
    series : dict of str to numpy.ndarray
        The tow's series: ``time`` (k,) s, ``main_tether_tension``, ``thrust`` (k,) N,
        ``main_tether_elongation`` (k,) m, ``debris_com_inertial``, ``chaser_com_inertial``
        (k, 3) m (inertial frame), ``chaser_omega_body``, ``debris_omega_body`` (k, 3) rad/s (body
        frames).
    model : object
        The run's model: ``omega_body`` (2, 3) initial angular velocities of chaser and debris
        (rad/s, body frames), ``step`` (s), ``n_steps``, ``start_time`` and ``end_time`` (s).

    Returns
    -------
    dict
        Figures with their units in the key names (N, s, m, deg/s).
    """
    t, tension = series["time"], series["main_tether_tension"]
    dt = np.diff(t, prepend=t[0])
    separation = np.linalg.norm(series["debris_com_inertial"] - series["chaser_com_inertial"], axis=1)
    return {
        "case": case.name, "thrust_kind": case.thrust.kind,
        "spin_rate_deg_s": float(np.rad2deg(np.linalg.norm(model.omega_body[1]))),
        "main_tether_peak_tension_N": float(tension.max()),
        "main_tether_final_tension_N": float(tension[-1]),
        "main_tether_slack_time_while_thrusting_s": float(np.sum(dt[(series["thrust"] != 0.0) & (tension <= 0.0)])),
        "main_tether": tautness(series, reference_elongation(case)),
        "separation_m": {"initial": float(separation[0]), "min": float(separation.min()),
                         "max": float(separation.max()), "final": float(separation[-1])},
        "chaser_peak_rate_deg_s": float(np.rad2deg(np.linalg.norm(series["chaser_omega_body"], axis=1).max())),
        "debris_final_rate_deg_s": float(np.rad2deg(np.linalg.norm(series["debris_omega_body"][-1]))),
        "step_s": model.step, "n_steps": model.n_steps, "simulated_s": model.end_time - model.start_time,
    }
