"""Run folders shared by the riskassess tests (simulated once per session)."""
from pathlib import Path

import pytest

from riskassess.cli import main

CASES = Path(__file__).resolve().parents[2] / "cases"

#: The reference weak locations of cases/envisat_net_impact.toml, two of them: the solar-array
#: hinge (seed paper Sec. 3.3.3: 200-1000 N m) and the ASAR mount (Al 7075 section).
STRUCTURES = '''
[structures]
skip_initial = 0.25
release = "low"

[[structures.weak_locations]]
name = "solar_array_hinge_panel"
joint = "solar_array_hinge"
allowable_moment = [200.0, 1000.0]

[[structures.weak_locations]]
name = "asar_mount"
joint = "asar_mount"
beam_axis = [0.0, 0.0, 1.0]
width_axis = [1.0, 0.0, 0.0]
section = { kind = "solid_rectangle", width = 1.5, height = 0.156 }
material = { ultimate_normal = 570e6, ultimate_shear = 330e6 }
'''


@pytest.fixture(scope="session")
def assessed(tmp_path_factory):
    """The reduced Envisat case (15 x 15 net), 2 s, with weak locations: a complete run folder."""
    tmp = tmp_path_factory.mktemp("assess")
    text = (CASES / "envisat_small.toml").read_text().replace("end_time = 7.5", "end_time = 2.0", 1)
    case = tmp / "small_assess.toml"
    case.write_text(text + STRUCTURES)
    out = tmp / "run"
    assert main(["assess", str(case), "--out", str(out), "--json"]) == 0
    return out
