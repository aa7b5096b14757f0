"""The tabulated nearest-point query against scipy's exact KD-tree."""
import numpy as np
import trimesh
from scipy.spatial import cKDTree

from perception.nearest_grid import CellList, NearestPointGrid
from perception.registration import known_shape_model

VOXEL = 0.03


def _sphere_model(radius=0.7):
    mesh = trimesh.creation.icosphere(subdivisions=5, radius=radius)
    return known_shape_model(mesh, VOXEL, seed=0)


def test_grid_matches_the_kd_tree_within_the_curvature_bound():
    points, normals = _sphere_model()
    grid = NearestPointGrid(points, VOXEL / 3, 0.1)
    rng = np.random.default_rng(1)
    queries = points[rng.choice(len(points), 3000)] + rng.normal(0.0, 0.02, (3000, 3))
    gap, index = grid.query(queries, distance_upper_bound=0.1)
    exact_gap, exact_index = cKDTree(points).query(queries, distance_upper_bound=0.1)
    # 2 cm noise (5 sigma = 0.1 m): every query is within reach of the surface, both find a point.
    assert np.array_equal(np.isfinite(gap), np.isfinite(exact_gap)) and np.isfinite(gap).all()
    # Measured 95 % exact; the cell answer refined by one descent step is exact for most queries.
    assert np.mean(index == exact_index) > 0.9
    residual = np.einsum("ij,ij->i", queries - points[index], normals[index])
    exact = np.einsum("ij,ij->i", queries - points[exact_index], normals[exact_index])
    # A tangent plane taken a distance d along the surface from the exact one changes the
    # residual by about kappa d^2 / 2; d < one cell diagonal (1.7 cm), kappa = 1/0.7 m^-1:
    # 0.2 mm at worst, far below the 2 cm noise. Measured 0.05 mm rms.
    assert np.sqrt(np.mean((residual - exact) ** 2)) < 2e-4
    assert np.max(np.abs(residual - exact)) < 1e-3
    assert np.all(gap >= exact_gap - 1e-12)   # never nearer than the exact nearest point


def test_grid_finds_nothing_beyond_reach():
    points, _ = _sphere_model()
    grid = NearestPointGrid(points, VOXEL / 3, 0.1)
    far = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.7 + 0.2], [5.0, 0.0, 0.0]])   # centre, 0.2 m out, outside the grid
    gap, index = grid.query(far, distance_upper_bound=0.1)
    assert np.all(np.isinf(gap)) and np.all(index == len(points))


def test_cell_list_is_the_kd_tree_within_any_bound():
    # The cell list (perception.nearest_grid.CellList, the scan-to-map track's map index) searches
    # shells of cells until no point outside them can be nearer: the same nearest point and distance
    # as scipy's exact KD-tree for every bound (ties aside: random points have none), whether the
    # query is near the surface (2 cm noise), far off it, or outside the grid.
    points, _ = _sphere_model()
    cells = CellList(points, 0.1 / 3, 0.1)
    tree = cKDTree(points)
    rng = np.random.default_rng(2)
    near = points[rng.choice(len(points), 2000)] + rng.normal(0.0, 0.02, (2000, 3))
    far = rng.uniform(-1.2, 1.2, (500, 3))
    for queries in (near, far):
        for bound in (0.1 / 3, 0.05, 0.1, 0.3):
            gap, index = cells.query(queries, distance_upper_bound=bound)
            exact_gap, exact_index = tree.query(queries, distance_upper_bound=bound)
            assert np.array_equal(index, exact_index), bound
            assert np.array_equal(gap, exact_gap), bound


def test_kept_look_up_is_the_kd_tree_while_points_creep():
    # nearest_in_cells_kept (the compiled scan-to-map ICP's look-up) looks a point up again only once it
    # has moved past its safe radius (half the gap between its nearest and its second nearest, or the
    # searched block): the answer must be the exact nearest within the bound at every step. Points near
    # the surface (2 cm noise) and off it creep in small random steps (0.1-3 mm, an ICP's iterations)
    # and jump once (5 cm, a new level's start); compared with scipy's exact KD-tree at every step.
    from perception.nearest_grid import nearest_in_cells_kept
    points, _ = _sphere_model()
    cells = CellList(points, 0.1 / 3, 0.1)
    tree = cKDTree(points)
    rng = np.random.default_rng(3)
    queries = np.vstack([points[rng.choice(len(points), 1500)] + rng.normal(0.0, 0.02, (1500, 3)),
                         rng.uniform(-1.0, 1.0, (300, 3))])
    n = len(queries)
    for bound in (0.1 / 3, 0.1):
        shells = int(np.ceil(bound / cells.cell))
        kept_points, kept_index, kept_safe = np.zeros((n, 3)), np.full(n, -1, np.int64), np.full(n, -1.0)
        gap, index = np.empty(n), np.empty(n, np.int64)
        moving = queries.copy()
        looked_up = []
        for step in range(12):
            size = 0.05 if step == 6 else (1e-4 if step < 6 else 3e-3)
            moving = moving + rng.normal(0.0, size / np.sqrt(3), (n, 3))
            before = kept_points.copy()
            nearest_in_cells_kept(moving, cells.low, cells.cell, cells.shape, cells.starts, cells.sorted_points,
                                  bound, shells, kept_points, kept_index, kept_safe, gap, index)
            looked_up.append(np.mean(np.any(kept_points != before, axis=1)))
            exact_gap, exact_index = tree.query(moving, distance_upper_bound=bound)
            found = index < len(points)
            answer = np.where(found, cells.order[np.minimum(index, len(points) - 1)], len(points))
            assert np.array_equal(answer, exact_index), (bound, step)
            assert np.allclose(gap, exact_gap, rtol=0, atol=1e-12) and np.array_equal(np.isinf(gap), np.isinf(exact_gap))
        # the point of it: after 0.1 mm steps (the fine level's late iterations) most points need no new
        # look-up (this model's samples are 1.2 cm apart, so the safe radii are a few mm)
        assert np.median(looked_up[1:6]) < 0.5
