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
from riskassess.vtk_export import export_vtk


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


def test_collection_lists_every_snapshot_and_paraview_reader_sees_them(exported, run_data):
    times = run_data["net"]["time"]
    datasets = ET.parse(exported / "impact.pvd").getroot().find("Collection").findall("DataSet")
    assert len(datasets) == 3 * len(times)             # net, bodies, bullets per snapshot
    assert [float(d.get("timestep")) for d in datasets[::3]] == pytest.approx(times, abs=1e-9)
    reader = pv.get_reader(str(exported / "impact.pvd"))
    assert len(reader.time_values) == len(times)
    reader.set_active_time_value(reader.time_values[-1])
    blocks = reader.read()
    assert blocks[0].n_points == len(run_data["net"]["masses"])


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
    result = export_vtk(assessed, out, every=7)
    n = len(run_data["net"]["time"])
    assert result.n_frames == math.ceil(n / 7) and len(list(out.glob("net_*.vtu"))) == result.n_frames
    before = sorted(p.name for p in out.iterdir())

    def interrupt(done, total):
        if done == 3:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt):
        export_vtk(assessed, out, every=1, progress=interrupt, overwrite=True)
    assert sorted(p.name for p in out.iterdir()) == before     # the old export is untouched
    assert [p.name for p in tmp_path.iterdir()] == ["vtk"]      # no partial folder left behind
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
