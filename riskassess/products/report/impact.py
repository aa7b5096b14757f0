"""Report sections of the coupled impact: contact loads, debris motion, hinges, energy."""
from __future__ import annotations

import numpy as np

from riskassess.products.report.blocks import Figure, Note, Section, Table
from riskassess.products.plotting import COMPONENT_COLORS, legend, mark_release, panels, plain
from riskassess.products.results import RunFolder
from riskassess.products.summary import contact_totals_debris
from riskassess.products.tables import format_vector


def _release_times(run: RunFolder) -> dict[str, float]:
    """Joint name -> release time (s) of the joints a failed weak location released."""
    if not run.has("structures.json"):
        return {}
    return {p["joint"]: p["release_time_s"] for p in run.structures["released_pieces"]}


def contact_section(run: RunFolder) -> Section:
    """Net contact force on each debris body and the total contact moment about the debris CoM
    (N, N m, LVLH), with their peaks and the seed paper's figures.

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``timeseries.npz``, ``summary.json``).

    Returns
    -------
    Section
    """
    s = run.timeseries
    summary = run.summary
    t = s["time"]
    force, moment = contact_totals_debris(s)
    names = [str(n) for n in s["body_names"]]
    fig, (ax_f, ax_m) = panels(2, 2.1)
    ax_f.plot(t, np.linalg.norm(force, axis=1), color="k", lw=1.2, label="whole debris")
    for k, name in enumerate(names):
        ax_f.plot(t, np.linalg.norm(s["contact_force_lvlh"][:, k], axis=1), lw=0.8, label=plain(name))
    ax_f.set_ylabel("|contact force| (N)")
    ax_f.set_title("net contact force on the debris bodies")
    legend(ax_f)
    for i, axis in enumerate("xyz"):
        ax_m.plot(t, moment[:, i], color=COMPONENT_COLORS[i], label=f"M{axis} (LVLH)")
    ax_m.set_ylabel("moment (N m)")
    ax_m.set_title("contact moment about the debris centre of mass, LVLH")
    legend(ax_m)
    ref = run.key(summary, "paper_reference")
    rows = [[name, f"{p['value']:.4g}", f"{p['time_s']:.3f}"]
            for name, p in run.key(summary, "peak_contact_force_per_body_N").items()]
    f, m = summary["peak_contact_force_N"], summary["peak_contact_moment_about_debris_com_Nm"]
    rows.insert(0, ["whole debris (force)", f"{f['value']:.4g}", f"{f['time_s']:.3f}"])
    rows.insert(1, ["whole debris (moment about CoM, N m)", f"{m['value']:.4g}", f"{m['time_s']:.3f}"])
    return Section("contact", "Contact forces and moments", [
        Figure.from_matplotlib("fig-contact", "Net contact force per body (top) and the total contact moment about "
                               "the debris centre of mass in LVLH (bottom); samples at the run's output rate.", fig),
        Table(["body", "peak |force| (N)", "at (s)"], rows, "Peak contact loads"),
        Note(f"Seed paper (decoupled, debris held fixed): peak force {ref['peak_contact_force_N']:.3g} N, peak "
             f"moment {ref['peak_contact_moment_Nm']:.3g} N m. Here the debris moves and the net wraps it, so "
             f"later peaks (net closing, bullets striking) can exceed the first-impact peak; see docs/model.md."),
    ])


def debris_motion_section(run: RunFolder) -> Section:
    """Debris CoM velocity change (m/s, LVLH) with the momentum-exchange estimate, and the main
    body's angular velocity (rad/s, its body frame).

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``timeseries.npz``, ``summary.json``).

    Returns
    -------
    Section
    """
    s = run.timeseries
    summary = run.summary
    t = s["time"]
    dv = s["debris_velocity_lvlh"] - s["debris_velocity_lvlh"][0]
    estimate = np.asarray(run.key(summary, "momentum_exchange_estimate_lvlh_m_s"))
    omega = s["body_omega_body"][:, 0]
    fig, (ax_v, ax_w) = panels(2, 2.0)
    for i, (axis, name) in enumerate(zip("xyz", ("radial", "along-track", "cross-track"))):
        ax_v.plot(t, dv[:, i], color=COMPONENT_COLORS[i], label=f"dv{axis} ({name})")
        ax_w.plot(t, omega[:, i], color=COMPONENT_COLORS[i], label=f"omega {axis}")
    ax_v.axhline(estimate[1], color=COMPONENT_COLORS[1], ls="--", lw=0.9, label="momentum-exchange\nestimate (y)")
    ax_v.set_ylabel("velocity change (m/s)")
    ax_v.set_title("debris centre-of-mass velocity change, LVLH")
    legend(ax_v)
    ax_w.set_ylabel("angular velocity (rad/s)")
    ax_w.set_title(f"angular velocity of {plain(s['body_names'][0])}, its body frame")
    legend(ax_w)
    mean = np.asarray(summary["debris_velocity_change_final_third_mean_lvlh_m_s"])
    rows = [["final velocity change (m/s, LVLH)", format_vector(dv[-1], 4)],
            ["mean over the last third (m/s, LVLH)", format_vector(mean, 4)],
            ["momentum-exchange estimate (m/s, LVLH)", format_vector(estimate, 4)],
            [f"final angular velocity of {s['body_names'][0]} (rad/s, body frame)", format_vector(omega[-1], 4)]]
    return Section("debris-motion", "Debris velocity and angular velocity", [
        Figure.from_matplotlib("fig-debris-motion", "Velocity change of the debris centre of mass (all bodies) "
                               "and angular velocity of the main body.", fig),
        Table(["quantity", "value"], rows),
    ])


def hinge_section(run: RunFolder) -> Section:
    """Angle and rate of every revolute joint; after a release the curves continue in grey
    (the relative rotation of two bodies no longer joined is not a hinge angle).

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``timeseries.npz``; ``structures.json`` for the release times).

    Returns
    -------
    Section
    """
    s = run.timeseries
    t = s["time"]
    kinds = [str(k) for k in s["joint_kinds"]]
    names = [str(n) for n in s["joint_names"]]
    hinges = [j for j, kind in enumerate(kinds) if kind == "revolute"]
    if not hinges:
        return Section("hinges", "Hinge angles", [Note("The target has no revolute joint.")])
    released = _release_times(run)
    fig, (ax_a, ax_r) = panels(2, 1.8)
    rows = []
    for j in hinges:
        joined = t < released.get(names[j], np.inf)
        angle = s["joint_rotation_joint"][:, j, 1]
        rate = s["joint_rate_joint"][:, j, 1]
        for ax, values in ((ax_a, angle), (ax_r, rate)):
            line, = ax.plot(t[joined], values[joined], label=plain(names[j]))
            if not joined.all():
                ax.plot(t[~joined], values[~joined], color="0.6", ls="--", lw=0.8, label="after release")
                mark_release(ax, released[names[j]], f"{names[j]} released")
        rows.append([names[j], f"{np.abs(angle[joined]).max():.4g}", f"{np.abs(rate[joined]).max():.4g}",
                     f"{released[names[j]]:.3f}" if names[j] in released else "-"])
    ax_a.set_ylabel("hinge angle (rad)")
    ax_a.set_title("rotation about the hinge axis h2, child relative to parent")
    legend(ax_a)
    ax_r.set_ylabel("hinge rate (rad/s)")
    legend(ax_r)
    return Section("hinges", "Hinge angles", [
        Figure.from_matplotlib("fig-hinge-angle", "Hinge angle and rate of every revolute joint; grey dashed: "
                               "relative rotation after the joint was released (no longer a hinge angle).", fig),
        Table(["hinge", "max |angle| while joined (rad)", "max |rate| while joined (rad/s)", "released at (s)"],
              rows)])


#: Energy terms of the recorder, with their legend labels; the total is their balance.
ENERGY_TERMS = (("energy_net_kinetic", "net kinetic"), ("energy_net_elastic", "net threads elastic"),
                ("energy_net_bending", "net bending"), ("energy_contact_elastic", "contact elastic"),
                ("energy_debris_translational", "debris translational"),
                ("energy_debris_rotational", "debris rotational"), ("energy_joint_elastic", "joint elastic"),
                ("energy_dissipated_threads", "dissipated, threads"),
                ("energy_dissipated_contact", "dissipated, contact"),
                ("energy_dissipated_joints", "dissipated, joints' dampers"),
                ("energy_tether_elastic", "main tether elastic"), ("energy_dissipated_tether", "dissipated, main tether"))


def energy_section(run: RunFolder) -> Section:
    """Energy terms of net and debris (kJ in the figure) and the drift of their balance, with the
    conservation checks.

    Parameters
    ----------
    run : RunFolder
        An impact run folder (``timeseries.npz``, ``summary.json``).

    Returns
    -------
    Section
    """
    s = run.timeseries
    t = s["time"]
    fig, (ax_e, ax_d) = panels(2, 2.2)
    for key, label in ENERGY_TERMS:
        if key in s and np.abs(s[key]).max() > 0:
            ax_e.plot(t, s[key] / 1e3, label=label)
    ax_e.plot(t, s["energy_total"] / 1e3, color="k", lw=1.4, label="balance (sum, incl. orbital potential)")
    ax_e.set_yscale("symlog", linthresh=1e-3)
    ax_e.set_ylabel("energy (kJ, symlog)")
    ax_e.set_title("energy of net and debris, relative to the LVLH frame")
    legend(ax_e)
    e = s["energy_total"]
    # a run driven by recorded loads (sequential) starts at rest: its balance is read against the
    # health check's reference, the net's launch energy
    reference = max(abs(e[0]), run.summary.get("health", {}).get("energy_reference_J") or 0.0)
    drift = (e - e[0]) / reference * 100.0
    ax_d.plot(t, drift, color="k")
    ax_d.set_ylabel("balance drift (%)")
    ax_d.set_title("conservation check: (E(t) - E(0)) / E(0)" if reference == abs(e[0]) else
                   "conservation check: (E(t) - E(0)) / launch energy of the net")
    checks = run.key(run.summary, "checks")
    rows = [[name.replace("_", " "), f"{value:.3g}"] for name, value in checks.items()]
    return Section("energy", "Net and debris energy", [
        Figure.from_matplotlib("fig-energy", "Energy terms (top, symmetric-log axis) and the drift of their "
                               "balance, which an exact integration would hold at zero (bottom).", fig),
        Table(["check", "value (relative unless stated)"], rows, "Conservation checks"),
        Note("The balance books kinetic, elastic, orbital (Clohessy-Wiltshire) potential energy and what the "
             "threads and contacts dissipate; the damping of hinges and penalty joints is not booked, so a slow "
             "decrease of the balance is expected where joints swing. Drift from the integrator grows with the "
             "step: docs/model.md gives the step study."),
    ])
