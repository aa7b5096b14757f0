"""The largest safe impact velocity at 95 % confidence and 90 % reliability, by Monte Carlo.

    python3 bench/bench_safe_velocity.py [CASE] [--velocities 2:5:4] [--runs 29] [--workers 2]
                                         [--uncertain KEY=DIST(...) ...] [--seed 0] [--store PATH]

At each velocity, ``--runs`` Monte Carlo samples (29 by default: 0.9^29 = 0.047, the fewest debris-free
runs that show P(no debris) >= 90 % at 95 % confidence) of the uncertain inputs (default: the paper's
static friction and Hunt-Crossley damping with an assumed spread, and the aim point +-0.5 m along the
array), on the project's sweep runner into a fresh store. Prints per velocity the runs, those with
debris and the unknown ones (failed or indeterminate: counted as debris, never safe), the one-sided
Clopper-Pearson lower bound of P(no debris), the largest utilization, and the envelope's statement, with
the wall time and the load; then why the indeterminate runs are indeterminate: per velocity, the number of
runs each (location, rule) made so (the rules of structures.indeterminacy.RULES; the store keeps
each run's reasons), and one reason in full per rule. A store written before the reasons were kept counts
its runs under "not_recorded". Default case: cases/envisat_small.toml (the reference case needs ~1 h for
116 runs on 2 cores). ``--store PATH`` keeps the runs in that store (a re-run resumes it: the finished runs
are found, not run again); by default a temporary one.
"""
from __future__ import annotations

import argparse
import contextlib
import os
import tempfile
import time
from pathlib import Path

from riskassess.cases.uncertain import parse_uncertain
from riskassess.products.envelope import envelope, envelope_statement
from riskassess.products.sweep_records import indeterminate_reasons_of, indeterminate_rule_counts
from riskassess.sweep.runner import run_sweep
from riskassess.sweep.spec import parse_vary, run_specs
from riskassess.sweep.store import ResultStore

ROOT = Path(__file__).resolve().parents[1]
#: [paper T2] mu_s = 0.19, alpha = 0.05 s/m with an assumed spread (mu_s stays above mu_k = 0.152);
#: the aim point +-0.5 m along the array [assumed].
DEFAULT_UNCERTAIN = ["contact.mu_static=uniform(0.16,0.228)", "contact.hunt_crossley_alpha=uniform(0.04,0.06)",
                     "launch.aim_point[2]=uniform(6.5,7.5)"]


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_small.toml"))
    parser.add_argument("--velocities", default="2:5:4", help="START:STOP:N (m/s)")
    parser.add_argument("--runs", type=int, default=29)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--uncertain", action="append", default=None)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--store", default=None, help="results store to keep and resume (default: a temporary one)")
    args = parser.parse_args()
    uncertain = [parse_uncertain(u) for u in (args.uncertain or DEFAULT_UNCERTAIN)]
    specs = run_specs([parse_vary(f"launch.velocity={args.velocities}")], uncertain, args.runs, args.seed)
    start, load = time.perf_counter(), os.getloadavg()[0]
    where = contextlib.nullcontext(None) if args.store else tempfile.TemporaryDirectory()
    with where as tmp, ResultStore(Path(args.store) if args.store else Path(tmp) / "safe.sqlite") as store:
        outcome = run_sweep(args.case, specs, store, {"arguments": []}, n_workers=args.workers)
        rows = store.rows()
    wall = time.perf_counter() - start
    env = envelope(rows, "launch.velocity", confidence=0.95, reliability=0.9)
    print(f"{args.case}: {outcome.total} runs ({outcome.failed} failed) in {wall:.0f} s on {args.workers} workers; "
          f"load average {load:.1f} -> {os.getloadavg()[0]:.1f}")
    print("velocity m/s  runs  with debris  unknown  P(no debris) >= (95 %)  max utilization  safe")
    for p in env["points"]:
        utilization = "-" if p["max_utilization"] is None else f"{p['max_utilization']:.3f}"
        print(f"{p['value']:12.2f}  {p['total_runs']:4d}  {p['with_debris']:11d}  {p['unknown_runs']:7d}  "
              f"{p['no_debris_lower_bound']:22.3f}  {utilization:>15s}  {'yes' if p['safe'] else 'NO'}")
    print(envelope_statement(env))
    print_indeterminate_reasons(rows)


def print_indeterminate_reasons(rows: list[dict]) -> None:
    """Per velocity, the indeterminate runs per (location, rule), then one full reason per rule."""
    by_velocity: dict = {}
    for row in rows:
        by_velocity.setdefault(row["overrides"].get("launch.velocity"), []).append(row)
    print("why indeterminate (runs per location and rule; a run can count under several)")
    examples = {}
    for velocity in sorted(by_velocity, key=lambda v: (v is None, v)):
        counts = indeterminate_rule_counts(by_velocity[velocity])
        shown = ", ".join(f"{loc or 'run'}: {rule} {n}" for (loc, rule), n in counts.items()) or "none"
        print(f"{velocity:12.2f}  {shown}" if velocity is not None else f"{'-':>12s}  {shown}")
        for row in by_velocity[velocity]:
            for r in indeterminate_reasons_of(row["result"]) if row["state"] == "done" and row["result"] else []:
                examples.setdefault(r["rule"], f"{r['location'] or 'run'} at {velocity} m/s: {r['reason']}")
    for rule, text in examples.items():
        print(f"  {rule}, e.g. {text}")


if __name__ == "__main__":
    main()
