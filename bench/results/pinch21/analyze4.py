import pickle, sys, numpy as np
d = pickle.load(open(sys.argv[1], "rb"))
r2, rows = d["rec2"], d["rows"]
t = np.array([r["t"] for r in r2])
diss = np.cumsum([r["diss"] for r in r2], axis=0)
tot = np.cumsum([r["thread_contact_diss"] for r in rows])
node = np.cumsum([r["node_diss"] for r in rows])
ce = np.array([r["contact_elastic"] for r in rows]); nk = np.array([r["net_kin"] for r in rows])
jump = np.array([r["jump"] for r in r2])
for k in range(0, len(t), 250):
    g = r2[k]["geo"]
    q = {key: round(v[0]*1e3, 3) for key, v in g.items() if np.isfinite(v[0])}
    print(f"{t[k]:.3f} s: booked thread 419 {diss[k,0]:.4f} J, 423 {diss[k,1]:.4f} J, all threads' contacts {tot[k]:.4f} J, node contact {node[k]:.4f} J; "
          f"jump 419 {jump[k,0]-jump[0,0]:+.4f} 423 {jump[k,1]-jump[0,1]:+.4f}; contact elastic {ce[k]:.4f}; net KE {nk[k]:.4f}; q (mm) {q}; owned {r2[k]['owned']}")
