"""Power flow in the breathing band of a full-net tow (issue 27, MRAC at 20.44 and 29.01 deg/s): who pumps the
chaser-debris motion at a harmonic of the spin, and who damps it.

    python bench/mrac_band_power.py bench/results/probe/mrac2_20.44.npz bench/results/probe/ramp141_20.44.npz
    python bench/mrac_band_power.py --rate 10.71 bench/results/mrac_replicas/range1000_rate0.6_full-net_mrac2_10.71_0.npz
    python bench/mrac_band_power.py --rate 29.01 --harmonic 1 --range-damping 1000 \\
        bench/results/mrac_replicas/range1000_rate0.6_full-net_mrac2_29.01_0.npz          # the once-per-revolution line

Reads a probe file of bench/bench_mrac_probe.py (``time``, ``thrust``, ``separation``, ``tension``, ``elongation``) or
a replicas file of bench/bench_mrac_replicas.py (``main_tether_tension``, ``main_tether_elongation``, ``separation``).
Band-passes (2nd-order Butterworth, zero phase, 0.5-1 rad/s: the breathing at 2 x 20.44 deg/s = 0.71 rad/s; with
``--rate`` the band is n omega x [0.7, 1.4], n = ``--harmonic``, default 2) the thrust F, the main-tether tension T and
the chaser-debris CoM distance s, and prints per 25 s window: the band's standard deviations, the mean power of the
thrust on the separation <F_b ds_b/dt> (W; < 0: the thrust damps the motion) and of the tether -<T_b ds_b/dt> (> 0:
the tether, i.e. the netted stage, pumps it), the phase of T and F against s at n omega, |T_b / s_b| (N/m), the share
of samples at the +u_max saturation, and the same two powers as equivalent viscous coefficients on the band's
separation rate: c_F = -<F_b ds_b/dt> / <(ds_b/dt)^2> (N s/m, > 0: the thrust damps like a dashpot of c_F) and
c_T = -<T_b ds_b/dt> / <(ds_b/dt)^2> (> 0: the tether pumps like a negative dashpot of c_T).

With ``--rate`` a second table gives, per window, the Fourier amplitudes at omega and 2 omega (projection on
exp(-i n omega t) over the window, mean removed) of s, of s - z (the tow point's along-line motion relative to the
debris CoM, z the main tether's elongation), of T and of F, and of the two parts of F at omega when ``--range-damping``
c_R (N s/m) is given: the range term -c_R ds/dt the laws add (``mrac.range_damping``) and the rest (the laws' own
elongation feedback); the thrust's amplitude at omega against the headroom u_max - mean thrust; the spin-axis angle in
the debris body (from body -y towards +x, deg; the shipped start spins about body -y); and the energy flow of the line
at omega (band omega x [0.7, 1.4]): its energy mu (omega A)^2 / 2 (mu = m_C m_D / (m_C + m_D), A the band's amplitude),
the tether's power on it -<T_b ds_b/dt>, the thrust's m_D / (m_C + m_D) <F_b ds_b/dt> (the share of the chaser's force
the separation sees), and the rate of change of the debris' rotational energy (W, a straight-line fit over the window;
the source the tether draws on). What these leave out (the net's contact friction and thread damping) is the residual.
Measured with it (docs/towing.md, "What grows the swing at 29.01 deg/s"): the separation's swing on the full net is one
line at the spin rate, not at twice it.
"""
from __future__ import annotations

import argparse

import numpy as np
from scipy.signal import butter, filtfilt


def band(x, low, high, rate_hz):
    """Zero-phase 2nd-order Butterworth band-pass of ``x`` between ``low`` and ``high`` (rad/s)."""
    b, a = butter(2, [low / (np.pi * rate_hz), high / (np.pi * rate_hz)], btype="band")
    return filtfilt(b, a, x)


def phasor(x, t, omega):
    """Complex amplitude of ``x`` at ``omega`` (rad/s) over the samples ``t`` (s): 2 mean((x - mean x) e^{-i omega t});
    |.| is the amplitude of a sinusoid filling the window."""
    return 2.0 * np.mean((x - x.mean()) * np.exp(-1j * omega * t))


def band_table(t, thrust, tension, s, omega_n, low, high, u_max):
    """Print the band-power table (module doc) of one run."""
    fs = 1.0 / np.median(np.diff(t))
    fb, tb, sb = band(thrust, low, high, fs), band(tension, low, high, fs), band(s, low, high, fs)
    sdb = np.gradient(sb, t)
    print("| window (s) | std s (mm) | std T (N) | std F (N) | P thrust (W) | P tether (W) | phase T-s (deg) | "
          "phase F-s (deg) | abs(T/s) (N/m) | saturated | c_F (N s/m) | c_T (N s/m) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for w0 in range(50, int(t[-1]), 25):
        m = (t >= w0) & (t < w0 + 25)
        c = np.exp(-1j * omega_n * t[m])
        ts, fsum, ss = np.sum(tb[m] * c), np.sum(fb[m] * c), np.sum(sb[m] * c)
        v2 = np.mean(sdb[m] ** 2)
        print(f"| {w0}-{w0 + 25} | {sb[m].std() * 1e3:.1f} | {tb[m].std():.1f} | {fb[m].std():.1f} | "
              f"{np.mean(fb[m] * sdb[m]):.2f} | {-np.mean(tb[m] * sdb[m]):.2f} | {np.degrees(np.angle(ts / ss)):.0f} | "
              f"{np.degrees(np.angle(fsum / ss)):.0f} | {abs(ts / ss):.0f} | "
              f"{np.mean(thrust[m] >= u_max * (1 - 1e-9)):.2f} | "
              f"{-np.mean(fb[m] * sdb[m]) / v2:.0f} | {-np.mean(tb[m] * sdb[m]) / v2:.0f} |")


def harmonic_table(d, t, thrust, tension, s, omega, c_range, u_max, masses, inertia):
    """Print the amplitudes at omega and 2 omega per window, the thrust's split and headroom, and the energy flow of
    the line at omega (module doc)."""
    z = d["main_tether_elongation"] if "main_tether_elongation" in d.files else d["elongation"]
    spin = d["debris_omega_body"] if "debris_omega_body" in d.files else None
    tow_point = s - z
    range_term = -c_range * np.gradient(s, t)
    fs = 1.0 / np.median(np.diff(t))
    low, high = 0.7 * omega, 1.4 * omega
    fb, tb, sb = band(thrust, low, high, fs), band(tension, low, high, fs), band(s, low, high, fs)
    sdb = np.gradient(sb, t)
    spin_energy = 0.5 * np.sum(np.asarray(inertia) * spin ** 2, axis=1) if spin is not None else None
    m_c, m_d = masses
    reduced, share = m_c * m_d / (m_c + m_d), m_d / (m_c + m_d)   # the separation sees share x the chaser's force
    print("| window (s) | s at w (mm) | s at 2w (mm) | s - z at w (mm) | T at w (N) | F at w (N) | F at 2w (N) | "
          "range term at w (N) | laws' rest at w (N) | F at w / headroom | spin axis (deg) | line energy (J) | "
          "P tether at w (W) | share x P thrust at w (W) | spin energy rate (W) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|")
    for w0 in range(50, int(t[-1]), 25):
        m = (t >= w0) & (t < w0 + 25)
        tm = t[m]
        f1 = phasor(thrust[m], tm, omega)
        r1 = phasor(range_term[m], tm, omega)
        headroom = u_max - thrust[m].mean()
        split = (f"{abs(r1):.0f} | {abs(f1 - r1):.0f}" if c_range > 0.0 else "- | -")
        axis, spin_rate = "-", "-"
        if spin is not None:
            o = spin[m].mean(axis=0)
            axis = f"{np.degrees(np.arctan2(o[0], -o[1])):.0f}"
            spin_rate = f"{np.polyfit(tm, spin_energy[m], 1)[0]:.2f}"
        line_energy = reduced * (omega * sb[m].std()) ** 2   # mu (omega A)^2 / 2, A = sqrt(2) std of the band
        print(f"| {w0}-{w0 + 25} | {abs(phasor(s[m], tm, omega)) * 1e3:.0f} | "
              f"{abs(phasor(s[m], tm, 2 * omega)) * 1e3:.0f} | {abs(phasor(tow_point[m], tm, omega)) * 1e3:.0f} | "
              f"{abs(phasor(tension[m], tm, omega)):.0f} | {abs(f1):.0f} | {abs(phasor(thrust[m], tm, 2 * omega)):.0f} | "
              f"{split} | {abs(f1) / headroom:.2f} | {axis} | {line_energy:.2f} | {-np.mean(tb[m] * sdb[m]):.2f} | "
              f"{share * np.mean(fb[m] * sdb[m]):.2f} | {spin_rate} |")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("files", nargs="+")
    ap.add_argument("--rate", type=float, default=None, help="spin rate (deg/s); default the 0.5-1 rad/s band")
    ap.add_argument("--harmonic", type=int, default=2, help="band at this multiple of the spin rate (with --rate)")
    ap.add_argument("--range-damping", type=float, default=0.0, help="c_R (N s/m) of the run, to split F at omega")
    ap.add_argument("--u-max", type=float, default=200.0)
    ap.add_argument("--masses", type=float, nargs=2, default=(1600.0, 9000.0), help="chaser, debris (kg; the case's)")
    ap.add_argument("--inertia", type=float, nargs=3, default=(94880.0, 94880.0, 46295.5),
                    help="debris principal inertia (kg m^2, body axes; the case's)")
    a = ap.parse_args()
    for name in a.files:
        d = np.load(name)
        t, thrust, s = d["time"], d["thrust"], d["separation"]
        tension = d["tension"] if "tension" in d.files else d["main_tether_tension"]
        omega = np.radians(a.rate if a.rate else 20.44)
        omega_n = a.harmonic * omega if a.rate else 2.0 * omega
        low, high = (0.7 * omega_n, 1.4 * omega_n) if a.rate else (0.5, 1.0)
        print(name)
        band_table(t, thrust, tension, s, omega_n, low, high, a.u_max)
        if a.rate:
            print()
            harmonic_table(d, t, thrust, tension, s, omega, a.range_damping, a.u_max, a.masses, a.inertia)


if __name__ == "__main__":
    main()
