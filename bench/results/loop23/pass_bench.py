"""CPU per call of the kernel's thread pass (multibody.net.add_thread_forces_runs) on the reference 35 x 35 net, taut
and slack threads mixed; the best of 7 trials of 20000 calls (time.process_time)."""
import os, sys, time
import numpy as np
from multibody.net import add_thread_forces_runs, flat_square_net, thread_runs
net = flat_square_net([0.0, 0.0, 0.0], [0.0, 1.0, 0.0], 30.0, 35, 0.0078, 0.01, 6.2e4, 1.58, 1.8, 0.01, 1.0)
rng = np.random.default_rng(0)
x = np.ascontiguousarray((net.positions + rng.normal(0, 0.05, net.positions.shape)).T)
v = np.ascontiguousarray(rng.normal(0, 1.0, net.positions.shape).T)
runs = thread_runs(net.threads, net.rest_lengths, net.stiffness, net.damping)
force, work = np.zeros_like(x), np.zeros((5, len(runs.rest_lengths)))
add_thread_forces_runs(x, v, runs, force, work)
best = []
for trial in range(7):
    start = time.process_time()
    for _ in range(20000):
        add_thread_forces_runs(x, v, runs, force, work)
    best.append((time.process_time() - start) / 20000 * 1e6)
print(f"{sys.argv[1]}: {min(best):.2f} us a call (best of 7; all {', '.join(f'{b:.2f}' for b in best)}), "
      f"{len(net.threads)} threads, load {os.getloadavg()[0]:.1f}")
