"""Controls of the shared-node scene: which part makes its first-order error."""
import sys, time, os
import numpy as np
import bench.bench_pinch as bp
from bench.bench_pinch import NetTopology, NODE_MASS, NODE_RADIUS, THREAD_STIFFNESS, PLATE_HALF, plate, run

def scene(step, alpha, node_2, b_length, with_thread_1=True):
    positions = np.array([[-0.2, 0.0, 0.0], [0.2, 0.0, 0.0], node_2])
    threads = np.array([[0, 1], [1, 2]]) if with_thread_1 else np.array([[0, 1]])
    lengths = np.linalg.norm(positions[threads[:, 1]] - positions[threads[:, 0]], axis=1)
    if not with_thread_1:
        lengths = lengths[:1]
    net = NetTopology(positions=positions, masses=np.full(3, NODE_MASS), radii=np.full(3, NODE_RADIUS), threads=threads,
                      rest_lengths=lengths, stiffness=np.full(len(threads), THREAD_STIFFNESS), damping=np.zeros(len(threads)),
                      bending_triples=np.zeros((0, 3), np.int64), bending_stiffness=np.zeros(0), nodes_per_side=0, n_bullets=0)
    y = NODE_RADIUS + 0.0005 + PLATE_HALF
    bodies = [plate("a", [0.05, 0.05, 0.4], [0.0, -y, 0.0], [0.0, 0.01, 0.0], 1000.0),
              plate("b", [0.05, 0.05, b_length], [0.0, y, 0.0], [0.0, -0.01, 0.0], 1000.0)]
    return run(net, bodies, step, 0.1, alpha, 0.0, thread_segments=True)

SCENES = [("thread 1 on b (the scene)", dict(node_2=(-0.2, 0.0008, 0.6), b_length=0.8)),
                 ("thread 1 clear of b", dict(node_2=(-0.2, -0.02, 0.6), b_length=0.8)),
                 ("thread 1 beyond b's end (b 0.4 m)", dict(node_2=(-0.2, 0.0008, 0.6), b_length=0.4)),
                 ("no thread 1, b 0.8 m", dict(node_2=(-0.2, -0.02, 0.6), b_length=0.8, with_thread_1=False))]
for name, kw in SCENES[:int(os.environ.get("NSCENES", "4"))]:
    for alpha in (0.0, 0.05):
        for step in (1e-4, 5e-5):
            t0 = time.process_time()
            s = scene(step, alpha, **kw)
            tot = s["energy_total"]
            print(f"{name}, alpha {alpha}, h {step:.0e}: booked {s['energy_dissipated_contact'][-1]:.2e} J, largest change "
                  f"{np.max(np.abs(tot - tot[0])):.6e} J, end {tot[-1]-tot[0]:+.6e}; cpu {time.process_time()-t0:.1f} s load {os.getloadavg()[0]:.1f}", flush=True)
