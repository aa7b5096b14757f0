"""Threads 419 (223-224) and 423 (224-228) in sample 9's pinch: their contact with each box, per step."""
import sys, os, time, pickle
import numpy as np
sys.path.insert(0, "/tmp/pinch21")
from probe import *  # noqa
from multibody.segment_cycle import thread_contact_geometry
from multibody.segment_box import MAX_BREAKPOINTS

THREADS = [419, 423]
class Probe2(Probe):
    def record(self, t, imp0, seg0, sc0, bimp0, lag0, lagb0, force_bodies):
        super().record(t, imp0, seg0, sc0, bimp0, lag0, lagb0, force_bodies)
        b, st, shapes = self.b, self.b.states, self.kernel.shapes
        x = b.work_soa[0]
        work = np.zeros(MAX_BREAKPOINTS)
        rec = dict(t=t, diss=(b.segments.dissipated - seg0)[THREADS].copy(), jump=b.segments.energy_jump[THREADS].copy(),
                   owned={i: int(b.segments.owned_shape[i]) for i in (223, 224, 228)},
                   node_shape={i: int(b.segments.node_shape[i]) for i in (223, 224, 228)},
                   lag_body=b.segments.lag_body[THREADS].copy(), geo={}, body_force=b.work_body[0].copy(),
                   x={i: x[:, i].copy() for i in (223, 224, 228)}, v=self.kn.qt.reshape(3, -1)[:, [223, 224, 228]].copy())
        th = self.kernel.net.threads
        for j in THREADS:
            for s in (0, 2):
                bb = shapes.body[s]
                pa = tuple(st.body_to_lvlh[bb].T @ (x[:, th[j, 0]] - st.com_lvlh[bb]))
                pc = tuple(st.body_to_lvlh[bb].T @ (x[:, th[j, 1]] - st.com_lvlh[bb]))
                g = thread_contact_geometry(pa, pc, shapes.box_min_body, shapes.box_max_body, s,
                                            self.kernel.net.radius[th[j, 0]], self.kernel.net.radius[th[j, 1]], work)
                rec["geo"][(j, s)] = g[:7]
        self.rec2.append(rec)

def main2():
    sample = 9; t0w, t1w, end, out = float(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]
    ov = sample_overrides(sample) | {"structures.release": "never", "simulation.end_time": end}
    case = validate_case(case_with(tomllib.loads(Path(CASE).read_text()), ov), CASE)
    inputs = model_inputs(case, Path(CASE).parent)
    sim = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
    sim.health.reference_energy = None
    shapes = sim.system.kernel.shapes
    print("kernel threads 419, 423:", sim.system.kernel.net.threads[[419, 423]], "assembly:", np.asarray(sim.assembly.net.threads)[[419, 423]]); print("box min/max", shapes.box_min_body, shapes.box_max_body, "radius", sim.system.kernel.net.radius[[223,224,228]], "mass", sim.system.kernel.net.mass[[223,224,228]])
    start = time.process_time(); load = os.getloadavg()[0]
    p = Probe2(sim, (t0w, t1w)); p.rec2 = []
    with p:
        series = sim.run().series
    print(f"CPU {time.process_time() - start:.1f} s, load {load:.1f} -> {os.getloadavg()[0]:.1f}")
    pickle.dump(dict(rec2=p.rec2, rows=p.rows, series=series, body_com=None), open(out, "wb"))

if __name__ == "__main__":
    main2()
