"""Energy-balance probe (drift23; made path-independent by loop23): run a case (a sample of a store) to END with overrides; print the energy balance per window and
the booked terms; save the energy series. python probe.py LABEL END [key=value ...] [--sample N] [--case C] [--store S]"""
import os, time, json, sqlite3, tomllib, argparse
from pathlib import Path
import numpy as np
from multibody.impact import ImpactSimulation
from riskassess.cases.impact import validate_case
from riskassess.models.impact import model_inputs
from riskassess.sweep.spec import case_with

WT = str(Path(__file__).resolve().parents[1]) + "/"
p = argparse.ArgumentParser()
p.add_argument("label"); p.add_argument("end", type=float); p.add_argument("sets", nargs="*")
p.add_argument("--sample", type=int, default=1)
p.add_argument("--case", default=WT + "closing/envisat_small_segments_modes_high_closing.toml")
p.add_argument("--store", default=WT + "array_modes/lead_safe_velocity_high_1p0_135s_store")
p.add_argument("--windows", default="0,14.9,20,25,26,30,35,40")
a = p.parse_args()
ov = {}
if a.sample >= 0:
    with sqlite3.connect(a.store) as con:
        ov = json.loads(con.execute("select overrides from runs where sample = ? order by grid_index limit 1", (a.sample,)).fetchone()[0])
ov |= {"structures.release": "never", "simulation.end_time": a.end}
for s in a.sets:
    k, v = s.split("=", 1)
    ov[k] = json.loads(v) if v[:1] in "[{0123456789-." or v in ("true", "false", "null") else v
print(a.label, ov, flush=True)
case = validate_case(case_with(tomllib.loads(Path(a.case).read_text()), ov), a.case)
inputs = model_inputs(case, Path(a.case).parent)
sim = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
sim.health.reference_energy = None
start, load = time.process_time(), os.getloadavg()[0]
s = sim.run().series
print(f"CPU {time.process_time() - start:.1f} s, load {load:.1f} -> {os.getloadavg()[0]:.1f}")
t, tot = s["time"], s["energy_total"]
keys = [k for k in s if k.startswith("energy_")]
os.makedirs("/tmp/probe", exist_ok=True)
np.savez(f"/tmp/probe/probe_{a.label}.npz", time=t, **{k: s[k] for k in keys})
e0 = tot[0]
ws = [float(x) for x in a.windows.split(",")] + [a.end]
for x, y in zip(ws[:-1], ws[1:]):
    w = (t >= x) & (t <= y)
    if not w.any(): continue
    d = lambda k: s[k][w][-1] - s[k][w][0]
    print(f"  {x:6.2f}-{y:6.2f} s: balance {tot[w][-1]-tot[w][0]:+.5f} J (cum {100*(tot[w][-1]-e0)/e0:+.3f} %, min {100*(tot[w].min()-e0)/e0:+.3f}, max {100*(tot[w].max()-e0)/e0:+.3f}); "
          f"winch {d('energy_winch_work'):+.3f} thr.diss {d('energy_dissipated_threads'):+.3f} cont.diss {d('energy_dissipated_contact'):+.3f} KE_net end {s['energy_net_kinetic'][w][-1]:.3f}")
i = np.abs(tot - e0).argmax()
print(f"  largest drift {100*abs(tot[i]-e0)/e0:.3f} % at {t[i]:.3f} s of e0 {e0:.4f} J", flush=True)
