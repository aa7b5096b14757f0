import numpy as np, sys
d=np.load(sys.argv[1]); t=d['time']; ref=float(sys.argv[2]); t0=float(sys.argv[3])
k0=np.searchsorted(t,t0)
w=d['energy_winch_work']-d['energy_winch_work'][k0]
parts={'total':d['energy_total'],'contact':d['made_contact'],'threads+winch':d['made_threads']+d['energy_winch_work'],
       'netKE_sync':d['made_net_kinetic_sync'],'bodies':d['made_bodies_and_rest']-d['energy_winch_work']}
print(f"from {t[k0]:.3f} s, % of {ref} J:  "+"  ".join(f"{k:>13s}" for k in parts)+"   threads' dissipation (J)  contact's (J)")
for x in [26,27,27.5,28,29,30,32,35,40]:
    k=min(np.searchsorted(t,x),len(t)-1)
    print(f"{t[k]:6.2f} "+"  ".join(f"{100*(v[k]-v[k0])/ref:+13.3f}" for v in parts.values())+f"   {d['energy_dissipated_threads'][k]-d['energy_dissipated_threads'][k0]:8.3f}  {d['energy_dissipated_contact'][k]-d['energy_dissipated_contact'][k0]:8.3f}")
