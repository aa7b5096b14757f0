"""The risk pipeline: case file -> coupled simulation -> run folder.

Later stages (structures, reports, VTK) read the run folder; nothing here re-runs them.
"""
from __future__ import annotations

import datetime
import platform
import shutil
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh

from multibody.impact import ImpactSimulation
from riskassess import results
from riskassess.assemble import model_inputs, weak_locations
from riskassess.case import Case, load_case
from riskassess.summary import run_summary
from structures.release import ReleaseMonitor
from multibody.health import SimulationFailed
from structures.verdict import INDETERMINATE, demand_series, structures_verdict


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


def prepare_simulation(case: Case, case_path: Path) -> ImpactSimulation:
    """Build the Exudyn model; raises ``ValueError`` for model-level problems before running."""
    inputs = model_inputs(case, case_path.parent)
    return ImpactSimulation(inputs.assembly, inputs.rest_attitudes, inputs.rest_coms)


def run_case(case_path: str | Path, out_dir: str | Path, progress=None, case: Case | None = None) -> RunOutput:
    """Load (unless ``case`` is the already validated file), simulate and write the run folder."""
    case_path = Path(case_path)
    case = case or load_case(case_path)
    simulation = prepare_simulation(case, case_path)
    out = Path(out_dir)
    manifest = begin_run_folder(out, case_path, case)
    locations = weak_locations(case, simulation.assembly)
    monitor = None
    if locations and case.structures.release != "never":
        monitor = ReleaseMonitor(locations, simulation.system, case.structures.skip_initial, case.structures.release)
    try:
        recorder = simulation.run(progress=progress, monitor=monitor)
    except BaseException as exc:
        record_failed_run(out, manifest, exc, simulation)
        raise
    summary = finish_simulation(out, manifest, recorder, simulation, case)
    verdict = None
    if locations:
        # A later stage that fails leaves the finished simulation results and says so.
        try:
            verdict = structures_verdict(
                locations, recorder.series, simulation.assembly, monitor.events if monitor else [],
                recorder.net["positions_lvlh"][-1], case.structures.skip_initial, case.structures.release)
            results.atomic_write_npz(out / "structures.npz", demand_series(locations, recorder.series))
            results.atomic_write_json(out / "structures.json", verdict)
        except Exception as exc:
            manifest.update(status="structures_failed", error=f"{type(exc).__name__}: {exc}")
            results.atomic_write_json(out / "manifest.json", manifest)
            raise
        manifest["files"] += ["structures.json", "structures.npz"]
        results.atomic_write_json(out / "manifest.json", manifest)
    return RunOutput(out, summary, verdict)


def record_failed_run(out: Path, manifest: dict, exc: BaseException, simulation: ImpactSimulation) -> None:
    """The manifest of a run whose simulation stopped: status 'failed' (numerical health, see
    :mod:`multibody.health`) or 'interrupted' / 'error', the verdict 'indeterminate', and the reason."""
    if isinstance(exc, SimulationFailed):
        status = "failed"
    elif isinstance(exc, KeyboardInterrupt):
        status = "interrupted"
    else:
        status = "error"
    manifest.update(status=status, debris_state=INDETERMINATE, error=f"{type(exc).__name__}: {exc}",
                    health=simulation.health.summary())
    results.atomic_write_json(out / "manifest.json", manifest)


def begin_run_folder(out: Path, case_path: Path, case: Case) -> dict:
    """Create the run folder with the case and a manifest saying 'running', so an interrupted
    run is recognisable by later stages; returns the manifest to update."""
    out.mkdir(parents=True, exist_ok=True)
    manifest = {"format": results.FORMAT, "version": results.VERSION, "case": case.name,
                "created": datetime.datetime.now(datetime.timezone.utc).isoformat(),
                "status": "running", "files": ["case.toml", "case.json"], "software": software_versions()}
    shutil.copyfile(case_path, out / "case.toml")
    results.atomic_write_json(out / "case.json", case.model_dump())
    results.atomic_write_json(out / "manifest.json", manifest)
    return manifest


def finish_simulation(out: Path, manifest: dict, recorder, simulation: ImpactSimulation, case: Case) -> dict:
    """Write the simulation's results and summary; the manifest then says 'complete'."""
    summary = run_summary(recorder, simulation.assembly, case.name)
    write_simulation_results(out, recorder, simulation)
    results.atomic_write_json(out / "summary.json", summary)
    manifest.update(status="complete", files=manifest["files"] + ["summary.json", "timeseries.npz", "net.npz",
                                                                  "bodies.npz"])
    results.atomic_write_json(out / "manifest.json", manifest)
    return summary


def write_simulation_results(out: Path, recorder, simulation: ImpactSimulation) -> None:
    assembly = simulation.assembly
    series = dict(recorder.series)
    series["body_names"] = np.array([b.name for b in assembly.bodies])
    series["body_masses"] = np.array([b.mass for b in assembly.bodies])
    series["joint_names"] = np.array([j.name for j in assembly.joints])
    series["joint_kinds"] = np.array([j.kind for j in assembly.joints])
    results.atomic_write_npz(out / "timeseries.npz", series)
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

