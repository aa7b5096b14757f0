"""Summary of a safe-velocity store judged over the whole capture: one line a finished run, then the ranges
(lead, 2026-11-28).

    python3 bench/results/array_modes/row_summary.py STORE
"""
import json
import re
import sqlite3
import sys


def main(store: str) -> None:
    c = sqlite3.connect(f"file:{store}?mode=ro", uri=True)
    rows = [(s, st, ds, w, json.loads(r or "{}")) for s, st, ds, w, r in
            c.execute('select sample, state, debris_state, wall_s, result from runs where state != "pending" order by sample')]
    print("sample  state  debris_state   array_util  array_Nm  drift_%  rel_energy_end_J  last_rise_s  rising_at_end  wall_s")
    for s, st, ds, w, r in rows:
        loc = r["locations"]["solar_array_hinge_panel"]
        cw = r["capture_window"]
        m = re.search(r"demand rising at [\d.]+ s \(([^)]*)\)", loc.get("indeterminate_reason") or "")
        print(f"{s:6d}  {st:5s}  {ds or '':13s}  {loc['utilization']:10.3f}  {loc['peaks']['moment']:8.1f}  "
              f"{100 * r['energy_balance_relative_drift']:7.3f}  {cw['net_energy_relative_end_J']:16.3f}  "
              f"{cw['last_rise_s']:11.3f}  {m.group(1) if m else '-':>13s}  {w:6.0f}")
    u = [r["locations"]["solar_array_hinge_panel"]["utilization"] for *_, r in rows]
    d = [100 * r["energy_balance_relative_drift"] for *_, r in rows]
    e = [r["capture_window"]["net_energy_relative_end_J"] for *_, r in rows]
    n, debris = len(rows), sum(ds == "debris" for _, _, ds, *_ in rows)
    settled = sum(bool(r["capture_window"]["settled"]) for *_, r in rows)
    print(f"{n} finished, {debris} with debris, {settled} captures over by the rule; array utilization "
          f"{min(u):.3f}-{max(u):.3f}, drift {min(d):.2f}-{max(d):.2f} %, relative energy at the end {min(e):.3f}-{max(e):.3f} J")
    if debris == 0:
        print(f"read over the fixed window: {n} of {n} without debris, P(no debris) >= {0.05 ** (1 / n):.3f} at 95 % confidence")


if __name__ == "__main__":
    main(sys.argv[1])
