"""The risk pipeline: case file -> coupled simulation -> run folder.

Later stages (structures, reports, VTK) read the run folder; nothing here re-runs them.
"""
from __future__ import annotations

import platform
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from multibody.health import SimulationFailed
from multibody.impact import ImpactSimulation
from multibody.thread_crossing import pass_through_history
from riskassess.products import results
from riskassess.models.impact import model_inputs, weak_locations
from riskassess.models.impact_sequential import applied_contact_series, driven_inputs, recorded_loads, wall_inputs
from riskassess.cases.impact import Case, load_case
from riskassess.products.outfolder import OutputFolder, claim
from riskassess.products.summary import run_summary, sequential_summary
from structures.capture_window import CaptureMonitor, capture_window, hold_time, reference_body
from structures.release import ReleaseMonitor
from structures.reproducibility import TWIN_OFFSET
from structures.verdict import DEBRIS, INDETERMINATE, apply_twin, demand_series, structures_verdict


@dataclass
class RunOutput:
    run_dir: Path
    summary: dict                  # as in summary.json
    structures: dict | None = None  # as in structures.json, for a case with weak locations


def software_versions() -> dict:
    import exudyn
    import numba
    import trimesh

    return {"python": platform.python_version(), "exudyn": exudyn.__version__, "numpy": np.__version__,
            "numba": numba.__version__, "trimesh": trimesh.__version__}


def _simulation(inputs) -> ImpactSimulation:
    """The Exudyn model of ``inputs`` (:class:`riskassess.models.impact.ModelInputs`); raises
    ``ValueError`` for model-level problems before running."""
    return ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)


def run_case(case_path: str | Path, out_dir: str | Path, progress=None, case: Case | None = None,
             overwrite: bool = False, pending=(), command: str = "run") -> RunOutput:
    """Load (unless ``case`` is the already validated file), claim the output folder
    (:func:`riskassess.products.outfolder.claim`), simulate and write the run folder. ``pending``: product
    steps (``report``, ``vtk``) the caller makes next; the status stays ``running`` until they end.
    A sequential case (``simulation.coupling``) runs the net against the fixed target first and
    judges the free debris under the recorded loads (:mod:`riskassess.models.impact_sequential`).

    Parameters
    ----------
    case_path : str or Path
        The impact case file (mesh files relative to it).
    out_dir : str or Path
        The run folder.
    progress : callable or None
        ``progress(t)`` with the simulated time t (s) at every output sample (a sequential run's two
        steps each cover half of 0..end_time).
    case : Case or None
        The already validated case; read from ``case_path`` when None.
    overwrite : bool
        Replace an earlier run in ``out_dir``.
    pending : sequence of str
        Product steps still to come.
    command : str
        The command recorded in the manifest (``run``, ``assess``, ...).

    Returns
    -------
    RunOutput
        The run folder, the summary and the structures verdict (None without weak locations).
    """
    case_path = Path(case_path)
    case = case or load_case(case_path)
    sequential = case.simulation.coupling == "sequential"
    inputs = model_inputs(case, case_path.parent)       # model-level problems raise before the folder is claimed
    simulation = _simulation(wall_inputs(inputs) if sequential else inputs)
    folder = begin_run_folder(Path(out_dir), case_path, case, overwrite, command)
    with folder.recording():
        if sequential:
            wall_recorder = run_recorded(simulation, folder, progress=_scaled(progress, 0.0))
            wall = simulation
            loads = recorded_loads(wall_recorder.series, wall.health.reference_energy)
            simulation = _simulation(driven_inputs(inputs, loads))
        locations = weak_locations(case, simulation.assembly)
        monitor = None
        if locations and case.structures.release != "never":
            monitor = ReleaseMonitor(locations, simulation.system, case.structures.skip_initial,
                                     case.structures.release, interval_s=1.0 / case.simulation.output_rate)
        driven_progress = _scaled(progress, 0.5 * case.simulation.end_time) if sequential else progress
        capture = capture_monitor(case, locations, simulation.assembly)
        recorder = run_recorded(simulation, folder, progress=driven_progress, monitor=monitor, capture=capture)
        if sequential:
            recorder.series = applied_contact_series(recorder.series, loads)
            summary = write_sequential(folder, wall_recorder, wall, recorder, simulation, inputs.assembly, case)
            net_positions_final = wall_recorder.net["positions_lvlh"][-1]
        else:
            summary = write_simulation(folder, recorder, simulation, case)
            net_positions_final = recorder.net["positions_lvlh"][-1]
    verdict = None
    if locations:
        # A later stage that fails leaves the finished simulation results and says so.
        try:
            # the sequential run's net hit a wall, not the debris: no thread can have passed through it
            pass_throughs = None if sequential else pass_through_history(
                recorder.net["time"], recorder.net["positions_lvlh"], recorder.series["time"],
                recorder.series["body_com_lvlh"], recorder.series["body_to_lvlh"], simulation.assembly.net,
                [b.meshes_body for b in simulation.assembly.bodies])
            verdict = structures_verdict(
                locations, recorder.series, simulation.assembly, monitor.events if monitor else [],
                net_positions_final, case.structures.skip_initial, case.structures.release, pass_throughs,
                judge_pass_throughs=case.structures.thread_pass_through == "bound",
                thread_contact_drift=summary.get("checks", {}).get("energy_balance_relative_drift"),
                thread_segments=case.contact.thread_segments,
                capture=recorded_capture_window(case, locations, simulation.assembly, recorder) if capture else None)
            if not capture:         # the case states that nothing after its end time loads the target
                verdict["judged_window"] = {"window": "fixed", "end_time_s": float(recorder.series["time"][-1])}
            if case.structures.twin:
                verdict = _with_twin(verdict, locations, recorder.series, case, case_path)
            results.atomic_write_npz(folder.path / "structures.npz", demand_series(locations, recorder.series))
            results.atomic_write_json(folder.path / "structures.json", verdict)
        except BaseException as exc:
            folder.fail("structures_failed", exc)
            raise
        folder.add_files("structures.json", "structures.npz")
    folder.finish("complete", pending)
    return RunOutput(folder.path, summary, verdict)


def capture_monitor(case: Case, locations, assembly) -> CaptureMonitor | None:
    """The capture's settle test for the run (``structures.window = "capture"``; None otherwise): it stops the
    simulation once the capture is over (:mod:`structures.capture_window`)."""
    if not locations or case.structures.window != "capture":
        return None
    s = case.structures
    body, hold_s = _capture_body_and_hold(case, assembly)
    return CaptureMonitor(locations, assembly.net.masses, body, s.skip_initial, s.capture_energy_J, hold_s,
                          interval_s=1.0 / case.simulation.output_rate, energy_fraction=s.capture_energy_fraction)


def recorded_capture_window(case: Case, locations, assembly, recorder) -> dict:
    """Whether and when the recorded run's capture was over (:func:`structures.capture_window.capture_window`),
    read from its series and net snapshots."""
    s = case.structures
    body, hold_s = _capture_body_and_hold(case, assembly)
    window = capture_window(locations, recorder.series, recorder.net, assembly.net.masses, body,
                            assembly.bodies[body].name, s.skip_initial, s.capture_energy_J, hold_s,
                            s.capture_energy_fraction)
    window["end_time_cap_s"] = case.simulation.end_time
    window["stopped_early"] = bool(recorder.stopped_early)
    return window


def _capture_body_and_hold(case: Case, assembly) -> tuple[int, float]:
    """The capture's reference body (index) and hold (s): the same for the online test and the recorded one."""
    body = reference_body(assembly.bodies, assembly.joints, assembly.debris_indices)
    return body, hold_time(case.structures.capture_hold_s, case.launch.velocity)


def _with_twin(verdict: dict, locations, series: dict, case: Case, case_path: Path) -> dict:
    """The verdict with every judged peak labelled against a twin run (launch speed x (1 + TWIN_OFFSET), no
    release, no products: :func:`structures.verdict.apply_twin`); the twin is not run when the run already
    shows debris (the answer stands; its holding locations keep ``peak_window = "unchecked"``)."""
    skip, policy = case.structures.skip_initial, case.structures.release
    if verdict["debris_state"] == DEBRIS:       # the answer stands; holding locations stay "unchecked"
        verdict["twin"] = {"ran": False, "launch_velocity_factor": 1.0 + TWIN_OFFSET,
                           "note": "not run: the run shows debris"}
        return verdict
    launch = case.launch.model_copy(update={"velocity": case.launch.velocity * (1.0 + TWIN_OFFSET)})
    # the twin covers the run's own window: a capture window may have stopped the run before its end time (the cap)
    end = float(series["time"][-1])
    simulation = case.simulation
    if end < simulation.end_time - 0.5 * simulation.step:
        simulation = simulation.model_copy(update={"end_time": end})
    twin_case = case.model_copy(update={"launch": launch, "simulation": simulation})
    twin = _simulation(model_inputs(twin_case, case_path.parent))
    try:
        twin_series = twin.run().series
    except SimulationFailed as exc:
        return apply_twin(verdict, locations, series, None, skip, policy, f"the twin run failed: {exc}")
    if twin_series["time"].shape != series["time"].shape:
        return apply_twin(verdict, locations, series, None, skip, policy,
                          f"the twin run's {twin_series['time'].size} samples do not match the run's {series['time'].size}")
    return apply_twin(verdict, locations, series, twin_series, skip, policy)


def _scaled(progress, offset: float):
    """Progress of one step of a sequential run (wall run: ``offset`` 0, driven run: half the end
    time) on the 0..end_time scale of the whole: each step is half of it."""
    return None if progress is None else (lambda t: progress(offset + 0.5 * t))


def run_recorded(simulation: ImpactSimulation, folder: OutputFolder, **run_options):
    """``simulation.run(**run_options)``; when it stops (a failed health check, :mod:`multibody.health`,
    or any error) the manifest also gets the verdict 'indeterminate' and the health record, and the
    folder's recording marks it 'failed'.

    Parameters
    ----------
    simulation : ImpactSimulation
        The Exudyn model.
    folder : OutputFolder
        The claimed run folder.
    **run_options
        ``progress``, ``monitor`` and ``capture`` of :meth:`multibody.impact.ImpactSimulation.run`.

    Returns
    -------
    multibody.recorder.Recorder
    """
    try:
        return simulation.run(**run_options)
    except BaseException:
        folder.manifest.update(debris_state=INDETERMINATE, health=simulation.health.summary())
        raise


def begin_run_folder(out: Path, case_path: Path, case: Case, overwrite: bool = False,
                     command: str = "run") -> OutputFolder:
    """Claim the run folder and write the case into it; the manifest says 'running', so an
    interrupted run is recognisable by later stages.

    Parameters
    ----------
    out : Path
        The run folder.
    case_path : Path
        The case file (copied as ``case.toml``; the validated case goes to ``case.json``).
    case : Case
        The validated case.
    overwrite : bool
        Replace an earlier run in ``out``.
    command : str
        The command recorded in the manifest.

    Returns
    -------
    OutputFolder
    """
    folder = claim(out, case.name, command, overwrite, stage="impact", software=software_versions())
    with folder.recording():
        results.atomic_write_bytes(folder.path / "case.toml", case_path.read_bytes())
        results.atomic_write_json(folder.path / "case.json", case.model_dump())
        folder.add_files("case.toml", "case.json")
    return folder


def write_simulation(folder: OutputFolder, recorder, simulation: ImpactSimulation, case: Case) -> dict:
    """Write the simulation's results and summary and list them in the manifest (the status stays
    'running': the caller finishes the folder).

    Parameters
    ----------
    folder : OutputFolder
        The claimed run folder.
    recorder : multibody.recorder.Recorder
        The finished run's series and net snapshots.
    simulation : ImpactSimulation
        The simulated model.
    case : Case
        The case (its name goes into the summary).

    Returns
    -------
    dict
        The summary, as in ``summary.json``.
    """
    summary = run_summary(recorder, simulation.assembly, case.name)
    write_simulation_results(folder.path, recorder, simulation)
    results.atomic_write_json(folder.path / "summary.json", summary)
    folder.add_files("summary.json", "timeseries.npz", "net.npz", "bodies.npz")
    return summary


def write_sequential(folder: OutputFolder, wall_recorder, wall: ImpactSimulation, recorder,
                     simulation: ImpactSimulation, coupled, case: Case) -> dict:
    """Write a sequential run: the driven debris' series (``timeseries.npz``), the net of the wall
    run (``net.npz``) and the wall run's own series (``wall_timeseries.npz``: the loads recorded on
    the fixed target, the net's energies), and the summary of both; ``coupled``: the case's own
    assembly (its net gives the momentum-exchange estimate).

    Parameters
    ----------
    folder : OutputFolder
        The claimed run folder.
    wall_recorder : multibody.recorder.Recorder
        Step 1, the net against the fixed target.
    wall : ImpactSimulation
        Step 1's model.
    recorder : multibody.recorder.Recorder
        Step 2, the driven debris (series with the applied contact loads).
    simulation : ImpactSimulation
        Step 2's model.
    coupled : multibody.assembly.ImpactAssembly
        The case's own (coupled) assembly.
    case : Case
        The case.

    Returns
    -------
    dict
        The summary, as in ``summary.json``.
    """
    summary = sequential_summary(wall_recorder, wall.assembly, recorder, simulation.assembly, coupled, case.name)
    write_net_and_bodies(folder.path, wall_recorder, wall)
    results.atomic_write_npz(folder.path / "wall_timeseries.npz", dict(wall_recorder.series))
    write_series(folder.path, recorder, simulation)
    results.atomic_write_json(folder.path / "summary.json", summary)
    folder.add_files("summary.json", "timeseries.npz", "net.npz", "bodies.npz", "wall_timeseries.npz")
    return summary


def write_series(out: Path, recorder, simulation: ImpactSimulation) -> None:
    """``timeseries.npz``: the recorder's series with the body and joint names.

    Parameters
    ----------
    out : Path
        The run folder.
    recorder : multibody.recorder.Recorder
        The run's recorder (series in SI, frames in the key names).
    simulation : ImpactSimulation
        The simulated model (body names, masses (kg), joint names and kinds).
    """
    assembly = simulation.assembly
    series = dict(recorder.series)
    series["body_names"] = np.array([b.name for b in assembly.bodies])
    series["body_masses"] = np.array([b.mass for b in assembly.bodies])
    series["joint_names"] = np.array([j.name for j in assembly.joints])
    series["joint_kinds"] = np.array([j.kind for j in assembly.joints])
    results.atomic_write_npz(out / "timeseries.npz", series)


def write_simulation_results(out: Path, recorder, simulation: ImpactSimulation) -> None:
    """``timeseries.npz``, ``net.npz`` and ``bodies.npz`` of a coupled run (:func:`write_series`,
    :func:`write_net_and_bodies`).

    Parameters
    ----------
    out : Path
        The run folder.
    recorder : multibody.recorder.Recorder
        The run's recorder.
    simulation : ImpactSimulation
        The simulated model.
    """
    write_series(out, recorder, simulation)
    write_net_and_bodies(out, recorder, simulation)


def write_net_and_bodies(out: Path, recorder, simulation: ImpactSimulation) -> None:
    """``net.npz`` (the recorder's net snapshots and the net's arrays) and ``bodies.npz`` (meshes).

    Parameters
    ----------
    out : Path
        The run folder.
    recorder : multibody.recorder.Recorder
        The run's recorder (net snapshots, LVLH).
    simulation : ImpactSimulation
        The simulated model: net threads, rest lengths (m), stiffness, damping, masses (kg), radii (m);
        body meshes (m, body frame).
    """
    assembly = simulation.assembly
    net = assembly.net
    results.atomic_write_npz(out / "net.npz", dict(
        recorder.net, threads=net.threads, rest_lengths=net.rest_lengths, stiffness=net.stiffness,
        damping=net.damping, masses=net.masses, radii=net.radii, n_bullets=net.n_bullets))
    meshes = {}
    for k, body in enumerate(assembly.bodies):
        merged = trimesh.util.concatenate(body.meshes_body)
        meshes[f"vertices_{k}"] = np.asarray(merged.vertices)
        meshes[f"faces_{k}"] = np.asarray(merged.faces)
    results.atomic_write_npz(out / "bodies.npz", meshes)

