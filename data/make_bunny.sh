#!/usr/bin/env bash
# Regenerates data/bunny.ply from the npm registry package `bunny` (Stanford bunny, 1,839 vertices;
# the package declares itself public domain). Run once; the result is committed.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
(cd "$work" && npm pack --silent bunny@1.0.1 >/dev/null && tar xzf bunny-1.0.1.tgz)
node -e '
const b = require(process.argv[1]);
const lines = ["ply", "format ascii 1.0",
  "comment Stanford bunny (Stanford 3D Scanning Repository) via npm package bunny@1.0.1, public domain",
  "element vertex " + b.positions.length, "property float x", "property float y", "property float z",
  "element face " + b.cells.length, "property list uchar int vertex_indices", "end_header"];
for (const p of b.positions) lines.push(p.join(" "));
for (const c of b.cells) lines.push(c.length + " " + c.join(" "));
require("fs").writeFileSync(process.argv[2], lines.join("\n") + "\n");
' "$work/package/index.js" "$here/bunny.ply"
echo "wrote $here/bunny.ply"
