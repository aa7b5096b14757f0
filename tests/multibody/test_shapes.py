"""Contact shapes are plug-ins (multibody/shapes, one file each): found by NAME, an unknown kind is
refused with the known ones listed, and each shipped shape's mesh matches its analytic definition."""
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
import trimesh
from scipy.spatial.transform import Rotation

from multibody import shapes
from multibody.maths.plugins import discover
from multibody.shapes.base import ContactShape
from multibody.geometry import shape_mesh
from riskassess.cases.impact import SHAPE_MODELS, CaseError, _shape_model, load_case

CASES = Path(__file__).resolve().parents[2] / "cases"

#: A shape written as a user would add one: a right-corner tetrahedron of leg ``leg``.
TETRAHEDRON = textwrap.dedent('''
    """Contact shape ``tetrahedron``: corner at ``center``, legs along the target axes."""
    import numpy as np
    import trimesh

    from multibody.shapes.base import Key

    NAME = "tetrahedron"
    KEYS = (Key("leg", "positive", "Leg length (m)."),
            Key("center", "vector3", "Right-angle corner, target frame (m).", default=(0.0, 0.0, 0.0)))


    def mesh_target_frame(leg, center=(0, 0, 0)):
        corners = leg * np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], float) + np.asarray(center, float)
        return trimesh.Trimesh(corners, [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
''')


def test_a_new_shape_file_is_found_by_its_name(tmp_path, monkeypatch):
    # Adding a shape is adding one file: a module dropped into the package's folder is discovered
    # under its NAME, and the case schema is built from its KEYS.
    (tmp_path / "tetrahedron.py").write_text(TETRAHEDRON)
    monkeypatch.setattr(shapes, "__path__", [*shapes.__path__, str(tmp_path)])
    monkeypatch.delitem(sys.modules, "multibody.shapes.tetrahedron", raising=False)
    try:
        found = discover(shapes.__name__, shapes.__path__, "contact shape", ContactShape, skip=shapes.NOT_SHAPES)
    finally:
        sys.modules.pop("multibody.shapes.tetrahedron", None)
    assert list(found) == ["box", "cylinder", "ellipsoid", "mesh", "sphere", "tetrahedron"]
    module = found["tetrahedron"]
    # Volume of the corner tetrahedron: leg^3 / 6 (exact up to rounding).
    assert module.mesh_target_frame(leg=0.6, center=[1, 2, 3]).volume == pytest.approx(0.6**3 / 6, rel=1e-12)
    model = _shape_model(module)
    assert model(kind="tetrahedron", leg=0.6).center == [0.0, 0.0, 0.0]
    with pytest.raises(ValueError, match="greater than 0"):
        model(kind="tetrahedron", leg=-1.0)


def test_shipped_shapes_and_case_schema_agree():
    # Every file of multibody/shapes but the interface (base.py) is a case shape kind, and nothing else is.
    files = sorted(p.stem for p in Path(shapes.__file__).parent.glob("*.py")
                   if p.stem not in ("__init__", *shapes.NOT_SHAPES))
    assert sorted(shapes.SHAPES) == files
    assert list(SHAPE_MODELS) == list(shapes.SHAPES)
    for name, module in shapes.SHAPES.items():
        assert list(SHAPE_MODELS[name].model_fields) == ["kind", *(key.name for key in module.KEYS)]


def test_unknown_kind_is_refused_with_the_known_ones():
    with pytest.raises(ValueError) as info:
        shape_mesh("cone", radius=1.0)
    assert str(info.value) == ("unknown contact shape 'cone'; the known contact shapes are: "
                               "box, cylinder, ellipsoid, mesh, sphere")


def test_unknown_kind_in_a_case_names_file_key_and_kinds(tmp_path):
    reference = (CASES / "envisat_net_impact.toml").read_text()
    old = 'kind = "cylinder"'
    assert old in reference
    path = tmp_path / "bad.toml"
    path.write_text(reference.replace(old, 'kind = "cone"', 1))
    with pytest.raises(CaseError) as info:
        load_case(path)
    message = str(info.value)
    assert f"{path}: target.bodies[3].shapes[0]: " in message
    assert "'cone'" in message and "'box', 'cylinder', 'ellipsoid', 'mesh', 'sphere'" in message


def test_box_volume_and_turned_corner():
    # A box of edges a, b, c has volume abc; its corner (a, b, c)/2 turned by R and moved to c0.
    size, center, rotvec = [1.0, 2.0, 3.0], np.array([0.5, -1.0, 2.0]), np.array([0.2, -0.4, 0.7])
    mesh = shape_mesh("box", size=size, center=center, rotation_vector=rotvec)
    assert mesh.volume == pytest.approx(6.0, rel=1e-12)
    corner = center + Rotation.from_rotvec(rotvec).apply(np.array(size) / 2)
    assert np.min(np.linalg.norm(mesh.vertices - corner, axis=1)) < 1e-12


def test_cylinder_vertices_on_its_surface():
    # Every vertex lies at the radius from the axis and on an end cap (|axial| = L/2) or on the axis.
    radius, length, axis, center = 0.3, 2.0, np.array([1.0, 1.0, 0.0]), np.array([2.0, 0.0, 0.0])
    mesh = shape_mesh("cylinder", radius=radius, length=length, axis=axis, center=center)
    unit = axis / np.linalg.norm(axis)
    rel = mesh.vertices - center
    axial = rel @ unit
    radial = np.linalg.norm(rel - np.outer(axial, unit), axis=1)
    assert np.allclose(np.abs(axial), length / 2, atol=1e-12)
    assert np.all(np.isclose(radial, radius, atol=1e-12) | np.isclose(radial, 0.0, atol=1e-12))
    # 32 facets: the polygon area 32/2 r^2 sin(2 pi/32) times L.
    assert mesh.volume == pytest.approx(16 * radius**2 * np.sin(2 * np.pi / 32) * length, rel=1e-12)


def test_sphere_and_ellipsoid_vertices_on_their_surfaces():
    sphere = shape_mesh("sphere", radius=0.7, center=[0.1, 0.2, 3.0])
    assert np.allclose(np.linalg.norm(sphere.vertices - [0.1, 0.2, 3.0], axis=1), 0.7, atol=1e-12)
    semi, center, rotvec = np.array([0.5, 0.8, 1.1]), np.array([1.0, 1.0, 1.0]), np.array([0.3, -0.2, 0.1])
    ellipsoid = shape_mesh("ellipsoid", semi_axes=semi, center=center, rotation_vector=rotvec)
    own = Rotation.from_rotvec(rotvec).inv().apply(ellipsoid.vertices - center)   # ellipsoid frame
    assert np.allclose(np.sum((own / semi) ** 2, axis=1), 1.0, atol=1e-12)
    assert len(ellipsoid.faces) == 1280   # icosphere of 3 subdivisions: 20 * 4^3


def test_mesh_file_scaled_and_placed(tmp_path):
    # A unit cube written to STL and read back with scale 2: volume 8, centred at ``center``.
    trimesh.creation.box(extents=[1, 1, 1]).export(tmp_path / "cube.stl")
    mesh = shape_mesh("mesh", file=tmp_path / "cube.stl", scale=2.0, center=[0, 0, 5],
                      rotation_vector=[0, 0, np.pi / 4])
    assert mesh.volume == pytest.approx(8.0, rel=1e-6)   # STL stores float32 vertices
    assert np.allclose(mesh.vertices.mean(axis=0), [0, 0, 5], atol=1e-6)
