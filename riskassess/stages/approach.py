"""`riskassess approach`: optimal net-approach guidance of two maneuverable units (MUs).

Load the case (:mod:`riskassess.cases.approach`), solve the optimal-control problem by
Hermite-Simpson collocation and IPOPT (:mod:`multibody.control.mu_approach`), re-simulate the controls with
an independent integrator to check the constraints between the collocation points, optionally
replay the path with the 3-D Exudyn net (:mod:`multibody.mu_replay`), and write the output folder:

=================  ==============================================================
file               content
=================  ==============================================================
manifest.json      format, ``stage = "approach"``, status, files
case.toml          the case file as given
approach_case.json the validated case (every default filled in)
approach.json      the answer (what ``--json`` prints): final time, fuel, checks
approach.npz       nodes, midpoints and the re-simulation (times, states, controls)
approach_*.png     trajectories, thrust magnitudes and angles, masses and widths
=================  ==============================================================
"""
from __future__ import annotations

from pathlib import Path

import numpy as np

from multibody.control.mu_approach import constraint_report, solve
from multibody.control.mu_mesh import collocation_points, resimulate
from multibody.control.mu_problem import ApproachProblem
from multibody.control.mu_dynamics import thrust_angles
from multibody.mu_replay import replay
from riskassess.products import results
from riskassess.cases.approach import ApproachCase
from riskassess.models.approach import build_problem
from riskassess.products.approach_plots import write_plots
from riskassess.cases.impact import load_model
from riskassess.products.outfolder import claim

#: Tolerances of the checks on the re-simulation (open-loop replay of the collocation controls,
#: which drifts from the nodes where the thrust switches inside an interval): the mouth width may
#: dip 1 cm (0.05 % of 22 m) below its bound, the mouth centre end 5 cm from the debris centre
#: (1 % of the 5.5 m keep-out radius); the keep-out circle itself is kept exactly (the collocation
#: points keep ``keep_out_margin`` more).
WIDTH_TOLERANCE_M = 0.01
MISS_TOLERANCE_M = 0.05


def _satisfied(problem: ApproachProblem, check: dict) -> bool:
    ok = check["keep_out_margin_m"] >= 0.0 and check["final_mouth_miss_m"] <= MISS_TOLERANCE_M
    if "width_margin_m" in check:
        ok = ok and check["width_margin_m"] >= -WIDTH_TOLERANCE_M
    if "mass_margin_kg" in check:
        ok = ok and check["mass_margin_kg"] >= 0.0
    return bool(ok and check["thrust_margin_N"] >= -1e-6)


def _reference_comparison(case: ApproachCase, answer: dict) -> dict | None:
    ref = case.reference
    if ref is None:
        return None
    out = {"source": ref.source}
    for key, value in (("final_time", ref.final_time), ("fuel_kg", ref.fuel), ("solve_s", ref.solve_time)):
        if value is not None:
            out[key] = value
            out[f"{key}_relative_difference"] = (answer[key] - value) / value
    return out


def solve_case(case: ApproachCase, source: str = "case"):
    """Solve and check a case; returns (answer dict, solution, re-simulation).

    Parameters
    ----------
    case : ApproachCase
        A validated approach case.
    source : str
        What the case came from (its file name), named in errors.

    Returns
    -------
    answer : dict
        JSON-ready: solver status, final time (s), fuel (kg), impulse (N s), constraint reports at the
        collocation points and re-simulated (m), whether they hold, comparison with the case's reference.
    solution : multibody.control.mu_problem.ApproachSolution
    resim : multibody.control.mu_mesh.Resimulation
        The controls replayed open loop through the dynamics (DOP853).
    """
    problem = build_problem(case, source)
    solution = solve(problem)
    resim = resimulate(solution)
    _, states, controls = collocation_points(solution)
    points = constraint_report(problem, states, controls)
    fine = constraint_report(problem, resim.states, resim.controls)
    answer = {"case": case.name, "kind": case.model.kind, "objective": case.objective.kind,
              "solver_status": solution.status, "converged": solution.success,
              "final_time": solution.final_time, "fuel_kg": solution.fuel_kg, "impulse_Ns": solution.impulse_Ns,
              "objective_value": solution.objective_value, "iterations": solution.iterations,
              "nlp_solves": solution.extras["nlp_solves"], "smoothing_penalty": solution.extras["smoothing_penalty"],
              "solve_s": solution.solve_s, "solve_cpu_s": solution.extras["cpu_s"],
              "intervals": solution.problem.intervals, "mesh_refinements": solution.extras["mesh_refinements"],
              "constraints_at_collocation_points": points,
              "constraints_resimulated": fine,
              "resimulation_final_state_difference": float(np.abs(resim.states[:, -1] - solution.states[:, -1]).max()),
              "tolerances": {"width_m": WIDTH_TOLERANCE_M, "final_mouth_miss_m": MISS_TOLERANCE_M}}
    answer["constraints_satisfied"] = bool(solution.success and _satisfied(problem, fine))
    answer["reference"] = _reference_comparison(case, answer)
    return answer, solution, resim


def _unit_paths(problem, states):
    x1, y1, x2, y2 = problem.model.unit_positions(states)
    return np.array([[x1, y1], [x2, y2]])


def _replay(case: ApproachCase, solution, resim) -> tuple[dict, dict]:
    r, problem = case.replay, solution.problem
    widths = problem.width_bounds
    side = r.side_length or (widths[1] if widths else case.model.length)
    masses = [float(m[0]) for m in np.broadcast_arrays(*problem.model.unit_masses(resim.states))]
    spec = dict(side_length=side, nodes_per_side=r.nodes_per_side, net_mass=r.net_mass,
                axial_rigidity=r.thread_axial_rigidity, damping=r.thread_damping,
                tracking_stiffness=r.tracking_stiffness, tracking_damping=r.tracking_damping)
    out = replay(resim.t, _unit_paths(problem, resim.states), masses, spec, problem.debris_center,
                 problem.keep_out_radius, r.step)
    arrays = {"replay_time": out.time, "replay_unit_positions": out.unit_positions,
              "replay_mouth_edge": out.mouth_edge, "replay_tracking_force": out.tracking_force}
    return {**out.summary, "net_nodes_per_side": r.nodes_per_side, "net_mass_kg": r.net_mass}, arrays


def approach_case(case_path, out_dir, replay: bool = False, case: ApproachCase | None = None,
                  overwrite: bool = False) -> dict:
    """Load (unless given), claim the output folder (:func:`riskassess.products.outfolder.claim`), solve, check,
    optionally replay, and write the output folder.

    Parameters
    ----------
    case_path : str or Path
        The approach case file (copied into the folder as ``case.toml``).
    out_dir : str or Path
        The output folder.
    replay : bool
        Also replay the solved unit paths with a net between the units (``[replay]`` table).
    case : ApproachCase or None
        The already validated case; read from ``case_path`` when None.
    overwrite : bool
        Replace an earlier approach output in ``out_dir``.

    Returns
    -------
    dict
        The answer (:func:`solve_case`, plus ``replay``), also written to ``approach.json``.
    """
    case_path = Path(case_path)
    case = case or load_model(case_path, ApproachCase)
    folder = claim(out_dir, case.name, "approach", overwrite, stage="approach")
    out = folder.path
    with folder.recording():
        results.atomic_write_bytes(out / "case.toml", case_path.read_bytes())
        results.atomic_write_json(out / "approach_case.json", case.model_dump())
        folder.add_files("case.toml", "approach_case.json")
        answer, solution, resim = solve_case(case, str(case_path))
        arrays = _arrays(solution, resim)
        if replay:
            answer["replay"], more = _replay(case, solution, resim)
            arrays.update(more)
        results.atomic_write_npz(out / "approach.npz", arrays)
        results.atomic_write_json(out / "approach.json", answer)
        pngs = write_plots(out, answer, arrays)
        folder.add_files("approach.npz", "approach.json", *pngs)
    folder.finish("complete")
    return answer


def _arrays(solution, resim) -> dict:
    problem = solution.problem
    t, states, controls = collocation_points(solution)
    arrays = {"t": t, "states": states, "controls": controls, "resim_t": resim.t, "resim_states": resim.states,
              "resim_controls": resim.controls, "state_names": np.array(problem.model.state_names),
              "unit_paths": _unit_paths(problem, states), "resim_unit_paths": _unit_paths(problem, resim.states),
              "thrust_angles": np.array(thrust_angles(controls)), "debris_center": problem.debris_center,
              "keep_out_radius": problem.keep_out_radius, "thrust_bounds": np.array(problem.thrust_bounds),
              "masses": np.array(np.broadcast_arrays(*problem.model.unit_masses(states)))}
    if problem.width_bounds is not None:
        arrays["width_bounds"] = np.array(problem.width_bounds)
    return arrays
