"""Sample 9's pinch, step by step: the node contacts (re-evaluated with the kernel's own compiled functions at the
kernel's evaluation state), the thread contacts, the bodies' energies, over a window."""
import sys, os, time, json, sqlite3, tomllib
from pathlib import Path
import numpy as np
sys.path.insert(0, "/work/wt-pinch21/bench")
import multibody.kernel_net as kernel_net_module
from multibody.kernel import CONTACT_DISSIPATED, CONTACT_ELASTIC, THREAD_DISSIPATED
from multibody.impact import ImpactSimulation
from multibody.broad_phase import box_signed_distance
from multibody.contact import contact_over_step, hertz_elastic_energy
from multibody.contact_kernel import _substeps_to_resolve_contact, _effective_mass_of_body
from riskassess.cases.impact import validate_case
from riskassess.models.impact import model_inputs
from riskassess.sweep.spec import case_with

CASE = "/work/wt-pinch21/bench/results/array_modes/envisat_small_segments_modes_high_135s.toml"
STORE = "/work/wt-pinch21/bench/results/array_modes/lead_safe_velocity_high_1p0_135s_store"

def sample_overrides(sample):
    with sqlite3.connect(STORE) as con:
        row = con.execute("select overrides from runs where sample = ? order by grid_index limit 1", (sample,)).fetchone()
    return json.loads(row[0])

class Probe:
    def __init__(self, sim, window):
        self.sim, self.window = sim, window
        self.kernel = sim.system.kernel
        self.kn = sim.system.kernel_net
        self.orig = kernel_net_module.kernel_net_step
        self.rows, self.nodes = [], []
        b = self.kernel.buffers
        self.b = b
        self.masses = np.array([bd.mass for bd in sim.assembly.bodies])
        self.inertia = np.array([bd.inertia_body for bd in sim.assembly.bodies])
    def __enter__(self):
        kernel_net_module.kernel_net_step = self
        return self
    def __exit__(self, *a):
        kernel_net_module.kernel_net_step = self.orig
    def __call__(self, m, q_bodies, qt_bodies, qtt_bodies, t, q_next, force_bodies):
        inside = self.window[0] <= t <= self.window[1]
        if inside:
            imp0 = self.b.node_impulse_lvlh.copy()
            seg0 = self.b.segments.dissipated.copy()
            sc0 = self.b.scalars.copy()
            bimp0 = self.b.body_impulse_lvlh.copy()
            lag0 = self.b.velocity_lag.copy(); lagb0 = self.b.lag_body.copy()
        self.orig(m, q_bodies, qt_bodies, qtt_bodies, t, q_next, force_bodies)
        if inside:
            self.record(t, imp0, seg0, sc0, bimp0, lag0, lagb0, force_bodies)
    def record(self, t, imp0, seg0, sc0, bimp0, lag0, lagb0, force_bodies):
        b = self.b
        sc = b.scalars
        dseg = b.segments.dissipated - seg0
        threads = np.nonzero(dseg)[0]
        dimp = b.node_impulse_lvlh - imp0
        nodes = np.nonzero(np.abs(dimp).sum(axis=1))[0]
        st = b.states
        v = self.kn.qt.reshape(3, -1)
        n_kin = 0.5 * float(np.sum(self.kernel.net.mass * np.sum(v * v, axis=0)))
        kb = 0.5 * self.masses * np.sum(st.velocity_lvlh ** 2, axis=1) + 0.5 * np.einsum("bi,bij,bj->b", st.omega_body, self.inertia, st.omega_body)
        row = dict(t=t, node_diss=(sc[CONTACT_DISSIPATED] - sc0[CONTACT_DISSIPATED]) - dseg.sum(), thread_contact_diss=dseg.sum(),
                   threads_diss=sc[THREAD_DISSIPATED] - sc0[THREAD_DISSIPATED], contact_elastic=sc[CONTACT_ELASTIC],
                   net_kin=n_kin, body_kin=kb.copy(), body_force=b.work_body[0].copy(), body_impulse=(b.body_impulse_lvlh - bimp0).copy(),
                   contact_threads=threads.tolist(), contact_nodes=nodes.tolist(), seg_jump=b.segments.energy_jump.sum())
        self.rows.append(row)
        # node contacts re-evaluated
        law, shapes = self.kernel.law, self.kernel.shapes
        x = b.work_soa[0]
        step = self.kernel.step
        for i in nodes:
            cs = []
            for s in range(shapes.body.shape[0]):
                if b.segments.enabled and b.segments.owned_shape[i] == s:
                    continue
                bb = shapes.body[s]
                a = x[:, i] - st.com_lvlh[bb]
                p = st.body_to_lvlh[bb].T @ a
                if not shapes.is_box[s]:
                    continue
                d, nbx, nby, nbz = box_signed_distance(p[0], p[1], p[2], shapes.box_min_body, shapes.box_max_body, s)
                pen = self.kernel.net.radius[i] - d
                nrm = st.body_to_lvlh[bb] @ np.array([nbx, nby, nbz])
                rel = b.work[3][i] - st.velocity_lvlh[bb] - np.cross(st.omega_lvlh[bb], a)
                if pen > -0.01:
                    meff = _effective_mass_of_body(st.body_to_lvlh, self.kernel.bodies.inverse_inertia_body, bb, self.kernel.bodies.mass[bb], a[0], a[1], a[2], nrm[0], nrm[1], nrm[2])
                    cs.append((s, bb, pen, nrm, rel, meff))
            self.nodes.append((t, int(i), dimp[i].copy(), cs, b.work[2][i].copy(), b.work[3][i].copy(), lag0[:, i].copy(), int(lagb0[i]),
                               b.velocity_lag[:, i].copy(), int(b.lag_body[i]), int(b.segments.owned_shape[i]) if b.segments.enabled else -1))

def main():
    sample = int(sys.argv[1]); t0w, t1w = float(sys.argv[2]), float(sys.argv[3]); end = float(sys.argv[4]); out = sys.argv[5]
    ov = sample_overrides(sample) | {"structures.release": "never", "simulation.end_time": end}
    case = validate_case(case_with(tomllib.loads(Path(CASE).read_text()), ov), CASE)
    inputs = model_inputs(case, Path(CASE).parent)
    sim = ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)
    ref = sim.health.reference_energy
    sim.health.reference_energy = None
    print("bodies", [b.name for b in inputs.assembly.bodies], "masses", [b.mass for b in inputs.assembly.bodies])
    print("shapes body", sim.system.kernel.shapes.body, "is_box", sim.system.kernel.shapes.is_box)
    print("law", sim.system.kernel.law)
    start = time.process_time(); load = os.getloadavg()[0]
    with Probe(sim, (t0w, t1w)) as p:
        try:
            series = sim.run().series
        except Exception as e:
            print("run stopped:", e); series = sim.recorder.series
    print(f"CPU {time.process_time() - start:.1f} s, load {load:.1f} -> {os.getloadavg()[0]:.1f}; reference {ref} J")
    import pickle
    with open(out, "wb") as f:
        pickle.dump(dict(rows=p.rows, nodes=p.nodes, series={k: v for k, v in series.items()}, ref=ref,
                         body_names=[b.name for b in inputs.assembly.bodies], node_mass=np.asarray(sim.system.kernel.net.mass),
                         radius=np.asarray(sim.system.kernel.net.radius), threads=np.asarray(sim.assembly.net.threads)), f)

if __name__ == "__main__":
    main()
