"""The energy balance's drift of kept impact runs, per phase of a closed capture (helper loop23, after drift23's table).

    python3 bench/results/loop23/phases.py KEPT_DIR [KEPT_DIR ...]

Per run: the step, the time simulated, the largest drift (% of the first recorded total, summary.json's measure) and
when, the winch's work, the loop's and the net's booked thread dissipation; then per phase (flight and wrap 0-14.9 s,
reel-in 14.9-26 s, after the closing 26-40 s, 40-135 s, 135 s-end) its start, end, lowest and highest drift.
"""
import json
import sys
from pathlib import Path

import numpy as np

PHASES = [(0.0, 14.9), (14.9, 26.0), (26.0, 40.0), (40.0, 135.0), (135.0, np.inf)]

for folder in map(Path, sys.argv[1:]):
    series = np.load(folder / "timeseries.npz")
    t, total = series["time"], series["energy_total"]
    drift = 100.0 * (total - total[0]) / total[0]
    i = int(np.abs(drift).argmax())
    summary = json.loads((folder / "summary.json").read_text())
    step = json.loads((folder / "case.json").read_text())["simulation"]["step"]
    winch = -series["energy_winch_work"][-1] if "energy_winch_work" in series.files else float("nan")
    print(f"{folder}: step {step:g} s, {t[-1]:.2f} s simulated; largest {drift[i]:+.3f} % at {t[i]:.3f} s (summary "
          f"{100 * summary['checks']['energy_balance_relative_drift']:.3f} %); winch {winch:.2f} J; threads "
          f"dissipated {series['energy_dissipated_threads'][-1]:.2f} J")
    for a, b in PHASES:
        m = (t >= a) & (t < b)
        if m.any():
            print(f"   [{a:g}, {b:g}) s: start {drift[m][0]:+.3f} end {drift[m][-1]:+.3f} lowest {drift[m].min():+.3f} "
                  f"at {t[m][drift[m].argmin()]:.2f} s, highest {drift[m].max():+.3f}")
