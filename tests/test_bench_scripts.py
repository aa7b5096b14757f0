"""Every benchmark script still imports against the current packages (a layout move broke
bench/bench_impact.py once without any test noticing) and has a ``main`` to run."""
import importlib.util
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench"


@pytest.mark.parametrize("script", sorted(BENCH.glob("*.py")), ids=lambda p: p.name)
def test_bench_script_imports(script):
    spec = importlib.util.spec_from_file_location(f"bench_{script.stem}", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)          # top level only: every script guards main()
    assert callable(getattr(module, "main", None)), f"{script.name} has no main()"
