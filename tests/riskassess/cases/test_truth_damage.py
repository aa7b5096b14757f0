"""[perception.truth_damage]: the real target's shapes and mass properties, and the case checks."""
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from multibody.geometry import geometric_center_of_mass, uniform_density_inertia
from riskassess.cases.impact import CaseError, load_case
from riskassess.cases.target_geometry import body_meshes_target_frame
from riskassess.cases.truth_damage import damaged_case, hinge_turn

CASE = Path(__file__).parents[3] / "cases" / "featured_debris_perception_damaged.toml"


def _with_damage(tmp_path, damage: str) -> Path:
    """The shipped damaged case with its [perception.truth_damage] replaced by ``damage``."""
    text = CASE.read_text()
    text = text[:text.index("\n[perception.truth_damage]") + 1] + damage
    path = tmp_path / "case.toml"
    path.write_text(text)
    return path


def test_the_real_body_is_the_damaged_shapes_at_the_models_density(tmp_path):
    # The model states no CoM or inertia, so its mass properties are uniform density over its three
    # shapes; the real body (array bent, antenna lost) must then be uniform density over the shapes
    # it keeps, at the same density: an independent computation from the damaged meshes.
    case = load_case(CASE)
    model = body_meshes_target_frame(case, CASE.parent)[0]
    real = damaged_case(case, CASE.parent)
    body = real.target.bodies[0]
    meshes = body_meshes_target_frame(real, CASE.parent)[0]
    assert len(meshes) == 2                       # the antenna is gone
    density = case.target.bodies[0].mass / sum(m.volume for m in model)
    assert body.mass == pytest.approx(density * sum(m.volume for m in meshes), rel=1e-12)
    assert body.mass < case.target.bodies[0].mass
    com = geometric_center_of_mass(meshes)
    shift = np.array(case.perception.truth_damage.center_of_mass_shift)
    assert np.allclose(body.center_of_mass, com + shift, atol=1e-12)
    assert np.allclose(body.inertia, uniform_density_inertia(meshes, body.mass, com), rtol=1e-10, atol=1e-9)


def test_a_hinge_turn_moves_the_shape_about_the_hinge_line():
    # the array's root edge lies on the hinge line and stays; its tip (2 m out) moves by 2 sin(15 deg) m
    case = load_case(CASE)
    array = case.target.bodies[0].shapes[1]
    bent = hinge_turn(array, [0.0, 0.5, 0.2], [0.0, 0.0, 2.0], np.radians(15.0))
    turn = Rotation.from_rotvec(np.radians(15.0) * np.array([0.0, 0.0, 1.0]))
    assert np.allclose(bent.center, [0.0, 0.5, 0.2] + turn.apply([0.0, 1.0, 0.0]), atol=1e-12)
    assert np.allclose(Rotation.from_rotvec(bent.rotation_vector).as_matrix(), turn.as_matrix(), atol=1e-12)
    tip = np.array(bent.center) + turn.apply([0.0, 1.0, 0.0])
    assert np.linalg.norm(tip - [0.0, 2.5, 0.2]) == pytest.approx(2 * 2 * np.sin(np.radians(7.5)), rel=1e-12)


def test_no_damage_leaves_the_case_alone(tmp_path):
    case = load_case(_with_damage(tmp_path, ""))
    assert damaged_case(case, tmp_path) is case


@pytest.mark.parametrize("damage, message", [
    ("missing_shapes = [3]\n", "perception.truth_damage.missing_shapes: shape 3 does not exist; target.bodies[0] has shapes 0 to 2"),
    ("missing_shapes = [0, 1, 2]\n", "removes every shape"),
    ("missing_shapes = [1]\n[[perception.truth_damage.bends]]\nshape = 1\nhinge_point = [0.0, 0.0, 0.0]\n"
     "hinge_axis = [0.0, 0.0, 1.0]\nangle = 0.1\n", "shapes [1] are both missing and bent"),
    ("[[perception.truth_damage.bends]]\nshape = 1\nhinge_point = [0.0, 0.0, 0.0]\nhinge_axis = [0.0, 0.0, 0.0]\n"
     "angle = 0.1\n", "hinge_axis must be a non-zero vector"),
    ("[[perception.truth_damage.bends]]\nshape = 1\nhinge_point = [0.0, 0.0, 0.0]\nhinge_axis = [0.0, 0.0, 1.0]\n"
     "angle = 4.0\n", "perception.truth_damage.bends[0].angle"),
    ("missing_shapes = [-1]\n", "perception.truth_damage.missing_shapes[0]"),
    ("bend = 0.1\n", "perception.truth_damage.bend"),
])
def test_bad_damage_is_named(tmp_path, damage, message):
    path = _with_damage(tmp_path, "[perception.truth_damage]\n" + damage)
    with pytest.raises(CaseError) as err:
        load_case(path)
    assert "case.toml" in str(err.value) and message in str(err.value), str(err.value)
