"""Wall time of the products made from a run folder: the report (sections, HTML, PDF) and the VTK export.

    python3 bench/bench_products.py [RUN_DIR]

Without RUN_DIR the full reference case (cases/envisat_net_impact.toml) is run first into a
temporary folder (about a minute). Prints seconds per phase, page count, file sizes and
frames per second of the export.
"""
from __future__ import annotations

import sys
import tempfile
import time
from pathlib import Path

from riskassess.products.report.document import build_sections, render_html, render_pdf
from riskassess.products.results import RunFolder
from riskassess.products.vtk_export import export_vtk

ROOT = Path(__file__).resolve().parents[1]


def folder_size_mb(path: Path) -> float:
    return sum(p.stat().st_size for p in path.rglob("*") if p.is_file()) / 1e6


def main() -> None:
    if len(sys.argv) > 1:
        run_dir = Path(sys.argv[1])
    else:
        from riskassess.stages.run import run_case

        run_dir = Path(tempfile.mkdtemp()) / "envisat"
        t0 = time.perf_counter()
        run_case(ROOT / "cases" / "envisat_net_impact.toml", run_dir)
        print(f"reference run: {time.perf_counter() - t0:.1f} s -> {run_dir}")
    run = RunFolder(run_dir)
    marks = []
    t0 = time.perf_counter()
    sections = build_sections(run, lambda k, n, title: marks.append((title, time.perf_counter())))
    for (title, start), (_, end) in zip(marks, marks[1:]):
        print(f"  section {title:45s} {end - start:6.2f} s")
    t1 = time.perf_counter()
    html = render_html(run, sections)
    t2 = time.perf_counter()
    pdf, pages, _ = render_pdf(html, run.path)
    t3 = time.perf_counter()
    print(f"report: sections {t1 - t0:.2f} s (incl. loading the run folder), HTML {t2 - t1:.2f} s "
          f"({len(html) / 1e6:.2f} MB), PDF {t3 - t2:.2f} s ({pages} pages, {len(pdf) / 1e6:.2f} MB)")
    with tempfile.TemporaryDirectory() as tmp:
        t4 = time.perf_counter()
        result = export_vtk(run_dir, Path(tmp) / "vtk")
        t5 = time.perf_counter()
        print(f"VTK export: {result.n_frames} frames in {t5 - t4:.2f} s ({result.n_frames / (t5 - t4):.0f} frames/s), "
              f"{folder_size_mb(result.folder):.1f} MB")


if __name__ == "__main__":
    main()
