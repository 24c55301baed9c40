"""pcl_ddg.distributed on a LocalCluster of 2 worker processes: a shared scan split into 4 files by
a grid (written here, in a temporary folder) gives, merged, the bytes pcl_ddg_normals /
pcl_ddg_curvature write for the merged cloud; batch mode equals the tool per file (clouds, and
OFF, OBJ and STL meshes, whose outputs are PLY); the far-point refit and the halo widening where
they must run; a worker killed in the middle of a tile, a resumed run, reruns after a change of
options, version, input or tool (exactly what it affects is redone), bad inputs, and a worker's
peak memory."""

import json
import os
import signal
import struct
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import pcl_ddg
from conftest import icosphere, run_tool, shared_data

distributed = pytest.importorskip("distributed")
import pcl_ddg.distributed as dd  # noqa: E402

# For the command line's own cluster of fresh workers (about 100M each before any point, more on
# some machines): room for tiles of up to about 160k points.
MEMORY = "192M"


STEP = 16 << 20
POINT_BYTES = 400  # docs/distributed.md: a tile's room holds a gathered point per 400 bytes


def baseline(resident):
    """Where a tile's room starts (docs/distributed.md, Memory): the workers' resident memory
    rounded up to 16 MiB, plus 16 MiB."""
    return (resident // STEP + 2) * STEP


def memory(client, points=30000):
    """A limit that leaves tiles of `points` points above what the client's workers hold now:
    they grow from test to test (from about 100M to 112M on some machines), which a fixed
    limit would leave no room above."""
    resident = max(client.run(dd._resident_bytes).values())
    return baseline(resident) + points * POINT_BYTES


@pytest.fixture(scope="module")
def client():
    c = dd.connect(workers=2)
    yield c
    cluster = c.cluster
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def scene(tmp_path_factory):
    """terrain_CSite1 (aerial LiDAR, UTM, duplicate points) cut into 4 binary PLY files by a
    grid off its median, and their concatenation, the merged cloud."""
    folder = tmp_path_factory.mktemp("scene")
    mesh = pcl_ddg.read(shared_data() / "clouds" / "terrain_CSite1_red2-utm.pcd")
    p = mesh.points[np.isfinite(mesh.points).all(axis=1)]
    cut = np.median(p[:, :2], axis=0) + 13.0
    quadrant = (p[:, 0] >= cut[0]).astype(int) * 2 + (p[:, 1] >= cut[1]).astype(int)
    parts = [p[quadrant == i] for i in range(4)]
    parts[1][[7, 4000]] = np.nan  # rows without a point: NaN out, as the tool
    (folder / "tiles").mkdir()
    paths = []
    for i, part in enumerate(parts):
        paths.append(folder / "tiles" / f"part{i}.ply")
        pcl_ddg.write(paths[-1], part)
    merged = folder / "merged.ply"
    pcl_ddg.write(merged, np.concatenate(parts))
    return paths, merged


@pytest.fixture(scope="module")
def las_scene(tmp_path_factory):
    """autzen_trim.las (LAS 1.2, format 3, scale 0.01) cut into 4 LAS files by a grid, and their
    concatenation: the header and VLRs kept, the count set, the records copied byte for byte."""
    folder = tmp_path_factory.mktemp("las")
    data = (shared_data() / "las" / "autzen_trim.las").read_bytes()
    offset, = struct.unpack_from("<I", data, 96)
    length, = struct.unpack_from("<H", data, 105)
    count, = struct.unpack_from("<I", data, 107)
    records = np.frombuffer(data, np.uint8, count * length, offset).reshape(count, length)
    X = records[:, 0:4].copy().view("<i4").ravel()
    Y = records[:, 4:8].copy().view("<i4").ravel()
    quadrant = (X >= np.median(X) + 1300).astype(int) * 2 + (Y >= np.median(Y) + 1300)

    def write(path, part):
        head = bytearray(data[:offset])
        struct.pack_into("<I", head, 107, len(part))
        path.write_bytes(bytes(head) + part.tobytes())

    (folder / "tiles").mkdir()
    parts = [records[quadrant == i] for i in range(4)]
    paths = [folder / "tiles" / f"part{i}.las" for i in range(4)]
    for path, part in zip(paths, parts):
        write(path, part)
    write(folder / "merged.las", np.concatenate(parts))
    return paths, folder / "merged.las"


def keywords(args):
    names = {"-k": "k", "-radius": "radius", "-method": "method", "-max_nn": "max_nn"}
    out = {}
    for flag, value in zip(args[::2], args[1::2]):
        out[names[flag]] = value if flag == "-method" else float(value) if flag == "-radius" \
            else int(value)
    return out


@pytest.mark.parametrize("args", [["-k", "16"], ["-radius", "2.5"],
                                  ["-method", "quadric", "-k", "20"],
                                  ["-method", "quadric", "-radius", "3", "-max_nn", "40"]])
def test_merged_normals_equal_the_tool_on_the_merged_cloud(tmp_path, client, scene, args):
    paths, merged = scene
    expected = tmp_path / "tool.ply"
    run_tool("pcl_ddg_normals", merged, expected, *args)
    out = tmp_path / "out"
    summary = dd.estimate_normals(paths, out, client=client, merge=str(out / "merged.ply"),
                                  memory_per_worker=memory(client), **keywords(args))
    assert summary["tiles"] >= 4 and summary["points"] == 131622
    assert (out / "merged.ply").read_bytes() == expected.read_bytes()


@pytest.mark.parametrize("args,suffix", [(["-k", "16", "-orient", "up"], ".ply"),
                                         (["-method", "quadric", "-radius", "8"], ".pcd"),
                                         (["-k", "16"], ".las"),
                                         # its wider planes read rows a dozen steps away
                                         (["-method", "robust"], ".las")])
def test_las_tiles_equal_the_tool_on_the_merged_las(tmp_path, client, las_scene, args, suffix):
    paths, merged = las_scene
    expected = tmp_path / ("tool" + suffix)
    run_tool("pcl_ddg_normals", merged, expected, *args)
    out = tmp_path / "out"
    options = keywords([a for a in args if a not in ("-orient", "up")])
    if "up" in args:
        options["orient"] = "up"
    dd.estimate_normals(paths, out, client=client, merge=str(out / ("m" + suffix)),
                        memory_per_worker=memory(client), **options)
    assert (out / ("m" + suffix)).read_bytes() == expected.read_bytes()


@pytest.mark.parametrize("name,args", [("autzen_trim.laz", ["-k", "16"]),
                                       ("1.2-with-color.copc.laz", ["-method", "quadric",
                                                                    "-k", "12"])])
def test_laz_tiles_equal_the_tool_and_follow_the_chunk_table(tmp_path, client, name, args):
    # A LAZ input: the plan's chunks are the file's compressed chunks (autzen: three of up to
    # 50,000 points; COPC: its 65 nodes), each tile decodes the chunks its box meets, and the
    # .laz output (its records compressed a chunk at a time) is the tool's, byte for byte.
    laz = shared_data() / "las" / "laz" / name
    expected = tmp_path / ("tool_" + name)
    run_tool("pcl_ddg_normals", laz, expected, *args)
    out = tmp_path / "out"
    summary = dd.estimate_normals([laz], out, client=client, **keywords(args),
                                  memory_per_worker=memory(client, 8000))
    assert (out / name).read_bytes() == expected.read_bytes()
    plan = json.loads((out / dd.STATE_FOLDER / "normals" / "plan.json").read_text())
    table = pcl_ddg._pcl_ddg._cloud_layout(str(laz))["chunks"]
    assert len(table) == (3 if name == "autzen_trim.laz" else 65)
    # The plan's chunks follow the table's: in order, covering every point, none across the end
    # of a compressed chunk (the large ones cut to the plan's chunk size).
    ends = {first + count for first, count in table}
    at = 0
    for _, first, count, _ in plan["chunks"]:
        assert first == at and count > 0
        start = max(f for f, _ in table if f <= first)
        assert first + count <= min(e for e in ends if e > start)
        at = first + count
    assert at == sum(count for _, count in table)
    if name == "autzen_trim.laz":
        assert summary["tiles"] >= 4


def test_survey_coordinates_in_tiles_equal_the_tool_and_the_cloud_at_the_origin(tmp_path, client):
    # A double PLY 5e6 from the origin (a sphere beside a height field on a 2^-16 grid): the tiles
    # are searched and fitted about the run's local origin, as the tool fits the file, and give
    # the normals of the same points at the origin (but where two frames' floats order a near
    # tie of distances differently).
    rng = np.random.default_rng(3)
    d = rng.normal(size=(20000, 3))
    sphere = np.array([150.0, 0.0, 0.0]) + 20.0 * d / np.linalg.norm(d, axis=1)[:, None]
    u, v = np.meshgrid(np.arange(100.0) - 50.0, np.arange(100.0) - 50.0)
    x, y = u.ravel() + rng.uniform(-0.3, 0.3, u.size), v.ravel() + rng.uniform(-0.3, 0.3, v.size)
    near = np.concatenate([sphere, np.stack([x, y, np.sin(x / 7.0) * np.cos(y / 5.0)], 1)])
    near = np.round(near * 65536.0) / 65536.0
    far = near + np.array([5e5, 5e6, 200.0])
    pcl_ddg.write(tmp_path / "far.ply", far)
    run_tool("pcl_ddg_normals", tmp_path / "far.ply", tmp_path / "tool.ply", "-k", "16",
             "-orient", "up")
    summary = dd.estimate_normals([tmp_path / "far.ply"], tmp_path / "out", client=client, k=16,
                                  orient="up", memory_per_worker=memory(client, 8000))
    assert summary["tiles"] >= 4
    assert (tmp_path / "out" / "far.ply").read_bytes() == (tmp_path / "tool.ply").read_bytes()
    fields = pcl_ddg.read(tmp_path / "out" / "far.ply").fields
    tiles = np.stack([fields["nx"], fields["ny"], fields["nz"]], axis=1).astype(np.float64)
    reference = pcl_ddg.estimate_normals(near, k=16, orient="up").normals
    # atan2 of the cross and dot products: exact near 0, where arccos of a float dot is not.
    angle = np.arctan2(np.linalg.norm(np.cross(tiles, reference), axis=1),
                       np.abs(np.sum(tiles * reference, axis=1)))
    assert np.count_nonzero(angle > 1e-6) <= len(near) // 500, np.sort(angle)[-10:]


def test_curvature_pcd_and_per_file_outputs(tmp_path, client, scene):
    paths, merged = scene
    expected = tmp_path / "tool.pcd"
    run_tool("pcl_ddg_curvature", merged, expected, "-method", "quadric", "-k", "20")
    out = tmp_path / "out"
    dd.principal_curvatures(paths, out, client=client, merge=str(tmp_path / "merged.pcd"),
                            memory_per_worker=memory(client), k=20)
    assert (tmp_path / "merged.pcd").read_bytes() == expected.read_bytes()
    # Without --merge: one file per input, its points with the scene's neighbours (the merged
    # result's rows of that file).
    summary = dd.estimate_normals(paths, out, client=client, memory_per_worker=memory(client), k=16)
    run_tool("pcl_ddg_normals", merged, tmp_path / "tool.ply", "-k", "16", "-precision", "double")
    whole = pcl_ddg.read(tmp_path / "tool.ply").fields
    first = 0
    for path, output in zip(paths, summary["outputs"]):
        part = pcl_ddg.read(output)
        n = len(part.points)
        np.testing.assert_array_equal(part.points, pcl_ddg.read(path).points)
        for name in ("nx", "ny", "nz", "curvature"):
            np.testing.assert_array_equal(part.fields[name], whole[name][first:first + n])
        first += n


def test_command_line(tmp_path, scene):
    paths, merged = scene
    expected = tmp_path / "tool.ply"
    run_tool("pcl_ddg_normals", merged, expected, "-k", "12")
    out = tmp_path / "out"
    result = subprocess.run(
        [sys.executable, "-m", "pcl_ddg.distributed", "normals", *map(str, paths), str(out),
         "-k", "12", "--workers", "2", "--memory-per-worker", MEMORY, "--merge",
         str(out / "m.ply")], capture_output=True, text=True, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "dashboard" in result.stderr and "points/s" in result.stderr
    assert (out / "m.ply").read_bytes() == expected.read_bytes()


def test_batch_equals_the_tool_per_file(tmp_path, client, scene):
    paths, _ = scene
    out = tmp_path / "out"
    summary = dd.batch(str(paths[0].parent / "part[01].ply"), out, "normals",
                       ["-method", "quadric", "-k", "20"], client=client)
    assert summary["files_run"] == 2
    for path in paths[:2]:
        run_tool("pcl_ddg_normals", path, tmp_path / path.name, "-method", "quadric", "-k", "20")
        assert (out / path.name).read_bytes() == (tmp_path / path.name).read_bytes()
    again = dd.batch(str(paths[0].parent / "part[01].ply"), out, "normals",
                     ["-method", "quadric", "-k", "20"], client=client)
    assert again["files_run"] == 0 and again["files_skipped"] == 2


def test_batch_redoes_what_changed_and_only_that(tmp_path, client, scene, monkeypatch):
    """batch keeps an output only for the tool (its executable), arguments, project version and
    input content that made it: other arguments redo every file; an input rewritten with its
    size and mtime kept redoes that file alone; an input touched without a change is hashed (by
    a worker) and skipped; a rebuilt tool or another version redoes everything. Every output is
    then the tool's bytes for its input and arguments."""
    paths, _ = scene
    inputs = tmp_path / "in"
    inputs.mkdir()
    a, b = inputs / "a.ply", inputs / "b.ply"
    a.write_bytes(paths[0].read_bytes())
    b.write_bytes(paths[1].read_bytes())
    out = tmp_path / "out"

    def run(*args):
        return dd.batch(str(inputs), out, "normals", list(args), client=client)

    def assert_outputs(*args):
        for path in (a, b):
            expected = tmp_path / ("tool_" + path.name)
            run_tool("pcl_ddg_normals", path, expected, *args)
            assert (out / path.name).read_bytes() == expected.read_bytes(), (path.name, args)

    assert run("-k", "16")["files_run"] == 2
    assert_outputs("-k", "16")
    summary = run("-k", "12")
    assert (summary["files_run"], summary["files_skipped"]) == (2, 0)
    assert_outputs("-k", "12")

    # b rewritten: the same size, its mtime set back.
    stat = b.stat()
    cloud = pcl_ddg.read(b)
    points = cloud.points.copy()
    points[:, 2] += 0.5
    pcl_ddg.write(b, points, precision=cloud.precision)  # its own precision: the same size
    os.utime(b, ns=(stat.st_atime_ns, stat.st_mtime_ns))
    assert (b.stat().st_size, b.stat().st_mtime_ns) == (stat.st_size, stat.st_mtime_ns)
    summary = run("-k", "12")
    assert (summary["files_run"], summary["files_skipped"]) == (1, 1)
    assert_outputs("-k", "12")

    # a touched: its stat changed, its content did not.
    stat = a.stat()
    os.utime(a, ns=(stat.st_atime_ns, stat.st_mtime_ns + 10**9))
    summary = run("-k", "12")
    assert (summary["files_run"], summary["files_skipped"], summary["files_rechecked"]) == \
        (0, 2, 1)
    summary = run("-k", "12")  # and the record follows the new stat: no hash this time
    assert (summary["files_run"], summary["files_skipped"], summary["files_rechecked"]) == \
        (0, 2, 0)

    # A rebuilt tool: here the same program with a byte more (an ELF ignores it).
    tools = tmp_path / "tools"
    tools.mkdir()
    rebuilt = tools / "pcl_ddg_normals"
    with open(dd.find_tool("normals"), "rb") as f:
        rebuilt.write_bytes(f.read() + b"\0")
    rebuilt.chmod(0o755)
    monkeypatch.setenv("PCL_DDG_TOOLS_DIR", str(tools))
    assert run("-k", "12")["files_run"] == 2
    assert_outputs("-k", "12")
    assert run("-k", "12")["files_run"] == 0

    monkeypatch.setattr(pcl_ddg, "__version__", pcl_ddg.__version__ + "+changed")
    summary = run("-k", "12")
    assert (summary["files_run"], summary["files_skipped"]) == (2, 0)
    assert_outputs("-k", "12")


def write_meshes(folder, V, F):
    """The same triangle mesh as OFF, OBJ and ASCII STL (sphere_off.off, ...), written here from
    the formats' texts."""
    folder.mkdir()
    rows = ["{!r} {!r} {!r}\n".format(*v) for v in V]
    texts = {
        "off": f"OFF\n{len(V)} {len(F)} 0\n" + "".join(rows) +
               "".join(f"3 {a} {b} {c}\n" for a, b, c in F),
        "obj": "".join("v " + r for r in rows) +
               "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F),
        "stl": "solid sphere\n" + "".join(
            "facet normal 0 0 0\nouter loop\n" + "".join("vertex " + rows[i] for i in face) +
            "endloop\nendfacet\n" for face in F) + "endsolid sphere\n",
    }
    paths = []
    for extension, text in texts.items():
        paths.append(folder / f"sphere_{extension}.{extension}")
        paths[-1].write_text(text)
    return paths


def test_batch_over_meshes_writes_ply_with_the_tools_normals(tmp_path, client):
    """Meshes with default options: each output is <name>.ply, byte for byte the tool's output
    for that file, and its normals are the sphere's (outward radial, to the faces' resolution)."""
    centre = np.array([3.0, -1.0, 0.5])
    V, F = icosphere(3, radius=2.0)
    inputs = write_meshes(tmp_path / "meshes", V + centre, F)
    out = tmp_path / "out"
    summary = dd.batch(str(tmp_path / "meshes" / "sphere_*"), out, "normals", client=client)
    assert summary["files_run"] == 3
    expected = [out / f"sphere_{e}.ply" for e in ("obj", "off", "stl")]  # sorted by name
    assert summary["outputs"] == [str(p) for p in expected]
    for path in inputs:
        written = out / (path.stem + ".ply")
        assert written.exists(), written
        tool_output = tmp_path / ("tool_" + path.stem + ".ply")
        run_tool("pcl_ddg_normals", path, tool_output)
        assert written.read_bytes() == tool_output.read_bytes(), path.name
        m = pcl_ddg.read(written)
        assert m.faces is not None and len(m.faces) == len(F)
        n = np.stack([m.fields["nx"], m.fields["ny"], m.fields["nz"]], axis=1)
        radial = m.points - centre
        radial /= np.linalg.norm(radial, axis=1, keepdims=True)
        assert np.all(np.einsum("ij,ij->i", n, radial) > 0.999), path.name
    # A folder gives its meshes too; two that would write the same .ply are refused before any
    # task runs, naming both.
    twice = tmp_path / "twice"
    twice.mkdir()
    for path in inputs[:2]:
        (twice / ("same" + path.suffix)).write_bytes(path.read_bytes())
    with pytest.raises(ValueError, match=r"same\.obj and .*same\.off would both write same\.ply"):
        dd.batch(str(twice), tmp_path / "out2", "normals", client=client)


def test_worker_killed_in_a_tile(tmp_path, scene, monkeypatch):
    paths, merged = scene
    expected = tmp_path / "tool.ply"
    run_tool("pcl_ddg_normals", merged, expected, "-k", "16")
    monkeypatch.setenv("PCL_DDG_DISTRIBUTED_TILE_DELAY", "1.0")  # tiles long enough to kill
    own = dd.connect(workers=2)
    out = tmp_path / "out"
    attempts = out / dd.STATE_FOLDER / "normals" / "attempts"
    killed = []

    def killer():
        deadline = time.time() + 60
        while time.time() < deadline and not killed:
            try:
                names = os.listdir(attempts)
            except OSError:
                names = []
            for name in names:
                pid = int(name.split(".")[1])
                os.kill(pid, signal.SIGKILL)  # in the middle of the tile's delay
                killed.append(pid)
                break
            time.sleep(0.02)

    thread = threading.Thread(target=killer)
    thread.start()
    try:
        summary = dd.estimate_normals(paths, out, client=own, merge=str(out / "m.ply"),
                                      memory_per_worker=memory(own), k=16, retries=3)
    finally:
        thread.join()
        cluster = own.cluster
        own.close()
        cluster.close()
    assert killed, "no tile was started"
    print(f"killed worker {killed[0]}: {summary['retries']} retries, {summary['tiles']} tiles")
    assert summary["retries"] >= 1
    assert (out / "m.ply").read_bytes() == expected.read_bytes()


def test_resume_does_only_the_missing_tiles(tmp_path, client, scene):
    paths, merged = scene
    out = tmp_path / "out"
    # Both runs on ballast that puts the workers' resident memory where the test wants it,
    # whatever earlier tests left it at: 1M above a 16M step for the first run, one step higher
    # for the second (as workers drift between runs). The base is 3 steps above what they hold
    # now, so that neither this run's growth nor earlier tests' can reach the second target.
    # (Ballast this large is mmapped: freed, it leaves the process.)
    base = (max(client.run(dd._resident_bytes).values()) // STEP + 4) * STEP

    def grow(target):
        sys.pcl_ddg_ballast = None
        sys.pcl_ddg_ballast = b"\x01" * max(0, target - dd._resident_bytes())
        return dd._resident_bytes()

    tile_points = 30000
    limit = baseline(base + (1 << 20)) + tile_points * POINT_BYTES
    try:
        grown = client.run(grow, base + (1 << 20)).values()
        assert all(base <= r < base + STEP for r in grown), (grown, base)
        first = dd.estimate_normals(paths, out, client=client, merge=str(out / "m.ply"),
                                    memory_per_worker=limit, k=16)
        state = out / dd.STATE_FOLDER / "normals" / "tiles"
        assert json.loads((state.parent / "plan.json").read_text())["points_per_tile"] == \
            tile_points
        tiles = sorted(state.glob("tile_*.bin"))
        assert len(tiles) == first["tiles"] >= 4
        # A run stopped after half its tiles: the other half's results are missing, one of them
        # torn (present, but not what its checksum says).
        half = tiles[len(tiles) // 2:]
        for t in half[1:]:
            t.unlink()
        half[0].write_bytes(half[0].read_bytes()[:-4])
        (out / "m.ply").unlink()
        # The workers one 16M step above the first run's: a fresh plan would find no room left
        # for a tile (the limit leaves 12M above the first run's baseline), the resumed run
        # keeps its tile size.
        assert limit - baseline(base + STEP + (1 << 20)) < 4096 * POINT_BYTES
        grown = client.run(grow, base + STEP + (1 << 20)).values()
        assert all(base + STEP <= r < base + 2 * STEP for r in grown), (grown, base)
        second = dd.estimate_normals(paths, out, client=client, merge=str(out / "m.ply"),
                                     memory_per_worker=limit, k=16)
    finally:
        client.run(lambda: setattr(sys, "pcl_ddg_ballast", None))
    assert second["tiles_run"] == len(half)
    assert second["tiles_skipped"] == len(tiles) - len(half)
    run_tool("pcl_ddg_normals", merged, tmp_path / "tool.ply", "-k", "16")
    assert (out / "m.ply").read_bytes() == (tmp_path / "tool.ply").read_bytes()


def test_other_options_or_version_redo_every_tile_others_none(tmp_path, client, scene,
                                                               monkeypatch):
    """A tile's results are kept only for the options and code that made them: another k, or
    another project version, redoes every tile (and the output is the tool's for the new k);
    what changes no tile's results (the precision, the outputs, the memory limit, the threads)
    redoes none."""
    paths, merged = scene
    out = tmp_path / "out"

    def run(**options):
        # The limit sized anew each run: the workers grow from run to run (a limit fixed at the
        # start left no room for a tile by the fourth run on a 2-core CI machine); a changed limit
        # keeps the tiles (asserted by the third run).
        return dd.estimate_normals(paths, out, client=client, memory_per_worker=memory(client),
                                   **options)

    first = run(k=16, merge=str(out / "m.ply"))
    assert first["tiles_run"] == first["tiles"] >= 4
    second = run(k=12, merge=str(out / "m.ply"))
    assert (second["tiles_run"], second["tiles_skipped"]) == (second["tiles"], 0)
    run_tool("pcl_ddg_normals", merged, tmp_path / "k12.ply", "-k", "12")
    assert (out / "m.ply").read_bytes() == (tmp_path / "k12.ply").read_bytes()

    third = dd.estimate_normals(paths, out, client=client,
                                memory_per_worker=memory(client) + STEP, k=12,
                                precision="double", merge=str(out / "double.ply"),
                                threads_per_worker=2)
    assert (third["tiles_run"], third["tiles_skipped"]) == (0, third["tiles"])
    assert (third["inputs_hashed"], third["inputs_changed"]) == (0, 0)
    run_tool("pcl_ddg_normals", merged, tmp_path / "k12d.ply", "-k", "12", "-precision", "double")
    assert (out / "double.ply").read_bytes() == (tmp_path / "k12d.ply").read_bytes()

    monkeypatch.setattr(pcl_ddg, "__version__", pcl_ddg.__version__ + "+changed")
    fourth = run(k=12, merge=str(out / "m.ply"))
    assert (fourth["tiles_run"], fourth["tiles_skipped"]) == (fourth["tiles"], 0)
    assert (out / "m.ply").read_bytes() == (tmp_path / "k12.ply").read_bytes()


def side_by_side(folder, right_amplitude, rewrite_right=False):
    """Two height fields of unit spacing side by side, each file in x order (so its chunks are
    narrow in x, and the tiles are cut across x): left.ply x in [0, 300), right.ply [300, 600),
    y in [0, 100). The left one holds the scene's lowest and highest points (z within +-2.9 of
    0), so a right one of amplitude below that has the same bounds: the same plan. float32: the
    same file size whatever the values. rewrite_right: left.ply is left alone."""
    u, v = np.meshgrid(np.arange(300.0), np.arange(100.0), indexing="ij")
    x, y = u.ravel(), v.ravel()
    left = np.stack([x, y, 3.0 * np.sin(x / 30.0) * np.cos(y / 20.0)], 1)
    right = np.stack([x + 300.0, y, right_amplitude * np.sin(x / 17.0) * np.cos(y / 11.0)], 1)
    assert np.abs(right[:, 2]).max() < np.abs(left[:, 2]).max() - 0.05
    folder.mkdir(exist_ok=True)
    for name, points in (("left", left), ("right", right))[int(rewrite_right):]:
        pcl_ddg.write(folder / f"{name}.ply", points.astype(np.float32))
    pcl_ddg.write(folder.parent / "merged.ply", np.concatenate([left, right]).astype(np.float32))
    return folder / "left.ply", folder / "right.ply", folder.parent / "merged.ply"


def test_a_changed_input_redoes_the_tiles_that_read_it(tmp_path, client):
    """An input is identified by its stat (size, mtime, ctime) and, when that changed, by its
    SHA-256 (computed by a worker): touched without a change it redoes nothing; rewritten with
    the same size, with or without its mtime set back, it redoes every tile whose gathers meet
    its points (at least those whose cell meets its x range) and only those (at least the cells
    more than 5 point spacings, above any halo here, from it), and the output is the tool's on
    the new scene."""
    folder = tmp_path / "in"
    left, right, merged = side_by_side(folder, 1.0)
    out = tmp_path / "out"

    def run():
        # sized anew each run: the workers grow from run to run (the tiles are kept whatever it)
        summary = dd.estimate_normals([left, right], out, client=client, k=16,
                                      merge=str(out / "m.ply"),
                                      memory_per_worker=memory(client, 8000))
        run_tool("pcl_ddg_normals", merged, tmp_path / "tool.ply", "-k", "16")
        assert (out / "m.ply").read_bytes() == (tmp_path / "tool.ply").read_bytes()
        return summary

    first = run()
    assert first["tiles_run"] == first["tiles"]
    nx, ny, nz = first["grid"]
    assert (ny, nz) == (1, 1) and nx >= 4, first["grid"]
    cells = np.linspace(0.0, 599.0, nx + 1)  # the points' x bounds, cut into nx cells
    must_run = int(np.count_nonzero(cells[1:] >= 300.0))
    must_skip = int(np.count_nonzero(cells[1:] + 5.0 < 300.0))
    assert must_run >= 2 and must_skip >= 1

    stat = right.stat()
    os.utime(right, ns=(stat.st_atime_ns, stat.st_mtime_ns + 10**9))  # touched, not changed
    touched = run()
    assert (touched["tiles_run"], touched["tiles_skipped"]) == (0, touched["tiles"])
    assert (touched["inputs_hashed"], touched["inputs_changed"]) == (1, 0)

    for amplitude, restore_mtime in ((2.0, False), (0.5, True)):
        stat = right.stat()
        side_by_side(folder, amplitude, rewrite_right=True)
        assert right.stat().st_size == stat.st_size
        if restore_mtime:  # what cp -p or an rsync of the old times would leave
            os.utime(right, ns=(stat.st_atime_ns, stat.st_mtime_ns))
            assert right.stat().st_mtime_ns == stat.st_mtime_ns
        again = run()
        assert again["tiles"] == first["tiles"] and again["grid"] == first["grid"]
        assert again["tiles_run"] + again["tiles_skipped"] == again["tiles"]
        assert again["tiles_run"] >= must_run and again["tiles_skipped"] >= must_skip, \
            (again["tiles_run"], again["tiles_skipped"], must_run, must_skip)
        assert (again["inputs_hashed"], again["inputs_changed"]) == (1, 1), amplitude


def outlier_scene(folder):
    """A 350 x 350 height field of unit spacing (amplitude 1), and 30 above it a diagonal line of
    isolated points 5 apart: each one's k-th neighbour (k <= 20) is at least 29 away, further
    than the halo a uniform density gives, so near a tile's face it is not certified."""
    u, v = np.meshgrid(np.arange(350.0), np.arange(350.0), indexing="ij")
    x, y = u.ravel(), v.ravel()
    surface = np.stack([x, y, np.sin(x / 23.0) * np.cos(y / 17.0)], 1)
    t = np.arange(4.0, 346.0, 5.0 / np.sqrt(2.0))
    line = np.stack([t, t, np.full_like(t, 30.0)], 1)
    points = np.concatenate([surface, line])
    points = points[np.lexsort((points[:, 1], points[:, 0]))]  # x order
    folder.mkdir()
    pcl_ddg.write(folder / "outliers.ply", points.astype(np.float32))
    return folder / "outliers.ply", line


def two_densities(folder):
    """Unit spacing on [0, 300)^2 and spacing 12 on [300, 1500) x [0, 300): the halo the mean
    density gives (about 7.4 for k = 16, 8.3 for k = 20) is well below a sparse point's k-th
    neighbour (12 sqrt(5) = 26.8), so in a tile of sparse points alone the points within about
    19 of a face, a column of 25 or more, are far more than 1 % of its points."""
    u, v = np.meshgrid(np.arange(300.0), np.arange(300.0), indexing="ij")
    dense = np.stack([u.ravel(), v.ravel()], 1)
    u, v = np.meshgrid(np.arange(306.0, 1500.0, 12.0), np.arange(6.0, 300.0, 12.0),
                       indexing="ij")
    xy = np.concatenate([dense, np.stack([u.ravel(), v.ravel()], 1)])
    points = np.concatenate([xy, 2.0 * np.sin(xy[:, :1] / 40.0) * np.cos(xy[:, 1:] / 30.0)], 1)
    points = points[np.lexsort((points[:, 1], points[:, 0]))]
    folder.mkdir()
    pcl_ddg.write(folder / "densities.ply", points.astype(np.float32))
    return folder / "densities.ply"


def cuts(summary, lo, hi):
    """The tiles' inner faces along each axis of the grid (the points' bounds cut evenly)."""
    return [np.linspace(lo[a], hi[a], n + 1)[1:-1] for a, n in enumerate(summary["grid"])]


@pytest.mark.parametrize("args", [["-k", "16"], ["-method", "quadric", "-k", "20"]])
def test_far_points_are_refitted_as_the_tool_fits_them(tmp_path, client, args):
    path, line = outlier_scene(tmp_path / "in")
    run_tool("pcl_ddg_normals", path, tmp_path / "tool.ply", *args)
    summary = dd.estimate_normals([path], tmp_path / "out", client=client,
                                  memory_per_worker=memory(client, 12000), **keywords(args))
    assert (tmp_path / "out" / path.name).read_bytes() == (tmp_path / "tool.ply").read_bytes()
    # An isolated point within 20 of an inner face reaches at most 20 + the halo (< 24) inside
    # its tile's halo box, less than its k-th neighbour: not certified. Uniform density elsewhere
    # (the surface's k-th neighbour is under 3.6, the halo over 3.3): no surface point is far,
    # and no tile has 1 % of its points uncertified, so none widens.
    faces = cuts(summary, (0, 0, -1), (349, 349, 30))
    near = sum(1 for p in line if any(np.any(np.abs(f - p[a]) < 20.0) for a, f in enumerate(faces)
                                      if len(f)))
    assert summary["tiles"] >= 4 and summary["grid"][2] == 1 and near >= 10, \
        (summary["grid"], near)
    assert near <= summary["far_points"] <= len(line), (near, summary["far_points"])
    assert summary["halo_growths"] == 0


@pytest.mark.parametrize("args", [["-k", "16"], ["-method", "quadric", "-k", "20"]])
def test_halos_widen_where_the_density_drops_as_the_tool_fits(tmp_path, client, args):
    path = two_densities(tmp_path / "in")
    run_tool("pcl_ddg_normals", path, tmp_path / "tool.ply", *args)
    summary = dd.estimate_normals([path], tmp_path / "out", client=client,
                                  memory_per_worker=memory(client, 12000), **keywords(args))
    assert (tmp_path / "out" / path.name).read_bytes() == (tmp_path / "tool.ply").read_bytes()
    # Every tile whose cell lies in the sparse part widens its halo at least once.
    nx, ny, nz = summary["grid"]
    assert (ny, nz) == (1, 1) and nx >= 4, summary["grid"]
    sparse_tiles = int(np.count_nonzero(np.linspace(0.0, 1494.0, nx + 1)[:-1] >= 300.0))
    assert sparse_tiles >= 2
    assert summary["halo_growths"] >= sparse_tiles, (summary["halo_growths"], sparse_tiles)
    # Each point fitted once: a widened tile keeps its certified fits and refits only the rest.
    assert sum(r["points"] for r in summary["tile_reports"]) == summary["finite_points"]


def test_bad_inputs(tmp_path, client, scene):
    paths, _ = scene
    with pytest.raises(FileNotFoundError, match="missing.ply"):
        dd.estimate_normals([paths[0], tmp_path / "missing.ply"], tmp_path / "o", client=client)
    # Different fields: refused, naming both files.
    other = tmp_path / "other.ply"
    pts = pcl_ddg.read(paths[1]).points
    pcl_ddg.write(other, pts, fields={"intensity": np.ones(len(pts))})
    with pytest.raises(ValueError, match="incompatible inputs.*other.ply"):
        dd.estimate_normals([paths[0], other], tmp_path / "o", client=client)
    # LAS files of different scales.
    las = shared_data() / "las"
    with pytest.raises(ValueError, match="scale"):
        dd.estimate_normals([las / "autzen_trim.las", las / "test1_4.las"], tmp_path / "o",
                            client=client)
    with pytest.raises(ValueError, match="incompatible inputs"):
        dd.estimate_normals([las / "autzen_trim.las", paths[0]], tmp_path / "o", client=client)
    with pytest.raises(OSError, match="version 1"):  # LASzip 1.2r0's first compressors
        dd.estimate_normals([las / "laz" / "simple-laszip-compressor-version-1.2r0.laz"],
                            tmp_path / "o", client=client)
    # The output folder is an input's folder.
    with pytest.raises(ValueError, match="output folder"):
        dd.estimate_normals(paths, paths[0].parent, client=client)
    # A scheduler nobody listens at: a clear error, quickly.
    start = time.perf_counter()
    with pytest.raises(dd.DistributedError, match="cannot reach the Dask scheduler"):
        dd.estimate_normals(paths, tmp_path / "o", scheduler="tcp://127.0.0.1:9")
    assert time.perf_counter() - start < 10


def peak_resident(pid):
    """A process's peak resident memory (VmHWM), read here from /proc, not by the module."""
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
    raise AssertionError(f"no VmHWM for process {pid}")


def test_worker_peak_memory_stays_under_the_limit(tmp_path):
    """A synthetic survey (a height field in flight-line order) of 600k points: fitted at once
    it takes about 10x the room the limit leaves above a worker's own ~100M. The output is a
    .pcd, written by the client, so that the workers' lifetime peak, read here from /proc, is
    that of the plan and the tiles, which the limit binds (a worker that writes a .ply output
    holds 2^18-point pieces, about 40M, whatever the limit: docs/distributed.md, Memory)."""
    own = dd.connect(workers=2)
    try:
        pids = list(own.run(os.getpid).values())
        resident = max(own.run(dd._resident_bytes).values())
        limit = resident + (24 << 20) + (32 << 20)  # 24-40M of tile room above the rounding
        room = limit - baseline(resident)
        # At least 9x the room, whatever the worker's own size rounds to (600k points or more).
        side = max(775, int(np.ceil(np.sqrt(9 * room / POINT_BYTES))))
        u, v = np.meshgrid(np.arange(side, dtype=float), np.arange(side, dtype=float))
        z = 2.0 * np.sin(u / 40.0) * np.cos(v / 55.0)
        points = np.stack([u.ravel(), v.ravel() + 0.25 * (u.ravel() % 2), z.ravel()], 1)
        survey = tmp_path / "in" / "survey.ply"
        survey.parent.mkdir()
        pcl_ddg.write(survey, points.astype(np.float32))
        assert len(points) * POINT_BYTES >= 9 * room
        out = tmp_path / "out"
        summary = dd.estimate_normals([survey], out, client=own, memory_per_worker=int(limit),
                                      k=16, merge=str(out / "survey.pcd"))
        peaks = [peak_resident(pid) for pid in pids]  # the same workers, over their lifetime
        assert sorted(own.run(os.getpid).values()) == sorted(pids)
    finally:
        cluster = own.cluster
        own.close()
        cluster.close()
    print(f"memory: limit {limit >> 20} MiB, worker peak {max(peaks) >> 20} MiB, "
          f"{summary['tiles']} tiles, largest gather {summary['largest_gather']} points")
    # The plan measures the workers again, and their resident memory moves by a 16M rounding step
    # between the two readings on some machines (6 tiles there, 9 here): what matters is that the
    # survey was cut into tiles far smaller than itself, and that the workers stayed under the limit.
    assert summary["tiles"] >= 5
    assert summary["largest_gather"] <= len(points) // 4
    assert max(peaks) <= limit, (peaks, limit)
    # The module's own report, read in the worker: the kernel batches each thread's RSS count
    # (64 pages), which another process's read may not see yet: 2M of slack for that.
    assert 0 < summary["worker_peak_bytes"] <= max(peaks) + (2 << 20), \
        (summary["worker_peak_bytes"], peaks)
    run_tool("pcl_ddg_normals", survey, tmp_path / "tool.pcd", "-k", "16")
    assert (out / "survey.pcd").read_bytes() == (tmp_path / "tool.pcd").read_bytes()
    # and they are the height field's normals: z = 2 sin(u/40) cos(v/55) has a slope of at most
    # sqrt(0.05^2 + 0.036^2) = 0.062, so its exact normal has |nz| = 1/sqrt(1 + slope^2) >= 0.9981;
    # a plane fitted to 16 points a unit apart where the curvature is at most 2/40^2 tilts by
    # ~1e-3 rad at most: |nz| > 0.997 everywhere.
    fields = pcl_ddg.read(out / "survey.pcd").fields
    nz = fields["normal_z"] if "normal_z" in fields else fields["nz"]
    assert len(nz) == len(points) and np.isfinite(nz).all()
    assert np.abs(nz).min() > 0.997, np.abs(nz).min()


def test_starting_a_local_cluster_leaves_the_callers_environment_alone():
    """Dask's nannies set OMP_NUM_THREADS=1 and the like for their workers in the process that
    starts them, at every (re)spawn; a tool the caller runs afterwards must not inherit them (it
    would compute on one thread). The workers still get them."""
    def environment():  # DASK_PARENT only marks the process for Dask's process titles
        return {k: v for k, v in os.environ.items() if k != "DASK_PARENT"}

    before = environment()
    c = dd.connect(workers=1)
    try:
        assert environment() == before
        c.restart()  # the nanny spawns the worker again
        assert environment() == before
        assert c.run(lambda: os.environ.get("OMP_NUM_THREADS")) == {
            address: "1" for address in c.scheduler_info()["workers"]}
    finally:
        cluster = c.cluster
        c.close()
        cluster.close()


def test_the_runs_warnings_are_the_tools(tmp_path, client, las_scene):
    """A viewpoint too far to orient by: the summary lists the tool's own warning (the same
    words, result_warnings.h) and the log prints it."""
    import io
    import subprocess

    from conftest import tools_dir

    paths, merged = las_scene
    tool = subprocess.run([str(tools_dir() / "pcl_ddg_normals"), str(merged),
                           str(tmp_path / "tool.ply"), "-viewpoint", "0,0,0"],
                          capture_output=True, text=True, timeout=300)
    assert tool.returncode == 0, tool.stderr
    log = io.StringIO()
    out = tmp_path / "out"
    summary = dd.estimate_normals(paths, out, client=client, merge=str(out / "m.ply"),
                                  viewpoint=(0.0, 0.0, 0.0), memory_per_worker=memory(client),
                                  stream=log)
    assert len(summary["warnings"]) == 1, (summary["warnings"], tool.stderr)
    message = summary["warnings"][0]
    assert message.startswith("the viewpoint (0, 0, 0) is ") and "-orient up" in message
    assert "pcl_ddg_normals: warning: " + message in tool.stderr, (message, tool.stderr)
    assert "pcl_ddg.distributed: warning: " + message in log.getvalue()


@pytest.mark.parametrize("text,size", [("2G", 2 << 30), ("2GB", 2 << 30), ("2GiB", 2 << 30),
                                       ("512m", 512 << 20), ("64k", 64 << 10), ("1.5G", 3 << 29),
                                       ("1000000", 1000000), (" 3M ", 3 << 20)])
def test_memory_sizes_are_the_tools(text, size):
    # The runner's memory_per_worker and the tools' -memory share one parser (byte_size.h; the
    # C++ table: test/tiling/test_byte_size.cpp): the same sizes, and the same refusals.
    assert dd.parse_size(text) == size


@pytest.mark.parametrize("text", ["", "lots", "0", "-1G", "1kk", "2 G", "inf", "1e19", "0x10"])
def test_memory_sizes_the_tools_refuse_are_refused(text):
    with pytest.raises(ValueError, match="a size like 2G"):
        dd.parse_size(text)
