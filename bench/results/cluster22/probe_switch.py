"""Sample 9 of the 1.0 m/s row run alone to END s, the companion threads (contact_segment._companion_threads) off until
T_ON s and on after it: the energy balance per window (the same trajectory as main's up to T_ON)."""
import sys, os, time, json, sqlite3, tomllib
from pathlib import Path
import numpy as np
import multibody.kernel_net as kernel_net_module
from multibody.impact import ImpactSimulation
from riskassess.cases.impact import validate_case
from riskassess.models.impact import model_inputs
from riskassess.sweep.spec import case_with

WT = "/work/wt-cluster22/bench/results/array_modes/"
CASE = WT + "envisat_small_segments_modes_high_135s.toml"
STORE = WT + "lead_safe_velocity_high_1p0_135s_store"

def sample_overrides(sample):
    with sqlite3.connect(STORE) as con:
        row = con.execute("select overrides from runs where sample = ? order by grid_index limit 1", (sample,)).fetchone()
    return json.loads(row[0])

class Switch:
    def __init__(self, sim, t_on):
        self.seg = sim.system.kernel.buffers.segments
        self.t_on, self.orig = t_on, kernel_net_module.kernel_net_step
        self.seg.companions[0] = 0
    def __enter__(self):
        kernel_net_module.kernel_net_step = self
        return self
    def __exit__(self, *a):
        kernel_net_module.kernel_net_step = self.orig
    def __call__(self, m, q_bodies, qt_bodies, qtt_bodies, t, q_next, force_bodies):
        if t >= self.t_on and self.seg.companions[0] == 0:
            self.seg.companions[0] = 1
            print(f"companions on at {t:.6f} s", flush=True)
        self.orig(m, q_bodies, qt_bodies, qtt_bodies, t, q_next, force_bodies)

end = float(sys.argv[1])
for t_on in [float(v) for v in sys.argv[2].split(",")]:
    ov = sample_overrides(9) | {"structures.release": "never", "simulation.end_time": end}
    case = validate_case(case_with(tomllib.loads(Path(CASE).read_text()), ov), CASE)
    inputs = model_inputs(case, Path(CASE).parent)
    sim = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
    sim.health.reference_energy = None
    start, load = time.process_time(), os.getloadavg()[0]
    with Switch(sim, t_on):
        s = sim.run().series
    t, tot, dc = s["time"], s["energy_total"], s["energy_dissipated_contact"]
    print(f"T_ON {t_on}: CPU {time.process_time() - start:.1f} s, load {load:.1f} -> {os.getloadavg()[0]:.1f}")
    for a, b in [(0, 71.4), (71.4, 87.0), (87.0, 87.6), (87.6, 87.7), (87.7, 87.8), (87.8, 87.9), (87.9, end)]:
        w = (t >= a) & (t <= b)
        print(f"  {a}-{b} s: balance {tot[w][0]:.4f} -> {tot[w][-1]:.4f} J ({tot[w][-1] - tot[w][0]:+.4f}), contact booked "
              f"{dc[w][-1] - dc[w][0]:+.4f} J, peak force main/asar {np.abs(s['contact_force_lvlh'][w, 0]).max():.0f} / "
              f"{np.abs(s['contact_force_lvlh'][w, 2]).max():.0f} N", flush=True)
    print(f"  largest drift over the run {100 * np.max(np.abs(tot - tot[0])) / tot[0]:.3f} % of the start's {tot[0]:.4f} J", flush=True)
    np.savez(f"/tmp/cluster22/switch_{t_on}.npz", time=t, total=tot, contact=dc)
