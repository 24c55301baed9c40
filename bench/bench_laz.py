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
import subprocess
import sys
import tempfile
import warnings

import numpy as np

from bench_las_end_to_end import write_las

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python",
                                "tests"))
from lazperf_oracle import decode, lazperf_folder  # noqa: E402

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
                records, seconds = decode(node, lazs[las], repeats=3)
                with open(las, "rb") as f:
                    ours = f.read()
                at = int.from_bytes(ours[96:100], "little")
                length = int.from_bytes(ours[105:107], "little")
                peer = len(records) // length / seconds
                same = len(records) == points * length and ours[at:at + len(records)] == records
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
