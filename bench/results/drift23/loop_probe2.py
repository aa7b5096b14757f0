"""drift23: the closing loop's own balance in Verlet's terms, per step, on the same trajectory as the plain run.
python loop_probe2.py CASE END OUT.npz (CASE without a thread_segments line: the key is inserted on, e.g. s1_closing.toml less its line; loop_at.py, loop2_at.py read OUT)
Per step (after the kernel's net step; arrays as used in that step's evaluation):
  loop: work of the 12 loop threads' forces on the nodes, h f(x(n+1), v(n+1/2)) . v(n+1) (J, running);
        their elastic energy at x(n+1); their damper power as booked, P(v(n+1/2)) h (running); the damper part's work
        h (T - k s) l'(n+1) (running).
  net threads (all threads but the loop): the same four."""
import sys, os, time
from pathlib import Path
import numpy as np
sys.path.insert(0, "/work/wt-drift23/bench")
import multibody.kernel_net as kernel_net_module
from multibody.impact import ImpactSimulation
from riskassess.cases.impact import load_case
from riskassess.models.impact import model_inputs
from multibody.net import PADDING_REST_LENGTH

case_path, end, out = Path(sys.argv[1]), float(sys.argv[2]), sys.argv[3]
import tempfile
from bench_thread_segments import case_text
with tempfile.TemporaryDirectory() as folder:
    p = Path(folder) / case_path.name
    p.write_text(case_text(case_path.read_text(), True, end, None, None))
    assembly = model_inputs(load_case(p), case_path.parent).assembly
sim = ImpactSimulation(assembly)
sim.health.reference_energy = None
kn = sim.system.kernel_net; kernel = sim.system.kernel
net = kernel.net
runs = net.thread_runs
real = np.flatnonzero(runs.rest_lengths != PADDING_REST_LENGTH)
threads = np.asarray(net.threads, np.int64)
m = threads.shape[0]
assert len(real) == m
inv_mass = 1.0 / np.asarray(net.mass, float)
step = kernel.step
force = kernel.buffers.work_soa[2]
ref = net.reference_lvlh
damping_all = runs.damping
groups = {"loop": np.arange(m - 12, m), "net": np.arange(0, m - 12)}
n_steps = int(round(end / step)) + 2
rec = np.zeros((n_steps, 1 + 4 * 2 + 4))
winch = sim.system.closing
prev_taut = np.zeros(12, bool)
tot = np.zeros(8)

class Meter:
    def __init__(self): self.orig = kernel_net_module.kernel_net_step; self.k = 0
    def __enter__(self): kernel_net_module.kernel_net_step = self
    def __exit__(self, *a): kernel_net_module.kernel_net_step = self.orig
    def __call__(self, mm, qb, qtb, qttb, t, qn, fb):
        self.orig(mm, qb, qtb, qttb, t, qn, fb)
        v_end = kn.qt.reshape(3, -1)
        x = ref + kn.q.reshape(3, -1).T
        v_mid = v_end - 0.5 * step * force * inv_mass
        for g, (name, idx) in enumerate(groups.items()):
            ti = real[idx]
            a, b = threads[idx, 0], threads[idx, 1]
            d = x[b] - x[a]; L = np.linalg.norm(d, axis=1); u = d / L[:, None]
            rest, k, c = runs.rest_lengths[ti], runs.stiffness[ti], damping_all[ti]
            s = L - rest
            rm = np.einsum("ti,it->t", u, v_mid[:, b] - v_mid[:, a])
            re = np.einsum("ti,it->t", u, v_end[:, b] - v_end[:, a])
            pulling = s > 0
            T = np.where(pulling, np.maximum(k * s + c * rm, 0.0), 0.0)
            ps = np.where(pulling, s, 0.0)
            fd = T - k * ps
            # work on nodes: force on a is +T u, on b -T u: work = T (u.v_a - u.v_b) = -T re
            tot[4 * g + 0] += -step * float(np.sum(T * re))
            tot[4 * g + 1] = float(np.sum(0.5 * k * ps * ps))
            tot[4 * g + 2] += step * float(np.sum(fd * rm))
            tot[4 * g + 3] += step * float(np.sum(fd * re))
            if name == "loop":
                global prev_taut
                taut = T > 0
                onset = taut & ~prev_taut
                release = prev_taut & ~taut
                prev_taut = taut
                extra = (float(onset.sum()), float(release.sum()), float(np.max(np.abs(rm[onset]), initial=0.0)))
        if self.k < n_steps:
            rec[self.k, 0] = t; rec[self.k, 1:9] = tot; rec[self.k, 9] = winch.work; rec[self.k, 10:13] = extra
        self.k += 1

start = time.process_time()
mt = Meter()
with mt:
    s = sim.run().series
print(f"CPU {time.process_time() - start:.1f} s, load {os.getloadavg()[0]:.1f}")
rec = rec[:mt.k]
np.savez(out, rec=rec, **{k: s[k] for k in s if k.startswith("energy_") or k == "time"})
