import numpy as np, sys
for f in sys.argv[1:]:
    d=np.load(f); t=d['time']; e=d['energy_total']
    for a,b in [(15,25),(25,40),(40,135)]:
        g=np.arange(a,b+1e-9,0.1); i=np.searchsorted(t,g); i=i[i<len(t)]
        cols=['energy_dissipated_threads','energy_dissipated_contact','energy_winch_work']
        X=np.stack([np.diff(d[k][i]) for k in cols],1); y=np.diff(e[i])
        KE=0.5*(d['energy_net_kinetic'][i][1:]+d['energy_net_kinetic'][i][:-1])*0.1
        X2=np.column_stack([X,KE])
        c,res,*_=np.linalg.lstsq(X2,y,rcond=None)
        r2=1-np.sum((y-X2@c)**2)/np.sum((y-y.mean())**2)
        print(f"{f[:20]} {a}-{b}: dE={y.sum():+.4f}  coef thr {c[0]:+.4f} con {c[1]:+.4f} winch {c[2]:+.5f} KE*dt {c[3]:+.5f}/s  R2 {r2:.2f}")
