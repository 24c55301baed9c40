"""pcl_ddg: discrete differential geometry of meshes and point clouds on NumPy arrays.

Free functions on arrays, as libigl and point-cloud-utils users expect:

* meshes take ``V`` (n x 3) and ``F`` (m x 3 int32/int64, or a list of polygons, which are
  fan-triangulated): :func:`vertex_normals`, :func:`laplacian`, :func:`mass_matrix`,
  :func:`curvatures`, :func:`mesh_report`, :func:`smooth`, :func:`smooth_field`;
* clouds take ``points`` (n x 3, or an organized h x w x 3 grid): :func:`estimate_normals`,
  :func:`principal_curvatures`, :func:`grid_normals`, :func:`orient_normals`,
  :func:`compare_neighbourhoods`;
* files: :func:`read` and :func:`write` (PLY, OBJ, OFF, STL, VTK, PCD in; PLY and PCD out).

Conventions, the same as the C++ library and the ``pcl_ddg_*`` tools:

* keyword names and defaults are the tools' flags (``pcl_ddg_normals -method pca -k 16`` is
  ``estimate_normals(points, method="pca", k=16)``);
* rows are never dropped: a vertex or point without a result gets NaN, and ``valid`` says which;
* float64 C-contiguous input is read in place; float32, integer and non-contiguous arrays are
  converted once; every output is float64; results are bit-identical to the C++ library's;
* the GIL is released during every computation, so Python threads run in parallel;
* errors: ``ValueError`` for shapes, dtypes, out-of-range faces and options;
  :class:`InvalidMeshError` (a ``ValueError``) for meshes the library refuses (empty, NaN vertices);
  ``OSError`` for files; ``RuntimeError`` for failed computations (:class:`SurfaceCollapseError`
  when a smoothing step collapses the surface). The library's message is kept.
"""

from __future__ import annotations

import json
import numbers
import os
import warnings
from typing import Any, Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

import numpy as np

from . import _pcl_ddg
from ._pcl_ddg import InvalidMeshError, SurfaceCollapseError


class PclDdgWarning(UserWarning):
    """What the tools warn about a result (rounded coordinates, a viewpoint too far to orient by,
    points left without an estimate, ...): ``warnings.simplefilter("error", PclDdgWarning)``
    turns them into errors, ``"ignore"`` silences them."""


def _warn(messages: Sequence[str]) -> None:
    """Each message as a PclDdgWarning at the caller's line outside this package."""
    import sys

    level, frame = 2, sys._getframe(1)  # stacklevel 2: _warn's caller
    while frame is not None and (frame.f_globals.get("__name__", "") + ".").startswith("pcl_ddg."):
        level, frame = level + 1, frame.f_back  # type: ignore[assignment]
    for message in messages:
        warnings.warn(message, PclDdgWarning, stacklevel=level)

__version__: str = _pcl_ddg.__version__

__all__ = [
    "PclDdgWarning",
    "InvalidMeshError",
    "SurfaceCollapseError",
    "VertexNormals",
    "Curvatures",
    "Normals",
    "PrincipalCurvatures",
    "RobustNormals",
    "OrientedNormals",
    "NeighbourhoodComparison",
    "MeshFile",
    "vertex_normals",
    "laplacian",
    "mass_matrix",
    "curvatures",
    "mesh_report",
    "smooth",
    "smooth_field",
    "estimate_normals",
    "principal_curvatures",
    "robust_normals",
    "grid_normals",
    "orient_normals",
    "compare_neighbourhoods",
    "read",
    "read_copc",
    "copc_info",
    "write",
]

ArrayLike = Any
Faces = Union[np.ndarray, Sequence[np.ndarray], Sequence[Sequence[int]]]
Vector3 = Optional[Union[Sequence[float], np.ndarray]]

_INDEX_MAX = 2**31 - 1  # the library counts points and neighbours in int


def _shown(value: Any) -> str:
    text = repr(value)
    return text if len(text) <= 40 else text[:37] + "..."


_THREADS_MAX = 1024  # OpenMP cannot start many more threads than that on any machine


def _integer(value: Any, name: str, minimum: int = 0, maximum: int = _INDEX_MAX,
             required: bool = False) -> Any:
    """An integer option as an int (None stays None unless required), or ValueError naming it:
    bools and floats are refused, as are values outside [minimum, maximum]."""
    if value is None and not required:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise ValueError(f"{name} must be a whole number, not {_shown(value)}")
    if not minimum <= int(value) <= maximum:
        raise ValueError(f"{name} must be from {minimum} to {maximum}, not {int(value)}")
    return int(value)


def _threads(value: Any) -> int:
    """threads= (0: every core)."""
    return int(_integer(value, "threads", 0, _THREADS_MAX, required=True))


def _real(value: Any, name: str, required: bool = False) -> Any:
    """A real option as a float (None stays None unless required), or ValueError naming it."""
    if value is None and not required:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise ValueError(f"{name} must be a number, not {_shown(value)}")
    return float(value)


def _text(value: Any, name: str, required: bool = False) -> Any:
    """A named choice as a str (None stays None unless required), or ValueError naming it."""
    if (value is None and not required) or isinstance(value, str):
        return value
    raise ValueError(f"{name} must be a name (str), not {_shown(value)}")


def _flag(value: Any, name: str) -> bool:
    """A yes/no option: a bool (NumPy's too), or ValueError naming it."""
    if isinstance(value, (bool, np.bool_)):
        return bool(value)
    raise ValueError(f"{name} must be True or False, not {_shown(value)}")


def _renamed(old_value: Any, old: str, new: str, value: Any, default: Any) -> Any:
    """value, or the deprecated keyword's (with a DeprecationWarning) when only it is given."""
    if old_value is None:
        return value
    warnings.warn(f"{old}= is deprecated: use {new}=", DeprecationWarning, stacklevel=3)
    if value != default:
        raise ValueError(f"{old}= and {new}= name the same option: give {new}= only")
    return old_value


def _array(value: ArrayLike, name: str) -> np.ndarray:
    """value as an ndarray without a copy when it is one already (the binding converts once)."""
    if isinstance(value, np.ndarray):
        return value
    try:
        return np.asarray(value)
    except (TypeError, ValueError) as error:
        raise ValueError(f"{name} must be an array: {error}") from None


def _faces(F: Optional[Faces]) -> Any:
    if isinstance(F, np.ndarray):
        return F
    if F is None:
        raise ValueError("F is None: no faces (a cloud, or a file without faces)")
    if isinstance(F, (list, tuple)):
        # A rectangular list of lists is an array; ragged polygons stay a list.
        lengths = {len(p) if hasattr(p, "__len__") else -1 for p in F}
        if len(lengths) == 1 and -1 not in lengths:
            array = np.asarray(F)
            if array.dtype.kind in "iu" or array.size == 0:
                return array.astype(np.int64, copy=False).reshape(len(F), -1)
        return list(F)
    try:  # an array-like: Open3D's mesh.triangles, a memoryview, ...
        array = np.asarray(F)
    except (TypeError, ValueError):
        array = None
    if array is not None and array.ndim == 2 and array.dtype.kind in "iu":
        return array
    raise ValueError("F must be an (m, 3) integer array or a sequence of polygons")


def _file_defaults(
    points: Any, faces: Optional[Faces], viewpoint: Vector3, orient: Optional[str]
) -> Tuple[Any, Optional[Faces], Vector3, Optional[str]]:
    """A :class:`MeshFile` given as the points brings the tools' defaults for its file: its faces,
    its organized grid, its VIEWPOINT, and for a LAS cloud ``orient="up"`` (aerial LiDAR has no
    single viewpoint; as ``pcl_ddg_normals`` and PDAL's filters.normal). Arrays pass unchanged."""
    if not isinstance(points, MeshFile):
        return points, faces, viewpoint, orient
    f = points
    if faces is None:
        faces = f.faces
    if orient is None and viewpoint is None and f.las is not None and faces is None:
        orient = "up"
    if viewpoint is None and orient != "up":
        viewpoint = f.viewpoint
    return (f.grid if f.organized_shape is not None else f.points), faces, viewpoint, orient


def _vector(value: Vector3, name: str) -> Optional[List[float]]:
    if value is None:
        return None
    v = np.asarray(value, dtype=np.float64).ravel()
    if v.shape != (3,):
        raise ValueError(f"{name} must be three numbers x, y, z")
    return [float(x) for x in v]


# ---------------------------------------------------------------------------------------------
# Meshes


class VertexNormals(NamedTuple):
    """Per-vertex normals: unit rows, NaN where ``valid`` is False."""

    normals: np.ndarray  #: (n, 3) float64
    valid: np.ndarray  #: (n,) bool


def vertex_normals(
    V: ArrayLike,
    F: Optional[Faces],
    weights: str = "area",
    epsilon: Optional[float] = None,
    mass: str = "mixed",
    weighting: Optional[str] = None,
) -> VertexNormals:
    """Normals of a triangle mesh, oriented like its faces (``pcl_ddg_normals -method ...``).

    weights:
        ``"area"`` (sum of the triangles' area vectors; the default), ``"uniform"`` (every face
        the same), ``"angle"`` (unit face normals weighted by the corner angle), or
        ``"mean_curvature"`` (the direction of -M^-1 L x, the area normal where the surface is
        flat (|M^-1 L x| < epsilon) and on the boundary).
    epsilon:
        ``mean_curvature`` only: the flatness threshold in 1/length; None: 0.02 / mean edge length.
    mass:
        the vertex areas M of ``mean_curvature``: ``"mixed"``, ``"voronoi"``, ``"barycentric"``.

    weighting:
        the former name of ``weights`` (deprecated).

    Vertices with no non-degenerate triangle, or whose face normals cancel, get NaN and
    ``valid=False``.
    """
    weights = _renamed(weighting, "weighting", "weights", weights, "area")
    normals, valid, counts = _pcl_ddg.vertex_normals(
        _array(V, "V"), _faces(F), _text(weights, "weights", True), _real(epsilon, "epsilon"),
        _text(mass, "mass", True),
    )
    _warn(counts["warnings"])
    return VertexNormals(normals, valid)


def _csr(data: np.ndarray, indices: np.ndarray, indptr: np.ndarray) -> Any:
    from scipy import sparse

    n = indptr.shape[0] - 1
    return sparse.csr_matrix((data, indices, indptr), shape=(n, n), copy=False)


def laplacian(
    V: ArrayLike, F: Optional[Faces], weights: str = "cotan", form: str = "summed", mass: str = "mixed"
) -> Any:
    """The discrete Laplace-Beltrami operator L as a ``scipy.sparse.csr_matrix`` (n x n).

    L is NEGATIVE semi-definite: off-diagonal ``L[i, j] = w_ij`` for every edge ij, diagonal
    ``L[i, i] = -sum_j w_ij``, so ``L @ ones = 0`` and ``(L x)_i = sum_j w_ij (x_j - x_i)``.
    (libigl's ``cotmatrix`` uses the same sign; potpourri3d's ``cotan_laplacian`` and
    robust_laplacian return the POSITIVE semi-definite -L.)

    weights:
        ``"cotan"``: ``w_ij = (cot a_ij + cot b_ij) / 2`` over the angles opposite edge ij (one
        cotangent on a boundary edge); ``"uniform"``: ``w_ij = 1``.
    form:
        ``"summed"``: L itself, symmetric (the stiffness matrix, used with :func:`mass_matrix`);
        ``"averaged"``: ``M^-1 L``, a pointwise Laplacian (``M^-1 L x ~ -2 H n`` with cotan
        weights); rows of zero-mass vertices are zero.
    mass:
        M of the averaged form: ``"mixed"``, ``"voronoi"`` or ``"barycentric"``.
    """
    data, indices, indptr = _pcl_ddg.laplacian(
        _array(V, "V"), _faces(F), _text(weights, "weights", True), _text(form, "form", True),
        _text(mass, "mass", True),
    )
    return _csr(data, indices, indptr)


def mass_matrix(
    V: ArrayLike, F: Optional[Faces], mass: str = "mixed", kind: Optional[str] = None
) -> Any:
    """The lumped (diagonal) mass matrix M as a ``scipy.sparse.csr_matrix``: vertex areas.

    mass:
        ``"mixed"`` (Meyer et al. 2003's mixed Voronoi areas, never negative; the default),
        ``"voronoi"`` (circumcentric cells, negative contributions on obtuse triangles) or
        ``"barycentric"`` (a third of every incident triangle).

    kind:
        the former name of ``mass`` (deprecated).

    The masses sum to the total area for every kind.
    """
    mass = _renamed(kind, "kind", "mass", mass, "mixed")
    area = _pcl_ddg.mass_matrix(_array(V, "V"), _faces(F), _text(mass, "mass", True))
    n = area.shape[0]
    index = np.arange(n, dtype=np.int32)
    return _csr(area, index, np.arange(n + 1, dtype=np.int32))


class Curvatures(NamedTuple):
    """Discrete curvatures per vertex (NaN where the vertex has no area or no orientation)."""

    mean: np.ndarray  #: H, > 0 on an outward-oriented sphere
    gauss: np.ndarray  #: K density: angle defect / vertex area
    k1: np.ndarray  #: H + sqrt(max(H^2 - K, 0)), k1 >= k2
    k2: np.ndarray  #: H - sqrt(max(H^2 - K, 0))
    area: np.ndarray  #: the vertex area used (mixed Voronoi by default)

    @property
    def valid(self) -> np.ndarray:
        """Vertices with a curvature (the library's mask: finite H)."""
        return np.isfinite(self.mean)


def curvatures(V: ArrayLike, F: Optional[Faces], mass: str = "mixed") -> Curvatures:
    """Mean, Gaussian and principal curvatures of a mesh (``pcl_ddg_curvature -method cotan``).

    H from the cotangent Laplacian (``Hn = -1/2 M^-1 L x``, signed by the area normal), K from the
    angle defect (2 pi - sum of angles inside, pi - sum on the boundary) over the vertex area, so
    that ``sum(gauss * area) = 2 pi chi`` (Gauss-Bonnet). ``mass`` (the ``-area`` flag): ``"mixed"``,
    ``"voronoi"``, ``"barycentric"``.
    """
    mean, gauss, k1, k2, area, _, counts = _pcl_ddg.curvatures(
        _array(V, "V"), _faces(F), _text(mass, "mass", True)
    )
    _warn(counts["warnings"])
    return Curvatures(mean, gauss, k1, k2, area)


def mesh_report(V: ArrayLike, F: Optional[Faces]) -> Dict[str, Any]:
    """Everything worth knowing about a mesh before trusting numbers computed on it.

    The dict of ``pcl_ddg_info -json``: counts of degenerate, duplicate, out-of-range and
    triangulated faces, boundary edges and loops, non-manifold edges and vertices, unreferenced
    and non-finite vertices, components, Euler characteristic, genus, orientability, mean edge
    length and bounding box. Defects are counted, never refused.
    """
    return json.loads(_pcl_ddg.mesh_report(_array(V, "V"), _faces(F)))


def smooth(
    V: ArrayLike,
    F: Optional[Faces],
    method: str = "implicit",
    weights: Optional[str] = None,
    average: Optional[str] = None,
    mass: Optional[str] = None,
    lambda_dt: Optional[float] = None,
    lambda_: Optional[float] = None,
    mu: Optional[float] = None,
    iterations: int = 1,
    absolute_time: bool = False,
    freeze_weights: bool = False,
    update_mass: bool = False,
    rebuild_weights: bool = False,
    thickness_limit: Optional[float] = None,
    fix_boundary: bool = False,
    allow_unstable: bool = False,
    preserve: str = "none",
    solver: str = "auto",
) -> np.ndarray:
    """Laplacian smoothing of the vertex positions (``pcl_ddg_smooth``): dx/dt = A^-1 L x.

    method:
        ``"implicit"`` (backward Euler, stable for any step), ``"explicit"`` (forward Euler,
        stable only below a bound; a larger step raises ValueError unless ``allow_unstable``) or
        ``"taubin"`` (a step of ``lambda_`` then one of ``mu`` per iteration: no shrinkage).
    weights:
        ``"cotan"``, ``"uniform"`` or ``"umbrella"`` (uniform averaged by degree: each vertex moves
        towards the mean of its neighbours). Default: cotan for implicit steps or with ``mass``,
        else umbrella.
    average:
        what divides L: ``"area"`` (the vertex areas of ``mass``, default ``"mixed"``: the
        geometric flow) or ``"degree"`` (each vertex's total weight). Default: degree for umbrella,
        else area.
    lambda_dt:
        the flow's time step: averaged by area in units of h^2 (h = mean edge length), or in
        length^2 with ``absolute_time=True``; averaged by degree without unit. Default: 1
        (implicit), half the stability bound (explicit).
    lambda_, mu:
        Taubin's two steps (mu < -lambda_), in lambda_dt's units; default 0.5 and -0.53. Only
        with ``method="taubin"`` (ValueError otherwise, as ``lambda_dt`` with it).
    freeze_weights / update_mass / rebuild_weights:
        by default (``freeze_weights``) L and M stay those of the input; ``update_mass`` lets M
        follow the surface (conformalized mean-curvature flow), ``rebuild_weights`` rebuilds both
        every iteration (mean-curvature flow, which pinches thin parts into slivers).
    thickness_limit:
        a vertex whose inner ball (the largest empty ball touching it from inside: half the
        local thickness) has radius r smooths for at most about ``thickness_limit * r**2`` in
        all, so that handles, legs and horns a few edges thick do not collapse into slivers.
        Default (None) 0.5 for area-averaged explicit and implicit steps, where alone it
        applies (ValueError elsewhere); 0: no limit.
    fix_boundary: boundary vertices keep their position.
    preserve: ``"none"``, ``"volume"`` (closed meshes) or ``"area"``: rescale after every step.
    solver: ``"auto"``, ``"cholmod"``, ``"ldlt"`` or ``"cg"`` (conjugate gradients).

    Returns the smoothed (n, 3) positions; Ctrl-C interrupts between iterations. A step that
    collapses the surface raises :class:`SurfaceCollapseError`.
    """
    return _pcl_ddg.smooth(
        _array(V, "V"),
        _faces(F),
        _text(method, "method", True),
        _text(weights, "weights"),
        _text(average, "average"),
        _text(mass, "mass"),
        _real(lambda_dt, "lambda_dt"),
        _real(lambda_, "lambda_"),
        _real(mu, "mu"),
        _integer(iterations, "iterations", required=True),
        _flag(absolute_time, "absolute_time"),
        _flag(freeze_weights, "freeze_weights"),
        _flag(update_mass, "update_mass"),
        _flag(rebuild_weights, "rebuild_weights"),
        _real(thickness_limit, "thickness_limit"),
        _flag(fix_boundary, "fix_boundary"),
        _flag(allow_unstable, "allow_unstable"),
        _text(preserve, "preserve", True),
        _text(solver, "solver", True),
    )


def smooth_field(
    V: ArrayLike,
    F: Optional[Faces],
    values: ArrayLike,
    time: float,
    method: str = "implicit",
    weights: str = "cotan",
    mass: str = "mixed",
    iterations: int = 1,
    absolute_time: bool = False,
    fix_boundary: bool = False,
    solver: str = "auto",
) -> np.ndarray:
    """Heat flow of per-vertex values on the fixed mesh: df/dt = Laplace-Beltrami(f).

    values: (n,) or (n, c) (every column smoothed). time: the diffusion time in units of h^2
    (as ``pcl_ddg_curvature -smooth t``), or in length^2 with ``absolute_time=True``; detail
    below a wavelength of about 2 pi sqrt(time) is gone. The mass-weighted sum is conserved on a
    closed mesh; a free boundary is insulated, a fixed one (``fix_boundary``) keeps its values.
    """
    return _pcl_ddg.smooth_field(
        _array(V, "V"),
        _faces(F),
        _array(values, "values"),
        _real(time, "time", required=True),
        _text(method, "method", True),
        _text(weights, "weights", True),
        _text(mass, "mass", True),
        _integer(iterations, "iterations", required=True),
        _flag(absolute_time, "absolute_time"),
        _flag(fix_boundary, "fix_boundary"),
        _text(solver, "solver", True),
    )


# ---------------------------------------------------------------------------------------------
# Clouds


class Normals(NamedTuple):
    """Fitted normals: NaN rows where ``valid`` is False (too few neighbours, NaN points)."""

    normals: np.ndarray  #: (n, 3), or (h, w, 3) for an organized cloud
    curvature: np.ndarray  #: PCL's surface variation l0 / (l0 + l1 + l2) (pca)
    valid: np.ndarray  #: bool


def estimate_normals(
    points: ArrayLike,
    method: str = "pca",
    k: Optional[int] = None,
    radius: Optional[float] = None,
    max_nn: Optional[int] = None,
    min_nn: Optional[int] = None,
    neighbours: Optional[str] = None,
    faces: Optional[Faces] = None,
    viewpoint: Vector3 = None,
    orient: Optional[str] = None,
    up: Vector3 = None,
    max_depth_jump: Optional[float] = None,
    threads: int = 0,
) -> Normals:
    """Normals by fitting a plane (``"pca"``), a quadric (``"quadric"``) or a robust plane
    (``"robust"``: its own scale up to k, not across sharp edges; :func:`robust_normals` also
    returns the scale and confidence) to each point's neighbours (``pcl_ddg_normals -method``).

    points: (n, 3), or (h, w, 3) for an organized cloud (kept: the output has its grid), in any
        real dtype; float64 coordinates are fitted as they are, wherever they lie (about their
        local origin, as the tools: docs/library.md). Or what :func:`read` returned, which
        brings its file's defaults: its faces, grid and VIEWPOINT, and for a LAS file
        ``orient="up"``, as ``pcl_ddg_normals`` orients LAS files.
    k: neighbours (default 16, quadric 20, robust 96 or all points if fewer: the
        neighbourhood searched, beyond which robust widens only on noisy data; at least 3, at most the point count).
    radius: a radius search instead of k, keeping at most ``max_nn`` (default 64) nearest;
        ``min_nn``: the min_nn nearest where the ball holds fewer.
    neighbours: ``"kdtree"`` (clouds' default), ``"rings"`` (rings of the mesh ``faces``; the
        default when faces are given) or ``"grid"`` (an organized cloud's pixels; its default,
        never across a depth jump above ``max_depth_jump``, default 0.02). The former ``"knn"``
        and ``"bfs"`` still mean ``"kdtree"`` and ``"rings"``.
    viewpoint: the sensor: normals face it (default the origin, as PCL).
    orient: ``"viewpoint"`` (clouds' default), ``"mesh"`` (like the faces; meshes' default),
        ``"up"`` (n . up >= 0; ``up`` default +z) or ``"mst"`` (consistent along a minimum
        spanning tree; the viewpoint or ``up`` decides every sign it can).
    threads: 0 for every core.
    """
    normals, curvature, valid, _, _, _ = _fitted_normals(
        points, method, k, radius, max_nn, min_nn, neighbours, faces, viewpoint, orient, up,
        max_depth_jump, threads,
    )
    return Normals(normals, curvature, valid)


def _fitted_normals(
    points: ArrayLike,
    method: str,
    k: Optional[int],
    radius: Optional[float],
    max_nn: Optional[int],
    min_nn: Optional[int],
    neighbours: Optional[str],
    faces: Optional[Faces],
    viewpoint: Vector3,
    orient: Optional[str],
    up: Vector3,
    max_depth_jump: Optional[float],
    threads: int,
) -> Tuple[Any, ...]:
    """The binding's fit with the arguments checked and converted (estimate_normals' order):
    normals, curvature, valid, counts, and robust's scale and confidence (else None)."""
    points, faces, viewpoint, orient = _file_defaults(points, faces, viewpoint, orient)
    result = _pcl_ddg.estimate_normals(
        _array(points, "points"),
        _text(method, "method", True),
        _integer(k, "k"),
        _real(radius, "radius"),
        _integer(max_nn, "max_nn"),
        _integer(min_nn, "min_nn"),
        _text(neighbours, "neighbours"),
        None if faces is None else _faces(faces),
        _vector(viewpoint, "viewpoint"),
        _text(orient, "orient"),
        _vector(up, "up"),
        _real(max_depth_jump, "max_depth_jump"),
        _threads(threads),
    )
    _warn(result[3]["warnings"])
    return result


class RobustNormals(NamedTuple):
    """Normals of robust planes (NaN where ``valid`` is False), with the scale each used."""

    normals: np.ndarray  #: (n, 3) unit
    curvature: np.ndarray  #: surface variation of the fit
    valid: np.ndarray  #: bool
    scale: np.ndarray  #: neighbours the plane used; a wider plane: about 32 (level + 1)^2
    confidence: np.ndarray  #: share of the k found used (1: a wider plane); small at edges


def robust_normals(
    points: ArrayLike,
    k: Optional[int] = None,
    neighbours: Optional[str] = None,
    faces: Optional[Faces] = None,
    viewpoint: Vector3 = None,
    orient: Optional[str] = None,
    up: Vector3 = None,
    threads: int = 0,
) -> RobustNormals:
    """Normals that choose their own scale and keep sharp edges (``pcl_ddg_normals -method
    robust``; the method: ``docs/library.md``, fitted normals). k: the neighbourhood searched
    (default 96, or all points if fewer). Options as :func:`estimate_normals`.
    """
    normals, curvature, valid, _, scale, confidence = _fitted_normals(
        points, "robust", k, None, None, None, neighbours, faces, viewpoint, orient, up, None,
        threads,
    )
    return RobustNormals(normals, curvature, valid, scale, confidence)


class PrincipalCurvatures(NamedTuple):
    """Principal curvatures of a quadric fitted at each point (NaN where ``valid`` is False)."""

    k1: np.ndarray  #: k1 >= k2, signed like the normal
    k2: np.ndarray
    direction1: np.ndarray  #: (n, 3) unit direction of k1
    normals: np.ndarray  #: (n, 3)
    valid: np.ndarray  #: bool


def principal_curvatures(
    points: ArrayLike,
    k: Optional[int] = None,
    radius: Optional[float] = None,
    max_nn: Optional[int] = None,
    min_nn: Optional[int] = None,
    neighbours: Optional[str] = None,
    faces: Optional[Faces] = None,
    viewpoint: Vector3 = None,
    orient: Optional[str] = None,
    up: Vector3 = None,
    threads: int = 0,
) -> PrincipalCurvatures:
    """k1, k2, the k1 direction and the normal of a quadric fitted to each point's neighbours
    (``pcl_ddg_curvature -method quadric``; k default 20). Options as :func:`estimate_normals`.
    Mean curvature is ``(k1 + k2) / 2``, Gaussian ``k1 * k2``.
    """
    points, faces, viewpoint, orient = _file_defaults(points, faces, viewpoint, orient)
    k1, k2, direction, normals, valid, counts = _pcl_ddg.principal_curvatures(
        _array(points, "points"),
        _integer(k, "k"),
        _real(radius, "radius"),
        _integer(max_nn, "max_nn"),
        _integer(min_nn, "min_nn"),
        _text(neighbours, "neighbours"),
        None if faces is None else _faces(faces),
        _vector(viewpoint, "viewpoint"),
        _text(orient, "orient"),
        _vector(up, "up"),
        _threads(threads),
    )
    _warn(counts["warnings"])
    return PrincipalCurvatures(k1, k2, direction, normals, valid)


def grid_normals(
    xyz: ArrayLike,
    k: int = 16,
    max_depth_jump: Optional[float] = None,
    viewpoint: Vector3 = None,
    orient: Optional[str] = None,
    threads: int = 0,
) -> Normals:
    """PCA normals of an organized cloud (an RGB-D frame, a range image) of shape (h, w, 3).

    Each pixel's plane is fitted to the smallest square window of at least k pixels, from
    windowed sums, never across a depth jump (a range change above ``max_depth_jump``, default
    0.02, times the range per pixel). NaN pixels stay NaN. The result keeps the (h, w) grid.
    """
    xyz = _array(xyz, "xyz")
    if xyz.ndim != 3 or xyz.shape[-1] != 3:
        raise ValueError(f"xyz must have shape (h, w, 3), not {xyz.shape}")
    return estimate_normals(
        xyz,
        method="pca",
        k=k,
        neighbours="grid",
        max_depth_jump=max_depth_jump,
        viewpoint=viewpoint,
        orient=orient,
        threads=threads,
    )


class OrientedNormals(NamedTuple):
    normals: np.ndarray  #: (n, 3), the input's rows, some negated
    flipped: int  #: how many were turned


def orient_normals(
    points: ArrayLike,
    normals: ArrayLike,
    method: str = "mst",
    viewpoint: Vector3 = None,
    up: Vector3 = None,
    k: int = 10,
    faces: Optional[Faces] = None,
) -> OrientedNormals:
    """Turns normals to one consistent side; only signs change (the values are the input's).

    method:
        ``"mst"``: along a minimum spanning tree of the k-nearest graph (or of the mesh ``faces``),
        weighted by 1 - |n_i . n_j| (Hoppe et al. 1992); with ``viewpoint`` or ``up`` the reference
        decides every point it can (|n . d| >= 0.1) and the tree the rest, else each component's
        highest point faces +z. ``"viewpoint"``: n . (viewpoint - p) >= 0 (default the origin).
        ``"up"``: n . up >= 0 (default +z).
    """
    out, flipped = _pcl_ddg.orient_normals(
        _array(points, "points"),
        _array(normals, "normals"),
        _text(method, "method", True),
        _vector(viewpoint, "viewpoint"),
        _vector(up, "up"),
        _integer(k, "k", required=True),
        None if faces is None else _faces(faces),
    )
    return OrientedNormals(out, flipped)


class NeighbourhoodComparison(NamedTuple):
    angle_difference: np.ndarray  #: degrees between the two normals, NaN where either failed
    overlap: np.ndarray  #: Jaccard overlap of the two neighbour sets, in [0, 1]
    summary: Dict[str, float]  #: compared, mean, median, percentile95, max, share_over_5, ...


def compare_neighbourhoods(
    V: ArrayLike,
    F: Optional[Faces],
    method: str = "pca",
    k: Optional[int] = None,
    radius: Optional[float] = None,
    max_nn: Optional[int] = None,
    threads: int = 0,
) -> NeighbourhoodComparison:
    """The same fit with topological (mesh rings; or an organized cloud's pixel grid when F is
    None) and Euclidean (kd-tree) neighbourhoods, and how much they differ at every vertex
    (``pcl_ddg_compare_neighbourhoods``; k default 16)."""
    angle, overlap, summary = _pcl_ddg.compare_neighbourhoods(
        _array(V, "V"),
        None if F is None else _faces(F),
        _text(method, "method", True),
        _integer(k, "k"),
        _real(radius, "radius"),
        _integer(max_nn, "max_nn"),
        _threads(threads),
    )
    return NeighbourhoodComparison(angle, overlap, summary)


# ---------------------------------------------------------------------------------------------
# Files


class MeshFile:
    """A file's contents: ``points`` (n, 3) float64 (the file's doubles exactly where it stores
    doubles), ``faces`` ((m, 3) int32, a list of polygons, or None for a cloud), ``fields`` (every
    other vertex property by name, in its own dtype; colours as ``"rgb"`` uint8 (n, 3)),
    ``viewpoint`` (a PCD's VIEWPOINT origin; zeros otherwise), ``orientation`` (its rotation, w x
    y z), ``organized_shape`` ((h, w) of an organized cloud, else None), ``precision`` (the
    declared coordinate type, ``"float"`` or ``"double"``) and ``las`` (a LAS file's
    :class:`_pcl_ddg.LasLayout`: version, point format, scale/offset, VLRs; else None). For a LAS
    file ``points`` are ``X * scale + offset`` in double and ``fields`` every record field as
    stored (``red green blue`` uint16, Extra Bytes by name; docs/las.md)."""

    __slots__ = (
        "points", "faces", "fields", "viewpoint", "orientation", "organized_shape", "precision",
        "las",
    )

    def __init__(
        self,
        points: np.ndarray,
        faces: Optional[Union[np.ndarray, List[np.ndarray]]],
        fields: Dict[str, np.ndarray],
        viewpoint: np.ndarray,
        orientation: np.ndarray,
        organized_shape: Optional[Tuple[int, int]],
        precision: str,
        las: Optional["_pcl_ddg.LasLayout"] = None,
    ) -> None:
        self.points = points
        self.faces = faces
        self.fields = fields
        self.viewpoint = viewpoint
        self.orientation = orientation
        self.organized_shape = organized_shape
        self.precision = precision
        self.las = las

    @property
    def grid(self) -> np.ndarray:
        """The points of an organized cloud as an (h, w, 3) view."""
        if self.organized_shape is None:
            raise ValueError("not an organized cloud")
        return self.points.reshape(*self.organized_shape, 3)

    def __repr__(self) -> str:
        faces = "None" if self.faces is None else str(len(self.faces))
        return (
            f"MeshFile(points={self.points.shape[0]}, faces={faces}, fields={sorted(self.fields)}, "
            f"organized_shape={self.organized_shape})"
        )


def _path(path: Union[str, bytes, "os.PathLike[str]"]) -> str:
    return os.fsdecode(os.fspath(path))


def _file_of(result: Tuple[Any, ...]) -> MeshFile:
    points, faces, fields, viewpoint, orientation, shape, precision, las = result
    return MeshFile(
        points,
        faces,
        fields,
        np.array(viewpoint, dtype=np.float64),
        np.array(orientation, dtype=np.float64),
        shape,
        precision,
        las,
    )


def _existing(path: Union[str, "os.PathLike[str]"]) -> str:
    path = _path(path)
    if not os.path.exists(path):
        import errno

        raise FileNotFoundError(errno.ENOENT, os.strerror(errno.ENOENT), path)
    return path


def read(path: Union[str, "os.PathLike[str]"]) -> MeshFile:
    """Reads a mesh or a cloud: .ply (ascii/binary; face, tristrips, range_grid), .obj, .off
    (also binary), .stl, .vtk (legacy POLYDATA), .pcd (organized or not), .las (LAS 1.0-1.4,
    formats 0-10), .laz (LASzip-compressed: formats 0-3 and 6-8, COPC included). OSError if the
    file is missing, unknown or malformed."""
    return _file_of(_pcl_ddg.read(_existing(path)))


def copc_info(path: Union[str, "os.PathLike[str]"]) -> Dict[str, Any]:
    """A COPC file's octree (docs/las.md, COPC), read from its header, VLRs and hierarchy pages
    only: ``center``, ``halfsize``, ``spacing``, ``gpstime`` (min, max), ``points``,
    ``hierarchy_pages`` and ``nodes``, a list of (depth, x, y, z, offset, bytes, points). OSError
    if the file is not COPC or its hierarchy is inconsistent."""
    return dict(_pcl_ddg.copc_info(_existing(path)))


def read_copc(
    path: Union[str, "os.PathLike[str]"],
    bounds: Optional[ArrayLike] = None,
    max_depth: Optional[int] = None,
    nodes: Optional[Sequence[Sequence[int]]] = None,
) -> Tuple[MeshFile, int]:
    """Part of a COPC file, read by byte ranges: the points within ``bounds`` ((2, 3) or 6
    numbers: min x y z, max x y z, in the file's coordinates; closed) from the nodes whose cubes
    meet it, down to ``max_depth`` (None: every level; smaller is a coarser sample), or the points
    of the chosen ``nodes`` ((depth, x, y, z) each, in that order). Returns the points as
    :func:`read` gives a LAS file's, and the bytes read. ValueError for both or neither of
    bounds and nodes, or a node the file does not hold; OSError for a file that is not COPC."""
    path = _existing(path)
    if (bounds is None) == (nodes is None):
        raise ValueError("read_copc takes bounds or nodes (one of them)")
    if nodes is not None:
        keys = []
        for node in nodes:
            key = [_integer(v, "a node's depth, x, y, z", 0, 2**31 - 1, required=True) for v in node]
            if len(key) != 4:
                raise ValueError(f"a node is (depth, x, y, z), not {_shown(node)}")
            keys.append(key)
        result, bytes_read = _pcl_ddg.read_copc(path, keys, None, -1)
        return _file_of(result), bytes_read
    box = np.asarray(bounds, dtype=np.float64).reshape(-1)
    if box.size != 6 or not np.all(np.isfinite(box)) or np.any(box[:3] > box[3:]):
        raise ValueError(f"bounds are min x y z, max x y z (finite, min <= max), not {_shown(bounds)}")
    depth = -1 if max_depth is None else _integer(max_depth, "max_depth", 0, 31)
    result, bytes_read = _pcl_ddg.read_copc(path, None, box.tolist(), depth)
    return _file_of(result), bytes_read


def write(
    path: Union[str, "os.PathLike[str]"],
    points: ArrayLike,
    faces: Optional[Faces] = None,
    fields: Optional[Dict[str, ArrayLike]] = None,
    viewpoint: Vector3 = None,
    precision: Optional[str] = None,
    encoding: str = "binary",
    organized_shape: Optional[Tuple[int, int]] = None,
    las: Optional["_pcl_ddg.LasLayout"] = None,
) -> None:
    """Writes a .ply (binary, or ``encoding="ascii"``), a .pcd (binary_compressed; faces are
    not stored), a .las or a .laz (LASzip-compressed; formats 0-3 and 6-8), atomically (a failed
    write leaves no file).

    fields: per-vertex values by name, (n,) each; ``"normals"`` (n, 3) becomes nx ny nz (PLY) or
    normal_x normal_y normal_z (PCD); ``"rgb"`` uint8 (n, 3) the colours; another (n, c) array
    becomes name_0 .. name_{c-1}. precision: ``"float"`` or ``"double"``; None (default) keeps
    every value exact (double where float would round a float64 value). viewpoint: a PCD's
    VIEWPOINT. organized_shape: (h, w) of an organized cloud (h * w = n).

    .las: every field keeps its dtype ((n, c) is one field of c values); the LAS point fields
    (``intensity``, ``classification``, ``red``, ... as :func:`read` gives them) fill the
    records, every other field becomes an Extra Bytes dimension (``"normals"`` as NormalX
    NormalY NormalZ). ``las``: the layout to keep (a LAS :func:`read`'s ``las``: version, point
    format, scale/offset, VLRs), so that unchanged records round-trip bit for bit; None: LAS 1.4
    format 6 (7 with ``"rgb"``), scale and offset chosen from the points, and no VLR but the
    fields' Extra Bytes: an input's CRS (its projection VLRs) and its other VLRs are not carried,
    which a :class:`PclDdgWarning` says. To keep them, pass the input's layout::

        cloud = pcl_ddg.read("survey.las")
        pcl_ddg.write("out.las", cloud.points, fields=..., las=cloud.las)
    """
    points = _array(points, "points")
    if points.ndim == 3 and organized_shape is None:
        organized_shape = (points.shape[0], points.shape[1])
        points = points.reshape(-1, points.shape[-1])
    path = _path(path)
    _pcl_ddg.write(
        path,
        points,
        None if faces is None else _faces(faces),
        None if fields is None else dict(fields),
        _vector(viewpoint, "viewpoint"),
        _text(precision, "precision"),
        _text(encoding, "encoding", True),
        None if organized_shape is None else (int(organized_shape[0]), int(organized_shape[1])),
        las,
    )
    if las is None and path.lower().endswith((".las", ".laz")):
        _warn([
            f"{path}: written without las=, so it carries no CRS and no VLR of any input; pass "
            "las=pcl_ddg.read(input).las to keep the input's projection, VLRs, scale and offset"
        ])
