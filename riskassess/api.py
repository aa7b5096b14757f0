"""The Python API of the main jobs: load a net-impact case, change parameters, run it, read the
verdict and the time series, make the report. The ``riskassess run`` / ``assess`` / ``report``
commands call these same functions.

>>> import riskassess.api as ra
>>> case = ra.load_case("cases/envisat_small.toml").with_values({"simulation.end_time": 0.5})
>>> result = ra.run(case, "runs/small_short")            # doctest: +SKIP
>>> result.debris_state, result.peak_contact_force_N      # doctest: +SKIP
('debris', 16718.3)
>>> t, f = result.time, result.series["contact_force_lvlh"]  # (n,), (n, bodies, 3): s, N, LVLH

Units are SI throughout (m, kg, s, N, N m, rad); every vector names its frame in its key
(``_lvlh``: chaser-centred LVLH, x radial, y along-track, z cross-track; ``_body``: the body's
own frame; ``_joint``: the joint frame). docs/api.md has the full reference.
"""
from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from multibody.impact import kernels_compiled
from riskassess.cases.impact import Case, CaseError, read_toml, validate_case
from riskassess.stages.kinds import case_kind
from riskassess.products.outfolder import open_existing
from riskassess.stages.run import run_case
from riskassess.products.results import RunFolder, atomic_write_json
from riskassess.sweep.spec import case_with
from riskassess.products.report import write_report

__all__ = ["ImpactCase", "RunResult", "load_case", "run", "open_run", "report", "needs_compilation"]

#: File in a run folder with the parameters changed by :meth:`ImpactCase.with_values`.
OVERRIDES_FILE = "overrides.json"


@dataclass(frozen=True)
class ImpactCase:
    """A validated net-impact case file, possibly with some of its values changed.

    Attributes of the validated case read through: ``case.simulation.end_time`` (s),
    ``case.launch.velocity`` (m/s), ``case.name``; the pydantic model itself is ``case.model``
    (:class:`riskassess.cases.impact.Case`, docs/case-format.md).

    Parameters
    ----------
    path : Path
        The case file (TOML). Mesh paths in it are relative to its folder; the run folder keeps a
        copy of it (``case.toml``) and of the validated case with the overrides (``case.json``).
    raw : dict
        The file as parsed, before the overrides.
    model : riskassess.cases.impact.Case
        The validated case, overrides applied.
    overrides : dict
        Dotted case keys and their new values (SI), e.g. ``{"launch.velocity": 12.0}``.
    """

    path: Path
    raw: dict = field(repr=False)
    model: Case = field(repr=False)
    overrides: dict = field(default_factory=dict)

    def __getattr__(self, name: str):
        if name.startswith("_") or name in ("model", "raw", "path", "overrides"):
            raise AttributeError(name)  # during copy / unpickling, before the fields exist
        return getattr(self.model, name)

    def with_values(self, values: Mapping[str, object]) -> ImpactCase:
        """A new case with ``values`` changed, validated as the case file would be.

        Parameters
        ----------
        values : mapping of str to value
            Dotted case keys, as in ``riskassess sweep --vary``: ``"launch.velocity"`` (m/s),
            ``"simulation.end_time"`` (s), ``"target.joints[solar_array_hinge].torsional_damping"``
            (a list item by its ``name``, or by index ``[0]``). Values in the case file's units (SI).

        Returns
        -------
        ImpactCase
            This case with the values changed (earlier overrides kept unless replaced).

        Raises
        ------
        riskassess.cases.impact.CaseError
            A key the case does not have, or a value out of its range (the message names both).
        """
        overrides = {**self.overrides, **dict(values)}
        try:
            raw = case_with(self.raw, overrides)
        except KeyError as exc:
            raise CaseError(f"{self.path}: {exc.args[0]}") from None
        return ImpactCase(self.path, self.raw, validate_case(raw, self.path), overrides)


def load_case(path: str | Path) -> ImpactCase:
    """Read and validate a net-impact case file (``run``, ``assess`` and ``perceive`` cases).

    Parameters
    ----------
    path : str or Path
        Case file (TOML), docs/case-format.md.

    Returns
    -------
    ImpactCase

    Raises
    ------
    riskassess.cases.impact.CaseError
        The file is not valid (every problem named, with the file), or is a case of another kind
        (towing, approach, diagnosis: run those with their own command).
    """
    path = Path(path)
    raw = read_toml(path)
    kind = case_kind(raw)
    if kind != "impact":
        command = {"towing": "tow", "approach": "approach", "diagnosis": "diagnose"}[kind]
        raise CaseError(f"{path}: a {kind} case; the Python API runs net-impact cases only "
                        f"(use 'riskassess {command} {path}')")
    return ImpactCase(path, raw, validate_case(raw, path))


def needs_compilation(case: ImpactCase | None = None) -> bool:
    """The first run will compile the force kernels (about 30 s on one core): numba's disk cache
    holds no compilation of their current source for this CPU (:mod:`multibody.jit_cache`).

    Parameters
    ----------
    case : ImpactCase or riskassess.cases.impact.Case, optional
        The case to be run: its ``simulation.net_integration`` and ``integrator`` choose the kernels
        (Runge-Kutta integrators and ``"exudyn"`` use the reference path's); default the kernel path.
    """
    if case is None:
        return not kernels_compiled()
    simulation = case.simulation
    return not kernels_compiled(simulation.net_integration == "kernel" and simulation.integrator == "VelocityVerlet")


def run(case: ImpactCase | str | Path, out: str | Path, *, overwrite: bool = False,
        progress: Callable[[float], None] | None = None, pending=(), command: str = "run") -> RunResult:
    """Simulate the capture and write the run folder (the same folder as ``riskassess run``).

    Parameters
    ----------
    case : ImpactCase or path
        The case (a path is loaded with :func:`load_case`).
    out : str or Path
        Run folder: new, empty, or this case's earlier run with ``overwrite`` (docs/outputs.md).
    overwrite : bool
        Replace this case's earlier run in ``out`` (only the files its manifest lists).
    progress : callable, optional
        ``progress(t)`` with the simulated time t (s) at every output sample.
    pending : sequence of str
        Product steps the caller makes next (``"report"``, ``"vtk"``): the folder's status stays
        ``running`` until they are recorded (:func:`riskassess.products.outfolder.step_done`).
    command : str
        The command recorded in the manifest (``run`` or ``assess``).

    Returns
    -------
    RunResult
        The finished run, read back from ``out``.

    Raises
    ------
    multibody.health.SimulationFailed
        The simulation failed its numerical health check; the folder says ``failed``.
    riskassess.products.outfolder.OutputRefused
        ``out`` holds something else.
    """
    case = case if isinstance(case, ImpactCase) else load_case(case)
    output = run_case(case.path, out, progress=progress, case=case.model, overwrite=overwrite, pending=pending,
                      command=command)
    if case.overrides:
        atomic_write_json(output.run_dir / OVERRIDES_FILE, case.overrides)
        open_existing(output.run_dir).add_files(OVERRIDES_FILE)
    return open_run(output.run_dir)


def open_run(path: str | Path) -> RunResult:
    """A run folder written by :func:`run` or ``riskassess run`` / ``assess``.

    Raises
    ------
    riskassess.products.results.MissingData
        The folder lacks its summary (not a finished impact run).
    ValueError
        Not a run folder of this tool (no readable manifest).

    Parameters
    ----------
    path : str or Path
        The run folder (holding ``manifest.json`` and ``summary.json``).

    Returns
    -------
    RunResult
    """
    return RunResult(RunFolder(path))


def report(run: RunResult | str | Path, pdf: bool = False, progress=None):
    """Write ``report.html`` (and ``report.pdf`` with ``pdf=True``) into the run folder.

    Parameters
    ----------
    run : RunResult or path
        A finished run (or its folder).
    pdf : bool
        Also write the PDF (slower: WeasyPrint).
    progress : callable, optional
        ``progress(done, total, title)`` after each report section.

    Returns
    -------
    riskassess.products.report.ReportOutput
        ``.html`` and ``.pdf`` paths, ``.sections`` (each says whether its data was missing).
    """
    # Imported here, not at the top: riskassess.products.report selects matplotlib's headless backend on
    # import, which would switch off a notebook's inline plots for anyone importing this module.
    folder = run.path if isinstance(run, RunResult) else Path(run)
    return write_report(folder, pdf=pdf, progress=progress)


class RunResult:
    """A finished impact run, read from its folder.

    Attributes
    ----------
    path : Path
        The run folder.
    summary : dict
        ``summary.json``: peaks, joints, checks, wall time (keys carry their units).
    verdict : dict or None
        ``structures.json``, the structural verdict (a case with weak locations), else None.
    manifest : dict
        ``manifest.json``: status, files, software versions.
    """

    def __init__(self, folder: RunFolder):
        self._folder = folder
        self.path = folder.path
        self.manifest = folder.manifest
        self.summary = folder.summary
        self.verdict = folder.structures if folder.has("structures.json") else None

    def __repr__(self) -> str:
        return f"RunResult({str(self.path)!r}, debris_state={self.debris_state!r})"

    @property
    def debris_state(self) -> str | None:
        """'debris', 'no_debris' or 'indeterminate' (docs/structures.md, "Three answers");
        None for a case without weak locations (no verdict was asked for); 'indeterminate' for a
        case with weak locations whose verdict is missing (the structures stage failed)."""
        if self.verdict is None:
            return "indeterminate" if (self._folder.case.get("structures") or {}).get("weak_locations") else None
        return self.verdict.get("debris_state") or ("debris" if self.verdict["secondary_debris"] else "no_debris")

    @property
    def released_pieces(self) -> list[dict]:
        """Pieces broken off (bodies, mass_kg, release_time_s, velocity relative to the chaser, LVLH)."""
        return [] if self.verdict is None else self.verdict["released_pieces"]

    @property
    def peak_contact_force_N(self) -> float:
        """Peak magnitude of the net's total contact force on the debris (N)."""
        return float(self.summary["peak_contact_force_N"]["value"])

    @property
    def peak_contact_moment_Nm(self) -> float:
        """Peak magnitude of the contact moment about the debris centre of mass (N m)."""
        return float(self.summary["peak_contact_moment_about_debris_com_Nm"]["value"])

    @cached_property
    def series(self) -> dict[str, np.ndarray]:
        """The time series (``timeseries.npz``), first axis time. Among them: ``time`` (n,) s;
        ``contact_force_lvlh`` (n, bodies, 3) N, LVLH; ``contact_moment_body`` (n, bodies, 3) N m,
        body frame; ``debris_com_lvlh`` (n, 3) m and ``debris_velocity_lvlh`` (n, 3) m/s, LVLH;
        ``body_omega_body`` (n, bodies, 3) rad/s, body frame; ``joint_rotation_joint`` and
        ``joint_moment_joint`` (n, joints, 3) rad and N m, joint frame; ``energy_*`` (n,) J;
        ``body_names``, ``joint_names`` for the body and joint axes (docs/outputs.md)."""
        return self._folder.timeseries

    @property
    def time(self) -> np.ndarray:
        """Sample times (s), shape (n,)."""
        return self.series["time"]

    @cached_property
    def demands(self) -> dict[str, np.ndarray]:
        """Weak-location demand and stress series (``structures.npz``; empty without weak locations)."""
        return self._folder.structures_series if self._folder.has("structures.npz") else {}

    def body(self, name: str) -> int:
        """Index of the body ``name`` along the body axis of :attr:`series`.

        Parameters
        ----------
        name : str
            A body name of the case (``target.bodies[].name``); ``KeyError`` listing the names otherwise.

        Returns
        -------
        int
            Index along the body axis (axis 1 of the ``(n, bodies, 3)`` series).
        """
        names = [str(n) for n in self.series["body_names"]]
        if name not in names:
            raise KeyError(f"no body '{name}' in {self.path} (bodies: {', '.join(names)})")
        return names.index(name)
