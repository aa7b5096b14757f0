import numpy as np, sys
d=np.load(sys.argv[1]); rec=d['rec']; e0=d['energy_total'][0]
ts=rec[:,0]; m=(ts>=14.9)&(ts<=25.1)
r=rec[m]
made=r[:,1]+r[:,2]+r[:,3]-r[:,9]
dm=np.diff(made)
onset=r[1:,10]>0; release=r[1:,11]>0
near=np.zeros_like(onset)
for sh in range(-2,3):
    near|=np.roll(onset|release,sh)
print(f"{sys.argv[1]}: loop made 14.9-25.1 s {made[-1]-made[0]:+.5f} J ({100*(made[-1]-made[0])/e0:+.3f} % of {e0:.4f} J); steps {len(dm)}")
print(f"  onsets {int(r[:,10].sum())}, releases {int(r[:,11].sum())}; made within 2 steps of an onset or release: {dm[near].sum():+.5f} J in {near.sum()} steps; elsewhere {dm[~near].sum():+.5f} J")
sp=r[1:,12][onset]
print(f"  onset speeds |l'| (m/s): median {np.median(sp):.3f}, 90th pct {np.percentile(sp,90):.3f}, max {sp.max():.3f}")
# damper part
dpart=(r[-1,3]-r[0,3])-(r[-1,4]-r[0,4])
print(f"  loop damper booked {r[-1,3]-r[0,3]:.3f} J, its Verlet work {r[-1,4]-r[0,4]:.3f} J (booked less work {dpart:+.5f} J); winch work {r[-1,9]-r[0,9]:.3f} J")
