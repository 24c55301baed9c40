"""LAZperf (its WebAssembly build from the npm registry, run by node) as an independent LAZ
decoder: a test oracle for what our encoder writes (python/tests/test_las.py) and the peer of
bench/bench_laz.py. Never shipped; installed into ~/.cache/pcl_ddg_bench/node on first use."""
import json
import os
import shutil
import subprocess
import tempfile

# Decodes a LAZ file `repeats` times (timed inside node, its start-up left out), writes the
# records of the last decode to a file and prints the best time and the point count as JSON.
DECODE_JOB = r"""
const fs = require('fs');
const { createLazPerf } = require('laz-perf');
(async () => {
  const [lazPath, outPath, repeats] = process.argv.slice(2);
  const lp = await createLazPerf();
  const laz = fs.readFileSync(lazPath);
  const file = lp._malloc(laz.length);
  lp.HEAPU8.set(laz, file);
  let best = Infinity, out = null, count = 0;
  for (let rep = 0; rep < Number(repeats); ++rep) {
    const t0 = process.hrtime.bigint();
    const reader = new lp.LASZip();
    reader.open(file, laz.length);
    count = reader.getCount();
    const len = reader.getPointLength(), point = lp._malloc(len);
    out = Buffer.alloc(count * len);
    for (let i = 0; i < count; ++i) {
      reader.getPoint(point);
      out.set(lp.HEAPU8.subarray(point, point + len), i * len);
    }
    lp._free(point);
    reader.delete();
    best = Math.min(best, Number(process.hrtime.bigint() - t0) / 1e9);
  }
  fs.writeFileSync(outPath, out);
  console.log(JSON.stringify({seconds: best, points: count}));
})();
"""

CACHE = os.path.expanduser("~/.cache/pcl_ddg_bench/node")


def lazperf_folder():
    """The folder whose node_modules holds laz-perf (installed from npm on first use), or None
    without node and npm or when the install fails (its error then in lazperf_folder.error)."""
    lazperf_folder.error = "node and npm are not installed"
    if not (shutil.which("node") and shutil.which("npm")):
        return None
    if not os.path.isdir(os.path.join(CACHE, "node_modules", "laz-perf")):
        os.makedirs(CACHE, exist_ok=True)
        install = subprocess.run(["npm", "install", "--silent", "--prefix", CACHE, "laz-perf"],
                                 capture_output=True, text=True, timeout=300)
        if install.returncode != 0:
            lazperf_folder.error = "laz-perf could not be installed: " + install.stderr[-200:]
            return None
    return CACHE


def decode(folder, laz_path, repeats=1):
    """(records, seconds): the LAZ file's point records as laz-perf decodes them, and its best
    time over `repeats` decodes."""
    with tempfile.TemporaryDirectory(prefix="pcl_ddg_lazperf_") as scratch:
        script = os.path.join(scratch, "decode.js")
        with open(script, "w") as out:
            out.write(DECODE_JOB)
        records = os.path.join(scratch, "records")
        job = subprocess.run(["node", script, str(laz_path), records, str(repeats)], check=True,
                             capture_output=True, text=True, timeout=600,
                             env=dict(os.environ, NODE_PATH=os.path.join(folder, "node_modules")))
        with open(records, "rb") as f:
            return f.read(), json.loads(job.stdout)["seconds"]
