"""Run a sweep's cases on dask.distributed and write each finished run to the results store.

Workers run :func:`simulate_run` (the same pipeline as ``riskassess run``) in their own
processes and return a small JSON-ready record; only this client process writes the store,
as each run finishes (:func:`dask.distributed.as_completed`). A worker that dies has its
run rescheduled by the Dask scheduler; a run that fails is recorded with its error and the
sweep goes on.
"""
from __future__ import annotations

import json
import logging
import shutil
import tempfile
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

from riskassess.case import CaseError, validate_case
from riskassess.sweep.spec import RunSpec, SweepSpecError, case_with
from riskassess.sweep.store import ResultStore

#: Error types that come from the cluster, not from the run: a resume retries these runs.
INFRASTRUCTURE_ERRORS = ("KilledWorker", "CommClosedError", "CancelledError", "TimeoutError", "FutureCancelledError")


@dataclass
class SweepOutcome:
    total: int
    skipped: int       # finished in an earlier sweep with the same store
    done: int
    failed: int
    wall_s: float


def run_record(summary: dict, verdict: dict | None, overrides: dict) -> dict:
    """What the store keeps of one run: inputs, verdict, margins, peak loads, wall time (SI)."""
    record = {
        "inputs": overrides,
        "secondary_debris": None if verdict is None else bool(verdict["secondary_debris"]),
        "peak_contact_force_N": summary["peak_contact_force_N"]["value"],
        "peak_contact_moment_Nm": summary["peak_contact_moment_about_debris_com_Nm"]["value"],
        "joint_peak_moment_after_transient_Nm": {
            name: max(j["max_abs_moment_after_transient_Nm"] or j["max_abs_moment_joint_Nm"])
            for name, j in summary["joints"].items()},
        "energy_balance_relative_drift": summary["checks"]["energy_balance_relative_drift"],
        "wall_time_s": summary["wall_time_s"],
        "steps_per_second": summary["steps_per_second"],
        "locations": {}, "released_pieces": [], "breakup_likelihood": None,
    }
    if verdict is None:
        return record
    survival = 1.0
    for loc in verdict["locations"]:
        criteria = loc["criteria"]
        record["locations"][loc["name"]] = {
            "fails": loc["fails"], "likelihood": loc["likelihood"], "released_at_s": loc["released_at_s"],
            "utilization": max(c["peak"] / c["decisive_allowable"] for c in criteria.values()),
            "min_margin_of_safety": min(c["margin_of_safety"] for c in criteria.values()),
            "peaks": {name: c["peak"] for name, c in criteria.items()},
            "units": {name: c["unit"] for name, c in criteria.items()},
        }
        survival *= 1.0 - loc["likelihood"]
    # independent locations: the run breaks up when any location fails
    record["breakup_likelihood"] = 1.0 - survival
    record["released_pieces"] = [{k: p[k] for k in ("location", "bodies", "mass_kg", "release_time_s",
                                                    "inside_net_at_end")} for p in verdict["released_pieces"]]
    return record


def simulate_run(case_path: str, case_text: str, overrides: dict, keep_dir: str | None = None) -> dict:
    """One run of the sweep (runs on a worker): case + overrides -> record for the store."""
    from riskassess.pipeline import run_case

    case = validate_case(case_with(tomllib.loads(case_text), overrides), case_path)
    out = Path(keep_dir) if keep_dir else Path(tempfile.mkdtemp(prefix="riskassess-sweep-"))
    try:
        result = run_case(case_path, out, case=case)
        if keep_dir:
            (out / "overrides.json").write_text(json.dumps(overrides, indent=2) + "\n")
        return run_record(result.summary, result.structures, overrides)
    finally:
        if not keep_dir:
            shutil.rmtree(out, ignore_errors=True)


def validate_runs(case_path: str, case_text: str, specs: list[RunSpec]) -> None:
    """Every run's case must load before any runs: one message listing the bad ones."""
    raw = tomllib.loads(case_text)
    problems = []
    for spec in specs:
        try:
            validate_case(case_with(raw, spec.overrides), case_path)
        except KeyError as exc:
            raise SweepSpecError(f"{case_path}: {exc.args[0]}") from None
        except CaseError as exc:
            problems.append(f"run {spec.run_id} {spec.overrides}:\n  {str(exc).replace(chr(10), chr(10) + '  ')}")
    if problems:
        more = f"\n... and {len(problems) - 5} more" if len(problems) > 5 else ""
        raise SweepSpecError(f"{len(problems)} of {len(specs)} sweep runs give an invalid case:\n"
                             + "\n".join(problems[:5]) + more)


def _client(scheduler: str | None, n_workers: int):
    from dask.distributed import Client, LocalCluster

    if scheduler:
        return Client(scheduler), None
    # processes, one thread each: Exudyn systems are not shared between threads
    cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True, dashboard_address=None,
                           silence_logs=logging.ERROR)
    return Client(cluster), cluster


def run_sweep(case_path: str | Path, specs: list[RunSpec], store: ResultStore, definition: dict,
              scheduler: str | None = None, n_workers: int = 2, retry_failed: bool = False,
              keep_runs: str | Path | None = None, progress=None, validate: bool = True) -> SweepOutcome:
    """Run every spec not finished in ``store``; ``progress(done, failed, remaining)`` after each.

    ``validate=False`` when the caller already ran :func:`validate_runs`.
    """
    from dask.distributed import as_completed

    case_path = str(case_path)
    case_text = Path(case_path).read_text()
    if validate:
        validate_runs(case_path, case_text, specs)
    store.declare(case_path, case_text, definition, specs)
    todo = store.to_run([s.run_id for s in specs], retry_failed)
    by_id = {s.run_id: s for s in specs}
    start = time.perf_counter()
    done = failed = 0
    if progress:
        progress(done, failed, len(todo))
    if todo:
        client, cluster = _client(scheduler, n_workers)
        try:
            futures = {client.submit(simulate_run, case_path, case_text, by_id[rid].overrides,
                                     str(Path(keep_runs) / rid) if keep_runs else None,
                                     key=f"riskassess-run-{rid}", pure=False): rid for rid in todo}
            for future in as_completed(futures):
                rid = futures[future]
                try:
                    store.write_done(rid, future.result())
                    done += 1
                except Exception as exc:  # noqa: BLE001 -- every failure is recorded, the sweep goes on
                    kind = "infrastructure" if type(exc).__name__ in INFRASTRUCTURE_ERRORS else "simulation"
                    store.write_failed(rid, f"{type(exc).__name__}: {exc}", kind)
                    failed += 1
                if progress:
                    progress(done, failed, len(todo) - done - failed)
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    return SweepOutcome(len(specs), len(specs) - len(todo), done, failed, time.perf_counter() - start)


def write_sweep_products(store: ResultStore, confidence: float = 0.95, reliability: float = 0.9,
                         pdf: bool = True) -> dict:
    """envelope.json and report.html (+ .pdf) beside the store; returns the envelope."""
    from riskassess import results
    from riskassess.report.document import render_document, render_pdf
    from riskassess.report.plotting import STYLE
    from riskassess.report.sweep import envelope_section, runs_section
    from riskassess.sweep.envelope import envelope

    import matplotlib.pyplot as plt

    rows = store.rows()
    info = store.info()
    env = envelope(rows, confidence=confidence, reliability=reliability)
    folder = store.path.parent
    results.atomic_write_json(folder / "envelope.json", env)
    varied = [a.split(" ", 1)[1].split("=")[0] for a in info.get("arguments", []) if a.startswith("--vary ")]
    with plt.rc_context(STYLE):
        sections = [envelope_section(rows, env, [k for k in varied if k != env["key"]]), runs_section(rows)]
    problems = [f"{env['pending_runs']} runs pending"] if env["pending_runs"] else []
    html = render_document(f"Sweep: {Path(info.get('case_path', '?')).name}",
                           " ".join(info.get("arguments", [])), folder, info.get("created", "-"), problems, sections)
    results.atomic_write_bytes(folder / "report.html", html.encode("utf-8"))
    if pdf:
        results.atomic_write_bytes(folder / "report.pdf", render_pdf(html, folder)[0])
    return env
