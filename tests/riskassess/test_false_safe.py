"""Issue 20 reproducers: no run says "no secondary debris" without having computed it.

Each test is one reproducer of the issue (item number in the name's docstring), run through the
CLI on the reduced Envisat case (15 x 15 net) with a short end time.
"""
import json

import numpy as np
import pytest

from riskassess.cli import main
from riskassess.products.results import RunFolder, read_manifest
from structures.verdict import MAX_SAMPLE_INTERVAL_S, MIN_JUDGED_SAMPLES, evidence_gaps
from tests.riskassess.conftest import CASES, shortened_case


def _case(tmp_path, end_time, **simulation):
    """envisat_small with ``end_time`` and other [simulation] values replaced (TOML literals)."""
    text = shortened_case(end_time)
    for key, value in simulation.items():
        lines = text.splitlines()
        k = next(i for i, line in enumerate(lines) if line.startswith(f"{key} = "))
        lines[k] = f"{key} = {value}"
        text = "\n".join(lines) + "\n"
    path = tmp_path / "case.toml"
    path.write_text(text)
    return path


def test_a_diverging_run_is_failed_and_indeterminate(tmp_path, capsys):
    """Item 2: 0.6 s at step = 1e-2 s used to give NaN everywhere and 'secondary debris: none'."""
    out = tmp_path / "run"
    code = main(["assess", str(_case(tmp_path, 0.6, step="1e-2", output_rate="100.0")), "--out", str(out), "--json"])
    captured = capsys.readouterr()
    assert code == 5
    answer = json.loads(captured.out)
    assert answer["status"] == "failed" and answer["debris_state"] == "indeterminate"
    assert answer["secondary_debris"] is None
    # envisat_small's 2.143 m threads: k = E A / l = 1.7501e10 Pa x pi (1 mm)^2 / 2.143 m = 25.66 kN/m on
    # 0.04223 kg nodes: sqrt(m/k) = 1.28e-3 s, and the message names half of it as the step to use
    assert "sqrt(m/k) = 0.00128 s" in captured.err and "use simulation.step <= 0.00064 s" in captured.err
    assert "none" not in captured.err
    manifest = json.loads((out / "manifest.json").read_text())
    assert manifest["status"] == "failed" and manifest["debris_state"] == "indeterminate"
    assert not manifest["health"]["healthy"] and manifest["health"]["failure"]["time_s"] < 0.6
    assert not (out / "summary.json").exists() and not (out / "structures.json").exists()
    assert not RunFolder(out).complete  # later stages do not take the folder for a complete run
    assert manifest["files"] == ["case.toml", "case.json", "solver.log"]   # the failed solve's own output kept


def test_a_run_ending_before_the_judged_window_is_indeterminate(tmp_path, capsys):
    """Item 3: end_time 0.2 s < skip_initial 0.25 s used to give '0 N m, margin +inf, pass'."""
    out = tmp_path / "run"
    assert main(["assess", str(_case(tmp_path, 0.2)), "--out", str(out)]) == 6
    printed = capsys.readouterr().out
    assert "secondary debris: INDETERMINATE" in printed and "pass" not in printed and "+inf" not in printed
    verdict = json.loads((out / "structures.json").read_text())
    assert verdict["debris_state"] == "indeterminate" and verdict["secondary_debris"] is None
    assert all(loc["state"] == "indeterminate" and loc["likelihood"] is None for loc in verdict["locations"])
    assert all(c["peak"] is None and c["margin_of_safety"] is None
               for loc in verdict["locations"] for c in loc["criteria"].values())
    assert "0 samples after skip_initial = 0.25 s" in verdict["indeterminate_reasons"][0]
    assert read_manifest(out)["status"] == "complete"  # the simulation itself is fine


def test_a_run_sampled_too_sparsely_is_indeterminate(tmp_path):
    """Item 3: output_rate = 1e-300 Hz recorded only the first and the last step and said 'pass'."""
    out = tmp_path / "run"
    code = main(["assess", str(_case(tmp_path, 0.5, output_rate="1e-300")), "--out", str(out), "--json"])
    verdict = json.loads((out / "structures.json").read_text())
    # An exceedance seen in the one judged sample is evidence of a failure (the solar-array hinge
    # at 0.5 s); every location without one is indeterminate, none "holds".
    assert {loc["state"] for loc in verdict["locations"]} <= {"fails", "indeterminate"}
    assert "indeterminate" in {loc["state"] for loc in verdict["locations"]}
    assert verdict["debris_state"] in ("debris", "indeterminate")
    reasons = " ".join(verdict["indeterminate_reasons"])
    assert "1 samples after skip_initial" in reasons and "0.5 s apart" in reasons
    # the last step is sampled whatever the rate, so the series still ends at the end time
    assert np.load(out / "timeseries.npz")["time"].tolist() == pytest.approx([0.0, 0.5])
    assert code == (6 if verdict["debris_state"] == "indeterminate" else 0)


def test_evidence_needs_samples_resolution_and_contact():
    """The three evidence rules on hand-made series (times in s, contact forces in N)."""
    time = np.arange(0.0, 1.0, 1e-3)
    touching = np.zeros((time.size, 1, 3))
    touching[:, 0, 1] = 100.0
    assert evidence_gaps(time, touching, 0.25) == []
    # no contact after skip_initial (contact only before it): nothing judged was loaded by the net
    early = touching.copy()
    early[time >= 0.25] = 0.0
    assert evidence_gaps(time, early, 0.25) == [("no_capture_load", "no contact between the net and the debris after "
                                                "skip_initial = 0.25 s: the judged window holds no capture load")]
    # MIN_JUDGED_SAMPLES - 1 judged samples
    short = time[:250 + MIN_JUDGED_SAMPLES - 1]
    assert "a verdict needs at least 10" in evidence_gaps(short, touching[:short.size], 0.25)[0].reason
    # a gap just above MAX_SAMPLE_INTERVAL_S
    sparse = np.arange(0.0, 1.0, 1.01 * MAX_SAMPLE_INTERVAL_S)
    assert "a verdict needs at least 100 Hz" in evidence_gaps(sparse, touching[:sparse.size], 0.25)[0].reason


def test_huge_work_is_refused_before_any_folder_exists(tmp_path, capsys):
    """Item 7: end_time = 1e6 s (1e10 steps) started silently; now an estimate and a refusal."""
    out = tmp_path / "run"
    assert main(["run", str(_case(tmp_path, 1e6)), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    # 1e6 s / 1e-4 s = 1e10 steps; (17 + 0.0273 x 229) us per step = 23.25 us -> 2.325e5 s = 2.69 days
    # (riskassess/stages/estimate.py; envisat_small takes node contact only)
    assert "1e+10 steps, about 2.69 days" in err and "--force" in err
    assert not out.exists()
    # above the hard limit, --force does not help
    assert main(["run", str(_case(tmp_path, 2e6)), "--out", str(out), "--force"]) == 2
    assert "refused even with --force" in capsys.readouterr().err and not out.exists()


def test_a_billion_second_tow_is_refused(tmp_path, capsys):
    """Item 7: a towing end_time = 1e9 s was accepted; at the 4 ms step that is 2.5e11 steps."""
    text = (CASES / "zenit2_towing.toml").read_text()
    assert "end_time = 300.0" in text
    case = tmp_path / "zenit2_towing.toml"
    case.write_text(text.replace("end_time = 300.0", "end_time = 1e9", 1))
    out = tmp_path / "tow"
    assert main(["tow", str(case), "--out", str(out), "--force"]) == 2
    assert "2.5e+11 steps" in capsys.readouterr().err and not out.exists()
