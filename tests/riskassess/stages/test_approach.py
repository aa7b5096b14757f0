"""`riskassess approach` end to end: JSON answer, output folder, report, 3-D replay, bad input."""
import gc
import json
import re
from pathlib import Path

import pytest

from riskassess.cli import main

CASES = Path(__file__).parents[3] / "cases"


def _small_replay(tmp_path, name="approach_mu_min_time.toml", **replace):
    text = (CASES / name).read_text().replace("nodes_per_side = 8 ", "nodes_per_side = 4 ")
    for key, value in replace.items():
        text = re.sub(rf"(?m)^{key} = .*$", f"{key} = {value}", text)
    path = tmp_path / name
    path.write_text(text)
    return path


@pytest.fixture(scope="module")
def answered(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("approach")
    case = _small_replay(tmp)
    return tmp, case


def test_json_answer_and_replay(answered, capsys):
    tmp, case = answered
    assert main(["approach", str(case), "--out", str(tmp / "out"), "--json", "--replay"]) == 0
    answer = json.loads(capsys.readouterr().out)
    for key in ("final_time", "fuel_kg", "constraints_satisfied", "solve_s", "solver_status"):
        assert key in answer
    assert answer["constraints_satisfied"] is True
    # not worse than the paper's 4.8384 s (Sec. 3.4); see tests/control/test_mu_approach.py
    assert answer["final_time"] <= answer["reference"]["final_time"]
    replay = answer["replay"]
    # The MUs track the plan against the net's pull: the mouth chord centre ends within 5 cm of
    # the debris centre (gains 200 N/m, 40 N s/m against ~5 N of net pull: ~2.5 cm error), and
    # no MU comes nearer than the keep-out radius (the plan keeps 5.52 m).
    assert replay["final_mouth_chord_center_distance_m"] < 0.05
    assert replay["min_unit_debris_distance_m"] > 5.5
    manifest = json.loads((tmp / "out" / "manifest.json").read_text())
    assert manifest["stage"] == "approach" and "approach_trajectory.png" in manifest["files"]
    # the replay's system is freed once it is over: its sampler and tracking loads held the system while Exudyn
    # held them from C++ (a cycle the collector cannot see; multibody.impact.detach_step_functions). Exact count.
    gc.collect()
    left = [o for o in gc.get_objects() if type(o).__module__ == "multibody.mu_replay"
            and type(o).__name__ in ("_Sampler", "_TrackingLoad")]
    assert left == []


def test_report_of_an_approach_folder_has_only_its_section(answered):
    tmp, _ = answered
    assert main(["report", str(tmp / "out"), "--no-pdf"]) == 0
    html = (tmp / "out" / "report.html").read_text()
    assert '<section id="approach"' in html
    assert '<section id="contact"' not in html and "missing files" not in html


def test_bad_case_names_file_and_key(tmp_path, capsys):
    case = _small_replay(tmp_path, max="-3.0")
    assert main(["approach", str(case)]) == 2
    err = capsys.readouterr().err
    assert str(case) in err and "thrust.max" in err


def test_an_impossible_problem_exits_non_zero_with_the_solver_status(tmp_path, capsys):
    # 1 s is far too short to move the mouth 23 m at 12 N / 2.5 kg (needs >= 3.1 s)
    case = _small_replay(tmp_path, "approach_mu_min_fuel.toml", final_time="1.0")
    assert main(["approach", str(case), "--out", str(tmp_path / "out"), "--json"]) == 4
    answer = json.loads(capsys.readouterr().out)
    assert answer["converged"] is False and answer["constraints_satisfied"] is False
    assert answer["solver_status"] not in ("Solve_Succeeded", "Solved_To_Acceptable_Level")
