"""Case schema of the towing stages (``riskassess tow``, ``riskassess identify``).

Boonrath, Singh & Botta 2024: Table 1 (system parameters), Table 2 (initial conditions), Table 3
(initial debris spin rates), Sec. 4.1 (thrust and attitude-control settings), eq. (24) (bounds of
the identification). Every quantity is SI except where a key says otherwise (``_deg_s``); the
inertial frame is Earth-centred; quaternions are scalar-first, body->inertial.
Load with ``riskassess.cases.impact.load_model(path, TowingCase)``.
"""
from __future__ import annotations

import math

from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator

from multibody.control.lateral import TARGETS as LATERAL_TARGETS
from multibody.control.thrust_laws import LAWS as THRUST_LAWS
from riskassess.cases.impact import NonNegative, Positive, Strict, Vector3
from riskassess.cases.inputs import KIND_NOTE, CaseName, Search, Text

Quaternion = Annotated[list[float], Field(min_length=4, max_length=4)]
PositiveVector3 = Annotated[list[Positive], Field(min_length=3, max_length=3)]
DecisionVector = Annotated[list[float], Field(min_length=4, max_length=4)]


class BodyState(Strict):
    position_inertial: Vector3 = Field(description="CoM position from the Earth's centre, inertial (m).")
    velocity_inertial: Vector3 = Field(description="CoM velocity, inertial (m/s).")
    attitude_quaternion: Quaternion = Field(description="Body->inertial quaternion, scalar first (-); normalised on load.")

    @model_validator(mode="after")
    def _unit_quaternion(self):
        if abs(np.linalg.norm(self.attitude_quaternion) - 1.0) > 1e-3:
            raise ValueError(f"attitude_quaternion must have unit norm (within 1e-3). "
                             f"Got norm {np.linalg.norm(self.attitude_quaternion):.6g} instead")
        return self


class TowChaser(BodyState):
    mass: Positive = Field(description="m_C (kg), Table 1.")
    side_length: Positive = Field(description="L_C, cube side (m), Table 1 (plots only).")
    principal_inertia: PositiveVector3 = Field(description="Diagonal of J_C, body frame (kg m^2), Table 1.")
    tether_attachment_body: Vector3 = Field(description="r_A/C, main-tether attachment, chaser frame (m), Table 1.")
    angular_velocity_body: Vector3 = Field([0.0, 0.0, 0.0], description="Initial angular velocity, chaser frame (rad/s).")


class TowDebris(BodyState):
    nominal_mass: Positive = Field(description="m_D,nom (kg), Table 1; the lower-order debris carries "
                                                "m_D,nom + m_net (1 - connection_mass_fraction).")
    length: Positive = Field(description="L_D (m), Table 1 (plots only).")
    diameter: Positive = Field(description="d_D (m), Table 1 (plots only).")
    principal_inertia: PositiveVector3 = Field(description="Diagonal of J_D, body frame (kg m^2), Table 1.")
    spin_axis_body: Vector3 = Field(description="Direction of the initial angular velocity, debris frame (-), Table 2.")
    spin_rate_deg_s: NonNegative = Field(description="Initial spin rate of the 'tow' run (deg/s).")


class MainTether(Strict):
    stiffness: Positive = Field(description="k_MT (N/m), Table 1.")
    damping: NonNegative = Field(description="c_MT (N s/m), Table 1.")
    natural_length: Positive = Field(description="l_MT,0 (m), Table 1.")


class SubTethers(Strict):
    attachment_points_body: Annotated[list[Vector3], Field(min_length=1, max_length=16)] = Field(
        description="r_i/D, sub-tether attachments, debris frame (m), Table 1.")
    stiffness: Positive = Field(description="k_ST of each sub-tether (N/m); s1 = log10 k_ST.")
    natural_length: Positive = Field(description="l_ST,0 (m); s2.")
    damping: NonNegative = Field(description="c_ST (N s/m); s3 = log10 c_ST.")
    connection_mass_fraction: Annotated[float, Field(gt=0, le=1)] = Field(
        description="m_P / m_net (-); s4. The rest of the net mass goes to the debris.")
    connection_point_start_inertial: Vector3 | None = Field(
        None, description="Initial position of P (m, inertial), moving with the debris; default: on the line from the "
                          "debris CoM to the main tether's chaser end where the farthest sub-tether is at its natural "
                          "length. The full-net identification sets it to the net's central node at 25 s (Sec. 4.1).")


class Thrust(Strict):
    kind: Literal[tuple(THRUST_LAWS)] = Field(   # one plug-in module each, multibody/control/thrust_laws
        "ramp", description="'ramp': open loop against the orbital velocity (paper after eq. 2); 'mrac1'/'mrac2': "
                            "main-tether elongation control along the chaser's body z (MRAC paper eqs. 9-21).")
    t_on: NonNegative = Field(description="Thruster on (s), Sec. 4.1.")
    t_slope: Positive = Field(description="Ramp time from 0 to max_force (s), Sec. 4.1.")
    max_force: Positive = Field(description="F_t,max, also the MRAC saturation u_max (N), Sec. 4.1.")


class Mrac(Strict):
    desired_elongation: Positive = Field(description="z_d (m).")
    k_p: Positive = Field(description="Reference-model proportional gain K_P (N/m).")
    k_d: Positive = Field(description="Reference-model derivative gain K_D (N s/m).")
    lambda0: Positive = Field(description="MRAC-1 lambda_0 (1/s).")
    k_s: NonNegative = Field(description="MRAC-1 sliding gain k_s (N s/m).")
    gamma: NonNegative = Field(description="MRAC-1 adaptation rate gamma (-).")
    xi_h: NonNegative = Field(description="MRAC-1 damping xi_h of the h adaptation (-).")
    xi_a: Annotated[list[NonNegative], Field(min_length=2, max_length=2)] = Field(description="MRAC-1 diagonal of Xi_a (-).")
    gamma_z: Annotated[list[NonNegative], Field(min_length=2, max_length=2)] = Field(description="MRAC-2 diagonal of Gamma_z (-).")
    gamma_r: NonNegative = Field(description="MRAC-2 gamma_r (-).")
    gamma_theta: Annotated[list[NonNegative], Field(min_length=2, max_length=2)] = Field(description="MRAC-2 diagonal of Gamma_theta (-).")
    xi_2: NonNegative = Field(description="MRAC-2 e-modification gain xi_2 (-).")
    q: Annotated[list[Positive], Field(min_length=2, max_length=2)] = Field(description="MRAC-2 diagonal of Q in eq. (21a) (-).")
    range_damping: NonNegative = Field(
        0.0, description="Range-rate damping c_R (N s/m) both laws add to their command: -c_R dr/dt, r the chaser-debris "
                         "CoM distance from relative navigation; it damps the chaser moving against the netted debris "
                         "and is zero in steady towing. 0: the paper's laws (docs/towing.md, MRAC on the full net).")
    rate_filter_time: NonNegative = Field(
        0.0, description="Time constant tau of the elongation-rate estimate both laws use (s): the band-limited "
                         "difference quotient of the sampled elongation, corner 1/tau; 0: the plant's "
                         "instantaneous elongation rate (on the full-net plant that is the net node's vibration, "
                         "docs/towing.md). One decade above the reference model: 0.1 / sqrt((k_MT + K_P) / m_C).")
    min_thrust: float | None = Field(
        None, description="Lower bound u_min of the actuator's saturation, sat(u) of eq. (16) (N): the command is "
                          "clipped to [min_thrust, thrust.max_force] and the adaptation frozen outside it; must lie in "
                          "[-max_force, max_force). Default: -max_force (the paper's symmetric saturation). 0: a main "
                          "engine along the chaser's body z, which never pushes the chaser back towards the debris "
                          "(docs/towing.md, MRAC on the full net).")
    max_thrust: float | None = Field(
        None, description="Upper bound u_max of the actuator's saturation for the MRAC laws (N), at most "
                          "thrust.max_force (the default). With min_thrust it confines the command to a band around "
                          "the steady thrust (docs/towing.md, MRAC on the full net).")
    thrust_band: Annotated[float, Field(gt=0, le=1)] | None = Field(
        None, description="Actuator band of both laws as a fraction beta of the steady thrust F_ss = k z_d (k the "
                          "abstracted tether stiffness; with free_debris (1 + m_C/m_D) k_MT z_d): sat(u) of eq. (16) "
                          "clips to [(1 - beta) F_ss, (1 + beta) F_ss] (within +-thrust.max_force) and the adaptation "
                          "is frozen outside it. Not together with min_thrust / max_thrust. Default: none (the "
                          "paper's symmetric saturation). docs/towing.md, MRAC on the full net.")
    slack_elongation: NonNegative | None = Field(
        None, description="Slack hold (m): while the measured main-tether elongation is below it both laws command the "
                          "steady thrust k z_d (k the abstracted stiffness) and do not adapt; on the full net a slack "
                          "tether reads z ~ 0 whatever the distance (docs/towing.md, MRAC on the full net). Default: "
                          "none (the paper's laws throughout).")
    slack_hold_periods: NonNegative = Field(
        0.0, description="With slack_elongation: the slack hold lasts this many breathing periods (half a debris spin "
                         "period each: the net breathes at twice the spin) after the last sample below "
                         "slack_elongation, so the re-engagement snap is also met with the steady thrust; 0: only "
                         "while slack. docs/towing.md, MRAC on the full net.")
    breathing_notch: bool = Field(
        False, description="Both laws see the main-tether elongation through a notch at twice the debris spin rate "
                           "(the netted stage presents its outline twice a revolution, so the net breathes at 2 "
                           "omega_spin; the laws then neither chase nor adapt on that swing); the rate estimate is "
                           "then the difference quotient of the notched elongation (needs rate_filter_time > 0). The "
                           "spin rate is the tow's (debris.spin_rate_deg_s or the rate the run is made at, the GNC's "
                           "estimate) unless notch_frequency is given. docs/towing.md, MRAC on the full net.")
    notch_frequency: Positive | None = Field(
        None, description="Centre of the breathing notch (rad/s), a stated input instead of twice the tow's spin rate.")
    notch_quality: Positive = Field(
        4.0, description="Quality Q of the breathing notch (-): -3 dB width about omega_notch / Q, memory time "
                         "2 Q / omega_notch. 4: +-12.5 % about twice the spin rate, wide against the spin estimate's "
                         "error and the spin's change over a steady tow (< 1 %), narrow enough to leave the tow's "
                         "own bounce (~0.3 rad/s) mostly alone (docs/towing.md).")
    range_notch: bool = Field(
        False, description="The range damping acts on the range rate through a notch at the debris spin rate (the "
                           "GNC's estimate: debris.spin_rate_deg_s or the rate the run is made at): the stage's CoM, "
                           "0.217 m off its cylinder's middle, moves the bag's tow point once per turn, a forced "
                           "motion the chaser should follow rather than damp (damping it costs thrust at the spin "
                           "rate, which met the 200 N limit at 29.01 deg/s). Needs range_damping > 0. Measured: it does not "
                           "hold 29.01 deg/s and breaks 20.44 deg/s (docs/towing.md, MRAC: a range-rate notch at the "
                           "spin rate, and a thrust budget).")
    range_notch_quality: Positive = Field(
        3.0, description="Quality Q of the range-rate notch (-): -3 dB width about omega_spin / Q, memory time "
                         "2 Q / omega_spin. 3: +-17 % about the spin rate, wide against the spin's change over a "
                         "failing tow (29.01 -> 28.0 deg/s, 3.5 %) and the line's measured spread (0.503-0.511 rad/s "
                         "for omega 0.506), while twice the spin rate (the breathing the range damping was sized "
                         "for) passes with gain 1.01 (docs/towing.md).")
    tow_point_offset: NonNegative | None = Field(
        None, description="Once-per-turn thrust budget (m): the distance delta of the debris CoM from the middle of "
                          "the netted body (perception's CoM estimate; Zenit-2, Table 1: 0.217 m), which moves the "
                          "bag's tow point once per turn. With it the laws hold min(desired_elongation, (u_max - m_C "
                          "omega^2 delta) / k) (k the abstracted stiffness, omega the tow's spin rate): the steady "
                          "thrust leaves m_C omega^2 delta of headroom, the thrust the once-per-turn line asks for "
                          "near the chaser-bag resonance. Default: none (desired_elongation at every rate). Measured: the "
                          "line still grows with that headroom and both laws fail at 29.01 deg/s (docs/towing.md, MRAC: "
                          "a range-rate notch at the spin rate, and a thrust budget).")
    free_debris: bool = Field(
        False, description="Abstracted model (eq. 9) of the chaser relative to a free debris: tether terms scaled by "
                           "1 + m_C/m_D (two-body reduction along the tether); false: the paper's wall "
                           "(assumption iv, m_C << m_D).")
    settle_at_desired: bool = Field(
        False, description="Command the reference model (eq. 13) with z_d (k_MT + K_P) / K_P so that it settles at "
                          "desired_elongation; false: the paper's command z_d, with which it settles at "
                          "K_P z_d / (k_MT + K_P) (eq. 13 has no integral action).")


class Lateral(Strict):
    """Lateral station keeping of the chaser on the full-net plant (multibody/control/lateral.py; docs/towing.md,
    "A lateral station-keeping law"). Off by default: the runs are then bit-identical to those without it."""
    enabled: bool = Field(False, description="A thrust component across the main tether (side thrusters in the "
                                             "chaser's body x-y plane) holding the chaser on a line through the "
                                             "debris CoM. Full-net plant only: the lower-order model's chaser has no "
                                             "lateral thrust, and that model runs without it.")
    thrust_laws: Annotated[list[Literal[tuple(THRUST_LAWS)]], Field(min_length=1)] = Field(
        ["mrac1", "mrac2"], description="The thrust laws (thrust.kind) the lateral law acts with. Default the two "
                                        "elongation laws, the tows it was measured with (docs/towing.md); the ramp, "
                                        "the papers' open-loop thrust of the identification runs, keeps the papers' "
                                        "chaser (no side thrust), so its runs and their caches do not change.")
    target: Literal[tuple(LATERAL_TARGETS)] = Field(
        "momentum_axis", description="'momentum_axis' (default): the debris' angular-momentum axis (the tow "
                                     "point's once-per-turn circle across the tether; holds 29.01 deg/s with 7-8 N, "
                                     "docs/towing.md); 'tow_point': the line debris CoM -> tow point (no moment from "
                                     "the tow point's offset, but 845 N of side thrust at 29.01 deg/s: fails).")
    natural_frequency_rad_s: Positive = Field(0.2, description="omega_L of F = -m_C (omega_L^2 e + 2 zeta_L omega_L "
                                                                "e') (rad/s).")
    damping_ratio: Positive = Field(1.0, description="zeta_L (-): the lateral error decays as exp(-zeta_L omega_L t).")
    max_force: Positive = Field(50.0, description="Largest lateral force (N), in the chaser's body x-y plane; apart "
                                                  "from thrust.max_force, which is the tether-axis thrust's.")


class AttitudeControl(Strict):
    enabled: bool = Field(True, description="Sliding-mode attitude control of the chaser (eqs. 7-10).")
    k_gain: Positive = Field(description="K (1/s), Sec. 4.1.")
    gain: PositiveVector3 = Field(description="Diagonal of G (rad/s^2), Sec. 4.1.")
    boundary_layer: Positive = Field(description="epsilon (rad/s), Sec. 4.1; widened to the sampled-loop value "
                                                 "for the step (multibody.control.attitude.sampled_boundary_layer).")


class TowSimulation(Strict):
    start_time: NonNegative = Field(description="Time of the lower-order run's initial state (s); the paper starts "
                                                "the lower-order runs at thrust-on, 25 s.")
    end_time: Positive = Field(description="End of the run (s); 300 s in the paper.")
    step: Annotated[float, Field(gt=0, le=0.05)] = Field(description="VelocityVerlet step (s); reduced automatically "
                                                                    "below the connection point's stability limit.")
    output_interval: Positive = Field(description="Time between samples, Delta t_save (s).")
    mu: Positive = Field(3.986e14, description="Earth's gravitational parameter (m^3/s^2), Sec. 2.1.")
    model: Literal["lower-order", "full-net"] = Field(
        "lower-order", description="Model 'riskassess tow' runs: the lower-order model (Sec. 2.2) or the full net "
                                   "wrapped around the debris ([full_net], Sec. 2.1; docs/towing.md).")

    @model_validator(mode="after")
    def _times(self):
        if self.end_time <= self.start_time:
            raise ValueError(f"end_time must be > start_time ({self.start_time:g} s). Got {self.end_time:g} instead")
        if self.output_interval < self.step:
            raise ValueError(f"output_interval must be >= step ({self.step:g} s). Got {self.output_interval:g} instead")
        return self


class Rates(Strict):
    training_deg_s: Annotated[list[NonNegative], Field(min_length=1)] = Field(description="Table 3, training (deg/s).")
    validation_deg_s: Annotated[list[NonNegative], Field(min_length=1)] = Field(description="Table 3, validation (deg/s).")




class Optimizers(Strict):
    swarm_size: Annotated[int, Field(ge=2)] = Field(40, description="PSO particles (-), Sec. 4.3.")
    pso_generations: Annotated[int, Field(ge=1)] = Field(100, description="Largest number of PSO generations (-).")
    pso_tolerance: Positive = Field(1e-6, description="PSO stops when the best cost improves by less than this, "
                                                      "relative, over stall_generations (-).")
    stall_generations: Annotated[int, Field(ge=1)] = Field(20, description="MaxStallIterations (-), Sec. 4.3.")
    pattern_evaluations: Annotated[int, Field(ge=1)] = Field(2000, description="Largest number of pattern-search evaluations (-).")
    pattern_tolerance: Positive = Field(1e-6, description="Pattern-search step tolerance, in units of each bound range (-).")
    polish_evaluations: Annotated[int, Field(ge=0)] = Field(
        0, description="Pattern-search evaluations polishing the PSO's best (0: none); reported as optimizer 'pso+pattern' (-).")
    restart_evaluations: Annotated[int, Field(ge=10)] = Field(
        1000, description="Evaluations of one pattern-search leg before it restarts from its best point (-).")
    polish_delta: Annotated[float, Field(gt=0, le=0.5)] = Field(
        0.02, description="Pattern-search step of the polish and of every restart, in units of each bound range (-).")
    seed: Annotated[int, Field(ge=0)] = Field(0, description="Seed of the PSO and of MADS (-).")
    mads_iterations: Annotated[int, Field(ge=1)] = Field(
        250, description="Largest number of MADS iterations (NOMAD MAX_ITERATIONS), Sec. 4.3: 250 (-).")
    mads_mesh_tolerance: Positive = Field(
        1e-6, description="MADS stops when its mesh size falls below this (NOMAD MIN_MESH_SIZE), Sec. 4.3: 1e-6 (-).")
    mads_evaluations: Annotated[int, Field(ge=1)] = Field(
        2000, description="Largest number of MADS evaluations (NOMAD MAX_BB_EVAL) (-).")


class Identification(Strict):
    cost: Literal["f1", "f1_inertial", "f2"] = Field(
        "f1", description="f1: weighted RMSE of r_D/C and both angular velocities, eq. (18), the rates compared in "
                          "body components; f1_inertial: the same, the rates compared in inertial components (each "
                          "turned by its own body's attitude; needs full-net runs that store the attitudes); f2: "
                          "main-tether tension RMSE, eq. (20).")
    weights: Annotated[list[NonNegative], Field(min_length=2, max_length=2)] = Field(
        description="w1 (1/m) and w2 (s/rad) of eq. (18), Sec. 4.2.")
    lower_bounds: DecisionVector = Field(description="Lower bounds of s = [log10 k_ST, l_ST0, log10 c_ST, m_P/m_net], eq. (24).")
    upper_bounds: DecisionVector = Field(description="Upper bounds of s, eq. (24).")
    initial_guess: DecisionVector = Field(description="Pattern-search start s_0, Sec. 4.3.")
    benchmark_truth: DecisionVector = Field(description="s of the benchmark's data, Sec. 4.3.")
    optimizers: Optimizers = Optimizers()
    searches: Annotated[list[Search], Field(min_length=1)] = Field(
        ["pso", "pattern"], description="Optimizers 'riskassess identify' runs, in order: 'pso' (pymoo PSO; then the "
                                        "pattern-search polish, reported as 'pso+pattern', if optimizers.polish_evaluations "
                                        "> 0) and 'pattern' (pattern search from initial_guess); --optimizers overrides it.")
    workers: Annotated[int, Field(ge=1)] = Field(2, description="Processes evaluating simulations in parallel (-).")
    step: Annotated[float, Field(gt=0, le=0.05)] = Field(
        0.02, description="Step of the identification's lower-order runs (s); the connection point is implicit, so it "
                          "does not depend on s (docs/towing.md: step study).")

    @model_validator(mode="after")
    def _inside_bounds(self):
        lo, hi = np.asarray(self.lower_bounds), np.asarray(self.upper_bounds)
        if np.any(lo >= hi):
            raise ValueError(f"lower_bounds must be < upper_bounds component-wise. Got {self.lower_bounds} and {self.upper_bounds}")
        for key in ("initial_guess", "benchmark_truth"):
            s = np.asarray(getattr(self, key))
            if np.any(s < lo) or np.any(s > hi):
                raise ValueError(f"{key} {getattr(self, key)} lies outside the bounds {self.lower_bounds} .. {self.upper_bounds}")
        if lo[3] <= 0:
            raise ValueError("the lower bound of s4 = m_P/m_net must be > 0 (a massless connection point is not physical)")
        return self


class FullNetContact(Strict):
    stiffness: Positive = Field(description="Hertz k_n of node-debris contact (N/m^exponent).")
    exponent: Annotated[float, Field(ge=1, le=2)] = Field(1.5, description="Hertz exponent n (-).")
    hunt_crossley_alpha: NonNegative = Field(description="Hunt-Crossley alpha (s/m); d_n = 1.5 alpha k_n.")
    mu_static: NonNegative = Field(description="Static friction coefficient (-), Hollar's law.")
    mu_kinetic: NonNegative = Field(description="Kinetic friction coefficient (-).")
    transition_speed: Positive = Field(description="Slip speed V_t0 where friction reaches mu_static (m/s).")


class FullNet(Strict):
    """The wrapped net of the full-net towing model (multibody/net_towing.py; docs/towing.md)."""

    start: Literal["wrapped", "capture", "run"] = Field(
        "wrapped", description="'wrapped': prepared wrapped state at simulation.start_time; 'capture': the open net "
                               "ejected from the chaser at t = 0 s towards the debris (Table 2 states), closed from "
                               "closing_time on (Sec. 2.1, 4.1); 'run': the end state of the impact run folder "
                               "from_run (docs/towing.md).")
    from_run: Text | None = Field(
        None, description="start = 'run': the impact stage's run folder (riskassess run), relative to this case "
                           "file's folder or absolute; its manifest must say complete, its net and target must be "
                           "this case's (docs/towing.md, 'Tow from an impact run').")
    switch_to_lower_order: bool = Field(
        False, description="Stop the full-net run at quasi-steady state and continue with the lower-order model "
                           "from the net's state there (multibody/tow_switch.py, docs/towing.md).")
    switch_window: Positive | None = Field(
        None, description="Quasi-steady criterion: the conditions must hold over this time (s); at least two "
                          "averaging blocks; default three blocks (three debris spin periods: two would not see a slow trend), 5 s "
                          "with switch_averaging = 0.")
    switch_averaging: NonNegative | None = Field(
        None, description="Quasi-steady criterion: tension and net energy are judged on their means over consecutive "
                          "blocks of this length (s); default one debris spin period, 360 / debris.spin_rate_deg_s "
                          "(the tow repeats itself from one revolution to the next); 0: every sample is a block.")
    switch_kinetic_energy: Positive = Field(
        0.5, description="Quasi-steady criterion: the net counts as calm when its kinetic energy relative to the "
                         "debris' rigid motion stays at or below this (block means, J); otherwise it must be "
                         "stationary (block means within switch_tension_variation).")
    switch_tension_variation: Positive = Field(
        0.2, description="Quasi-steady criterion: largest peak-to-peak of the block means of the main-tether tension "
                         "(and of a net energy above switch_kinetic_energy) over their mean (-); the tether must also "
                         "stay taut over the window.")
    switch_earliest: NonNegative | None = Field(
        None, description="No switch before this time (s); default thrust.t_on.")
    launch_speed: Positive = Field(2.0, description="Capture start: speed of every net node relative to the chaser at "
                                                    "t = 0, along r_D/C (m/s) [assumed: the authors' launch data are "
                                                    "not available].")
    launch_offset: NonNegative = Field(1.0, description="Capture start: distance of the flat net's centre ahead of the "
                                                        "chaser's tether attachment along r_D/C at t = 0 (m).")
    closing_duration: Positive = Field(5.0, description="Capture start: the closing loop is reeled in linearly from "
                                                        "open to closed over this time from closing_time on (s).")
    side_length: Positive = Field(description="Side of the square net (m); (nodes_per_side - 1) sections of l_net,0.")
    nodes_per_side: Annotated[int, Field(ge=5, le=41)] = Field(description="Nodes along a side (-), odd so that a central node exists.")
    corner_mass: Positive = Field(description="Each of the four corner masses (kg), part of net_mass.")
    node_radius: Positive = Field(description="Contact radius of a net node (m).")
    corner_radius: Positive = Field(description="Contact radius of a corner mass (m).")
    thread_axial_rigidity: Positive = Field(description="EA of a thread (N); a section of length l gets EA/l (N/m).")
    thread_damping: NonNegative = Field(description="Axial damping of a thread section (N s/m).")
    closing_axial_rigidity: Positive = Field(description="EA of the closing thread (N).")
    closed_fraction: Annotated[float, Field(gt=0, le=1)] = Field(
        description="Natural length of the closed loop over its open length (-).")
    closing_time: NonNegative = Field(15.0, description="Closing-mechanism activation; the main tether gets its "
                                                        "stiffness and damping from then on (s), Sec. 2.1, 4.1.")
    main_tether_slack: NonNegative = Field(0.0, description="How much shorter than l_MT,0 the main tether starts in "
                                                            "the wrapped state (m); 0: at its natural length.")
    step: Annotated[float, Field(gt=0, le=0.02)] = Field(description="VelocityVerlet step of chaser and debris (s).")
    substeps: Annotated[int, Field(ge=1, le=1000)] = Field(description="Net sub-steps per step (-); the net's step is "
                                                                      "step/substeps (docs/towing.md: step study).")
    net_output_interval: Positive = Field(1.0, description="Time between net snapshots in net.npz (s).")
    contact: FullNetContact
    identification_end_time: Positive | None = Field(
        None, description="End of the full-net and lower-order runs of 'riskassess identify' (s); default simulation.end_time.")
    identification_training_runs: Annotated[int, Field(ge=1)] | None = Field(
        None, description="Use only the first k training rates (-); default all.")
    identification_validation_runs: Annotated[int, Field(ge=1)] | None = Field(
        None, description="Use only the first k validation rates (-); default all.")

    @model_validator(mode="after")
    def _odd(self):
        if self.nodes_per_side % 2 == 0:
            raise ValueError(f"nodes_per_side must be odd (the main tether needs a central node). Got {self.nodes_per_side}")
        if (self.start == "run") != (self.from_run is not None):
            raise ValueError("from_run (the impact run folder) goes with start = 'run', and only with it. "
                             f"Got start = '{self.start}', from_run = {self.from_run!r}")
        return self


class TowingCase(Strict):
    kind: Literal["towing"] = Field("towing", description=KIND_NOTE)
    name: CaseName = Field(description="Case name; default output folder runs/<name>.")
    description: Text = ""
    simulation: TowSimulation
    chaser: TowChaser
    debris: TowDebris
    net_mass: Positive = Field(description="m_net, total net mass (kg), Sec. 4.1.")
    main_tether: MainTether
    sub_tethers: SubTethers
    thrust: Thrust
    mrac: Mrac | None = None
    attitude_control: AttitudeControl
    lateral: Lateral = Field(default_factory=Lateral)
    rates: Rates
    identification: Identification
    full_net: FullNet | None = None

    def _check_notch(self, m):
        """The breathing notch's settings: a rate estimate to take the notched rate from, a frequency (stated or
        from a spinning debris) below the Nyquist frequency of the coarser of the two plants' steps."""
        if m.rate_filter_time <= 0.0:
            raise ValueError("mrac.breathing_notch needs mrac.rate_filter_time > 0: the laws' rate is then the "
                             "difference quotient of the notched elongation (0 would hand the plant's instantaneous "
                             f"rate through, breathing and all). Got rate_filter_time = {m.rate_filter_time:g}")
        if m.notch_frequency is None and self.debris.spin_rate_deg_s <= 0.0:
            raise ValueError("mrac.breathing_notch: debris.spin_rate_deg_s = 0, so there is no breathing at twice the "
                             "spin rate; give mrac.notch_frequency (rad/s) or set mrac.breathing_notch = false")
        omega = m.notch_frequency if m.notch_frequency is not None else 2.0 * math.radians(self.debris.spin_rate_deg_s)
        self._check_below_nyquist(omega, "mrac.notch_frequency (or twice debris.spin_rate_deg_s)")

    def _check_below_nyquist(self, omega, named):
        """A notch centre ``omega`` (rad/s, ``named`` in the message) below the Nyquist frequency of the coarser of
        the two plants' steps (the controller samples at that step)."""
        step = max(self.simulation.step, self.full_net.step if self.full_net is not None else 0.0)
        if omega * step >= math.pi:
            raise ValueError(f"{named} = {omega:g} rad/s is above the Nyquist frequency pi / step = "
                             f"{math.pi / step:g} rad/s of the controller's step {step:g} s")

    def _check_range_notch(self, m):
        """The range-rate notch's settings: a range damping to notch, a spinning debris, the spin rate below the
        Nyquist frequency of the coarser of the two plants' steps."""
        if m.range_damping <= 0.0:
            raise ValueError("mrac.range_notch filters the range damping's range rate, but mrac.range_damping = "
                             f"{m.range_damping:g}; give range_damping > 0 or set mrac.range_notch = false")
        if self.debris.spin_rate_deg_s <= 0.0:
            raise ValueError("mrac.range_notch: debris.spin_rate_deg_s = 0, so there is no once-per-turn line to "
                             "leave out; set mrac.range_notch = false")
        self._check_below_nyquist(math.radians(self.debris.spin_rate_deg_s),
                                  "mrac.range_notch: the spin rate debris.spin_rate_deg_s")

    @model_validator(mode="after")
    def _mrac_given(self):
        for section in THRUST_LAWS[self.thrust.kind].CASE_SECTIONS:
            if getattr(self, section) is None:
                raise ValueError(f"thrust.kind = '{self.thrust.kind}' needs an [{section}] section")
        if self.simulation.model == "full-net" and self.full_net is None:
            raise ValueError("simulation.model = 'full-net' needs a [full_net] section")
        fn = self.full_net
        if fn is not None and fn.switch_to_lower_order and fn.switch_averaging is None and self.debris.spin_rate_deg_s == 0:
            raise ValueError("full_net.switch_averaging has no default for a debris that does not spin "
                             "(debris.spin_rate_deg_s = 0): give a block length in s, or 0 to judge every sample")
        if fn is not None and fn.switch_to_lower_order and fn.switch_window is not None:
            averaging = fn.switch_averaging if fn.switch_averaging is not None else 360.0 / self.debris.spin_rate_deg_s
            if averaging > 0 and fn.switch_window < 2.0 * averaging - 1e-9:
                raise ValueError(f"full_net.switch_window must hold at least two averaging blocks: >= 2 x "
                                 f"switch_averaging = {2.0 * averaging:g} s (switch_averaging defaults to one spin "
                                 f"period, 360 / debris.spin_rate_deg_s). Got {fn.switch_window:g} s")
        m = self.mrac
        if m is not None and m.min_thrust is not None and not -self.thrust.max_force <= m.min_thrust < self.thrust.max_force:
            raise ValueError(f"mrac.min_thrust must lie in [-thrust.max_force, thrust.max_force) = "
                             f"[{-self.thrust.max_force:g}, {self.thrust.max_force:g}) N. Got {m.min_thrust:g} instead")
        if m is not None and m.thrust_band is not None and (m.min_thrust is not None or m.max_thrust is not None):
            raise ValueError("mrac.thrust_band sets the actuator range itself: give it or mrac.min_thrust / "
                             "mrac.max_thrust, not both")
        if m is not None and m.max_thrust is not None:
            low = -self.thrust.max_force if m.min_thrust is None else m.min_thrust
            if not low < m.max_thrust <= self.thrust.max_force:
                raise ValueError(f"mrac.max_thrust must lie in (mrac.min_thrust, thrust.max_force] = ({low:g}, "
                                 f"{self.thrust.max_force:g}] N. Got {m.max_thrust:g} instead")
        if m is not None and m.breathing_notch:
            self._check_notch(m)
        if m is not None and m.range_notch:
            self._check_range_notch(m)
        if m is not None and m.slack_hold_periods > 0 and m.slack_elongation is None:
            raise ValueError("mrac.slack_hold_periods needs mrac.slack_elongation (the elongation below which the "
                             "tether counts as slack and the hold starts)")
        if m is not None and m.slack_hold_periods > 0 and self.debris.spin_rate_deg_s <= 0.0:
            raise ValueError("mrac.slack_hold_periods counts breathing periods (half a spin period), but "
                             "debris.spin_rate_deg_s = 0; set mrac.slack_hold_periods = 0")
        if self.lateral.enabled and not self.attitude_control.enabled:
            raise ValueError("lateral.enabled acts in the chaser's body x-y plane, across the tether only while the "
                             "attitude control holds body z along it: set attitude_control.enabled = true")
        if self.full_net is not None and 4 * self.full_net.corner_mass >= self.net_mass:
            raise ValueError(f"full_net.corner_mass must be < net_mass / 4 ({self.net_mass / 4:g} kg). "
                             f"Got {self.full_net.corner_mass:g} instead")
        return self
