import numpy as np, sys, time
sys.path.insert(0, "/work/wt-speed21")
from numba import njit
import tests.multibody.test_segment_candidates as t
from multibody.segment_candidates import refresh_candidates, _candidates_hold
from multibody.segment_pairs import _near_shapes
from multibody.contact_segment import segment_buffers
from multibody.kernel import BodyStates
@njit
def loop_hold(k, x, seg, states, shapes, step):
    r = 0
    for _ in range(k): r += _candidates_hold(x, seg, states, shapes, step)
    return r
@njit
def loop_near(k, x, v, F, M, L, seg, states, shapes, step):
    for _ in range(k): _near_shapes(x, v, F, M, L, seg, states, shapes, step)
@njit
def loop_build(k, x, threads, radius, seg, states, shapes, step):
    for _ in range(k): refresh_candidates(x, threads, radius, seg, states, shapes, step)
rng = np.random.default_rng(0)
n, m, nb, step = 229, 420, 5, 1e-4
shapes = t._boxes()
shapes = shapes._replace(body=np.array([0, 1, 2], np.int64))
x = rng.uniform(-1.2, 1.8, (3, n)); v = rng.uniform(-1, 1, (3, n))
threads = np.stack([rng.integers(0, n, m), rng.integers(0, n, m)], 1).astype(np.int64)
radius = np.full(n, 0.001)
seg = segment_buffers(m, n, 3, nb, True)
att = np.stack([t._rotation(rng.uniform(-1, 1, 3)) for _ in range(nb)])
states = BodyStates(att, rng.uniform(-1,1,(nb,3)), np.zeros((nb,3)), np.zeros((nb,3)), att, np.zeros((nb,3)))
F = np.zeros((3, n)); M = np.ones(n); L = np.zeros((3, n))
_near_shapes(x, v, F, M, L, seg, states, shapes, step); refresh_candidates(x, threads, radius, seg, states, shapes, step)
K = 200000
def tm(f, *a):
    f(10, *a); t0 = time.process_time(); f(K, *a); return (time.process_time() - t0) / K * 1e6
print("near_shapes us", tm(loop_near, x, v, F, M, L, seg, states, shapes, step))
print("hold, cheap bound decides us", tm(loop_hold, x, seg, states, shapes, step), loop_hold(1, x, seg, states, shapes, step))
seg.built_body[:, 12] = 1e9
print("hold, body-frame pass us", tm(loop_hold, x, seg, states, shapes, step), loop_hold(1, x, seg, states, shapes, step))
seg.candidate_scalar[0] = 0.0
print("build every call us", tm(loop_build, x, threads, radius, seg, states, shapes, step), seg.candidate_count)
