# Full-net tow with the closing loop: the loop dampers on l' (before) and on l' - l0' (after), side by side
# (lead, 2026-11-28; docs/towing.md "The closing loop's dampers on the stretch's rate"). Usage: python reel_damper_ab.py [N [END_S]]
"""Full-net tow with the closing loop: the loop's dampers on l' (before) and on l' - l0' (after)."""
import time
import numpy as np
from multibody.net_towing import NetTowState, run_exudyn
from riskassess.cases.impact import load_model
from riskassess.models.towing_fullnet import full_net_model
from riskassess.cases.towing import TowingCase

case = load_model(str(__import__("pathlib").Path(__file__).resolve().parents[3] / "cases" / "zenit2_towing.toml"), TowingCase)
n = int(__import__("sys").argv[1]) if len(__import__("sys").argv) > 1 else 7
case = case.model_copy(update=dict(full_net=case.full_net.model_copy(update=dict(start="capture", nodes_per_side=n))))
fn = case.full_net
end = float(__import__("sys").argv[2]) if len(__import__("sys").argv) > 2 else fn.closing_time + fn.closing_duration + 10.0
print(f"net {n}x{n}, closing at {fn.closing_time} s over {fn.closing_duration} s, end {end} s")
reel = NetTowState.reel
out = {}
for label in ("l' (before)", "l' - l0' (after)"):
    if label.startswith("l' ("):
        def patched(self, t):
            reel(self, t)
            self.rest_rate[:] = 0.0
        NetTowState.reel = patched
    else:
        NetTowState.reel = reel
    model = full_net_model(case, end_time=end)
    c0 = time.process_time()
    r = run_exudyn(model)
    s = r.series()
    out[label] = s
    keys = [k for k in s if "closing" in k or "tension" in k]
    t = s["time"]
    w = (t >= fn.closing_time) & (t <= fn.closing_time + fn.closing_duration)
    print(f"{label:18s} CPU {time.process_time() - c0:6.1f} s; largest closing tension in the reel-in "
          f"{s['closing_thread_peak_tension'][w].max():8.3f} N, after {s['closing_thread_peak_tension'][t > fn.closing_time + fn.closing_duration].max():8.3f} N; "
          f"main tether tension max {s['tether_tension'].max() if 'tether_tension' in s else float('nan'):8.3f} N")
a, b = out["l' (before)"], out["l' - l0' (after)"]
for lab, s in out.items():
    t = s["time"]
    print(f"{lab}: main tether peak {s['main_tether_tension'].max():.1f} N, final {s['main_tether_tension'][-1]:.1f} N; closing loop peak "
          f"{s['closing_thread_peak_tension'].max():.1f} N; debris spin {np.degrees(np.linalg.norm(s['debris_omega_body'][0])):.3f} -> "
          f"{np.degrees(np.linalg.norm(s['debris_omega_body'][-1])):.3f} deg/s; chaser-debris distance "
          f"{np.linalg.norm(s['debris_com_inertial'][-1] - s['chaser_com_inertial'][-1]):.3f} m")
for k in a:
    if a[k].dtype.kind == "f" and a[k].shape == b[k].shape and k != "time":
        d = np.abs(a[k] - b[k]).max(); sc = np.abs(a[k]).max()
        print(f"  {k:45s} max |after - before| {d:10.4g} (of max |before| {sc:10.4g})")
