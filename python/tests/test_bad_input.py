"""The bad-input table: every case must raise its Python exception; each runs in a subprocess,
so that a crash (a segfault, an abort) fails the test instead of the whole run."""

import pytest

from conftest import python_subprocess

SETUP = """
import numpy as np, pcl_ddg
t = (1 + 5 ** 0.5) / 2
V = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
              [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
F = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
              [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
              [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
P = np.random.default_rng(0).random((50, 3))
"""

CASES = {
    # shapes and dtypes
    "V 1-D": ("pcl_ddg.vertex_normals(V.ravel(), F)", "ValueError"),
    "V (n, 2)": ("pcl_ddg.laplacian(V[:, :2], F)", "ValueError"),
    "V (n, 4)": ("pcl_ddg.curvatures(np.hstack([V, V[:, :1]]), F)", "ValueError"),
    "V strings": ("pcl_ddg.mass_matrix(V.astype(str), F)", "ValueError"),
    "V complex": ("pcl_ddg.vertex_normals(V.astype(complex), F)", "ValueError"),
    "V object": ("pcl_ddg.vertex_normals(np.array([[1, 2, None]] * 12), F)", "ValueError"),
    "F float": ("pcl_ddg.vertex_normals(V, F.astype(float))", "ValueError"),
    "F (m, 2)": ("pcl_ddg.vertex_normals(V, F[:, :2])", "ValueError"),
    "F 3-D": ("pcl_ddg.vertex_normals(V, F[None])", "ValueError"),
    "F string": ("pcl_ddg.vertex_normals(V, 'faces')", "ValueError"),
    "F ragged junk": ("pcl_ddg.vertex_normals(V, [[0, 1, 2], ['a']])", "ValueError"),
    # empty input
    "empty mesh": ("pcl_ddg.vertex_normals(np.zeros((0, 3)), np.zeros((0, 3), int))",
                   "ValueError"),
    "empty cloud": ("pcl_ddg.estimate_normals(np.zeros((0, 3)))", "ValueError"),
    # NaN and out-of-range indices
    "NaN vertex": ("V[3] = np.nan; pcl_ddg.laplacian(V, F)", "pcl_ddg.InvalidMeshError"),
    "inf vertex": ("V[3, 1] = np.inf; pcl_ddg.smooth(V, F)", "pcl_ddg.InvalidMeshError"),
    "face index too large": ("F[4, 1] = 12; pcl_ddg.curvatures(V, F)", "ValueError"),
    "negative face index": ("F[4, 1] = -1; pcl_ddg.vertex_normals(V, F)", "ValueError"),
    "int64 face index overflow": ("F = F.astype(np.int64); F[0, 0] = 2**40; "
                                  "pcl_ddg.laplacian(V, F)", "ValueError"),
    "polygon out of range": ("pcl_ddg.mass_matrix(V, [[0, 1, 2, 99]])", "ValueError"),
    "faces out of range (cloud)": ("pcl_ddg.estimate_normals(V, faces=F + 100)", "ValueError"),
    # options
    "unknown weighting": ("pcl_ddg.vertex_normals(V, F, weights='cot')", "ValueError"),
    "epsilon without mean_curvature": ("pcl_ddg.vertex_normals(V, F, epsilon=0.1)", "ValueError"),
    "negative epsilon": ("pcl_ddg.vertex_normals(V, F, weights='mean_curvature', epsilon=-1)",
                         "ValueError"),
    "unknown form": ("pcl_ddg.laplacian(V, F, form='normalised')", "ValueError"),
    "unknown mass": ("pcl_ddg.mass_matrix(V, F, mass='lumped')", "ValueError"),
    "iterations 0": ("pcl_ddg.smooth(V, F, iterations=0)", "ValueError"),
    "negative time step": ("pcl_ddg.smooth(V, F, lambda_dt=-1)", "ValueError"),
    "NaN time step": ("pcl_ddg.smooth(V, F, lambda_dt=float('nan'))", "ValueError"),
    "both weight updates": ("pcl_ddg.smooth(V, F, freeze_weights=True, rebuild_weights=True)",
                            "ValueError"),
    "two weight updates": ("pcl_ddg.smooth(V, F, update_mass=True, rebuild_weights=True)",
                           "ValueError"),
    "unknown solver": ("pcl_ddg.smooth(V, F, solver='magic')", "ValueError"),
    "negative thickness limit": ("pcl_ddg.smooth(V, F, thickness_limit=-0.5)", "ValueError"),
    "NaN thickness limit": ("pcl_ddg.smooth(V, F, thickness_limit=float('nan'))", "ValueError"),
    "thickness limit with Taubin": ("pcl_ddg.smooth(V, F, method='taubin', thickness_limit=0.5)",
                                    "ValueError"),
    "Taubin mu not below -lambda": ("pcl_ddg.smooth(V, F, method='taubin', mu=-0.1)",
                                    "ValueError"),
    "lambda_dt for Taubin": ("pcl_ddg.smooth(V, F, method='taubin', lambda_dt=0.5)",
                             "ValueError"),
    "umbrella averaged by area": ("pcl_ddg.smooth(V, F, weights='umbrella', average='area')",
                                  "ValueError"),
    "mu without Taubin": ("pcl_ddg.smooth(V, F, method='explicit', mu=-0.6)", "ValueError"),
    "areas averaged by degree": ("pcl_ddg.smooth(V, F, mass='voronoi', average='degree')",
                                 "ValueError"),
    "unstable Taubin": ("pcl_ddg.smooth(V, F, method='taubin', lambda_=0.99, mu=-1.0)",
                        "ValueError"),
    "field row count": ("pcl_ddg.smooth_field(V, F, np.ones(5), 1.0)", "ValueError"),
    "field zero time": ("pcl_ddg.smooth_field(V, F, np.ones(12), 0.0)", "ValueError"),
    "k > n": ("pcl_ddg.estimate_normals(P, k=51)", "ValueError"),
    "k < 3": ("pcl_ddg.estimate_normals(P, k=2)", "ValueError"),
    "negative radius": ("pcl_ddg.estimate_normals(P, radius=-0.1)", "ValueError"),
    "k and radius": ("pcl_ddg.estimate_normals(P, k=8, radius=0.1)", "ValueError"),
    "max_nn without radius": ("pcl_ddg.estimate_normals(P, max_nn=10)", "ValueError"),
    "unknown method": ("pcl_ddg.estimate_normals(P, method='svd')", "ValueError"),
    "rings without faces": ("pcl_ddg.estimate_normals(P, neighbours='rings')", "ValueError"),
    "bfs without faces": ("pcl_ddg.estimate_normals(P, neighbours='bfs')", "ValueError"),
    "grid on a flat cloud": ("pcl_ddg.estimate_normals(P, neighbours='grid')", "ValueError"),
    "viewpoint of 2": ("pcl_ddg.estimate_normals(P, viewpoint=[0, 0])", "ValueError"),
    "zero up": ("pcl_ddg.estimate_normals(P, orient='up', up=[0, 0, 0])", "ValueError"),
    "orient mesh on a cloud": ("pcl_ddg.estimate_normals(P, orient='mesh')", "ValueError"),
    "grid_normals of (n, 3)": ("pcl_ddg.grid_normals(P)", "ValueError"),
    "orient row mismatch": ("pcl_ddg.orient_normals(P, P[:10])", "ValueError"),
    "unknown orientation": ("pcl_ddg.orient_normals(P, P, method='random')", "ValueError"),
    "compare without faces": ("pcl_ddg.compare_neighbourhoods(P, None)", "ValueError"),
    # files
    "missing file": ("pcl_ddg.read('/nonexistent/x.ply')", "OSError"),
    "unknown extension": ("pcl_ddg.read(__file__ if '__file__' in dir() else '/etc/hostname')",
                          "OSError"),
    "write to a missing folder": ("pcl_ddg.write('/nonexistent/x.ply', V)", "OSError"),
    "write unknown format": ("import tempfile, os; pcl_ddg.write(os.path.join("
                             "tempfile.mkdtemp(), 'x.obj2'), V)", "OSError"),
    "write bad colours": ("import tempfile, os; pcl_ddg.write(os.path.join(tempfile.mkdtemp(), "
                          "'x.ply'), V, fields={'rgb': np.ones((12, 3))})", "ValueError"),
}


@pytest.mark.parametrize("name", sorted(CASES))
def test_bad_input_raises(name):
    code, expected = CASES[name]
    script = SETUP + f"""
try:
    {code}
except {expected} as error:
    assert str(error), "an empty message"
    print("RAISED", type(error).__name__, error)
else:
    print("NO EXCEPTION")
"""
    result = python_subprocess(script)
    assert result.returncode == 0, f"crashed or failed ({result.returncode}): {result.stderr}"
    assert "RAISED" in result.stdout, result.stdout + result.stderr


def test_invalid_mesh_error_is_a_value_error():
    import pcl_ddg

    assert issubclass(pcl_ddg.InvalidMeshError, ValueError)
    assert issubclass(pcl_ddg.SurfaceCollapseError, RuntimeError)


# Options of the wrong kind or out of range: ValueError with one line naming the option (never
# pybind11's TypeError listing every argument, the arrays included).
OPTION_CASES = {
    "k beyond int": ("pcl_ddg.estimate_normals(P, k=2**31)", "k"),
    "k a float": ("pcl_ddg.estimate_normals(P, k=16.0)", "k"),
    "k a bool": ("pcl_ddg.orient_normals(P, P, k=True)", "k"),
    "k a string": ("pcl_ddg.principal_curvatures(P, k='20')", "k"),
    "threads negative": ("pcl_ddg.estimate_normals(P, threads=-1)", "threads"),
    "threads a float": ("pcl_ddg.compare_neighbourhoods(V, F, threads=1.5)", "threads"),
    "max_nn a float": ("pcl_ddg.estimate_normals(P, radius=0.2, max_nn=8.0)", "max_nn"),
    "radius a string": ("pcl_ddg.principal_curvatures(P, radius='0.1')", "radius"),
    "method a number": ("pcl_ddg.estimate_normals(P, method=3)", "method"),
    "orient a list": ("pcl_ddg.estimate_normals(P, orient=['up'])", "orient"),
    "iterations a float": ("pcl_ddg.smooth(V, F, iterations=2.5)", "iterations"),
    "lambda_dt a list": ("pcl_ddg.smooth(V, F, lambda_dt=[1.0])", "lambda_dt"),
    "time missing": ("pcl_ddg.smooth_field(V, F, V[:, 0], None)", "time"),
    "epsilon a string": ("pcl_ddg.vertex_normals(V, F, weights='mean_curvature', epsilon='x')",
                         "epsilon"),
    "weights a number": ("pcl_ddg.laplacian(V, F, weights=1)", "weights"),
    "mass a number": ("pcl_ddg.mass_matrix(V, F, mass=2)", "mass"),
    "threads beyond OpenMP": ("pcl_ddg.estimate_normals(P, threads=100000)", "threads"),
    "threads None": ("pcl_ddg.estimate_normals(P, threads=None)", "threads"),
    "iterations None": ("pcl_ddg.smooth(V, F, iterations=None)", "iterations"),
    "weights None": ("pcl_ddg.vertex_normals(V, F, weights=None)", "weights"),
    "mass None": ("pcl_ddg.mass_matrix(V, F, mass=None)", "mass"),
    "k None for orientation": ("pcl_ddg.orient_normals(P, P, k=None)", "k"),
    "a flag not a bool": ("pcl_ddg.smooth(V, F, absolute_time='no')", "absolute_time"),
    "encoding a number": ("pcl_ddg.write('x.ply', V, encoding=1)", "encoding"),
}


@pytest.mark.parametrize("name", sorted(OPTION_CASES))
def test_a_bad_option_is_a_value_error_of_one_line_naming_it(name):
    import numpy as np  # noqa: F401 (the cases' namespace)
    import pcl_ddg  # noqa: F401

    code, option = OPTION_CASES[name]
    namespace: dict = {}
    exec(SETUP, namespace)
    with pytest.raises(ValueError) as error:
        exec(code, namespace)
    message = str(error.value)
    assert message.startswith(option + " ") and "\n" not in message and len(message) < 120, message


@pytest.mark.parametrize("name, content, where", [
    ("random.pcd", bytes(range(255, -1, -1)) * 12, "line 1"),
    ("bad_line.obj", b"v 0 0 0\nv 1 0 0\nv 0 1 0\n\xff\xfe 1 2 3\nf 1 2 3\n", "line 4"),
], ids=["random.pcd", "bad_line.obj"])
def test_a_message_keeps_bytes_that_are_not_utf8(tmp_path, name, content, where):
    """The tool prints these files' bytes in its message; Python escapes them (never '')."""
    import pcl_ddg

    path = tmp_path / name
    path.write_bytes(content)
    with pytest.raises(OSError) as error:
        pcl_ddg.read(path)
    message = str(error.value)
    assert message.startswith(str(path) + ": " + where), message
    assert "\\x" in message, message  # the bytes that are not UTF-8, escaped
