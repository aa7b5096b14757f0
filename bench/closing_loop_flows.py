"""Where a closing run's energy balance goes during the reel-in: the closing loop's own balance, step by step.

    python3 bench/closing_loop_flows.py CASE [--set SECTION.KEY=VALUE ...] [--from T0] [--times T1,T2,...]

The run's simulation alone (as ``bench/net_energy_flows.py``, whose :class:`FlowMeter` this extends: the kernel's net
step wrapped, the dynamics untouched, the health check's limit lifted), with, every step, the balance of the
closing loop (the net's last 12 threads, :mod:`multibody.closing`) and of the net's own threads apart, each in
VelocityVerlet's terms (module ``multibody.kernel_net``: a force evaluated at ``x(n+1)``, ``v(n+1/2)`` changes the
kinetic energy by ``h f . v(n+1)``):

* made = the work the group's forces do on the nodes (``h f . v(n+1)``) + the change of its elastic energy + its
  dampers' dissipation as the kernel books it (``(T - k s) s'(n+1/2) h``, ``s' = l' - l0'``,
  :func:`multibody.net.kelvin_voigt_dissipated_power`) - the winch's booked work (the loop only; its spring share and
  its damper share ``-(T - k s) l0' h``, :func:`multibody.net.reel_damper_power`): zero for an exact integration;
* its damper part = the dampers' booking less the winch's damper share less the work their force does in Verlet's
  terms (``(T - k s) l'(n+1) h``), helper gain18's split (docs/model.md, "The gain the joints' dampers unmasked");
  the spring part is the rest;
* the loop's tension onsets and releases (T > 0 starting or ending) and the loop made within 2 steps of one.

Printed from ``--from`` (default 14.9 s) at ``--times``, as % of the run's first recorded total (the measure of
summary.json's ``checks.energy_balance_relative_drift``), with the contact's share (FlowMeter's), the CPU time and the
load. Helper drift23 (docs/model.md, "The closing's energy dip").
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
from net_energy_flows import FlowMeter, at_samples  # noqa: E402
from thread_contact_drift import with_overrides  # noqa: E402

from multibody.closing import N_CLOSING  # noqa: E402
from multibody.impact import ImpactSimulation  # noqa: E402
from multibody.net import PADDING_REST_LENGTH, reel_damper_power  # noqa: E402
from riskassess.cases.impact import load_case  # noqa: E402
from riskassess.models.impact import model_inputs  # noqa: E402

#: Per-step running totals kept by :class:`LoopMeter`, per group (loop, net): work on the nodes, elastic energy
#: (not running), dampers' booking, dampers' Verlet work, the reel's damper share (0 for a fixed natural length);
#: then the winch's work, onsets, releases.
GROUP_FIELDS = 5


class LoopMeter(FlowMeter):
    """:class:`FlowMeter` that also keeps, every step, the closing loop's and the net threads' balances (module doc)."""

    def __init__(self, simulation: ImpactSimulation, n_steps: int):
        super().__init__(simulation, n_steps)
        if simulation.system.closing is None:
            raise ValueError("the case has no [net.closing]: no loop to meter")
        runs = self.kernel.net.thread_runs
        self._runs = runs
        self._padded = np.flatnonzero(runs.rest_lengths != PADDING_REST_LENGTH)   # the thread list's order
        m = len(self._padded)
        self.groups = (np.arange(m - N_CLOSING, m), np.arange(m - N_CLOSING))
        self.winch = simulation.system.closing
        self.loop_record = np.zeros((n_steps + 2, 1 + 2 * GROUP_FIELDS + 3))
        self._loop_totals = np.zeros(2 * GROUP_FIELDS)
        self._taut = np.zeros(N_CLOSING, bool)

    def __call__(self, m, q_bodies, qt_bodies, qtt_bodies, t, q_next_bodies, force_bodies):
        super().__call__(m, q_bodies, qt_bodies, qtt_bodies, t, q_next_bodies, force_bodies)
        velocity_end = self.net_velocity.reshape(3, -1)
        velocity_mid = velocity_end - 0.5 * self.step * self.node_force * self._inverse_mass
        x = self._reference + self._position.reshape(3, -1).T
        changes = (0, 0)
        for g, rows in enumerate(self.groups):
            tension, parts = self._group_balance(rows, x, velocity_mid, velocity_end)
            self._loop_totals[g * GROUP_FIELDS:(g + 1) * GROUP_FIELDS] += parts
            self._loop_totals[g * GROUP_FIELDS + 1] = parts[1]                  # elastic energy: a state
            if g == 0:
                taut = tension > 0.0
                changes = (int(np.sum(taut & ~self._taut)), int(np.sum(self._taut & ~taut)))
                self._taut = taut
        k = self.count - 1
        if k < self.loop_record.shape[0]:
            self.loop_record[k] = (t, *self._loop_totals, self.winch.work, *changes)

    def _group_balance(self, rows, x, velocity_mid, velocity_end):
        """One group's tensions (N) and step totals: work on its nodes, elastic energy, dampers' booking and Verlet
        work (J), the kernel's law (:func:`multibody.net.thread_tension_strain`'s) at ``x(n+1)``, ``v(n+1/2)``."""
        padded = self._padded[rows]
        a, b = self._threads[rows, 0], self._threads[rows, 1]
        d = x[b] - x[a]
        unit = d / np.linalg.norm(d, axis=1)[:, None]
        rest, k, c = self._runs.rest_lengths[padded], self._runs.stiffness[padded], self._runs.damping[padded]
        rest_rate = self._runs.rest_rates[padded]       # as the step's evaluation read them (the winch sets the next)
        stretch = np.linalg.norm(d, axis=1) - rest
        rate_mid = np.einsum("ti,it->t", unit, velocity_mid[:, b] - velocity_mid[:, a])
        rate_end = np.einsum("ti,it->t", unit, velocity_end[:, b] - velocity_end[:, a])
        pulled = np.where(stretch > 0.0, stretch, 0.0)
        tension = np.where(stretch > 0.0, np.maximum(k * stretch + c * (rate_mid - rest_rate), 0.0), 0.0)
        non_elastic = tension - k * pulled
        h = self.step
        return tension, np.array([-h * np.sum(tension * rate_end), np.sum(0.5 * k * pulled ** 2),
                                  h * np.sum(non_elastic * (rate_mid - rest_rate)), h * np.sum(non_elastic * rate_end),
                                  h * np.sum(reel_damper_power(tension, pulled, k, rest_rate))])


def print_balance(meter: LoopMeter, series: dict, t_from: float, times: list) -> None:
    """The balance's drift from ``t_from`` split into the contact, the loop (spring, damper), the net's threads and
    the rest, at ``times`` (s), % of the run's first recorded total."""
    t = series["time"]
    e0 = series["energy_total"][0]
    loop = meter.loop_record[:meter.count]
    flows = at_samples(meter.record[:meter.count], t, meter.step)
    k0 = int(np.searchsorted(t, t_from))
    j = np.clip(np.searchsorted(loop[:, 0], t - 0.5 * meter.step), 0, len(loop) - 1)
    rows = loop[j] - loop[j[k0]]
    made = {g: rows[:, 1 + o] + rows[:, 2 + o] + rows[:, 3 + o] for g, o in (("loop", 0), ("net", GROUP_FIELDS))}
    made["loop"] = made["loop"] - rows[:, 1 + 2 * GROUP_FIELDS]
    damper = {g: rows[:, 3 + o] - rows[:, 5 + o] - rows[:, 4 + o] for g, o in (("loop", 0), ("net", GROUP_FIELDS))}
    d = {key: series[key] - series[key][k0] for key in ("energy_total", "energy_contact_elastic",
                                                          "energy_dissipated_contact")}
    contact = (flows[:, 1] - flows[k0, 1] + flows[:, 3] - flows[k0, 3] + d["energy_contact_elastic"]
               + d["energy_dissipated_contact"])
    print(f"   from {t[k0]:.3f} s (% of the first total {e0:.4f} J): total, contact, loop (spring + damper), net's "
          "threads (spring + damper), rest; the loop's booked damper dissipation, the winch's work and its damper "
          "share (J)")
    for when in times:
        k = min(int(np.searchsorted(t, when)), len(t) - 1)
        rest = d["energy_total"][k] - contact[k] - made["loop"][k] - made["net"][k]
        print(f"   t {t[k]:8.3f} s {100 * d['energy_total'][k] / e0:+8.3f} {100 * contact[k] / e0:+8.3f} "
              f"{100 * made['loop'][k] / e0:+8.3f} ({100 * (made['loop'][k] - damper['loop'][k]) / e0:+.3f} "
              f"{100 * damper['loop'][k] / e0:+.3f}) {100 * made['net'][k] / e0:+8.3f} "
              f"({100 * (made['net'][k] - damper['net'][k]) / e0:+.3f} {100 * damper['net'][k] / e0:+.3f}) "
              f"{100 * rest / e0:+8.3f}   {rows[k, 3]:.3f} {rows[k, 1 + 2 * GROUP_FIELDS]:.3f} {rows[k, 5]:.3f}")
    print_events(loop[j[k0]:], e0)


def print_events(loop: np.ndarray, e0: float) -> None:
    """The loop made within 2 steps of a tension onset or release, and elsewhere."""
    made = loop[:, 1] + loop[:, 2] + loop[:, 3] - loop[:, 1 + 2 * GROUP_FIELDS]
    step_made = np.diff(made)
    changes = (loop[1:, -2] + loop[1:, -1]) > 0
    near = np.zeros_like(changes)
    for shift in range(-2, 3):
        near |= np.roll(changes, shift)
    print(f"   the loop's tension onsets {int(loop[1:, -2].sum())}, releases {int(loop[1:, -1].sum())}; the loop made "
          f"{100 * step_made[near].sum() / e0:+.3f} % within 2 steps of one ({int(near.sum())} steps), "
          f"{100 * step_made[~near].sum() / e0:+.3f} % in the other {int((~near).sum())}")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case")
    parser.add_argument("--set", action="append", default=[], metavar="SECTION.KEY=VALUE",
                        help="a case value overridden, e.g. simulation.end_time=25.2 (repeatable)")
    parser.add_argument("--from", dest="t_from", type=float, default=14.9, help="start of the split (s)")
    parser.add_argument("--times", default="16,18,20,22,24,25", help="times of the table (s), comma-separated")
    args = parser.parse_args(argv)
    case_path = Path(args.case)
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / case_path.name
        path.write_text(with_overrides(case_path.read_text(), args.set))
        assembly = model_inputs(load_case(path), case_path.parent).assembly
    simulation = ImpactSimulation(assembly)
    simulation.health.reference_energy = None       # measure the drift, do not refuse it
    n_steps = int(round(assembly.solver.end_time / assembly.solver.step))
    start, load = time.process_time(), os.getloadavg()[0]
    meter = LoopMeter(simulation, n_steps)
    with meter:
        series = simulation.run().series
    print(f"{case_path.name} {' '.join(args.set)}, end {series['time'][-1]:.3f} s, step {meter.step:g} s: CPU "
          f"{time.process_time() - start:.1f} s, load {load:.1f} -> {os.getloadavg()[0]:.1f}", flush=True)
    print_balance(meter, series, args.t_from, [float(v) for v in args.times.split(",")])


if __name__ == "__main__":
    main()
