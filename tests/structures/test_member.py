"""A clamped joint carrying its member's compliance (``member`` on the joint, structures/member.py):
the springs from the section, the ring-down of a dish on its bracket against the cantilever's
frequency, and the case checks."""
from pathlib import Path

import numpy as np
import pytest

from multibody.assembly import ContactLaw, ImpactAssembly, JointSpec, RigidBodySpec, SolverSpec
from multibody.hinge import hinge_frame_lvlh, joint_stiffness_joint_frame
from multibody.impact import ImpactSimulation
from multibody.recorded_loads import RecordedBodyLoads
from riskassess.cases.impact import CaseError, load_case
from riskassess.models.impact import model_inputs
from structures.member import SHEAR_COEFFICIENT, member_stiffness_joint_frame
from structures.section_shapes import SHAPES
from tests.conftest import single_node

CASES = Path(__file__).resolve().parents[2] / "cases"
SMALL = (CASES / "envisat_small.toml").read_text()
# the Ka-band dish bracket of the shipped cases: 40 x 1 mm tube, Ti-6Al-4V (E 114 GPa, G 44 GPa)
TUBE = SHAPES["circular_tube"].properties(outer_diameter=0.04, wall=0.001)
E, G, L = 114e9, 44e9, 0.45
DISH_MASS = 10.0


def test_springs_are_the_members_axial_shear_torsion_and_bending_stiffness():
    # member along h1: axis 1 -> h1, 2 -> h2, 3 -> h3 (the joint frame's axes, either sign)
    k = member_stiffness_joint_frame(TUBE, L, E, G, [-1.0, 0.0, 0.0])
    d, d_in = 0.04, 0.038
    area, i = np.pi * (d ** 2 - d_in ** 2) / 4, np.pi * (d ** 4 - d_in ** 4) / 64      # Roark Table A.1
    np.testing.assert_allclose(k, [E * area / L, SHEAR_COEFFICIENT * G * area / L, SHEAR_COEFFICIENT * G * area / L,
                                   G * 2 * i / L, 3 * E * i / L, 3 * E * i / L], rtol=1e-12)
    # along h3: the axial spring and the torsion move to the third axis
    k3 = member_stiffness_joint_frame(TUBE, L, E, G, [0.0, 0.0, 2.0])
    assert k3[2] == pytest.approx(k[0]) and k3[5] == pytest.approx(k[3]) and k3[3] == pytest.approx(k[4])
    with pytest.raises(ValueError, match="must run along one of its joint's axes"):
        member_stiffness_joint_frame(TUBE, L, E, G, [1.0, 1.0, 0.0])


def dish_on_bracket(angle0, step):
    """A 10 kg dish (small rotary inertia) at the end of the bracket, clamped to a 1e6 kg base; the
    dish starts turned by ``angle0`` about the joint's h2 (bending), at rest."""
    base = RigidBodySpec(name="base", mass=1e6, inertia_body=np.eye(3) * 1e8, com_lvlh=np.zeros(3))
    root, tip = np.zeros(3), np.array([L, 0.0, 0.0])
    frame = hinge_frame_lvlh([0.0, 0.0, 1.0], root, tip)      # h1 = -x (towards the root), h2 = z
    turn = np.array([[np.cos(angle0), -np.sin(angle0), 0], [np.sin(angle0), np.cos(angle0), 0], [0, 0, 1]])
    dish = RigidBodySpec(name="dish", mass=DISH_MASS, inertia_body=np.eye(3) * 0.01, com_lvlh=turn @ tip,
                         body_to_lvlh=turn)
    joint = JointSpec(name="root", kind="clamped", parent=0, child=1, point_lvlh=root, hinge_to_lvlh=frame,
                      penalty_damping_ratio=0.0,
                      structural_stiffness=member_stiffness_joint_frame(TUBE, L, E, G, frame.T @ [1.0, 0.0, 0.0]))
    assembly = ImpactAssembly(net=single_node([100.0, 100.0, 100.0], [0.0, 0.0, 0.0]), net_velocity=np.zeros((1, 3)),
                              bodies=[base, dish], joints=[joint], contact=ContactLaw(stiffness=1e8),
                              solver=SolverSpec(end_time=0.5, step=step, output_rate=2000.0, net_output_rate=10.0))
    return assembly, [np.eye(3), np.eye(3)], [base.com_lvlh, tip]


def cantilever_frequency() -> float:
    """Lowest natural frequency (rad/s) of a massless Timoshenko cantilever of the bracket carrying the dish
    at its end: tip flexibility [[L^3/3EI + L/(kappa G A), L^2/2EI], [L^2/2EI, L/EI]] (Roark Table 8.1
    case 1a/3a) against the tip mass and rotary inertia."""
    ei = E * TUBE.second_moment_2
    flexibility = np.array([[L ** 3 / (3 * ei) + L / (SHEAR_COEFFICIENT * G * TUBE.area), L ** 2 / (2 * ei)],
                            [L ** 2 / (2 * ei), L / ei]])
    w2 = np.linalg.eigvals(np.linalg.inv(flexibility) @ np.linalg.inv(np.diag([DISH_MASS, 0.01])))
    return float(np.sqrt(w2.real.min()))


def measured_frequency(t, angle) -> float:
    crossings = np.flatnonzero(np.sign(angle[:-1]) != np.sign(angle[1:]))
    times = t[crossings] - angle[crossings] * (t[crossings + 1] - t[crossings]) / (angle[crossings + 1] - angle[crossings])
    return 2.0 * np.pi / (2.0 * np.mean(np.diff(times)))


def test_a_dish_on_its_bracket_rings_at_the_cantilevers_frequency_whatever_the_step():
    measured = []
    for step in (1e-4, 5e-5):
        assembly, rest_att, rest_com = dish_on_bracket(0.002, step)
        rec = ImpactSimulation(assembly, rest_att, rest_com).run()
        measured.append(measured_frequency(rec.series["time"], rec.series["joint_rotation_joint"][:, 0, 1]))
    # the bracket's 14.9 Hz bending mode: 3 E I / L at the root is the cantilever's tip stiffness, so the
    # lumped member and the beam agree up to the dish's own rotary inertia (0.01 against m L^2 = 2 kg m^2,
    # the beam turns its tip, the lumped root does not) and the 1e6 kg base's recoil: both below 0.5 %
    assert measured[0] == pytest.approx(cantilever_frequency(), rel=0.01)
    # no penalty is left in the joint: halving the step moves the frequency by < 0.1 % (Verlet's phase
    # error (omega h)^2 / 24 is 4e-6 at this mode)
    assert measured[1] == pytest.approx(measured[0], rel=1e-3)


def static_tip_deflection(force, step, end_time=0.5):
    """Deflection (m, along the load) of a dish's CoM on the bracket under a constant transverse ``force`` (N)
    at the CoM, relative to the 1e6 kg base, settled: the dish of the case (10 kg, disc inertias 0.51, 1.01,
    0.51 kg m^2), damping 0.2 of critical (0.5 s: 9 decay times of the 14.9 Hz mode)."""
    base = RigidBodySpec(name="base", mass=1e6, inertia_body=np.eye(3) * 1e8, com_lvlh=np.zeros(3))
    root, tip = np.zeros(3), np.array([L, 0.0, 0.0])
    frame = hinge_frame_lvlh([0.0, 0.0, 1.0], root, tip)
    dish = RigidBodySpec(name="dish", mass=DISH_MASS, inertia_body=np.diag([0.51, 1.01, 0.51]), com_lvlh=tip)
    joint = JointSpec(name="root", kind="clamped", parent=0, child=1, point_lvlh=root, hinge_to_lvlh=frame,
                      penalty_damping_ratio=0.2,
                      structural_stiffness=member_stiffness_joint_frame(TUBE, L, E, G, frame.T @ [1.0, 0.0, 0.0]))
    loads = RecordedBodyLoads(time=np.array([end_time]), force_lvlh=np.array([[[0.0, 0.0, 0.0], [0.0, force, 0.0]]]),
                              moment_body=np.zeros((1, 2, 3)), reference_energy=1.0)
    assembly = ImpactAssembly(net=single_node([100.0, 100.0, 100.0], [0.0, 0.0, 0.0]), net_velocity=np.zeros((1, 3)),
                              bodies=[base, dish], joints=[joint], contact=ContactLaw(stiffness=1e8),
                              solver=SolverSpec(end_time=end_time, step=step, output_rate=1000.0, net_output_rate=10.0),
                              body_loads=loads)
    com = ImpactSimulation(assembly, [np.eye(3), np.eye(3)], [base.com_lvlh, tip]).run().series["body_com_lvlh"]
    return (com[-1, 1, 1] - com[-1, 0, 1]) - (com[0, 1, 1] - com[0, 0, 1])


@pytest.mark.parametrize("force", [1.0, 0.01])
def test_a_member_deflects_as_the_timoshenko_cantilever_under_a_tip_load(force):
    # Tip deflection of a cantilever under an end load: F L^3 / (3 E I) (Euler-Bernoulli, Roark Table 8.1 case
    # 1a) plus the shear term F L / (kappa G A): the lumped member's root springs give both exactly, the
    # dish being rigid. 0.01 N turns the root by 2.6e-7 rad at rates below Exudyn's attitude floor (2e-8 rad a
    # step, multibody/rotation_update.py): without the restored attitudes the bend would not show at all.
    expected = force * L ** 3 / (3 * E * TUBE.second_moment_2) + force * L / (SHEAR_COEFFICIENT * G * TUBE.area)
    # the transient has decayed to 1e-4 of the deflection, the base's recoil (1e-5 of the dish's mass) is below
    # 1e-4; measured 2.6e-4 (1 N) and 6.6e-4 (0.01 N) off; without the restored attitudes 0.01 N gives 12 %
    assert static_tip_deflection(force, 1e-4) == pytest.approx(expected, rel=2e-3)


def test_a_member_too_stiff_for_the_step_is_refused():
    assembly, _, _ = dish_on_bracket(0.0, 1e-4)
    joint = assembly.joints[0]
    joint.structural_stiffness = member_stiffness_joint_frame(TUBE, 0.05, E, G, [1.0, 0.0, 0.0])  # axial ~1.7 kHz
    with pytest.raises(ValueError, match="fewer than 20 steps of 0.0001 s per period"):
        joint_stiffness_joint_frame(joint, *assembly.bodies, 1e-4)


DISH_JOINT = 'position = [3.1875, 0.0, -3.0]\n'
FAST_OUTPUT = ("output_rate = 1000.0", "output_rate = 5000.0")      # resolves the member's modes
MEMBER = ('member = { length = 0.45, section = { kind = "circular_tube", outer_diameter = 0.04, wall = 0.001 }, '
          'modulus = 114e9, shear_modulus = 44e9, beam_axis = [1.0, 0.0, 0.0], source = "test" }\n')


def _write(tmp_path, text):
    path = tmp_path / "case.toml"
    path.write_text(text)
    return path


def test_a_case_member_becomes_the_joints_springs(tmp_path):
    case = load_case(_write(tmp_path, SMALL.replace(DISH_JOINT, DISH_JOINT + MEMBER).replace(*FAST_OUTPUT)))
    joint = model_inputs(case, CASES).assembly.joints[3]
    assert joint.name == "ka_band_dish_root"
    # beam along target x = -h1 of the joint (h1 points from the dish towards the root)
    np.testing.assert_allclose(joint.structural_stiffness, member_stiffness_joint_frame(TUBE, L, E, G, [1, 0, 0]))


@pytest.mark.parametrize("change, expected", [
    (MEMBER + "first_mode_hz = 20.0\n", "'member' sets all six springs of the joint; remove first_mode_hz"),
    (MEMBER.replace('kind = "circular_tube", outer_diameter = 0.04, wall = 0.001',
                    'kind = "solid_rectangle", width = 0.04, height = 0.01'), "does not (use circular_tube)"),
    (MEMBER.replace("beam_axis = [1.0, 0.0, 0.0]", "beam_axis = [1.0, 1.0, 0.0]"),
     "target.joints 'ka_band_dish_root'.member: a member must run along one of its joint's axes"),
])
def test_bad_members_are_refused(tmp_path, change, expected):
    with pytest.raises((CaseError, ValueError)) as info:
        case = load_case(_write(tmp_path, SMALL.replace(DISH_JOINT, DISH_JOINT + change).replace(*FAST_OUTPUT)))
        model_inputs(case, CASES)
    assert expected in str(info.value)


def test_a_member_and_a_modal_reading_of_the_same_joint_are_refused(tmp_path):
    text = SMALL.replace(DISH_JOINT, DISH_JOINT + MEMBER).replace(
        'material = { ultimate_normal = [950e6, 3500e6], ultimate_shear = [50e6, 100e6] }  # Pa [paper Sec. 3.4]',
        'material = { ultimate_normal = [950e6, 3500e6], ultimate_shear = [50e6, 100e6] }\nstructural_mode_hz = 2.0')
    with pytest.raises(CaseError) as info:
        load_case(_write(tmp_path, text))
    assert "already has its member's compliance in the dynamics" in str(info.value)


def test_a_member_needs_samples_that_resolve_its_modes(tmp_path):
    # the bracket's axial spring with the 10 kg dish rings at ~360 Hz: 1 kHz samples would read its peaks low
    case = load_case(_write(tmp_path, SMALL.replace(DISH_JOINT, DISH_JOINT + MEMBER)))
    with pytest.raises(ValueError, match="simulation.output_rate must be at least"):
        model_inputs(case, CASES)
    fine = SMALL.replace(DISH_JOINT, DISH_JOINT + MEMBER).replace(*FAST_OUTPUT)
    assert model_inputs(load_case(_write(tmp_path, fine)), CASES).assembly.joints[3].structural_stiffness is not None
