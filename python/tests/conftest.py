"""Shared fixtures: analytic surfaces generated here, the shared scans and the C++ tools."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]


def shared_data() -> Path:
    for candidate in (os.environ.get("PCL_DDG_SHARED_DATA"), ROOT.parent / "shared" / "data",
                      "/work/shared/data"):
        if candidate and (Path(candidate) / "CATALOG.md").exists():
            return Path(candidate)
    pytest.skip("shared data not found (set PCL_DDG_SHARED_DATA)")


def tools_dir() -> Path:
    candidates = [os.environ.get("PCL_DDG_TOOLS_DIR"), ROOT / "build" / "tools"]
    for candidate in candidates:
        if candidate and (Path(candidate) / "pcl_ddg_normals").exists():
            return Path(candidate)
    pytest.skip("the pcl_ddg_* tools are not built (set PCL_DDG_TOOLS_DIR)")


def run_tool(name: str, *args: str) -> None:
    result = subprocess.run([str(tools_dir() / name), *map(str, args)], capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, f"{name} {' '.join(map(str, args))}: {result.stderr}"


def icosphere(level: int, radius: float = 1.0):
    """An icosahedron subdivided `level` times, vertices on the sphere; outward faces."""
    t = (1.0 + 5.0 ** 0.5) / 2.0
    V = [[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t], [0, -1, -t],
         [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]]
    F = [[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
         [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
         [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]]
    V = [np.array(v, float) / np.linalg.norm(v) for v in V]
    for _ in range(level):
        midpoints = {}

        def midpoint(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoints:
                m = V[a] + V[b]
                V.append(m / np.linalg.norm(m))
                midpoints[key] = len(V) - 1
            return midpoints[key]

        refined = []
        for a, b, c in F:
            ab, bc, ca = midpoint(a, b), midpoint(b, c), midpoint(c, a)
            refined += [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
        F = refined
    return radius * np.array(V), np.array(F, dtype=np.int32)


def random_mesh(n: int = 400, seed: int = 1):
    """A jittered grid over a wavy height field: irregular, obtuse triangles, a boundary."""
    rng = np.random.default_rng(seed)
    side = int(np.sqrt(n))
    u, v = np.meshgrid(np.arange(side, dtype=float), np.arange(side, dtype=float))
    u = u + rng.uniform(-0.3, 0.3, u.shape)
    v = v + rng.uniform(-0.3, 0.3, v.shape)
    V = np.stack([u.ravel(), v.ravel(), 0.3 * np.sin(u.ravel()) * np.cos(0.7 * v.ravel())], 1)
    F = []
    for i in range(side - 1):
        for j in range(side - 1):
            a, b, c, d = i * side + j, i * side + j + 1, (i + 1) * side + j, (i + 1) * side + j + 1
            F += [[a, b, d], [a, d, c]] if rng.random() < 0.5 else [[a, b, c], [b, d, c]]
    return V, np.array(F, dtype=np.int64)


@pytest.fixture(scope="session")
def bunny():
    import pcl_ddg

    return pcl_ddg.read(shared_data() / "meshes" / "bunny.off")


def python_subprocess(code: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=300, env=dict(os.environ))


@pytest.fixture
def tool():
    return run_tool


def have_tools() -> bool:
    return shutil.which(str(Path(os.environ.get("PCL_DDG_TOOLS_DIR", ROOT / "build" / "tools"))
                            / "pcl_ddg_normals")) is not None
