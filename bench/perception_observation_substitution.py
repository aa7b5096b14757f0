"""Which of the observation's fitted quantities limits the smallest principal moment C of the momentum
step? Substitution experiments on a captured perception run (bench/perception_capture.py), beside those of
bench/perception_substitution.py (whose replay they use):

    python bench/perception_observation_substitution.py runs/captures/none_obs20_seed2.pkl [...]

* **the observation's registered poses, in parts**: the true rotations with the registered CoM track; the true
  poses turned by the registered rotation errors, all of them, their constant part in B (a turn of the map
  frame, which the torque-free fit takes into its axes and which leaves h0 alone), their constant part in the
  world (seen from the sensor) and the rest;
* **the observation fit's quantities** at the collision time t = 0, h0 = R_B->W T diag(J) T^T omega_B: the
  principal axes T, the ratios J, the rate's magnitude and direction in B, the attitude (the rotation phase),
  one at a time (the after fit redone when T or J change, since it takes them as known); and the observation
  fit redone with T and J held at the truth.

Printed beside them: the axes' error against their stated 1-sigma, the correlation time of the registered
errors against that of the fit's residuals (which scales the fit's covariance), C's 1-sigma from the
observation fit's covariance through h0 alone (as the stage counts it) and through h0 and the after fit, a
delete-a-block jackknife of the observation fit (the covariance of h0 and of the axes from refits without
each 2 s block), and the after stretch's own fit with the ratios and axes free (could it help fix the axes?).
The truth is read from the collision run's record; the estimators never see it.
"""
from __future__ import annotations

import argparse
import copy
import dataclasses
import sys
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from perception.euler_poinsot import TorqueFreeFit
from perception.free_flight import fit_free_motion
from perception.momentum import point_masses_momentum, rigid_body_momentum
from perception.momentum_balance import momentum_step
from perception.motion import attitude_sqrt_information, integrated_autocorrelation_time, isotropic_attitude_weights

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench script, also when imported

from perception_substitution import (Tracker, _vec, load, others_after, replay, true_body_to_world, true_c,  # noqa: E402
                                     true_com_body, true_terms, with_true_poses)


def slow_error_share(errors, frame_interval, rate):
    """Share of each component's variance (3,) (-) of per-frame errors (k, 3) below half the tumble
    frequency |omega| / (4 pi) (Hz), and each component's strongest frequency (3,) (Hz): an error that
    follows the view comes back with the tumble, one below it is a drift the fit can take for motion."""
    errors = errors - errors.mean(axis=0)
    frequencies = np.fft.rfftfreq(len(errors), frame_interval)
    power = np.abs(np.fft.rfft(errors, axis=0)) ** 2
    slow = frequencies < np.linalg.norm(rate) / (4.0 * np.pi)
    return power[slow].sum(axis=0) / power.sum(axis=0), frequencies[np.argmax(power[1:], axis=0) + 1]


#: Contiguous blocks of the delete-a-block jackknife of the observation fit (2 s each over 20 s of
#: observation, longer than the registration errors' correlation times measured here, 0.4-1.9 s).
JACKKNIFE_BLOCKS = 10


def registered_attitude_errors(cap, indices) -> np.ndarray:
    """Each frame's registered attitude against the truth, e = rotvec(R_true^T R_registered) (k, 3) (rad, frame B)."""
    return np.array([Rotation.from_matrix(true_body_to_world(cap, k)[:3, :3].T
                                          @ cap["alignments"][k].body_to_world[:3, :3]).as_rotvec() for k in indices])


def with_attitude_errors(cap, indices, errors_body) -> Tracker:
    """The alignments with frames ``indices`` set to the true pose turned by ``errors_body`` (k, 3) (rad,
    frame B): rotation R_true R(e), the true CoM kept where it is (translation true_com - R com_B)."""
    alignments = [copy.copy(a) for a in cap["alignments"]]
    com_body = true_com_body(cap)
    for k, error in zip(indices, errors_body):
        pose = np.eye(4)
        pose[:3, :3] = true_body_to_world(cap, k)[:3, :3] @ Rotation.from_rotvec(error).as_matrix()
        pose[:3, 3] = np.asarray(cap["frames"]["true_com_world"][k]) - pose[:3, :3] @ com_body
        alignments[k].world_to_body = np.linalg.inv(pose)
    return Tracker(alignments)


def with_registered_com_track(cap, indices) -> Tracker:
    """The alignments with frames ``indices`` given the true rotation and a translation that puts the true
    CoM in B where the registered pose puts it: the registered CoM track with the attitude errors removed."""
    alignments = [copy.copy(a) for a in cap["alignments"]]
    com_body = true_com_body(cap)
    for k in indices:
        registered = cap["alignments"][k].body_to_world
        pose = np.eye(4)
        pose[:3, :3] = true_body_to_world(cap, k)[:3, :3]
        pose[:3, 3] = registered[:3, :3] @ com_body + registered[:3, 3] - pose[:3, :3] @ com_body
        alignments[k].world_to_body = np.linalg.inv(pose)
    return Tracker(alignments)


def attitude_error_parts(cap, indices) -> dict:
    """The observation's registered attitude errors (frame B), whole and split into a constant part in B (a
    turn of the map's frame, which a torque-free fit takes into its axes) or in the world (a turn of the
    sensor's view, which turns h0) and the rest; each as per-frame B-frame errors (k, 3) (rad)."""
    errors_body = registered_attitude_errors(cap, indices)
    true_rotations = [true_body_to_world(cap, k)[:3, :3] for k in indices]
    errors_world = np.array([r @ e for r, e in zip(true_rotations, errors_body)])
    mean_body, mean_world = errors_body.mean(axis=0), errors_world.mean(axis=0)
    world_mean_in_body = np.array([r.T @ mean_world for r in true_rotations])
    return {"all of them": errors_body,
            "their mean in B only (a constant turn of the map frame)": np.tile(mean_body, (len(indices), 1)),
            "all minus their mean in B": errors_body - mean_body,
            "their mean in the world only (a constant turn seen from the sensor)": world_mean_in_body,
            "all minus their mean in the world": errors_body - world_mean_in_body}


# -- the observation fit's quantities, one at a time ------------------------------------------------------
# h0 = R_B->W(t_c) diag-in-B(J) omega_B(t_c), with diag-in-B(J) = T diag(J1, J2, 1) T^T (T: principal -> B):
# the spin per C of the observation's torque-free fit, written at the collision time t_c = 0 through the four
# quantities the fit estimates: the attitude there (the rotation phase), the principal axes T, the moment
# ratios J and the body rate (magnitude and direction). Each is replaced by its truth alone; the after fit is
# redone when the axes or ratios change (it takes them from the observation fit).

COLLISION_TIME = 0.0   # (s) the collision run starts at t = 0 on the frames' clock (state_at_zero)


@dataclasses.dataclass
class SpinState:
    """The spin of the debris at the collision time, in the tracker's body frame B."""

    body_to_world: np.ndarray        # (3, 3) attitude B -> world (LVLH) at t_c
    principal_to_body: np.ndarray    # (3, 3) principal -> B, columns the principal axes in B
    moments: np.ndarray              # (3,) normalized principal moments [A/C, B/C, 1] (-)
    omega_body: np.ndarray           # (3,) angular rate (rad/s), frame B

    def spin_per_c(self) -> np.ndarray:
        """h = R_B->W T diag(J) T^T omega_B (rad/s, world), the spin angular momentum per C."""
        inertia_body = self.principal_to_body @ np.diag(self.moments) @ self.principal_to_body.T
        return self.body_to_world @ inertia_body @ self.omega_body


def fitted_spin_state(fit) -> SpinState:
    """The observation fit's spin state at the collision time (its motion propagated from its first frame)."""
    body_to_world = fit.predict_body_to_world([fit.time0_, COLLISION_TIME])[-1].as_matrix()
    return SpinState(body_to_world, fit.principal_to_body_, fit.moments_, fit.rate_body_at(COLLISION_TIME))


def true_spin_state(cap, estimate: SpinState) -> SpinState:
    """The simulated truth at the collision time in frame B, its principal axes ordered and signed as the
    estimate's (each estimated axis paired with the true one it is nearest to)."""
    _, target_to_world, _, omega_target = cap["state_at_zero"]
    target_to_body = cap["target_to_body"][:3, :3]
    inertia_body = target_to_body @ cap["truth"]["inertia_target"] @ target_to_body.T
    eigenvalues, axes_body = np.linalg.eigh(inertia_body)
    pairing = np.argmax(np.abs(estimate.principal_to_body.T @ axes_body), axis=1)
    axes_body, eigenvalues = axes_body[:, pairing], eigenvalues[pairing]
    axes_body = axes_body * np.sign(np.sum(axes_body * estimate.principal_to_body, axis=0))
    return SpinState(target_to_world @ target_to_body.T, axes_body, eigenvalues / true_c(cap),
                     target_to_body @ omega_target)


def _angle_deg(a, b) -> float:
    return float(np.degrees(np.arccos(np.clip(a @ b / np.linalg.norm(a) / np.linalg.norm(b), -1.0, 1.0))))


def _rotation_angle_deg(a, b) -> float:
    return float(np.degrees(np.linalg.norm(Rotation.from_matrix(a.T @ b).as_rotvec())))


def spin_substitutions(estimate: SpinState, truth: SpinState) -> dict:
    """Spin states with one fitted quantity (or a named pair) replaced by its truth."""
    rate_magnitude = estimate.omega_body * np.linalg.norm(truth.omega_body) / np.linalg.norm(estimate.omega_body)
    rate_direction = truth.omega_body * np.linalg.norm(estimate.omega_body) / np.linalg.norm(truth.omega_body)
    return {
        "principal axes T (B -> principal)": dataclasses.replace(estimate, principal_to_body=truth.principal_to_body),
        "moment ratios J1, J2": dataclasses.replace(estimate, moments=truth.moments),
        "axes and ratios (the normalized inertia in B)": dataclasses.replace(
            estimate, principal_to_body=truth.principal_to_body, moments=truth.moments),
        "rate magnitude |omega_B|": dataclasses.replace(estimate, omega_body=rate_magnitude),
        "rate direction in B": dataclasses.replace(estimate, omega_body=rate_direction),
        "rate omega_B (magnitude and direction)": dataclasses.replace(estimate, omega_body=truth.omega_body),
        "rotation phase at the collision (attitude B -> W at t = 0)": dataclasses.replace(
            estimate, body_to_world=truth.body_to_world),
        "phase and rate": dataclasses.replace(estimate, body_to_world=truth.body_to_world,
                                              omega_body=truth.omega_body),
        "all four (h0 from the truth)": truth,
    }


def replay_with_spin_before(cap, before, h0, shape=None):
    """The momentum step with the observation fit's spin per C replaced by ``h0`` (rad/s, world) and, when
    ``shape`` = (moments, principal_to_body) is given, the after fit redone with that normalized inertia;
    returns (C, its 1-sigma, h1)."""
    times = np.asarray(cap["frames"]["time"])
    before_sub = dataclasses.replace(before, spin_per_c=np.asarray(h0, float))
    after = fit_free_motion(Tracker(cap["alignments"]), cap["fits"][-1]["indices"], times, before.line.com_body,
                            *(shape or (before.fit.moments_, before.fit.principal_to_body_)))
    origin = before.line.position_world([0.0])[0]
    others = others_after(cap, after.times, origin)
    parts, ch = cap["assembly"], cap["assembly"]["chaser"]
    p_c, l_c = rigid_body_momentum(ch["mass"], ch["inertia_body"], ch["com_lvlh"], ch["velocity_lvlh"],
                                   ch["body_to_lvlh"], ch["omega_body"], origin)
    p_n, l_n = point_masses_momentum(parts["net_masses"], parts["net_positions"], parts["net_velocity"], origin)
    step = momentum_step(before_sub, after, (p_c + p_n, l_c + l_n), others, origin)
    return step["c"].value, step["c"].sigma, after.spin_per_c


def refit_observation_with_shape(cap, moments, principal_to_body):
    """The observation's torque-free fit redone with the normalized inertia (ratios and axes in B) held at
    the values given: the attitude and rate at its first frame re-fitted to the same registered frames."""
    times = np.asarray(cap["frames"]["time"])
    return fit_free_motion(Tracker(cap["alignments"]), cap["fits"][0]["indices"], times, None, moments,
                           principal_to_body)


def axes_error_principal(estimate: SpinState, truth: SpinState, fit):
    """The principal axes' error as a rotation (rad, principal frame: about axis 1, 2, 3) and its stated
    1-sigma (rad) from the fit's covariance (the T -> B rotation vector, parameters 8-10, B frame)."""
    t2b = estimate.principal_to_body
    error_body = Rotation.from_matrix(truth.principal_to_body @ t2b.T).as_rotvec()
    cov_principal = t2b.T @ fit.covariance_[8:11, 8:11] @ t2b
    return t2b.T @ error_body, np.sqrt(np.diag(cov_principal)), float(
        error_body @ np.linalg.solve(fit.covariance_[8:11, 8:11], error_body))


def c_sigma_from_observation_parameters(cap, before, c0):
    """1-sigma of C (kg m^2) from the observation fit's parameter covariance, first order (forward
    differences of one parameter 1-sigma), two ways: through h0 only (what the stage's covariance of C
    holds of the observation) and through h0 and the after fit, which takes the observation's ratios and
    axes as known (their uncertainty reaches h1 too, and h0 and h1 are correlated through it)."""
    fit = before.fit
    p0, sigmas = fit._p.copy(), np.sqrt(np.diag(fit.covariance_))
    g_h0, g_both = np.zeros(p0.size), np.zeros(p0.size)
    for i in range(p0.size):
        p = p0.copy()
        p[i] += sigmas[i]
        t2w, omega, moments, t2b = fit._unpack(p)
        h0 = t2w.as_matrix() @ (moments * omega)
        g_h0[i] = (replay_with_spin_before(cap, before, h0)[0] - c0) / sigmas[i]
        g_both[i] = g_h0[i] if i < 6 else (replay_with_spin_before(cap, before, h0, (moments, t2b))[0] - c0) / sigmas[i]
    cov = fit.covariance_
    return float(np.sqrt(g_h0 @ cov @ g_h0)), float(np.sqrt(g_both @ cov @ g_both))


def report_observation_quantities(cap, before, after, blocks=JACKKNIFE_BLOCKS):
    """The table: each of the observation fit's quantities replaced by its truth -> C error, h0, h1."""
    c_true = true_c(cap)
    estimate = fitted_spin_state(before.fit)
    truth = true_spin_state(cap, estimate)
    h0_true = truth.spin_per_c()
    h1_true = true_terms(cap, before, after, before.line.position_world([0.0])[0])["h1"]
    sigma0 = np.sqrt(np.diag(before.spin_per_c_cov))
    axes_error, axes_sigma, axes_chi2 = axes_error_principal(estimate, truth, before.fit)
    ratio_sigma = before.fit.moments_std_
    print(f"\nobservation fit at the collision time against the truth: principal axes turned by "
          f"{_vec(np.degrees(axes_error))} deg about principal axes 1, 2, 3 (stated 1-sigma {_vec(np.degrees(axes_sigma))} deg, "
          f"chi2 {axes_chi2:.1f} for 3 dof); ratios {_vec(estimate.moments[:2])} vs {_vec(truth.moments[:2])} "
          f"(1-sigma {_vec(ratio_sigma)}); |omega_B| {np.linalg.norm(estimate.omega_body):.5f} vs "
          f"{np.linalg.norm(truth.omega_body):.5f} rad/s "
          f"({100 * (np.linalg.norm(estimate.omega_body) / np.linalg.norm(truth.omega_body) - 1):+.3f} %), "
          f"direction off {_angle_deg(estimate.omega_body, truth.omega_body):.3f} deg; attitude at t = 0 off "
          f"{_rotation_angle_deg(estimate.body_to_world, truth.body_to_world):.3f} deg; |h0| "
          f"{100 * (np.linalg.norm(before.spin_per_c) / np.linalg.norm(h0_true) - 1):+.3f} %, its direction off "
          f"{_angle_deg(before.spin_per_c, h0_true):.3f} deg; stated 1-sigma of h0 {_vec(sigma0)} rad/s")
    print("| observation quantity replaced by its truth | C error (%) | stated 1-sigma of C (%) | h0 - true h0 (rad/s) "
          "| (h0 - true)/sigma | h1 - true h1 (rad/s) |")
    print("|---|---|---|---|---|---|")
    rows = {"none (the fit's own state at t = 0)": estimate, **spin_substitutions(estimate, truth)}
    for name, spin in rows.items():
        refit = not (np.array_equal(spin.moments, estimate.moments)
                     and np.array_equal(spin.principal_to_body, estimate.principal_to_body))
        h0 = spin.spin_per_c()
        c, sigma, h1 = replay_with_spin_before(cap, before, h0, (spin.moments, spin.principal_to_body) if refit else None)
        _observation_row(name + (" (after fit redone)" if refit else ""), c, sigma, c_true, h0 - h0_true, sigma0,
                         h1 - h1_true)
    refit = refit_observation_with_shape(cap, truth.moments, truth.principal_to_body)
    c, sigma, h1 = replay_with_spin_before(cap, before, refit.spin_per_c, (truth.moments, truth.principal_to_body))
    _observation_row("axes and ratios held at the truth, observation (phase, rate) and after fits redone", c, sigma,
                     c_true, refit.spin_per_c - h0_true, sigma0, h1 - h1_true)
    print_error_correlation(cap, before)
    print_jackknife(cap, before, estimate, truth, blocks)
    print_after_fit_free_shape(cap, before, after, estimate, truth)
    c0 = replay_with_spin_before(cap, before, before.spin_per_c)[0]
    sigma_h0, sigma_both = c_sigma_from_observation_parameters(cap, before, c0)
    print(f"1-sigma of C from the observation fit's covariance, first order: through h0 only {100 * sigma_h0 / c0:.2f} %, "
          f"through h0 and the after fit (its ratios and axes) {100 * sigma_both / c0:.2f} %")


def print_error_correlation(cap, before):
    """The observation's registered attitude errors against the truth beside the fit's residuals: their
    integrated autocorrelation times (frames; the fit's covariance is scaled by the residuals') and the
    fitted motion's own error (deg, frame B), which is the part of the registration error the fit took in."""
    times = np.asarray(cap["frames"]["time"])
    used = [int(np.argmin(np.abs(times - t))) for t in before.times]
    errors = registered_attitude_errors(cap, used)
    fitted = before.fit.predict_body_to_world(before.times)
    true_rotations = Rotation.from_matrix([true_body_to_world(cap, k)[:3, :3] for k in used])
    fit_error = (true_rotations.inv() * fitted).as_rotvec()
    print(f"observation: {len(used)} frames; registered attitude errors (frame B, their mean removed) rms "
          f"{_vec(np.degrees(errors.std(axis=0)))} deg, correlation time {integrated_autocorrelation_time(errors):.1f} "
          f"frames; the fit's residuals' correlation time {before.fit.correlation_time_:.1f} frames; the fitted motion "
          f"against the truth: mean {_vec(np.degrees(fit_error.mean(axis=0)))} deg, rms about the mean "
          f"{_vec(np.degrees(fit_error.std(axis=0)))} deg")
    rate = before.fit.rate_body_at(before.times[0])
    share, peak = slow_error_share(errors, float(np.median(np.diff(before.times))), rate)
    print(f"  their variance below half the tumble frequency ({np.linalg.norm(rate) / (4 * np.pi):.3f} Hz), per B axis: "
          f"{_vec(share)}; strongest frequency {_vec(peak)} Hz")


def jackknife_observation_fit(cap, before, blocks=JACKKNIFE_BLOCKS):
    """Delete-a-block jackknife of the observation's torque-free fit: refitted without each of ``blocks``
    contiguous blocks of its frames (from the full fit's state), the covariance (G - 1)/G sum (x_i - x_bar)^2
    of h0 (rad/s, world) and of the axes' turn (rad, principal frame) -- a covariance that sees errors
    correlated up to a block's length, where the fit's own is scaled by its residuals' correlation time."""
    times = np.asarray(cap["frames"]["time"])
    used = np.array([int(np.argmin(np.abs(times - t))) for t in before.times])
    attitudes = Rotation.from_matrix([cap["alignments"][k].body_to_world[:3, :3] for k in used])
    weights = isotropic_attitude_weights(attitude_sqrt_information([cap["alignments"][k].information for k in used]))
    t2b = before.fit.principal_to_body_
    spins, turns = [], []
    for block in np.array_split(np.arange(len(used)), blocks):
        keep = np.setdiff1d(np.arange(len(used)), block)
        fit = TorqueFreeFit().fit(times[used][keep], attitudes[keep], weights[keep],
                                  before.fit.rate_body_at(times[used][keep][0]), before.fit.moments_, t2b)
        spins.append(fit.spin_momentum_per_c()[0])
        turns.append(t2b.T @ Rotation.from_matrix(fit.principal_to_body_ @ t2b.T).as_rotvec())
    return (blocks - 1) * np.cov(np.array(spins).T, bias=True), (blocks - 1) * np.cov(np.array(turns).T, bias=True)


def print_jackknife(cap, before, estimate, truth, blocks=JACKKNIFE_BLOCKS):
    """h0's and the axes' errors against the fit's stated 1-sigma and the jackknife's (chi2 over 3 dof)."""
    cov_h0, cov_axes = jackknife_observation_fit(cap, before, blocks)
    dh0 = before.spin_per_c - truth.spin_per_c()
    axes_error, axes_sigma, _ = axes_error_principal(estimate, truth, before.fit)
    print(f"jackknife of the observation fit ({blocks} blocks): h0 - true {_vec(dh0)} rad/s, 1-sigma stated "
          f"{_vec(np.sqrt(np.diag(before.spin_per_c_cov)))}, jackknife {_vec(np.sqrt(np.diag(cov_h0)))}, chi2 stated "
          f"{dh0 @ np.linalg.solve(before.spin_per_c_cov, dh0):.1f}, jackknife {dh0 @ np.linalg.solve(cov_h0, dh0):.1f}; "
          f"axes' turn {_vec(np.degrees(axes_error))} deg, 1-sigma stated {_vec(np.degrees(axes_sigma))}, jackknife "
          f"{_vec(np.degrees(np.sqrt(np.diag(cov_axes))))} deg")


def print_after_fit_free_shape(cap, before, after, estimate, truth):
    """Could the after-collision stretch help fix the axes? Its torque-free fit with the ratios and axes free
    (started from the observation's): the axes' turn against the truth and its stated 1-sigma (deg)."""
    times = np.asarray(cap["frames"]["time"])
    used = np.array([int(np.argmin(np.abs(times - t))) for t in after.times])
    attitudes = Rotation.from_matrix([cap["alignments"][k].body_to_world[:3, :3] for k in used])
    weights = isotropic_attitude_weights(attitude_sqrt_information([cap["alignments"][k].information for k in used]))
    t2b = estimate.principal_to_body
    fit = TorqueFreeFit().fit(times[used], attitudes, weights, after.fit.rate_body_at(times[used][0]),
                              before.fit.moments_, t2b)
    turn = t2b.T @ Rotation.from_matrix(truth.principal_to_body @ fit.principal_to_body_.T).as_rotvec()
    sigma = np.sqrt(np.diag(t2b.T @ fit.covariance_[8:11, 8:11] @ t2b))
    print(f"after-collision stretch alone, ratios and axes free ({len(used)} frames): axes turned by "
          f"{_vec(np.degrees(turn))} deg from the truth, stated 1-sigma {_vec(np.degrees(sigma))} deg, ratios "
          f"{_vec(fit.moments_[:2])} (true {_vec(truth.moments[:2])})")


def _observation_row(name, c, sigma, c_true, dh0, sigma0, dh1):
    print(f"| {name} | {100 * (c - c_true) / c_true:+.2f} | {100 * sigma / c:.2f} | {_vec(dh0)} | {_vec(dh0 / sigma0)} | "
          f"{_vec(dh1)} |")


def report_pose_parts(cap):
    """Table (a): the observation's registered poses replaced by the truth in parts -> C error, its 1-sigma,
    the mass error."""
    c_true, mass_true = true_c(cap), cap["truth"]["mass"]
    before_idx = cap["fits"][0]["indices"]
    rows = {"as registered (the stage's replay)": None,
            "truth": with_true_poses(cap, before_idx),
            "true rotations, the registered CoM track (true CoM in B placed by the registered pose)":
                with_registered_com_track(cap, before_idx)}
    for name, errors in attitude_error_parts(cap, before_idx).items():
        rows[f"true poses turned by the registered rotation errors, {name}"] = with_attitude_errors(
            cap, before_idx, errors)
    print("| observation poses | C error (%) | stated 1-sigma of C (%) | mass error (%) |")
    print("|---|---|---|---|")
    for name, tracker in rows.items():
        c, sigma, mass, *_ = replay(cap, before_tracker=tracker)
        print(f"| {name} | {100 * (c - c_true) / c_true:+.2f} | {100 * sigma / c:.2f} | "
              f"{100 * (mass - mass_true) / mass_true:+.3f} |")


def report(path, blocks=JACKKNIFE_BLOCKS):
    cap = load(path)
    answer = cap["answer"]
    print(f"\n== {path}: seed {answer['bench_seed']}, stage C error "
          f"{answer['principal_moments_error_percent'][2]:+.2f} %, true C {true_c(cap):.3f} kg m^2")
    report_pose_parts(cap)
    _, _, _, before, after, *_ = replay(cap)
    report_observation_quantities(cap, before, after, blocks)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("captures", nargs="+")
    parser.add_argument("--blocks", type=int, default=JACKKNIFE_BLOCKS,
                        help="contiguous blocks of the observation fit's jackknife")
    args = parser.parse_args()
    np.set_printoptions(precision=4, suppress=True)
    for path in args.captures:
        report(path, args.blocks)
    sys.stdout.flush()


if __name__ == "__main__":
    main()
