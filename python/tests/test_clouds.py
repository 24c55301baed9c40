"""Cloud functions on analytic surfaces: normals, principal curvatures, grids, orientation."""

import numpy as np
import pytest

import pcl_ddg
from conftest import icosphere, shared_data


def sphere_cloud(n=20000, radius=2.0, seed=0):
    rng = np.random.default_rng(seed)
    p = rng.standard_normal((n, 3))
    return radius * p / np.linalg.norm(p, axis=1, keepdims=True)


def test_pca_normals_of_a_sphere_are_radial_and_face_the_viewpoint():
    points = sphere_cloud()
    r = pcl_ddg.estimate_normals(points, method="pca", k=16)
    assert r.valid.all() and r.normals.shape == points.shape
    radial = points / 2.0
    # Viewpoint at the origin (PCL's default): the normals point inwards.
    assert np.max(1.0 + np.einsum("ij,ij->i", r.normals, radial)) < 2e-3
    # Without a reference the tree is seeded up at the highest point: outwards everywhere.
    out = pcl_ddg.estimate_normals(points, k=16, orient="mst")
    assert np.all(np.einsum("ij,ij->i", out.normals, radial) > 0.99)
    assert np.all(r.curvature >= 0) and np.all(r.curvature < 0.05)


def test_quadric_principal_curvatures_of_a_sphere():
    points = sphere_cloud(30000, radius=2.0, seed=1)
    c = pcl_ddg.principal_curvatures(points, k=20, orient="mst")
    assert c.valid.mean() > 0.99
    # Outward normals: the sphere bends away from them, k1 = k2 = 1/R > 0.
    assert np.median(c.k1[c.valid]) == pytest.approx(0.5, rel=0.02)
    assert np.median(c.k2[c.valid]) == pytest.approx(0.5, rel=0.02)
    inward = pcl_ddg.principal_curvatures(points, k=20)  # facing the viewpoint at the centre
    assert np.median(inward.k1[inward.valid]) == pytest.approx(-0.5, rel=0.02)
    assert np.all(c.k1[c.valid] >= c.k2[c.valid])
    assert np.allclose(np.linalg.norm(c.direction1[c.valid], axis=1), 1.0, atol=1e-6)


def test_mesh_neighbourhoods_with_faces():
    V, F = icosphere(4, 1.0)
    r = pcl_ddg.estimate_normals(V, faces=F)  # mesh rings, oriented like the faces (outward)
    assert r.valid.all()
    assert np.min(np.einsum("ij,ij->i", r.normals, V)) > 0.999
    q = pcl_ddg.estimate_normals(V, method="quadric", faces=F, neighbours="kdtree")
    assert np.min(np.einsum("ij,ij->i", q.normals, V)) > 0.999
    assert not np.array_equal(r.normals, pcl_ddg.estimate_normals(V, faces=F, neighbours="kdtree").normals)
    # The former spellings: bfs for rings, knn for kdtree.
    for old, new in (("bfs", "rings"), ("knn", "kdtree")):
        before = pcl_ddg.estimate_normals(V, faces=F, neighbours=old)
        assert np.array_equal(before.normals, pcl_ddg.estimate_normals(V, faces=F, neighbours=new).normals)


def test_grid_normals_of_a_tilted_plane_keep_the_grid():
    h, w = 60, 80
    y, x = np.mgrid[0:h, 0:w].astype(float) * 0.01
    z = 2.0 + 0.5 * x + 0.25 * y
    xyz = np.stack([x - 0.4, y - 0.3, z], axis=-1)
    xyz[10, 10] = np.nan  # a hole stays a hole
    r = pcl_ddg.grid_normals(xyz)
    assert r.normals.shape == (h, w, 3) and r.valid.shape == (h, w)
    assert not r.valid[10, 10] and np.isnan(r.normals[10, 10]).all()
    exact = np.array([-0.5, -0.25, 1.0]) / np.linalg.norm([-0.5, -0.25, 1.0])
    good = r.normals[r.valid]
    # Facing the sensor at the origin (the plane lies at z ~ 2): n . exact = -1.
    assert np.max(np.abs(np.abs(good @ exact) - 1.0)) < 1e-5
    assert np.all(good @ exact < 0)


def test_nan_points_are_invalid_rows():
    points = sphere_cloud(2000)
    points[5] = np.nan
    r = pcl_ddg.estimate_normals(points)
    assert r.normals.shape == points.shape
    assert not r.valid[5] and np.isnan(r.normals[5]).all() and r.valid.sum() == 1999


def test_orient_normals_only_changes_signs():
    points = sphere_cloud(5000)
    exact = points / 2.0
    rng = np.random.default_rng(3)
    signs = rng.choice([-1.0, 1.0], size=(points.shape[0], 1))
    normals = exact * signs
    for method, kwargs, expected_sign in (("viewpoint", {"viewpoint": [0, 0, 0]}, -1.0),
                                          ("mst", {"viewpoint": [0, 0, 0]}, -1.0)):
        out = pcl_ddg.orient_normals(points, normals, method=method, **kwargs)
        assert np.array_equal(np.abs(out.normals), np.abs(normals))
        assert np.all(np.sign(np.einsum("ij,ij->i", out.normals, exact)) == expected_sign)
    up = pcl_ddg.orient_normals(points, normals, method="up")
    assert np.all(up.normals[:, 2] >= 0)


def _plate(n: int, z: float, seed: int, flip: bool):
    """A jittered n x n grid over [-1, 1]^2 at height z (jitter in the plane: flat exactly),
    two triangles per cell, wound towards +z (or -z when flip)."""
    h = 2.0 / n
    u, v = np.meshgrid(np.linspace(-1, 1, n + 1), np.linspace(-1, 1, n + 1), indexing="ij")
    xy = np.stack([u.ravel(), v.ravel()], axis=1)
    xy += np.random.default_rng(seed).uniform(-0.1 * h, 0.1 * h, xy.shape)
    V = np.column_stack([xy, np.full(len(xy), z)])
    index = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b = index[:-1, :-1].ravel(), index[1:, :-1].ravel()
    c, d = index[1:, 1:].ravel(), index[:-1, 1:].ravel()
    F = np.concatenate([np.stack([a, b, c], 1), np.stack([a, c, d], 1)])
    return V, (F[:, [0, 2, 1]] if flip else F)


def test_compare_neighbourhoods_on_two_close_sheets_against_brute_force():
    # Two flat plates 1.5 h apart (h = 1/12). Mesh rings stay on their plate, whose points are
    # coplanar: their PCA normal is the plate's, +-z, exactly. So the angle difference at a vertex
    # is the angle of the k-nearest PCA normal to z, computed here by brute force (numpy's eigh of
    # the covariance of the 16 nearest, the vertex included), and on average it is large: the
    # kd-tree's neighbourhoods reach the other plate.
    n, k = 24, 16
    top, top_faces = _plate(n, 0.0, 1, flip=False)
    bottom, bottom_faces = _plate(n, -1.5 * 2.0 / n, 2, flip=True)
    V = np.vstack([top, bottom])
    F = np.vstack([top_faces, bottom_faces + len(top)])
    c = pcl_ddg.compare_neighbourhoods(V, F, k=k)
    assert c.angle_difference.shape == (len(V),) and c.overlap.shape == (len(V),)
    assert np.isfinite(c.angle_difference).all()
    P = V.astype(np.float32).astype(np.float64)  # the coordinates the estimator fits (float)
    d2 = ((P[:, None, :] - P[None, :, :]) ** 2).sum(axis=2)
    order = np.argsort(d2, axis=1, kind="stable")
    expected = np.empty(len(V))
    same_plate = np.empty(len(V))
    for i in range(len(V)):
        nearest = order[i, :k]
        centred = P[nearest] - P[nearest].mean(axis=0)
        normal = np.linalg.eigh(centred.T @ centred)[1][:, 0]
        expected[i] = np.degrees(np.arccos(min(abs(normal[2]), 1.0)))
        # the ring side's neighbours: the same plate; the kd-tree's: how many from it
        same_plate[i] = np.mean((nearest < len(top)) == (i < len(top)))
    np.testing.assert_allclose(c.angle_difference, expected, rtol=0, atol=1e-3)
    assert expected.mean() > 15.0
    assert np.all(c.overlap <= same_plate + 1e-12)  # what the kd-tree took from the other plate
    # The summary is of the arrays.
    s = c.summary
    assert s["compared"] == len(V)
    assert s["mean"] == pytest.approx(expected.mean(), abs=1e-3)
    assert s["max"] == pytest.approx(expected.max(), abs=1e-3)
    assert s["share_over_30"] == pytest.approx(np.mean(c.angle_difference > 30.0))
    assert s["mean_overlap"] == pytest.approx(c.overlap.mean())


def test_compare_neighbourhoods_on_a_mesh():
    V, F = icosphere(3)
    c = pcl_ddg.compare_neighbourhoods(V, F, k=12)
    assert c.angle_difference.shape == (V.shape[0],)
    assert c.summary["compared"] == V.shape[0]
    assert np.all((c.overlap >= 0) & (c.overlap <= 1))
    assert c.summary["mean"] == pytest.approx(c.angle_difference.mean())


def _survey_scene(seed: int = 5) -> np.ndarray:
    """A sphere of radius 20 beside a jittered 60 x 60 height field, on a 2^-16 grid so that
    moving it by a survey's offset is exact in float64."""
    rng = np.random.default_rng(seed)
    d = rng.normal(size=(4000, 3))
    sphere = np.array([150.0, 0.0, 0.0]) + 20.0 * d / np.linalg.norm(d, axis=1)[:, None]
    u, v = np.meshgrid(np.arange(60.0) - 30.0, np.arange(60.0) - 30.0)
    x = u.ravel() + rng.uniform(-0.3, 0.3, u.size)
    y = v.ravel() + rng.uniform(-0.3, 0.3, v.size)
    field = np.stack([x, y, 2.0 * np.sin(x / 7.0) * np.cos(y / 5.0)], axis=1)
    return np.round(np.concatenate([sphere, field]) * 65536.0) / 65536.0


@pytest.mark.parametrize("method", ["pca", "quadric", "robust"])
def test_float64_points_far_away_give_the_normals_at_the_origin(method):
    # Fitted about their local origin in double (as the tools fit a file): 5e6 away, the float32
    # points would step by 0.5 and the height field's normals be off by tens of degrees.
    near = _survey_scene()
    far = near + np.array([5e5, 5e6, 200.0])
    assert np.array_equal(far - np.array([5e5, 5e6, 200.0]), near)
    a = pcl_ddg.estimate_normals(near, method=method, orient="up").normals
    b = pcl_ddg.estimate_normals(far, method=method, orient="up").normals
    # atan2 of the cross and dot products: exact near 0, where arccos of a float dot is not.
    angle = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.abs(np.sum(a * b, axis=1)))
    # Two frames' float searches may order a near tie of distances either way: a few points.
    assert np.count_nonzero(angle > 1e-6) <= len(near) // 500, np.sort(angle)[-10:]
    rounded = pcl_ddg.estimate_normals(far.astype(np.float32), method=method, orient="up").normals
    off = np.arctan2(np.linalg.norm(np.cross(a, rounded), axis=1),
                     np.abs(np.sum(a * rounded, axis=1)))
    assert np.degrees(off.max()) > 5.0  # float32 input keeps its floats: they are its truth


def test_principal_curvatures_far_away_equal_those_at_the_origin():
    near = _survey_scene()
    a = pcl_ddg.principal_curvatures(near, orient="up")
    b = pcl_ddg.principal_curvatures(near + np.array([5e5, 5e6, 200.0]), orient="up")
    same = np.isclose(a.k1, b.k1, rtol=1e-9, atol=1e-12) & np.isclose(a.k2, b.k2, rtol=1e-9,
                                                                        atol=1e-12)
    assert np.count_nonzero(~same) <= len(near) // 500


def test_a_las_file_read_is_oriented_up_by_default():
    las = shared_data() / "las" / "autzen_trim.las"
    f = pcl_ddg.read(las)
    normals = pcl_ddg.estimate_normals(f).normals
    assert np.nanmin(normals[:, 2]) >= 0.0
    assert np.array_equal(normals, pcl_ddg.estimate_normals(f.points, orient="up").normals,
                          equal_nan=True)
    # A viewpoint given chooses otherwise, as the tool's -viewpoint does.
    below = f.points.mean(axis=0) - np.array([0.0, 0.0, 1e4])
    down = pcl_ddg.estimate_normals(f, viewpoint=below).normals
    assert np.nanmean(down[:, 2] < 0) > 0.9
