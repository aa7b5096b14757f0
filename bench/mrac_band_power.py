"""Power flow in the breathing band of a full-net tow (issue 27, MRAC at 20.44 deg/s): who pumps the chaser-debris
motion at twice the spin, and who damps it.

    python bench/mrac_band_power.py bench/results/probe/mrac2_20.44.npz bench/results/probe/ramp141_20.44.npz
    python bench/mrac_band_power.py --rate 10.71 bench/results/mrac_replicas/range1000_rate0.6_full-net_mrac2_10.71_0.npz

Reads a probe file of bench/bench_mrac_probe.py (``time``, ``thrust``, ``separation``, ``tension``, ``elongation``) or
a replicas file of bench/bench_mrac_replicas.py (``main_tether_tension``, ``main_tether_elongation``, ``separation``).
Band-passes (2nd-order Butterworth, zero phase, 0.5-1 rad/s: the breathing at 2 x 20.44 deg/s = 0.71 rad/s; with
``--rate`` the band is 2 omega x [0.7, 1.4]) the thrust F, the main-tether tension T and the chaser-debris CoM distance
s, and prints per 25 s window: the band's standard deviations, the mean power of the thrust on the separation
<F_b ds_b/dt> (W; < 0: the thrust damps the motion) and of the tether -<T_b ds_b/dt> (> 0: the tether, i.e. the netted
stage, pumps it), the phase of T and F against s at 2 omega, |T_b / s_b| (N/m), the share of samples at the
+-200 N saturation, and the same two powers as equivalent viscous coefficients on the band's separation rate:
c_F = -<F_b ds_b/dt> / <(ds_b/dt)^2> (N s/m, > 0: the thrust damps like a dashpot of c_F) and
c_T = -<T_b ds_b/dt> / <(ds_b/dt)^2> (> 0: the tether pumps like a negative dashpot of c_T). The swing grows where
c_T exceeds the damping the thrust gives it (c_F times the share of the chaser's force the separation sees).
"""
from __future__ import annotations

import argparse

import numpy as np
from scipy.signal import butter, filtfilt


def band(x, low, high, rate_hz):
    """Zero-phase 2nd-order Butterworth band-pass of ``x`` between ``low`` and ``high`` (rad/s)."""
    b, a = butter(2, [low / (np.pi * rate_hz), high / (np.pi * rate_hz)], btype="band")
    return filtfilt(b, a, x)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+")
    ap.add_argument("--rate", type=float, default=None, help="spin rate (deg/s); default the 0.5-1 rad/s band")
    ap.add_argument("--u-max", type=float, default=200.0)
    a = ap.parse_args()
    for name in a.files:
        d = np.load(name)
        t, thrust, s = d["time"], d["thrust"], d["separation"]
        tension = d["tension"] if "tension" in d.files else d["main_tether_tension"]
        omega2 = 2.0 * np.radians(a.rate if a.rate else 20.44)
        low, high = (0.7 * omega2, 1.4 * omega2) if a.rate else (0.5, 1.0)
        fs = 1.0 / np.median(np.diff(t))
        fb, tb, sb = band(thrust, low, high, fs), band(tension, low, high, fs), band(s, low, high, fs)
        sdb = np.gradient(sb, t)
        print(name)
        print("| window (s) | std s (mm) | std T (N) | std F (N) | P thrust (W) | P tether (W) | phase T-s (deg) | "
              "phase F-s (deg) | abs(T/s) (N/m) | saturated | "
              "c_F (N s/m) | c_T (N s/m) |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|")
        for w0 in range(50, int(t[-1]), 25):
            m = (t >= w0) & (t < w0 + 25)
            c = np.exp(-1j * omega2 * t[m])
            ts, fsum, ss = np.sum(tb[m] * c), np.sum(fb[m] * c), np.sum(sb[m] * c)
            v2 = np.mean(sdb[m] ** 2)
            print(f"| {w0}-{w0 + 25} | {sb[m].std() * 1e3:.1f} | {tb[m].std():.1f} | {fb[m].std():.1f} | "
                  f"{np.mean(fb[m] * sdb[m]):.2f} | {-np.mean(tb[m] * sdb[m]):.2f} | {np.degrees(np.angle(ts / ss)):.0f} | "
                  f"{np.degrees(np.angle(fsum / ss)):.0f} | {abs(ts / ss):.0f} | "
                  f"{np.mean(np.abs(thrust[m]) >= a.u_max * (1 - 1e-9)):.2f} | "
                  f"{-np.mean(fb[m] * sdb[m]) / v2:.0f} | {-np.mean(tb[m] * sdb[m]) / v2:.0f} |")


if __name__ == "__main__":
    main()
