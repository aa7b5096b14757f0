import pickle, sys, numpy as np
d = pickle.load(open(sys.argv[1], "rb"))
r2 = d["rec2"]
step = int(sys.argv[2]) if len(sys.argv) > 2 else 50
dcum = np.cumsum([r["diss"] for r in r2], axis=0)
for k in range(0, len(r2), step):
    r = r2[k]
    g = r["geo"]
    def fmt(j, s):
        e = g[(j, s)]
        return f"q {e[0]*1e3:+8.3f} dep {e[1]*1e3:+7.3f} s {e[2]:.2f} end {e[4]} da {e[5]*1e3:+7.3f} dc {e[6]*1e3:+7.3f}"
    print(f"t {r['t']:.4f} diss419 {dcum[k,0]:.4f} diss423 {dcum[k,1]:.4f} jump {np.round(r['jump'],3)} owned {r['owned']} nshape {r['node_shape']} lagb {r['lag_body']}")
    for j in (419, 423):
        for s in (0, 2):
            print(f"     thread {j} box {s}: {fmt(j, s)}")
    bf = r["body_force"]
    print(f"     body force main {np.round(bf[0],1)} asar {np.round(bf[2],1)}; v nodes 223,224,228 {np.round(r['v'].T,4).tolist()}")
