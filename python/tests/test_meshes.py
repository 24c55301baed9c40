"""Mesh functions against exact values on analytic surfaces and against identities."""

import numpy as np
import pytest
from scipy import sparse

import pcl_ddg
from conftest import icosphere, random_mesh


def cotan_laplacian(V, F):
    """The summed cotangent Laplacian assembled triangle by triangle with scipy: for each corner,
    half its cotangent on the opposite edge, symmetric, diagonal minus the row sums."""
    rows, cols, vals = [], [], []
    for tri in F:
        for k in range(3):
            i, j, o = tri[(k + 1) % 3], tri[(k + 2) % 3], tri[k]
            e1, e2 = V[i] - V[o], V[j] - V[o]
            cot = np.dot(e1, e2) / np.linalg.norm(np.cross(e1, e2))
            rows += [i, j]
            cols += [j, i]
            vals += [0.5 * cot, 0.5 * cot]
    n = V.shape[0]
    L = sparse.coo_matrix((vals, (rows, cols)), shape=(n, n)).tocsr()
    return (L - sparse.diags(np.asarray(L.sum(axis=1)).ravel())).tocsr()


def triangle_areas(V, F):
    return 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)


def test_sphere_normals_are_radial():
    R = 3.0
    V, F = icosphere(4, R)
    for weighting in ("area", "uniform", "angle", "mean_curvature"):
        n = pcl_ddg.vertex_normals(V, F, weights=weighting)
        assert n.valid.all()
        assert np.allclose(np.linalg.norm(n.normals, axis=1), 1.0, atol=1e-14)
        # Symmetric 1-rings give the radial direction to rounding, the others to O(h^2).
        assert np.max(1.0 - np.einsum("ij,ij->i", n.normals, V / R)) < 1e-4, weighting


def test_sphere_curvatures_converge_at_order_two():
    # test_curvature.cpp: unit icosphere, mixed areas: H and K errors fall at order 2 (+- 0.25),
    # max |K - 1| < 9e-5 at level 6. Level 5 here: the same order, four times that bound.
    errors = []
    for level in (3, 4, 5):
        R = 2.0
        V, F = icosphere(level, R)
        c = pcl_ddg.curvatures(V, F)
        assert c.valid.all()
        k_error = np.max(np.abs(c.gauss * R * R - 1.0))
        h_error = np.max(np.abs(c.mean * R - 1.0))
        assert np.all(c.k1 >= c.k2)
        errors.append((k_error, h_error))
    for (k0, h0), (k1, h1) in zip(errors, errors[1:]):
        assert abs(np.log2(k0 / k1) - 2.0) < 0.25
        assert abs(np.log2(h0 / h1) - 2.0) < 0.25
    assert errors[-1][0] < 4 * 9e-5
    V, F = icosphere(5, 2.0)
    c = pcl_ddg.curvatures(V, F)
    # Gauss-Bonnet on a sphere: the integrated K is 4 pi (chi = 2) to rounding.
    assert abs(np.sum(c.gauss * c.area) - 4 * np.pi) < 1e-9


def test_laplacian_equals_scipy_cotan_matrix_on_a_random_mesh():
    V, F = random_mesh(400)
    L = pcl_ddg.laplacian(V, F)
    assert isinstance(L, sparse.csr_matrix)
    reference = cotan_laplacian(V, F)
    difference = abs(L - reference).max()
    assert difference <= 1e-14 * abs(reference).max()
    assert np.max(np.abs(L @ np.ones(V.shape[0]))) < 1e-12 * abs(reference).max()
    assert abs(L - L.T).max() == 0.0
    # Negative semi-definite: x^T L x <= 0.
    x = np.random.default_rng(0).normal(size=V.shape[0])
    assert x @ (L @ x) <= 0.0


def test_laplacian_forms_and_uniform_weights():
    V, F = random_mesh(225, seed=3)
    L = pcl_ddg.laplacian(V, F, weights="cotan", form="summed")
    M = pcl_ddg.mass_matrix(V, F)
    A = pcl_ddg.laplacian(V, F, form="averaged")
    assert abs(A - sparse.diags(1.0 / M.diagonal()) @ L).max() < 1e-12 * abs(A).max()
    U = pcl_ddg.laplacian(V, F, weights="uniform")
    off = U - sparse.diags(U.diagonal())
    assert set(np.unique(off.data)) == {1.0}
    assert np.array_equal(-U.diagonal(), np.asarray(off.sum(axis=1)).ravel())


def test_mass_sums_to_the_area():
    V, F = random_mesh(400, seed=5)
    area = triangle_areas(V, F).sum()
    for kind in ("mixed", "voronoi", "barycentric"):
        M = pcl_ddg.mass_matrix(V, F, mass=kind)
        assert isinstance(M, sparse.csr_matrix)
        assert abs(M.sum() - area) < 1e-12 * area, kind
    assert (pcl_ddg.mass_matrix(V, F, mass="mixed").diagonal() >= 0).all()


def test_polygon_lists_are_fan_triangulated():
    # A unit square as one quad, as a list and as an (m, 4) array: two triangles' worth of area.
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], float)
    for F in ([[0, 1, 2, 3]], np.array([[0, 1, 2, 3]]), [np.array([0, 1, 2, 3])]):
        assert pcl_ddg.mass_matrix(V, F).sum() == pytest.approx(1.0, abs=1e-15)
    report = pcl_ddg.mesh_report(V, [[0, 1, 2, 3]])
    assert report["triangulated_faces"] == 1 and report["triangles"] == 2


def test_mesh_report_counts_defects_instead_of_refusing():
    V, F = icosphere(2)
    report = pcl_ddg.mesh_report(V, F)
    assert report["euler_characteristic"] == 2 and report["genus"] == 0
    bad = np.vstack([F, [[0, 1, 10_000]]])
    report = pcl_ddg.mesh_report(V, bad)
    assert report["out_of_range_faces"] == 1


def test_smoothing_shrinks_a_sphere_and_keeps_volume_when_asked():
    V, F = icosphere(3, 1.0)
    rng = np.random.default_rng(2)
    noisy = V * (1.0 + 0.01 * rng.standard_normal((V.shape[0], 1)))
    smoothed = pcl_ddg.smooth(noisy, F, lambda_dt=1.0)
    assert smoothed.shape == V.shape and smoothed.dtype == np.float64
    r = np.linalg.norm(smoothed, axis=1)
    assert r.std() < np.linalg.norm(noisy, axis=1).std()
    kept = pcl_ddg.smooth(noisy, F, lambda_dt=1.0, preserve="volume", iterations=3)
    assert np.linalg.norm(kept, axis=1).mean() == pytest.approx(
        np.linalg.norm(noisy, axis=1).mean(), rel=2e-3)
    explicit = pcl_ddg.smooth(noisy, F, method="explicit", iterations=5)
    assert np.isfinite(explicit).all()
    with pytest.raises(ValueError, match="stability bound"):
        pcl_ddg.smooth(noisy, F, method="explicit", lambda_dt=100.0)


def test_heat_flow_conserves_the_mass_weighted_sum():
    V, F = icosphere(3)
    rng = np.random.default_rng(4)
    values = rng.standard_normal((V.shape[0], 2))
    smoothed = pcl_ddg.smooth_field(V, F, values, time=2.0)
    m = pcl_ddg.mass_matrix(V, F).diagonal()
    assert smoothed.shape == values.shape
    assert np.allclose(m @ smoothed, m @ values, rtol=1e-9, atol=1e-12)
    assert smoothed.std(axis=0).max() < values.std(axis=0).min()
    one = pcl_ddg.smooth_field(V, F, values[:, 0], time=2.0)
    assert one.shape == (V.shape[0],)
    np.testing.assert_array_equal(one, smoothed[:, 0])


def test_invalid_vertices_are_nan_rows_not_dropped():
    V, F = icosphere(1)
    V = np.vstack([V, [[5.0, 5.0, 5.0]]])  # an isolated vertex
    n = pcl_ddg.vertex_normals(V, F)
    assert n.normals.shape == V.shape
    assert not n.valid[-1] and np.isnan(n.normals[-1]).all() and n.valid[:-1].all()
    c = pcl_ddg.curvatures(V, F)
    assert np.isnan(c.mean[-1]) and not c.valid[-1]


def test_a_mesh_without_faces_gives_nan_rows():
    V, _ = icosphere(1)
    c = pcl_ddg.curvatures(V, np.zeros((0, 3), dtype=np.int32))
    assert c.mean.shape == (V.shape[0],) and not c.valid.any()


def test_one_keyword_per_concept_and_the_former_names_still_work_with_a_warning():
    import warnings

    V, F = icosphere(1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the current names warn about nothing
        area = pcl_ddg.vertex_normals(V, F, weights="angle").normals
        mixed = pcl_ddg.mass_matrix(V, F, mass="voronoi").diagonal()
    with pytest.warns(DeprecationWarning, match="weighting= is deprecated: use weights="):
        old = pcl_ddg.vertex_normals(V, F, weighting="angle").normals
    np.testing.assert_array_equal(old, area)
    with pytest.warns(DeprecationWarning, match="kind= is deprecated: use mass="):
        old = pcl_ddg.mass_matrix(V, F, kind="voronoi").diagonal()
    np.testing.assert_array_equal(old, mixed)
    with pytest.raises(ValueError, match="give mass= only"), pytest.warns(DeprecationWarning):
        pcl_ddg.mass_matrix(V, F, mass="barycentric", kind="voronoi")


class _TriangleVector:
    """Open3D's mesh.triangles: no ndarray, but the buffer protocol (as Vector3iVector)."""

    def __init__(self, F):
        self._array = np.ascontiguousarray(F, dtype=np.int32)

    def __buffer__(self, flags):  # Python 3.12
        return memoryview(self._array)

    def __array__(self, dtype=None):
        return self._array if dtype is None else self._array.astype(dtype)


def test_faces_as_an_array_like_such_as_open3d_triangles():
    V, F = icosphere(1)
    expected = pcl_ddg.vertex_normals(V, F).normals
    for faces in (_TriangleVector(F), memoryview(np.ascontiguousarray(F, dtype=np.int32))):
        np.testing.assert_array_equal(pcl_ddg.vertex_normals(V, faces).normals, expected)
        np.testing.assert_array_equal(pcl_ddg.curvatures(V, faces).mean,
                                      pcl_ddg.curvatures(V, F).mean)
