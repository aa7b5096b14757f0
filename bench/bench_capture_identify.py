"""f1/f2 table of identifications against full-net runs (Boonrath, Singh & Botta 2024, Sec. 4.4, Tables 7-10):
reads the ``identification.json`` and cached full-net runs of one or more ``riskassess identify`` output
folders (wrapped or capture start) and prints, per folder, each identified s and, for comparison, the
paper's f1 and f2 optima and s0 evaluated on the same data: s, training f1 and f2, validation f1 and f2
(summed over the runs, eqs. 18, 20) and the mean RMSE per channel over the validation runs.

    python bench/bench_capture_identify.py CASE:OUT [CASE:OUT ...]

CASE is the towing case file the folder OUT was identified with (its full_net.start says which start).
Only lower-order runs are made here (the full-net runs are the folder's cache).
"""
from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase
from riskassess.stages.identify_fullnet import _totals, comparison_rows, full_net_runs, lower_order_case

#: Reference decision vectors: the paper's f1 and f2 PSO 1 optima (Tables 7, 8) and its initial guess s0.
REFERENCES = {"paper f1 PSO 1 (Table 7)": [1.4422, 6.851, 2.106, 0.1],
              "paper f2 PSO 1 (Table 8)": [2.6822, 8.8304, 2.7865, 0.1533], "s0": [1.0, 6.0, 3.0, 0.25]}


def rows_for(case_path: str, out: str):
    """(label, s, training totals, validation totals) of every optimizer of the folder and every reference."""
    case = load_model(case_path, TowingCase)
    answer = json.loads((Path(out) / "identification.json").read_text())
    end = answer["end_time_s"]
    training, validation = answer["training_rates_deg_s"], answer["validation_rates_deg_s"]
    data = full_net_runs(case, list(training) + list(validation), Path(out), end, 1)
    train, valid = data[:len(training)], data[len(training):]
    lower = lower_order_case(case, data[0])
    rows = [(f"ours, {name}, {answer['cost_function']}", run["s"], run["training_totals"], run["validation_totals"])
            for name, run in answer["runs"].items()]
    for label, s in REFERENCES.items():
        rows.append((label, s, _totals(comparison_rows(lower, np.asarray(s), train, end)),
                     _totals(comparison_rows(lower, np.asarray(s), valid, end))))
    return case, answer, rows


def main():
    print("| start | s | s1 | s2 (m) | s3 | s4 | training f1 | training f2 (N) | validation f1 | validation f2 (N) "
          "| validation mean RMSE r_D/C (m), omega_C, omega_D (rad/s), T_MT (N) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    printed = set()
    for arg in sys.argv[1:]:
        case_path, out = arg.split(":", 1)
        case, answer, rows = rows_for(case_path, out)
        start = f"{case.full_net.start}, {len(answer['training_rates_deg_s'])}+{len(answer['validation_rates_deg_s'])} runs, " \
                f"to {answer['end_time_s']:g} s"
        for label, s, tr, va in rows:
            if (start, label) in printed:
                continue   # the references once per data set
            printed.add((start, label))
            rmse = ", ".join(f"{va['mean_rmse_' + c]:.3g}" for c in ("relative_position", "chaser_omega_body",
                                                                      "debris_omega_body", "main_tether_tension"))
            print(f"| {start} | {label} | {s[0]:.4f} | {s[1]:.4f} | {s[2]:.4f} | {s[3]:.4f} | {tr['f1']:.3f} | "
                  f"{tr['f2']:.1f} | {va['f1']:.3f} | {va['f2']:.1f} | {rmse} |")


if __name__ == "__main__":
    main()
