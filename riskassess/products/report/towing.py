"""Report section of `riskassess tow`: the lower-order or full-net towing run (Boonrath, Singh & Botta
2024): main-tether tension and tautness under the chosen thrust law, separation, rates and run facts.
A full-net run (``towing.json`` with ``model = "full-net"``) has no sub-tethers and no decision
vector s; it shows the net's figures instead."""
from __future__ import annotations

import math

from riskassess.products.report.blocks import Figure, Note, Section, Table
from riskassess.products.results import RunFolder
from riskassess.products.towing_plots import tow_figure

TITLE = "Towing: main tether and tethered bodies"


def _model_rows(summary: dict) -> list[list[str]]:
    """The rows of the model's own parts: the sub-tethers (lower-order) or the net (full-net)."""
    if summary.get("model") != "full-net":
        return [["s = [log10 k_ST, l_ST0, log10 c_ST, m_P/m_net]", ", ".join(f"{x:.4g}" for x in summary["decision_vector_s"])],
                ["sub-tether peak tension (N)", f"{summary['sub_tether_peak_tension_N']:.1f}"]]
    net = summary["net"]
    return [["net nodes / mean nodes in contact with the debris", f"{net['nodes']} / {net['mean_contacts']:.1f}"],
            ["closing-loop peak tension (N)", f"{net['closing_thread_peak_tension_N']:.1f}"],
            ["momentum balance max |P - P0 - J_ext| (N s)", f"{net['momentum_residual_Ns']:.3g}"]]


def _rows(summary: dict) -> list[list[str]]:
    mt, sep = summary["main_tether"], summary["separation_m"]
    return [
        ["thrust law", summary["thrust_kind"]],
        ["debris spin rate (rad/s)", f"{math.radians(summary['spin_rate_deg_s']):.4f}"],
        *_model_rows(summary),
        ["main tether engaged at (s)", f"{mt['engaged_at_s']:.1f}"],
        ["smallest tension after engagement (N)", f"{mt['min_tension_after_engagement_N']:.3f}"],
        ["slack time after engagement (s)", f"{mt['slack_after_engagement_s']:.1f}"],
        ["peak / final tension (N)", f"{mt['peak_tension_N']:.1f} / {summary['main_tether_final_tension_N']:.1f}"],
        ["final elongation (m)", f"{mt['final_elongation_m']:.4f}"],
        ["MRAC reference elongation / RMS error, last 100 s (m)",
         "-" if mt["target_elongation_m"] is None else f"{mt['target_elongation_m']:.4f} / {mt['rms_elongation_error_m']:.4f}"],
        ["chaser-debris distance min / max / final (m)", f"{sep['min']:.2f} / {sep['max']:.2f} / {sep['final']:.2f}"],
        ["chaser peak rate (rad/s)", f"{math.radians(summary['chaser_peak_rate_deg_s']):.4f}"],
        ["debris final rate (rad/s)", f"{math.radians(summary['debris_final_rate_deg_s']):.4f}"],
    ]


def _label(summary: dict) -> str:
    return "Full-net" if summary.get("model") == "full-net" else "Lower-order"


def _scheme(summary: dict) -> str:
    if summary.get("model") == "full-net":
        return (f"net sub-cycled at {summary['net_step_s'] * 1e6:.0f} us (symplectic Euler), central node implicit "
                "under the main tether (backward Euler)")
    return "connection point implicit (BDF2)"


def towing_section(run: RunFolder) -> Section | None:
    """None unless the folder holds a tow run (``towing.json``).

    Parameters
    ----------
    run : RunFolder
        An output folder of ``riskassess tow`` (``towing.json``, ``towing.npz``).

    Returns
    -------
    Section or None
    """
    if not run.has("towing.json"):
        return None
    summary = run.json("towing.json")
    series = run.arrays("towing.npz")
    mt = summary["main_tether"]
    taut = mt["slack_after_engagement_s"] == 0.0 and mt["min_tension_after_engagement_N"] > 0.0
    blocks = [Note(f"Main tether {'taut' if taut else 'SLACK'} after engagement with thrust '{summary['thrust_kind']}': "
                   f"smallest tension {mt['min_tension_after_engagement_N']:.3f} N, slack "
                   f"{mt['slack_after_engagement_s']:.1f} s.", "info" if taut else "warning"),
              Table(["quantity", "value"], _rows(summary), f"{_label(summary)} towing run (engagement: first "
                                                           "main-tether tension above 1 N)"),
              Figure.from_matplotlib("fig-towing", "Main-tether tension and thrust, chaser-debris distance and "
                                     "angular rates.", tow_figure(series, summary["case"])),
              Note(f"Exudyn VelocityVerlet, step {summary['step_s'] * 1e3:.3f} ms ({summary['n_steps']} steps, "
                   f"{summary['simulated_s']:g} s simulated), {_scheme(summary)}; {summary['wall_time_s']:.2f} s wall.")]
    return Section("towing", TITLE, blocks)
