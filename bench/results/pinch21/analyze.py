import pickle, sys, numpy as np
d = pickle.load(open(sys.argv[1], "rb"))
rows, nodes, s = d["rows"], d["nodes"], d["series"]
names = d["body_names"]
t = np.array([r["t"] for r in rows])
cum = lambda key: np.cumsum([r[key] for r in rows])
nd, td, thd = cum("node_diss"), cum("thread_contact_diss"), cum("threads_diss")
ce = np.array([r["contact_elastic"] for r in rows]); nk = np.array([r["net_kin"] for r in rows])
bk = np.array([r["body_kin"] for r in rows])
print("t       node_diss  thr_contact_diss  threads_diss  contact_el  net_kin  " + "  ".join(f"KE_{n}" for n in names))
for k in range(0, len(t), 100):
    print(f"{t[k]:.4f}  {nd[k]:8.4f}  {td[k]:8.4f}  {thd[k]:8.4f}  {ce[k]:8.4f}  {nk[k]:8.4f}  " + "  ".join(f"{x:9.5f}" for x in bk[k]))
# series energy at 1 ms
ts = s["time"]
sel = (ts >= 87.6)
for key in ["energy_total", "energy_net_kinetic", "energy_net_elastic", "energy_contact_elastic", "energy_debris_translational", "energy_debris_rotational", "energy_joint_elastic", "energy_dissipated_threads", "energy_dissipated_contact", "energy_dissipated_joints"]:
    v = s[key][sel]
    print(f"{key:30s}", " ".join(f"{x:8.4f}" for x in v[::25]))
print("times", " ".join(f"{x:8.4f}" for x in ts[sel][::25]))
# which nodes/threads
from collections import Counter
cn = Counter(); ct = Counter()
for r in rows:
    cn.update(r["contact_nodes"]); ct.update(r["contact_threads"])
print("contact nodes (steps):", cn.most_common(30))
print("contact threads (steps):", ct.most_common(30))
