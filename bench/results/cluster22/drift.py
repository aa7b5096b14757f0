"""The energy balance's drift (% of the reference energy) per window, and the booked thread-contact dissipation."""
import sys, json
import numpy as np
d = np.load(sys.argv[1] + "/timeseries.npz", allow_pickle=True)
summ = json.load(open(sys.argv[1] + "/summary.json"))
t = d["time"]; tot = d["energy_total"]
keys = [k for k in d.files if k.startswith("energy")]
ref = None
for k in ("reference_energy", "energy_reference"):
    if k in summ: ref = summ[k]
print("keys", keys, "summary keys", list(summ.keys())[:40])
drift = tot - tot[0]
for a, b in [(0, 71.4), (71.4, 87.0), (87.0, 87.6), (87.6, 87.7), (87.7, 87.8), (87.8, 87.9), (87.9, 88.0), (88.0, 135.0)]:
    m = (t >= a) & (t <= b)
    if m.any():
        print(f"{a}-{b}: total {tot[m][0]:.4f} -> {tot[m][-1]:.4f}, change {tot[m][-1]-tot[m][0]:+.4f} J, contact booked "
              f"{d['energy_dissipated_contact'][m][-1]-d['energy_dissipated_contact'][m][0]:+.4f} J" if 'energy_dissipated_contact' in d.files else "")
