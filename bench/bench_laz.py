#!/usr/bin/python3
"""LAZ decode and encode speed, ours beside laz-perf (LAZperf's WebAssembly build, run by node) in
the same run, on two 5M-point files the script makes: LAS 1.2 point format 3 (34-byte records,
bench_las_end_to_end.py's terrain) and the same points as LAS 1.4 format 7 (pcl_ddg.write without
a layout). Ours: build/bench/bench_laz (lazToLas with 1 and 2 threads, lasToLaz, and our
uncompressed LAS read of the same file); laz-perf decodes the LAZ our encoder wrote, and its
records are compared with the LAS file's (an independent decoder of what we write).

laz-perf is installed from the npm registry into ~/.cache/pcl_ddg_bench/node on first use (a
benchmark peer and test oracle only, never shipped); without node and npm its column is empty.

    /usr/bin/python3 bench/bench_laz.py BUILD_DIR [points]
"""
import json
import os
import shutil
import subprocess
import sys
import tempfile
import warnings

import numpy as np

from bench_las_end_to_end import write_las

LAZPERF_JOB = r"""
const fs = require('fs');
const { createLazPerf } = require('laz-perf');
(async () => {
  const [lazPath, lasPath] = process.argv.slice(2);
  const lp = await createLazPerf();
  const laz = fs.readFileSync(lazPath);
  const filePtr = lp._malloc(laz.length);
  lp.HEAPU8.set(laz, filePtr);
  let best = Infinity, out = null, count = 0, len = 0;
  for (let rep = 0; rep < 3; ++rep) {
    const t0 = process.hrtime.bigint();
    const reader = new lp.LASZip();
    reader.open(filePtr, laz.length);
    count = reader.getCount(); len = reader.getPointLength();
    const point = lp._malloc(len);
    out = Buffer.alloc(count * len);
    for (let i = 0; i < count; ++i) {
      reader.getPoint(point);
      out.set(lp.HEAPU8.subarray(point, point + len), i * len);
    }
    lp._free(point);
    reader.delete();
    best = Math.min(best, Number(process.hrtime.bigint() - t0) / 1e9);
  }
  const las = fs.readFileSync(lasPath);
  const at = las.readUInt32LE(96);
  console.log(JSON.stringify({seconds: best, points: count,
                              same: las.subarray(at, at + count * len).equals(out)}));
})();
"""


def lazperf_folder():
    """A folder whose node_modules holds laz-perf, or None without node and npm."""
    if not (shutil.which("node") and shutil.which("npm")):
        return None
    folder = os.path.expanduser("~/.cache/pcl_ddg_bench/node")
    if not os.path.isdir(os.path.join(folder, "node_modules", "laz-perf")):
        os.makedirs(folder, exist_ok=True)
        subprocess.run(["npm", "install", "--silent", "--prefix", folder, "laz-perf"], check=True)
    return folder


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    build = sys.argv[1]
    points = int(sys.argv[2]) if len(sys.argv) > 2 else 5_000_000
    sys.path.insert(0, os.path.join(build, "python"))
    import pcl_ddg

    with tempfile.TemporaryDirectory(prefix="pcl_ddg_laz_") as folder:
        f3 = os.path.join(folder, "format3.las")
        write_las(f3, points)
        m = pcl_ddg.read(f3)
        f7 = os.path.join(folder, "format7.las")
        fields = {k: m.fields[k] for k in ("intensity", "classification", "gps_time")}
        fields["rgb"] = np.column_stack([m.fields[c] >> 8 for c in ("red", "green", "blue")]
                                        ).astype(np.uint8)
        with warnings.catch_warnings():  # (no input layout to keep: a new LAS 1.4 file)
            warnings.simplefilter("ignore")
            pcl_ddg.write(f7, m.points, fields=fields)
        lazs = {}
        for las in (f3, f7):
            m = pcl_ddg.read(las)
            lazs[las] = las[:-4] + ".laz"
            pcl_ddg.write(lazs[las], m.points, fields=m.fields, las=m.las)
        del m
        run = subprocess.run([os.path.join(build, "bench", "bench_laz"), f3, f7,
                              "--benchmark_repetitions=3", "--benchmark_report_aggregates_only",
                              "--benchmark_format=json"], check=True, capture_output=True,
                             text=True)
        rates = {}
        for b in json.loads(run.stdout)["benchmarks"]:
            if b.get("aggregate_name") == "median":
                rates[b["run_name"]] = b["points/s"]
        node = lazperf_folder()
        print(f"{points} points; {os.cpu_count()} cores; million points per second, medians of 3")
        print("| file | decode, 1 thread | decode, 2 threads | laz-perf decode | ratio (2 threads) "
              "| encode | our LAS read | LAZ / LAS size |")
        print("|---|---|---|---|---|---|---|---|")
        for name, las in (("format 3", f3), ("format 7", f7)):
            peer, same = None, None
            if node:
                script = os.path.join(folder, "lazperf_job.js")
                with open(script, "w") as out:
                    out.write(LAZPERF_JOB)
                job = subprocess.run(["node", script, lazs[las], las], check=True,
                                     capture_output=True, text=True,
                                     env=dict(os.environ, NODE_PATH=os.path.join(node,
                                                                                 "node_modules")))
                result = json.loads(job.stdout)
                peer, same = result["points"] / result["seconds"], result["same"]
            one = rates[f"laz_decode/{las}/1/real_time"]
            two = rates[f"laz_decode/{las}/2/real_time"]
            size = os.path.getsize(lazs[las]) / os.path.getsize(las)
            print(f"| {name} | {one / 1e6:.2f} | {two / 1e6:.2f} | "
                  f"{'-' if peer is None else f'{peer / 1e6:.2f}'} | "
                  f"{'-' if peer is None else f'{two / peer:.2f}x'} | "
                  f"{rates[f'laz_encode/{las}/real_time'] / 1e6:.2f} | "
                  f"{rates[f'las_read/{las}/real_time'] / 1e6:.2f} | {size:.3f} |")
            if same is not None:
                print(f"  laz-perf decodes our {name} LAZ to the LAS records: {same}")


if __name__ == "__main__":
    main()
