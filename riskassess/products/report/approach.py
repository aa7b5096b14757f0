"""Report section of `riskassess approach`: the optimal approach of the net carried by two
maneuverable units (figures, constraint margins, the paper's figures, the 3-D replay)."""
from __future__ import annotations

from riskassess.products.report.blocks import Figure, Note, Section, Table
from riskassess.products.results import RunFolder
from riskassess.products.approach_plots import controls_figure, trajectory_figure


def _rows(answer: dict) -> list[list[str]]:
    fine, points = answer["constraints_resimulated"], answer["constraints_at_collocation_points"]
    rows = [["solver status (IPOPT)", answer["solver_status"], "-"],
            ["final time (s)", f"{answer['final_time']:.5g}", "-"],
            ["fuel of both MUs (kg)", f"{answer['fuel_kg']:.5g}", "-"],
            ["solve time (s), iterations", f"{answer['solve_s']:.2f}, {answer['iterations']}", "-"],
            ["keep-out margin (m)", f"{fine['keep_out_margin_m']:.4f}", f"{points['keep_out_margin_m']:.4f}"],
            ["mouth centre to debris at t_f (m)", f"{fine['final_mouth_miss_m']:.4f}",
             f"{points['final_mouth_miss_m']:.2g}"]]
    if "width_margin_m" in fine:
        rows.append(["mouth width range (m)", "{:.4f}-{:.4f}".format(*fine["width_range_m"]),
                     "{:.4f}-{:.4f}".format(*points["width_range_m"])])
    return rows


def _reference_rows(reference: dict) -> list[list[str]]:
    rows = []
    for key, label in (("final_time", "final time (s)"), ("fuel_kg", "fuel (kg)"), ("solve_s", "solve time (s)")):
        if key in reference:
            rows.append([label, f"{reference[key]:.5g}", f"{100 * reference[key + '_relative_difference']:+.1f} %"])
    return rows


def approach_section(run: RunFolder) -> Section | None:
    """The approach section: verdict on the constraints, solution and margins, paths and controls, the
    paper's figures and the 3-D replay; None unless the folder holds ``approach.json``.

    Parameters
    ----------
    run : RunFolder
        An output folder of ``riskassess approach`` (``approach.json``, ``approach.npz``).

    Returns
    -------
    Section or None
    """
    if not run.has("approach.json"):
        return None
    answer, arrays = run.json("approach.json"), run.arrays("approach.npz")
    verdict = "satisfied" if answer["constraints_satisfied"] else "NOT satisfied"
    blocks = [Note(f"{answer['objective']} ({answer['kind']}): constraints {verdict} on the re-simulation.",
                   "info" if answer["constraints_satisfied"] else "alarm"),
              Table(["quantity", "re-simulated / solution", "at the collocation points"], _rows(answer),
                    "Solution and constraint margins (negative margin: violation)"),
              Figure.from_matplotlib("fig-approach-paths", "MU paths (lines: independent re-simulation of the "
                                     "controls; dots: collocation points), net mouth, keep-out circle.",
                                     trajectory_figure(answer, arrays)),
              Figure.from_matplotlib("fig-approach-controls", "Thrust magnitudes, thrust angles and MU masses.",
                                     controls_figure(answer, arrays))]
    if answer.get("reference"):
        blocks.append(Table(["quantity", "paper", "this solution vs paper"], _reference_rows(answer["reference"]),
                            f"Against the paper ({answer['reference']['source']}); see docs/approach.md"))
    if answer.get("replay"):
        r = answer["replay"]
        blocks.append(Note(f"3-D replay ({r['net_nodes_per_side']}x{r['net_nodes_per_side']} net, "
                           f"{r['net_mass_kg']:g} kg): mouth chord centre {r['final_mouth_chord_center_distance_m']:.3f} m "
                           f"from the debris centre at t_f, mouth edge middle node "
                           f"{r['final_mouth_edge_middle_node_distance_m']:.2f} m; closest MU "
                           f"{r['min_unit_debris_distance_m']:.3f} m; tracking force up to "
                           f"{r['max_tracking_force_N']:.2f} N beyond the plan."))
    return Section("approach", "Net approach with maneuverable units", blocks)
