"""Capture-start probe: what the net does between its ejection and the tow (issue 27: the captures at
28.25 and 29.01 deg/s fail; the paper captured at every Table 3 rate).

    python bench/bench_capture_probe.py --rates 9.60 20.44 28.25 --end 30 --out bench/results/capture_probe.json
    python bench/bench_capture_probe.py --table bench/results/capture_probe.json

Runs the case's capture start (``full_net.start = "capture"``) at each rate from the ejection to ``--end``
with net snapshots every ``--snap`` s (keys of the case can be changed with ``--set full_net.launch_speed=4``)
and records, in the debris body frame (the spin axis is body y, which points from the debris to the chaser's
side: the net arrives from y < 0):

* first contact (first sample with a node in contact) and the angle the debris turns from it to the end
  of the closing (``closing_time + closing_duration``): the net's closing time against the spin;
* the closing loop: mean y of its twelve lacing points and their mean distance from the spin axis
  (a loop behind the cylinder, y > radius, closed to less than the cylinder's half length holds it);
* the central node's position and the main-tether tension, the closing-loop peak tension, the contact count;
* the net's centre of mass velocity relative to the debris along y (m/s; < 0: moving back to the chaser).

Each rate is one run (resumable: a rate already in ``--out`` is skipped); results are written after each.
"""
from __future__ import annotations

import argparse
import json
import os
import time

import numpy as np

from multibody.net_towing import run_exudyn
from multibody.net_towing_kernel import cylinder_distance
from multibody.closing import closing_loop
from riskassess.cases.impact import load_model
from riskassess.cases.towing import TowingCase
from riskassess.models.towing_fullnet import debris_geometry, full_net_model

CASE = os.path.join(os.path.dirname(__file__), "..", "cases", "zenit2_towing.toml")


def with_settings(case, settings):
    """The case with ``section.key=value`` settings applied (values parsed as JSON)."""
    data = case.model_dump()
    for item in settings:
        key, value = item.split("=", 1)
        *path, last = key.split(".")
        node = data
        for p in path:
            node = node[p]
        node[last] = json.loads(value)
    return TowingCase.model_validate(data)


def snapshot_figures(x_body, geometry, loop, central, masses):
    """Shape figures of one net snapshot in the debris body frame (m)."""
    clear = np.array([cylinder_distance(p[0], p[1], p[2], geometry)[0] for p in x_body])
    ring = x_body[loop]
    return {"loop_y": float(ring[:, 1].mean()), "loop_radius": float(np.hypot(ring[:, 0], ring[:, 2]).mean()),
            "loop_behind": int(np.sum(ring[:, 1] > geometry[0])),
            "central": x_body[central].tolist(), "near_fraction": float(np.mean(clear < 0.5)),
            "median_clearance": float(np.median(clear)), "max_clearance": float(clear.max()),
            "com_y": float(masses @ x_body[:, 1] / masses.sum())}


def probe(case, rate, end, snap):
    """One capture run to ``end`` (s); figures per snapshot and the run's event times."""
    case = case.model_copy(update={"full_net": case.full_net.model_copy(update={"net_output_interval": snap})})
    model = full_net_model(case, rate, end_time=end)
    t0 = time.process_time()
    result = run_exudyn(model)
    cpu = time.process_time() - t0
    s = result.series()
    geometry = debris_geometry(case)
    loop = closing_loop(case.full_net.nodes_per_side)
    masses = model.net.topology.masses
    t = s["time"]
    rot = s["debris_to_inertial"]
    snaps = []
    for k, (tn, nodes) in enumerate(zip(s["net_time"], s["net_nodes_inertial"])):
        i = int(np.argmin(abs(t - tn)))
        x_body = (nodes - s["debris_com_inertial"][i]) @ rot[i]
        a_point = s["chaser_com_inertial"][i] + s["chaser_to_inertial"][i] @ model.attach_chaser_body
        ring = nodes[loop]
        snaps.append({"t": float(tn), **snapshot_figures(x_body, geometry, loop, model.net.central, masses),
                      "tether_distance": float(np.linalg.norm(nodes[model.net.central] - a_point)),
                      "loop_length": float(np.linalg.norm(ring - np.roll(ring, -1, axis=0), axis=1).sum())})
    for a, b in zip(snaps[:-1], snaps[1:]):
        a["com_vy"] = (b["com_y"] - a["com_y"]) / (b["t"] - a["t"])
    contact = s["net_contacts"] > 0
    first = float(t[contact.argmax()]) if contact.any() else None
    closed = case.full_net.closing_time + case.full_net.closing_duration
    w = np.linalg.norm(s["debris_omega_body"], axis=1)
    dt = np.diff(t, prepend=t[0])
    turned = float(np.degrees(np.sum((w * dt)[(t > first) & (t <= closed)]))) if first is not None else None
    samples = [{"t": float(t[k]), "T_MT": float(s["main_tether_tension"][k]),
                "closing": float(s["closing_thread_peak_tension"][k]), "contacts": float(s["net_contacts"][k]),
                "z": float(s["main_tether_elongation"][k])} for k in range(len(t))]
    return {"rate_deg_s": rate, "end_s": end, "cpu_s": cpu, "first_contact_s": first, "closed_s": closed,
            "turned_contact_to_closed_deg": turned, "turned_per_s_deg": float(np.degrees(w[0])),
            "separation_end_m": float(np.linalg.norm(s["debris_com_inertial"][-1] - s["chaser_com_inertial"][-1])),
            "separation_max_m": float(np.linalg.norm(s["debris_com_inertial"] - s["chaser_com_inertial"], axis=1).max()),
            "spin_end_deg_s": float(np.degrees(w[-1])),
            "peak_tension_after_25_s_N": float(s["main_tether_tension"][t >= 25.0].max(initial=0.0)),
            "slack_share_after_25_s": float(np.mean(s["main_tether_tension"][t >= 25.0] <= 0.0)) if end > 25.0 else None,
            "snapshots": snaps, "samples": samples}


def table(path):
    """Print per rate: first contact, turned angle, the loop and central node at key times, tensions."""
    runs = json.load(open(path))
    print("| rate (deg/s) | first contact (s) | debris turned contact -> closed (deg) | loop y / radius at 15 s (m) | "
          "loop y / radius at 20 s (m) | lacing points behind at 20 s | central node y at 15, 20, 25 s (m) | "
          "peak T_MT 15-25 s (N) | peak closing (N) | mean contacts 10-25 s | separation at end (m) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for key, r in sorted(runs.items(), key=lambda kv: kv[1]["rate_deg_s"]):
        snaps = {round(x["t"], 3): x for x in r["snapshots"]}
        at = lambda tt: snaps.get(round(tt, 3)) or min(r["snapshots"], key=lambda x: abs(x["t"] - tt))
        smp = r["samples"]
        peak = max((x["T_MT"] for x in smp if 15 <= x["t"] <= 25), default=float("nan"))
        closing = max(x["closing"] for x in smp)
        contacts = np.mean([x["contacts"] for x in smp if 10 <= x["t"] <= 25])
        print(f"| {key} | {r['first_contact_s']} | "
              f"{r['turned_contact_to_closed_deg']:.0f} | {at(15)['loop_y']:.2f} / {at(15)['loop_radius']:.2f} | "
              f"{at(20)['loop_y']:.2f} / {at(20)['loop_radius']:.2f} | {at(20)['loop_behind']} | "
              f"{at(15)['central'][1]:.2f}, {at(20)['central'][1]:.2f}, {at(min(25, r['end_s']))['central'][1]:.2f} | "
              f"{peak:.0f} | {closing:.0f} | {contacts:.1f} | {r['separation_end_m']:.1f} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--rates", type=float, nargs="*", default=[])
    ap.add_argument("--end", type=float, default=30.0)
    ap.add_argument("--snap", type=float, default=0.5)
    ap.add_argument("--set", nargs="*", default=[], help="case settings section.key=JSON value")
    ap.add_argument("--label", default="", help="suffix of the result keys (a variant of the case)")
    ap.add_argument("--out", default="bench/results/capture_probe.json")
    ap.add_argument("--table", default=None)
    a = ap.parse_args()
    if a.table:
        table(a.table)
        return
    case = load_model(CASE, TowingCase)
    case = case.model_copy(update={"full_net": case.full_net.model_copy(update={"start": "capture"})})
    case = with_settings(case, a.set)
    runs = json.load(open(a.out)) if os.path.exists(a.out) else {}
    for rate in a.rates:
        key = f"{rate:.2f}" + (f" {a.label}" if a.label else "")
        if key in runs:
            continue
        r = probe(case, rate, a.end, a.snap)
        r["settings"] = a.set
        runs[key] = r
        tmp = a.out + ".tmp"
        json.dump(runs, open(tmp, "w"))
        os.replace(tmp, a.out)
        print(f"{key}: first contact {r['first_contact_s']} s, turned {r['turned_contact_to_closed_deg']:.0f} deg "
              f"to closed, separation {r['separation_end_m']:.1f} m, CPU {r['cpu_s']:.0f} s", flush=True)


if __name__ == "__main__":
    main()
