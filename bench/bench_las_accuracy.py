#!/usr/bin/env python3
"""How far pcl_ddg_normals' PCA normals are from an independent double-precision PCA.

Inputs: the LAS files in DATA/las/ (autzen_trim, autzen_trim_7, mvk-thin, test1_4,
1.2-with-color, epsg_4326; a missing one is skipped with a note) and two synthetic clouds this
script writes as binary little-endian PLY with `double x y z`, both placed at
(500000, 5000000, 200): a sphere of radius 50 (100,000 Fibonacci points) and a height field
z = 3 sin(x/20) cos(y/15) on a 400 x 400 grid of spacing 1.

For each input the tool runs as

    TOOL input out.ply -method pca -k K -neighbours kdtree -orient up

and its normals (normal_x/y/z, or nx/ny/nz as the tool names them) are read back from the
output PLY. The reference is computed here, in float64, from coordinates read by this script's
own LAS and PLY parsers (the project's Python module is not used: this is an oracle):
coordinates centred on their mean, the K nearest neighbours of every point (itself included)
from scipy.spatial.cKDTree, and the eigenvector of the smallest eigenvalue of each
neighbourhood's covariance (numpy.linalg.eigh).

The error of a point is the unoriented angle arccos(min(1, |n.r|)) (computed as
atan2(|n x r|, |n.r|), the same angle, accurate near 0). Points whose tool normal is NaN, and
points whose reference neighbourhood is degenerate (second-smallest eigenvalue <= 1e-12 times the
largest), are counted apart and left out of the statistics. Exact duplicate points make the k-NN
ambiguous (at a distance tie the tool and scipy may keep different neighbours), so the statistics
are given twice: over all points, and over the "clean" points, those none of whose K neighbours
has an exact duplicate in the cloud. "tie at k" is the share of points whose K-th and (K+1)-th
reference distances are exactly equal (also an ambiguous neighbourhood, duplicates or not).

    /usr/bin/python3 bench/bench_las_accuracy.py build/tools/pcl_ddg_normals \
        [--data ../shared/data] [--k 16] [--keep DIR] [--json]

Prints a Markdown table on stdout; with --json, prints JSON on stdout instead and the table on
stderr. --keep DIR keeps the synthetic inputs and the tool's outputs in DIR.
"""
import argparse
import json
import os
import struct
import subprocess
import sys
import tempfile

import numpy as np
from scipy.spatial import cKDTree

LAS_FILES = ["autzen_trim.las", "autzen_trim_7.las", "mvk-thin.las", "test1_4.las",
             "1.2-with-color.las", "epsg_4326.las"]
FAR_OFFSET = np.array([500000.0, 5000000.0, 200.0])
DEGENERATE = 1e-12
CHUNK = 200_000  # points per vectorised eigh

PLY_TYPES = {
    "char": "i1", "int8": "i1", "uchar": "u1", "uint8": "u1",
    "short": "i2", "int16": "i2", "ushort": "u2", "uint16": "u2",
    "int": "i4", "int32": "i4", "uint": "u4", "uint32": "u4",
    "float": "f4", "float32": "f4", "double": "f8", "float64": "f8",
    "int64": "i8", "uint64": "u8",  # not in the PLY standard; harmless to accept
}


def note(*args):
    print(*args, file=sys.stderr, flush=True)


# ---------------------------------------------------------------------------------------------
# Readers and writers (independent of the project)

def read_las_xyz(path):
    """The LAS points as float64 X*scale + offset (LAS 1.0-1.4, uncompressed)."""
    with open(path, "rb") as f:
        data = f.read()
    if data[:4] != b"LASF":
        raise ValueError(f"{path}: not a LAS file")
    minor = data[25]
    offset_to_points, = struct.unpack_from("<I", data, 96)
    raw_format = data[104]
    record_length, count = struct.unpack_from("<HI", data, 105)
    scale = np.array(struct.unpack_from("<3d", data, 131))
    offset = np.array(struct.unpack_from("<3d", data, 155))
    if raw_format & 0xC0:
        raise ValueError(f"{path}: compressed (LAZ) point format {raw_format:#x}")
    if count == 0 and minor >= 4:
        count, = struct.unpack_from("<Q", data, 247)
    whole = (len(data) - offset_to_points) // record_length
    if count > whole:
        note(f"  {os.path.basename(path)}: header says {count} points, file holds {whole}")
        count = whole
    record = np.dtype({"names": ["X", "Y", "Z"], "formats": ["<i4"] * 3,
                       "offsets": [0, 4, 8], "itemsize": record_length})
    rec = np.frombuffer(data, record, count, offset_to_points)
    xyz = np.stack([rec["X"], rec["Y"], rec["Z"]], axis=1).astype(np.float64)
    return xyz * scale + offset


def read_ply_vertices(path):
    """The vertex element of a binary PLY as a NumPy structured array (any scalar types)."""
    with open(path, "rb") as f:
        data = f.read()
    end = data.find(b"end_header")
    if not data.startswith(b"ply") or end < 0:
        raise ValueError(f"{path}: not a PLY file")
    body = data.index(b"\n", end) + 1
    elements, order = [], "<"
    for line in data[:end].decode("ascii", "replace").splitlines()[1:]:
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        if words[0] == "format":
            if words[1] == "ascii":
                raise ValueError(f"{path}: ASCII PLY is not read by this script")
            order = "<" if words[1] == "binary_little_endian" else ">"
        elif words[0] == "element":
            elements.append((words[1], int(words[2]), []))
        elif words[0] == "property":
            if words[1] == "list":
                elements[-1][2].append((words[4], None))
            else:
                elements[-1][2].append((words[2], order + PLY_TYPES[words[1]]))
    position = body
    for name, count, properties in elements:
        if any(t is None for _, t in properties):
            raise ValueError(f"{path}: list property in element '{name}' before the vertices")
        dtype = np.dtype(properties)
        if name == "vertex":
            return np.frombuffer(data, dtype, count, position)
        position += count * dtype.itemsize
    raise ValueError(f"{path}: no vertex element")


def columns(vertices, names):
    """The named vertex properties as an (n, len(names)) float64 array."""
    return np.stack([vertices[name] for name in names], axis=1).astype(np.float64)


def write_ply_xyz(path, xyz):
    """A binary little-endian PLY of `double x y z`."""
    header = ("ply\nformat binary_little_endian 1.0\ncomment bench_las_accuracy.py\n"
              f"element vertex {len(xyz)}\n"
              "property double x\nproperty double y\nproperty double z\nend_header\n")
    with open(path, "wb") as f:
        f.write(header.encode("ascii"))
        f.write(np.ascontiguousarray(xyz, dtype="<f8").tobytes())


# ---------------------------------------------------------------------------------------------
# Synthetic clouds

def fibonacci_sphere(n=100_000, radius=50.0):
    i = np.arange(n, dtype=np.float64) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = np.pi * (1.0 + np.sqrt(5.0)) * i
    r = np.sqrt(1.0 - z * z)
    return radius * np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1) + FAR_OFFSET


def height_field(side=400, spacing=1.0):
    u = (np.arange(side, dtype=np.float64) - side / 2) * spacing
    x, y = np.meshgrid(u, u, indexing="xy")
    z = 3.0 * np.sin(x / 20.0) * np.cos(y / 15.0)
    return np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1) + FAR_OFFSET


# ---------------------------------------------------------------------------------------------
# Tool and reference

def run_tool(tool, source, target, k):
    command = [tool, source, target, "-method", "pca", "-k", str(k),
               "-neighbours", "kdtree", "-orient", "up"]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        note(f"  tool failed ({done.returncode}): {' '.join(command)}\n{done.stderr.strip()}")
        return None
    vertices = read_ply_vertices(target)
    names = vertices.dtype.names
    normal = ["normal_x", "normal_y", "normal_z"] if "normal_x" in names else ["nx", "ny", "nz"]
    return columns(vertices, normal), columns(vertices, "xyz")


def reference_normals(xyz, k):
    """Smallest-eigenvalue eigenvectors of the k-NN covariances, degenerate flags, neighbours."""
    centred = xyz - xyz.mean(axis=0)
    distances, neighbours = cKDTree(centred).query(centred, k=k + 1)
    normals = np.empty_like(centred)
    degenerate = np.empty(len(centred), dtype=bool)
    for start in range(0, len(centred), CHUNK):
        block = centred[neighbours[start:start + CHUNK, :k]]
        block = block - block.mean(axis=1, keepdims=True)
        covariance = np.einsum("nki,nkj->nij", block, block) / k
        values, vectors = np.linalg.eigh(covariance)
        normals[start:start + CHUNK] = vectors[:, :, 0]
        degenerate[start:start + CHUNK] = values[:, 1] <= DEGENERATE * values[:, 2]
    tie = distances[:, k - 1] == distances[:, k]
    return normals, degenerate, neighbours[:, :k], tie


def duplicated(xyz):
    """True for every point whose coordinates occur more than once."""
    _, inverse, counts = np.unique(xyz, axis=0, return_inverse=True, return_counts=True)
    return counts[inverse.ravel()] > 1


def angles_deg(a, b):
    a = a / np.linalg.norm(a, axis=1, keepdims=True)
    b = b / np.linalg.norm(b, axis=1, keepdims=True)
    dot = np.abs(np.einsum("ij,ij->i", a, b))
    cross = np.linalg.norm(np.cross(a, b), axis=1)
    return np.degrees(np.arctan2(cross, dot))


def summary(angles):
    if len(angles) == 0:
        return {"points": 0, "over_1deg": None, "over_5deg": None, "p95_deg": None,
                "max_deg": None}
    return {"points": int(len(angles)),
            "over_1deg": float(np.mean(angles > 1.0)),
            "over_5deg": float(np.mean(angles > 5.0)),
            "p95_deg": float(np.percentile(angles, 95)),
            "max_deg": float(angles.max())}


def measure(name, source, xyz, tool, out_dir, k):
    note(f"{name}: {len(xyz)} points")
    target = os.path.join(out_dir, os.path.splitext(name)[0] + "_normals.ply")
    result = run_tool(tool, source, target, k)
    if result is None:
        return {"file": name, "error": "tool failed"}
    tool_normals, tool_xyz = result
    if len(tool_normals) != len(xyz):
        return {"file": name, "error": f"tool wrote {len(tool_normals)} points of {len(xyz)}"}
    reference, degenerate, neighbours, tie = reference_normals(xyz, k)
    nan = ~np.all(np.isfinite(tool_normals), axis=1)
    dup = duplicated(xyz)
    clean = ~dup[neighbours].any(axis=1)
    valid = ~nan & ~degenerate
    angles = angles_deg(tool_normals[valid], reference[valid])
    return {"file": name, "points": int(len(xyz)),
            "duplicates": float(dup.mean()), "tie_at_k": float(tie.mean()),
            "nan": int(nan.sum()), "degenerate": int((degenerate & ~nan).sum()),
            "xyz_max_diff": float(np.abs(tool_xyz - xyz).max()),
            "all": summary(angles), "clean": summary(angles_deg(
                tool_normals[valid & clean], reference[valid & clean]))}


# ---------------------------------------------------------------------------------------------
# Report

def percent(x):
    if x is None:
        return "—"
    return "< 0.01 %" if 0 < x < 5e-5 else f"{100 * x:.2f} %"


def degrees(x):
    return "—" if x is None else f"{x:.3g}°"


def table(rows, k):
    lines = [f"k = {k}; statistics over points with a finite tool normal and a non-degenerate "
             "reference; clean = no exact duplicate among the k neighbours.", "",
             "| file | points | dup | tie at k | NaN | degen. | > 1° | > 5° | p95 | max "
             "| clean points | clean > 1° | clean > 5° | clean p95 | clean max |",
             "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        if "error" in r:
            lines.append(f"| {r['file']} | {r['error']} |" + " |" * 13)
            continue
        a, c = r["all"], r["clean"]
        lines.append(
            f"| {r['file']} | {r['points']} | {percent(r['duplicates'])} "
            f"| {percent(r['tie_at_k'])} | {r['nan']} | {r['degenerate']} "
            f"| {percent(a['over_1deg'])} | {percent(a['over_5deg'])} | {degrees(a['p95_deg'])} "
            f"| {degrees(a['max_deg'])} | {c['points']} | {percent(c['over_1deg'])} "
            f"| {percent(c['over_5deg'])} | {degrees(c['p95_deg'])} | {degrees(c['max_deg'])} |")
    return "\n".join(lines)


def inputs(data_dir, work_dir):
    """(name, path, float64 coordinates) of every input, synthetic ones written to work_dir."""
    for name in LAS_FILES:
        path = os.path.join(data_dir, "las", name)
        if not os.path.exists(path):
            note(f"{name}: missing ({path}), skipped")
            continue
        yield name, path, read_las_xyz(path)
    for name, xyz in [("sphere_far.ply", fibonacci_sphere()),
                      ("height_field_far.ply", height_field())]:
        path = os.path.join(work_dir, name)
        write_ply_xyz(path, xyz)
        yield name, path, columns(read_ply_vertices(path), "xyz")


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("tool", help="path of pcl_ddg_normals")
    parser.add_argument("--data", default=os.path.join(here, "..", "..", "shared", "data"))
    parser.add_argument("--k", type=int, default=16)
    parser.add_argument("--keep", metavar="DIR", help="keep the inputs and outputs here")
    parser.add_argument("--json", action="store_true", help="JSON on stdout, table on stderr")
    args = parser.parse_args()

    with tempfile.TemporaryDirectory(prefix="bench_las_accuracy_") as temp:
        work_dir = args.keep or temp
        os.makedirs(work_dir, exist_ok=True)
        rows = [measure(name, path, xyz, args.tool, work_dir, args.k)
                for name, path, xyz in inputs(args.data, work_dir)]
    for r in rows:
        if r.get("xyz_max_diff", 0.0) > 1e-6:
            note(f"{r['file']}: output coordinates differ from the input by up to "
                 f"{r['xyz_max_diff']:.3g} (reordered or rounded points?)")
    if args.json:
        print(table(rows, args.k), file=sys.stderr)
        json.dump({"k": args.k, "tool": args.tool, "results": rows}, sys.stdout, indent=2)
        print()
    else:
        print(table(rows, args.k))


if __name__ == "__main__":
    main()
