"""One full-net tow with everything the elongation controller sees and does recorded: the measured
elongation and tension, the law's states (reference model z_m, its rate, the rate estimate, the
adaptive parameters), the thrust and its saturation, the chaser's pointing against the tether, where
the net's central node sits on the debris (debris body frame), the main tether's moment about the
debris CoM and the debris' angular momentum (issue 27: why MRAC fails on the full net at 20.44 deg/s).

    python bench/bench_mrac_probe.py --law mrac2 --rate 20.44 --out bench/results/probe/mrac2_20.44.npz
                                     [--end 300] [--set mrac.KEY=VALUE ...] [--set thrust.KEY=VALUE ...]
    python bench/bench_mrac_probe.py --analyse bench/results/probe/*.npz      # the mechanism line of each run

Writes one ``.npz`` (series below; SI, frames in the names) and prints a per-25-s table. ``--set``
overrides case keys of ``[mrac]`` or ``[thrust]`` (numbers, booleans or lists as JSON), or
``sub_tethers.attachment_points_body`` (where the full net's cylinder sits on the debris axis; diagnostic).

Series: ``time``; ``tension``, ``elongation``, ``thrust``; ``law_state`` (k, j): the thrust law's state
(``multibody.control.thrust_laws``: z_m, z_m rate, last elongation, rate estimate, adaptive parameters);
``node_debris_body`` (k, 3): the central node relative to the debris CoM, debris body frame (m);
``tether_moment_inertial`` (k, 3): moment of the main tether's pull on the central node about the debris
CoM (N m, inertial); ``debris_angular_momentum_inertial`` (k, 3) (N m s); ``net_torque_debris_body``
(k, 3): the net's torque on the debris over the last step, debris body frame (N m); ``pointing_error``
(k,): angle between the chaser's body z (the MRAC thrust axis) and the tether from the node to the
chaser (rad); ``tow_alignment`` (k,): angle between the tether and the debris -> chaser line (rad);
``debris_omega_body`` (k, 3) (rad/s); ``separation`` (k,) chaser-debris CoM distance (m).
"""
from __future__ import annotations

import argparse
import json
import os
import time
from pathlib import Path

import numpy as np

import multibody.net_towing as net_towing
from multibody.maths.rotations import rotation_matrix_from_rotation_vector
from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase
from riskassess.models.towing_fullnet import full_net_model
from riskassess.products import results
from multibody.control.mrac import A0


class _ProbeForces(net_towing._Forces):
    """The force user function, keeping the forces of the last advancing call (the step's mean reactions)."""

    last = np.zeros(12)

    def __call__(self, mbs, t, item, q, q_t):
        advance = t > self.last_time and t > 0.0
        out = super().__call__(mbs, t, item, q, q_t)
        if advance:
            _ProbeForces.last = np.array(out, float)
        return out


class _ProbeSampler(net_towing._Sampler):
    """The run's sampler plus the probe's series (module doc)."""

    def __init__(self, state):
        super().__init__(state)
        k = len(self.time)
        self.extra = {"law_state": np.zeros((k, len(state.thrust_state))), "node_debris_body": np.zeros((k, 3)),
                      "tether_moment_inertial": np.zeros((k, 3)), "debris_angular_momentum_inertial": np.zeros((k, 3)),
                      "net_torque_debris_body": np.zeros((k, 3)), "pointing_error": np.zeros(k),
                      "tow_alignment": np.zeros(k)}

    def record(self, mbs, t):
        k = self.sample
        keep = super().record(mbs, t)
        if self.sample == k + 1:
            self._probe(k)
        return keep

    def _probe(self, k):
        s, m, e = self.state, self.state.model, self.extra
        q, v = self.q[k], self.v[k]
        rot_c, rot_d = rotation_matrix_from_rotation_vector(q[3:6]), rotation_matrix_from_rotation_vector(q[9:12])
        com_c, com_d = m.positions[0] + q[0:3], m.positions[1] + q[6:9]
        node = self.node[k, 0:3]
        a_point = com_c + rot_c @ np.asarray(m.attach_chaser_body, float)
        to_chaser = (a_point - node) / np.linalg.norm(a_point - node)
        tension = self.diag[k, net_towing.D_TENSION]
        e["law_state"][k] = s.thrust_state
        e["node_debris_body"][k] = rot_d.T @ (node - com_d)
        e["tether_moment_inertial"][k] = np.cross(node - com_d, tension * to_chaser)
        e["debris_angular_momentum_inertial"][k] = rot_d @ (m.inertia_body[1] @ v[9:12])
        e["net_torque_debris_body"][k] = _ProbeForces.last[9:12]
        e["pointing_error"][k] = np.arccos(np.clip(rot_c[:, 2] @ to_chaser, -1.0, 1.0))
        line = (com_c - com_d) / np.linalg.norm(com_c - com_d)
        e["tow_alignment"][k] = np.arccos(np.clip(to_chaser @ line, -1.0, 1.0))


def _value(text):
    try:
        return json.loads(text)
    except json.JSONDecodeError:
        return text


def overridden(case, settings):
    """``case`` with ``[mrac]`` / ``[thrust]`` / ``[lateral]`` keys set from ``section.key=value`` strings (validated again); also
    ``sub_tethers.attachment_points_body``, which places the full net's cylinder along the debris axis (a diagnostic:
    symmetric points put the geometric centre on the CoM, ``riskassess.models.towing_fullnet.debris_geometry``)."""
    data = case.model_dump()
    allowed = {"mrac": set(data["mrac"]), "thrust": set(data["thrust"]), "lateral": set(data["lateral"]),
               "sub_tethers": {"attachment_points_body"}}
    for item in settings:
        key, value = item.split("=", 1)
        section, name = key.split(".", 1)
        if name not in allowed.get(section, ()):
            raise SystemExit(f"--set {item}: unknown key; allowed: mrac.* {sorted(data['mrac'])}, thrust.* "
                             f"{sorted(data['thrust'])}, lateral.* {sorted(data['lateral'])}, "
                             "sub_tethers.attachment_points_body")
        data[section][name] = _value(value)
    return TowingCase.model_validate(data)


def table(series, t_on):
    """Per-25-s rows of the probe's series (printed)."""
    t, tension, thrust = series["time"], series["tension"], series["thrust"]
    state, spin = series["law_state"], np.degrees(np.linalg.norm(series["debris_omega_body"], axis=1))
    u_max = np.abs(thrust).max()
    print(f"{'window s':>9} {'T mean':>7} {'T max':>7} {'slack':>5} {'z mean':>7} {'z_m mean':>8} {'F mean':>7} "
          f"{'F<0':>5} {'sat+':>5} {'sat-':>5} {'point deg':>9} {'spin deg/s':>14} {'adaptive (mean)':>30}")
    for a in np.arange(t_on, t[-1], 25.0):
        w = (t >= a) & (t < a + 25.0)
        if not w.any():
            continue
        print(f"{a:4.0f}-{a + 25:<4.0f} {tension[w].mean():7.1f} {tension[w].max():7.0f} {np.mean(tension[w] <= 0):5.2f} "
              f"{series['elongation'][w].mean():7.4f} {state[w, 0].mean():8.4f} {thrust[w].mean():7.1f} "
              f"{np.mean(thrust[w] < 0):5.2f} {np.mean(thrust[w] >= u_max * (1 - 1e-9)):5.2f} "
              f"{np.mean(thrust[w] <= -u_max * (1 - 1e-9)):5.2f} {np.degrees(series['pointing_error'][w]).mean():9.1f} "
              f"{spin[w][0]:6.2f}->{spin[w][-1]:6.2f} {np.array2string(state[w, A0:].mean(axis=0), precision=1):>30}",
              flush=True)


def mechanism(series, label):
    """One line of the slack-and-snap mechanism (printed): the debris' angular-momentum change about its spin axis
    against the integral of the main tether's moment about its CoM (the spin is lost through the tether if they
    agree), the mean thrust while the tether is slack (T < 1 N) and while it snaps (T > 300 N), from 50 s on, the
    slack share, the elongation's mean and its standard deviation from 150 s on with the share of its variance at
    0.5-1 rad/s (twice the spin rate, 0.71 rad/s at 20.44 deg/s: the net's breathing on the tumbling stage)."""
    t, tension, thrust, z = series["time"], series["tension"], series["thrust"], series["elongation"]
    momentum = series["debris_angular_momentum_inertial"]
    axis = momentum[0] / np.linalg.norm(momentum[0])
    moment = series["tether_moment_inertial"] @ axis
    integral = float(np.sum(0.5 * (moment[1:] + moment[:-1]) * np.diff(t)))
    late, tail = t >= 50.0, t >= 150.0
    slack, snap = late & (tension < 1.0), late & (tension > 300.0)
    x = z[tail] - z[tail].mean()
    power = np.abs(np.fft.rfft(x * np.hanning(len(x)))) ** 2
    w = 2 * np.pi * np.fft.rfftfreq(len(x), t[1] - t[0])
    breathing = power[(w >= 0.5) & (w < 1.0)].sum() / power[1:].sum()
    spin = np.degrees(np.linalg.norm(series["debris_omega_body"], axis=1))
    print(f"{label:34s} dL_spin {momentum[-1] @ axis - momentum[0] @ axis:9.0f} N m s, tether moment integral "
          f"{integral:9.0f} N m s; thrust slack {thrust[slack].mean() if slack.any() else np.nan:6.1f} N, snap "
          f"{thrust[snap].mean() if snap.any() else np.nan:6.1f} N; slack share {slack.sum() / late.sum():.2f}, peak "
          f"{tension[late].max():5.0f} N; "
          f"z 150-300 s mean {z[tail].mean():.4f} std {x.std():.4f} m (0.5-1 rad/s: {breathing:.2f}); "
          f"spin {spin[0]:.2f} -> {spin[-1]:.2f} deg/s", flush=True)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--case", default="cases/zenit2_towing.toml")
    parser.add_argument("--law", default="mrac2")
    parser.add_argument("--rate", type=float, default=20.44)
    parser.add_argument("--end", type=float, default=None)
    parser.add_argument("--set", nargs="*", default=[])
    parser.add_argument("--out", type=Path, default=None)
    parser.add_argument("--analyse", type=Path, nargs="+", default=None,
                        help="print the mechanism line of probe files already written, run nothing")
    args = parser.parse_args()
    if args.analyse:
        for path in args.analyse:
            with np.load(path) as data:
                mechanism(dict(data), path.stem)
        return
    if args.out is None:
        parser.error("--out is required unless --analyse")
    if args.out.exists():
        parser.error(f"--out {args.out} exists")
    case = load_model(args.case, TowingCase)
    case = overridden(case, [f"thrust.kind={json.dumps(args.law)}"] + args.set)
    model = full_net_model(case, args.rate, end_time=args.end)
    net_towing._Forces = _ProbeForces
    start, load0 = time.process_time(), os.getloadavg()[0]
    sampler = {}

    class _Keep(_ProbeSampler):
        def __init__(self, state):
            super().__init__(state)
            sampler["it"] = self

    net_towing._Sampler = _Keep
    result = net_towing.run_exudyn(model)
    cpu = time.process_time() - start
    k = len(result.time)
    p = sampler["it"]
    series = {"time": result.time, "tension": result.diag[:, net_towing.D_TENSION],
              "elongation": result.diag[:, net_towing.D_ELONGATION], "thrust": result.diag[:, net_towing.D_THRUST],
              "debris_omega_body": result.v[:, 9:12], "chaser_omega_body": result.v[:, 3:6],
              "separation": np.linalg.norm((model.positions[0] + result.q[:, 0:3])
                                           - (model.positions[1] + result.q[:, 6:9]), axis=1),
              "net_kinetic_energy_relative_to_debris": result.kinetic_relative,
              **{name: value[:k] for name, value in p.extra.items()}}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    results.atomic_write_npz(args.out, series)
    print(f"law {args.law}, {args.rate} deg/s, set {args.set}: {cpu:.1f} s CPU, load {load0:.1f} -> "
          f"{os.getloadavg()[0]:.1f}; {args.out}")
    table(series, case.thrust.t_on)
    mechanism(series, args.out.stem)


if __name__ == "__main__":
    main()
