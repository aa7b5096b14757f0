"""What a simulation will cost, said before it starts, and refused above a limit unless forced.

A stated cost model (not a calibration run): the figures are the project's own measurements on
the 2-core machine CI uses (the impact's: CPU times at load 3-9, which a quiet machine matches or
beats by up to some 10 %; the tows': quiet, load < 1), and a run on a loaded or slower machine takes
longer in wall time. They only need to be right within a factor of a few: their job is to stop a mistyped
``end_time = 1e6`` (1e10 steps, years of wall time) before it starts, not to schedule work.

* impact (``run``, ``assess``, ``perceive``, sweeps): a fixed 2.4 s (building the model, loading the compiled
  kernels, writing the products), then per step 17 us (Exudyn's bodies and joints, the hooks, the recorder) plus
  0.0273 us per net node (the compiled kernel integrating the net) plus 27 us with the thread contact on
  (``contact.thread_segments``: its pair search, geometry and sub-cycles, a whole capture's mean over flight,
  wrapping and the wrapped net's late contacts). The first two terms fitted by helper speed21 (2026-11-28,
  docs/model.md "Speed", CPU times at load 3-9, nice 10) to the reference case's solve with the 15 x 15 and 35 x 35
  nets (``bench/bench_impact.py --sizes 15 35``: 23.3 and 50.6 us a step, 229 and 1229 nodes: the line through them);
  the fixed part is the pipeline's CPU less the solve's on the 2.0 m/s capture copy to 15 s (2.3-2.5 s). The thread
  contact's term refitted by helper speed22 (2026-11-28) to the 1.0 m/s capture case run to 200 s (the steps' 106.6 s
  CPU, 53.3 us a step, less the first two terms; speed21's 22 us came from runs of 15-135 s, and a capture keeps 3-5
  thread contacts a step past 200 s against 1-2 before: 50-64 us a step then), and to 27 us by helper speed23
  (2026-11-28), who skipped the pair tests whose answer is proven (the same case to 300 s: the steps over 1-300 s
  149.5 s CPU, 50.0 us a step, against 163.4 s, 54.7 us, on main in the same conditions). Not in the model: the products a run
  writes after its end, which grow with the simulated time (some 0.07-0.09 s CPU per simulated second of a capture at
  1 kHz output, docs/model.md "Speed"), so a long whole run reads some 0.85 of its measured CPU. The earlier model
  (60 us a step plus 0.33 us per node-step, from the 143 and 481 us a step of 2026-11-26) read 2-3x the cost of
  today's code (183 s for a 135 s run);
* lower-order tow: 15 us per step (0.97 s for 71 100 steps, docs/towing.md);
* full-net tow: 0.11 us per net node and net sub-step (300 s of the 15 x 15 net, 229 nodes, with
  20 sub-steps of each 2 ms step: 6.9e8 node sub-steps in 75.7 s, docs/towing.md).

Memory: the impact recorder keeps every net snapshot (positions float64 and velocities float32,
36 bytes per node) and about 1 kB per time-series sample and body.
"""
from __future__ import annotations

from dataclasses import dataclass

IMPACT_SETUP_S = 2.4
IMPACT_US_PER_STEP = 17.0
IMPACT_US_PER_NODE_STEP = 0.0273
THREAD_CONTACT_US_PER_STEP = 27.0
TOW_US_PER_STEP = 15.0
FULL_NET_US_PER_NODE_SUBSTEP = 0.11

#: Work refused without ``--force``: one hour of estimated wall time (a reference impact of 7.5 s is about 6 s; a
#: 60 s impact of the full net about 33 s; 1000 s of a 15 x 15 capture with the thread contact about 8.5 min) or
#: 8 GB of recorded data.
LIMIT_WALL_S = 3600.0
LIMIT_MEMORY_BYTES = 8e9
#: Never started, even with ``--force``: beyond this the estimate itself says the run cannot finish.
HARD_LIMIT_STEPS = 1e10


class TooMuchWork(ValueError):
    """The estimated work is above the limit; the message gives the estimate and how to go on."""


@dataclass(frozen=True)
class Estimate:
    """Steps, expected wall time (s) and recorded data (bytes) of one simulation."""

    what: str
    steps: float
    wall_s: float
    memory_bytes: float

    def text(self) -> str:
        return (f"estimate: {self.what}: {self.steps:.3g} steps, about {_duration(self.wall_s)} wall on one core "
                f"of a quiet 2-core machine, {self.memory_bytes / 1e6:.3g} MB recorded")


def _duration(seconds: float) -> str:
    for unit, size in (("days", 86400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= 2 * size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.2g} s"


def impact_estimate(end_time: float, step: float, n_nodes: int, n_bodies: int, output_rate: float,
                    net_output_rate: float, thread_segments: bool = False) -> Estimate:
    """Cost of an impact run of ``end_time`` (s) at ``step`` (s) with ``n_nodes`` net nodes.

    Parameters
    ----------
    end_time : float
        Simulated time (s).
    step : float
        Integrator step (s).
    n_nodes : int
        Net nodes (bullets included).
    n_bodies : int
        Rigid bodies.
    output_rate : float
        Time-series samples per second (Hz).
    net_output_rate : float
        Net snapshots per second (Hz).
    thread_segments : bool
        The threads take contact too (the case's ``contact.thread_segments``).

    Returns
    -------
    Estimate
        Steps, wall time (s) and recorded data (bytes).
    """
    steps = end_time / step
    per_step_us = (IMPACT_US_PER_STEP + IMPACT_US_PER_NODE_STEP * n_nodes
                   + (THREAD_CONTACT_US_PER_STEP if thread_segments else 0.0))
    wall = IMPACT_SETUP_S + steps * per_step_us * 1e-6
    samples = min(end_time * output_rate, steps) + 2
    snapshots = min(end_time * net_output_rate, steps) + 2
    memory = samples * 1e3 * max(n_bodies, 1) + snapshots * 36.0 * n_nodes
    return Estimate(f"{end_time:g} s of impact with {n_nodes} net nodes", steps, wall, memory)


def tow_estimate(duration: float, step: float, net_nodes: int = 0, substeps: int = 1) -> Estimate:
    """Cost of a tow of ``duration`` (s): lower-order (``net_nodes`` 0) or full-net.

    Parameters
    ----------
    duration : float
        Simulated time (s).
    step : float
        Integrator step (s).
    net_nodes : int
        Net nodes of a full-net tow; 0 for the lower-order model.
    substeps : int
        Net sub-steps per step (full-net).

    Returns
    -------
    Estimate
        Steps, wall time (s) and recorded data (bytes, 200 per step).
    """
    steps = duration / step
    if net_nodes:
        wall = steps * substeps * net_nodes * FULL_NET_US_PER_NODE_SUBSTEP * 1e-6
        what = f"{duration:g} s of full-net tow with {net_nodes} nodes"
    else:
        wall = steps * TOW_US_PER_STEP * 1e-6
        what = f"{duration:g} s of lower-order tow"
    return Estimate(what, steps, wall, steps * 200.0)


def check_budget(estimate: Estimate, force: bool) -> None:
    """Raise :class:`TooMuchWork` when ``estimate`` is above the limits (the soft ones unless ``force``).

    Parameters
    ----------
    estimate : Estimate
        The estimated work.
    force : bool
        Skip the soft limits (:data:`LIMIT_WALL_S`, :data:`LIMIT_MEMORY_BYTES`); the hard one,
        :data:`HARD_LIMIT_STEPS`, always applies.
    """
    if estimate.steps > HARD_LIMIT_STEPS:
        raise TooMuchWork(f"{estimate.text()}; more than {HARD_LIMIT_STEPS:.0e} steps is refused even with --force "
                          f"(check simulation.end_time and simulation.step)")
    if force:
        return
    if estimate.wall_s > LIMIT_WALL_S or estimate.memory_bytes > LIMIT_MEMORY_BYTES:
        raise TooMuchWork(f"{estimate.text()}; above the limit of {_duration(LIMIT_WALL_S)} or "
                          f"{LIMIT_MEMORY_BYTES / 1e9:g} GB: check simulation.end_time, simulation.step and the output "
                          f"rates, or pass --force to run it anyway")
