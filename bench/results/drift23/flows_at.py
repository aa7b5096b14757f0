import numpy as np, sys
d=np.load(sys.argv[1]); t=d['time']; ref=float(sys.argv[2]) if len(sys.argv)>2 else d['energy_total'][0]
w=d['energy_winch_work']-d['energy_winch_work'][0]
parts={'total':d['energy_total']-d['energy_total'][0],'contact':d['made_contact'],'threads+winch':d['made_threads']+w,
       'netKE_sync':d['made_net_kinetic_sync'],'bodies':d['made_bodies_and_rest']-w}
print("t      "+"  ".join(f"{k:>13s}" for k in parts), "(% of", ref, "J)")
for x in [1,5,10,14.9,16,18,20,22,23,24,24.5,25,25.5,26]:
    k=min(np.searchsorted(t,x),len(t)-1)
    print(f"{t[k]:6.2f} "+"  ".join(f"{100*v[k]/ref:+13.3f}" for v in parts.values()))
