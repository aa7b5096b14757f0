"""envisat_small with thread contact on, energy limit lifted: drift series, per-thread record."""
import os, sys, time, numpy as np, tomllib, tempfile
from pathlib import Path
sys.path.insert(0, "bench")
from bench_thread_segments import case_text
from riskassess.cases.impact import load_case
from riskassess.models.impact import model_inputs
from multibody.impact import ImpactSimulation
case_path = Path(os.environ.get("CASE", "cases/envisat_small.toml"))
end = float(os.environ.get("END", "7.5")); vel = os.environ.get("VEL")
text = case_text(case_path.read_text(), os.environ.get("KEY", "on") == "on", end, float(vel) if vel else None, os.environ.get("RELEASE"))
tmp = Path(tempfile.mkdtemp()) / case_path.name
tmp.write_text(text)
for f in case_path.parent.iterdir():
    if f.suffix != ".toml" and not (tmp.parent / f.name).exists():
        os.symlink(f.resolve(), tmp.parent / f.name)
case = load_case(tmp)
asm = model_inputs(case, tmp.parent).assembly
sim = ImpactSimulation(asm)
REF = sim.health.reference_energy
sim.health.reference_energy = None
t0 = time.process_time()
rec = sim.run()
cpu = time.process_time() - t0
s = rec.series
ref = REF
E = s["energy_total"]; t = s["time"]
# reference energy as the health check: use the launch kinetic energy of net and bodies
drift = (E - E[0]) / ref
print(f"{case_path.name} key {os.environ.get('KEY','on')} end {end}: CPU {cpu:.1f} s, load {os.getloadavg()[0]:.1f}; "
      f"largest |drift| {100*np.abs(drift).max():.2f} % (at {t[np.abs(drift).argmax()]:.3f} s), end {100*drift[-1]:+.2f} % of the reference energy {ref:.0f} J", flush=True)
for tt in (0.1, 0.2, 0.5, 1, 2, 2.5, 3, 4, 5, 6, 7, 7.5):
    k = np.searchsorted(t, tt) - 1
    if 0 <= k < len(t): print(f"   t {t[k]:.3f}  drift {100*drift[k]:+.3f} %")
d = np.diff(drift)
for k in np.argsort(-d)[:10]:
    print("   gain at t %.4f: %+.3f %%" % (t[k+1], 100*d[k]))
seg = sim.system.kernel.buffers.segments
if seg.enabled:
    print("   per-thread: made between steps %.3f %% (largest thread %.3f %%), dissipated %.2f %%" % (
        100*seg.energy_jump.sum()/ref, 100*seg.energy_jump.max()/ref, 100*seg.dissipated.sum()/ref))
    top = np.argsort(-np.abs(seg.energy_jump))[:5]
    print("   threads", top.tolist(), (100*seg.energy_jump[top]/ref).round(3).tolist())
np.savez(os.environ.get("SAVE", "/tmp/t12_case.npz"), t=t, drift=drift)
