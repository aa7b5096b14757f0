"""Report section of `riskassess perceive`: the estimates with uncertainties and errors, and how
the tracking went (rotation error, registration time, the net's gap to the debris)."""
from __future__ import annotations

import numpy as np

from riskassess.products.report.blocks import Figure, Note, Section, Table
from riskassess.products.plotting import legend, panels
from riskassess.products.results import RunFolder
from riskassess.products.tables import perception_rows


def perception_section(run: RunFolder) -> Section | None:
    """The perception section: estimates with 1 sigma and errors, tracking per phase and its
    figure; None unless the folder holds ``perception.json``.

    Parameters
    ----------
    run : RunFolder
        An output folder of ``riskassess perceive`` (``perception.json``, ``perception.npz``).

    Returns
    -------
    Section or None
    """
    if not run.has("perception.json"):
        return None
    answer = run.json("perception.json")
    frames = run.arrays("perception.npz")
    blocks = [Table(["quantity", "estimate", "1 sigma", "error vs truth"], perception_rows(answer),
                    "Debris estimates (Tang et al. 2023 method: torque-free fit before, momentum balance across "
                    "the net collision)")]
    if answer["not_observable"]:
        blocks.append(Note(f"Not observable: {answer['not_observable']}", "alarm"))
    for key in ("model_mismatch", "model_mass_mismatch"):
        if answer.get(key):
            blocks.append(Note(f"Wrong model: {answer[key]}", "warning"))
    blocks.append(_tracking_figure(answer, frames))
    tracking = answer["tracking"]
    blocks.append(Table(["phase", "frames", "registered (checked ok)", "rotation error mean (deg)", "p95 (deg)"],
                        [[name, str(t["frames"]), str(t["registered"]),
                          "-" if t["rotation_error_mean_deg"] is None else f"{t['rotation_error_mean_deg']:.2f}",
                          "-" if t["rotation_error_p95_deg"] is None else f"{t['rotation_error_p95_deg']:.2f}"]
                         for name, t in tracking.items()], "Registration per phase"))
    net = answer["net"]
    blocks.append(Note(
        f"Time 0 is the start of the chaser's run in; the collision simulation starts from the observed tumble's end "
        f"state. Net: {net['mass_kg']:.3g} kg, {net['returns_per_frame_mean']:.0f} LiDAR returns per frame on average; "
        f"node position error {net['node_position_error_mean_m'] * 100:.1f} cm mean (nodes outside the field of view "
        f"follow the chaser and the seen ones). The chaser's navigation is taken as exact. Ray casting "
        f"{answer['ray_casting_ms_per_frame']:.1f} ms/frame; whole stage {answer['wall_s']:.0f} s wall."))
    return Section("perception", "Perception: debris mass and inertia", blocks)


def _tracking_figure(answer, frames) -> Figure:
    t = frames["time"]
    ok = frames["ok"].astype(bool)
    fig, (ax_e, ax_s, ax_n) = panels(3, 1.7, sharex=False)
    ax_e.plot(t[ok], np.degrees(frames["rotation_error_rad"][ok]), ".", ms=2, color="tab:blue", label="registered")
    ax_e.plot(t[~ok], np.zeros((~ok).sum()), "x", ms=3, color="tab:red", label="rejected by the check")
    ax_e.set_ylabel("rotation error (deg)")
    ax_e.set_title("registration against the truth (symmetric poses counted as right)")
    legend(ax_e)
    ax_s.plot(t, frames["registration_s"] * 1e3, ".", ms=2, color="k")
    ax_s.set_yscale("log")
    ax_s.set_ylabel("registration (ms)")
    ax_s.set_title("time per frame (first frame and re-acquisitions: global search)")
    ax_n.plot(frames["net_time"], frames["net_separation_m"], color="tab:green", label="debris-net gap")
    if answer.get("free_flight_after_s"):
        ax_n.axvspan(*answer["free_flight_after_s"], color="tab:green", alpha=0.12, lw=0, label="free flight used")
    ax_n.set_ylabel("gap (m)")
    ax_n.set_xlabel("time (s)")
    ax_n.set_title("smallest gap between the tracked net and the registered debris")
    legend(ax_n)
    return Figure.from_matplotlib("fig-perception", "Perception: rotation error of each registered frame, "
                                  "registration time, and the debris-net gap after the run in.", fig)
