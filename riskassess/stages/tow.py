"""`riskassess tow`: the towing run of a towing case, lower-order (:func:`riskassess.models.towing.towing_model`)
or full-net (:mod:`riskassess.stages.tow_fullnet`, ``simulation.model = "full-net"``). :func:`tow_case` runs
it in Exudyn and writes the run folder:

============== ==============================================================
file           content
============== ==============================================================
manifest.json  format of :mod:`riskassess.products.results`, stage ``tow``, case, status, files
case.toml      the case file as given
towing.json    tension peaks, tautness after engagement, separation, rates, step, wall time
towing.npz     every series of :meth:`multibody.towing.TowResult.series`
tow.png        main-tether tension, thrust, separation and angular rates
============== ==============================================================

``riskassess report DIR`` shows it in its towing section (:mod:`riskassess.products.report.towing`).
"""
from __future__ import annotations

from pathlib import Path

from multibody.towing import run_exudyn
from riskassess.products import results
from riskassess.cases.impact import load_model
from riskassess.products.outfolder import claim
from riskassess.stages.run import software_versions
from riskassess.models.towing import case_decision_vector, towing_model
from riskassess.products.towing_figures import run_figures
from riskassess.stages.tow_fullnet import run_full_net
from riskassess.models.towing_from_run import impact_run_start
from riskassess.cases.towing import TowingCase
from riskassess.products.towing_plots import plot_tow


def summarize(case: TowingCase, result, s) -> dict:
    """The numbers ``riskassess tow`` prints and writes to towing.json (SI):
    :func:`~riskassess.products.towing_figures.run_figures`, the decision vector s and the sub-tethers' peak tension,
    wall time.

    Parameters
    ----------
    case : TowingCase
        The towing case.
    result : multibody.towing.TowResult
        The finished lower-order run.
    s : (4,) float
        Its sub-tether decision vector (eq. 22).

    Returns
    -------
    dict
    """
    series = result.series()
    return {**run_figures(case, series, result.model), "decision_vector_s": [float(x) for x in s],
            "sub_tether_peak_tension_N": float(series["sub_tether_tension"].max()),
            "wall_time_s": result.wall_time, "steps_per_second": result.model.n_steps / result.wall_time}


def tow_case(case_path: str | Path, out_dir: str | Path, case: TowingCase | None = None,
             overwrite: bool = False) -> dict:
    """Load the case (unless given), claim the output folder (:func:`riskassess.products.outfolder.claim`),
    run the lower-order tow in Exudyn (or the full-net tow when ``simulation.model = "full-net"``,
    :mod:`riskassess.stages.tow_fullnet`), write the run folder; return the summary.

    Parameters
    ----------
    case_path : str or Path
        The towing case file (copied as ``case.toml``).
    out_dir : str or Path
        The run folder.
    case : TowingCase or None
        The already validated case; read from ``case_path`` when None.
    overwrite : bool
        Replace an earlier tow in ``out_dir``.

    Returns
    -------
    dict
        The summary, as in ``towing.json``.
    """
    case_path = Path(case_path)
    case = case or load_model(case_path, TowingCase)
    model = towing_model(case)
    run_start = None
    if case.simulation.model == "full-net" and case.full_net.start == "run":
        run_start = impact_run_start(case, case_path)   # checked before the folder is claimed
    folder = claim(out_dir, case.name, "tow", overwrite, stage="tow", software=software_versions())
    out = folder.path
    with folder.recording():
        results.atomic_write_bytes(out / "case.toml", case_path.read_bytes())
        folder.add_files("case.toml")
        if case.simulation.model == "full-net":
            summary, series = run_full_net(case, out, run_start)
            return _finish(case, folder, series, summary, ["towing.json", "towing.npz", "net.npz", "tow.png"])
        result = run_exudyn(model)
        summary = summarize(case, result, case_decision_vector(case))
        results.atomic_write_npz(out / "towing.npz", result.series())
        results.atomic_write_json(out / "towing.json", summary)
        return _finish(case, folder, result.series(), summary, ["towing.json", "towing.npz", "tow.png"])


def _finish(case, folder, series, summary, files) -> dict:
    """Plot, mark the run folder complete with ``files``, return ``summary``."""
    plot_tow(series, folder.path / "tow.png", case.name)
    folder.add_files(*files)
    folder.finish("complete")
    return summary
