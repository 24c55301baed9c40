#!/usr/bin/python3
"""LAS end to end, as a user runs it, on a 10M-point LAS 1.2 point format 3 file the script makes
(an aerial-like terrain: 3 km x 3 km, centimetre scale, UTM offsets, records in flight-line order
with GPS time, intensity, classification and colour; 340 MB):

  pcl_ddg_info survey.las                        what the file holds (duplicates, spacing, ...)
  pcl_ddg_normals survey.las out.las -k 16       PCA normals, written as Extra Bytes
  library: pcl_ddg.read + estimate_normals(k=16, orient="up") + pcl_ddg.write(las=...)
           in one Python process (the same work through the library; timed inside, without the
           interpreter's start and import)
  pcl_ddg_normals survey.pcd out.pcd -k 16       the same points as a float x y z PCD (about
           their offset, as a PCL user stores them; 114 MiB), to a compressed PCD

Each is a fresh process: its wall time, peak resident memory and minor page faults
(/usr/bin/time -f '%M %R'), medians of the repetitions (default 3), run alternately so that a
load on a shared machine falls on all alike. The tool's time against the library's is the
"tools as fast as the library" ratio; the input file's size is printed beside the peaks.

    /usr/bin/python3 bench/bench_las_end_to_end.py BUILD_DIR [repetitions] [points]
    (BUILD_DIR holds tools/ and python/: a build with the Python module)
"""
import os
import statistics
import struct
import sys
import tempfile

import numpy as np

from fresh_process import environment, machine_state, measured

LIBRARY_JOB = """
import sys, time
sys.path.insert(0, sys.argv[3])
import pcl_ddg
start = time.perf_counter()
cloud = pcl_ddg.read(sys.argv[1])
n = pcl_ddg.estimate_normals(cloud, k=16)
# float32, as the tool writes them (its default -precision float)
pcl_ddg.write(sys.argv[2], cloud.points, fields={**cloud.fields,
              "normals": n.normals.astype("float32"), "curvature": n.curvature.astype("float32")},
              las=cloud.las)
print(time.perf_counter() - start)
"""


def write_las(path, points, seed=50):
    """A LAS 1.2 file of point format 3 (34-byte records): a terrain sampled along flight lines
    (east-west strips, each scanned in GPS-time order), scale 0.01 m, offset at UTM values."""
    rng = np.random.default_rng(seed)
    strips = 40
    per_strip = points // strips
    n = per_strip * strips
    x = rng.uniform(0.0, 3000.0, n)
    y = (np.repeat(np.arange(strips), per_strip) + rng.uniform(0.0, 1.0, n)) * (3000.0 / strips)
    order = np.argsort(np.repeat(np.arange(strips), per_strip) * 4000.0 + x, kind="stable")
    x, y = x[order], y[order]
    z = 200.0 + 10.0 * np.sin(x / 300.0) * np.cos(y / 400.0) + rng.normal(0.0, 0.05, n)
    offset = np.array([500_000.0, 5_000_000.0, 0.0])
    scale = 0.01
    xyz = np.column_stack([x, y, z]) + offset
    ints = np.round((xyz - offset) / scale).astype(np.int32)
    record = np.dtype([("X", "<i4"), ("Y", "<i4"), ("Z", "<i4"), ("intensity", "<u2"),
                       ("flags", "u1"), ("classification", "u1"), ("scan_angle", "i1"),
                       ("user_data", "u1"), ("source", "<u2"), ("gps_time", "<f8"),
                       ("red", "<u2"), ("green", "<u2"), ("blue", "<u2")])
    records = np.zeros(n, dtype=record)
    records["X"], records["Y"], records["Z"] = ints[:, 0], ints[:, 1], ints[:, 2]
    records["intensity"] = rng.integers(0, 4096, n)
    records["flags"] = 0x09  # return 1 of 1
    records["classification"] = np.where(rng.uniform(size=n) < 0.6, 2, 5)
    records["source"] = 1 + np.arange(n) // per_strip
    records["gps_time"] = 1.0e8 + np.arange(n) * 1e-5
    records["red"], records["green"], records["blue"] = 20000, 30000, 10000
    exact = ints * scale + offset
    header_size = 227
    header = bytearray(header_size)
    header[0:4] = b"LASF"
    struct.pack_into("<BB", header, 24, 1, 2)
    header[26:58] = b"pcl_ddg bench".ljust(32, b"\0")
    header[58:90] = b"bench_las_end_to_end.py".ljust(32, b"\0")
    struct.pack_into("<HHHIIBHI", header, 90, 1, 2026, header_size, header_size, 0, 3,
                     record.itemsize, n)
    struct.pack_into("<5I", header, 111, n, 0, 0, 0, 0)
    struct.pack_into("<3d3d", header, 131, scale, scale, scale, *offset)
    mins, maxs = exact.min(axis=0), exact.max(axis=0)
    struct.pack_into("<6d", header, 179, maxs[0], mins[0], maxs[1], mins[1], maxs[2], mins[2])
    with open(path, "wb") as out:
        out.write(header)
        out.write(records.tobytes())
    return n, exact - offset


def write_pcd(path, xyz):
    """A binary PCD of x y z as float32."""
    n = len(xyz)
    header = ("# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
              f"WIDTH {n}\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS {n}\nDATA binary\n")
    with open(path, "wb") as out:
        out.write(header.encode())
        out.write(xyz.astype("<f4").tobytes())


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    build = sys.argv[1]
    repetitions = int(sys.argv[2]) if len(sys.argv) > 2 else 3
    points = int(sys.argv[3]) if len(sys.argv) > 3 else 10_000_000
    print(machine_state())
    with tempfile.TemporaryDirectory(prefix="pcl_ddg_las_e2e_") as folder:
        survey = os.path.join(folder, "survey.las")
        n, local = write_las(survey, points)
        size = os.path.getsize(survey) / 2**20
        print(f"{survey}: {n} points, point format 3, {size:.0f} MiB; {os.cpu_count()} cores")
        survey_pcd = os.path.join(folder, "survey.pcd")
        write_pcd(survey_pcd, local)
        del local
        sizes = {"pcl_ddg_normals survey.pcd -k 16": os.path.getsize(survey_pcd) / 2**20}
        tools = os.path.join(build, "tools")
        info = [os.path.join(tools, "pcl_ddg_info"), survey]

        def normals(output):
            return [os.path.join(tools, "pcl_ddg_normals"), survey, os.path.join(folder, output),
                    "-k", "16"]
        # The tools also without the huge pages they ask glibc for on a large input
        # (tools/common/huge_pages.h): what those give on this machine, in the same run.
        huge_pages, small_pages = environment(), environment(PCL_DDG_HUGE_PAGES="0")
        jobs = {
            "pcl_ddg_info": (info, huge_pages),
            "pcl_ddg_info, PCL_DDG_HUGE_PAGES=0": (info, small_pages),
            "pcl_ddg_normals -k 16": (normals("tool.las"), huge_pages),
            "pcl_ddg_normals, PCL_DDG_HUGE_PAGES=0": (normals("tool_small_pages.las"), small_pages),
            "library read + fit + write": ([sys.executable, "-c", LIBRARY_JOB, survey,
                                            os.path.join(folder, "library.las"),
                                            os.path.join(build, "python")], huge_pages),
            "pcl_ddg_normals survey.pcd -k 16": ([os.path.join(tools, "pcl_ddg_normals"),
                                                  survey_pcd, os.path.join(folder, "tool.pcd"),
                                                  "-k", "16"], huge_pages),
        }
        runs = {name: [] for name in jobs}
        for repetition in range(repetitions):
            # The order reverses every other repetition: on a fresh machine whichever runs first
            # touches memory anew.
            names = list(jobs) if repetition % 2 == 0 else list(reversed(jobs))
            for name in names:
                command, env = jobs[name]
                runs[name].append(measured(command, env))
        outputs = {"pcl_ddg_normals -k 16": os.path.join(folder, "tool.las"),
                   "pcl_ddg_normals, PCL_DDG_HUGE_PAGES=0": os.path.join(folder, "tool_small_pages.las"),
                   "library read + fit + write": os.path.join(folder, "library.las"),
                   "pcl_ddg_normals survey.pcd -k 16": os.path.join(folder, "tool.pcd")}
        for name, results in runs.items():
            wall = statistics.median(r[0] for r in results)
            line = (f"{name:38s} {wall:7.2f} s  peak {statistics.median(r[2] for r in results):6.0f}"
                    f" MB  {statistics.median(r[3] for r in results):8.0f} minor faults")
            if name in outputs:
                out = os.path.getsize(outputs[name]) / 2**20
                read = sizes.get(name, size)
                peak = statistics.median(r[2] for r in results)
                line += (f"  (input {read:.0f} + output {out:.0f} MiB: peak"
                         f" {peak / (read + out):.2f}x)")
            if name.startswith("library"):
                line += f"; the calls alone {statistics.median(float(r[1]) for r in results):.2f} s"
            print(line)
        tool = statistics.median(r[0] for r in runs["pcl_ddg_normals -k 16"])
        library = statistics.median(float(r[1]) for r in runs["library read + fit + write"])
        print(f"tool / library calls: {tool / library:.2f}")
        library_bytes = open(outputs["library read + fit + write"], "rb").read()
        for name in ("pcl_ddg_normals -k 16", "pcl_ddg_normals, PCL_DDG_HUGE_PAGES=0"):
            same = open(outputs[name], "rb").read() == library_bytes
            print(f"{name}: its .las and the library's are "
                  + ("the same bytes" if same else "different"))


if __name__ == "__main__":
    main()
