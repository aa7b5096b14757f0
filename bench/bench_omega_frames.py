"""omega_D of the capture-start full-net runs and of the lower-order model in body and in inertial components:
does the turn of the full net's debris rate within the body x-y plane (docs/towing.md, "The capture start on the
held runs only") remain in inertial space, and what is f1 (eq. 18) with the rates compared in body components,
in inertial components and roll-blind, on the same s.

    python bench/bench_omega_frames.py --runs DIR [--results DIR/results.json --key 'capture|f1|pso+pattern']
        [--case cases/zenit2_towing.toml] [--end 300] [--s S1 S2 S3 S4] [--reconstruct]

``DIR`` holds the cached capture-start runs (``DIR/capture/fullnet/rate_*_end_<end>_capture.npz``, as
bench_fullnet_identify.py and ``riskassess identify`` write them); only the runs present are read (none is run)
and the failed captures are left out by ``identify_fullnet.held_runs``' rule. s: ``--s``, else the answer
``--key`` of ``--results``. Runs cached before 2026-11-27 store no attitude: with ``--reconstruct`` their
debris attitude is integrated from the start attitude (25 s) and the sampled body rates (:func:`attitude_from_rates`,
second-order Magnus at the 0.1 s samples; checked against the recorded attitude on the runs that store one, the
column "reconstruction error"), else they are listed as lacking it.

Per run: the body-frame turn of omega_D within the plane normal to the debris' symmetry axis (net angle from 25 s
to the end, deg), the largest angle of omega_D in inertial components from its direction at 25 s and from its mean
direction (deg), for the full net (H) and the lower-order model (L); the angle between H's and L's omega_D in body
and in inertial components (RMS and largest over the samples, deg); RMSE of omega_D in both frames; f1 per run in
body components, inertial components and roll-blind. The LVLH columns give omega_D (relative to the inertial frame, as
eq. 17e) in the debris' orbit frame (:func:`lvlh_to_inertial_circular`); its RMSE equals the inertial one (printed
at the end), since both models' rates are turned by the same rotation at each sample.
"""
from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from multibody.orbit import lvlh_to_eci
from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase
from riskassess.stages.identify import MissingAttitude, angular_velocity, rmse, simulate, symmetry_axis_body
from riskassess.stages.identify_fullnet import comparison_rows, held_runs, lower_order_case, start_state


def attitude_from_rates(start_to_inertial, omega_body, dt) -> np.ndarray:
    r"""Attitudes (body -> inertial) integrated from sampled body rates: :math:`R_{k+1} = R_k \exp([\phi_k]_\times)`
    with the second-order Magnus increment :math:`\phi_k = \frac{h}{2}(\omega_k + \omega_{k+1}) + \frac{h^2}{12}
    \omega_k \times \omega_{k+1}` (Iserles et al. 2000, Acta Numerica, Sec. 4), the rate linear between samples.

    Parameters
    ----------
    start_to_inertial : (3, 3) float
        Attitude at the first sample.
    omega_body : (k, 3) float
        Body-frame angular velocity at the samples (rad/s).
    dt : float
        Sample interval (s).

    Returns
    -------
    (k, 3, 3) float
    """
    omega = np.asarray(omega_body, float)
    increments = dt / 2 * (omega[:-1] + omega[1:]) + dt**2 / 12 * np.cross(omega[:-1], omega[1:])
    steps = Rotation.from_rotvec(increments)
    out = [Rotation.from_matrix(start_to_inertial)]
    for k in range(len(increments)):
        out.append(out[-1] * steps[k])
    return np.array([r.as_matrix() for r in out])


def angle_deg(a, b) -> np.ndarray:
    """Angles between the rows of ``a`` and ``b`` (deg)."""
    cos = np.sum(a * b, axis=-1) / np.linalg.norm(a, axis=-1) / np.linalg.norm(b, axis=-1)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def lvlh_to_inertial_circular(start: dict, times) -> np.ndarray:
    """LVLH -> inertial at ``times`` (s) of the debris' orbit frame (``multibody.orbit.lvlh_to_eci``), from its
    state at the start time turned about the orbit normal at the start's angular rate |r x v| / |r|^2: a
    circular-orbit propagation (the cached runs keep the debris' inertial state only at 25 s; the tow's 200 N on
    ~10 t changes the orbital rate by < 1e-3 of itself over 275 s)."""
    r, v = np.asarray(start["debris_com"], float), np.asarray(start["debris_velocity"], float)
    normal = np.cross(r, v)
    rate = np.linalg.norm(normal) / (r @ r)
    turn = Rotation.from_rotvec(np.outer(np.asarray(times, float) - start["start_time"], normal / np.linalg.norm(normal) * rate))
    return np.einsum("kij,jl->kil", turn.as_matrix(), lvlh_to_eci(r, v))


def turn_measures(series: dict, axis_body, lvlh_to_inertial=None) -> dict:
    """How omega_D turns: net angle within the body plane normal to ``axis_body`` from the first sample to the last
    (deg, unwrapped), and in inertial (and LVLH) components the largest angle from the first sample's direction and
    from the mean direction (deg; absent without an attitude)."""
    omega = np.asarray(series["debris_omega_body"], float)
    axis = np.asarray(axis_body, float)
    e1 = np.cross(axis, [1.0, 0.0, 0.0]) if abs(axis[0]) < 0.9 else np.cross(axis, [0.0, 1.0, 0.0])
    e1 /= np.linalg.norm(e1)
    e2 = np.cross(axis, e1)
    phase = np.unwrap(np.arctan2(omega @ e2, omega @ e1))
    out = {"body_turn_deg": float(np.degrees(phase[-1] - phase[0])),
           "body_turn_range_deg": float(np.degrees(np.ptp(phase)))}
    if "debris_to_inertial" in series:
        inertial = np.einsum("kij,kj->ki", np.asarray(series["debris_to_inertial"], float), omega)
        mean = inertial.mean(axis=0)
        out.update(inertial_from_start_deg=float(angle_deg(inertial, inertial[0]).max()),
                   inertial_from_mean_deg=float(angle_deg(inertial, mean[None, :]).max()))
        if lvlh_to_inertial is not None:
            lvlh = np.einsum("kji,kj->ki", lvlh_to_inertial, inertial)   # the transpose: inertial -> LVLH
            mean = lvlh.mean(axis=0)
            out.update(lvlh_from_start_deg=float(angle_deg(lvlh, lvlh[0]).max()),
                       lvlh_from_mean_deg=float(angle_deg(lvlh, mean[None, :]).max()))
    return out


def between(model: dict, run: dict) -> str:
    """'RMS / max | RMS / max': the angle between the two models' omega_D at each sample in body components and in
    inertial components (deg; '- / -' for the inertial one without an attitude)."""
    cells = []
    for frame in ("body", "inertial"):
        try:
            angle = angle_deg(angular_velocity(model, "debris_omega_body", frame),
                              angular_velocity(run, "debris_omega_body", frame))
            cells.append(f"{np.sqrt(np.mean(angle**2)):.1f} / {angle.max():.1f}")
        except MissingAttitude:
            cells.append("- / -")
    return " | ".join(cells)


def load_runs(folder: Path, case: TowingCase, end: float) -> tuple[list[dict], list[dict], list[dict], list[float]]:
    """The cached capture-start runs present in ``folder`` (training first), the held ones split by role, and the
    rates of Table 3 not cached there."""
    rates = list(case.rates.training_deg_s) + list(case.rates.validation_deg_s)
    found, absent = [], []
    for rate in rates:
        path = folder / f"rate_{rate:.2f}_end_{end:g}_capture.npz"
        if not path.exists():
            absent.append(rate)
            continue
        run = {k: (float(v) if v.ndim == 0 else v) for k, v in np.load(path).items()}
        run["start"] = start_state(run)
        found.append(run)
    n_training = sum(float(r["rate_deg_s"]) in case.rates.training_deg_s for r in found)
    train, valid, excluded = held_runs(case, found, n_training)
    return train, valid, excluded, absent


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", required=True, help="bench_fullnet_identify.py's --out folder")
    parser.add_argument("--case", default="cases/zenit2_towing.toml")
    parser.add_argument("--end", type=float, default=300.0)
    parser.add_argument("--results", help="results.json of bench_fullnet_identify.py (default DIR/results.json)")
    parser.add_argument("--key", default="capture|f1|pso+pattern", help="the answer whose s is used")
    parser.add_argument("--s", type=float, nargs=4, help="s instead of an answer's")
    parser.add_argument("--reconstruct", action="store_true",
                        help="integrate the attitude of runs cached without one from their sampled rates")
    args = parser.parse_args()
    case = load_model(args.case, TowingCase)
    case = case.model_copy(update=dict(full_net=case.full_net.model_copy(update=dict(start="capture"))))
    if args.s:
        s = list(args.s)
    else:
        store = Path(args.results or Path(args.runs) / "results.json")
        s = json.loads(store.read_text())[args.key]["s"]
    train, valid, excluded, absent = load_runs(Path(args.runs) / "capture" / "fullnet", case, args.end)
    dt = case.simulation.output_interval
    axis = symmetry_axis_body(case.debris.principal_inertia)
    print(f"s = {[round(x, 4) for x in s]}; runs: {len(train)} training + {len(valid)} validation held, "
          f"left out {[w['rate_deg_s'] for w in excluded]}, not cached {absent} (load {os.getloadavg()[0]:.1f})")
    print("\n| role | rate (deg/s) | attitude | reconstruction error (deg) | H body turn (deg) | H inertial from start "
          "/ from mean (deg) | H LVLH from start / from mean (deg) | L body turn (deg) | L inertial from start / from "
          "mean (deg) | L LVLH from start / from mean (deg) | angle H-L body: RMS / max (deg) | angle H-L inertial: "
          "RMS / max (deg) | RMSE omega_D body / inertial (rad/s) | f1 body | f1 inertial | f1 roll-blind |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    lower = lower_order_case(case, train[0])
    sums, lvlh_gap = {}, 0.0
    for role, runs in (("training", train), ("validation", valid)):
        for run in runs:
            source, error = ("recorded", "")
            rebuilt = attitude_from_rates(run["start"]["body_to_inertial"][1], run["debris_omega_body"], dt)
            if "debris_to_inertial" in run:
                apart = Rotation.from_matrix(rebuilt).inv() * Rotation.from_matrix(run["debris_to_inertial"])
                error = f"{np.degrees(apart.magnitude().max()):.3f}"
            elif args.reconstruct:
                run = {**run, "debris_to_inertial": rebuilt,
                       "chaser_to_inertial": attitude_from_rates(run["start"]["body_to_inertial"][0],
                                                                 run["chaser_omega_body"], dt)}
                source = "reconstructed"
            else:
                source = "missing"
            model = simulate(lower, run["rate_deg_s"], s, args.end, run.get("start"))
            lvlh = lvlh_to_inertial_circular(run["start"], run["start"]["start_time"] + dt * np.arange(len(run["debris_omega_body"])))
            h, lo = turn_measures(run, axis, lvlh), turn_measures(model, axis, lvlh)
            row = comparison_rows(lower, s, [run], args.end)[0]
            if "f1_inertial" in row:   # LVLH components: the same RMSE (one rotation for both models per sample)
                in_lvlh = [np.einsum("kji,kj->ki", lvlh, angular_velocity(x, "debris_omega_body", "inertial"))
                           for x in (model, run)]
                lvlh_gap = max(lvlh_gap, abs(rmse(*in_lvlh) - row["rmse_debris_omega_inertial"]))
            inertial_rmse = (f"{row['rmse_debris_omega_inertial']:.4f}" if "f1_inertial" in row else "-")
            f1_inertial = f"{row['f1_inertial']:.3f}" if "f1_inertial" in row else "-"
            for key in ("f1", "f1_inertial", "f1_free_roll"):
                if key in row:
                    sums.setdefault((role, key), []).append(row[key])

            def inertial(m):
                return (f"{m['inertial_from_start_deg']:.1f} / {m['inertial_from_mean_deg']:.1f} | "
                        f"{m['lvlh_from_start_deg']:.1f} / {m['lvlh_from_mean_deg']:.1f}"
                        if "inertial_from_start_deg" in m else "- | -")
            print(f"| {role} | {run['rate_deg_s']:.2f} | {source} | {error} | {h['body_turn_deg']:.1f} | {inertial(h)} "
                  f"| {lo['body_turn_deg']:.1f} | {inertial(lo)} | {between(model, run)} "
                  f"| {row['rmse_debris_omega_body']:.4f} / {inertial_rmse} "
                  f"| {row['f1']:.3f} | {f1_inertial} | {row['f1_free_roll']:.3f} |", flush=True)
    print(f"largest |RMSE omega_D in LVLH components - in inertial components|: {lvlh_gap:.2e} rad/s")
    for (role, key), values in sums.items():
        print(f"{role} {key}: {sum(values) / len(values):.3f} per run over {len(values)} runs")


if __name__ == "__main__":
    main()
