"""Output folders (issue 20, items 4 and 5): the tool never deletes or overwrites what it did not
write, the case name never becomes a path unsanitized, and a re-run never leaves old results
beside a new case."""
import json
import os
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from riskassess.products import outfolder
from riskassess.cli import main
from riskassess.products.outfolder import OutputRefused, claim, default_out, step_done
from riskassess.products.results import RunFolder, atomic_write_json
from tests.riskassess.conftest import shortened_case

ROOT = Path(__file__).resolve().parents[3]


def _tree(folder: Path) -> dict:
    """Every file under ``folder`` with its bytes: 'nothing was changed' is this staying equal."""
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def _manifest(folder: Path) -> dict:
    return json.loads((folder / "manifest.json").read_text())


# ---------------------------------------------------------------------------- names -> paths
@pytest.mark.parametrize("name", ["../../escaped", "/tmp/absolute", "", "..", ".hidden", "a/../../b", "~/x",
                                  "C:\\windows", "x[/red]$x^{$", "名前", "-rf", "a" * 300])
def test_default_out_stays_inside_runs(name, tmp_path):
    out = default_out(name)
    assert out.parent == Path("runs") and out.name and not out.name.startswith((".", "-"))
    assert "/" not in out.name and "\\" not in out.name and len(out.name) <= outfolder.MAX_NAME
    assert (tmp_path / out).resolve().parent == (tmp_path / "runs").resolve()


def test_default_out_keeps_a_plain_name():
    assert default_out("envisat_small") == Path("runs/envisat_small")
    assert default_out("zenit2", "_identify") == Path("runs/zenit2_identify")


# ---------------------------------------------------------------------------- claiming
def test_missing_folder_is_created_and_empty_folder_used(tmp_path):
    folder = claim(tmp_path / "a" / "b", "case", "run")
    assert folder.path.is_dir() and _manifest(folder.path)["status"] == "running"
    (tmp_path / "empty").mkdir()
    assert _manifest(claim(tmp_path / "empty", "case", "run").path)["case"] == "case"


def test_foreign_folder_is_refused_and_untouched(tmp_path):
    thesis = tmp_path / "thesis"
    (thesis / "figures").mkdir(parents=True)
    (thesis / "chapter1.tex").write_text("years of work")
    before = _tree(thesis)
    with pytest.raises(OutputRefused, match=r"thesis.*not written by riskassess.*chapter1\.tex"):
        claim(thesis, "case", "run", overwrite=True)
    assert _tree(thesis) == before and sorted(p.name for p in thesis.iterdir()) == ["chapter1.tex", "figures"]
    (tmp_path / "file").write_text("x")
    with pytest.raises(OutputRefused, match="is not a folder"):
        claim(tmp_path / "file", "case", "run")


def test_folder_of_another_case_or_command_is_refused(tmp_path):
    claim(tmp_path / "out", "alpha", "run").finish()
    before = _tree(tmp_path / "out")
    with pytest.raises(OutputRefused, match="case 'alpha'.*case 'beta'"):
        claim(tmp_path / "out", "beta", "run", overwrite=True)
    with pytest.raises(OutputRefused, match="riskassess run.*riskassess tow"):
        claim(tmp_path / "out", "alpha", "tow", overwrite=True)
    assert _tree(tmp_path / "out") == before
    # run and assess write the same kind of folder: a re-run, which needs --overwrite
    with pytest.raises(OutputRefused, match="pass --overwrite"):
        claim(tmp_path / "out", "alpha", "assess")


def _old_run(out: Path) -> None:
    """A finished run folder with a product (a VTK folder with its own manifest) and a temporary
    file left by a killed write."""
    folder = claim(out, "alpha", "run")
    for name in ("case.toml", "summary.json", "report.html"):
        (out / name).write_text(f"old {name}")
    folder.add_files("case.toml", "summary.json")
    (out / "vtk").mkdir()
    (out / "vtk" / "net_0000.vtu").write_text("old frame")
    atomic_write_json(out / "vtk" / "manifest.json", {"format": "riskassess-vtk", "files": ["net_0000.vtu"]})
    folder.manifest["products"] = ["report.html", "vtk"]
    folder.finish()
    (out / ".summary.json.abcd1234.tmp").write_text("half")


def test_rerun_needs_overwrite_which_removes_only_the_listed_files(tmp_path):
    out = tmp_path / "out"
    _old_run(out)
    before = _tree(out)
    with pytest.raises(OutputRefused, match=r"already holds a 'complete' output of case 'alpha'; pass --overwrite"):
        claim(out, "alpha", "run")
    assert _tree(out) == before
    folder = claim(out, "alpha", "run", overwrite=True)
    assert sorted(p.name for p in out.iterdir()) == ["manifest.json"]
    assert folder.manifest["status"] == "running" and folder.manifest["files"] == []


def test_overwrite_with_a_user_file_inside_is_refused_and_changes_nothing(tmp_path):
    out = tmp_path / "out"
    _old_run(out)
    (out / "notes.txt").write_text("mine")
    (out / "vtk" / "my_view.pvsm").write_text("mine too")
    before = _tree(out)
    with pytest.raises(OutputRefused, match=r"notes\.txt, vtk/my_view\.pvsm"):
        claim(out, "alpha", "run", overwrite=True)
    assert _tree(out) == before


def test_manifest_says_running_before_the_first_old_file_goes(tmp_path, monkeypatch):
    """A kill during the clean-up must not leave a folder that still claims 'complete'."""
    out = tmp_path / "out"
    _old_run(out)
    seen = []

    def unlink(self, missing_ok=False):
        seen.append(_manifest(out)["status"])
        raise KeyboardInterrupt  # the process dies here

    monkeypatch.setattr(Path, "unlink", unlink)
    with pytest.raises(KeyboardInterrupt):
        claim(out, "alpha", "run", overwrite=True)
    assert seen == ["running"] and _manifest(out)["status"] == "running"


def test_failure_while_running_is_recorded(tmp_path):
    folder = claim(tmp_path / "out", "alpha", "run")
    with pytest.raises(RuntimeError), folder.recording():
        raise RuntimeError("NaN in the net state at t = 0.3 s")
    manifest = _manifest(tmp_path / "out")
    assert manifest["status"] == "failed" and "NaN in the net state" in manifest["error"]


def test_status_stays_running_until_the_last_product_and_records_a_failed_one(tmp_path):
    folder = claim(tmp_path / "out", "alpha", "run")
    folder.finish("complete", pending=["report", "vtk"])
    assert _manifest(folder.path)["status"] == "running" and RunFolder(folder.path).complete
    step_done(folder.path, "report")
    assert _manifest(folder.path)["status"] == "running"
    step_done(folder.path, "vtk", OSError("No space left on device"))
    manifest = _manifest(folder.path)
    assert manifest["status"] == "products_failed" and "No space left" in manifest["product_errors"]["vtk"]
    assert RunFolder(folder.path).complete       # the results stay readable
    step_done(folder.path, "report")              # a step the run did not fail changes nothing
    step_done(folder.path, "vtk")                 # the retry succeeds
    manifest = _manifest(folder.path)
    assert manifest["status"] == "complete" and "product_errors" not in manifest


# ---------------------------------------------------------------------------- whole commands
@pytest.fixture(scope="module")
def small_case(tmp_path_factory):
    """envisat_small for 0.1 s without its weak locations (test_report.py's `run --report --vtk` case): a
    folder in about a second. These tests check the folder's mechanics (names, re-runs, kill -9, failed
    products), none of the physics: they need a complete run and its products, not the first contact
    (~0.15 s at 20 m/s) or a verdict. The 0.3 s case with weak locations they used before made the report
    (more sections, 16 instead of 6 animation frames) most of the file's time: the re-run test took 124 s,
    72 s of it the one report (cProfile, load ~8)."""
    case = tmp_path_factory.mktemp("small") / "small.toml"
    case.write_text(shortened_case(0.1).split("\n[structures]")[0])
    return case


def _case_named(tmp_path: Path, small_case: Path, name: str, velocity: float = 20.0) -> Path:
    text = small_case.read_text().replace('name = "envisat_small"', f"name = {json.dumps(name)}", 1)
    text = text.replace("velocity = 20.0 ", f"velocity = {velocity} ", 1)
    path = tmp_path / f"case_{velocity:g}.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize("name", ["../../escaped", "/tmp/riskassess-absolute-name", ""])
def test_case_name_never_writes_outside_runs(name, tmp_path, small_case, monkeypatch):
    """Issue 20 item 4: the case name became the output path unchecked."""
    work = tmp_path / "deep" / "work"
    work.mkdir(parents=True)
    case = _case_named(work, small_case, name)
    monkeypatch.chdir(work)
    code = main(["run", str(case), "--json"])
    if code == 2:   # the case schema may refuse the name itself: then nothing is written at all
        assert sorted(p.name for p in tmp_path.rglob("*")) == sorted(["deep", case.name, "work"])
        return
    assert code == 0
    assert sorted(p.name for p in work.iterdir()) == [case.name, "runs"]
    (run_dir,) = (work / "runs").iterdir()
    assert _manifest(run_dir)["status"] == "complete" and _manifest(run_dir)["case"] == name
    assert sorted(p.name for p in tmp_path.iterdir()) == ["deep"]
    assert not name or not Path(name).exists()


def test_rerun_into_a_run_folder_never_mixes_runs(tmp_path, small_case, capsys):
    """Issue 20 item 5: an old report (20 m/s) stayed beside new results (100 m/s), and a kill -9 during
    the re-run left the old summary beside the new case."""
    out = tmp_path / "run"
    slow, fast = _case_named(tmp_path, small_case, "mix", 20.0), _case_named(tmp_path, small_case, "mix", 100.0)
    assert main(["run", str(slow), "--out", str(out), "--report", "--json"]) == 0
    assert {"report.html", "report.pdf"} <= set(_manifest(out)["products"]) and _manifest(out)["status"] == "complete"
    before = _tree(out)
    capsys.readouterr()
    assert main(["run", str(fast), "--out", str(out), "--json"]) == 2
    assert "--overwrite" in capsys.readouterr().err and _tree(out) == before
    # kill -9 while the re-run simulates: nothing of the old run may be left to read as this case's
    script = ("import os, signal, sys\nfrom multibody.impact import ImpactSimulation\n"
              "ImpactSimulation.run = lambda *a, **k: os.kill(os.getpid(), signal.SIGKILL)\n"
              "from riskassess.cli import main\nmain(sys.argv[1:])\n")
    killed = subprocess.run([sys.executable, "-c", script, "run", str(fast), "--out", str(out), "--overwrite", "--json"],
                            env={**os.environ, "PYTHONPATH": str(ROOT)}, capture_output=True)
    assert killed.returncode == -signal.SIGKILL
    manifest = _manifest(out)
    assert manifest["status"] == "running" and manifest["files"] == ["case.toml", "case.json"]
    assert sorted(p.name for p in out.iterdir()) == ["case.json", "case.toml", "manifest.json"]
    assert (out / "case.toml").read_text() == fast.read_text()
    with pytest.raises(Exception, match="summary.json is missing"):
        RunFolder(out).summary
    # the re-run proper: only its own files, no report of the old run
    assert main(["run", str(fast), "--out", str(out), "--overwrite", "--json"]) == 0
    assert not (out / "report.html").exists() and "products" not in _manifest(out)
    assert json.loads((out / "case.json").read_text())["launch"]["velocity"] == 100.0


def test_report_never_overwrites_a_file_it_did_not_write(tmp_path, small_case, capsys):
    out = tmp_path / "run"
    assert main(["run", str(small_case), "--out", str(out), "--json"]) == 0
    (out / "report.html").write_text("my own notes")
    capsys.readouterr()
    assert main(["report", str(out), "--no-pdf"]) == 2
    assert "report.html: exists and was not written by riskassess" in capsys.readouterr().err
    assert (out / "report.html").read_text() == "my own notes" and _manifest(out)["status"] == "complete"


def test_a_failed_product_is_recorded_and_the_results_stay(tmp_path, small_case, monkeypatch, capsys):
    """Issue 20 item 4: `run --report --vtk` is 'running' until its last product; a product that fails
    leaves 'products_failed' (exit code 1) with readable results, and a retry of the step clears it."""
    import riskassess.api

    out = tmp_path / "run"
    statuses = []
    real = riskassess.api.write_report

    def full_disk(run_dir, **kwargs):
        statuses.append(_manifest(Path(run_dir))["status"])
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(riskassess.api, "write_report", full_disk)
    assert main(["run", str(small_case), "--out", str(out), "--report", "--vtk", "--json"]) == 1
    assert statuses == ["running"]
    manifest = _manifest(out)
    assert manifest["status"] == "products_failed" and manifest["outcome"] == "complete"
    assert "No space left" in manifest["product_errors"]["report"] and manifest["products"] == ["vtk"]
    assert "retry this step alone with 'riskassess report" in capsys.readouterr().err
    assert RunFolder(out).summary["case"] == "envisat_small"   # the results stay readable
    monkeypatch.setattr(riskassess.api, "write_report", real)
    assert main(["report", str(out), "--no-pdf"]) == 0
    manifest = _manifest(out)
    assert manifest["status"] == "complete" and "product_errors" not in manifest
