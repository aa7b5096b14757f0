"""Demand if held: each weak location's utilization against the impact velocity, with joint release off.

    python3 bench/bench_velocity_envelope.py [CASE] [--velocities 2:25:8] [--workers 2]

A joint released at its first exceedance carries nothing afterwards, so a sweep with release on
records for it the demand at release, and its utilization hardly moves with the impact energy
(envisat_small's array hinge: 1.11 / 1.16 / 1.15 at 5 / 12.5 / 20 m/s). With ``structures.release = "never"`` every
joint holds whatever it carries, so the recorded peak is the demand it would see if it held. This
script runs the case (default ``cases/envisat_small.toml``) that way at each velocity on the sweep
runner and prints, per velocity, every location's utilization (peak / decisive allowable), its
peak's time, and the impact's kinetic energy scale v^2 relative to the first velocity. Prints the
load with the wall time.
"""
from __future__ import annotations

import argparse
import os
import tempfile
import time
from pathlib import Path

from riskassess.sweep.runner import run_sweep
from riskassess.sweep.spec import parse_vary, run_specs
from riskassess.sweep.store import ResultStore

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_small.toml"))
    parser.add_argument("--velocities", default="2:25:8", help="START:STOP:N (m/s)")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    text = Path(args.case).read_text()
    if 'release = "low"' not in text:
        raise SystemExit(f"{args.case}: expected release = \"low\" in [structures] to switch it off")
    with tempfile.TemporaryDirectory() as tmp:
        case = Path(tmp) / "held.toml"
        case.write_text(text.replace('release = "low"', 'release = "never"', 1))
        for data in ("data", "meshes"):
            if (Path(args.case).parent / data).exists():
                os.symlink((Path(args.case).parent / data).resolve(), Path(tmp) / data)
        specs = run_specs([parse_vary(f"launch.velocity={args.velocities}")])
        start, load = time.perf_counter(), os.getloadavg()[0]
        with ResultStore(Path(tmp) / "held.sqlite") as store:
            outcome = run_sweep(str(case), specs, store, {"arguments": []}, n_workers=args.workers)
            rows = store.rows()
        wall = time.perf_counter() - start
    names = sorted({n for r in rows if r["result"] for n in r["result"]["locations"]})
    print(f"{args.case} with release off, {outcome.done} runs ({outcome.failed} failed) in {wall:.0f} s on "
          f"{args.workers} workers; load average {load:.1f} -> {os.getloadavg()[0]:.1f}")
    print("velocity m/s  v^2/v0^2  " + "  ".join(f"{n[:22]:>22s}" for n in names) + "  state")
    v0 = min(r["overrides"]["launch.velocity"] for r in rows)
    for r in rows:
        v = r["overrides"]["launch.velocity"]
        if not r["result"]:
            print(f"{v:12.2f}  {(v / v0) ** 2:8.1f}  failed: {r['error']}")
            continue
        cells = []
        for n in names:
            loc = r["result"]["locations"].get(n, {})
            u = loc.get("utilization")
            cells.append(f"{u:22.3g}" if u is not None else f"{'-':>22s}")
        print(f"{v:12.2f}  {(v / v0) ** 2:8.1f}  " + "  ".join(cells) + f"  {r['debris_state']}")


if __name__ == "__main__":
    main()
