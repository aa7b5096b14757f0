"""Every benchmark script still imports against the current packages (a layout move broke
bench/bench_impact.py once without any test noticing) and has a ``main`` to run."""
import importlib.util
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench"


@pytest.mark.parametrize("script", sorted(BENCH.glob("*.py")), ids=lambda p: p.name)
def test_bench_script_imports(script):
    name = f"bench_{script.stem}"
    spec = importlib.util.spec_from_file_location(name, script)
    module = importlib.util.module_from_spec(spec)
    # registered as importlib's recipe does: a dataclass under "from __future__ import annotations" looks its
    # module up in sys.modules while the class is made
    sys.modules[name] = module
    try:
        spec.loader.exec_module(module)      # top level only: every script guards main()
    finally:
        sys.modules.pop(name, None)
    assert callable(getattr(module, "main", None)), f"{script.name} has no main()"


def test_step_refinement_springs_alone_is_minus_k_times_the_joint_offset():
    """bench_step_refinement.py's springs-alone reading: for a joint whose parent sits at rest at the origin and
    whose child is moved by a known offset and turned by a known rotation, the springs' load on the child is
    -k (offset, rotation) in the joint frame (Hooke's law, per axis; the joint frame here turned 90 deg about z
    from LVLH, so the offset's components swap)."""
    from types import SimpleNamespace

    import numpy as np

    spec = importlib.util.spec_from_file_location("bench_step_refinement", BENCH / "bench_step_refinement.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    turn_z = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])      # joint frame in the parent body
    system = SimpleNamespace(joint_to_parent=[turn_z], joint_point_parent_body=[np.array([1.0, 0.0, 0.0])],
                             joint_point_child_body=[np.array([-1.0, 0.0, 0.0])])
    offset_lvlh = np.array([1e-3, -2e-3, 3e-3])
    series = {"body_com_lvlh": np.array([[[0.0, 0.0, 0.0], [2.0, 0.0, 0.0] + offset_lvlh]]),
              "body_to_lvlh": np.array([[np.eye(3), np.eye(3)]]),
              "joint_rotation_joint": np.array([[[1e-4, -2e-4, 5e-5]]])}
    stiffness = np.array([[1e6, 2e6, 3e6, 1e5, 2e5, 3e5]])
    force, moment = module.elastic_reaction_joint(system, [(0, 1)], stiffness, series)
    offset_joint = turn_z.T @ offset_lvlh                      # (-2e-3, -1e-3, 3e-3)
    assert np.allclose(force[0, 0], -stiffness[0, :3] * offset_joint, rtol=1e-12, atol=0.0)
    assert np.allclose(moment[0, 0], -stiffness[0, 3:] * series["joint_rotation_joint"][0, 0], rtol=1e-12, atol=0.0)
