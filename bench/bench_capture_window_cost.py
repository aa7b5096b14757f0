"""CPU of the capture window's settle check (structures.window = "capture") against the fixed window, same run.

    python3 bench/bench_capture_window_cost.py [CASE] [--end-time T] [--repeats N]

Runs CASE (default cases/envisat_small.toml; release "never", every allowable_moment range x 100 so that nothing
is released) over T s (default 3) through the pipeline (:func:`riskassess.stages.run.run_case`), alternately with
``structures.window = "fixed"`` and ``"capture"``, N times each (default 2), and prints the CPU time of each run, the
load, and the capture's state at the end (a capture that is not over runs the check to the end: the full cost).
"""
from __future__ import annotations

import argparse
import os
import re
import tempfile
import time
from pathlib import Path

from riskassess.stages.run import run_case

ROOT = Path(__file__).resolve().parents[1]


def case_text(case: Path, end_time: float, window: str) -> str:
    """The case with end_time, release "never", the window and allowable moments x 100."""
    text = re.sub(r"end_time = [0-9.eE+-]+", f"end_time = {end_time}", case.read_text(), count=1)
    text = re.sub(r'release = "[a-z]+"', f'release = "never"\nwindow = "{window}"', text, count=1)
    return re.sub(r"allowable_moment = \[([0-9.eE+-]+), ([0-9.eE+-]+)\]",
                  lambda m: f"allowable_moment = [{100 * float(m[1])}, {100 * float(m[2])}]", text)


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("case", nargs="?", default=str(ROOT / "cases" / "envisat_small.toml"))
    parser.add_argument("--end-time", type=float, default=3.0)
    parser.add_argument("--repeats", type=int, default=2)
    args = parser.parse_args()
    case = Path(args.case).resolve()
    with tempfile.TemporaryDirectory(dir=case.parent if os.access(case.parent, os.W_OK) else None) as tmp:
        for _ in range(args.repeats):
            for window in ("fixed", "capture"):
                path = Path(tmp) / f"case_{window}.toml"
                path.write_text(case_text(case, args.end_time, window))
                load, start = os.getloadavg()[0], time.process_time()
                out = run_case(path, Path(tmp) / f"run_{window}", overwrite=True)
                capture = (out.structures or {}).get("capture_window") or {}
                print(f"{window:8s} CPU {time.process_time() - start:6.2f} s, load {load:.1f} -> {os.getloadavg()[0]:.1f}; "
                      f"answer {out.structures['debris_state']}; capture over: {capture.get('settled')}, "
                      f"relative energy at the end {capture.get('net_energy_relative_end_J')}")


if __name__ == "__main__":
    main()
