"""Every option of the mesh and cloud functions checked for its effect, against oracles written
here with NumPy and SciPy from the formulas the docstrings and docs/library.md give (masses per
triangle corner, the cotangent and uniform Laplacians, backward and forward Euler, the heat
equation with a fixed boundary, PCA of the nearest neighbours), never against the module itself:

* mass kinds (``mass_matrix``, ``curvatures``, ``laplacian(form="averaged")``, ``smooth_field``),
  Laplacian weights, ``absolute_time``, ``fix_boundary``, ``method`` and ``iterations`` of
  ``smooth_field``;
* ``smooth``'s ``fix_boundary``, ``allow_unstable``, ``preserve``, ``absolute_time``, ``solver``,
  ``update_mass`` and ``rebuild_weights``;
* ``estimate_normals``' radius search default ``max_nn`` (64), ``orient`` and ``up``;
* the array conversions: big-endian, Fortran-ordered and strided inputs give the same bits."""

import numpy as np
import pytest
from scipy import sparse
from scipy.sparse import linalg

import pcl_ddg
from conftest import icosphere, random_mesh

# --- oracles ------------------------------------------------------------------------------------


def triangle_geometry(V, F):
    """Per triangle: area and, per corner k, the angle's cotangent and the squared lengths of the
    two edges at it (corner order as in F)."""
    P = [V[F[:, k]] for k in range(3)]
    area = 0.5 * np.linalg.norm(np.cross(P[1] - P[0], P[2] - P[0]), axis=1)
    cot = np.empty((len(F), 3))
    for k in range(3):
        a, b = P[(k + 1) % 3] - P[k], P[(k + 2) % 3] - P[k]
        cot[:, k] = np.einsum("ij,ij->i", a, b) / np.linalg.norm(np.cross(a, b), axis=1)
    return P, area, cot


def corner_masses(V, F, kind):
    """(m, 3) corner areas: barycentric a third; Voronoi (|e_ij|^2 cot k + |e_ik|^2 cot j) / 8
    (Meyer et al. 2003); mixed: Voronoi on non-obtuse triangles, else half the area to the obtuse
    corner and a quarter to the others."""
    P, area, cot = triangle_geometry(V, F)
    if kind == "barycentric":
        return np.repeat(area[:, None] / 3.0, 3, axis=1)
    voronoi = np.empty((len(F), 3))
    for k in range(3):
        j, l = (k + 1) % 3, (k + 2) % 3
        voronoi[:, k] = (np.sum((P[j] - P[k]) ** 2, axis=1) * cot[:, l]
                         + np.sum((P[l] - P[k]) ** 2, axis=1) * cot[:, j]) / 8.0
    if kind == "voronoi":
        return voronoi
    obtuse = cot < 0.0
    mixed = np.where(obtuse, area[:, None] / 2.0, area[:, None] / 4.0)
    return np.where(obtuse.any(axis=1)[:, None], mixed, voronoi)


def lumped_mass(V, F, kind="mixed"):
    m = np.zeros(len(V))
    np.add.at(m, F.ravel(), corner_masses(V, F, kind).ravel())
    return m


def cotan_laplacian(V, F):
    """Summed: L_ij = (cot a + cot b) / 2 over the corners opposite edge ij, L_ii = -sum_j L_ij."""
    _, _, cot = triangle_geometry(V, F)
    rows, cols, vals = [], [], []
    for k in range(3):
        i, j = F[:, (k + 1) % 3], F[:, (k + 2) % 3]
        rows += [i, j]
        cols += [j, i]
        vals += [0.5 * cot[:, k], 0.5 * cot[:, k]]
    n = len(V)
    L = sparse.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                          shape=(n, n)).tocsr()
    return (L - sparse.diags(np.asarray(L.sum(axis=1)).ravel())).tocsr()


def edges_of(F):
    """Unique edges (smaller, larger) and how many triangles hold each."""
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    return np.unique(e, axis=0, return_counts=True)


def uniform_laplacian(V, F):
    edges, _ = edges_of(F)
    n = len(V)
    A = sparse.coo_matrix((np.ones(2 * len(edges)), (np.concatenate([edges[:, 0], edges[:, 1]]),
                                                     np.concatenate([edges[:, 1], edges[:, 0]]))),
                          shape=(n, n)).tocsr()
    return (A - sparse.diags(np.asarray(A.sum(axis=1)).ravel())).tocsr()


def boundary_vertices(F, n):
    edges, counts = edges_of(F)
    on = np.zeros(n, bool)
    on[edges[counts == 1].ravel()] = True
    return on


def mean_edge_length(V, F):
    edges, _ = edges_of(F)
    return np.linalg.norm(V[edges[:, 0]] - V[edges[:, 1]], axis=1).mean()


def backward_euler(L, m, values, tau, fixed=None):
    """(M - tau L) x' = M x; rows of fixed vertices keep their values (Dirichlet)."""
    values = np.asarray(values, float)
    out = values.copy()
    free = np.ones(len(m), bool) if fixed is None else ~fixed
    A = (sparse.diags(m) - tau * L).tocsr()
    rhs = m[:, None] * values.reshape(len(m), -1)
    rhs = rhs[free] - A[free][:, ~free] @ values.reshape(len(m), -1)[~free]
    solved = linalg.spsolve(A[free][:, free].tocsc(), rhs)
    out.reshape(len(m), -1)[free] = solved.reshape(int(free.sum()), -1)
    return out


def surface_area(V, F):
    return triangle_geometry(V, F)[1].sum()


def enclosed_volume(V, F):
    return np.einsum("ij,ij->i", V[F[:, 0]], np.cross(V[F[:, 1]], V[F[:, 2]])).sum() / 6.0


def max_relative(a, b):
    return np.max(np.abs(a - b)) / np.max(np.abs(b))


# --- masses, curvatures, Laplacian forms ----------------------------------------------------


@pytest.mark.parametrize("kind", ["mixed", "voronoi", "barycentric"])
def test_mass_kinds_are_their_closed_forms(kind):
    V, F = random_mesh(400, seed=7)  # jittered: obtuse triangles, so the kinds differ
    _, _, cot = triangle_geometry(V, F)
    assert np.any(cot < 0), "the mesh has obtuse triangles"
    expected = lumped_mass(V, F, kind)
    others = [lumped_mass(V, F, k) for k in ("mixed", "voronoi", "barycentric") if k != kind]
    assert all(max_relative(o, expected) > 1e-3 for o in others)  # the kinds are told apart
    got = pcl_ddg.mass_matrix(V, F, mass=kind).diagonal()
    assert max_relative(got, expected) < 1e-12
    # curvatures(mass=) reports that area, and K = angle defect / area with it
    c = pcl_ddg.curvatures(V, F, mass=kind)
    assert max_relative(c.area, expected) < 1e-12
    interior = ~boundary_vertices(F, len(V))
    P, _, _ = triangle_geometry(V, F)
    angle_sum = np.zeros(len(V))
    for k in range(3):
        a, b = P[(k + 1) % 3] - P[k], P[(k + 2) % 3] - P[k]
        cosine = np.einsum("ij,ij->i", a, b) / np.linalg.norm(a, axis=1) / np.linalg.norm(b, axis=1)
        np.add.at(angle_sum, F[:, k], np.arccos(np.clip(cosine, -1, 1)))
    defect = 2 * np.pi - angle_sum
    np.testing.assert_allclose((c.gauss * c.area)[interior], defect[interior], rtol=1e-9,
                               atol=1e-12)
    # the averaged Laplacian divides the summed cotangent one by that mass
    A = pcl_ddg.laplacian(V, F, form="averaged", mass=kind)
    reference = sparse.diags(1.0 / expected) @ cotan_laplacian(V, F)
    assert abs(A - reference).max() < 1e-11 * abs(reference).max()


# --- heat flow of fields --------------------------------------------------------------------


@pytest.mark.parametrize("weights,mass", [("cotan", "mixed"), ("uniform", "barycentric"),
                                          ("cotan", "voronoi")])
@pytest.mark.parametrize("absolute_time", [False, True])
@pytest.mark.parametrize("fix_boundary", [False, True])
def test_smooth_field_is_backward_euler_of_the_heat_equation(weights, mass, absolute_time,
                                                             fix_boundary):
    V, F = random_mesh(225, seed=11)  # open: a boundary to fix
    rng = np.random.default_rng(3)
    values = rng.standard_normal((len(V), 2))
    h = mean_edge_length(V, F)
    time = 0.05 if absolute_time else 2.0
    t = time if absolute_time else time * h * h
    L = cotan_laplacian(V, F) if weights == "cotan" else uniform_laplacian(V, F)
    m = lumped_mass(V, F, mass)
    fixed = boundary_vertices(F, len(V)) if fix_boundary else None
    expected = backward_euler(L, m, values, t, fixed)
    for iterations in (1, 3):
        got = pcl_ddg.smooth_field(V, F, values, time, weights=weights, mass=mass,
                                   iterations=iterations, absolute_time=absolute_time,
                                   fix_boundary=fix_boundary)
        want = expected
        if iterations > 1:  # each iteration a step of time / iterations
            want = values
            for _ in range(iterations):
                want = backward_euler(L, m, want, t / iterations, fixed)
        assert max_relative(got, want) < 1e-9, iterations
        if fix_boundary:
            assert np.array_equal(got[fixed], values[fixed])
    # the options change the result (the comparison compares something)
    assert max_relative(backward_euler(L, m, values, 2 * t, fixed), expected) > 1e-3


def test_smooth_field_explicit_is_forward_euler():
    V, F = random_mesh(225, seed=12)
    values = np.random.default_rng(5).standard_normal(len(V))
    L, m = cotan_laplacian(V, F), lumped_mass(V, F)
    t = 0.01
    got = pcl_ddg.smooth_field(V, F, values, t, method="explicit", absolute_time=True)
    expected = values + t * (L @ values) / m
    assert max_relative(got, expected) < 1e-12


# --- smoothing positions --------------------------------------------------------------------


def test_smooth_fix_boundary_keeps_the_boundary_and_solves_the_interior():
    V, F = random_mesh(225, seed=13)
    fixed = boundary_vertices(F, len(V))
    h = mean_edge_length(V, F)
    got = pcl_ddg.smooth(V, F, lambda_dt=2.0, fix_boundary=True, thickness_limit=0)
    assert np.array_equal(got[fixed], V[fixed])
    expected = backward_euler(cotan_laplacian(V, F), lumped_mass(V, F), V, 2.0 * h * h, fixed)
    assert max_relative(got - V, expected - V) < 1e-8
    free = pcl_ddg.smooth(V, F, lambda_dt=2.0, thickness_limit=0)
    assert np.max(np.abs(free[fixed] - V[fixed])) > 1e-3 * h  # a free boundary moves


def test_smooth_allow_unstable_lets_a_step_beyond_the_bound_run():
    V, F = icosphere(2)
    with pytest.raises(ValueError, match="stability bound"):
        pcl_ddg.smooth(V, F, method="explicit", lambda_dt=100.0)
    # one step beyond the bound, allowed: forward Euler with the umbrella operator (the explicit
    # default: uniform weights averaged by degree), which overshoots but stays finite
    got = pcl_ddg.smooth(V, F, method="explicit", lambda_dt=3.0, allow_unstable=True)
    U = uniform_laplacian(V, F)
    degree = -U.diagonal()
    expected = V + 3.0 * (U @ V) / degree[:, None]
    assert max_relative(got, expected) < 1e-12


def test_smooth_preserve_keeps_the_area_or_the_volume():
    V, F = icosphere(3)
    noisy = V * (1.0 + 0.02 * np.random.default_rng(9).standard_normal((len(V), 1)))
    area, volume = surface_area(noisy, F), enclosed_volume(noisy, F)
    results = {}
    for preserve in ("none", "area", "volume"):
        results[preserve] = pcl_ddg.smooth(noisy, F, lambda_dt=1.0, iterations=2,
                                           preserve=preserve, thickness_limit=0)
    assert surface_area(results["none"], F) < 0.99 * area
    assert enclosed_volume(results["none"], F) < 0.99 * volume
    assert surface_area(results["area"], F) == pytest.approx(area, rel=1e-12)
    assert enclosed_volume(results["volume"], F) == pytest.approx(volume, rel=1e-12)
    # smoothing makes the surface rounder: at equal area it encloses more, at equal volume it has
    # less area, so neither correction keeps the other measure
    assert enclosed_volume(results["area"], F) > volume * (1 + 1e-4)
    assert surface_area(results["volume"], F) < area * (1 - 1e-4)


@pytest.mark.parametrize("solver", ["auto", "cholmod", "ldlt", "cg"])
def test_smooth_absolute_time_and_every_solver_are_backward_euler(solver):
    V, F = random_mesh(225, seed=14)
    h = mean_edge_length(V, F)
    expected = backward_euler(cotan_laplacian(V, F), lumped_mass(V, F), V, 0.3)
    absolute = pcl_ddg.smooth(V, F, lambda_dt=0.3, absolute_time=True, solver=solver,
                              thickness_limit=0)
    relative = pcl_ddg.smooth(V, F, lambda_dt=0.3 / h ** 2, solver=solver, thickness_limit=0)
    assert max_relative(absolute - V, expected - V) < 1e-7
    assert max_relative(relative - V, expected - V) < 1e-7
    in_h2 = backward_euler(cotan_laplacian(V, F), lumped_mass(V, F), V, 0.3 * h * h)
    assert max_relative(in_h2 - V, expected - V) > 0.1  # h^2 is not 1 here


@pytest.mark.parametrize("update", ["freeze_weights", "update_mass", "rebuild_weights"])
def test_smooth_weight_updates_follow_the_surface_as_documented(update):
    # freeze_weights: L and M of the input; update_mass: M of the current positions;
    # rebuild_weights: both of the current positions; every iteration a backward Euler step.
    V, F = icosphere(2)
    V = V * (1.0 + 0.05 * np.random.default_rng(1).standard_normal((len(V), 1)))
    tau = 0.05
    x = V.copy()
    L, m = cotan_laplacian(V, F), lumped_mass(V, F)
    for iteration in range(3):
        if iteration > 0 and update != "freeze_weights":
            m = lumped_mass(x, F)
            if update == "rebuild_weights":
                L = cotan_laplacian(x, F)
        x = backward_euler(L, m, x, tau)
    got = pcl_ddg.smooth(V, F, lambda_dt=tau, absolute_time=True, iterations=3,
                         thickness_limit=0, **{update: True})
    assert max_relative(got - V, x - V) < 1e-8


# --- clouds -----------------------------------------------------------------------------------


def noisy_sphere(n=20000, seed=2):
    rng = np.random.default_rng(seed)
    p = rng.standard_normal((n, 3))
    p /= np.linalg.norm(p, axis=1, keepdims=True)
    return p * (1.0 + 0.01 * rng.standard_normal((n, 1)))


def test_radius_search_keeps_the_64_nearest_by_default():
    points = noisy_sphere()
    radius = 0.15  # about 110 points inside: more than 64
    r = pcl_ddg.estimate_normals(points, radius=radius)
    assert r.valid.all()
    rng = np.random.default_rng(4)
    close, inside = 0, []
    for i in rng.choice(len(points), 200, replace=False):
        d = np.linalg.norm(points - points[i], axis=1)
        order = np.argsort(d)
        inside.append(int(np.sum(d <= radius)))
        nearest = points[order[:64]]
        centred = nearest - nearest.mean(axis=0)
        normal = np.linalg.eigh(centred.T @ centred)[1][:, 0]
        close += abs(normal @ r.normals[i]) > 1 - 1e-6  # (the normals are PCL's floats)
    assert min(inside) > 64
    assert close >= 198  # (a tie at the 64th distance in float could swap one neighbour)


def test_orient_viewpoint_and_up():
    points = noisy_sphere(5000)
    up = pcl_ddg.estimate_normals(points, orient="up").normals
    assert np.all(up[:, 2] >= 0)
    x = pcl_ddg.estimate_normals(points, orient="up", up=[1, 0, 0]).normals
    assert np.all(x[:, 0] >= 0)
    viewpoint = np.array([3.0, -2.0, 0.5])
    toward = pcl_ddg.estimate_normals(points, orient="viewpoint", viewpoint=viewpoint).normals
    assert np.all(np.einsum("ij,ij->i", toward, viewpoint - points) >= 0)
    # the same lines with another sign: only the signs differ
    np.testing.assert_array_equal(np.abs(up), np.abs(toward))
    assert np.any(up[:, 2] != toward[:, 2])


# --- array conversions ----------------------------------------------------------------------


def test_big_endian_fortran_and_strided_inputs_give_the_same_bits():
    V, F = icosphere(3)
    reference = pcl_ddg.curvatures(V, F)
    wide = np.zeros((len(V), 6))
    wide[:, 1::2] = V
    for variant in (V.astype(">f8"), np.asfortranarray(V), wide[:, 1::2]):
        c = pcl_ddg.curvatures(variant, F)
        np.testing.assert_array_equal(c.mean, reference.mean)
        np.testing.assert_array_equal(c.gauss, reference.gauss)
    points = noisy_sphere(3000)
    normals = pcl_ddg.estimate_normals(points).normals
    wide = np.zeros((len(points), 6))
    wide[:, ::2] = points
    for variant in (points.astype(">f8"), np.asfortranarray(points), wide[:, ::2],
                    points.astype(">f8")[::1]):
        np.testing.assert_array_equal(pcl_ddg.estimate_normals(variant).normals, normals)
