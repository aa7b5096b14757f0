"""`riskassess export-vtk`: files ParaView opens, read back and compared with the run folder."""
import json
import math
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest
import pyvista as pv
import trimesh

from riskassess.cli import main
from riskassess.products.vtk_export import export_vtk


@pytest.fixture(scope="module")
def exported(assessed, tmp_path_factory):
    out = tmp_path_factory.mktemp("vtk") / "vtk"
    assert main(["export-vtk", str(assessed), "--out", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def run_data(assessed):
    load = lambda name: dict(np.load(assessed / name))  # noqa: E731
    return {"net": load("net.npz"), "series": load("timeseries.npz"), "bodies": load("bodies.npz"),
            "verdict": json.loads((assessed / "structures.json").read_text())}


PARTS = ["net", "bodies", "bullets", "body_frames", "joints"]


def test_collection_lists_every_snapshot_and_paraview_reader_sees_named_blocks(exported, run_data):
    times = run_data["net"]["time"]
    datasets = ET.parse(exported / "impact.pvd").getroot().find("Collection").findall("DataSet")
    assert len(datasets) == len(times)             # one multiblock per snapshot (the small run is within budget)
    assert [float(d.get("timestep")) for d in datasets] == pytest.approx(times, abs=1e-9)
    reader = pv.get_reader(str(exported / "impact.pvd"))
    assert len(reader.time_values) == len(times)
    reader.set_active_time_value(reader.time_values[-1])
    frame = reader.read()[0]
    assert frame.keys() == PARTS     # ParaView shows these names, not Block-00/01/02
    assert frame["net"].n_points == len(run_data["net"]["masses"])


def test_node_contact_forces_balance_the_body_contact_forces(exported, run_data):
    """Newton's third law: over each net-snapshot interval the impulse the nodes get from the bodies
    is minus the impulse the bodies get from the nodes (kernel: one action-reaction pair per contact)."""
    net, s = run_data["net"], run_data["series"]
    on_bodies = s["contact_force_lvlh"].sum(axis=1)          # (k, 3) N, each averaged over its 1 ms interval
    checked = 0
    for f in range(1, len(net["time"])):
        mesh = meshio.read(exported / f"net_{f:04d}.vtu")
        on_nodes = mesh.point_data["contact_force_lvlh_N"].sum(axis=0)
        inside = (s["time"] > net["time"][f - 1] + 1e-9) & (s["time"] <= net["time"][f] + 1e-9)
        expected = -on_bodies[inside].mean(axis=0)
        # float32 storage of the node forces (~1e-7 relative per node, a few hundred nodes)
        assert on_nodes == pytest.approx(expected, rel=1e-4, abs=1e-3 * (1 + np.abs(expected).max()))
        checked += bool(np.abs(expected).max() > 1.0)
    assert checked > 10   # the net touches the debris over most of the run


def test_body_frames_carry_the_pose_and_the_contact_loads(exported, run_data):
    s, net = run_data["series"], run_data["net"]
    nb = len(s["body_names"])
    f = len(net["time"]) // 2
    i = int(np.argmin(np.abs(s["time"] - net["time"][f])))
    mesh = meshio.read(exported / f"body_frames_{f:04d}.vtu")
    points = mesh.points.reshape(nb, 4, 3)
    assert np.allclose(points[:, 0], s["body_com_lvlh"][i], atol=1e-12)
    axes = points[:, 1:] - points[:, :1]                       # (nb, 3 axes, 3)
    unit = axes / np.linalg.norm(axes, axis=2, keepdims=True)
    assert np.allclose(np.swapaxes(unit, 1, 2), s["body_to_lvlh"][i], atol=1e-9)   # columns of body->LVLH
    force = mesh.point_data["contact_force_lvlh_N"].reshape(nb, 4, 3)
    assert np.allclose(force[:, 0], s["contact_force_lvlh"][i]) and not force[:, 1:].any()
    assert np.allclose(mesh.point_data["contact_moment_lvlh_Nm"].reshape(nb, 4, 3)[:, 0], s["contact_moment_lvlh"][i])


def test_joint_and_weak_location_markers_follow_the_parent(exported, run_data, assessed):
    case = json.loads((assessed / "case.json").read_text())
    joints = json.loads((exported / "joints.json").read_text())
    names = [str(n) for n in run_data["series"]["body_names"]]
    hinge = next(j for j in case["target"]["joints"] if j["name"] == "solar_array_hinge")
    k = [j["name"] for j in joints].index("solar_array_hinge")
    # t = 0, target attitude zero in this case: the point is the target origin plus the declared position
    assert case["target"]["attitude_rotation_vector"] == [0.0, 0.0, 0.0]
    first = meshio.read(exported / "joints_0000.vtu")
    assert np.allclose(first.points[k], np.add(case["target"]["position_lvlh"], hinge["position"]), atol=1e-6)
    # later: fixed in the parent body (same body-frame coordinates as at t = 0)
    s, net = run_data["series"], run_data["net"]
    p = names.index(hinge["parent"])
    f = len(net["time"]) - 1
    i = int(np.argmin(np.abs(s["time"] - net["time"][f])))
    last = meshio.read(exported / f"joints_{f:04d}.vtu")
    body_point_0 = s["body_to_lvlh"][0, p].T @ (first.points[k] - s["body_com_lvlh"][0, p])
    body_point_f = s["body_to_lvlh"][i, p].T @ (last.points[k] - s["body_com_lvlh"][i, p])
    assert np.allclose(body_point_f, body_point_0, atol=1e-9)
    release = run_data["verdict"]["released_pieces"][0]
    assert release["joint"] == "solar_array_hinge" and joints[k]["released_at_s"] == release["release_time_s"]
    assert first.point_data["released"][k] == 0 and last.point_data["released"][k] == 1
    failing = {loc["joint"] for loc in run_data["verdict"]["locations"] if loc["fails"]}
    declared = {loc["joint"] for loc in run_data["verdict"]["locations"]}
    assert [bool(x) for x in last.point_data["fails"]] == [j["name"] in failing for j in joints]
    assert [bool(x) for x in last.point_data["weak_location"]] == [j["name"] in declared for j in joints]


def test_net_mesh_holds_the_snapshot_and_thread_loads(exported, run_data):
    net = run_data["net"]
    f = len(net["time"]) // 2
    mesh = meshio.read(exported / f"net_{f:04d}.vtu")
    assert mesh.points.shape == net["positions_lvlh"][f].shape
    assert mesh.cells_dict["line"].shape == net["threads"].shape
    assert np.array_equal(mesh.points, net["positions_lvlh"][f])
    assert np.array_equal(mesh.point_data["velocity_lvlh_m_s"], net["velocities_lvlh"][f])
    tension = mesh.cell_data["tension_N"][0]
    strain = mesh.cell_data["strain"][0]
    # tension by hand for every thread: T = max(0, k (l - l0) + c dl/dt) when stretched (paper eq. 1)
    x, v = net["positions_lvlh"][f], net["velocities_lvlh"][f].astype(float)
    assert x.dtype == np.float64  # float32 positions would leave ~0.3 N of noise in the tensions
    for t, (a, b) in enumerate(net["threads"]):
        d = x[b] - x[a]
        length = np.linalg.norm(d)
        rate = (v[b] - v[a]) @ d / length
        stretch = length - net["rest_lengths"][t]
        expected = max(0.0, net["stiffness"][t] * stretch + net["damping"][t] * rate) if stretch > 0 else 0.0
        assert tension[t] == pytest.approx(expected, rel=1e-9, abs=1e-9)
        assert strain[t] == pytest.approx(stretch / net["rest_lengths"][t], rel=1e-9, abs=1e-12)
    assert (tension > 0).any()  # mid-capture, threads are loaded
    assert mesh.cell_data["bullet_tether"][0].sum() == int(net["n_bullets"])


def test_bodies_move_rigidly_with_their_recorded_pose(exported, run_data):
    s, meshes, net = run_data["series"], run_data["bodies"], run_data["net"]
    n_bodies = len(s["body_names"])
    f = len(net["time"]) - 1
    mesh = meshio.read(exported / f"bodies_{f:04d}.vtu")
    i = int(np.argmin(np.abs(s["time"] - net["time"][f])))
    body_index = mesh.cell_data["body_index"][0]
    triangles = mesh.cells_dict["triangle"]
    offset = 0
    for k in range(n_bodies):
        vertices = meshes[f"vertices_{k}"]
        expected = vertices @ s["body_to_lvlh"][i, k].T + s["body_com_lvlh"][i, k]
        assert np.allclose(mesh.points[offset:offset + len(vertices)], expected, rtol=0, atol=1e-9)
        # a rigid motion keeps the surface area (m^2) of the body's mesh
        posed = trimesh.Trimesh(mesh.points, triangles[body_index == k], process=False)
        assert posed.area == pytest.approx(trimesh.Trimesh(vertices, meshes[f"faces_{k}"]).area, rel=1e-9)
        # the surface velocity of a rigid body has the same component along any two points' chord
        v = mesh.point_data["velocity_lvlh_m_s"][offset:offset + len(vertices)]
        chord = expected[1] - expected[0]
        assert (v[1] - v[0]) @ chord == pytest.approx(0.0, abs=1e-9 * (1 + np.linalg.norm(v)))
        offset += len(vertices)
    assert offset == len(mesh.points)


def test_released_piece_flagged_from_its_release_time(exported, run_data):
    pieces = run_data["verdict"]["released_pieces"]
    # the reduced case releases the solar array shortly after the 0.25 s transient (see test_assess_cli)
    assert pieces, "the reference small run is expected to release the solar array"
    names = [str(n) for n in run_data["series"]["body_names"]]
    k = names.index(pieces[0]["bodies"][0])
    times = run_data["net"]["time"]
    for f in (0, int(np.searchsorted(times, pieces[0]["release_time_s"])), len(times) - 1):
        mesh = meshio.read(exported / f"bodies_{f:04d}.vtu")
        body = mesh.cell_data["body_index"][0] == k
        flag = mesh.cell_data["released"][0]
        assert (flag[body] == (times[f] >= pieces[0]["release_time_s"])).all()
        assert (flag[~body] == 0).all()
    assert json.loads((exported / "bodies.json").read_text())[k]["released_at_s"] == pieces[0]["release_time_s"]


def test_bullets_are_the_last_net_nodes(exported, run_data):
    net = run_data["net"]
    n_bullets = int(net["n_bullets"])
    mesh = meshio.read(exported / "bullets_0003.vtu")
    assert np.array_equal(mesh.points, net["positions_lvlh"][3, -n_bullets:])
    assert np.array_equal(mesh.point_data["radius_m"], net["radii"][-n_bullets:])


def test_every_nth_frame_and_an_interrupted_export_keeps_the_old_one(assessed, tmp_path, run_data):
    out = tmp_path / "vtk"
    n = len(run_data["net"]["time"])
    small = export_vtk(assessed, tmp_path / "small", max_frames=10)
    assert small.n_frames <= 10 and small.n_frames == math.ceil(n / math.ceil(n / 10))
    assert np.allclose(np.diff(small.times), np.diff(small.times)[0])   # a constant stride: ParaView plays evenly
    result = export_vtk(assessed, out, every=7)
    assert result.n_frames == math.ceil(n / 7) and len(list(out.glob("net_*.vtu"))) == result.n_frames
    before = sorted(p.name for p in out.iterdir())

    def interrupt(done, total):
        if done == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        export_vtk(assessed, out, every=1, progress=interrupt, overwrite=True)
    assert sorted(p.name for p in out.iterdir()) == before     # the old export is untouched
    assert sorted(p.name for p in tmp_path.iterdir()) == ["small", "vtk"]   # no partial folder left behind
    with pytest.raises(ValueError, match="every must be >= 1"):
        export_vtk(assessed, out, every=0)
    # with --overwrite the export replaces its own files (every frame now), and only those
    result = export_vtk(assessed, out, every=1, overwrite=True)
    assert sorted(p.name for p in out.iterdir()) == sorted(json.loads((out / "manifest.json").read_text())["files"]
                                                          + ["manifest.json"])
    assert len(list(out.glob("net_*.vtu"))) == result.n_frames == n


def _tree(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_export_never_deletes_a_folder_it_did_not_make(assessed, tmp_path, capsys):
    """Issue 20 item 1: `export-vtk RUN --out DIR` renamed DIR away and deleted it recursively (a
    thesis folder; the run folder itself when DIR is the run)."""
    thesis = tmp_path / "thesis"
    (thesis / "figures").mkdir(parents=True)
    (thesis / "chapter1.tex").write_text("years of work")
    run_before, thesis_before = _tree(assessed), _tree(thesis)
    for out in (thesis, assessed, assessed.parent):
        for extra in ([], ["--overwrite"]):
            capsys.readouterr()
            assert main(["export-vtk", str(assessed), "--out", str(out), "--every", "50", *extra]) == 2
            assert str(out) in capsys.readouterr().err
    assert _tree(thesis) == thesis_before and _tree(assessed) == run_before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["thesis"]   # no staging folder left either


def test_export_into_an_empty_folder_then_only_into_its_own(assessed, tmp_path, capsys):
    out = tmp_path / "empty"
    out.mkdir()
    assert main(["export-vtk", str(assessed), "--out", str(out), "--every", "50"]) == 0
    made = _tree(out)
    assert main(["export-vtk", str(assessed), "--out", str(out), "--every", "50"]) == 2   # needs --overwrite
    assert "--overwrite" in capsys.readouterr().err and _tree(out) == made
    (out / "my_view.pvsm").write_text("a ParaView state of mine")
    assert main(["export-vtk", str(assessed), "--out", str(out), "--every", "50", "--overwrite"]) == 2
    assert "my_view.pvsm" in capsys.readouterr().err and (out / "my_view.pvsm").is_file()
    (out / "my_view.pvsm").unlink()
    assert main(["export-vtk", str(assessed), "--out", str(out), "--every", "25", "--overwrite"]) == 0
    assert _tree(out) != made and sorted(p.name for p in tmp_path.iterdir()) == ["empty"]


def test_frame_stride_keeps_the_export_within_its_budget():
    from riskassess.products.vtk_frames import frame_stride

    # 376 snapshots of 120 kB in 20 MB: at most 166 frames, so every 3rd snapshot (126 frames)
    assert frame_stride(376, None, None, lambda: 120_000, budget=20_000_000) == 3
    assert frame_stride(376, None, 100, None) == 4 and frame_stride(376, 5, None, None) == 5
    assert frame_stride(10, None, None, lambda: 1, budget=20_000_000) == 1
    with pytest.raises(ValueError, match="not both"):
        frame_stride(376, 5, 100, None)
