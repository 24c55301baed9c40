"""pcl_ddg.distributed: the fitted estimators on a Dask cluster, equal to the tools byte for byte.

A scene (one large LAS, binary PCD or binary PLY cloud, or many files that together form one
scene, like a LAScatalog) is cut into a grid of tiles; each tile is a Dask task that reads its own points and
a halo around them from the shared filesystem, fits them with the out-of-core path's certified
halo rule, and writes its results atomically with a checksum. The output is one file per input
(each with its own fields plus the fitted ones) or, with ``merge``, one file of every point in
the inputs' order: the bytes ``pcl_ddg_normals`` / ``pcl_ddg_curvature -method quadric`` write for
the merged cloud.

    python3 -m pcl_ddg.distributed normals INPUT... OUTPUT_DIR -k 16 [-method pca|quadric|robust]
        [-radius R [-max_nn N]] [-viewpoint x,y,z] [-orient viewpoint|up [-up x,y,z]]
        [-precision float|double] [--scheduler tcp://HOST:8786 | --workers N]
        [--memory-per-worker 2G] [--retries 3] [--merge FILE] [--resume | --no-resume]
    python3 -m pcl_ddg.distributed curvature INPUT... OUTPUT_DIR [-k 20] ...
    python3 -m pcl_ddg.distributed batch 'scans/*.ply' OUTPUT_DIR -- normals -k 16
        (meshes too: 'models/*.off' gives OUTPUT_DIR/<name>.ply)

How it stays exact (docs/distributed.md has the details):

* the plan reads headers only on the client; the workers measure the bounds of byte ranges of
  the files (chunks) in a first pass, and the tiles are half-open cells of a grid over them;
* a tile gathers its core points and every point inside a halo box, in the merged cloud's order
  (the kd-tree breaks distance ties by index, so its neighbours are the whole cloud's). A core
  point's result is kept only when its k-th neighbour is nearer than the halo box's edge; the
  halo is widened when more than 1 % are not, and the rest are fitted with everything around them
  (src/tiling/tiled_local_fit.cpp's rule). A radius search's halo is the radius;
* the merged output is written by the tools' writer (the out-of-core path's piecewise writer).
"""

from __future__ import annotations

import argparse
import glob as globmodule
import hashlib
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import time
import uuid
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np

from . import _pcl_ddg

__all__ = ["estimate_normals", "principal_curvatures", "batch", "main", "DistributedError"]

CLOUD_EXTENSIONS = (".pcd", ".ply", ".las", ".laz")
# What else the tools read (batch runs them on any such file), and what they write: a mesh format
# they do not write gives a .ply output, the one format that keeps its faces (the tools' own
# -input_dir rule).
MESH_EXTENSIONS = (".obj", ".off", ".stl", ".vtk")
OUTPUT_EXTENSIONS = (".ply", ".pcd", ".las", ".laz")
# What a worker process holds before any tile (the interpreter, NumPy, Dask, the module), and
# what a gathered point costs at once (float points, indices, the kd-tree, the fit, the results
# and their copies): the tile size follows from --memory-per-worker with these.
WORKER_BASELINE_BYTES = 128 << 20  # when the workers cannot be asked (about 96M measured)
BYTES_PER_POINT = 400
CHUNK_POINTS_MAX = 1 << 18
STATE_FOLDER = ".pcl_ddg_distributed"


class DistributedError(RuntimeError):
    """A run that cannot start or finish (its message says why)."""


# ---------------------------------------------------------------------------------------------
# Inputs and their headers


@dataclass
class CloudInput:
    path: str
    points: int
    first: int  #: the index of its first point in the merged cloud
    fields: List[Tuple[str, int, int, int]]
    viewpoint: Tuple[float, float, float]
    width: int
    height: int
    #: a LAZ file's chunks (first, count), which the plan's chunks follow: a tile then decodes
    #: only the compressed chunks its points and halo lie in
    chunks: Optional[List[Tuple[int, int]]] = None


def parse_size(text: str) -> int:
    """Bytes of a size like 2G, 512M, 64k, 2GB, 2GiB or 1000000 (powers of 1024): the tools'
    -memory parser (pcl_ddg/tiling/byte_size.h), so that both take the same sizes. ValueError
    for anything else."""
    return int(_pcl_ddg._parse_byte_size(str(text)))


def expand_inputs(inputs: Sequence[str],
                  extensions: Sequence[str] = CLOUD_EXTENSIONS) -> List[str]:
    """Files, folders (their files of these extensions: by default .pcd/.ply/.las) and glob
    patterns, in order; a name that is none of them is an error (FileNotFoundError)."""
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    paths: List[str] = []
    for item in map(os.fspath, inputs):
        if os.path.isdir(item):
            found = sorted(os.path.join(item, n) for n in os.listdir(item)
                           if n.lower().endswith(tuple(extensions)))
            if not found:
                raise FileNotFoundError(f"{item}: no {', '.join(extensions[:-1])} or "
                                        f"{extensions[-1]} file in the folder")
            paths += found
        elif os.path.exists(item):
            paths.append(item)
        elif globmodule.has_magic(item):
            found = sorted(globmodule.glob(item))
            if not found:
                raise FileNotFoundError(f"{item}: no file matches the pattern")
            paths += found
        else:
            raise FileNotFoundError(f"{item}: no such file")
    seen = set()
    for p in paths:
        real = os.path.realpath(p)
        if real in seen:
            raise ValueError(f"{p} is given twice")
        seen.add(real)
    return paths


def las_header(path: str) -> Dict[str, Any]:
    """The public header block of a LAS file (and its CRS records), read by the library's LAS
    reader (the one the chunks are read with): counts, bounds, scale, offset, point format. No
    point is read. A LAZ file's (``compressed`` True) is that of the LAS file it stands for."""
    header = _pcl_ddg._las_header(os.fspath(path))
    header["crs"] = sorted((record, hashlib.sha256(data).hexdigest())
                           for user, record, data in header.pop("vlrs")
                           if user == b"LASF_Projection")
    return header


def _check_las(paths: List[str], allow_mixed_crs: bool) -> None:
    headers = [las_header(p) for p in paths]
    first = headers[0]
    for p, h in zip(paths[1:], headers[1:]):
        if h["scale"] != first["scale"] or h["offset"] != first["offset"]:
            raise ValueError(
                f"{p} has scale {h['scale']} and offset {h['offset']}, but {paths[0]} has "
                f"scale {first['scale']} and offset {first['offset']}: files of one scene must "
                "share them (reproject or rescale them first, e.g. pdal translate with "
                "writers.las.scale_x/offset_x)")
        if h["crs"] != first["crs"] and not allow_mixed_crs:
            raise ValueError(f"{p} and {paths[0]} have different coordinate reference systems "
                             "(LASF_Projection records); --allow-mixed-crs to run anyway")


def scan_inputs(paths: List[str], allow_mixed_crs: bool = False) -> List[CloudInput]:
    """The inputs' headers, checked: the same format, fields and viewpoint in every file (they
    form one cloud; LAS: the same scale, offset and CRS records), LAS, binary PCD or PLY."""
    las = [p for p in paths if p.lower().endswith((".las", ".laz"))]
    if las:
        _check_las(las, allow_mixed_crs)
    clouds: List[CloudInput] = []
    first = 0
    for p in paths:
        if not p.lower().endswith(CLOUD_EXTENSIONS):
            raise ValueError(f"{p}: not a .pcd, .ply, .las or .laz cloud")
        try:
            layout = _pcl_ddg._cloud_layout(p)
        except OSError as error:
            raise OSError(f"{error} (pcl_ddg.distributed reads LAS, binary PCD and binary PLY "
                          "clouds by byte ranges; write it as binary PLY, e.g. "
                          "pcl_ddg.write('cloud.ply', pcl_ddg.read(path).points))") from None
        chunks = layout["chunks"]
        clouds.append(CloudInput(p, int(layout["points"]), first,
                                 [tuple(f) for f in layout["fields"]],
                                 tuple(layout["viewpoint"]), int(layout["width"]),
                                 int(layout["height"]),
                                 None if chunks is None else [tuple(c) for c in chunks]))
        first += int(layout["points"])
    reference = clouds[0]
    names = lambda c: " ".join(f"{n}:{t}x{k}" for n, t, k, _ in c.fields)  # noqa: E731
    for c in clouds[1:]:
        if c.fields != reference.fields or os.path.splitext(c.path)[1].lower() != \
                os.path.splitext(reference.path)[1].lower():
            raise ValueError(
                f"incompatible inputs: {c.path} has the fields ({names(c)}) but "
                f"{reference.path} has ({names(reference)}); the files of one scene must have "
                "the same format and fields (name:type x count)")
        if c.viewpoint != reference.viewpoint:
            raise ValueError(f"{c.path} has the VIEWPOINT {c.viewpoint} but {reference.path} "
                             f"{reference.viewpoint}: give the sensor with -viewpoint x,y,z")
    return clouds  # an organized cloud is fitted with kd-tree neighbours, as with -memory


def check_output_folder(output_dir: str, paths: Sequence[str], merge: Optional[str]) -> None:
    out = os.path.realpath(output_dir)
    for p in paths:
        folder = os.path.dirname(os.path.realpath(p))
        if folder == out or folder.startswith(out + os.sep):
            raise ValueError(f"the output folder {output_dir} holds the input {p}: choose a "
                             "folder apart from the inputs")
        if merge and os.path.realpath(merge) == os.path.realpath(p):
            raise ValueError(f"--merge {merge} is an input")
    if os.path.exists(output_dir) and not os.path.isdir(output_dir):
        raise ValueError(f"{output_dir} is a file, not a folder")


# ---------------------------------------------------------------------------------------------
# The plan


@dataclass
class Plan:
    """Tiles of the merged cloud, cut in its local frame: lo, hi and the chunks' boxes bound the
    points' floats relative to `origin` (the tools' local origin, local_cloud.h)."""
    origin: Tuple[float, float, float]
    lo: Tuple[float, float, float]
    hi: Tuple[float, float, float]
    dims: Tuple[int, int, int]
    chunks: List[Tuple[int, int, int, Tuple[float, ...]]]  #: (input, first, count, bbox)
    tiles: List[int]  #: non-empty tiles' ids
    finite_points: int
    points_per_tile: int
    halo_guess: float

    @property
    def bounds(self) -> List[float]:
        return list(self.lo) + list(self.hi)

    def cell_size(self) -> np.ndarray:
        return (np.array(self.hi) - np.array(self.lo)) / np.array(self.dims)

    def tile_box(self, t: int) -> Tuple[np.ndarray, np.ndarray]:
        nx, ny, nz = self.dims
        i = np.array([t // (ny * nz), (t // nz) % ny, t % nz], dtype=float)
        size = self.cell_size()
        lo = np.array(self.lo) + i * size
        return lo, lo + size


def _chunk_bounds(path: str, index: int, first: int, count: int) -> Tuple:
    """A worker's pass over a byte range: the exact bounds of its finite points."""
    xyz = _pcl_ddg._read_positions(path, first, count)
    finite = np.isfinite(xyz).all(axis=1)
    n = int(finite.sum())
    if n == 0:
        return index, first, count, None, 0
    pts = xyz[finite]
    return index, first, count, tuple(pts.min(axis=0)) + tuple(pts.max(axis=0)), n


def _local_box(box: Sequence[float], origin: np.ndarray) -> Tuple[float, ...]:
    """An exact box in the local frame, as its points' floats bound it (rounding to float is
    monotonic, and the subtraction exact)."""
    lo = (np.asarray(box[:3], np.float64) - origin).astype(np.float32).astype(np.float64)
    hi = (np.asarray(box[3:], np.float64) - origin).astype(np.float32).astype(np.float64)
    return tuple(lo) + tuple(hi)


def _grid_dims(extent: np.ndarray, tiles: int) -> Tuple[int, int, int]:
    dims = [1, 1, 1]
    while dims[0] * dims[1] * dims[2] < tiles:
        d = int(np.argmax(extent / np.array(dims)))
        dims[d] += 1
    return tuple(dims)  # type: ignore[return-value]


def make_plan(client: Any, clouds: List[CloudInput], points_per_tile: int,
              options: Dict[str, Any]) -> Plan:
    chunk = max(4096, min(CHUNK_POINTS_MAX, points_per_tile // 8))
    # A LAZ file's chunks are its compressed chunks, cut where larger than a chunk (each part
    # then decodes its whole compressed chunk, but holds only its own points).
    jobs = [(c.path, i, f, min(chunk, first + count - f)) for i, c in enumerate(clouds)
            for first, count in (c.chunks or [(0, c.points)])
            for f in range(first, first + count, chunk)]
    futures = client.map(_chunk_bounds, *zip(*jobs), pure=False, key=[
        f"pcl_ddg-bounds-{uuid.uuid4().hex[:8]}-{j}" for j in range(len(jobs))])
    results = client.gather(futures)
    boxes = [r[3] for r in results if r[3] is not None]
    finite = sum(r[4] for r in results)
    if not boxes:
        raise DistributedError("the inputs have no finite point")
    world = np.array(boxes)
    origin = np.array(_pcl_ddg._local_origin(list(world[:, :3].min(axis=0)) +
                                             list(world[:, 3:].max(axis=0))))
    chunks = [(r[0], r[1], r[2], _local_box(r[3], origin)) for r in results if r[3] is not None]
    b = np.array([c[3] for c in chunks])
    lo, hi = b[:, :3].min(axis=0), b[:, 3:].max(axis=0)
    # Cut first across the axes along which the chunks are narrow (a file in scan or flight-line
    # order): a tile then reads few chunks beyond its own points.
    extent = np.maximum(hi - lo, 1e-300)
    width = np.median(b[:, 3:] - b[:, :3], axis=0) / extent
    dims = _grid_dims(extent / np.maximum(width, 0.05),
                      max(1, math.ceil(finite / points_per_tile)))
    extent = np.sort(hi - lo)[::-1]
    area = max(extent[0] * max(extent[1], extent[0] * 1e-3), 1e-300)
    k = options["k"]
    guess = 1.5 * math.sqrt(k / (math.pi * finite / area)) if options["radius"] == 0 else 0.0
    if options["method"] == "robust" and options["radius"] == 0 and k >= 32:
        # Its wider planes read rows (32 nearest) up to twelve steps away: about 14 of their radii.
        guess = max(guess, 14 * 1.5 * math.sqrt(32 / (math.pi * finite / area)))
    plan = Plan(tuple(origin), tuple(lo), tuple(hi), dims, chunks, [], finite, points_per_tile,
                guess)
    tiles = []
    for t in range(dims[0] * dims[1] * dims[2]):
        tlo, thi = plan.tile_box(t)
        if any(_intersects(tlo, thi, c[3]) for c in chunks):
            tiles.append(t)
    plan.tiles = tiles
    return plan


def _intersects(lo: np.ndarray, hi: np.ndarray, box: Sequence[float]) -> bool:
    return bool(np.all(np.array(box[:3]) <= hi) and np.all(np.array(box[3:]) >= lo))


# ---------------------------------------------------------------------------------------------
# A tile, on a worker


def _status_bytes(key: str, default: int) -> int:
    """A memory line of /proc/self/status (in kB there) in bytes; default where it cannot be read."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith(key + ":"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return default


def _peak_bytes() -> int:
    """This process's peak resident memory (VmHWM)."""
    return _status_bytes("VmHWM", 0)


def worker_baseline_bytes(resident: int) -> int:
    """Where a tile's room starts: a worker's resident memory rounded down to a 16M step, plus 32M
    for what it allocates around a tile (Dask's buffers, the output's serialisation)."""
    return (resident // (16 << 20) + 2) * (16 << 20)


def _resident_bytes() -> int:
    """This process's resident memory now (VmRSS)."""
    return _status_bytes("VmRSS", WORKER_BASELINE_BYTES)


def _gather(plan: Plan, paths: List[str], firsts: List[int], lo: np.ndarray, hi: np.ndarray,
            tile: int) -> Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The points inside [lo, hi] and (tile >= 0) every point of the tile, in the merged cloud's
    order and its local frame: (float32 points, the same in float64, global indices, own mask).
    Only the byte ranges whose bounds meet the box are read."""
    parts_xyz, parts_exact, parts_index, parts_own = [], [], [], []
    lo64, hi64 = np.asarray(lo, np.float64), np.asarray(hi, np.float64)
    size = plan.cell_size()
    size = [float(v) if v > 0 else 1.0 for v in size]
    for index, first, count, box in plan.chunks:
        if not _intersects(lo64, hi64, box):
            continue
        # In C++: a chunk's points inside the box, and the tile's own (its half-open cells).
        xyz, exact, at, own = _pcl_ddg._gather_chunk(
            paths[index], first, count, list(lo64), list(hi64), list(plan.lo), size,
            list(plan.dims), tile, list(plan.origin))
        parts_xyz.append(xyz)
        parts_exact.append(exact)
        parts_index.append(firsts[index] + first + at)
        parts_own.append(own)
    if not parts_xyz:
        return (np.zeros((0, 3), np.float32), np.zeros((0, 3)), np.zeros(0, np.int64),
                np.zeros(0, bool))
    # The chunks are visited in the merged order and each keeps its order: already sorted.
    return (np.concatenate(parts_xyz), np.concatenate(parts_exact),
            np.concatenate(parts_index).astype(np.int64), np.concatenate(parts_own))


def _record_floats(method: str) -> int:
    """Floats per point of a fit's results: normal and curvature, then the quadric's principal
    curvatures and k1 direction, or robust's scale and confidence."""
    return {"quadric": 9, "robust": 6}.get(method, 4)


def _fit(plan, xyz, exact, own_positions, options, halo_lo, halo_hi, mode):
    o = options
    return _pcl_ddg._fit_tile(
        xyz, exact, list(plan.origin), own_positions, o["method"], o["k"], o["radius"],
        o["max_nn"], list(o["viewpoint"]),
        o["orient"], None if o["up"] is None else list(o["up"]),
        None if halo_lo is None else list(halo_lo) + list(halo_hi), plan.bounds, mode,
        o["threads"], plan.finite_points)


def _read_json(path: str) -> Any:
    """A state file's content, or None when it is missing or torn."""
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def _write_atomic(path: str, data: bytes) -> None:
    temporary = f"{path}.{uuid.uuid4().hex[:8]}.partial"
    with open(temporary, "wb") as f:
        f.write(data)
        f.flush()
        os.fsync(f.fileno())
    os.replace(temporary, path)


def _file_digest(path: str) -> str:
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def project_version() -> str:
    """The project's version, ``pcl_ddg.__version__`` (the CMake project's), read at every run."""
    from . import __version__

    return str(__version__)


def _code_identity() -> Dict[str, str]:
    """What computes the tiles: the project version, and the compiled module's SHA-256 (a rebuild
    that keeps the version number still changes results)."""
    module = getattr(_pcl_ddg, "__file__", None)
    return {"version": project_version(),
            "module_sha256": _file_digest(module) if module else ""}


def _file_state(path: str) -> Dict[str, Any]:
    """An input as stat sees it: real path, size, and modification and change times in ns. The
    change time cannot be set back (touch -d, os.utime and cp -p set only mtime), so a rewrite
    that keeps the size and restores mtime still shows here."""
    st = os.stat(path)
    return {"path": os.path.realpath(path), "size": st.st_size, "mtime_ns": st.st_mtime_ns,
            "ctime_ns": st.st_ctime_ns}


def _same_file_state(recorded: Any, now: Dict[str, Any]) -> bool:
    return isinstance(recorded, dict) and all(recorded.get(k) == v for k, v in now.items())


def _tile_paths(state: str, tile: int) -> Tuple[str, str]:
    base = os.path.join(state, "tiles", f"tile_{tile:06d}")
    return base + ".bin", base + ".sha256"


def tile_complete(state: str, tile: int) -> bool:
    """A tile's results exist and match their checksum."""
    data, check = _tile_paths(state, tile)
    try:
        with open(check) as f:
            expected = json.load(f)
        with open(data, "rb") as f:
            digest = hashlib.sha256(f.read()).hexdigest()
    except (OSError, ValueError):
        return False
    return digest == expected.get("sha256")


def _drop_tile(state: str, tile: int) -> None:
    for path in _tile_paths(state, tile):
        try:
            os.remove(path)
        except FileNotFoundError:
            pass


def _tiles_reading(state: str, tiles: Sequence[int], boxes: Sequence[Sequence[float]]) -> List[int]:
    """The finished tiles whose gathers met one of these boxes (or that do not say where they
    gathered): a tile's results depend on the points inside its gather boxes alone."""
    hit = []
    for t in tiles:
        record = _read_json(_tile_paths(state, t)[1])
        gathered = record.get("boxes") if isinstance(record, dict) else None
        if not isinstance(gathered, list) or any(
                _intersects(np.array(g[:3]), np.array(g[3:]), b) for g in gathered for b in boxes):
            hit.append(t)
    return hit


def run_tile(tile: int, plan: Plan, paths: List[str], firsts: List[int], options: Dict[str, Any],
             state: str) -> Dict[str, Any]:
    """One tile on a worker: gather, certify, widen, fit; results written atomically."""
    start = time.perf_counter()
    attempt = os.path.join(state, "attempts", f"tile_{tile:06d}.{os.getpid()}.{uuid.uuid4().hex[:6]}")
    open(attempt, "w").close()
    delay = float(os.environ.get("PCL_DDG_DISTRIBUTED_TILE_DELAY", "0") or 0)
    if delay > 0:  # fault tests: a tile long enough to be killed in the middle of
        time.sleep(delay)
    floats = _record_floats(options["method"])
    bounds = plan.bounds
    core_lo, core_hi = plan.tile_box(tile)
    radius = options["radius"]
    halo = _pcl_ddg._radius_halo(radius) if radius > 0 else plan.halo_guess
    growths = 0
    # Every box gathered from, kept with the results: a later run with a changed input redoes
    # only the tiles whose boxes meet that input's chunks.
    boxes = [[float(v) for v in (*(core_lo - halo), *(core_hi + halo))]]
    xyz, exact, index, own = _gather(plan, paths, firsts, core_lo - halo, core_hi + halo, tile)
    largest = len(xyz)
    results_index = [np.zeros(0, np.int64)]
    results = [np.zeros((0, floats), np.float32)]
    failed = fallback = far_count = certified_before = 0
    if own.any():
        for round_ in range(3):
            own_at = np.flatnonzero(own)
            if radius > 0:
                rec, ok, look, _, f1, f2 = _fit(plan, xyz, exact, own_at, options, None, None,
                                                "all")
                far = np.zeros(0, np.int64)
                break
            lo, hi = core_lo - halo, core_hi + halo
            # Fitted at once: the certified points' fits are the whole cloud's, kept even when
            # the halo must widen for the others (robust fits are costly).
            rec, ok, look, reach, f1, f2 = _fit(plan, xyz, exact, own_at, options, lo, hi,
                                                "certified")
            needed = np.maximum(0.0, halo + look - reach)
            if options["method"] != "robust":
                # The 99th percentile over every point of the tile, as fitTiles measures it (the
                # points certified before need no more than the halo they had): robust's is over
                # the points left, as there.
                needed = np.concatenate([needed, np.zeros(certified_before)])
            p99 = np.sort(needed)[len(needed) - 1 - len(needed) // 100]
            if p99 > halo and round_ < 2:
                failed += f1
                fallback += f2
                results_index.append(index[own_at[ok]])
                results.append(rec[ok])
                certified_before += int(np.count_nonzero(ok))
                rest = index[own_at[~ok]]
                halo = 1.05 * p99 if np.isfinite(p99) else 2 * halo + float(
                    np.linalg.norm(core_hi - core_lo))
                growths += 1
                boxes.append([float(v) for v in (*(core_lo - halo), *(core_hi + halo))])
                del xyz, exact, index, own, rec
                xyz, exact, index, own = _gather(plan, paths, firsts, core_lo - halo,
                                                 core_hi + halo, tile)
                own &= np.isin(index, rest)
                largest = max(largest, len(xyz))
                continue
            far = own_at[~ok]
            break
        failed += f1
        fallback += f2
        results_index.append(index[own_at[ok]])
        results.append(rec[ok])
        if len(far):
            # Fitted apart with everything around them (their look among the gathered points is
            # never nearer than their true k-th neighbour). A robust look also counts the rows
            # its wider planes read, which only rows found in the whole cloud bound: robust far
            # points are certified in their box, and those that look past it fitted again in a
            # box whose looks at least double (the cloud's bounds certify every point).
            far_look = look[~ok]
            fq = xyz[far].astype(np.float64)
            far_index = index[far]
            del xyz, exact, own
            b = np.array(bounds)
            robust = options["method"] == "robust"
            far_count = len(far)
            while len(far_index):
                finite_look = np.isfinite(far_look)
                grown_lo = np.where(finite_look[:, None], fq - far_look[:, None], b[None, :3])
                grown_hi = np.where(finite_look[:, None], fq + far_look[:, None], b[None, 3:])
                a_lo = np.maximum(grown_lo.min(axis=0), b[:3] - 1.0)
                a_hi = np.minimum(grown_hi.max(axis=0), b[3:] + 1.0)
                boxes.append([float(v) for v in (*a_lo, *a_hi)])
                xyz2, exact2, index2, _ = _gather(plan, paths, firsts, a_lo, a_hi, -1)
                largest = max(largest, len(xyz2))
                positions = np.searchsorted(index2, far_index)
                if robust:
                    rec2, ok2, look2, _, f1, f2 = _fit(plan, xyz2, exact2, positions, options,
                                                       a_lo, a_hi, "certified")
                else:
                    rec2, _, _, _, f1, f2 = _fit(plan, xyz2, exact2, positions, options, None,
                                                 None, "all")
                    ok2 = np.ones(len(far_index), bool)
                failed += f1
                fallback += f2
                results_index.append(far_index[ok2])
                results.append(rec2[ok2])
                far_look = far_look[~ok2]
                if robust:
                    far_look = np.maximum(look2[~ok2], 2.0 * far_look)
                fq, far_index = fq[~ok2], far_index[~ok2]
    gi = np.concatenate(results_index)
    rr = np.concatenate(results).astype(np.float32)
    order = np.argsort(gi, kind="stable")
    gi, rr = gi[order], rr[order]
    payload = struct.pack("<qq", len(gi), floats) + gi.astype("<i8").tobytes() + \
        rr.astype("<f4").tobytes()
    data_path, check_path = _tile_paths(state, tile)
    _write_atomic(data_path, payload)
    _write_atomic(check_path, json.dumps({"sha256": hashlib.sha256(payload).hexdigest(),
                                          "points": int(len(gi)), "floats": floats,
                                          "boxes": boxes}).encode())
    return {"tile": tile, "points": int(len(gi)), "gathered": int(largest), "halo": float(halo),
            "halo_growths": growths, "far_points": int(far_count), "failed": int(failed),
            "fallback": int(fallback), "peak_bytes": _peak_bytes(), "pid": os.getpid(),
            "seconds": time.perf_counter() - start}


def write_output(inputs: List[str], output: str, results_path: str, first: int, floats: int,
                 tool: str, precision: str) -> int:
    """One output file on a worker: the inputs' points and fields, as the tool writes them, with
    the results from row `first` of the results file (written atomically)."""
    return _pcl_ddg._write_output(inputs, output, results_path, first, floats, tool, precision)


# ---------------------------------------------------------------------------------------------
# The client


def _import_distributed():
    try:
        import distributed  # noqa: F401
    except ImportError as error:  # pragma: no cover
        raise DistributedError("dask.distributed is needed (Debian: python3-distributed)") \
            from error
    return distributed


def connect(scheduler: Optional[str] = None, workers: Optional[int] = None,
            threads_per_worker: int = 1, timeout: float = 5.0, quiet: bool = True):
    """A Client of the scheduler at `scheduler`, or of a new LocalCluster of `workers` processes
    (one thread each). An unreachable scheduler is a DistributedError within `timeout` s."""
    distributed = _import_distributed()
    if scheduler:
        try:
            return distributed.Client(scheduler, timeout=timeout)
        except (OSError, TimeoutError) as error:
            raise DistributedError(f"cannot reach the Dask scheduler at {scheduler} within "
                                   f"{timeout:g} s ({type(error).__name__}: {error}); start it "
                                   "with `dask scheduler` or check the address") from None
    import logging

    # Dask's nannies put OMP_NUM_THREADS=1 (and MKL_, OPENBLAS_, MALLOC_TRIM_THRESHOLD_) into the
    # environment of the process that starts them, before each worker (re)spawns: the caller's
    # process, whose later subprocesses (a tool the user runs) would inherit them. They go to the
    # workers alone instead (set in each worker before it imports anything of ours); for as long
    # as the process runs, since a nanny re-reads the setting whenever it restarts a worker.
    import dask

    spawn = dict(dask.config.get("distributed.nanny.pre-spawn-environ", default={}) or {})
    if spawn:
        workers_environ = dask.config.get("distributed.nanny.environ", default={}) or {}
        dask.config.set({"distributed.nanny.pre-spawn-environ": {},
                         "distributed.nanny.environ": {**spawn, **workers_environ}})
    cluster = distributed.LocalCluster(
        n_workers=workers or os.cpu_count() or 1, threads_per_worker=threads_per_worker,
        processes=True, memory_limit=0, dashboard_address=":0",
        silence_logs=logging.ERROR if quiet else logging.WARNING)
    return distributed.Client(cluster)


def _have_bokeh() -> bool:
    """Whether Dask can serve its dashboard (it needs bokeh)."""
    import importlib.util

    return importlib.util.find_spec("bokeh") is not None


def _dashboard(client) -> str:
    try:
        link = client.dashboard_link
    except Exception:  # noqa: BLE001
        link = None
    return link if link and _have_bokeh() else "unavailable (install bokeh for Dask's dashboard)"


class _Progress:
    def __init__(self, total: int, points: int, stream, enabled: bool, unit: str = "tiles"):
        self.total, self.points, self.stream, self.enabled = total, points, stream, enabled
        self.unit = unit
        self.done, self.done_points, self.start = 0, 0, time.perf_counter()
        self.last = 0.0

    def update(self, points: int) -> None:
        self.done += 1
        self.done_points += points
        now = time.perf_counter()
        if not self.enabled or (now - self.last < 0.5 and self.done < self.total):
            return
        self.last = now
        seconds = max(now - self.start, 1e-9)
        end = "\n" if self.done == self.total or not self.stream.isatty() else ""
        if self.unit == "tiles":
            what = f"{self.done_points} points, {self.done_points / seconds:,.0f} points/s"
        else:
            what = f"{self.done / seconds:.2f} files/s"
        self.stream.write(f"\r{self.unit} {self.done}/{self.total}, {what}{end}")
        self.stream.flush()


def _fit_options(method: str, k: Optional[int], radius: Optional[float], max_nn: Optional[int],
                 viewpoint, orient: Optional[str], up, threads: int) -> Dict[str, Any]:
    # What only the runner refuses; the rest is checked, and defaulted, as the tools do.
    if method not in ("pca", "quadric", "robust"):
        raise ValueError(f"method must be 'pca', 'quadric' or 'robust', not '{method}'")
    if isinstance(radius, str):
        if radius.endswith("h"):
            raise ValueError("-radius is a length here (a multiple of h needs the whole cloud)")
        radius = float(radius)
    if orient is not None and orient not in ("viewpoint", "up"):
        raise ValueError(f"-orient {orient} needs the whole cloud; distributed normals face the "
                         "viewpoint or up")
    k, max_nn = _pcl_ddg._fit_request(
        method, None if k is None else int(k), None if radius is None else float(radius),
        None if max_nn is None else int(max_nn), orient, viewpoint is not None, up is not None)
    return {"method": method, "k": k, "radius": float(radius or 0.0), "max_nn": max_nn,
            "viewpoint": None if viewpoint is None else [float(v) for v in viewpoint],
            "orient": orient or "viewpoint", "up": None if up is None else [float(v) for v in up],
            "threads": int(threads)}


def _run(tool: str, inputs, output_dir: str, client=None, *, method: str = "pca",
         k: Optional[int] = None, radius: Optional[float] = None, max_nn: Optional[int] = None,
         viewpoint=None, orient: Optional[str] = None, up=None, precision: str = "float",
         merge: Optional[str] = None, memory_per_worker: Any = "2G", retries: int = 3,
         resume: bool = True, scheduler: Optional[str] = None, workers: Optional[int] = None,
         threads_per_worker: int = 1, output_format: Optional[str] = None,
         allow_mixed_crs: bool = False, progress: bool = False, stream=None,
         connect_timeout: float = 5.0) -> Dict[str, Any]:
    stream = stream or sys.stderr
    start = time.perf_counter()
    if precision not in ("float", "double"):
        raise ValueError("-precision must be float or double")
    options = _fit_options(method, k, radius, max_nn, viewpoint, orient, up, threads_per_worker)
    memory = parse_size(memory_per_worker) if not isinstance(memory_per_worker, int) \
        else int(memory_per_worker)
    if memory - WORKER_BASELINE_BYTES < 4096 * BYTES_PER_POINT:
        raise ValueError(f"--memory-per-worker {memory_per_worker} leaves no room for a tile "
                         f"(a worker holds about {WORKER_BASELINE_BYTES >> 20}M before any "
                         "point); give at least 200M")
    paths = expand_inputs(inputs)
    output_dir = os.fspath(output_dir)
    check_output_folder(output_dir, paths, merge)
    clouds = scan_inputs(paths, allow_mixed_crs)
    total = sum(c.points for c in clouds)
    if method == "robust" and k is None and radius is None:
        options["k"] = min(options["k"], total)  # as the tool's default: 96 or every point
    if options["radius"] == 0 and options["k"] > total:
        raise ValueError(f"-k {options['k']} is more than the {total} points of the input")
    # Aerial LiDAR has no single viewpoint: LAS inputs are oriented up unless told otherwise, as
    # the tools orient them (fit_steps.h, orientLasUp).
    las_up = orient is None and viewpoint is None and all(
        c.path.lower().endswith((".las", ".laz")) for c in clouds)
    if las_up:
        options["orient"] = "up"
        if progress:
            stream.write("pcl_ddg.distributed: LAS inputs: normals oriented up (n . z >= 0, as "
                         "PDAL's filters.normal; viewpoint= or orient= chooses otherwise)\n")
    if options["viewpoint"] is None:
        options["viewpoint"] = list(clouds[0].viewpoint)
    if merge is None:
        names = [os.path.basename(c.path) for c in clouds]
        if output_format:
            names = [os.path.splitext(n)[0] + "." + output_format.lstrip(".") for n in names]
        if len(set(names)) != len(names):
            raise ValueError("two inputs have the same file name: give --merge FILE")
        outputs = [os.path.join(output_dir, n) for n in names]
    else:
        if os.path.splitext(merge)[1].lower() not in OUTPUT_EXTENSIONS:
            raise ValueError(f"--merge {merge}: the output must be .ply, .pcd, .las or .laz")
        if merge.lower().endswith((".las", ".laz")) and \
                not clouds[0].path.lower().endswith((".las", ".laz")):
            raise ValueError(f"--merge {merge}: a LAS or LAZ output keeps a LAS input's layout "
                             "(scale, offset, VLRs): the inputs are not LAS")
        outputs = [merge]
    # Before any tile is fitted: LAZ holds no waveform formats (4, 5, 9, 10).
    laz_outputs = [o for o in outputs if o.lower().endswith(".laz")]
    if laz_outputs and clouds[0].path.lower().endswith((".las", ".laz")):
        point_format = las_header(clouds[0].path)["point_format"]
        if not _pcl_ddg._laz_compressible(point_format):
            raise ValueError(f"{laz_outputs[0]}: point format {point_format} cannot be written as "
                             "LAZ (formats 0-3 and 6-8 can): write .las (--format las)")
    os.makedirs(output_dir, exist_ok=True)
    state = os.path.join(output_dir, STATE_FOLDER, tool)
    config_path = os.path.join(state, "run.json")
    # What every tile's results depend on: the tool, the options that change them (not the
    # threads, memory, precision or outputs: the outputs are written again on every run), the
    # code, and the inputs in order with their point counts (which place each point in the merged
    # cloud). A change of any of them starts afresh; a changed input's content alone redoes only
    # the tiles that read it (below).
    identity = json.loads(json.dumps({
        "tool": tool, "options": {k: v for k, v in options.items() if k != "threads"},
        **_code_identity(), "inputs": [[os.path.realpath(c.path), c.points] for c in clouds]}))
    previous = _read_json(config_path) if resume else None
    recorded = previous.get("files") if isinstance(previous, dict) else None
    fresh = not isinstance(recorded, list) or len(recorded) != len(clouds) or \
        previous.get("identity") != identity
    if fresh:
        shutil.rmtree(state, ignore_errors=True)
        recorded = [None] * len(clouds)
    recorded = [r if isinstance(r, dict) else None for r in recorded]
    # Stat before any read, so that a write during the run shows at the next one.
    files_now = [_file_state(c.path) for c in clouds]
    for sub in ("tiles", "attempts"):
        os.makedirs(os.path.join(state, sub), exist_ok=True)

    own_client = client is None
    if own_client:
        client = connect(scheduler, workers, threads_per_worker, connect_timeout)
    try:
        dashboard = _dashboard(client)
        if progress:
            stream.write(f"pcl_ddg.distributed: dashboard {dashboard}\n")
        # The tile size: what the limit leaves above the workers' own resident memory.
        try:
            resident = max(client.run(_resident_bytes).values())
        except Exception:  # noqa: BLE001
            resident = WORKER_BASELINE_BYTES
        room = memory - worker_baseline_bytes(resident)
        points_per_tile = room // BYTES_PER_POINT
        plan_path = os.path.join(state, "plan.json")
        # A resumed run keeps its tile size while its tiles fit with one 16M step of drift in the
        # workers' resident memory (it moves between runs, and a new tile size would discard the
        # finished tiles); the room around a tile stays reserved.
        started_plan = _read_json(plan_path) if resume else None
        started_size = started_plan.get("points_per_tile", 0) \
            if isinstance(started_plan, dict) else 0
        if 4096 <= started_size and started_size * BYTES_PER_POINT <= room + (16 << 20):
            points_per_tile = started_size
        if points_per_tile < 4096:
            raise ValueError(f"--memory-per-worker {memory_per_worker} leaves no room for a tile "
                             f"(the workers hold {resident >> 20}M before any point)")
        started = time.perf_counter()
        # An input whose stat differs from the record (every input on a fresh start) is hashed
        # by a worker while the others measure the chunks: its content decides, not its times.
        to_hash = [i for i, now in enumerate(files_now) if not _same_file_state(recorded[i], now)]
        hashing = client.map(_file_digest, [clouds[i].path for i in to_hash], pure=False,
                             key=[f"pcl_ddg-sha256-{uuid.uuid4().hex[:8]}-{i}" for i in to_hash])
        plan = make_plan(client, clouds, points_per_tile, options)
        digests = dict(zip(to_hash, client.gather(hashing)))
        changed = [i for i in to_hash if (recorded[i] or {}).get("sha256") != digests[i]]
        seconds_plan = time.perf_counter() - started
        described = json.loads(json.dumps({
            "origin": plan.origin, "lo": plan.lo, "hi": plan.hi, "dims": plan.dims, "tiles": plan.tiles,
            "points_per_tile": plan.points_per_tile, "halo_guess": plan.halo_guess}))
        chunks = json.loads(json.dumps(plan.chunks))
        previous_plan = _read_json(plan_path)
        previous_chunks = previous_plan.pop("chunks", None) \
            if isinstance(previous_plan, dict) else None
        if previous_plan != described:  # tiles of another plan are not this one's
            shutil.rmtree(os.path.join(state, "tiles"), ignore_errors=True)
            os.makedirs(os.path.join(state, "tiles"))
        elif changed:
            # A changed input's points, where they were and where they are now: the tiles that
            # gathered, or would now gather, from its chunks' boxes are redone.
            boxes = [c[3] for c in chunks + (previous_chunks or []) if c[0] in changed]
            stale = plan.tiles if not isinstance(previous_chunks, list) else \
                _tiles_reading(state, plan.tiles, boxes)
            for t in stale:
                _drop_tile(state, t)
        _write_atomic(plan_path, json.dumps({**described, "chunks": chunks}).encode())
        # The inputs as they are now, recorded once the tiles they invalidate are gone.
        files = [{**now, "sha256": digests[i] if i in digests else recorded[i].get("sha256")}
                 for i, now in enumerate(files_now)]
        _write_atomic(config_path, json.dumps({"identity": identity, "files": files}).encode())
        todo = [t for t in plan.tiles if not (resume and tile_complete(state, t))]
        skipped = len(plan.tiles) - len(todo)
        before = set(os.listdir(os.path.join(state, "attempts")))
        report = _Progress(len(todo), plan.finite_points, stream, progress)
        distributed = _import_distributed()
        firsts = [c.first for c in clouds]
        # The plan travels with each task (kilobytes: the chunks' boxes), not as scattered data
        # that a killed worker would take with it.
        futures = [client.submit(run_tile, t, plan, paths, firsts, options, state,
                                 retries=retries, pure=False,
                                 key=f"pcl_ddg-tile-{t}-{uuid.uuid4().hex[:8]}") for t in todo]
        tiles = []
        started = time.perf_counter()
        for future in distributed.as_completed(futures):
            try:
                result = future.result()
            except Exception as error:  # noqa: BLE001
                for f in futures:
                    f.cancel()
                raise DistributedError(f"a tile failed after {retries} retries: "
                                       f"{type(error).__name__}: {error}") from error
            tiles.append(result)
            report.update(result["points"])
        attempts = set(os.listdir(os.path.join(state, "attempts"))) - before
        seconds_tiles = time.perf_counter() - started
        # The results at their points' places, then the output files, written as the tool writes
        # them: one task per input file on the workers (one for a merged output).
        started = time.perf_counter()
        floats = _record_floats(method)
        results_path = os.path.join(state, "results.bin")
        mm = np.memmap(results_path, dtype="<f4", mode="w+", shape=(max(total, 1), floats))
        mm[:] = np.nan
        for t in plan.tiles:
            data_path, _ = _tile_paths(state, t)
            with open(data_path, "rb") as f:
                n, fl = struct.unpack("<qq", f.read(16))
                gi = np.frombuffer(f.read(8 * n), "<i8")
                rr = np.frombuffer(f.read(4 * n * fl), "<f4").reshape(n, fl)
            mm[gi] = rr
        mm.flush()
        del mm
        tool_name = "normals" if tool == "normals" else "curvature"
        writes = [([c.path for c in clouds], merge, 0)] if merge is not None else [
            ([c.path], out, c.first) for c, out in zip(clouds, outputs)]
        # A .pcd is written from the whole cloud (binary_compressed, as the tool writes it): by
        # the client, which no tile budget binds. The others piece by piece, by workers.
        on_client = [w for w in writes if w[1].lower().endswith(".pcd")]
        on_workers = [w for w in writes if w not in on_client]
        try:
            futures = [client.submit(write_output, paths_in, out, results_path, first, floats,
                                     tool_name, precision, retries=retries, pure=False,
                                     key=f"pcl_ddg-write-{i}-{uuid.uuid4().hex[:8]}")
                       for i, (paths_in, out, first) in enumerate(on_workers)]
            for paths_in, out, first in on_client:
                write_output(paths_in, out, results_path, first, floats, tool_name, precision)
            client.gather(futures)
        except Exception as error:  # noqa: BLE001
            raise DistributedError(f"writing the outputs failed: {type(error).__name__}: "
                                   f"{error}") from error
        finally:
            os.remove(results_path)
        seconds_write = time.perf_counter() - started
    finally:
        if own_client:
            cluster = getattr(client, "cluster", None)
            client.close()
            if cluster is not None:
                cluster.close()
    seconds = time.perf_counter() - start
    computed = sum(r["points"] for r in tiles)
    # What the tool would warn about on the merged cloud (the points' sampling is not measured
    # here: the tiles never hold the whole cloud).
    world = [b + plan.origin[i % 3] for i, b in enumerate(plan.bounds)]  # bounds: local frame
    # Non-finite points are left out of the tiles; the tool counts them among the points without
    # an estimate. Resumed tiles' counts are not kept: those of this run's tiles.
    warnings = _pcl_ddg._result_warnings(
        world, options["orient"], list(options["viewpoint"]),
        sum(r["failed"] for r in tiles) + total - plan.finite_points,
        sum(r["fallback"] for r in tiles))
    for message in warnings:
        stream.write(f"pcl_ddg.distributed: warning: {message}\n")
    return {
        "points": total, "finite_points": plan.finite_points, "tiles": len(plan.tiles),
        "orientation": options["orient"] + (" (a LAS input's default)" if las_up else ""),
        "tiles_run": len(tiles), "tiles_skipped": skipped,
        "inputs_hashed": len(to_hash), "inputs_changed": len(changed),
        "retries": max(0, len(attempts) - len(tiles)), "seconds": seconds,
        "points_per_second": computed / seconds if seconds > 0 else 0.0,
        "halo_growths": sum(r["halo_growths"] for r in tiles),
        "far_points": sum(r["far_points"] for r in tiles),
        "largest_gather": max([r["gathered"] for r in tiles], default=0),
        "worker_peak_bytes": max([r["peak_bytes"] for r in tiles], default=0),
        "seconds_plan": seconds_plan, "seconds_tiles": seconds_tiles,
        "seconds_write": seconds_write,
        "points_per_tile": points_per_tile, "grid": list(plan.dims), "outputs": outputs,
        "dashboard": dashboard, "tile_reports": sorted(tiles, key=lambda r: r["tile"]),
        "warnings": warnings,
    }


def estimate_normals(inputs, output_dir, client=None, **options) -> Dict[str, Any]:
    """Normals of the scene formed by `inputs` (files, folders or glob patterns of LAS, binary
    PCD or binary PLY clouds), as ``pcl_ddg_normals -method pca|quadric|robust`` on the merged
    cloud, on a Dask cluster: `client` (a distributed.Client), or
    ``scheduler="tcp://host:8786"``, or a new LocalCluster of ``workers`` processes.

    options: method ("pca"|"quadric"|"robust"), k, radius, max_nn, viewpoint, orient
    ("viewpoint"|"up"), up, precision ("float"|"double"), merge (one output file) or one file per input in
    output_dir (``output_format`` "ply"|"pcd"|"las" to change it), memory_per_worker ("2G"), retries
    (3), resume (True: the tiles of an earlier run of the same tool, options, code and inputs whose
    results match their checksum are skipped; docs/distributed.md, "Resume"),
    threads_per_worker (1), progress (False: a progress line on stderr).

    Returns a summary: points, tiles, tiles_run, tiles_skipped, inputs_hashed (inputs whose stat
    differed from the state's record, or all on a fresh start), inputs_changed (those of them
    whose content differed), retries, seconds, points_per_second, halo_growths, far_points,
    worker_peak_bytes, outputs, dashboard.
    """
    return _run("normals", inputs, output_dir, client, **options)


def principal_curvatures(inputs, output_dir, client=None, **options) -> Dict[str, Any]:
    """Principal curvatures of quadrics (``pcl_ddg_curvature -method quadric``, k default 20) on
    a Dask cluster; the options and the summary are estimate_normals'."""
    options["method"] = "quadric"
    return _run("curvature", inputs, output_dir, client, **options)


# ---------------------------------------------------------------------------------------------
# Batch: one task per file, the tool itself


def find_tool(name: str) -> str:
    """The pcl_ddg_<name> executable: $PCL_DDG_TOOLS_DIR, the build tree beside the module, or
    PATH."""
    exe = name if name.startswith("pcl_ddg_") else f"pcl_ddg_{name}"
    here = os.path.dirname(os.path.abspath(__file__))
    for folder in (os.environ.get("PCL_DDG_TOOLS_DIR"),
                   os.path.join(here, "..", "..", "tools")):
        if folder and os.access(os.path.join(folder, exe), os.X_OK):
            return os.path.abspath(os.path.join(folder, exe))
    found = shutil.which(exe)
    if not found:
        raise DistributedError(f"{exe} not found (set PCL_DDG_TOOLS_DIR or put it on PATH)")
    return found


def _batch_identity(executable: str, arguments: Sequence[str]) -> Dict[str, Any]:
    """What a batch output depends on besides its input: the tool (its name and its executable's
    SHA-256: a rebuilt tool is another tool), its arguments and the project version."""
    return {"tool": os.path.basename(executable), "tool_sha256": _file_digest(executable),
            "arguments": [str(a) for a in arguments], "version": project_version()}


def _batch_complete(output: str, record: str, identity: Dict[str, Any], source: str) -> str:
    """Whether an output is done, from its record (state folder, <output name>.json): "complete"
    when the record names this tool, arguments and version, this input with the stat it has now,
    and the output matches its checksum; "hash" when all but the input's stat match (its content
    decides: the worker hashes it); else "run"."""
    previous = _read_json(record)
    try:
        if not isinstance(previous, dict) or \
                any(previous.get(k) != v for k, v in identity.items()):
            return "run"
        recorded, now = previous["input"], _file_state(source)
        if recorded["path"] != now["path"] or previous["output_sha256"] != _file_digest(output):
            return "run"
    except (OSError, KeyError, TypeError):
        return "run"
    return "complete" if _same_file_state(recorded, now) else "hash"


def run_file(tool: str, arguments: List[str], source: str, output: str, record: str,
             identity: Optional[Dict[str, Any]] = None, recheck: bool = False) -> Dict:
    """One file through the tool on a worker: the output under a temporary name, renamed when
    complete, then its record (identity, the input's stat and SHA-256, the output's SHA-256).
    recheck: the input's stat changed but its record is otherwise complete; an input whose
    content is the one recorded is not run again (skipped: True)."""
    start = time.perf_counter()
    state = _file_state(source)  # before the read: a write during the run shows next time
    digest = _file_digest(source)
    if recheck:
        previous = _read_json(record)
        if isinstance(previous, dict) and isinstance(previous.get("input"), dict) and \
                previous["input"].get("sha256") == digest:
            _write_atomic(record, json.dumps({**previous, "input": {**state, "sha256": digest}})
                          .encode())
            return {"input": source, "output": output, "skipped": True,
                    "seconds": time.perf_counter() - start, "peak_bytes": _peak_bytes()}
    folder, name = os.path.split(output)
    temporary = os.path.join(folder, f".{uuid.uuid4().hex[:8]}.partial.{name}")
    result = subprocess.run([tool, source, temporary, *arguments], capture_output=True,
                            text=True)
    if result.returncode != 0:
        if os.path.exists(temporary):
            os.remove(temporary)
        raise RuntimeError(f"{os.path.basename(tool)} {source}: {result.stderr.strip()}")
    os.replace(temporary, output)
    _write_atomic(record, json.dumps({**(identity or {}), "input": {**state, "sha256": digest},
                                      "output_sha256": _file_digest(output)}).encode())
    legacy = os.path.splitext(record)[0] + ".sha256"  # the record before issue 47: checksum only
    if os.path.exists(legacy):
        os.remove(legacy)
    return {"input": source, "output": output, "skipped": False,
            "seconds": time.perf_counter() - start, "peak_bytes": _peak_bytes()}


def _batch_output_name(path: str) -> str:
    """The name of batch's output for an input: the input's, or <stem>.ply for a format the tools
    do not write (.obj .off .stl .vtk)."""
    name = os.path.basename(path)
    stem, extension = os.path.splitext(name)
    return name if extension.lower() in OUTPUT_EXTENSIONS else stem + ".ply"


def batch(inputs, output_dir, tool: str, arguments: Sequence[str] = (), client=None, *,
          retries: int = 3, resume: bool = True, scheduler: Optional[str] = None,
          workers: Optional[int] = None, progress: bool = False, stream=None,
          connect_timeout: float = 5.0) -> Dict[str, Any]:
    """Runs the tool (``normals``, ``curvature``, ... or ``pcl_ddg_smooth``) on every input file
    (a cloud or a mesh; a folder gives all of its files the tools read) independently, one task
    each: OUTPUT_DIR/<input's name> equals the tool run on that file, written as .ply for a mesh
    format the tools do not write (a.off gives a.ply). resume: a file whose output was written
    by the same tool (executable), arguments and version from the same input content, and is
    intact, is skipped (docs/distributed.md, "Resume")."""
    stream = stream or sys.stderr
    start = time.perf_counter()
    executable = find_tool(tool)
    paths = expand_inputs(inputs, CLOUD_EXTENSIONS + MESH_EXTENSIONS)
    output_dir = os.fspath(output_dir)
    check_output_folder(output_dir, paths, None)
    names = [_batch_output_name(p) for p in paths]
    written_by: Dict[str, str] = {}
    for p, n in zip(paths, names):
        if n in written_by:
            raise ValueError(f"{written_by[n]} and {p} would both write {n}")
        written_by[n] = p
    state = os.path.join(output_dir, STATE_FOLDER, "batch")
    os.makedirs(state, exist_ok=True)
    identity = json.loads(json.dumps(_batch_identity(executable, arguments)))
    jobs = []
    skipped = 0
    for p, n in zip(paths, names):
        out, record = os.path.join(output_dir, n), os.path.join(state, n + ".json")
        status = _batch_complete(out, record, identity, p) if resume else "run"
        if status == "complete":
            skipped += 1
            continue
        jobs.append((p, out, record, status == "hash"))
    own_client = client is None
    if own_client:
        client = connect(scheduler, workers, 1, connect_timeout)
    try:
        dashboard = _dashboard(client)
        if progress:
            stream.write(f"pcl_ddg.distributed: dashboard {dashboard}\n")
        distributed = _import_distributed()
        futures = [client.submit(run_file, executable, list(arguments), p, o, r, identity,
                                 recheck, retries=retries, pure=False,
                                 key=f"pcl_ddg-file-{i}-{uuid.uuid4().hex[:8]}")
                   for i, (p, o, r, recheck) in enumerate(jobs)]
        report = _Progress(len(jobs), 0, stream, progress, unit="files")
        done = []
        for future in distributed.as_completed(futures):
            try:
                done.append(future.result())
            except Exception as error:  # noqa: BLE001
                raise DistributedError(str(error)) from error
            report.update(0)
    finally:
        if own_client:
            cluster = getattr(client, "cluster", None)
            client.close()
            if cluster is not None:
                cluster.close()
    rechecked = sum(1 for d in done if d["skipped"])
    return {"files": len(paths), "files_run": len(done) - rechecked,
            "files_skipped": skipped + rechecked, "files_rechecked": rechecked,
            "seconds": time.perf_counter() - start,
            "outputs": [os.path.join(output_dir, n) for n in names], "dashboard": dashboard}


# ---------------------------------------------------------------------------------------------
# Command line


def _vector(text: str) -> List[float]:
    parts = text.split(",")
    if len(parts) != 3:
        raise argparse.ArgumentTypeError(f"x,y,z, not '{text}'")
    return [float(p) for p in parts]


def _parser(tool: str) -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog=f"python3 -m pcl_ddg.distributed {tool}", allow_abbrev=False,
        description=("Normals" if tool == "normals" else "Principal curvatures (quadric)") +
        " of a scene of LAS/binary PCD/binary PLY files on a Dask cluster, equal byte for byte to "
        f"pcl_ddg_{tool} on the merged cloud.")
    p.add_argument("paths", nargs="+", metavar="INPUT... OUTPUT_DIR")
    if tool == "normals":
        p.add_argument("-method", choices=["pca", "quadric", "robust"], default="pca")
    p.add_argument("-k", type=int)
    p.add_argument("-radius", type=str)
    p.add_argument("-max_nn", type=int)
    p.add_argument("-viewpoint", type=_vector)
    p.add_argument("-orient", choices=["viewpoint", "up"])
    p.add_argument("-up", type=_vector)
    p.add_argument("-precision", choices=["float", "double"], default="float")
    p.add_argument("-neighbours", choices=["kdtree", "knn"], default="kdtree",
                   help="kd-tree neighbours (mesh rings and pixel grids need the whole input)")
    p.add_argument("--scheduler", help="tcp://HOST:8786 (default: a LocalCluster)")
    p.add_argument("--workers", type=int, help="LocalCluster worker processes (default: cores)")
    p.add_argument("--threads-per-worker", type=int, default=1)
    p.add_argument("--memory-per-worker", default="2G")
    p.add_argument("--retries", type=int, default=3)
    p.add_argument("--merge", metavar="FILE", help="one output file in the inputs' order")
    p.add_argument("--format", choices=["ply", "pcd", "las", "laz"],
                   help="per-input outputs' format")
    p.add_argument("--resume", action=argparse.BooleanOptionalAction, default=True)
    p.add_argument("--allow-mixed-crs", action="store_true")
    p.add_argument("--connect-timeout", type=float, default=5.0)
    return p


def main(argv: Optional[Sequence[str]] = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    usage = ("usage: python3 -m pcl_ddg.distributed normals|curvature INPUT... OUTPUT_DIR "
             "[options]\n       python3 -m pcl_ddg.distributed batch 'PATTERN' OUTPUT_DIR -- "
             "TOOL [tool flags]\n")
    if not argv or argv[0] in ("-h", "--help"):
        sys.stdout.write(usage)
        return 0 if argv else 2
    command, rest = argv[0], argv[1:]
    try:
        if command == "batch":
            if "--" not in rest:
                raise ValueError("batch needs '-- TOOL [flags]' after the output folder")
            cut = rest.index("--")
            own, tool_args = rest[:cut], rest[cut + 1:]
            if not tool_args:
                raise ValueError("batch needs a tool after '--'")
            p = argparse.ArgumentParser(prog="python3 -m pcl_ddg.distributed batch",
                                        allow_abbrev=False)
            p.add_argument("paths", nargs="+")
            p.add_argument("--scheduler")
            p.add_argument("--workers", type=int)
            p.add_argument("--retries", type=int, default=3)
            p.add_argument("--resume", action=argparse.BooleanOptionalAction, default=True)
            p.add_argument("--connect-timeout", type=float, default=5.0)
            a = p.parse_args(own)
            if len(a.paths) < 2:
                p.error("give INPUT... OUTPUT_DIR")
            summary = batch(a.paths[:-1], a.paths[-1], tool_args[0], tool_args[1:],
                            retries=a.retries, resume=a.resume, scheduler=a.scheduler,
                            workers=a.workers, progress=True, connect_timeout=a.connect_timeout)
            sys.stderr.write(f"pcl_ddg.distributed: {summary['files_run']} files run, "
                             f"{summary['files_skipped']} already complete, "
                             f"{summary['seconds']:.1f} s\n")
            return 0
        if command not in ("normals", "curvature"):
            raise ValueError(f"unknown command '{command}' (normals, curvature or batch)")
        a = _parser(command).parse_args(rest)
        if len(a.paths) < 2:
            raise ValueError("give INPUT... OUTPUT_DIR")
        options = dict(k=a.k, radius=a.radius, max_nn=a.max_nn, viewpoint=a.viewpoint,
                       orient=a.orient, up=a.up, precision=a.precision, merge=a.merge,
                       memory_per_worker=a.memory_per_worker, retries=a.retries,
                       resume=a.resume, scheduler=a.scheduler, workers=a.workers,
                       threads_per_worker=a.threads_per_worker, output_format=a.format,
                       allow_mixed_crs=a.allow_mixed_crs, progress=True,
                       connect_timeout=a.connect_timeout)
        if command == "normals":
            summary = estimate_normals(a.paths[:-1], a.paths[-1], method=a.method, **options)
        else:
            summary = principal_curvatures(a.paths[:-1], a.paths[-1], **options)
        sys.stderr.write(
            f"pcl_ddg.distributed: {summary['points']} points in {summary['tiles']} tiles "
            f"({summary['tiles_run']} run, {summary['tiles_skipped']} already complete, "
            f"{summary['retries']} retries), {summary['seconds']:.1f} s, "
            f"{summary['points_per_second']:,.0f} points/s; worker peak "
            f"{summary['worker_peak_bytes'] / 2**20:.0f} MiB; wrote "
            f"{', '.join(summary['outputs'])}\n")
        return 0
    except (ValueError, OSError, DistributedError) as error:
        sys.stderr.write(f"pcl_ddg.distributed: {error}\n")
        return 1


if __name__ == "__main__":
    sys.exit(main())
