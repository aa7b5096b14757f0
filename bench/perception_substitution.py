"""Which input limits the smallest principal moment C of the momentum step? Substitution experiments on a
captured perception run (bench/perception_capture.py): the momentum step is redone with one input at a
time replaced by its truth, and C's error and stated 1-sigma printed for each.

    python bench/perception_substitution.py runs/captures/none_obs20_seed1.pkl [...] [--unweighted]

Two kinds of substitution:

* **inputs** (the fits and balances redone): the registered attitudes after the collision (the truth
  in the tracker's frame B on the same frames), the same on every frame from the true end of contact
  (more free flight), the attitudes before the collision, the CoM in B, the net's nodes (true
  positions; true positions and velocities);
* **terms** of the angular balance ``m d(p x v) + C (h1 - h0) = -(dL_chaser + dL_net)`` (each
  replaced by its value from the simulated truth): the spin per C before (h0) and after (h1), the
  debris' orbital term, the net's angular momentum after, the mass.

The truth is read from the collision run's record (debris attitude, rates, CoM and velocity; net
nodes with their velocities); the estimators never see it.
"""
from __future__ import annotations

import argparse
import copy
import dataclasses
import pickle
import sys

import numpy as np

from perception import momentum
from perception.free_flight import fit_free_motion
from perception.momentum import point_masses_momentum, rigid_body_momentum, smallest_moment_from_angular_momentum
from perception.momentum_balance import _mean_and_covariance_of_mean, _orbital_per_mass, momentum_step
from perception.net_tracking import node_velocities


@dataclasses.dataclass
class Tracker:
    """The one thing the free-flight fits read of a tracker: its per-frame alignments."""

    alignments: list


def load(path) -> dict:
    with open(path, "rb") as f:
        return pickle.load(f)


def true_body_to_world(cap, k) -> np.ndarray:
    """The true pose (4, 4) of the tracker's frame B in the world at frame k (B -> world)."""
    frames = cap["frames"]
    rot, com = np.asarray(frames["true_target_to_world"][k]), np.asarray(frames["true_com_world"][k])
    target_to_world = np.eye(4)
    target_to_world[:3, :3] = rot
    target_to_world[:3, 3] = com - rot @ cap["truth"]["com_target"]
    return target_to_world @ np.linalg.inv(cap["target_to_body"])


def with_true_poses(cap, indices) -> Tracker:
    """The alignments with frames ``indices`` set to the true pose (registered, information kept; a
    frame that was not registered takes the mean information of the registered ones)."""
    alignments = [copy.copy(a) for a in cap["alignments"]]
    registered = [a.information for a in cap["alignments"] if a.ok]
    mean_information = np.mean(registered, axis=0)
    for k in indices:
        a = alignments[k]
        a.world_to_body = np.linalg.inv(true_body_to_world(cap, k))
        if not a.ok:
            a.information, a.ok = mean_information, True
    return Tracker(alignments)


def true_body_to_world_com_error(cap, k) -> np.ndarray:
    """Frame k's registered pose applied to the true CoM in B, minus the true CoM (m, world)."""
    pose = cap["alignments"][k].body_to_world
    return pose[:3, :3] @ true_com_body(cap) + pose[:3, 3] - np.asarray(cap["frames"]["true_com_world"][k])


def true_com_body(cap) -> np.ndarray:
    t2b = cap["target_to_body"]
    return t2b[:3, :3] @ cap["truth"]["com_target"] + t2b[:3, 3]


def others_after(cap, frame_times, origin, net_positions=None, net_velocities=None):
    """Chaser (navigation) + net linear and angular momentum about ``origin`` at the frames (the stage's
    perceive.others_momentum_after with the net's node positions and velocities chosen)."""
    series, parts, track = cap["series"], cap["assembly"], cap["track"]
    track_times = np.asarray(track.times)
    positions = np.asarray(track.positions if net_positions is None else net_positions)
    velocities = node_velocities(track_times, positions) if net_velocities is None else np.asarray(net_velocities)
    c, chaser = parts["chaser_index"], parts["chaser"]
    linear, angular = [], []
    for t in frame_times:
        i = int(np.argmin(np.abs(series["time"] - t)))
        j = int(np.argmin(np.abs(track_times - t)))
        p_c, l_c = rigid_body_momentum(chaser["mass"], chaser["inertia_body"], series["body_com_lvlh"][i, c],
                                       series["body_velocity_lvlh"][i, c], series["body_to_lvlh"][i, c],
                                       series["body_omega_body"][i, c], origin)
        p_n, l_n = point_masses_momentum(parts["net_masses"], positions[j], velocities[j], origin)
        linear.append(p_c + p_n)
        angular.append(l_c + l_n)
    return np.array(linear), np.array(angular)


def true_net(cap):
    """True net node positions and velocities (m, m/s, world) at the tracked frames."""
    net, times = cap["net"], np.asarray(cap["track"].times)
    rows = [int(np.argmin(np.abs(net["time"] - t))) for t in times]
    return net["positions_lvlh"][rows], net["velocities_lvlh"][rows].astype(float)


def free_flight_indices(cap, start_time, end_time=np.inf, all_frames=False):
    """Collision frames from ``start_time`` (s) on: the registered ones, or all."""
    frames = cap["frames"]
    time, phase = np.asarray(frames["time"]), np.asarray(frames["phase"])
    ok = np.array([a.ok for a in cap["alignments"]])
    select = (phase == 1) & (time >= start_time - 1e-9) & (time <= end_time + 1e-9)
    return np.flatnonzero(select if all_frames else select & ok)


def true_c(cap) -> float:
    return float(np.linalg.eigvalsh(cap["truth"]["inertia_target"])[0])


def replay(cap, *, before_tracker=None, after_tracker=None, after_indices=None, com_body=None, net=None,
           attitude_covariance=None):
    """Redo the stage's fits and momentum step with the inputs given (the captured ones otherwise; the after
    fit's correlated attitude covariance, a callable of the indices, as the stage's re-posed frames give it):
    returns (C, its 1-sigma, mass, before, after, origin, step)."""
    times = np.asarray(cap["frames"]["time"])
    fit_before, fit_after = cap["fits"][0], cap["fits"][-1]
    tracker = Tracker(cap["alignments"])
    before = fit_free_motion(before_tracker or tracker, fit_before["indices"], times, com_body)
    indices = fit_after["indices"] if after_indices is None else after_indices
    after = fit_free_motion(after_tracker or tracker, indices, times,
                            before.line.com_body, before.fit.moments_, before.fit.principal_to_body_,
                            attitude_covariance)
    origin = before.line.position_world([0.0])[0]
    others = others_after(cap, after.times, origin, *(net or (None, None)))
    parts = cap["assembly"]
    ch = parts["chaser"]
    p_c, l_c = rigid_body_momentum(ch["mass"], ch["inertia_body"], ch["com_lvlh"], ch["velocity_lvlh"],
                                   ch["body_to_lvlh"], ch["omega_body"], origin)
    p_n, l_n = point_masses_momentum(parts["net_masses"], parts["net_positions"], parts["net_velocity"], origin)
    step = momentum_step(before, after, (p_c + p_n, l_c + l_n), others, origin)
    return step["c"].value, step["c"].sigma, step["mass"].value, before, after, origin, step, (p_c + p_n, l_c + l_n), others


def true_terms(cap, before, after, origin):
    """The angular balance's terms from the truth, on the estimate's frames and origin: h0, h1 (spin per
    C, rad/s, world), orbital per mass before and after (p x v about ``origin``, m^2/s), the net's
    angular momentum after (mean over the frames, N m s) and the mass (kg)."""
    series = cap["series"]
    c_true = true_c(cap)
    inertia = cap["truth"]["inertia_target"]
    com0, rot0, v0, omega0 = cap["state_at_zero"]
    h0 = rot0 @ inertia @ omega0 / c_true
    h1s, orbital1 = [], []
    for t in after.times:
        i = int(np.argmin(np.abs(series["time"] - t)))
        rot, omega = series["body_to_lvlh"][i, 0], series["body_omega_body"][i, 0]
        h1s.append(rot @ inertia @ omega / c_true)
        orbital1.append(np.cross(series["body_com_lvlh"][i, 0] - origin, series["body_velocity_lvlh"][i, 0]))
    positions, velocities = true_net(cap)
    _, angular = others_after(cap, after.times, origin, positions, velocities)
    return {"h0": h0, "h1": np.mean(h1s, axis=0), "h1_spread": np.ptp(np.array(h1s), axis=0),
            "orbital0": np.cross(com0 - origin, v0), "orbital1": np.mean(orbital1, axis=0),
            "others_after_angular": angular.mean(axis=0), "mass": cap["truth"]["mass"]}


def estimated_terms(before, after, origin, step_others_before, others):
    return {"h0": before.spin_per_c, "h1": after.spin_per_c,
            "orbital0": _orbital_per_mass(before.line, origin)[0], "orbital1": _orbital_per_mass(after.line, origin)[0],
            "others_after_angular": others[1].mean(axis=0), "others_before_angular": step_others_before[1]}


def c_from_terms(terms, others_before_angular, mass, covariances=None):
    """C from the angular balance's terms, solved as the stage solves it (weighted by the covariances
    ``(cov_spin_change, cov_orbital_change_per_mass, mass_sigma, cov_others_change)`` when given,
    ordinary least squares otherwise); returns C and the balance's misfit (N m s)."""
    dh = terms["h1"] - terms["h0"]
    others = terms["others_after_angular"] - others_before_angular
    c = smallest_moment_from_angular_momentum(dh, terms["orbital1"] - terms["orbital0"], mass, others,
                                              *(covariances or ()))
    return c.value, c.misfit


def stage_covariances(before, after, origin, step, others):
    """The covariances the stage's angular balance is weighted with (perception.momentum_balance)."""
    cov_l_after = _mean_and_covariance_of_mean(others[1])[1]
    cov_orbital = _orbital_per_mass(before.line, origin)[1] + _orbital_per_mass(after.line, origin)[1]
    return (before.spin_per_c_cov + after.spin_per_c_cov, cov_orbital, step["mass"].sigma, cov_l_after)


def report(path):
    cap = load(path)
    c_true = true_c(cap)
    answer = cap["answer"]
    print(f"\n== {path}: seed {answer['bench_seed']}, stage C error "
          f"{answer['principal_moments_error_percent'][2]:+.2f} % (1-sigma "
          f"{100 * answer['principal_moments_std_kg_m2'][2] / answer['principal_moments_kg_m2'][2]:.2f} %), "
          f"free flight {answer['free_flight_after_s']}, true C {c_true:.3f} kg m^2")
    rows = []

    def row(name, **kwargs):
        try:
            c, sigma, mass, *_ = replay(cap, **kwargs)
            rows.append((name, 100 * (c - c_true) / c_true, 100 * sigma / c, 100 * (mass - cap["truth"]["mass"]) / cap["truth"]["mass"]))
        except Exception as exc:   # noqa: BLE001 -- a substitution that makes a fit refuse is a result too
            rows.append((name, np.nan, np.nan, np.nan))
            print(f"  {name}: {type(exc).__name__}: {exc}")

    base = replay(cap)
    c, sigma, mass, before, after, origin, step, others_before, others = base
    after_idx = cap["fits"][-1]["indices"]
    start = float(cap["frames"]["time"][after_idx[0]])
    end = float(cap["frames"]["time"][after_idx[-1]])
    contact_end = contact_end_time(cap)
    row("replay of the stage (no substitution)")
    positions, velocities = true_net(cap)
    row("net nodes: true positions (velocities differentiated as the stage)", net=(positions, None))
    row("net nodes: true positions and velocities", net=(positions, velocities))
    row("attitudes after: truth on the same frames", after_tracker=with_true_poses(cap, after_idx))
    all_after = free_flight_indices(cap, start, end, all_frames=True)
    row(f"attitudes after: truth on every frame {start:.1f}-{end:.1f} s", after_tracker=with_true_poses(cap, all_after),
        after_indices=all_after)
    early = free_flight_indices(cap, contact_end + 0.2, end, all_frames=True)
    row(f"attitudes after: truth on every frame from the true contact end + 0.2 s ({contact_end + 0.2:.1f}-{end:.1f} s)",
        after_tracker=with_true_poses(cap, early), after_indices=early)
    early_registered = free_flight_indices(cap, contact_end + 0.2, end)
    row(f"registered frames from the true contact end + 0.2 s ({len(early_registered)} frames, no truth)",
        after_indices=early_registered)
    before_idx = cap["fits"][0]["indices"]
    row("attitudes before: truth", before_tracker=with_true_poses(cap, before_idx))
    row("CoM in B: truth", com_body=true_com_body(cap))
    row("attitudes before and after (same frames) and CoM: truth", before_tracker=with_true_poses(cap, before_idx),
        after_tracker=with_true_poses(cap, after_idx), com_body=true_com_body(cap))
    row("all of it truth (attitudes, CoM, net)", before_tracker=with_true_poses(cap, before_idx),
        after_tracker=with_true_poses(cap, after_idx), com_body=true_com_body(cap), net=(positions, velocities))
    print("| substitution | C error (%) | stated 1-sigma of C (%) | mass error (%) |")
    print("|---|---|---|---|")
    for name, error, sig, m in rows:
        print(f"| {name} | {error:+.2f} | {sig:.2f} | {m:+.3f} |")

    # the balance's terms, one at a time from the truth
    truth = true_terms(cap, before, after, origin)
    est = estimated_terms(before, after, origin, others_before, others)
    mass_est = step["mass"].value
    covariances = stage_covariances(before, after, origin, step, others)
    c_base, misfit = c_from_terms(est, others_before[1], mass_est, covariances)
    print(f"\nterms (same frames and origin as the stage); C from the terms {100 * (c_base - c_true) / c_true:+.2f} %, "
          f"misfit {misfit:.1f} N m s")
    print("| term replaced by its truth | estimate | truth | difference | C error then (%) |")
    print("|---|---|---|---|---|")
    for key, unit in (("h0", "rad/s"), ("h1", "rad/s"), ("orbital0", "m^2/s"), ("orbital1", "m^2/s"),
                      ("others_after_angular", "N m s")):
        terms = dict(est)
        terms[key] = truth[key]
        c_sub, _ = c_from_terms(terms, others_before[1], mass_est, covariances)
        diff = est[key] - truth[key]
        print(f"| {key} | {_vec(est[key])} | {_vec(truth[key])} | {_vec(diff)} ({np.linalg.norm(diff):.3g} {unit}) | "
              f"{100 * (c_sub - c_true) / c_true:+.2f} |")
    c_sub, _ = c_from_terms(est, others_before[1], truth["mass"], covariances)
    print(f"| mass | {mass_est:.2f} | {truth['mass']:.2f} | {mass_est - truth['mass']:+.2f} kg | {100 * (c_sub - c_true) / c_true:+.2f} |")
    all_true = dict(truth)
    c_all, misfit_all = c_from_terms(all_true, others_before[1], truth["mass"], covariances)
    print(f"| every term | | | | {100 * (c_all - c_true) / c_true:+.2f} (misfit {misfit_all:.1f} N m s) |")
    dh = truth["h1"] - truth["h0"]
    print(f"\ntrue spin change per C |h1 - h0| = {np.linalg.norm(dh):.4f} rad/s (C dh = {c_true * np.linalg.norm(dh):.1f} N m s); "
          f"true h1 spread over the frames {_vec(truth['h1_spread'])} rad/s; "
          f"h0, h1 1-sigma (stated): {_vec(np.sqrt(np.diag(before.spin_per_c_cov)))}, {_vec(np.sqrt(np.diag(after.spin_per_c_cov)))}")
    errors = np.array([true_body_to_world_com_error(cap, k) for k in after_idx])
    unit = after.line.velocity_world / np.linalg.norm(after.line.velocity_world)
    across = errors - np.outer(errors @ unit, unit)
    print(f"per frame after the collision, the registered pose's CoM (true CoM in B) off the truth: across the "
          f"flight direction {1e3 * np.sqrt(np.mean(np.sum(across**2, axis=1))):.1f} mm rms, mean "
          f"{_vec(1e3 * across.mean(axis=0))} mm; along it {1e3 * np.sqrt(np.mean((errors @ unit) ** 2)):.1f} mm rms")
    print(f"after fit: {len(after.times)} frames {after.times[0]:.1f}-{after.times[-1]:.1f} s, "
          f"{after.attitude_residual_deg:.2f} deg rms, correlation time {after.fit.correlation_time_:.1f} frames; "
          f"true contact end {contact_end:.2f} s")
    return cap


def contact_end_time(cap) -> float:
    """Last time (s) the net pushes on the debris (body 0's net contact force in the record), from the truth."""
    series = cap["series"]
    force = np.linalg.norm(series["contact_force_lvlh"][:, 0], axis=1)
    touching = np.flatnonzero(force > 0)
    return float(series["time"][touching[-1]]) if len(touching) else float("nan")


def _vec(v):
    return "[" + ", ".join(f"{x:+.4g}" for x in np.ravel(v)) + "]"


def unweighted(direction, target, cov_direction, cov_target, name, unit):
    """The balance's solution before 2026-11-27: ordinary least squares over the three components, its
    variance propagated to first order (for the "before" column of the substitution table)."""
    d, b = np.asarray(direction, float), np.asarray(target, float)
    norm2 = float(d @ d)
    x = float(d @ b) / norm2
    g_b, g_d = d / norm2, (b - 2.0 * x * d) / norm2
    variance = g_b @ np.asarray(cov_target) @ g_b + g_d @ np.asarray(cov_direction) @ g_d
    return x, float(np.sqrt(max(variance, 0.0))), float(np.linalg.norm(b - x * d)), float("nan")


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("captures", nargs="+")
    parser.add_argument("--unweighted", action="store_true",
                        help="solve the balances by ordinary least squares, as the stage did before 2026-11-27")
    args = parser.parse_args()
    if args.unweighted:
        momentum._scalar_least_squares = unweighted
    np.set_printoptions(precision=4, suppress=True)
    for path in args.captures:
        report(path)
    sys.stdout.flush()


if __name__ == "__main__":
    main()
