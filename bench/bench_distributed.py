#!/usr/bin/env python3
"""pcl_ddg.distributed against the tool alone, on one synthetic survey (a height field of
--points points in flight-line order, jittered, as binary PLY):

1. pcl_ddg_normals -k 16 on the whole file, pinned to one core (the library, like PCL's OMP
   estimators, takes every core the process may run on: OMP_NUM_THREADS alone does not make it
   serial), and on all cores;
2. pcl_ddg.distributed normals -k 16 --merge on a LocalCluster of 1 and of 2 worker processes
   (one thread each), its output compared byte for byte with the tool's;
3. the scheduler's own cost per task (no-op tasks), for docs/distributed.md's projection.

The overhead at 1 worker is (distributed wall - tool wall with one thread) / tool wall. Wall times
include the cluster's start, the bounds pass, the tiles and the merged write.
Usage: PYTHONPATH=build/python python3 bench/bench_distributed.py [--points 10000000]
[--tool build/tools/pcl_ddg_normals] [--memory-per-worker 1G] [--scratch /tmp/...]
"""

import argparse
import filecmp
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

import pcl_ddg
import pcl_ddg.distributed as dd


def survey(path, points, seed=1):
    side = int(np.ceil(np.sqrt(points)))
    rng = np.random.default_rng(seed)
    rows = []
    for j in range(side):  # a flight line at a time: the file is in spatial order, as surveys are
        n = min(side, points - j * side)
        if n <= 0:
            break
        x = np.arange(n, dtype=np.float64) * 0.5 + rng.uniform(-0.1, 0.1, n)
        y = np.full(n, j * 0.5) + rng.uniform(-0.1, 0.1, n)
        z = 3.0 * np.sin(x / 60.0) * np.cos(y / 45.0) + 0.02 * rng.standard_normal(n)
        rows.append(np.stack([x, y, z], 1).astype(np.float32))
    pcl_ddg.write(path, np.concatenate(rows))


def timed(command, cores=None):
    """Wall seconds of command, run on the given cores only (None: every core)."""
    pin = None if cores is None else (lambda: os.sched_setaffinity(0, cores))
    start = time.perf_counter()
    subprocess.run(command, check=True, preexec_fn=pin, stdout=subprocess.DEVNULL,
                   stderr=subprocess.DEVNULL)
    return time.perf_counter() - start


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    here = os.path.dirname(os.path.abspath(__file__))
    parser.add_argument("--points", type=int, default=10_000_000)
    parser.add_argument("--tool", default=os.path.join(here, "..", "build", "tools",
                                                       "pcl_ddg_normals"))
    parser.add_argument("--memory-per-worker", default="1G")
    parser.add_argument("--scratch", default=None)
    parser.add_argument("--workers", default="1,2")
    args = parser.parse_args()
    scratch = args.scratch or tempfile.mkdtemp(prefix="pcl_ddg_bench_distributed_")
    os.makedirs(os.path.join(scratch, "in"), exist_ok=True)
    cloud = os.path.join(scratch, "in", "survey.ply")
    try:
        start = time.perf_counter()
        survey(cloud, args.points)
        print(f"survey: {args.points} points, {os.path.getsize(cloud) >> 20} MiB, written in "
              f"{time.perf_counter() - start:.1f} s", flush=True)
        tool_out = os.path.join(scratch, "tool.ply")
        one_core = {min(os.sched_getaffinity(0))}
        tool1 = timed([args.tool, cloud, tool_out, "-k", "16"], one_core)
        print(f"| tool, 1 thread | {tool1:.1f} s | {args.points / tool1:,.0f} points/s |",
              flush=True)
        tool_all = timed([args.tool, cloud, tool_out, "-k", "16"])
        print(f"| tool, all cores ({os.cpu_count()}) | {tool_all:.1f} s | "
              f"{args.points / tool_all:,.0f} points/s |", flush=True)
        results = {}
        for workers in [int(w) for w in args.workers.split(",")]:
            out = os.path.join(scratch, f"out{workers}")
            shutil.rmtree(out, ignore_errors=True)
            merged = os.path.join(out, "merged.ply")
            start = time.perf_counter()
            summary = dd.estimate_normals([cloud], out, workers=workers, k=16, merge=merged,
                                          memory_per_worker=args.memory_per_worker,
                                          resume=False)
            wall = time.perf_counter() - start
            same = filecmp.cmp(merged, tool_out, shallow=False)
            results[workers] = wall
            print(f"| distributed, {workers} worker(s) | {wall:.1f} s | "
                  f"{args.points / wall:,.0f} points/s | {summary['tiles']} tiles, plan "
                  f"{summary['seconds_plan']:.1f} s, tiles {summary['seconds_tiles']:.1f} s, "
                  f"write {summary['seconds_write']:.1f} s, "
                  f"{summary['halo_growths']} halo growths, worker peak "
                  f"{summary['worker_peak_bytes'] >> 20} MiB, identical to the tool: {same} |",
                  flush=True)
        if 1 in results:
            print(f"overhead at 1 worker over the tool (1 thread): "
                  f"{100 * (results[1] - tool1) / tool1:.0f} %")
        if 1 in results and 2 in results:
            print(f"speed-up 1 -> 2 workers: {results[1] / results[2]:.2f}x")
        # The scheduler's cost per task: no-op tasks on a LocalCluster of 2 workers.
        client = dd.connect(workers=2)
        try:
            n = 2000
            start = time.perf_counter()
            client.gather(client.map(lambda i: i, range(n), pure=False))
            per_task = (time.perf_counter() - start) / n
        finally:
            cluster = client.cluster
            client.close()
            cluster.close()
        print(f"scheduler: {per_task * 1e3:.2f} ms per no-op task ({n} tasks, 2 workers)")
    finally:
        if not args.scratch:
            shutil.rmtree(scratch, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
