"""Full-net tow from the end state of an impact run (riskassess/models/towing_from_run.py): the checks of
the run folder, the LVLH -> inertial transformation, and a short tow from it. The impact run is a reduced
copy of cases/zenit2_capture.toml (7 x 7 net launched 3 m from the debris CoM, 0.8 s), made once per module."""
import json
import shutil

import numpy as np
import pytest

from multibody.net_towing import run_exudyn
from multibody.maths.rotations import quaternion_to_matrix
from riskassess.cases.impact import CaseError, load_model
from riskassess.cases.towing import TowingCase
from riskassess.models.towing_from_run import drape_on_cylinder, impact_run_start, lift_onto_cylinder
from multibody.net_towing_kernel import cylinder_distance
from riskassess.models.towing_fullnet import debris_geometry, full_net_model
from riskassess.stages.run import run_case

CAPTURE, TOWING = "cases/zenit2_capture.toml", "cases/zenit2_towing_from_capture.toml"


@pytest.fixture(scope="module")
def impact_run(tmp_path_factory):
    """The capture case with a 7 x 7 net (node mass keeping m_net = 2.7326 kg) launched 3 m before the debris
    CoM, simulated to 0.8 s (the net reaches the cylinder at ~0.5 s)."""
    tmp = tmp_path_factory.mktemp("capture")
    text = open(CAPTURE).read()
    for old, new in (('end_time = 12.0 ', 'end_time = 0.8 '), ('distance = 17.7 ', 'distance = 3.0 '), ('nodes_per_side = 15', 'nodes_per_side = 7'),
                     ('node_mass = 0.0094782 ', 'node_mass = 0.04352245 '), ('net_output_rate = 10.0', 'net_output_rate = 20.0')):
        assert old in text
        text = text.replace(old, new)
    (tmp / "capture.toml").write_text(text)
    run_case(tmp / "capture.toml", tmp / "run")
    return tmp / "run"


def _towing(folder, **full_net):
    case = load_model(TOWING, TowingCase)
    fn = case.full_net.model_copy(update=dict(nodes_per_side=7, from_run=str(folder), **full_net))
    return case.model_copy(update=dict(full_net=fn))


def test_first_snapshot_is_the_table_2_state(impact_run):
    # The capture case was written from Table 2 in the chaser's LVLH frame; taken back to the inertial frame at
    # t = 0 the debris is at its Table 2 position (to the case's 7 digits: 1e-6 m), attitude (1e-6) and spin
    # (17.52 deg/s about -d_y, inertial: the LVLH frame's rate n added back, 1e-8 rad/s from the rounded n).
    case = _towing(impact_run)
    start = impact_run_start(case, TOWING, snapshot=0)
    assert start.time == 0.0
    np.testing.assert_allclose(start.debris_position, case.debris.position_inertial, rtol=0, atol=1e-6)
    np.testing.assert_allclose(start.debris_to_inertial, quaternion_to_matrix(np.asarray(case.debris.attitude_quaternion)),
                               rtol=0, atol=2e-6)   # the Table 2 quaternion has 4-5 digits: it is not exactly unit
    np.testing.assert_allclose(start.debris_omega_body, [0.0, -np.deg2rad(17.52), 0.0], rtol=0, atol=1e-7)
    # the net is the run's, with the closing loop appended open
    assert len(start.net.topology.masses) == 53 and start.net.topology.masses.sum() == pytest.approx(2.7326, rel=1e-6)


def test_run_folder_is_checked(impact_run, tmp_path):
    with pytest.raises(CaseError, match="is not a folder"):
        impact_run_start(_towing(tmp_path / "missing"), TOWING)
    with pytest.raises(CaseError, match="15 nodes a side"):
        impact_run_start(_towing(impact_run).model_copy(update=dict(
            full_net=_towing(impact_run).full_net.model_copy(update=dict(nodes_per_side=15)))), TOWING)
    case = _towing(impact_run)
    heavier = case.model_copy(update=dict(debris=case.debris.model_copy(update=dict(nominal_mass=9500.0))))
    with pytest.raises(CaseError, match="debris.nominal_mass"):
        impact_run_start(heavier, TOWING)
    copy = tmp_path / "running"
    shutil.copytree(impact_run, copy)
    manifest = json.loads((copy / "manifest.json").read_text())
    (copy / "manifest.json").write_text(json.dumps({**manifest, "status": "running"}))
    with pytest.raises(CaseError, match="status 'running'"):
        impact_run_start(_towing(copy), TOWING)


def test_tow_continues_from_the_run(impact_run):
    # 0.5 s of full-net tow from the run's end (0.8 s): the start is the run's state, and the momentum of chaser,
    # debris and net changes only by the external impulse (gravity; no thrust before 25 s, tether slack before
    # 15 s) up to Verlet's owed half kick H/2 |F| (2 ms x 85 kN / 2 = 85 N s, docs/towing.md)
    case = _towing(impact_run)
    start = impact_run_start(case, TOWING)
    # the hand-over corrections (towing_from_run module doc): no node inside the round cylinder by more than
    # round-off, the lift at most the facets' sag (1.95 (1 - cos(pi/32)) = 9.4 mm) plus a contact radius
    # (20 mm); the closing loop at most just taut
    geometry = debris_geometry(case)
    body = (start.node_positions - start.debris_position) @ start.debris_to_inertial
    gap = np.array([cylinder_distance(*x, geometry)[0] for x in body]) - start.net.topology.radii
    assert gap.min() > -1e-9 and 0.0 <= start.lift <= 0.0094 + 0.02
    top, k = start.net.topology, len(start.net.closing_rest_open)
    pairs = top.threads[-k:]
    reach = np.linalg.norm(start.node_positions[pairs[:, 1]] - start.node_positions[pairs[:, 0]], axis=1)
    assert np.all(reach <= top.rest_lengths[-k:] * (1 + 1e-12))
    model = full_net_model(case, end_time=start.time + 0.5, run_start=start)
    assert model.start_time == start.time == pytest.approx(0.8)
    np.testing.assert_array_equal(model.positions[1], start.debris_position)
    np.testing.assert_array_equal(model.positions[0], case.chaser.position_inertial)
    s = run_exudyn(model).series()
    p, j = s["total_momentum_inertial"], s["external_impulse_inertial"]
    assert np.linalg.norm(p - p[0] - (j - j[0]), axis=1).max() < 85.0
    assert np.all(np.isfinite(s["net_nodes_inertial"]))


def test_drape_on_cylinder_keeps_the_threads_lengths():
    # An arc of 9 nodes resting on the middles of the impact model's 32 facets (radius R cos(pi/32) + r for a
    # contact radius r), each thread at its natural length (a chord). Lifted along the normal onto the round
    # cylinder every thread is stretched by exactly (R + r) / (R cos(pi/32) + r) - 1 (similar triangles: 0.48 %,
    # the ~300 N in a Kevlar thread of the towing case); draped, no node is inside the surface and no thread
    # longer than its natural length (tolerance 1e-6 m), the arc's angle shrinking by that ratio instead.
    radius, r, n = 1.95, 0.005, 9
    angles = np.arange(n) * 2 * np.pi / 32                      # one node per facet middle
    faceted = (radius * np.cos(np.pi / 32) + r) * np.c_[np.cos(angles), np.sin(angles), np.zeros(n)]
    threads = np.c_[np.arange(n - 1), np.arange(1, n)]
    rest = np.linalg.norm(faceted[1:] - faceted[:-1], axis=1)
    geometry = np.array([radius, 5.5, 0.0])
    lifted, _ = lift_onto_cylinder(faceted, np.full(n, r), geometry)
    stretch = np.linalg.norm(lifted[1:] - lifted[:-1], axis=1) / rest - 1
    np.testing.assert_allclose(stretch, (radius + r) / (radius * np.cos(np.pi / 32) + r) - 1, rtol=1e-9)
    draped, lift, excess = drape_on_cylinder(faceted, np.full(n, 0.01), np.full(n, r), threads, rest, geometry)
    gap = np.array([cylinder_distance(*x, geometry)[0] for x in draped]) - r
    length = np.linalg.norm(draped[1:] - draped[:-1], axis=1)
    assert gap.min() > -1e-12 and excess <= 1e-6 and np.all(length <= rest + 1e-6)
    assert np.all(length >= rest - 1e-5)                       # not pulled slack either
    arc = np.arctan2(draped[-1, 1], draped[-1, 0]) - np.arctan2(draped[0, 1], draped[0, 0])
    chord_angle = 2 * np.arcsin(rest[0] / (2 * (radius + r)))   # the same chords on the round cylinder
    assert arc == pytest.approx((n - 1) * chord_angle, abs=1e-5)
    assert 0.0094 <= lift < 0.1
