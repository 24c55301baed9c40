#!/usr/bin/env python3
"""The Python module's cost, in one run:

1. the binding's overhead over the C++ call on the 1.15M-vertex bench torus (1600 x 720, as
   bench_support.cpp builds it): area normals, the cotan Laplacian, curvatures. The C++ time is
   the library's own (topology + operator, GIL released), measured inside the binding and read
   back with _pcl_ddg._last_compute_seconds(); the overhead is what the Python call costs beyond
   it (validation, reading the arrays, wrapping the results, scipy's csr_matrix). Target <= 5 %.
2. estimate_normals (pca, k = 16) against Open3D's estimate_normals (KNN 16, Debian's
   python3-open3d) and the pcl_ddg_normals tool on the same 1M-point cloud (the torus' points).
3. write of the torus with its faces (binary PLY) against the tool's own save of the same mesh
   (pcl_ddg_normals' "Saving" line, normals added). Target <= 1.5x.

Medians of --repeat runs. Usage: PYTHONPATH=build/python python3 bench/bench_python.py
[--tool build/tools/pcl_ddg_normals] [--repeat 5]
"""

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

import pcl_ddg
from pcl_ddg import _pcl_ddg


def torus(around=1600, tube=720):
    u = 2 * np.pi * np.arange(around) / around
    v = 2 * np.pi * np.arange(tube) / tube
    vv, uu = np.meshgrid(v, u, indexing="ij")  # vertex j * around + i
    V = np.stack([(1 + 0.4 * np.cos(vv)) * np.cos(uu), (1 + 0.4 * np.cos(vv)) * np.sin(uu),
                  0.4 * np.sin(vv)], axis=-1).reshape(-1, 3)
    j, i = np.meshgrid(np.arange(tube), np.arange(around), indexing="ij")
    a = j * around + i
    b = j * around + (i + 1) % around
    c = ((j + 1) % tube) * around + (i + 1) % around
    d = ((j + 1) % tube) * around + i
    F = np.stack([np.stack([a, b, c], -1), np.stack([a, c, d], -1)], axis=2).reshape(-1, 3)
    return np.ascontiguousarray(V), F.astype(np.int32)


def overhead(name, call, repeat):
    walls, library = [], []
    for _ in range(repeat):
        start = time.perf_counter()
        call()
        walls.append(time.perf_counter() - start)
        library.append(_pcl_ddg._last_compute_seconds())
    wall, cpp = statistics.median(walls), statistics.median(library)
    share = (wall - cpp) / cpp
    print(f"{name:28s} Python {wall * 1e3:8.1f} ms  C++ {cpp * 1e3:8.1f} ms  overhead "
          f"{100 * share:5.1f} %")
    return share


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tool", default=os.path.join("build", "tools", "pcl_ddg_normals"))
    parser.add_argument("--repeat", type=int, default=5)
    parser.add_argument("--points", type=int, default=1_000_000)
    args = parser.parse_args()

    V, F = torus()
    print(f"torus: {V.shape[0]} vertices, {F.shape[0]} triangles; {os.cpu_count()} cores")
    shares = [
        overhead("vertex_normals (area)", lambda: pcl_ddg.vertex_normals(V, F), args.repeat),
        overhead("laplacian (cotan)", lambda: pcl_ddg.laplacian(V, F), args.repeat),
        overhead("curvatures", lambda: pcl_ddg.curvatures(V, F), args.repeat),
    ]

    rng = np.random.default_rng(0)
    points = V[rng.choice(V.shape[0], args.points, replace=False)]
    points = points + 1e-4 * rng.standard_normal(points.shape)  # no exact grid ties
    times = []
    for _ in range(args.repeat):
        start = time.perf_counter()
        ours = pcl_ddg.estimate_normals(points, k=16)
        times.append(time.perf_counter() - start)
    t_ours = statistics.median(times)
    print(f"estimate_normals pca k=16 on {args.points} points: {t_ours * 1e3:.0f} ms")

    t_open3d = None
    try:
        import open3d as o3d

        cloud = o3d.geometry.PointCloud(o3d.utility.Vector3dVector(points))
        times = []
        for _ in range(args.repeat):
            cloud.normals = o3d.utility.Vector3dVector()
            start = time.perf_counter()
            cloud.estimate_normals(o3d.geometry.KDTreeSearchParamKNN(16))
            times.append(time.perf_counter() - start)
        t_open3d = statistics.median(times)
        theirs = np.asarray(cloud.normals)
        agree = np.abs(np.einsum("ij,ij->i", ours.normals, theirs))
        print(f"Open3D estimate_normals KNN 16: {t_open3d * 1e3:.0f} ms "
              f"(ours / Open3D = {t_ours / t_open3d:.2f}; median |n . n_o3d| "
              f"{np.median(agree):.6f})")
    except ImportError:
        print("Open3D not installed (Debian: python3-open3d): skipped")

    if os.path.exists(args.tool):
        with tempfile.TemporaryDirectory() as folder:
            source = os.path.join(folder, "cloud.pcd")
            pcl_ddg.write(source, points)
            times = []
            for _ in range(args.repeat):
                start = time.perf_counter()
                subprocess.run([args.tool, source, os.path.join(folder, "out.pcd"), "-method",
                                "pca", "-k", "16"], check=True, capture_output=True)
                times.append(time.perf_counter() - start)
            print(f"pcl_ddg_normals (load, fit, save): {statistics.median(times) * 1e3:.0f} ms")

    write_ratio = None
    if os.path.exists(args.tool):
        with tempfile.TemporaryDirectory() as folder:
            mesh = os.path.join(folder, "torus.ply")
            times, saves = [], []
            for _ in range(args.repeat):
                start = time.perf_counter()
                pcl_ddg.write(mesh, V, F)
                times.append(time.perf_counter() - start)
                run = subprocess.run([args.tool, mesh, os.path.join(folder, "out.ply")],
                                     check=True, capture_output=True, text=True)
                saves.append(float(re.search(r"> Saving .*?\[done, ([0-9.]+) ms", run.stderr)[1]))
            t_write, t_save = statistics.median(times), statistics.median(saves) / 1e3
            write_ratio = t_write / t_save
            print(f"write with faces ({F.shape[0]} triangles): {t_write * 1e3:.0f} ms; the tool's "
                  f"save of the same mesh {t_save * 1e3:.0f} ms (ratio {write_ratio:.2f})")

    ok = max(shares) <= 0.05 and (t_open3d is None or t_ours <= t_open3d) and (
        write_ratio is None or write_ratio <= 1.5)
    print("PASS" if ok else "over target (overhead 5 %, Open3D ratio 1, write 1.5x)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
