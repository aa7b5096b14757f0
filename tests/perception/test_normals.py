"""Surface normals by local PCA (perception/normals.py) against the analytic normals of a sphere
and against Open3D's estimate_normals, which they replace in the scan-to-map map."""
import numpy as np
import open3d as o3d
import trimesh
from scipy.spatial.transform import Rotation

from perception.normals import surface_normals, surface_planes
from perception.scan_to_map import voxel_means

VOXEL = 0.03   # m, the perception cases' map spacing


def test_sphere_normals_are_radial():
    # Noise-free samples of a 0.7 m sphere, ~4 cm apart. The PCA plane of a patch of a sphere is
    # perpendicular to the radius through the patch's centroid, not through the point: with the
    # centroid up to about half a sample spacing (2 cm) off the point the normal tilts by up to
    # 0.02 / 0.7 rad = 1.6 deg (measured 1.9 deg worst); a symmetric patch gives the radial normal.
    points, _ = trimesh.sample.sample_surface_even(trimesh.creation.icosphere(5, 0.7), 4000, seed=0)
    normals = surface_normals(points, 4 * VOXEL, 30)
    radial = points / np.linalg.norm(points, axis=1, keepdims=True)
    cosine = np.abs(np.einsum("ij,ij->i", normals, radial))
    np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, atol=1e-12)
    angle = np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))
    assert angle.max() < 3.0
    assert np.median(angle) < 0.5


def test_same_normals_as_open3d():
    # Open3D's estimate_normals with KDTreeSearchParamHybrid(radius, max_nn): the same neighbours (the
    # max_nn nearest within radius) and the same PCA, so the same normals up to sign and round-off.
    rng = np.random.default_rng(0)
    points = trimesh.sample.sample_surface(trimesh.creation.box([1.2, 3.0, 1.6]), 20000, seed=1)[0]
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points + rng.normal(0.0, 0.01, points.shape)))
    cloud = cloud.voxel_down_sample(VOXEL)
    cloud.estimate_normals(o3d.geometry.KDTreeSearchParamHybrid(radius=4 * VOXEL, max_nn=30))
    ours = surface_normals(np.asarray(cloud.points), 4 * VOXEL, 30)
    cosine = np.abs(np.einsum("ij,ij->i", ours, np.asarray(cloud.normals)))
    assert np.mean(cosine > 1 - 1e-9) > 0.999   # ties among equal distances may pick another neighbour
    assert cosine.min() > np.cos(np.radians(1.0))


def test_normals_filled_on_the_icp_index_as_they_are_matched():
    # The scan-to-map track computes a map point's normal only when a scan point is first matched to it,
    # on the ICP's cell list (cells of 1/3 of the correspondence distance, not of the normal radius):
    # the neighbour search goes shell by shell until the 30 nearest are inside, so the same neighbours
    # and the same normals as surface_normals, whatever the cells and in whatever order they are asked.
    # The same for the points projected on their fitted planes (fill_planes, what the ICP's residuals use).
    from perception.nearest_grid import CellList
    from perception.normals import fill_planes
    rng = np.random.default_rng(1)
    points = trimesh.sample.sample_surface(trimesh.creation.box([1.2, 3.0, 1.6]), 20000, seed=2)[0]
    cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points + rng.normal(0.0, 0.01, points.shape)))
    points = np.asarray(cloud.voxel_down_sample(VOXEL).points)
    views = points / np.linalg.norm(points, axis=1, keepdims=True)   # seen from outside the box (own-side planes)
    full_planes, full = surface_planes(points, 4 * VOXEL, 30, views)
    cells = CellList(points, 0.1 / 3, 0.1)
    normals, planes, known = np.empty_like(points), np.empty_like(points), np.zeros(len(points), np.bool_)
    for batch in np.array_split(rng.permutation(len(points) + 50), 5):   # rows >= n: unmatched, skipped
        fill_planes(batch, cells.sorted_points, cells.low, cells.cell, cells.shape, cells.starts, cells.largest_cell,
                    4 * VOXEL, 30, normals, planes, known, np.ascontiguousarray(views[cells.order]))
    assert known.all()
    cosine = np.abs(np.einsum("ij,ij->i", normals, full[cells.order]))
    assert cosine.min() > 1 - 1e-9   # same neighbours; the sums' order differs by round-off only
    np.testing.assert_allclose(planes, full_planes[cells.order], atol=1e-12)


def test_points_on_a_plane_stay_where_they_are():
    # Exactly planar points (a noise-free face): every fitted plane is the face, so the projection moves
    # no point (round-off only) and the normals are the face's.
    rng = np.random.default_rng(4)
    points = np.c_[rng.uniform(-0.5, 0.5, (3000, 2)), np.zeros(3000)]
    planes, normals = surface_planes(points, 4 * VOXEL, 30)
    np.testing.assert_allclose(planes, points, atol=1e-12)
    np.testing.assert_allclose(np.abs(normals[:, 2]), 1.0, atol=1e-12)


def test_voxel_means_of_noisy_returns_are_pulled_back_onto_the_surface():
    # A 1 x 1 m face (z = 0) seen with 1 cm noise along its normal (the order of a thinned scan point's
    # noise: 2 cm range noise averaged over the ~3-4 returns of a 3 cm voxel at 10 m), thinned to 3 cm voxel
    # means as the scan-to-map map is. With noise comparable to the voxel, the means do not average it away
    # across the surface: the points split between voxel layers and a layer's mean sits on its side (a voxel
    # straddling the face catches only its side of the noise), so the means are MORE spread than one
    # return (measured 1.57 cm rms against the 1 cm noise; the map is a slab, not a surface). The plane
    # fitted to a mean's 30 nearest goes through their mean, which averages the layers: the projections
    # are within 0.35 cm rms of the face (measured, seed 0; 1/sqrt(30) of the slab's 1.57 cm would be 0.29 cm,
    # the rest is the neighbourhood's layer imbalance). Bounds: the means above the 1 cm noise, the
    # projections below half of it. Points within 12 cm (the normal radius) of the edges are left out.
    rng = np.random.default_rng(0)
    returns = np.c_[rng.uniform(-0.5, 0.5, (200000, 2)), 0.01 * rng.standard_normal(200000)]
    means = np.asarray(o3d.geometry.PointCloud(o3d.utility.Vector3dVector(returns)).voxel_down_sample(VOXEL).points)
    planes, _ = surface_planes(means, 4 * VOXEL, 30)
    inner = np.all(np.abs(means[:, :2]) < 0.5 - 4 * VOXEL, axis=1)
    assert np.sqrt(np.mean(means[inner, 2] ** 2)) > 0.01
    assert np.sqrt(np.mean(planes[inner, 2] ** 2)) < 0.01 / 2


def test_the_two_faces_of_a_thin_plate_stay_apart_with_their_own_side():
    # A 1 x 1 m plate 5 cm thick (the featured debris' solar array), each face seen from its own side with
    # 1 cm noise along the normal (a thinned scan point's, as above), at a random attitude to the 3 cm voxel
    # grid, thinned to voxel means that carry the mean direction towards the sensor (perception.scan_to_map.
    # voxel_means). The 12 cm neighbourhood of a face point reaches the far face 5 cm away, and the plane
    # through all 30 nearest pulls each face towards the mid-plane (measured, rotations 0-4: 3.9-4.6 mm inward
    # on average, 7.8-8.3 mm rms about the face). Fitted to the neighbours seen from the point's side
    # (fill_planes' own-side rule) the faces stay apart: 3.4-4.2 mm outward on average, which is the voxel means'
    # own bias (raw means 4.1-4.3 mm outward: a voxel straddling the gap holds both faces' inner tails and counts
    # once, on one side), and 4.1-5.5 mm rms about the face. Bounds: own side rms below 6 mm and below
    # three quarters of the all-neighbours rms; mean offset within 5 mm of the raw means' (the projection adds no
    # bias of its own); all neighbours pulled inward by more than 2 mm (the defect the rule removes).
    # Points within 12 cm of the plate's edges left out.
    rotation = Rotation.random(random_state=0).as_matrix()
    rng = np.random.default_rng(0)
    n = 100000
    faces = [np.c_[rng.uniform(-0.5, 0.5, (n, 2)), side * 0.025 + 0.01 * rng.standard_normal(n)] for side in (1, -1)]
    views = np.r_[np.tile([0.0, 0.0, 1.0], (n, 1)), np.tile([0.0, 0.0, -1.0], (n, 1))]
    means, mean_views = voxel_means(np.vstack(faces) @ rotation.T, VOXEL, views @ rotation.T)
    local = means @ rotation
    side = np.sign((mean_views @ rotation)[:, 2])
    inner = np.all(np.abs(local[:, :2]) < 0.5 - 4 * VOXEL, axis=1)

    def outward(points):   # offset from the face of the side the point was seen from (m), outward positive
        return (side * (points @ rotation)[:, 2] - 0.025)[inner]

    raw = outward(means)
    every = outward(surface_planes(means, 4 * VOXEL, 30)[0])
    own = outward(surface_planes(means, 4 * VOXEL, 30, mean_views)[0])
    rms = lambda offsets: np.sqrt(np.mean(offsets ** 2))   # noqa: E731
    assert every.mean() < -0.002
    assert rms(own) < 0.006 and rms(own) < 0.75 * rms(every)
    assert abs(own.mean() - raw.mean()) < 0.005
