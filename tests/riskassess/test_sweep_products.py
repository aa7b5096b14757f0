"""Sweep products go into the store's own folder, one set per store, and never over a file the
tool did not write (issue 20, item 11, sweep part). Hand-made store rows: no simulation."""
import json

import pytest

from riskassess.cli import main
from riskassess.sweep.products import ProductConflict, products_dir, write_sweep_products
from riskassess.sweep.spec import RunSpec, run_id
from riskassess.sweep.store import ResultStore
from tests.riskassess.conftest import CASES


def _record(debris: bool, utilization: float) -> dict:
    return {"secondary_debris": debris, "debris_state": "debris" if debris else "no_debris",
            "peak_contact_force_N": 100.0, "wall_time_s": 1.0, "breakup_likelihood": float(debris),
            "locations": {"hinge": {"utilization": utilization, "likelihood": float(debris),
                                    "peaks": {"moment": utilization * 10.0}}}}


def _filled_store(path, velocities=(10.0, 20.0), case_text="name = 'x'\n") -> ResultStore:
    store = ResultStore(path)
    specs = [RunSpec(run_id({"launch.velocity": v}), {"launch.velocity": v}, k, 0) for k, v in enumerate(velocities)]
    store.declare("case.toml", case_text, {"arguments": [], "created": "-"}, specs)
    for spec in specs:
        v = spec.overrides["launch.velocity"]
        store.write_done(spec.run_id, _record(v > 15, v / 15))
    return store


def test_products_of_two_stores_in_one_folder_do_not_mix(tmp_path):
    """Before: both sweeps wrote tmp/report.html, the second over the first."""
    with _filled_store(tmp_path / "a.sqlite", (10.0, 20.0)) as a, _filled_store(tmp_path / "b.sqlite", (12.0,)) as b:
        write_sweep_products(a, pdf=False)
        write_sweep_products(b, pdf=False)
    assert products_dir(tmp_path / "a.sqlite") == tmp_path / "a.products"
    env_a = json.loads((tmp_path / "a.products" / "envelope.json").read_text())
    env_b = json.loads((tmp_path / "b.products" / "envelope.json").read_text())
    assert [p["value"] for p in env_a["points"]] == [10.0, 20.0] and [p["value"] for p in env_b["points"]] == [12.0]
    assert not (tmp_path / "report.html").exists() and not (tmp_path / "envelope.json").exists()
    # the default layout: products beside sweeps/<name>/results.sqlite
    assert products_dir(tmp_path / "s" / "results.sqlite") == tmp_path / "s"


def test_a_file_the_tool_did_not_write_is_never_overwritten(tmp_path):
    (tmp_path / "report.html").write_text("my own report")
    with _filled_store(tmp_path / "results.sqlite") as store:
        with pytest.raises(ProductConflict, match="report.html: exists and was not written for the store"):
            write_sweep_products(store, pdf=False)
    assert (tmp_path / "report.html").read_text() == "my own report"
    assert not (tmp_path / "envelope.json").exists()          # checked before the first product is written


def test_own_products_are_replaced_atomically(tmp_path):
    with _filled_store(tmp_path / "results.sqlite") as store:
        write_sweep_products(store, pdf=False)
        first = (tmp_path / "report.html").read_bytes()
        write_sweep_products(store, confidence=0.9, pdf=False)   # its own products: replaced
        assert json.loads((tmp_path / "envelope.json").read_text())["confidence"] == 0.9
        assert (tmp_path / "report.html").read_bytes() != first
        (tmp_path / "envelope.json").write_text("{}")             # edited by hand: no longer the tool's
        with pytest.raises(ProductConflict, match="envelope.json"):
            write_sweep_products(store, pdf=False)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["envelope.json", "report.html", "results.sqlite",
                                                          "results.sqlite.lock"]   # no temporary file left


def test_cli_refuses_a_foreign_report_before_any_run(tmp_path, capsys):
    store = tmp_path / "results.sqlite"
    (tmp_path / "report.html").write_text("another sweep's report")
    argv = ["sweep", str(CASES / "envisat_small.toml"), "--vary", "launch.velocity=12:20:2", "--store", str(store)]
    assert main(argv) == 2
    assert "report.html: exists and was not written" in capsys.readouterr().err
    assert not store.exists() and (tmp_path / "report.html").read_text() == "another sweep's report"
