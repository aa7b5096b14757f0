"""`riskassess report`: one self-contained HTML and its PDF, every section, and clear words
for incomplete or older run folders."""
import base64
import json
import re
import shutil

import numpy as np
import pytest
from pypdf import PdfReader

from riskassess.cli import main
from riskassess.products.report import SECTIONS, write_report
from riskassess.products.plotting import WIDTH_IN
from riskassess.products.report.blocks import FIGURE_DPI

FIGURES = {"capture": ["fig-capture"], "net-integrity": ["fig-net-tension"], "contact": ["fig-contact"], "debris-motion": ["fig-debris-motion"], "hinges": ["fig-hinge-angle"],
           "joint-loads": ["fig-joint-loads"], "stresses": ["fig-stresses"], "energy": ["fig-energy"]}


@pytest.fixture(scope="module")
def report(assessed, tmp_path_factory):
    run = tmp_path_factory.mktemp("report") / "run"
    shutil.copytree(assessed, run)
    return write_report(run, views=False)   # the animation and the viewer: test_view.py


def _html_section(html: str, section_id: str) -> str:
    start = html.index(f'<section id="{section_id}"')
    return html[start:html.index("</section>", start)]


#: Sections of stages the impact run does not have (they return None and are left out).
OTHER_STAGES = {"perception", "diagnosis", "towing", "approach"}
IMPACT_SECTIONS = [s for s in SECTIONS if s[0] not in OTHER_STAGES]


def test_html_has_every_section_in_order_with_its_figures(report):
    html = report.html.read_text()
    assert not any(f'<section id="{sid}"' in html for sid in OTHER_STAGES)
    positions = [html.index(f'<section id="{sid}"') for sid, _, _ in IMPACT_SECTIONS]
    assert positions == sorted(positions) and SECTIONS[0][0] == "verdict"   # the verdict first
    for sid, figure_ids in FIGURES.items():
        section = _html_section(html, sid)
        assert "Not available" not in section
        for fid in figure_ids:
            png = re.search(rf'<figure id="{fid}">\s*<img src="data:image/png;base64,([^"]+)"', section)
            assert png, f"figure {fid} missing from section {sid}"
            data = base64.b64decode(png.group(1))
            assert data[:8] == b"\x89PNG\r\n\x1a\n"
            width = int.from_bytes(data[16:20], "big")
            assert width == round(WIDTH_IN * FIGURE_DPI)  # the figure width set for an A4 page
    # self-contained: nothing loaded from elsewhere
    assert not re.search(r'(src|href)="(https?:|file:|/)', html)


def test_html_states_the_runs_numbers_with_units(report, assessed):
    html = report.html.read_text()
    verdict = json.loads((assessed / "structures.json").read_text())
    piece = verdict["released_pieces"][0]
    assert "SECONDARY DEBRIS: 1 piece(s) released" in html
    assert f"<td>{piece['release_time_s']:.3f}</td>" in _html_section(html, "verdict")
    peak = verdict["locations"][0]["criteria"]["moment"]["peak"]
    assert f"<td>{peak:.4g} N m</td>" in html
    inputs = _html_section(html, "case")
    # launch speed of cases/envisat_small.toml, with its unit
    assert "<td>launch.velocity</td><td>20</td><td>m/s</td>" in inputs
    assert "<td>main_body</td><td>6621</td>" in inputs  # main body mass (kg) [paper T2]
    appendix = _html_section(html, "appendix-inputs")
    assert "<td>velocity</td><td>20</td><td>m/s</td>" in appendix
    assert "<td>mass</td><td>6621</td><td>kg</td>" in appendix
    assert "<td>allowable_moment</td><td>[200, 1000]</td><td>N m</td>" in appendix  # the weak location
    facts = _html_section(html, "run-facts")
    assert "VelocityVerlet" in facts and "version of exudyn" in facts


def test_pdf_pages_hold_the_sections(report):
    reader = PdfReader(report.pdf)
    assert len(reader.pages) == report.pdf_pages >= len(IMPACT_SECTIONS)
    # each section after the verdict starts a page (print CSS); its title is on that page
    for number, (sid, title, _) in enumerate(IMPACT_SECTIONS, start=1):
        page = report.section_pages[sid]
        text = " ".join(reader.pages[page - 1].extract_text().split())
        assert f"{number}. {title}" in text, (sid, page)
    assert report.section_pages["verdict"] == 1
    pages = [report.section_pages[sid] for sid, _, _ in IMPACT_SECTIONS]
    assert pages == sorted(set(pages))
    assert "page 1 of" in reader.pages[0].extract_text()


def test_report_of_an_older_folder_says_what_is_missing(assessed, tmp_path, capsys):
    run = tmp_path / "old"
    shutil.copytree(assessed, run)
    for name in ("structures.json", "structures.npz", "report.html", "report.pdf"):
        (run / name).unlink(missing_ok=True)
    summary = json.loads((run / "summary.json").read_text())
    del summary["peak_contact_force_per_body_N"]    # a key older versions did not write
    (run / "summary.json").write_text(json.dumps(summary))
    assert main(["report", str(run), "--no-pdf"]) == 0
    html = (run / "report.html").read_text()
    contact = _html_section(html, "contact")
    assert "Not available" in contact and "peak_contact_force_per_body_N" in contact
    assert "structures.json is missing" in _html_section(html, "verdict")
    assert "Not available" not in _html_section(html, "energy")  # unaffected sections are whole
    assert "contact" in capsys.readouterr().out.lower()


def test_report_of_an_interrupted_run_and_of_no_run(assessed, tmp_path, capsys):
    run = tmp_path / "interrupted"
    run.mkdir()
    for name in ("case.toml", "case.json"):
        shutil.copy(assessed / name, run / name)
    manifest = json.loads((assessed / "manifest.json").read_text())
    manifest.update(status="running", files=["case.toml", "case.json"])
    manifest.pop("outcome")   # a run killed while simulating: its stage never ended
    (run / "manifest.json").write_text(json.dumps(manifest))
    assert main(["report", str(run), "--no-pdf"]) == 0
    html = (run / "report.html").read_text()
    assert "Incomplete:" in html and "status is &#39;running&#39;" in html
    assert "summary.json is missing (the run stopped with status &#39;running&#39;)" in html
    assert main(["report", str(tmp_path / "nowhere")]) == 2
    assert "no manifest.json" in capsys.readouterr().err


def test_release_marked_in_the_hinge_figure_data(report, assessed):
    """The hinge section lists the release time the structures stage recorded."""
    verdict = json.loads((assessed / "structures.json").read_text())
    t = verdict["released_pieces"][0]["release_time_s"]
    hinges = _html_section(report.html.read_text(), "hinges")
    assert f"<td>{t:.3f}</td>" in hinges
    series = np.load(assessed / "timeseries.npz")
    joined = series["time"] < t  # after the release the relative rotation is no hinge angle
    max_angle = np.abs(series["joint_rotation_joint"][joined, 0, 1]).max()   # rad, as in the CLI
    assert f"<td>{max_angle:.4g}</td>" in hinges


def test_run_writes_report_and_vtk_when_asked(tmp_path):
    """`riskassess run --report --vtk`: both products land in the run folder and its manifest."""
    from tests.riskassess.conftest import shortened_case

    case = tmp_path / "short.toml"
    case.write_text(shortened_case(0.1).split("\n[structures]")[0])  # without weak locations
    out = tmp_path / "run"
    assert main(["run", str(case), "--out", str(out), "--json", "--report", "--vtk"]) == 0
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["products"] == ["report.html", "report.pdf", "capture.gif", "viewer.html", "vtk"]
    assert manifest["status"] == "complete"
    assert json.loads((out / "vtk" / "manifest.json").read_text())["format"] == "riskassess-vtk"
    assert (out / "report.pdf").stat().st_size > 0
    # 0.1 s at 50 Hz net snapshots: t = 0, 0.02, ..., 0.1
    assert len(list((out / "vtk").glob("net_*.vtu"))) == 6
    html = (out / "report.html").read_text()
    assert "Not assessed: the case declares no weak locations" in _html_section(html, "verdict")


def test_the_report_states_what_a_fixed_and_an_open_capture_window_rest_on():
    # a fixed window is the case's statement that nothing later loads the target; a capture not over by the end
    # time cannot let a location hold (structures/capture_window.py)
    from riskassess.products.report.structures import capture_window_text, fixed_window_text
    fixed = fixed_window_text({"window": "fixed", "end_time_s": 7.5})
    assert "0 to 7.50 s" in fixed and "structures.window = 'fixed'" in fixed and "not judged" in fixed
    open_capture = capture_window_text({"window": "capture", "settled": False, "settled_at_s": None,
                                        "end_time_s": 45.0, "energy_threshold_J": 0.37, "hold_s": 10.5,
                                        "reference_body": "main_body", "net_energy_relative_end_J": 6.92,
                                        "last_rise_s": 30.228})
    assert "NOT over" in open_capture and "45.00 s" in open_capture and "0.37 J" in open_capture
    assert "6.92 J" in open_capture and "30.23 s" in open_capture and "indeterminate" in open_capture
