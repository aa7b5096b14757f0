"""Where a whole-capture run's CPU time goes: per window of simulated time (flight, first contact, wrapped) and per
part of the step (the compiled net step, the recorder's post-step work, the capture monitor, Exudyn and the glue).

    python3 bench/bench_capture_cost.py CASE --store STORE --sample N [--end-time T] [--windows 0,0.5,3,10,20]
                                        [--release never] [--perf-marks] [--census T,...] [--skin D]

Runs Monte Carlo sample ``N`` of a store written by ``bench/bench_safe_velocity.py`` (as
``bench/bench_safe_velocity_history.py`` does: its uncertain inputs, ``structures.release`` = ``--release``) through
the impact pipeline (:func:`riskassess.stages.run.run_case`, in a temporary folder), with the step's parts timed in
CPU time (``time.process_time``) by wrappers around them:

- ``kernel``: :func:`multibody.kernel_net.kernel_net_step` (threads, node contact, thread (segment) contact with its
  broad phase, narrow phase and sub-cycles, the net's Verlet update);
- ``post``: the recorder's post-step work (joint-damper booking, load filter, the output rows, the health checks),
  of which ``capture`` is the capture monitor (:class:`structures.capture_window.CaptureMonitor`, absent when the
  case judges a fixed window);
- ``other``: the rest of each step: Exudyn's own step (bodies, joints), the pre-step glue (views, exact attitudes,
  the force vector handed to Exudyn).

Prints per window: steps, CPU per simulated second and us per step of each part, the mean penetrating contacts
(node and thread) per step, the builds of the thread contact's candidate pairs (:mod:`multibody.segment_candidates`;
``--skin D`` sets their skin, in m: the cost changes, the run does not), then the totals, the load average before and after, and a hash of the run's time series
and net snapshots (two code versions that print the same hash computed the same trajectory to the last bit).
The wrappers cost about 1-2 us a step (four CPU-clock reads), included in ``other``.

``--perf-marks`` prints the CLOCK_MONOTONIC time at each window's start and writes ``/tmp/perf-<pid>.map``
(``bench/perf_profile.py``) at the end, so that ``perf record -k CLOCK_MONOTONIC -e cpu-clock`` of this command can
be split by window (``perf report --time START,END --sort sym``) into the compiled functions of the kernel.
"""
from __future__ import annotations

import argparse
import hashlib
import os
import sys
import tempfile
import time
import tomllib
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))   # the sibling bench scripts
from bench_safe_velocity_history import sample_overrides  # noqa: E402
from perf_profile import write_perf_map  # noqa: E402

import multibody.kernel_net as kernel_net_module  # noqa: E402
from multibody.kernel import N_CONTACTS  # noqa: E402
from multibody.recorder import Recorder  # noqa: E402
from riskassess.cases.impact import validate_case  # noqa: E402
from riskassess.stages.run import run_case  # noqa: E402
from riskassess.sweep.spec import case_with  # noqa: E402
from multibody.segment_box import TIE_DISTANCE  # noqa: E402
try:   # absent in trees before helper speed20 (their "before" figures)
    from multibody.segment_box import segment_box_separation  # noqa: E402
except ImportError:
    segment_box_separation = None
from multibody.segment_cycle import thread_contact_geometry  # noqa: E402
from structures.capture_window import CaptureMonitor  # noqa: E402

PARTS = ("total", "kernel", "post", "capture")


def segment_census(kernel) -> dict:
    """The thread contact's pair search at the last evaluation, counted (not timed) from the kernel's buffers:
    (thread, box) pairs tested, past the bounding-sphere test, past the slab test (the narrow phase's candidates, each
    one or two :func:`~multibody.segment_cycle.thread_contact_geometry` calls until speed20), of those penetrating
    now, those the separating-axis bound keeps apart (:func:`multibody.segment_pairs._contact_can_act`), and the
    pairs found (:mod:`multibody.segment_pairs`; the same tests, written out in Python on the same buffers)."""
    buffers, net, shapes = kernel.buffers, kernel.net, kernel.shapes
    seg, states, x = buffers.segments, buffers.states, buffers.work_soa[0]
    threads, radius, step = net.threads, net.radius, kernel.step
    counts = dict(tested=0, sphere=0, slab=0, penetrating_now=0, separated=0)
    for j in range(threads.shape[0]):
        a, c = threads[j]
        length = np.linalg.norm(x[:, c] - x[:, a])
        motion = step * max(seg.node_speed[a], seg.node_speed[c])
        for s in np.flatnonzero(shapes.is_box):
            counts["tested"] += 1
            reach = 1.001 * (min(radius[a], radius[c]) + motion + step * seg.shape_work[1, s])
            centre_distance = np.linalg.norm(x[:, [a, c]] - seg.shape_work[2:5, [s]], axis=0)
            if 0.5 * (centre_distance.sum() - length) > seg.shape_work[0, s] + reach:
                continue
            counts["sphere"] += 1
            b = shapes.body[s]
            pa = tuple(states.body_to_lvlh[b].T @ (x[:, a] - states.com_lvlh[b]))
            pc = tuple(states.body_to_lvlh[b].T @ (x[:, c] - states.com_lvlh[b]))
            low, high = np.minimum(pa, pc), np.maximum(pa, pc)
            if (low > shapes.box_max_body[s] + reach).any() or (high < shapes.box_min_body[s] - reach).any():
                continue
            counts["slab"] += 1
            now = thread_contact_geometry(pa, pc, shapes.box_min_body, shapes.box_max_body, s, radius[a], radius[c],
                                          np.zeros_like(seg.breakpoints))
            counts["penetrating_now"] += int(now[0] > 0.0 or (now[5] > 0.0) != (now[6] > 0.0))
            # decided by the separating-axis bound (segment_pairs._contact_can_act), no geometry call
            if segment_box_separation is None:
                continue
            lo, hi = tuple(shapes.box_min_body[s]), tuple(shapes.box_max_body[s])
            counts["separated"] += int(segment_box_separation(pa, tuple(np.subtract(pc, pa)), lo, hi)
                                       > min(radius[a], radius[c]) + TIE_DISTANCE)
    counts["pairs"] = int(seg.node_threads.sum() // 2)
    # the candidate pairs kept with a skin (multibody.segment_candidates; absent before helper speed21) and their builds
    if hasattr(seg, "candidate_count"):
        counts["listed"], counts["builds"] = int(seg.candidate_count[0]), int(seg.candidate_count[1])
    return counts


class PhaseClock:
    """CPU time (s) of each part of the step, summed per window of simulated time.

    Parameters
    ----------
    edges : (w + 1,) float
        Window edges (s of simulated time), increasing; steps past the last edge go to the last window.
    """

    def __init__(self, edges):
        self.edges = np.asarray(edges, float)
        n = len(self.edges) - 1
        self.cpu = {part: np.zeros(n) for part in PARTS}
        self.steps = np.zeros(n, np.int64)
        self.contacts = np.zeros(n)
        self.window = 0
        self.marks = []          # (window, CLOCK_MONOTONIC s) at each window's first step
        self._last_entry = None  # (window, process time) of the previous step's entry
        self.census_times = []   # s of simulated time at which to count the thread contact's pair search
        self.census = []         # (t, counts) (segment_census)
        self.skin = None         # the thread contact's candidate skin (m) set before the first step; None: default
        self.builds = np.zeros(n, np.int64)   # builds of the candidate pairs (multibody.segment_candidates) per window
        self._builds_seen = 0
        # pair tests skipped per window (multibody.segment_pairs, helper speed23): a pair's whole step by its clearance,
        # the test at the end of the free motion alone
        self.skips = np.zeros((n, 2), np.int64)
        self._skips_seen = np.zeros(2, np.int64)
        self._skip_window = 0
        # the kernel's candidate_count, read at each window's change only (read each step, it cost some 3 us a step
        # of numpy in the glue's column)
        self._skip_counters = None

    def count_skips(self) -> None:
        """The skips since the last call, to the window they were counted in (at a window's change and the end)."""
        if self._skip_counters is not None:
            self.skips[self._skip_window] += self._skip_counters[2:4] - self._skips_seen
            self._skips_seen = self._skip_counters[2:4].copy()
        self._skip_window = self.window

    def window_of(self, t: float) -> int:
        return int(min(max(np.searchsorted(self.edges, t, side="right") - 1, 0), len(self.edges) - 2))

    def step_entry(self, t: float) -> None:
        """A step's pre-step starts at evaluation time ``t`` (s): the time since the previous entry is that step's."""
        now = time.process_time()
        if self._last_entry is not None:
            self.cpu["total"][self._last_entry] += now - self._last_cpu
        k = self.window_of(t)
        if k != self.window or not self.marks:
            self.marks.append((k, time.clock_gettime(time.CLOCK_MONOTONIC)))
        self.window = k
        self.steps[k] += 1
        self._last_entry, self._last_cpu = k, now

    def add(self, part: str, seconds: float) -> None:
        self.cpu[part][self.window] += seconds

    def exclude(self, seconds: float) -> None:
        """Leave ``seconds`` of CPU spent inside this step (the census) out of its total."""
        self._last_cpu += seconds


def timed(clock: PhaseClock, part: str, function):
    """``function`` with its CPU time added to ``clock``'s ``part``."""
    def wrapper(*args, **kwargs):
        start = time.process_time()
        try:
            return function(*args, **kwargs)
        finally:
            clock.add(part, time.process_time() - start)
    return wrapper


def instrument(clock: PhaseClock) -> None:
    """Wrap the step's parts (module doc) so that their CPU time goes to ``clock``, with the step's penetrating
    contacts (node and thread, the kernel's scalar ``N_CONTACTS``)."""
    kernel_net_module.kernel_net_step = timed(clock, "kernel", kernel_net_module.kernel_net_step)
    call = kernel_net_module.KernelNet.__call__

    def pre_step(self, mbs, t):
        clock.step_entry(t)
        seg = self.kernel.buffers.segments
        listed = getattr(seg, "candidate_count", np.zeros(0))     # absent before helper speed21
        if clock.skin is not None and listed.size and clock._builds_seen == 0:
            seg.candidate_scalar[0] = clock.skin
        keep = call(self, mbs, t)
        clock.contacts[clock.window] += self.kernel.buffers.scalars[N_CONTACTS]
        if listed.size:
            clock.builds[clock.window] += listed[1] - clock._builds_seen
            clock._builds_seen = listed[1]
        if listed.size >= 4 and clock._skip_counters is None:        # the skip counters (helper speed23)
            clock._skip_counters = listed
        if clock.window != clock._skip_window:
            clock.count_skips()
        if clock.census_times and t >= clock.census_times[0]:
            clock.census_times.pop(0)
            start = time.process_time()
            clock.census.append((t, segment_census(self.kernel)))
            clock.exclude(time.process_time() - start)
        return keep

    kernel_net_module.KernelNet.__call__ = pre_step
    set_after_step = kernel_net_module.KernelNet.set_after_step

    def set_timed(self, after_step, start_time=0.0):
        set_after_step(self, None if after_step is None else timed(clock, "post", after_step), start_time)

    kernel_net_module.KernelNet.set_after_step = set_timed
    Recorder._check_capture = timed(clock, "capture", Recorder._check_capture)
    CaptureMonitor.sample = timed(clock, "capture", CaptureMonitor.sample)


def run_digest(folder: Path) -> str:
    """First 12 hex digits of the sha256 of the run's time series and net snapshots (keys and values, sorted)."""
    h = hashlib.sha256()
    for name in ("timeseries.npz", "net.npz"):
        with np.load(folder / name) as data:
            for key in sorted(data.files):
                h.update(key.encode())
                h.update(np.ascontiguousarray(data[key]).tobytes())
    return h.hexdigest()[:12]


def print_table(clock: PhaseClock, step: float) -> None:
    """Per window: steps, CPU per simulated second (s/s), us per step of each part, contacts per step."""
    clock.count_skips()
    print(f"{'window (s)':>14} {'steps':>7} {'CPU/sim-s':>9} {'total':>7} {'kernel':>7} {'post':>6} {'capture':>7} "
          f"{'other':>6} {'contacts':>8} {'builds':>7} {'skip/step':>9} {'end-skip':>8}   (us a step; CPU/sim-s in s "
          f"per simulated s; builds of the thread contact's candidate pairs; per step, pairs skipped whole by their "
          f"clearance and end-of-motion tests skipped)")
    for k in range(len(clock.steps)):
        n = clock.steps[k]
        if n == 0:
            continue
        us = {part: 1e6 * clock.cpu[part][k] / n for part in PARTS}
        other = us["total"] - us["kernel"] - us["post"]
        print(f"{clock.edges[k]:6.2f}-{clock.edges[k + 1]:6.2f} {n:7d} {clock.cpu['total'][k] / (n * step):9.2f} "
              f"{us['total']:7.1f} {us['kernel']:7.1f} {us['post']:6.1f} {us['capture']:7.2f} {other:6.1f} "
              f"{clock.contacts[k] / n:8.1f} {clock.builds[k]:7d} {clock.skips[k, 0] / n:9.1f} "
              f"{clock.skips[k, 1] / n:8.1f}")
    n = clock.steps.sum()
    total = {part: clock.cpu[part].sum() for part in PARTS}
    print(f"whole run: {n} steps, CPU {total['total']:.1f} s ({total['total'] / (n * step):.2f} s per simulated s): "
          f"kernel {total['kernel']:.1f} s, post-step {total['post']:.1f} s (capture monitor {total['capture']:.2f} s), "
          f"other {total['total'] - total['kernel'] - total['post']:.1f} s")
    for t, counts in clock.census:
        print(f"thread-contact pair search at {t:.4f} s: " + ", ".join(f"{k} {v}" for k, v in counts.items()))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("case")
    parser.add_argument("--store", required=True)
    parser.add_argument("--sample", type=int, default=0)
    parser.add_argument("--end-time", type=float, default=None)
    parser.add_argument("--release", default="never")
    parser.add_argument("--windows", default="0,0.5,3,10,20,40",
                        help="window edges (s of simulated time); the run's end closes the last")
    parser.add_argument("--perf-marks", action="store_true")
    parser.add_argument("--skin", type=float, default=None, help="the thread contact's candidate skin (m; "
                        "multibody.segment_candidates.CANDIDATE_SKIN unless given): changes the cost, not the run")
    parser.add_argument("--census", default="", help="times (s) at which to count the thread contact's pair search "
                        "(segment_census; its CPU time is left out of the step's)")
    args = parser.parse_args()
    overrides = sample_overrides(Path(args.store), args.sample) | {"structures.release": args.release}
    if args.end_time is not None:
        overrides["simulation.end_time"] = args.end_time
    case = validate_case(case_with(tomllib.loads(Path(args.case).read_text()), overrides), args.case)
    end_time = case.simulation.end_time
    edges = [e for e in (float(v) for v in args.windows.split(",")) if e < end_time] + [end_time]
    clock = PhaseClock(edges)
    clock.census_times = sorted(float(v) for v in args.census.split(",") if v)
    clock.skin = args.skin
    instrument(clock)
    print(f"{args.case}, sample {args.sample}: {overrides}")
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "run"
        load, start, wall = os.getloadavg()[0], time.process_time(), time.perf_counter()
        run_case(args.case, out, case=case, overwrite=True)
        cpu, wall = time.process_time() - start, time.perf_counter() - wall
        print(f"run_case: CPU {cpu:.1f} s, wall {wall:.1f} s, load average {load:.2f} -> {os.getloadavg()[0]:.2f}")
        print(f"trajectory hash (time series and net snapshots): {run_digest(out)}")
    print_table(clock, case.simulation.step)
    if args.perf_marks:
        for k, mark in clock.marks:
            print(f"perf mark: window {edges[k]:g}-{edges[k + 1]:g} s starts at CLOCK_MONOTONIC {mark:.6f}")
        print(f"perf mark: end at CLOCK_MONOTONIC {time.clock_gettime(time.CLOCK_MONOTONIC):.6f}")
        print(f"{write_perf_map()} symbols in /tmp/perf-{os.getpid()}.map", flush=True)


if __name__ == "__main__":
    main()
