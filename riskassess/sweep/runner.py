"""Run a sweep's cases on dask.distributed and write each finished run to the results store.

Workers run :func:`simulate_run` (the same pipeline as ``riskassess run``) in their own
processes and return a small JSON-ready record; only this client process writes the store,
as each run finishes (:func:`dask.distributed.as_completed`). A worker that dies has its
run rescheduled by the Dask scheduler; a run that fails is recorded with its error and the
sweep goes on.
"""
from __future__ import annotations

import contextlib
import itertools
import logging
import math
import shutil
import tempfile
import time
import tomllib
from dataclasses import dataclass
from pathlib import Path

from multibody.health import SimulationFailed
from riskassess.cases.impact import CaseError, validate_case
from riskassess.products.outfolder import open_existing
from riskassess.products.results import atomic_write_json
from riskassess.sweep.cluster_log import StderrToFile, distributed_logging_to
from riskassess.products.sweep_records import debris_state_of, indeterminate_reasons_of
from riskassess.sweep.spec import RunSpec, SweepSpecError, case_with
from riskassess.sweep.store import ResultStore
from structures.verdict import INDETERMINATE

#: Error types that come from the cluster, not from the run: a resume retries these runs.
INFRASTRUCTURE_ERRORS = ("KilledWorker", "CommClosedError", "CancelledError", "TimeoutError", "FutureCancelledError")
#: Validating one run's case costs about 36 ms (envisat_small, this machine); up to this many
#: runs every run is validated before the sweep (about 7 s), above it a sample (validate_runs).
VALIDATE_ALL_UP_TO = 200
#: Exit code of a sweep that ended with failed, indeterminate or pending runs: the code of a
#: failed single run, since the envelope has runs it cannot count as safe.
UNKNOWN_RUNS_EXIT = SimulationFailed.exit_code


class RunFailed(RuntimeError):
    """A run's failure as it crosses from the worker to the client: ``kind`` and message.

    Carries every failure the same way (a numerical failure, :class:`multibody.health.SimulationFailed`,
    as kind "diverged"), so the store and the report need one form only.
    """

    def __init__(self, kind: str, message: str):
        super().__init__(kind, message)
        self.kind = kind
        self.message = message

    def __str__(self) -> str:
        return self.message


@dataclass
class SweepOutcome:
    total: int
    skipped: int       # finished in an earlier sweep with the same store
    done: int
    failed: int
    wall_s: float
    indeterminate: int = 0   # of ``done``: runs whose verdict is indeterminate


def _ratio(peak, allowable) -> float:
    """Peak over allowable; NaN when either is missing (an indeterminate verdict)."""
    if peak is None or not allowable:
        return math.nan
    return peak / allowable


def _location_record(loc: dict) -> dict:
    criteria = loc["criteria"]
    return {"fails": loc["fails"], "likelihood": loc["likelihood"], "released_at_s": loc["released_at_s"],
            "utilization": max((_ratio(c["peak"], c["decisive_allowable"]) for c in criteria.values()),
                               default=math.nan),
            "min_margin_of_safety": min((c["margin_of_safety"] for c in criteria.values()
                                         if c["margin_of_safety"] is not None), default=None),
            "peaks": {name: c["peak"] for name, c in criteria.items()},
            "units": {name: c["unit"] for name, c in criteria.items()},
            # why a location has no verdict and the rules with it (structures.indeterminacy), so a sweep counts runs per rule
            "state": loc.get("state"), "indeterminate_reason": loc.get("indeterminate_reason"),
            "indeterminate_rules": list(loc["indeterminate_rules"])}


def run_record(summary: dict, verdict: dict | None, overrides: dict) -> dict:
    """What the store keeps of one run: inputs, verdict, margins, peak loads, wall time (SI).

    ``debris_state`` is the verdict's (``debris`` / ``no_debris`` / ``indeterminate``; None for
    a case without weak locations) and ``secondary_debris`` the same as True / False / None.

    Parameters
    ----------
    summary : dict
        The run summary (:func:`riskassess.products.summary.run_summary`).
    verdict : dict or None
        The structural verdict (``structures.json``); None for a case without weak locations.
    overrides : dict
        Dotted case key -> value (SI) of this run.

    Returns
    -------
    dict
        ``inputs``, ``secondary_debris``, ``debris_state``, ``peak_contact_force_N``,
        ``peak_contact_moment_Nm`` (about the debris CoM), ``joint_peak_moment_after_transient_Nm``,
        ``energy_balance_relative_drift``, ``wall_time_s``, ``steps_per_second``, ``locations``
        (per location ``utilization`` (-), ``likelihood``, ``peaks`` in their ``units``, ...),
        ``released_pieces`` and ``breakup_likelihood``; with ``structures.window = "capture"`` also
        ``capture_window`` (``settled``, ``settled_at_s``, ``end_time_s``, ``net_energy_relative_end_J``,
        ``last_rise_s``).
    """
    record = {
        "inputs": overrides,
        "secondary_debris": None,
        "debris_state": None,
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
        record["locations"][loc["name"]] = _location_record(loc)
        survival *= 1.0 - (math.nan if loc["likelihood"] is None else loc["likelihood"])
    # independent locations: the run breaks up when any location fails
    record["breakup_likelihood"] = 1.0 - survival
    record["released_pieces"] = [{k: p[k] for k in ("location", "bodies", "mass_kg", "release_time_s",
                                                    "inside_net_at_end")} for p in verdict["released_pieces"]]
    debris = verdict.get("secondary_debris")
    record["secondary_debris"] = None if debris is None else bool(debris)
    record["debris_state"] = verdict.get("debris_state")
    # the stored state: the verdict's, and indeterminate when its evidence is not finite
    record["debris_state"] = debris_state_of(record)
    if record["debris_state"] == INDETERMINATE:
        record["secondary_debris"] = None
    record["indeterminate_reasons"] = indeterminate_reasons_of(record)
    if verdict.get("capture_window"):      # structures.window = "capture": when the capture was over, and its energy
        window = verdict["capture_window"]
        record["capture_window"] = {k: window.get(k) for k in ("settled", "settled_at_s", "end_time_s",
                                                               "net_energy_relative_end_J", "last_rise_s")}
    return record


def simulate_run(case_path: str, case_text: str, overrides: dict, keep_dir: str | None = None) -> dict:
    """One run of the sweep (runs on a worker): case + overrides -> record for the store.

    A simulation stopped by the numerical health checks raises :class:`RunFailed` of kind
    ``diverged``, with the check's message.

    Parameters
    ----------
    case_path : str
        The case file (TOML); mesh paths in it are relative to its folder.
    case_text : str
        Its content, as the sweep read it.
    overrides : dict
        Dotted case key -> value (SI) of this run.
    keep_dir : str, optional
        Run folder to keep (``--keep-runs DIR/<run id>``); None runs in a temporary folder that is
        removed afterwards.

    Returns
    -------
    dict
        The run's record (:func:`run_record`).
    """
    from riskassess.stages.run import run_case  # the pipeline imports Exudyn: only on the worker

    case = validate_case(case_with(tomllib.loads(case_text), overrides), case_path)
    out = Path(keep_dir) if keep_dir else Path(tempfile.mkdtemp(prefix="riskassess-sweep-"))
    try:
        try:
            # a kept folder of this run from an earlier attempt (a retry) is this run's own: replace it
            result = run_case(case_path, out, case=case, overwrite=bool(keep_dir))
        except SimulationFailed as exc:
            raise RunFailed("diverged", f"SimulationFailed: {exc}") from None
        if keep_dir:
            atomic_write_json(out / "overrides.json", overrides)
            open_existing(out).add_files("overrides.json")
        return run_record(result.summary, result.structures, overrides)
    finally:
        if not keep_dir:
            shutil.rmtree(out, ignore_errors=True)


def failure_kind(exc: BaseException) -> str:
    """``diverged``, ``infrastructure`` (a resume retries it) or ``simulation`` (any other error of the run).

    Parameters
    ----------
    exc : BaseException
        The exception a run's future raised on the client.
    """
    if isinstance(exc, RunFailed):
        return exc.kind
    if isinstance(exc, SimulationFailed):
        return "diverged"
    return "infrastructure" if type(exc).__name__ in INFRASTRUCTURE_ERRORS else "simulation"


def failure_message(exc: BaseException) -> str:
    """The text stored under ``error`` for a failed run: the message of a :class:`RunFailed`, else 'Type: message'.

    Parameters
    ----------
    exc : BaseException
        The exception a run's future raised on the client.
    """
    return str(exc) if isinstance(exc, RunFailed) else f"{type(exc).__name__}: {exc}"


def validation_sample(specs: list[RunSpec], limit: int = VALIDATE_ALL_UP_TO) -> tuple[list[RunSpec], str]:
    """The runs whose cases are validated before the sweep, and a sentence saying which.

    Up to ``limit`` runs: all. Above: for each overridden key, the first run with each of its
    distinct values, plus the runs at the corners of the grid (every key at its smallest or
    largest value), so every value of every key is checked at least once. A combination of
    values that only fails together is then found when its run starts, and recorded as a
    failed run (never as safe).

    Parameters
    ----------
    specs : list of riskassess.sweep.spec.RunSpec
        Every run of the sweep.
    limit : int
        Largest number of runs that are all validated.

    Returns
    -------
    sample : list of riskassess.sweep.spec.RunSpec
        The runs to validate.
    what : str
        The sentence saying which.
    """
    if len(specs) <= limit:
        return specs, f"all {len(specs)} runs validated"
    keys = list(specs[0].overrides)
    bounds = {k: (min(s.overrides[k] for s in specs), max(s.overrides[k] for s in specs)) for k in keys}
    corners = {tuple(corner) for corner in itertools.product(*bounds.values())} if len(keys) <= 10 else set()
    chosen, seen = {}, set()
    for spec in specs:
        values = tuple(spec.overrides[k] for k in keys)
        new = [(k, v) for k, v in zip(keys, values) if (k, v) not in seen]
        if new or values in corners:
            chosen[spec.run_id] = spec
            seen.update(new)
            corners.discard(values)
    distinct = len(seen)
    return list(chosen.values()), (f"{len(chosen)} of {len(specs)} runs validated before the sweep (each of the "
                                   f"{distinct} distinct values of the {len(keys)} overridden keys at least once, "
                                   f"and the corners of the grid); the others are validated when they run")


def validate_runs(case_path: str, case_text: str, specs: list[RunSpec], limit: int = VALIDATE_ALL_UP_TO) -> str:
    """The runs' cases must load before any run (:func:`validation_sample` says which are
    checked): one message listing the bad ones. Returns the sentence of what was validated.

    Parameters
    ----------
    case_path : str
        The case file, named in the messages.
    case_text : str
        Its content (TOML).
    specs : list of riskassess.sweep.spec.RunSpec
        Every run of the sweep.
    limit : int
        Largest number of runs that are all validated.
    """
    raw = tomllib.loads(case_text)
    sample, what = validation_sample(specs, limit)
    problems = []
    for spec in sample:
        try:
            validate_case(case_with(raw, spec.overrides), case_path)
        except KeyError as exc:
            raise SweepSpecError(f"{case_path}: {exc.args[0]}") from None
        except CaseError as exc:
            problems.append(f"run {spec.run_id} {spec.overrides}:\n  {str(exc).replace(chr(10), chr(10) + '  ')}")
    if problems:
        more = f"\n... and {len(problems) - 5} more" if len(problems) > 5 else ""
        raise SweepSpecError(f"{len(problems)} of {len(sample)} validated sweep runs give an invalid case "
                             f"({what}):\n" + "\n".join(problems[:5]) + more)
    return what


def _client(scheduler: str | None, n_workers: int, log_path: Path | None = None):
    """A client of the scheduler at ``scheduler``, or of a new local cluster whose workers write
    their standard error to ``log_path`` (:mod:`riskassess.sweep.cluster_log`)."""
    from dask.distributed import Client, LocalCluster

    if scheduler:
        return Client(scheduler), None
    # processes, one thread each: Exudyn systems are not shared between threads
    cluster = LocalCluster(n_workers=n_workers, threads_per_worker=1, processes=True, dashboard_address=None,
                           silence_logs=logging.WARNING if log_path else logging.ERROR)
    client = Client(cluster)
    if log_path is not None:
        client.register_plugin(StderrToFile(log_path))
    return client, cluster


def run_sweep(case_path: str | Path, specs: list[RunSpec], store: ResultStore, definition: dict,
              scheduler: str | None = None, n_workers: int = 2, retry_failed: bool = False,
              keep_runs: str | Path | None = None, progress=None, validate: bool = True,
              log_path: str | Path | None = None) -> SweepOutcome:
    """Run every spec not finished in ``store``; ``progress(done, failed, remaining)`` after each.

    ``validate=False`` when the caller already ran :func:`validate_runs`. ``log_path``: the Dask
    cluster's warnings go to this file instead of the terminal (:mod:`riskassess.sweep.cluster_log`).

    Parameters
    ----------
    case_path : str or Path
        The case file (TOML).
    specs : list of riskassess.sweep.spec.RunSpec
        Every run of the sweep (:func:`riskassess.sweep.spec.run_specs`).
    store : ResultStore
        The results store, open for writing.
    definition : dict
        Sweep definition recorded in the store (``arguments``, ``created``).
    scheduler : str, optional
        Address of a Dask scheduler; None starts a local cluster.
    n_workers : int
        Worker processes of the local cluster (one thread each), >= 1.
    retry_failed : bool
        Run again every failed run, not only those lost to the cluster.
    keep_runs : str or Path, optional
        Folder where each run keeps its run folder (``<keep_runs>/<run id>``).
    progress : callable, optional
        ``progress(done, failed, remaining)``, counts of runs.
    validate : bool
        Validate the runs' cases first (:func:`validate_runs`).
    log_path : str or Path, optional
        The cluster's log file (``dask.log``).

    Returns
    -------
    SweepOutcome
        Run counts and wall time (s).
    """
    if n_workers < 1:
        raise ValueError(f"n_workers must be >= 1. Got {n_workers} instead.")
    case_path = str(case_path)
    case_text = Path(case_path).read_text()
    if validate:
        validate_runs(case_path, case_text, specs)
    store.declare(case_path, case_text, definition, specs)
    todo = store.to_run([s.run_id for s in specs], retry_failed)
    by_id = {s.run_id: s for s in specs}
    start = time.perf_counter()
    done = failed = indeterminate = 0
    if progress:
        progress(done, failed, len(todo))
    if todo:
        with contextlib.ExitStack() as stack:
            if log_path is not None:
                stack.enter_context(distributed_logging_to(log_path))
            done, failed, indeterminate = _run_on_cluster(
                _client(scheduler, n_workers, Path(log_path) if log_path else None), case_path, case_text,
                [by_id[rid] for rid in todo], store, keep_runs, progress)
    return SweepOutcome(len(specs), len(specs) - len(todo), done, failed, time.perf_counter() - start, indeterminate)


def _run_on_cluster(client_cluster, case_path: str, case_text: str, todo: list[RunSpec], store: ResultStore,
                    keep_runs, progress) -> tuple[int, int, int]:
    """Submit every run, write each to the store as it finishes; (done, failed, indeterminate).
    Closes the client (and the local cluster) at the end."""
    from dask.distributed import as_completed

    client, cluster = client_cluster
    done = failed = indeterminate = 0
    try:
        futures = {client.submit(simulate_run, case_path, case_text, spec.overrides,
                                 str(Path(keep_runs) / spec.run_id) if keep_runs else None,
                                 key=f"riskassess-run-{spec.run_id}", pure=False): spec.run_id for spec in todo}
        for future in as_completed(futures):
            rid = futures[future]
            try:
                record = future.result()
                store.write_done(rid, record)
                done += 1
                indeterminate += debris_state_of(record) == INDETERMINATE
            except Exception as exc:  # noqa: BLE001 -- every failure is recorded, the sweep goes on
                store.write_failed(rid, failure_message(exc), failure_kind(exc))
                failed += 1
            if progress:
                progress(done, failed, len(todo) - done - failed)
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return done, failed, indeterminate
