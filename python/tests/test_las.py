"""LAS through the module: exact coordinates and fields against an independent reader written
here from the ASPRS LAS 1.4 R15 tables (every readable shared file: formats 0, 1, 2, 3, 6, 7 from
libLAS/PDAL), read -> write round trips of the records, normals written as Extra Bytes checked in
every record's bytes, a new file's scale and offset, the warning of a new file that carries no
VLR of its input, the LAZ, truncated-file and no-point refusals, and normals equal to
pcl_ddg_normals' on the same file. test_las_formats.py checks every field of formats 0-10."""

import os
import struct
import warnings

import numpy as np
import pytest

import pcl_ddg
from conftest import run_tool, shared_data
from test_las_formats import eb_layout, parse_extra_bytes, parse_header, parse_vlrs, record_bytes

# Every readable LAS file of the shared data, written by libLAS, PDAL and others: point formats
# 0, 1, 2 (formats/), 3, 6 and 7 in LAS 1.0-1.4. test_las_formats.py checks every field of
# every record of these (and of formats 4, 5, 8-10 written there from the specification).
FILES = ([f"formats/1.{minor}_{fmt}.las" for minor in (0, 1, 2) for fmt in (0, 1, 2, 3)
          if minor == 2 or fmt < 2]
         + ["autzen_trim.las", "autzen_trim_7.las", "mvk-thin.las", "epsg_4326.las",
            "extrabytes.las", "test1_4.las", "1.2-with-color.las", "gps-time-nan.las"])


def las_path(name):
    path = shared_data() / "las" / name
    assert path.exists(), f"{path} is not in the shared data (CATALOG.md): a failure, not a skip"
    return path


# --- an independent reader: the specification's header offsets and record tables -------------


def header_of(raw: bytes) -> dict:
    major, minor = raw[24], raw[25]
    header = {
        "version": (major, minor),
        "header_size": struct.unpack_from("<H", raw, 94)[0],
        "point_offset": struct.unpack_from("<I", raw, 96)[0],
        "vlr_count": struct.unpack_from("<I", raw, 100)[0],
        "format": raw[104] & 0x3F,
        "record_length": struct.unpack_from("<H", raw, 105)[0],
        "count": struct.unpack_from("<I", raw, 107)[0],
        "scale": np.frombuffer(raw, "<f8", 3, 131),
        "offset": np.frombuffer(raw, "<f8", 3, 155),
    }
    if (major, minor) >= (1, 4):
        legacy = header["count"]
        header["count"] = struct.unpack_from("<Q", raw, 247)[0]
        assert legacy in (0, header["count"])
    return header


# Per point format: (name, numpy type, byte offset) of the whole-byte fields.
_COMMON = [("X", "<i4", 0), ("Y", "<i4", 4), ("Z", "<i4", 8), ("intensity", "<u2", 12)]
_LEGACY = _COMMON + [("bits", "u1", 14), ("class_byte", "u1", 15), ("scan_angle_rank", "i1", 16),
                     ("user_data", "u1", 17), ("point_source_id", "<u2", 18)]
_EXTENDED = _COMMON + [("returns", "u1", 14), ("flags", "u1", 15), ("classification", "u1", 16),
                       ("user_data", "u1", 17), ("scan_angle", "<i2", 18),
                       ("point_source_id", "<u2", 20), ("gps_time", "<f8", 22)]
_RGB = [("red", "<u2", 0), ("green", "<u2", 2), ("blue", "<u2", 4)]
LAYOUTS = {
    0: _LEGACY,
    1: _LEGACY + [("gps_time", "<f8", 20)],
    2: _LEGACY + [(n, t, 20 + o) for n, t, o in _RGB],
    3: _LEGACY + [("gps_time", "<f8", 20)] + [(n, t, 28 + o) for n, t, o in _RGB],
    6: _EXTENDED,
    7: _EXTENDED + [(n, t, 30 + o) for n, t, o in _RGB],
}


def test_every_layout_is_read_from_a_file_of_another_writer():
    formats = {header_of(las_path(name).read_bytes())["format"] for name in FILES}
    assert formats == set(LAYOUTS)  # no dead layout: each one checks a shared file


def records_of(raw: bytes, header: dict) -> np.ndarray:
    fields = LAYOUTS[header["format"]]
    dtype = np.dtype({"names": [f[0] for f in fields], "formats": [f[1] for f in fields],
                      "offsets": [f[2] for f in fields], "itemsize": header["record_length"]})
    return np.frombuffer(raw, dtype, header["count"], header["point_offset"])


def record_block(raw: bytes) -> bytes:
    h = header_of(raw)
    start = h["point_offset"]
    return raw[start:start + h["count"] * h["record_length"]]


def expected_fields(records: np.ndarray, point_format: int) -> dict:
    r = records
    if point_format < 6:
        return {
            "return_number": r["bits"] & 7, "number_of_returns": (r["bits"] >> 3) & 7,
            "scan_direction_flag": (r["bits"] >> 6) & 1, "edge_of_flight_line": r["bits"] >> 7,
            "classification": r["class_byte"] & 31, "classification_flags": r["class_byte"] >> 5,
            "scan_angle_rank": r["scan_angle_rank"],
        }
    return {
        "return_number": r["returns"] & 15, "number_of_returns": r["returns"] >> 4,
        "classification_flags": r["flags"] & 15, "scanner_channel": (r["flags"] >> 4) & 3,
        "scan_direction_flag": (r["flags"] >> 6) & 1, "edge_of_flight_line": r["flags"] >> 7,
        "classification": r["classification"], "scan_angle": r["scan_angle"],
    }


# --- tests -------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", FILES)
def test_coordinates_and_fields_equal_the_specification(name):
    path = las_path(name)
    raw = path.read_bytes()
    header = header_of(raw)
    records = records_of(raw, header)
    m = pcl_ddg.read(path)

    assert m.las is not None
    assert m.las.version == header["version"]
    assert m.las.point_format == header["format"]
    assert m.las.record_length == header["record_length"]
    assert m.las.scale == tuple(header["scale"]) and m.las.offset == tuple(header["offset"])
    assert len(m.las.vlrs) == header["vlr_count"]
    assert m.precision == "double" and m.points.dtype == np.float64

    integers = np.stack([records["X"], records["Y"], records["Z"]], axis=1).astype(np.float64)
    expected = integers * header["scale"] + header["offset"]  # X * scale + offset, in double
    assert m.points.shape == (header["count"], 3)
    np.testing.assert_array_equal(m.points, expected)

    for field in ("intensity", "user_data", "point_source_id", "gps_time", "red", "green",
                  "blue"):
        if field in records.dtype.names:
            got, want = m.fields[field], records[field]
            if want.dtype.kind == "f":  # bit for bit: gps-time-nan.las holds a NaN
                got, want = got.view(np.uint64), want.view("<u8")
            np.testing.assert_array_equal(got, want, err_msg=field)
            assert m.fields[field].dtype == records.dtype[field].newbyteorder("=")
    for field, values in expected_fields(records, header["format"]).items():
        np.testing.assert_array_equal(m.fields[field], values, err_msg=field)


def test_extra_bytes_dimensions():
    path = las_path("extrabytes.las")
    raw = path.read_bytes()
    header = header_of(raw)
    m = pcl_ddg.read(path)
    base = 34  # format 3
    assert header["record_length"] == 61
    # Colors (3 x uint16), Reserved (7 bytes), Flags (2 x int8), Intensity (uint32), Time (uint64)
    layout = [("Colors", "<u2", (3,), 0), ("Reserved", "u1", (7,), 6), ("Flags", "i1", (2,), 13),
              ("Intensity", "<u4", (), 15), ("Time", "<u8", (), 19)]
    dtype = np.dtype({"names": [f[0] for f in layout],
                      "formats": [(f[1], f[2]) if f[2] else f[1] for f in layout],
                      "offsets": [base + f[3] for f in layout], "itemsize": 61})
    extra = np.frombuffer(raw, dtype, header["count"], header["point_offset"])
    for name, *_ in layout:
        np.testing.assert_array_equal(m.fields[name], extra[name], err_msg=name)
    assert [d[0] for d in m.las.extra_bytes] == [f[0] for f in layout]
    assert all(len(d[1]) == 192 for d in m.las.extra_bytes)


@pytest.mark.parametrize("name", FILES)
def test_read_write_read_keeps_records_and_vlrs(name, tmp_path):
    path = las_path(name)
    raw = path.read_bytes()
    m = pcl_ddg.read(path)
    out = tmp_path / name.replace("/", "_")
    pcl_ddg.write(out, m.points, fields=m.fields, las=m.las)
    written = out.read_bytes()
    assert header_of(written)["format"] == header_of(raw)["format"]
    assert header_of(written)["record_length"] == header_of(raw)["record_length"]
    assert record_block(written) == record_block(raw)  # every record, bit for bit

    again = pcl_ddg.read(out)
    assert again.las.version == m.las.version and again.las.point_format == m.las.point_format
    assert again.las.scale == m.las.scale and again.las.offset == m.las.offset
    assert again.las.vlrs == m.las.vlrs and again.las.evlrs == m.las.evlrs
    np.testing.assert_array_equal(again.points, m.points)
    assert list(again.fields) == list(m.fields)
    for key, values in m.fields.items():
        assert again.fields[key].dtype == values.dtype, key
        np.testing.assert_array_equal(again.fields[key], values, err_msg=key)

    # ... and once more: the rewritten file rewrites to the same records
    out2 = tmp_path / ("again_" + name.replace("/", "_"))
    pcl_ddg.write(out2, again.points, fields=again.fields, las=again.las)
    assert record_block(out2.read_bytes()) == record_block(raw)


def test_new_file_and_normals_as_extra_bytes(tmp_path):
    m = pcl_ddg.read(las_path("test1_4.las"))
    n = pcl_ddg.estimate_normals(m, k=16)  # a LAS file: oriented up, as the tool orients it
    out = tmp_path / "normals.las"
    fields = dict(m.fields, normals=n.normals, curvature=n.curvature)
    pcl_ddg.write(out, m.points, fields=fields, las=m.las)
    back = pcl_ddg.read(out)
    # every record: the input's 30 bytes (format 6), then the four new dimensions, read here
    # from the file's Extra Bytes descriptors (LAS 1.4 R15, 192 bytes each)
    source = las_path("test1_4.las").read_bytes()
    written = out.read_bytes()
    h, w = parse_header(source), parse_header(written)
    assert w["point_format"] == 6 and w["points"] == h["points"] == len(m.points)
    assert h["record_length"] == 30
    new, old = record_bytes(written, w), record_bytes(source, h)
    np.testing.assert_array_equal(new[:, :30], old)
    eb = [v for v in parse_vlrs(written, w) if (v["user"], v["id"]) == ("LASF_Spec", 4)]
    assert len(eb) == 1
    dims = parse_extra_bytes(eb[0]["payload"])
    assert [d["name"] for d in dims] == ["NormalX", "NormalY", "NormalZ", "Curvature"]
    at, stored = 30, []
    for d in dims:
        kind, count = eb_layout(d["data_type"], d["options"])
        assert count == 1 and d["options"] == 0 and np.dtype(kind).kind == "f", d
        size = np.dtype(kind).itemsize
        stored.append(np.ascontiguousarray(new[:, at:at + size]).view(kind)[:, 0])
        at += size
    assert at == w["record_length"]
    assert n.normals.dtype == n.curvature.dtype == np.float64  # stored as doubles (type 10)
    for i, want in enumerate([n.normals[:, 0], n.normals[:, 1], n.normals[:, 2], n.curvature]):
        assert stored[i].dtype == np.float64, dims[i]
        np.testing.assert_array_equal(stored[i].view(np.uint64), want.view(np.uint64))  # bits
    # NormalX NormalY NormalZ Curvature in the file (PDAL's names); normal_x ... in the cloud
    assert [d[0] for d in back.las.extra_bytes] == ["normal_x", "normal_y", "normal_z", "curvature"]
    assert [d[1][4:13] for d in back.las.extra_bytes[:3]] == [b"NormalX\0\0", b"NormalY\0\0",
                                                              b"NormalZ\0\0"]
    got = np.stack([back.fields["normal_x"], back.fields["normal_y"], back.fields["normal_z"]], 1)
    assert got.dtype == n.normals.dtype
    assert np.array_equal(got, n.normals, equal_nan=True)
    assert np.array_equal(back.fields["curvature"], n.curvature, equal_nan=True)

    # Without a layout: LAS 1.4 format 6, exact enough coordinates, the fields kept.
    fresh = tmp_path / "fresh.las"
    with pytest.warns(UserWarning, match="no CRS"):
        pcl_ddg.write(fresh, m.points, fields={"intensity": m.fields["intensity"]})
    f = pcl_ddg.read(fresh)
    assert f.las.version == (1, 4) and f.las.point_format == 6
    np.testing.assert_array_equal(f.fields["intensity"], m.fields["intensity"])
    # docs/las.md: per axis a power of ten scale that holds the extent in 10^9 steps, an offset
    # below the minimum; every coordinate is then the nearest step (half a step away at most)
    extent = m.points.max(axis=0) - m.points.min(axis=0)
    assert np.all(extent > 1.0)  # test1_4: 501 x 5.3 x 6.3 units
    step = 10.0 ** np.ceil(np.log10(extent / 1e9))  # 1e-6, 1e-8, 1e-8
    np.testing.assert_allclose(f.las.scale, step, rtol=1e-12)
    assert np.all(np.array(f.las.offset) <= m.points.min(axis=0))
    rounding = np.spacing(np.abs(m.points).max(axis=0))  # X * scale + offset in double
    error = np.abs(f.points - m.points).max(axis=0)
    assert np.all(error <= 0.5 * step + 4 * rounding), (error, step)


def test_a_new_las_file_warns_that_it_carries_no_vlr_of_the_input(tmp_path):
    m = pcl_ddg.read(las_path("autzen_trim.las"))
    assert any(r[0] == "LASF_Projection" for r in m.las.vlrs)  # its CRS
    fresh = tmp_path / "fresh.las"
    with pytest.warns(UserWarning) as caught:
        pcl_ddg.write(fresh, m.points)
    assert len(caught) == 1
    message = str(caught[0].message)
    assert str(fresh) in message and "CRS" in message and "VLR" in message, message
    assert "las=pcl_ddg.read(input).las" in message, message
    assert caught[0].filename == __file__  # points at the caller's line
    assert pcl_ddg.read(fresh).las.vlrs == []  # what the warning says: no VLR of the input
    # With the input's layout every VLR is kept, and nothing is said; other formats say nothing.
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        pcl_ddg.write(tmp_path / "kept.las", m.points, fields=m.fields, las=m.las)
        pcl_ddg.write(tmp_path / "cloud.ply", m.points)
    assert pcl_ddg.read(tmp_path / "kept.las").las.vlrs == m.las.vlrs
    assert "las=" in pcl_ddg.write.__doc__ and "CRS" in pcl_ddg.write.__doc__


def test_a_file_of_no_points_is_refused_naming_it():
    path = las_path("no-points.las")
    with pytest.raises(OSError) as error:
        pcl_ddg.read(path)
    message = str(error.value)
    assert "no-points.las" in message and "no points" in message, message


def test_normals_equal_the_tool(tmp_path):
    path = las_path("autzen_trim.las")
    out = tmp_path / "tool.las"
    run_tool("pcl_ddg_normals", path, out, "-k", "16")
    tool = pcl_ddg.read(out)
    m = pcl_ddg.read(path)
    np.testing.assert_array_equal(tool.points, m.points)
    n = pcl_ddg.estimate_normals(m, k=16)  # a LAS file: oriented up, as the tool orients it
    got = np.stack([tool.fields["normal_x"], tool.fields["normal_y"], tool.fields["normal_z"]], 1)
    assert [d[1][4:13] for d in tool.las.extra_bytes[:3]] == [b"NormalX\0\0", b"NormalY\0\0",
                                                              b"NormalZ\0\0"]
    assert got.dtype == np.float32
    mine = n.normals.astype(np.float32)
    assert np.array_equal(got, mine, equal_nan=True)  # bit for bit
    assert np.array_equal(tool.fields["curvature"], n.curvature.astype(np.float32), equal_nan=True)
    # the input's records are the output's, the normals appended as Extra Bytes
    assert tool.las.point_format == m.las.point_format
    for key, values in m.fields.items():
        np.testing.assert_array_equal(tool.fields[key], values, err_msg=key)


def test_truncated_file_is_refused():
    path = las_path("1.2-with-color-clipped.las")
    with pytest.raises((OSError, ValueError)) as error:
        pcl_ddg.read(path)
    message = str(error.value)
    assert "1.2-with-color-clipped.las" in message
    assert "1065" in message.replace(",", "") or "1064" in message.replace(",", ""), message


def test_laz_reads_as_its_uncompressed_twin_and_writes_back(tmp_path):
    laz = pcl_ddg.read(las_path("simple.laz"))
    twin = pcl_ddg.read(las_path("1.2-with-color.las"))
    np.testing.assert_array_equal(laz.points, twin.points)
    assert laz.fields.keys() == twin.fields.keys()
    for name in twin.fields:
        np.testing.assert_array_equal(laz.fields[name], twin.fields[name], err_msg=name)
    pcl_ddg.write(tmp_path / "out.laz", laz.points, fields=laz.fields, las=laz.las)
    back = pcl_ddg.read(tmp_path / "out.laz")
    np.testing.assert_array_equal(back.points, twin.points)
    np.testing.assert_array_equal(back.fields["gps_time"], twin.fields["gps_time"])


def test_our_laz_decodes_with_laz_perf(tmp_path):
    """An independent decoder (LAZperf's WebAssembly build from npm, run by node; a test oracle,
    never shipped) reads what our encoder writes, formats 3 and 7, to the records of the .las
    written from the same cloud. Optional: without node and npm (or the npm registry), skipped."""
    from lazperf_oracle import decode, lazperf_folder

    folder = lazperf_folder()
    if folder is None:
        pytest.skip(lazperf_folder.error + ": no independent LAZ decoder")
    for name in ("autzen_trim.las", "autzen_trim_7.las"):
        m = pcl_ddg.read(las_path(name))
        pcl_ddg.write(tmp_path / "ours.las", m.points, fields=m.fields, las=m.las)
        pcl_ddg.write(tmp_path / "ours.laz", m.points, fields=m.fields, las=m.las)
        decoded, _ = decode(folder, tmp_path / "ours.laz")
        written = (tmp_path / "ours.las").read_bytes()
        header = parse_header(written)
        records = written[header["point_offset"]:]
        records = records[:header["points"] * header["record_length"]]
        assert decoded == records, name


def test_bad_fields_are_refused(tmp_path):
    m = pcl_ddg.read(las_path("test1_4.las"))
    with pytest.raises(ValueError, match="one row per point"):
        pcl_ddg.write(tmp_path / "x.las", m.points, fields={"intensity": np.zeros(3, np.uint16)})
    with pytest.raises(ValueError, match="numbers"):
        pcl_ddg.write(tmp_path / "x.las", m.points,
                      fields={"name": np.array(["a"] * len(m.points))})
    assert not (tmp_path / "x.las").exists()


# --- COPC: the octree from the hierarchy, parts of the file by byte ranges --------------------


def copc_path():
    return las_path("laz/1.2-with-color.copc.laz")


def test_copc_info_is_the_hierarchy_page_read_by_the_specification():
    raw = copc_path().read_bytes()
    # The info VLR follows the 375-byte header and its 54-byte VLR header (COPC 1.0).
    center = struct.unpack_from("<3d", raw, 375 + 54)
    root, size = struct.unpack_from("<2Q", raw, 375 + 54 + 40)
    entries = [struct.unpack_from("<4iQii", raw, e) for e in range(root, root + size, 32)]
    info = pcl_ddg.copc_info(copc_path())
    assert info["center"] == center
    assert info["points"] == sum(e[6] for e in entries) == 1065
    assert info["hierarchy_pages"] == 1
    assert [tuple(n) for n in info["nodes"]] == entries


def test_read_copc_gives_the_files_points_by_nodes_and_by_box():
    whole = pcl_ddg.read(copc_path())
    info = pcl_ddg.copc_info(copc_path())
    nodes = [n[:4] for n in info["nodes"]]
    every, read_bytes = pcl_ddg.read_copc(copc_path(), nodes=nodes)
    np.testing.assert_array_equal(np.unique(every.points, axis=0), np.unique(whole.points, axis=0))
    assert every.points.shape == whole.points.shape
    assert every.fields.keys() == whole.fields.keys()
    assert read_bytes < os.path.getsize(copc_path()) + 2000
    # A box over the points' south-west quarter: exactly the file's points inside it.
    lo, hi = whole.points.min(axis=0), whole.points.max(axis=0)
    box = np.array([lo, [(lo[0] + hi[0]) / 2, (lo[1] + hi[1]) / 2, hi[2]]])
    part, part_bytes = pcl_ddg.read_copc(copc_path(), bounds=box)
    inside = whole.points[np.all((whole.points >= box[0]) & (whole.points <= box[1]), axis=1)]
    assert 50 < len(inside) < len(whole.points)
    np.testing.assert_array_equal(np.unique(part.points, axis=0), np.unique(inside, axis=0))
    assert len(part.points) == len(inside)
    assert part_bytes < read_bytes
    assert part.las is not None and part.fields["classification"].shape == (len(inside),)
    # Down to level 1: fewer points, every one of them in the box.
    coarse, _ = pcl_ddg.read_copc(copc_path(), bounds=box, max_depth=1)
    assert 0 < len(coarse.points) < len(inside)
    assert np.all((coarse.points >= box[0]) & (coarse.points <= box[1]))


def test_read_copc_refuses_what_it_cannot_read(tmp_path):
    with pytest.raises(ValueError, match="bounds or nodes"):
        pcl_ddg.read_copc(copc_path())
    with pytest.raises(ValueError, match="bounds or nodes"):
        pcl_ddg.read_copc(copc_path(), bounds=[0] * 6, nodes=[(0, 0, 0, 0)])
    with pytest.raises(ValueError, match="no node 4-0-0-0"):
        pcl_ddg.read_copc(copc_path(), nodes=[(4, 0, 0, 0)])
    with pytest.raises(ValueError, match="a node is"):
        pcl_ddg.read_copc(copc_path(), nodes=[(0, 0, 0)])
    with pytest.raises(ValueError, match="bounds are"):
        pcl_ddg.read_copc(copc_path(), bounds=[1, 0, 0, 0, 0, 0])
    with pytest.raises(ValueError, match="max_depth"):
        pcl_ddg.read_copc(copc_path(), bounds=[0, 0, 0, 1, 1, 1], max_depth=-2)
    with pytest.raises(OSError, match="autzen_trim.laz: COPC: not a LAS 1.4 file"):
        pcl_ddg.copc_info(las_path("laz/autzen_trim.laz"))
    copc = pcl_ddg.read(copc_path())  # written again: LAZ 1.4 format 7, its octree left out
    pcl_ddg.write(tmp_path / "plain.laz", copc.points, fields=copc.fields, las=copc.las)
    with pytest.raises(OSError, match="no COPC info VLR"):
        pcl_ddg.copc_info(tmp_path / "plain.laz")
    with pytest.raises(OSError, match="not a LAZ file"):
        pcl_ddg.read_copc(las_path("test1_4.las"), bounds=[0, 0, 0, 1, 1, 1])
    with pytest.raises(FileNotFoundError):
        pcl_ddg.copc_info(tmp_path / "missing.copc.laz")
