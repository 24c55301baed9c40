#!/usr/bin/python3
"""Two builds of pcl_ddg_normals on the same 10M-point clouds, in the same run: the cost of a
change, its own baseline being the build before it (e.g. a worktree of the previous commit).

The clouds: a terrain of 10 million points over 3 km x 3 km (heights 180-220 m, a centimetre
grid, stored in no spatial order), once as float coordinates near the origin and once as double
coordinates at UTM-sized values (500,000 m east, 5,000,000 m north), each written once into a
temporary folder. PCA, k = 16. The two builds alternate run after run, so that a load on a shared
machine falls on both alike; medians of the repetitions (default 3) of the fit's own time (the
tool's "Computing", "Estimating" and "Fitting" lines) and of the whole process.

    /usr/bin/python3 bench/bench_two_builds.py BEFORE_TOOL AFTER_TOOL [repetitions]
"""
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

POINTS = 10_000_000


def write_ply(path, xyz, dtype):
    kind = "double" if dtype == np.float64 else "float"
    header = ("ply\nformat binary_little_endian 1.0\nelement vertex %d\n" % len(xyz) +
              "".join("property %s %s\n" % (kind, c) for c in "xyz") + "end_header\n")
    with open(path, "wb") as out:
        out.write(header.encode())
        out.write(np.ascontiguousarray(xyz, dtype="<f8" if kind == "double" else "<f4").tobytes())


def terrain(seed=46):
    rng = np.random.default_rng(seed)
    xy = np.round(rng.uniform(0.0, 3000.0, (POINTS, 2)), 2)
    z = 200.0 + 10.0 * np.sin(xy[:, 0] / 300.0) * np.cos(xy[:, 1] / 400.0)
    z = np.round(z + rng.normal(0.0, 0.05, POINTS), 2)
    return np.column_stack([xy, z])


def timed(tool, cloud, out):
    start = time.perf_counter()
    run = subprocess.run([tool, cloud, out, "-k", "16", "-method", "pca"], capture_output=True,
                         text=True)
    total = time.perf_counter() - start
    if run.returncode != 0:
        sys.exit("%s failed: %s" % (tool, run.stderr.strip().splitlines()[-1]))
    phases = re.findall(r"> (?:Computing|Estimating|Fitting)[^\[]*\[done, ([0-9.]+) (ms|s)", run.stderr)
    fit = sum(float(value) / (1000.0 if unit == "ms" else 1.0) for value, unit in phases)
    return fit, total


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    tools = {"before": sys.argv[1], "after": sys.argv[2]}
    repetitions = int(sys.argv[3]) if len(sys.argv) > 3 else 3
    with tempfile.TemporaryDirectory() as folder:
        xyz = terrain()
        clouds = {"float, near the origin": os.path.join(folder, "float.ply"),
                  "double, at UTM offsets": os.path.join(folder, "utm.ply")}
        write_ply(clouds["float, near the origin"], xyz, np.float32)
        write_ply(clouds["double, at UTM offsets"], xyz + [500_000.0, 5_000_000.0, 0.0],
                  np.float64)
        del xyz
        out = os.path.join(folder, "out.ply")
        for name, cloud in clouds.items():
            times = {tool: ([], []) for tool in tools}
            for _ in range(repetitions):
                for tool, path in tools.items():
                    fit, total = timed(path, cloud, out)
                    times[tool][0].append(fit)
                    times[tool][1].append(total)
            fit = {tool: statistics.median(times[tool][0]) for tool in tools}
            total = {tool: statistics.median(times[tool][1]) for tool in tools}
            print("%-24s fit %6.2f s -> %6.2f s (x%.3f) | process %6.2f s -> %6.2f s (x%.3f)" % (
                name, fit["before"], fit["after"], fit["after"] / fit["before"], total["before"],
                total["after"], total["after"] / total["before"]))


if __name__ == "__main__":
    main()
