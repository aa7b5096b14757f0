import numpy as np, sys
for f in sys.argv[1:]:
    d=np.load(f); t=d['time']; e=d['energy_total']; e0=e[0]; r=(e-e0)/e0*100
    i=np.abs(r).argmax()
    # max positive and negative, and in windows
    w=lambda a,b: (t>=a)&(t<b)
    s=f"{f[:22]:22s} max|.|={abs(r[i]):.3f}% at {t[i]:.3f}s; min {r.min():+.3f} at {t[r.argmin()]:.2f}; max {r.max():+.3f} at {t[r.argmax()]:.2f}; end {r[-1]:+.3f} at {t[-1]:.1f}"
    print(s)
    for a,b in [(0,14.9),(14.9,26),(26,40),(40,135),(135,1e9)]:
        m=w(a,b)
        if m.any(): print(f"   [{a},{b}) start {r[m][0]:+.3f} end {r[m][-1]:+.3f} min {r[m].min():+.3f} max {r[m].max():+.3f}")
