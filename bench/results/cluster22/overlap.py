"""Per step of the shared-node scene: each thread's contact coordinate q with each bar (from the net's positions)."""
import numpy as np, sys
import bench.bench_pinch as bp
from multibody.impact import ImpactSimulation
from multibody.segment_cycle import thread_contact_geometry
from multibody.segment_box import MAX_BREAKPOINTS
results = []
orig_run = ImpactSimulation.run
def run(self, *a, **k):
    r = orig_run(self, *a, **k); results.append((self, r)); return r
ImpactSimulation.run = run
orig_spec = bp.SolverSpec
bp.SolverSpec = lambda **kw: orig_spec(**(kw | {"net_output_rate": 1.0 / kw["step"]}))
s = bp.shared_node_pinch(float(sys.argv[1]), float(sys.argv[2]), sys.argv[3] == "1")   # step, alpha, companions
sim, r = results[-1]
print({k: np.shape(v) for k, v in r.net.items()})
shapes = sim.system.kernel.shapes
work = np.zeros(MAX_BREAKPOINTS)
tn = r.net["time"]; X = r.net["positions_lvlh"]
ts = s["time"]
rows = []
for i in range(len(tn)):
    k = np.argmin(abs(ts - tn[i]))
    out = [tn[i]]
    for j, (a, c) in enumerate([(0, 1), (1, 2)]):
        for sh in (0, 1):
            bb = shapes.body[sh]
            R = s["body_to_lvlh"][k, bb]; com = s["body_com_lvlh"][k, bb]
            pa = tuple(R.T @ (X[i, a] - com)); pc = tuple(R.T @ (X[i, c] - com))
            g = thread_contact_geometry(pa, pc, shapes.box_min_body, shapes.box_max_body, sh, 0.001, 0.001, work)
            out.append(max(g[0], 0.0))
    rows.append(out)
rows = np.array(rows)
on = rows[:, 1:] > 0
print("steps with q > 0: thread0-a, thread0-b, thread1-a, thread1-b:", on.sum(0))
both = on[:, 0] & on[:, 3]
print("steps thread 0 on a and thread 1 on b:", both.sum(), "first/last t", rows[both, 0][[0, -1]] if both.any() else None)
for i in range(0, len(rows), 40):
    print(" ".join(f"{v:.3e}" for v in rows[i]), "| node1", X[i, 1], "node2", X[i, 2])
