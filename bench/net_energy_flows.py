"""Where a run's energy balance gains: the work of the node contact and of every other force on the net, step by step.

    python3 bench/net_energy_flows.py [CASE] [--key off] [--end-time T] [--set SECTION.KEY=VALUE ...] [--save NPZ]
                                      [--events T0:T1]

The run's simulation alone (as ``bench/thread_contact_drift.py``: no pipeline products, the health check's energy
limit lifted) with the kernel's net step wrapped (a Python wrapper around ``multibody.kernel_net.kernel_net_step``,
the dynamics untouched), which adds up every step, exactly in VelocityVerlet's terms (module ``multibody.kernel_net``:
the force ``f`` evaluated at ``x(n+1)`` changes the half-step kinetic energy ``1/2 m v(n+1/2)^2`` by ``h f . v(n+1)``,
``v(n+1)`` the synchronized velocity):

* ``contact_on_nodes``: the node contact's work on the nodes, its impulses of the step (the kernel's per-node
  accumulator, lag releases included) times ``v(n+1)``;
* ``all_on_nodes``: the work of every force on the nodes (threads, bending, orbit, contact), ``h f . v(n+1)``;
* ``on_bodies``: the work of the kernel's generalized forces on the bodies (contact reactions and orbit), ``h`` times
  the force of a step times the bodies' velocity at its end (Exudyn's VelocityVerlet, the same identity).

From these and the recorded energy terms, at the output samples (% of the health check's reference energy):

* contact made = ``contact_on_nodes + on_bodies + d(contact_elastic) + dissipated_contact`` (the contact as a
  subsystem: what it gives the nodes and bodies less what it stored and dissipated; the orbit's force on the bodies
  is in ``on_bodies`` too, below 1e-3 % on the reference case, orbit on or off);
* threads made = ``(all_on_nodes - contact_on_nodes) + d(net_elastic + net_bending) + dissipated_threads`` (the
  orbit's work on the nodes is in it too);
* net made = ``d(net_kinetic) - all_on_nodes`` (the synchronized kinetic energy against the half-step one: bounded,
  not cumulative); bodies made = the rest of the balance's drift.

With ``--events T0:T1`` the contact made is also split per step inside that window (:class:`EventMeter`) and printed
by 5 ms: the nodes whose contact did the most work (bullets marked), the threads' contacts' share of the dissipation,
the bodies' largest contact force (helper keyon19: the key-on gains at 3.22 s and 4.74-4.86 s located this way).

Helper gain18 (docs/model.md, "The gain the joints' dampers unmasked").
"""
from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench scripts
from bench_thread_segments import case_text  # noqa: E402
from thread_contact_drift import with_overrides  # noqa: E402

import multibody.kernel_net as kernel_net_module  # noqa: E402
from multibody.kernel import CONTACT_DISSIPATED, CONTACT_ELASTIC  # noqa: E402
from multibody.impact import ImpactSimulation  # noqa: E402
from riskassess.cases.impact import load_case  # noqa: E402
from riskassess.models.impact import model_inputs  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
FLOWS = ("time", "contact_on_nodes", "all_on_nodes", "on_bodies", "thread_damper_booked_less_done")


class FlowMeter:
    """Wraps the kernel's net step; after each step adds the step's works (J) to running totals, kept per step.

    Parameters
    ----------
    simulation : ImpactSimulation
        Built, not yet run (its net integrated by the kernel).
    n_steps : int
        Steps the run will take (the size of the per-step record).
    thread_split : bool
        Also add up, per step, the threads' dampers' work as booked (``multibody.net.kelvin_voigt_dissipated_power``
        at the mid-step velocity ``v(n+1/2)``, where the force is evaluated) less the work the same force does in
        Verlet's terms (at ``v(n+1)``): :meth:`thread_damper_mismatch`. About 0.3 ms a step more.
    """

    def __init__(self, simulation: ImpactSimulation, n_steps: int, thread_split: bool = False):
        kernel_net = simulation.system.kernel_net
        if kernel_net is None:
            raise ValueError("the flows are measured on the kernel's net step (the default path)")
        self.kernel = simulation.system.kernel
        self.net_velocity = kernel_net.qt                      # (3 n,) coordinate-major, v(n+1) after the step
        self.node_impulse = self.kernel.buffers.node_impulse_lvlh   # (n, 3), reset by the recorder's snapshots
        self.node_force = self.kernel.buffers.work_soa[2]       # (3, n) the step's total force on the nodes (N)
        self.step = self.kernel.step
        self.record = np.zeros((n_steps + 2, len(FLOWS)))
        self.totals = np.zeros(len(FLOWS))
        self.count = 0
        self._body_force = None
        self._original = kernel_net_module.kernel_net_step
        self.thread_split = thread_split
        net = self.kernel.net
        self._threads, self._rest = net.threads, net.rest_lengths
        self._stiffness, self._damping = net.thread_stiffness, net.thread_damping
        self._position, self._reference = kernel_net.q, net.reference_lvlh
        self._inverse_mass = 1.0 / np.asarray(net.mass, float)

    def __enter__(self):
        kernel_net_module.kernel_net_step = self
        return self

    def __exit__(self, *exc):
        kernel_net_module.kernel_net_step = self._original

    def __call__(self, m, q_bodies, qt_bodies, qtt_bodies, t, q_next_bodies, force_bodies):
        if self._body_force is not None:        # the last step's force on the bodies times their end velocity
            self.totals[3] += self.step * float(self._body_force @ qt_bodies)
        before = self.node_impulse.copy()
        self._original(m, q_bodies, qt_bodies, qtt_bodies, t, q_next_bodies, force_bodies)
        velocity = self.net_velocity.reshape(3, -1)
        impulse = self.node_impulse - before     # (n, 3) the step's contact impulse on each node (N s)
        self.totals[0] = t
        self.totals[1] += float(np.einsum("ni,in->", impulse, velocity))
        self.totals[2] += self.step * float(np.einsum("in,in->", self.node_force, velocity))
        if self.thread_split:
            self.totals[4] += self.thread_damper_mismatch(velocity)
        self._body_force = np.array(force_bodies)
        if self.count < self.record.shape[0]:
            self.record[self.count] = self.totals
        self.count += 1


    def thread_damper_mismatch(self, velocity_end: np.ndarray) -> float:
        """The threads' dissipation booked over the step less the work their non-elastic force did (J).

        The kernel books ``P h`` with ``P = T l' - k s l'`` (``T = max(0, k s + c l')`` on a stretched thread, 0 on a
        slack one; ``l'`` at the mid-step velocity ``v(n+1/2)``, :func:`multibody.net.kelvin_voigt_dissipated_power`),
        while the same force's non-elastic part ``T - k s`` does ``-(T - k s) l'(n+1) h`` on the nodes in Verlet's
        terms (``v(n+1)``, the synchronized velocity). Their difference ``(T - k s)(l'(n+1/2) - l'(n+1)) h`` is what
        the booking makes on its own.

        Parameters
        ----------
        velocity_end : (3, n) float
            ``v(n+1)`` (m/s), LVLH, coordinate-major.
        """
        a, b = self._threads[:, 0], self._threads[:, 1]
        x = self._reference + self._position.reshape(3, -1).T
        half_kick = 0.5 * self.step * self.node_force * self._inverse_mass     # (3, n) v(n+1) - v(n+1/2)
        v_mid = velocity_end - half_kick
        d = x[b] - x[a]
        length = np.linalg.norm(d, axis=1)
        unit = d / length[:, None]
        rate_mid = np.einsum("ti,it->t", unit, v_mid[:, b] - v_mid[:, a])
        rate_end = np.einsum("ti,it->t", unit, velocity_end[:, b] - velocity_end[:, a])
        stretch = length - self._rest
        elastic = self._stiffness * stretch
        tension = np.where(stretch > 0.0, np.maximum(elastic + self._damping * rate_mid, 0.0), 0.0)
        non_elastic = np.where(stretch > 0.0, tension - elastic, 0.0)
        return self.step * float(np.sum(non_elastic * (rate_mid - rate_end)))


class EventMeter(FlowMeter):
    """:class:`FlowMeter` that also keeps, for each step inside ``window`` (s), each node's contact work in Verlet's
    terms (its contact impulse of the step times ``v(n+1)``, J), the contact's elastic energy (J) and booked
    dissipation (J, running), the threads' contacts' booked dissipation (J, running) and the bodies' work total."""

    def __init__(self, simulation: ImpactSimulation, n_steps: int, thread_split: bool, window: tuple):
        super().__init__(simulation, n_steps, thread_split)
        self.window = window
        self.steps = []
        self._scalars = self.kernel.buffers.scalars
        self._segments = self.kernel.buffers.segments

    def __call__(self, m, q_bodies, qt_bodies, qtt_bodies, t, q_next_bodies, force_bodies):
        inside = self.window[0] <= t <= self.window[1]
        before = self.node_impulse.copy() if inside else None
        super().__call__(m, q_bodies, qt_bodies, qtt_bodies, t, q_next_bodies, force_bodies)
        if inside:
            impulse = self.node_impulse - before
            nodes = np.nonzero(np.abs(impulse).sum(axis=1))[0]
            work = np.einsum("ni,in->n", impulse[nodes], self.net_velocity.reshape(3, -1)[:, nodes])
            thread_lost = float(self._segments.dissipated.sum()) if self._segments.enabled else 0.0
            self.steps.append((t, nodes, work, float(self._scalars[CONTACT_ELASTIC]),
                               float(self._scalars[CONTACT_DISSIPATED]), thread_lost, self.totals[3]))


def print_events(meter: EventMeter, series: dict, reference: float, node_mass: np.ndarray, span: float = 5e-3) -> None:
    """The contact made inside the meter's window, by ``span`` (s): per step the nodes' contact work, the bodies' (booked
    at the next step), the change of the contact's elastic energy and its booked dissipation."""
    steps = meter.steps
    heavy = node_mass > 10.0 * np.median(node_mass)
    print(f"   contact made by {1e3 * span:.0f} ms (% of the reference energy; B: a bullet):")
    groups = {}
    for k in range(1, len(steps) - 1):
        t, nodes, work, elastic, lost, thread_lost, _ = steps[k]
        made = (work.sum() + steps[k + 1][6] - steps[k][6] + elastic - steps[k - 1][3] + lost - steps[k - 1][4])
        g = groups.setdefault(int(np.floor(t / span + 1e-9)), [0.0, 0.0, 0.0, {}])
        g[0] += made
        g[1] += lost - steps[k - 1][4]
        g[2] += thread_lost - steps[k - 1][5]
        for i, w in zip(nodes.tolist(), work.tolist()):
            g[3][i] = g[3].get(i, 0.0) + w
    t_series = series["time"]
    for key in sorted(groups):
        made, lost, thread_lost, works = groups[key]
        rows = (t_series >= key * span) & (t_series < (key + 1) * span)
        force = np.abs(series["contact_force_lvlh"][rows]).max(axis=(0, 2)) if rows.any() else []
        top = sorted(works.items(), key=lambda kv: -abs(kv[1]))[:4]
        print(f"   {key * span:.3f} s {100 * made / reference:+.4f} %  dissipated {lost:.2f} J (threads' contacts "
              f"{thread_lost:.2f} J); largest |F| per body {np.round(force).astype(int).tolist()} N; nodes' work: "
              + ", ".join(f"{i}{'B' if heavy[i] else ''} {w:+.2f} J" for i, w in top))


def at_samples(record: np.ndarray, t_samples: np.ndarray, step: float) -> np.ndarray:
    """The per-step running totals at the output samples' times (the step whose evaluation time is the sample's);
    ``on_bodies`` is booked one step later, so it is read one step on."""
    t_steps = record[:, 0]
    k = np.clip(np.searchsorted(t_steps, t_samples - 0.5 * step), 0, len(t_steps) - 1)
    out = record[k].copy()
    out[:, 3] = record[np.clip(k + 1, 0, len(t_steps) - 1), 3]
    return out


def print_flows(series: dict, flows: np.ndarray, reference: float) -> dict:
    """The balance's drift split into what the contact, the threads, the net's integration and the bodies made."""
    t = series["time"]
    d = {key: series[key] - series[key][0] for key in series if key.startswith("energy_")}
    w = flows - flows[0]
    contact = w[:, 1] + w[:, 3] + d["energy_contact_elastic"] + d["energy_dissipated_contact"]
    threads = ((w[:, 2] - w[:, 1]) + d["energy_net_elastic"] + d["energy_net_bending"]
               + d["energy_dissipated_threads"])
    net = d["energy_net_kinetic"] - w[:, 2]
    total = d["energy_total"]
    bodies = total - contact - threads - net
    parts = {"contact": contact, "threads": threads, "net_kinetic_sync": net, "bodies_and_rest": bodies,
             "thread_dampers_booking": w[:, 4]}
    print("   made (% of the reference energy):      total   contact   threads   net KE (sync)   bodies and rest"
          "   (of the threads': their dampers' booking at v(n+1/2))")
    for when in (0.1, 0.2, 0.5, 1, 2, 3, 4, 5, 5.41, 5.45, 6, 7, 7.5):
        k = int(np.searchsorted(t, when)) - 1
        if 0 <= k < len(t) and t[k] > when - 0.01:
            print(f"   t {t[k]:.3f} s {100 * total[k] / reference:+25.3f} " + " ".join(
                f"{100 * part[k] / reference:+9.3f}" for part in parts.values()))
    gains = np.diff(total)
    for k in np.argsort(-gains)[:8]:
        print(f"   gain at t {t[k + 1]:.4f} s: {100 * gains[k] / reference:+.3f} %: " + ", ".join(
            f"{name} {100 * (part[k + 1] - part[k]) / reference:+.3f}" for name, part in parts.items()))
    return parts


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_net_impact.toml"))
    parser.add_argument("--end-time", type=float, default=None)
    parser.add_argument("--key", default="off", choices=("on", "off"))
    parser.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                        help="a case value overridden, e.g. contact.mu_static=0 (an experiment, repeatable)")
    parser.add_argument("--thread-split", action="store_true",
                        help="also measure the threads' dampers' booking against their work (FlowMeter.thread_split)")
    parser.add_argument("--save", default=None, metavar="NPZ", help="write the series and the flows to this file")
    parser.add_argument("--events", default=None, metavar="T0:T1",
                        help="also split the contact made per step in this window (s), printed by 5 ms (EventMeter)")
    args = parser.parse_args(argv)
    case_path = Path(args.case)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / case_path.name
        text = case_text(case_path.read_text(), args.key == "on", args.end_time, None, None)
        path.write_text(with_overrides(text, args.set))
        assembly = model_inputs(load_case(path), case_path.parent).assembly
    simulation = ImpactSimulation(assembly)
    reference = simulation.health.reference_energy
    simulation.health.reference_energy = None       # measure the drift, do not refuse it
    n_steps = int(round(assembly.solver.end_time / assembly.solver.step))
    start = time.process_time()
    window = tuple(float(v) for v in args.events.split(":")) if args.events else None
    meter = (EventMeter(simulation, n_steps, args.thread_split, window) if window
             else FlowMeter(simulation, n_steps, args.thread_split))
    with meter:
        series = simulation.run().series
    cpu = time.process_time() - start
    flows = at_samples(meter.record[:meter.count], series["time"], meter.step)
    print(f"{case_path.name} thread_segments {args.key} {' '.join(args.set)}, end {series['time'][-1]:.3f} s: CPU "
          f"{cpu:.1f} s, load {os.getloadavg()[0]:.1f}; reference energy {reference:.0f} J", flush=True)
    parts = print_flows(series, flows, reference)
    if window:
        print_events(meter, series, reference, np.asarray(simulation.system.kernel.net.mass, float))
    if args.save:
        np.savez_compressed(args.save, reference_energy=reference, flows=flows, step_record=meter.record[:meter.count],
                            **{f"made_{name}": part for name, part in parts.items()}, **series)


if __name__ == "__main__":
    main()
