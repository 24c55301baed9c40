#!/usr/bin/python3
"""End to end, as a user runs it: read an ascii OFF of a 1.15M-vertex mesh, compute area-weighted
vertex normals, write a binary PLY. pcl_ddg_normals (a process, everything included) against
Open3D's read_triangle_mesh + compute_vertex_normals + write_triangle_mesh in the same run.
The two alternate, run after run, so that a load on a shared machine falls on both alike;
medians of the repetitions (default 5) and of the runs' pairwise ratios. Each run is a fresh
process, ours and Open3D's (a Python running the three calls), and prints its peak resident
memory and minor page faults beside its time (/usr/bin/time -f '%M %R'); Open3D's time is that of its three calls, without the interpreter's
start and import. The mesh (the bench torus, 1600 x 720 grid) is generated once into a temporary
folder.

    /usr/bin/python3 bench/bench_end_to_end.py build/tools/pcl_ddg_normals [repetitions]
    (Debian's python: python3-open3d)
"""
import math
import os
import statistics
import sys
import tempfile

from fresh_process import environment, machine_state, measured


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


OPEN3D_JOB = """
import sys, time
import open3d
open3d.utility.set_verbosity_level(open3d.utility.VerbosityLevel.Error)
mesh_path, out_path = sys.argv[1], sys.argv[2]
start = time.perf_counter()
if mesh_path:
    m = open3d.io.read_triangle_mesh(mesh_path)
    m.compute_vertex_normals()
    open3d.io.write_triangle_mesh(out_path, m, write_ascii=False, compressed=False)
print(time.perf_counter() - start)
"""


def main():
    tool = sys.argv[1] if len(sys.argv) > 1 else "build/tools/pcl_ddg_normals"
    repetitions = int(sys.argv[2]) if len(sys.argv) > 2 else 5
    print(machine_state())  # before the mesh is written: its page cache is touched memory too
    folder = tempfile.mkdtemp(prefix="pcl_ddg_e2e_")
    mesh = os.path.join(folder, "torus.off")
    write_torus_off(mesh)
    print(f"mesh: {mesh} ({os.path.getsize(mesh) / 1e6:.0f} MB ascii OFF)")
    ours_command = [tool, mesh, os.path.join(folder, "ours.ply"), "-method", "area"]
    # The tool as it runs, and without the huge pages it asks glibc for on a large input
    # (tools/common/huge_pages.h): what they give on this machine, in the same run.
    huge_pages, small_pages = environment(), environment(PCL_DDG_HUGE_PAGES="0")
    try:
        import open3d  # noqa: F401  (only whether it is there)
    except ImportError:
        for name, env in (("", huge_pages), (", PCL_DDG_HUGE_PAGES=0", small_pages)):
            runs = [measured(ours_command, env) for _ in range(repetitions)]
            print(f"pcl_ddg_normals -method area{name}"
                  f"  {statistics.median(r[0] for r in runs) * 1000:8.0f} ms"
                  f"  peak {statistics.median(r[2] for r in runs):6.0f} MB"
                  f"  {statistics.median(r[3] for r in runs):8.0f} minor faults")
        print("open3d not installed (apt-get install python3-open3d): no baseline")
        return
    theirs_command = [sys.executable, "-c", OPEN3D_JOB, mesh, os.path.join(folder, "open3d.ply")]
    # Open3D's process includes Python and the import: what an empty job costs is printed too.
    baseline = measured([sys.executable, "-c", OPEN3D_JOB, "", ""])
    ours, ours_small, theirs = [], [], []
    for repetition in range(repetitions):
        # Which of ours runs first alternates: on a fresh machine the first touches memory anew.
        first, second = (huge_pages, small_pages) if repetition % 2 == 0 else (small_pages, huge_pages)
        runs = {id(first): measured(ours_command, first)}
        runs[id(second)] = measured(ours_command, second)
        ours.append(runs[id(huge_pages)])
        ours_small.append(runs[id(small_pages)])
        theirs.append(measured(theirs_command))
    o_time = statistics.median(r[0] for r in ours)
    t_time = statistics.median(float(r[1]) for r in theirs)
    print(f"pcl_ddg_normals -method area (the process)  {o_time * 1000:8.0f} ms"
          f"  peak {statistics.median(r[2] for r in ours):6.0f} MB"
          f"  {statistics.median(r[3] for r in ours):8.0f} minor faults")
    print(f"  the same, PCL_DDG_HUGE_PAGES=0            "
          f"{statistics.median(r[0] for r in ours_small) * 1000:8.0f} ms"
          f"  peak {statistics.median(r[2] for r in ours_small):6.0f} MB"
          f"  {statistics.median(r[3] for r in ours_small):8.0f} minor faults")
    print(f"Open3D read + normals + write (the calls)   {t_time * 1000:8.0f} ms"
          f"  peak {statistics.median(r[2] for r in theirs):6.0f} MB"
          f"  {statistics.median(r[3] for r in theirs):8.0f} minor faults (the process)")
    print(f"  of which Python + import open3d alone:   peak {baseline[2]:6.0f} MB"
          f"  {baseline[3]:8.0f} minor faults")
    ratios = sorted(float(t[1]) / o[0] for o, t in zip(ours, theirs))
    print(f"ratio: ours {t_time / o_time:.2f}x faster "
          f"(median of the runs' ratios {statistics.median(ratios):.2f}x, "
          f"range {ratios[0]:.2f}-{ratios[-1]:.2f}x, {repetitions} runs each, fresh processes)")


if __name__ == "__main__":
    main()
