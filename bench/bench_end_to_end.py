#!/usr/bin/python3
"""End to end, as a user runs it: read an ascii OFF of a 1.15M-vertex mesh, compute area-weighted
vertex normals, write a binary PLY. pcl_ddg_normals (a process, everything included) against
Open3D's read_triangle_mesh + compute_vertex_normals + write_triangle_mesh in the same run.
The two alternate, run after run, so that a load on a shared machine falls on both alike;
medians of the repetitions (default 5) and of the runs' pairwise ratios. The mesh (the bench
torus, 1600 x 720 grid) is generated once into a temporary folder.

    /usr/bin/python3 bench/bench_end_to_end.py build/tools/pcl_ddg_normals [repetitions]
    (Debian's python: python3-open3d)
"""
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time


def write_torus_off(path, around=1600, tube=720, major=1.0, minor=0.4):
    lines = [f"OFF\n{around * tube} {2 * around * tube} 0\n"]
    for i in range(around):
        cu, su = math.cos(2 * math.pi * i / around), math.sin(2 * math.pi * i / around)
        for j in range(tube):
            cv, sv = math.cos(2 * math.pi * j / tube), math.sin(2 * math.pi * j / tube)
            lines.append("%.9g %.9g %.9g\n" % ((major + minor * cv) * cu, (major + minor * cv) * su,
                                               minor * sv))
    for i in range(around):
        for j in range(tube):
            a, b = i * tube + j, ((i + 1) % around) * tube + j
            c, d = ((i + 1) % around) * tube + (j + 1) % tube, i * tube + (j + 1) % tube
            lines.append(f"3 {a} {b} {c}\n3 {a} {c} {d}\n")
    with open(path, "w") as f:
        f.write("".join(lines))


def seconds(run):
    start = time.perf_counter()
    run()
    return time.perf_counter() - start


def main():
    tool = sys.argv[1] if len(sys.argv) > 1 else "build/tools/pcl_ddg_normals"
    repetitions = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    folder = tempfile.mkdtemp(prefix="pcl_ddg_e2e_")
    mesh = os.path.join(folder, "torus.off")
    write_torus_off(mesh)
    print(f"mesh: {mesh} ({os.path.getsize(mesh) / 1e6:.0f} MB ascii OFF)")

    def ours_run():
        subprocess.run([tool, mesh, os.path.join(folder, "ours.ply"), "-method", "area"],
                       check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)

    try:
        import open3d
    except ImportError:
        ours = statistics.median(seconds(ours_run) for _ in range(repetitions))
        print(f"pcl_ddg_normals -method area     {ours * 1000:8.0f} ms")
        print("open3d not installed (apt-get install python3-open3d): no baseline")
        return
    open3d.utility.set_verbosity_level(open3d.utility.VerbosityLevel.Error)

    def open3d_run():
        m = open3d.io.read_triangle_mesh(mesh)
        m.compute_vertex_normals()
        open3d.io.write_triangle_mesh(os.path.join(folder, "open3d.ply"), m,
                                      write_ascii=False, compressed=False)

    ours, theirs = [], []
    for _ in range(repetitions):
        ours.append(seconds(ours_run))
        theirs.append(seconds(open3d_run))
    print(f"pcl_ddg_normals -method area     {statistics.median(ours) * 1000:8.0f} ms")
    print(f"Open3D read + normals + write    {statistics.median(theirs) * 1000:8.0f} ms")
    ratios = sorted(t / o for o, t in zip(ours, theirs))
    print(f"ratio: ours {statistics.median(theirs) / statistics.median(ours):.2f}x faster "
          f"(median of the runs' ratios {statistics.median(ratios):.2f}x, "
          f"range {ratios[0]:.2f}-{ratios[-1]:.2f}x, {repetitions} runs each)")


if __name__ == "__main__":
    main()
