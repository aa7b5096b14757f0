"""The impact scenario's model: the coupled net-capture simulation of an impact case
(:mod:`riskassess.models.impact`, :class:`multibody.impact.ImpactSimulation`) with some of its
physical parameters changed, observed as the diagnosis compares it with a record.

Observed (:data:`FIT_CHANNELS`): window means of the debris main body's CoM velocity relative to the
chaser, LVLH axes (``vel_x..z``, m/s) and of its inertial angular velocity in its own frame
(``omega_x..z``, rad/s). A record with poses only (``rel_x..z``, ``q_w..q_z``, what the perception
stage tracks) gives the same window means from the poses: the mean velocity over a window is the
slope of the position across it, the mean body rate the slope of the rotation vector of
R(t_0)^T R(t) (:func:`window_statistics`). Windows are ``[t_0 + k w, t_0 + (k + 1) w)`` from the
record's first time t_0; times are the impact case's (0 = the launch).
"""
from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from multibody.health import SimulationFailed
from multibody.impact import ImpactSimulation
from riskassess.cases.impact import read_toml, validate_case
from riskassess.diagnosis.plants.channels import OMEGA, QUATERNION, REL, VELOCITY
from riskassess.diagnosis.impact_effects.base import case_with_overrides
from riskassess.cases.target_geometry import body_meshes_target_frame
from riskassess.models.impact import mass_properties_target_frame, model_inputs

#: The fitted channels (window means).
FIT_CHANNELS = VELOCITY + OMEGA
#: Simulation output rate of the diagnosis runs (Hz): 50 samples per second give a window mean of
#: 0.5 s from 25 samples (the record's own rate does not matter: both are averaged over the window).
OUTPUT_RATE = 50.0
#: Net snapshots of the diagnosis runs (Hz): not used, the lowest the recorder allows.
NET_OUTPUT_RATE = 1.0
#: Round-off of sample times against window edges (s): far below any sampling interval.
EDGE_TOLERANCE = 1e-6
#: Fewest samples a window needs to be used (a mean or a slope of fewer is not worth its weight).
MIN_WINDOW_SAMPLES = 3


@dataclass(frozen=True)
class ImpactRun:
    """What one simulation needs: the parsed impact case file, its path (mesh files are relative to
    it), the end time (s) and the window edges (s)."""

    raw: dict
    path: str
    end_time: float
    edges: tuple


def run_spec(impact_path, end_time: float, edges) -> ImpactRun:
    """The run specification of an impact case file.

    Parameters
    ----------
    impact_path : str or Path
        The impact case file.
    end_time : float
        Simulated time (s), at least the last window's end.
    edges : (w + 1,) float
        Window edges (s).

    Returns
    -------
    ImpactRun
    """
    return ImpactRun(read_toml(impact_path), str(impact_path), float(end_time), tuple(float(e) for e in edges))


def simulate(run: ImpactRun, overrides: dict) -> dict | None:
    """Window means of the fitted channels of the impact case with ``overrides``; None when the run
    fails its health checks (:class:`multibody.health.SimulationFailed`: a parameter that makes the
    explicit integration unstable, for example).

    Parameters
    ----------
    run : ImpactRun
        The case and windows.
    overrides : dict of str to object
        Dotted impact-case key -> value (SI).

    Returns
    -------
    channels : dict of str to (w,) float, or None
        ``vel_x..z`` (m/s, LVLH) and ``omega_x..z`` (rad/s, main body frame), one value per window.
    """
    raw = case_with_overrides(run.raw, {**overrides, "simulation.end_time": run.end_time,
                                        "simulation.output_rate": OUTPUT_RATE,
                                        "simulation.net_output_rate": NET_OUTPUT_RATE})
    case = validate_case(raw, run.path)
    inputs = model_inputs(case, os.path.dirname(os.path.abspath(run.path)))
    try:
        recorder = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms).run()
    except SimulationFailed:
        return None
    series = recorder.series
    values = {**{c: series["body_velocity_lvlh"][:, 0, k] for k, c in enumerate(VELOCITY)},
              **{c: series["body_omega_body"][:, 0, k] for k, c in enumerate(OMEGA)}}
    means, _ = window_statistics(series["time"], values, np.asarray(run.edges), {})
    return {c: means[c] for c in FIT_CHANNELS}


def window_edges(times, window: float) -> np.ndarray:
    """Edges (s) of the windows of length ``window`` that fit in the record, from its first time.

    Parameters
    ----------
    times : (k,) float
        Record times (s).
    window : float
        Window length (s).

    Returns
    -------
    edges : (w + 1,) float
    """
    n = int(np.floor((times[-1] - times[0]) / window + 1e-9))
    if n < 2:
        raise ValueError(f"the record spans {times[-1] - times[0]:g} s: at least two windows of {window:g} s needed")
    return times[0] + window * np.arange(n + 1)


def window_statistics(times, values: dict, edges, noise: dict) -> tuple[dict, dict]:
    """Per fitted channel and window: the mean and its 1-sigma from the noise (NaN where the window
    has too few samples or the channel cannot be formed).

    ``vel`` and ``omega`` channels are averaged where given; otherwise formed from the poses: the
    least-squares slope of ``rel`` (m/s) and of the rotation vector of R(t_k)^T R(t) (body frame,
    rad/s; R the attitude ``q`` B -> LVLH at the window's samples, t_k its first). Slopes of LVLH
    quantities are relative to the rotating LVLH frame, as the simulation's ``vel``; so is the body
    rate from poses, and so is the simulation's (its attitude does not feel the frame's rotation,
    docs/model.md, "Orbit"), so no orbit rate is added.

    Parameters
    ----------
    times : (k,) float
        Sample times (s).
    values : dict of str to (k,) float
        Channels (SI), NaN where missing.
    edges : (w + 1,) float
        Window edges (s).
    noise : dict of str to float
        1-sigma noise per sample of the given channels (channel units); missing: 0.

    Returns
    -------
    means : dict of str to (w,) float
    sigmas : dict of str to (w,) float
        1-sigma of each window value from the noise alone.
    """
    times = np.asarray(times, float)
    # a sample on an edge belongs to the window it opens, whatever its round-off (a simulation's
    # 1.0 s may be 0.9999999999 s, a CSV's exactly 1.0: one sample moved between windows shifts a
    # window mean by 1/25 of the signal's change over the window, 4 sigma of a 1 mm/s sensor)
    index = np.searchsorted(edges, times + EDGE_TOLERANCE, side="right") - 1
    means, sigmas = {}, {}
    for group, pose in ((VELOCITY, REL), (OMEGA, QUATERNION)):
        given = all(c in values for c in group)
        from_pose = not given and all(c in values for c in pose)
        for c in group:
            means[c] = np.full(len(edges) - 1, np.nan)
            sigmas[c] = np.full(len(edges) - 1, np.nan)
        for w in range(len(edges) - 1):
            rows = np.flatnonzero(index == w)
            if given:
                _window_means(values, group, rows, noise, w, means, sigmas)
            elif from_pose:
                _window_slopes(times, values, group, pose, rows, noise, w, means, sigmas)
    return means, sigmas


def _window_means(values, group, rows, noise, w, means, sigmas) -> None:
    for c in group:
        v = values[c][rows]
        v = v[np.isfinite(v)]
        if len(v) >= MIN_WINDOW_SAMPLES:
            means[c][w] = v.mean()
            sigmas[c][w] = noise.get(c, 0.0) / np.sqrt(len(v))


def _window_slopes(times, values, group, pose, rows, noise, w, means, sigmas) -> None:
    ok = rows[np.all([np.isfinite(values[c][rows]) for c in pose], axis=0)] if len(rows) else rows
    if len(ok) < MIN_WINDOW_SAMPLES:
        return
    t = times[ok] - times[ok].mean()
    spread = float(t @ t)
    if spread <= 0:
        return
    if pose == REL:
        y = np.column_stack([values[c][ok] for c in REL])
        sigma = [noise.get(c, 0.0) for c in REL]
    else:
        q = np.column_stack([values[c][ok] for c in QUATERNION])
        attitude = Rotation.from_quat(q[:, [1, 2, 3, 0]])            # B -> LVLH, scalar last for scipy
        y = (attitude[0].inv() * attitude).as_rotvec()               # body frame of the window's start
        sigma = [2.0 * noise.get(c, 0.0) for c in QUATERNION[1:]]    # small angles: 2 dq per rad
    slope = t @ (y - y.mean(axis=0)) / spread
    for k, c in enumerate(group):
        means[c][w] = slope[k]
        sigmas[c][w] = sigma[k] / np.sqrt(spread)


def record_channels(series: dict, com_target) -> dict:
    """The record's channels of an impact run's series (:class:`multibody.recorder.Recorder`): main body
    velocity (``vel``, m/s, LVLH), body rates (``omega``, rad/s, body frame), target-frame origin
    (``rel``, m, LVLH) and attitude (``q``, B -> LVLH, scalar first, continuous sign).

    Parameters
    ----------
    series : dict of str to numpy.ndarray
        The recorder's series (``body_velocity_lvlh``, ``body_omega_body``, ``body_com_lvlh``,
        ``body_to_lvlh``; body 0 is the main body).
    com_target : (3,) float
        The main body's CoM in the target frame (m).

    Returns
    -------
    channels : dict of str to (k,) float
    """
    rotation = series["body_to_lvlh"][:, 0]
    origin = series["body_com_lvlh"][:, 0] - rotation @ np.asarray(com_target, float)
    q = Rotation.from_matrix(rotation).as_quat()[:, [3, 0, 1, 2]]
    if q[0, 0] < 0:
        q[0] = -q[0]
    for k in range(1, len(q)):                      # sign continuity, as the measured-data reader
        if q[k] @ q[k - 1] < 0:
            q[k] = -q[k]
    return {**{c: series["body_velocity_lvlh"][:, 0, k] for k, c in enumerate(VELOCITY)},
            **{c: series["body_omega_body"][:, 0, k] for k, c in enumerate(OMEGA)},
            **{c: origin[:, k] for k, c in enumerate(REL)},
            **{c: q[:, k] for k, c in enumerate(QUATERNION)}}


def simulate_record(impact_path, overrides: dict, end_time: float, rate: float) -> tuple[np.ndarray, dict]:
    """A record of the impact case with ``overrides`` (the truth of a synthetic test): every channel of
    :func:`record_channels` at ``rate`` from 0 to ``end_time``.

    Parameters
    ----------
    impact_path : str or Path
        The impact case file.
    overrides : dict of str to object
        Dotted impact-case key -> value (SI).
    end_time : float
        (s).
    rate : float
        Samples per second (Hz), at most 1 / the case's step.

    Returns
    -------
    times : (k,) float
        (s, from the launch).
    channels : dict of str to (k,) float
    """
    raw = case_with_overrides(read_toml(impact_path), {**overrides, "simulation.end_time": float(end_time),
                                                       "simulation.output_rate": float(rate),
                                                       "simulation.net_output_rate": NET_OUTPUT_RATE})
    case = validate_case(raw, impact_path)
    base = os.path.dirname(os.path.abspath(impact_path))
    inputs = model_inputs(case, base)
    recorder = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms).run()
    com_target = mass_properties_target_frame(case, body_meshes_target_frame(case, Path(base)))[0][0]
    return recorder.series["time"], record_channels(recorder.series, com_target)


def record_csv(times, channels: dict) -> str:
    """A record as the measured-data CSV (:mod:`riskassess.diagnosis.measured`): ``time`` then the channels.

    Parameters
    ----------
    times : (k,) float
        (s).
    channels : dict of str to (k,) float
        Channels (SI).

    Returns
    -------
    text : str
    """
    names = list(channels)
    rows = np.column_stack([times] + [channels[c] for c in names])
    lines = [",".join(["time"] + names)] + [",".join(f"{v:.10g}" for v in row) for row in rows]
    return "\n".join(lines) + "\n"
