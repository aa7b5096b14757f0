import numpy as np, sys
d=np.load(sys.argv[1]); rec=d['rec']; t=d['time']; e0=d['energy_total'][0]
ts=rec[:,0]
W=-(d['energy_winch_work']-d['energy_winch_work'][0])   # winch work done on the net (J)
print("t       total%   loop_made%  (spring part%  damper part%)   net_made%(spring%, damper%)   winch J  loop booked diss J")
for x in [14.9,16,18,20,22,24,25,25.1]:
    k=min(np.searchsorted(t,x),len(t)-1); j=np.searchsorted(ts,t[k]-1e-9)
    r=rec[j]; r0=rec[np.searchsorted(ts,14.9)]
    out=[]
    for g,(nm) in enumerate(["loop","net"]):
        Won, E, Db, Dw = r[1+4*g:5+4*g]; Won0,E0,Db0,Dw0 = r0[1+4*g:5+4*g]
        winch = W[k]-W[np.searchsorted(t,14.9)] if nm=="loop" else 0.0
        made = (Won-Won0) + (E-E0) + (Db-Db0) - winch
        damper = (Db-Db0) - (Dw-Dw0)          # booked less its Verlet work
        spring = made - damper
        out += [made, spring, damper]
    tot=d['energy_total'][k]-d['energy_total'][np.searchsorted(t,14.9)]
    print(f"{t[k]:6.2f} {100*tot/e0:+8.3f} "+" ".join(f"{100*v/e0:+9.3f}" for v in out)+f"  {W[k]:8.3f} {rec[j,3]-r0[3]:8.3f}")
