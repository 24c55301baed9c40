"""LAS point formats 0-10 read by pcl_ddg.read against an oracle written here from the ASPRS
LAS 1.4 R15 specification (public header offsets, Tables 7-21 of the point record formats, the
Extra Bytes descriptor), never from src/io/las_*.cpp:

* every LAS file in the shared data (written by libLAS, PDAL and others: formats 0, 1, 2, 3, 6, 7
  in LAS 1.0-1.4) and files of every format 0-10 whose bytes this test writes from the tables:
  every header value, every VLR, every point's coordinates and every field of every record;
* autzen_trim_7.las (format 7, PDAL) against its format 3 twin autzen_trim.las, point by point;
* Extra Bytes arrays of 2 and 3 elements with a scale and/or offset per element (deprecated data
  types 11-30 of LAS 1.4 R13, still read), in a file written here: the field is raw * scale +
  offset per element, and read -> write gives back the same bytes.

The shared files are named here, not globbed: a missing file fails, it is never skipped."""

import re
import struct

import numpy as np
import pytest

import pcl_ddg
from conftest import shared_data

# --- the specification ---------------------------------------------------------------------------
#
# Public header block (LAS 1.4 R15 Table 3; 1.0-1.3 are its first 227 / 235 bytes).
HEADER = {
    "file_source_id": ("<H", 4), "global_encoding": ("<H", 6), "version_major": ("B", 24),
    "version_minor": ("B", 25), "header_size": ("<H", 94), "point_offset": ("<I", 96),
    "vlr_count": ("<I", 100), "point_format": ("B", 104), "record_length": ("<H", 105),
    "legacy_count": ("<I", 107), "legacy_by_return": ("<5I", 111), "scale": ("<3d", 131),
    "offset": ("<3d", 155), "max_x": ("<d", 179), "min_x": ("<d", 187), "max_y": ("<d", 195),
    "min_y": ("<d", 203), "max_z": ("<d", 211), "min_z": ("<d", 219),
    # 1.3: start of the waveform data packet record; 1.4: EVLRs and 64-bit counts
    "waveform_start": ("<Q", 227), "evlr_start": ("<Q", 235), "evlr_count": ("<I", 243),
    "count": ("<Q", 247), "by_return": ("<15Q", 255),
}
HEADER_SIZE = {(1, 0): 227, (1, 1): 227, (1, 2): 227, (1, 3): 235, (1, 4): 375}
VLR_HEADER = 54  # reserved u16, user id char[16] at 2, record id u16 at 18, length u16 at 20,
#                  description char[32] at 22


def parse_header(raw: bytes) -> dict:
    h = {}
    for name, (fmt, at) in HEADER.items():
        if at + struct.calcsize(fmt) > struct.unpack_from("<H", raw, 94)[0]:
            continue  # not in this version's header
        value = struct.unpack_from(fmt, raw, at)
        h[name] = value[0] if len(value) == 1 else value
    h["version"] = (h["version_major"], h["version_minor"])
    h["points"] = h["count"] if h["version"] >= (1, 4) else h["legacy_count"]
    return h


def parse_vlrs(raw: bytes, h: dict) -> list:
    vlrs, at = [], h["header_size"]
    for _ in range(h["vlr_count"]):
        user = raw[at + 2:at + 18].split(b"\0")[0].decode("ascii")
        record_id, length = struct.unpack_from("<HH", raw, at + 18)
        description = raw[at + 22:at + 54].split(b"\0")[0].decode("ascii", "replace")
        vlrs.append({"user": user, "id": record_id, "description": description,
                     "payload": raw[at + VLR_HEADER:at + VLR_HEADER + length]})
        at += VLR_HEADER + length
    assert at <= h["point_offset"]
    return vlrs


# Point data record formats (Tables 7-21): (field, numpy type, byte offset). Bit fields are read
# as their whole byte here ("return_byte", "class_byte", "flag_byte") and split below.
LEGACY_CORE = [("X", "<i4", 0), ("Y", "<i4", 4), ("Z", "<i4", 8), ("intensity", "<u2", 12),
               ("return_byte", "u1", 14), ("class_byte", "u1", 15),
               ("scan_angle_rank", "i1", 16), ("user_data", "u1", 17),
               ("point_source_id", "<u2", 18)]
EXTENDED_CORE = [("X", "<i4", 0), ("Y", "<i4", 4), ("Z", "<i4", 8), ("intensity", "<u2", 12),
                 ("return_byte", "u1", 14), ("flag_byte", "u1", 15),
                 ("classification", "u1", 16), ("user_data", "u1", 17),
                 ("scan_angle", "<i2", 18), ("point_source_id", "<u2", 20),
                 ("gps_time", "<f8", 22)]


def _gps(at):
    return [("gps_time", "<f8", at)]


def _rgb(at):
    return [("red", "<u2", at), ("green", "<u2", at + 2), ("blue", "<u2", at + 4)]


def _nir(at):
    return [("nir", "<u2", at)]


def _wave(at):  # wave packet descriptor index, byte offset, size, location, x(t), y(t), z(t)
    return [("wave_packet_index", "u1", at), ("wave_packet_offset", "<u8", at + 1),
            ("wave_packet_size", "<u4", at + 9), ("wave_return_location", "<f4", at + 13),
            ("wave_x_t", "<f4", at + 17), ("wave_y_t", "<f4", at + 21),
            ("wave_z_t", "<f4", at + 25)]


SPEC = {
    0: LEGACY_CORE,
    1: LEGACY_CORE + _gps(20),
    2: LEGACY_CORE + _rgb(20),
    3: LEGACY_CORE + _gps(20) + _rgb(28),
    4: LEGACY_CORE + _gps(20) + _wave(28),
    5: LEGACY_CORE + _gps(20) + _rgb(28) + _wave(34),
    6: EXTENDED_CORE,
    7: EXTENDED_CORE + _rgb(30),
    8: EXTENDED_CORE + _rgb(30) + _nir(36),
    9: EXTENDED_CORE + _wave(30),
    10: EXTENDED_CORE + _rgb(30) + _nir(36) + _wave(38),
}
MINIMUM_SIZE = {0: 20, 1: 28, 2: 26, 3: 34, 4: 57, 5: 63, 6: 30, 7: 36, 8: 38, 9: 59, 10: 67}

# Extra Bytes data types (LAS 1.4 R13 Table 24; 11-30 deprecated in R14 but still defined):
# 1-10 scalars, 11-20 two-element and 21-30 three-element arrays of the same ten types.
EB_SCALAR = {1: "u1", 2: "i1", 3: "<u2", 4: "<i2", 5: "<u4", 6: "<i4", 7: "<u8", 8: "<i8",
             9: "<f4", 10: "<f8"}
EB_SCALE_BIT, EB_OFFSET_BIT = 1 << 3, 1 << 4


def eb_layout(data_type: int, options: int):
    """(numpy type, element count) of one Extra Bytes dimension."""
    if data_type == 0:
        return "u1", options  # undocumented bytes: their count in `options`
    return EB_SCALAR[(data_type - 1) % 10 + 1], (data_type - 1) // 10 + 1


def parse_extra_bytes(payload: bytes) -> list:
    """The 192-byte descriptors: reserved[2], data_type at 2, options at 3, name[32] at 4,
    unused[4] at 36, no_data[3] at 40, min[3] at 64, max[3] at 88, scale[3] at 112,
    offset[3] at 136, description[32] at 160."""
    assert len(payload) % 192 == 0
    dims = []
    for at in range(0, len(payload), 192):
        d = payload[at:at + 192]
        dims.append({"data_type": d[2], "options": d[3],
                     "name": d[4:36].split(b"\0")[0].decode("ascii"),
                     "scale": struct.unpack_from("<3d", d, 112),
                     "offset": struct.unpack_from("<3d", d, 136),
                     "description": d[160:192].split(b"\0")[0].decode("ascii")})
    return dims


def records_of(raw: bytes, h: dict) -> np.ndarray:
    fields = SPEC[h["point_format"]]
    dtype = np.dtype({"names": [f[0] for f in fields], "formats": [f[1] for f in fields],
                      "offsets": [f[2] for f in fields], "itemsize": h["record_length"]})
    return np.frombuffer(raw, dtype, h["points"], h["point_offset"])


def record_bytes(raw: bytes, h: dict) -> np.ndarray:
    """The records as an (n, record_length) uint8 array."""
    n, length = h["points"], h["record_length"]
    return np.frombuffer(raw, np.uint8, n * length, h["point_offset"]).reshape(n, length)


def expected_fields(raw: bytes, h: dict) -> dict:
    """Every field the module must give, by its name (docs/las.md), from the spec's tables."""
    r = records_of(raw, h)
    out = {}
    for name, _, _ in SPEC[h["point_format"]]:
        if name not in ("X", "Y", "Z", "return_byte", "class_byte", "flag_byte"):
            out[name] = r[name].copy()
    b14 = r["return_byte"]
    if h["point_format"] < 6:
        b15 = r["class_byte"]
        out.update(return_number=b14 & 7, number_of_returns=(b14 >> 3) & 7,
                   scan_direction_flag=(b14 >> 6) & 1, edge_of_flight_line=(b14 >> 7) & 1,
                   classification=b15 & 31,
                   classification_flags=(b15 >> 5) & 7)  # synthetic, key-point, withheld
    else:
        b15 = r["flag_byte"]
        out.update(return_number=b14 & 15, number_of_returns=(b14 >> 4) & 15,
                   classification_flags=b15 & 15,  # synthetic, key-point, withheld, overlap
                   scanner_channel=(b15 >> 4) & 3, scan_direction_flag=(b15 >> 6) & 1,
                   edge_of_flight_line=(b15 >> 7) & 1)
    for key in ("return_number", "number_of_returns", "scan_direction_flag",
                "edge_of_flight_line", "classification", "classification_flags",
                "scanner_channel"):
        if key in out:
            out[key] = out[key].astype(np.uint8)

    # Extra Bytes, after the format's own bytes
    rb = record_bytes(raw, h)
    at = MINIMUM_SIZE[h["point_format"]]
    for vlr in parse_vlrs(raw, h):
        if vlr["user"] == "LASF_Spec" and vlr["id"] == 4:
            for dim in parse_extra_bytes(vlr["payload"]):
                kind, count = eb_layout(dim["data_type"], dim["options"])
                size = np.dtype(kind).itemsize * count
                values = np.ascontiguousarray(rb[:, at:at + size]).view(kind)
                values = values.reshape(-1) if count == 1 and dim["data_type"] else values
                scaled = dim["options"] & (EB_SCALE_BIT | EB_OFFSET_BIT)
                if (dim["data_type"] and scaled and np.dtype(kind).kind in "iu"
                        and np.dtype(kind).itemsize <= 4):
                    scale = np.array([dim["scale"][i] if dim["options"] & EB_SCALE_BIT else 1.0
                                      for i in range(count)])
                    offset = np.array([dim["offset"][i] if dim["options"] & EB_OFFSET_BIT
                                       else 0.0 for i in range(count)])
                    values = values.astype(np.float64) * (scale if count > 1 else scale[0]) \
                        + (offset if count > 1 else offset[0])
                out[re.sub(r"[^A-Za-z0-9_]", "_", dim["name"])] = values.astype(
                    values.dtype.newbyteorder("="))
                at += size
    if at < h["record_length"]:
        out["las_undocumented_bytes"] = np.ascontiguousarray(rb[:, at:])
    return out


def check_against_the_specification(path, raw: bytes, m) -> dict:
    """Every header value, VLR, coordinate and field of `m` (pcl_ddg.read(path)) against `raw`."""
    h = parse_header(raw)
    where = str(path)
    assert h["header_size"] == HEADER_SIZE[h["version"]], where
    lay = m.las
    assert lay is not None, where
    assert lay.version == h["version"], where
    assert lay.point_format == h["point_format"], where
    assert lay.record_length == h["record_length"], where
    assert lay.point_count == h["points"], where
    assert lay.file_source_id == h["file_source_id"], where
    assert lay.global_encoding == h["global_encoding"], where
    assert lay.scale == h["scale"] and lay.offset == h["offset"], where
    assert lay.min == (h["min_x"], h["min_y"], h["min_z"]), where
    assert lay.max == (h["max_x"], h["max_y"], h["max_z"]), where
    vlrs = parse_vlrs(raw, h)
    assert len(lay.vlrs) == len(vlrs), where
    for got, want in zip(lay.vlrs, vlrs):
        # (user id, record id, description, payload)
        assert tuple(got) == (want["user"], want["id"], want["description"], want["payload"]), (
            where, tuple(got)[:3], (want["user"], want["id"], want["description"]))
    assert m.precision == "double" and m.points.dtype == np.float64, where

    # coordinates: X * scale + offset in double (the header's "Coordinates" formula)
    r = records_of(raw, h)
    xyz = np.stack([r["X"], r["Y"], r["Z"]], axis=1).astype(np.float64)
    assert m.points.shape == (h["points"], 3), where
    np.testing.assert_array_equal(m.points, xyz * np.array(h["scale"]) + np.array(h["offset"]),
                                  err_msg=where)

    # every field, exactly the fields the records hold, with their types
    want = expected_fields(raw, h)
    assert sorted(m.fields) == sorted(want), (where, sorted(m.fields), sorted(want))
    for name, values in want.items():
        got = m.fields[name]
        assert got.dtype == values.dtype, (where, name, got.dtype, values.dtype)
        assert got.shape == values.shape, (where, name, got.shape, values.shape)
        if values.dtype.kind == "f":  # bit for bit, NaN payloads included
            bits = {4: np.uint32, 8: np.uint64}[values.dtype.itemsize]
            mismatch = np.flatnonzero((got.view(bits) != values.view(bits)).reshape(len(got), -1)
                                      .any(axis=1))
        else:
            mismatch = np.flatnonzero((got != values).reshape(len(got), -1).any(axis=1))
        assert mismatch.size == 0, (
            f"{where}: field {name}: {mismatch.size} of {len(got)} points differ; first at point "
            f"{mismatch[:1]}: expected {values[mismatch[:3]]}, got {got[mismatch[:3]]}")
    return h


# --- the shared files -------------------------------------------------------------------------

def las_dir():
    return shared_data() / "las"


FORMATS_FILES = [f"formats/1.{minor}_{fmt}.las" for minor in (0, 1, 2) for fmt in (0, 1, 2, 3)
                 if minor == 2 or fmt < 2]
READABLE = FORMATS_FILES + [
    "autzen_trim.las", "autzen_trim_7.las", "mvk-thin.las", "epsg_4326.las", "extrabytes.las",
    "test1_4.las", "1.2-with-color.las", "gps-time-nan.las"]
# expected (version, point format) per file, from CATALOG.md: the oracle must not just agree
# with itself on a file that is not what the catalogue says
CATALOGUE = {
    "autzen_trim.las": ((1, 2), 3), "autzen_trim_7.las": ((1, 4), 7),
    "mvk-thin.las": ((1, 2), 1), "epsg_4326.las": ((1, 2), 0), "extrabytes.las": ((1, 4), 3),
    "test1_4.las": ((1, 4), 6), "1.2-with-color.las": ((1, 2), 3),
    "gps-time-nan.las": ((1, 2), 1),
    **{f: ((1, int(f[10])), int(f[12])) for f in FORMATS_FILES},
}
REFUSED = ["no-points.las", "1.2-with-color-clipped.las"]  # tested below and in test_las.py


def test_every_las_file_of_the_shared_data_is_tested():
    on_disk = {str(p.relative_to(las_dir())) for p in las_dir().rglob("*.las")}
    assert on_disk == set(READABLE) | set(REFUSED), on_disk ^ (set(READABLE) | set(REFUSED))
    assert len(FORMATS_FILES) == 8


@pytest.mark.parametrize("name", READABLE)
def test_shared_file_equals_the_specification(name):
    path = las_dir() / name
    raw = path.read_bytes()  # a missing file fails here
    h = check_against_the_specification(path, raw, pcl_ddg.read(path))
    assert (h["version"], h["point_format"]) == CATALOGUE[name]
    assert h["points"] > 0


def test_gps_time_nan_is_kept_as_the_nan_the_file_holds():
    path = las_dir() / "gps-time-nan.las"
    raw = path.read_bytes()
    h = parse_header(raw)
    stored = np.frombuffer(raw, "<f8", 1, h["point_offset"] + 20)  # format 1: GPS time at 20
    assert np.isnan(stored[0])
    got = pcl_ddg.read(path).fields["gps_time"]
    assert got.shape == (1,) and np.isnan(got[0])
    assert got.view(np.uint64)[0] == stored.view("<u8")[0]


def test_a_file_of_no_points():
    # pcl_ddg.read refuses it (docs/las.md: "and so does pcl_ddg.read (OSError)"), naming it
    path = las_dir() / "no-points.las"
    raw = path.read_bytes()
    h = parse_header(raw)
    assert h["points"] == 0 and h["point_offset"] == len(raw)
    with pytest.raises(OSError) as error:
        pcl_ddg.read(path)
    message = str(error.value)
    assert "no-points.las" in message and "no points" in message, message


def test_format_7_equals_its_format_3_twin_point_by_point():
    m3 = pcl_ddg.read(las_dir() / "autzen_trim.las")
    m7 = pcl_ddg.read(las_dir() / "autzen_trim_7.las")
    assert m3.las.point_format == 3 and m7.las.point_format == 7
    n = len(m3.points)
    assert n == 110000 and m7.points.shape == (n, 3)
    np.testing.assert_array_equal(m7.points, m3.points)  # as doubles, whatever scale and offset
    a, b = m3.fields, m7.fields
    for key in ("intensity", "return_number", "number_of_returns", "classification", "red",
                "green", "blue", "point_source_id", "user_data", "scan_direction_flag",
                "edge_of_flight_line"):
        np.testing.assert_array_equal(b[key], a[key], err_msg=key)
    np.testing.assert_array_equal(b["gps_time"].view(np.uint64), a["gps_time"].view(np.uint64))
    # synthetic, key-point and withheld are bits 0-2 in both; format 7 adds overlap (bit 3)
    np.testing.assert_array_equal(b["classification_flags"] & 7, a["classification_flags"])
    assert not np.any(b["scanner_channel"])
    # scan angle rank: whole degrees (int8); scan angle: 0.006 degree steps (int16)
    rank = a["scan_angle_rank"].astype(np.float64)
    degrees = b["scan_angle"].astype(np.float64) * 0.006
    assert np.max(np.abs(degrees - rank)) < 0.006  # the same angle, within one 0.006 degree step
    # exactly: PDAL converts rank / 0.006 truncated toward zero (-17 degrees -> -2833, not -2833.3)
    np.testing.assert_array_equal(b["scan_angle"], np.trunc(rank / 0.006).astype(np.int16))
    assert np.any(a["scan_angle_rank"] != 0)  # the comparison compares something
    for key in ("return_number", "number_of_returns", "classification", "red", "gps_time",
                "intensity", "scan_direction_flag"):
        assert np.unique(a[key]).size > 1, key  # the comparisons compare something
    assert np.all(a["point_source_id"] == 7326)  # one flight line: not zero at least


# --- files of every format, written here from the tables --------------------------------------


def vlr(user: str, record_id: int, payload: bytes, description: str = "") -> bytes:
    head = struct.pack("<H16sHH32s", 0, user.encode(), record_id, len(payload),
                       description.encode())
    assert len(head) == VLR_HEADER
    return head + payload


def las14(point_format: int, records: bytes, count: int, record_length: int, scale, offset,
          xyz_int: np.ndarray, returns: np.ndarray, vlrs=(), global_encoding: int = 0) -> bytes:
    """A LAS 1.4 file written from Table 3: header, VLRs, records."""
    body = b"".join(vlrs)
    header = bytearray(375)
    header[0:4] = b"LASF"
    struct.pack_into("<HH", header, 4, 7, global_encoding)
    header[8:24] = bytes(range(16))  # GUID
    header[24], header[25] = 1, 4
    header[26:58] = b"pcl_ddg tests".ljust(32, b"\0")
    header[58:90] = b"test_las_formats.py".ljust(32, b"\0")
    struct.pack_into("<HHHI", header, 90, 331, 2026, 375, 375 + len(body))
    struct.pack_into("<I", header, 100, len(vlrs))
    header[104] = point_format
    struct.pack_into("<HI", header, 105, record_length, count if point_format < 6 else 0)
    if point_format < 6:
        struct.pack_into("<5I", header, 111, *[int(np.sum(returns == i)) for i in range(1, 6)])
    coords = xyz_int * np.array(scale) + np.array(offset)
    hi, lo = coords.max(axis=0), coords.min(axis=0)
    struct.pack_into("<3d3d6d", header, 131, *scale, *offset, hi[0], lo[0], hi[1], lo[1], hi[2],
                     lo[2])
    struct.pack_into("<QQIQ", header, 227, 0, 0, 0, count)
    struct.pack_into("<15Q", header, 255, *[int(np.sum(returns == i)) for i in range(1, 16)])
    return bytes(header) + body + records


def random_records(point_format: int, n: int, rng, extra: int = 0) -> np.ndarray:
    """n records of the format's layout, every field filled over its range (bit-field bytes
    over all 256 values), plus `extra` bytes of zeros."""
    fields = SPEC[point_format]
    length = MINIMUM_SIZE[point_format] + extra
    dtype = np.dtype({"names": [f[0] for f in fields], "formats": [f[1] for f in fields],
                      "offsets": [f[2] for f in fields], "itemsize": length})
    r = np.zeros(n, dtype)
    for name, kind, _ in fields:
        t = np.dtype(kind)
        if name in "XYZ":
            r[name] = rng.integers(-2_000_000_000, 2_000_000_000, n)
        elif t.kind in "iu":
            info = np.iinfo(t)
            r[name] = rng.integers(info.min, info.max, n, dtype=t.newbyteorder("="),
                                   endpoint=True)
        elif name == "gps_time":
            r[name] = rng.uniform(-1e9, 1e9, n)
        else:
            r[name] = rng.normal(0, 1e3, n).astype(np.float32)
    return r


def test_the_oracle_tables_are_the_specifications():
    for point_format, fields in SPEC.items():
        covered = np.zeros(MINIMUM_SIZE[point_format], int)
        for _, kind, at in fields:
            covered[at:at + np.dtype(kind).itemsize] += 1
        assert np.all(covered == 1), point_format  # every byte once, up to the minimum size
    assert [name for name, _, _ in SPEC[10]][-7:] == [n for n, _, _ in _wave(0)]


def test_a_format_3_survey_written_as_format_7_keeps_its_angles_and_matches_the_twin(tmp_path):
    """autzen_trim.las's records written without a layout (LAS 1.4 format 7, since it has colours):
    every field as in PDAL's format 7 twin, and the scan angle rank (whole degrees) becomes the
    scan angle in 0.006 degree steps, rounded to the nearest step (PDAL truncates: rank 1 gives
    167 here, 166 in the twin)."""
    m3 = pcl_ddg.read(las_dir() / "autzen_trim.las")
    twin = pcl_ddg.read(las_dir() / "autzen_trim_7.las")
    out = tmp_path / "autzen_7.las"
    with pytest.warns(UserWarning, match="no CRS"):
        pcl_ddg.write(out, m3.points, fields=m3.fields)
    raw = out.read_bytes()
    h = parse_header(raw)
    assert (h["version"], h["point_format"]) == ((1, 4), 7)
    records = records_of(raw, h)
    rank = m3.fields["scan_angle_rank"].astype(np.float64)
    assert np.unique(rank).size > 5  # the angles compared vary
    # the nearest 0.006 degree step: k / 0.006 is never half-way for a whole k
    np.testing.assert_array_equal(records["scan_angle"], np.round(rank / 0.006).astype(np.int16))
    b, t = pcl_ddg.read(out).fields, twin.fields
    # the same grid points (this file's scale and offset are chosen here, so X * scale + offset
    # may differ from the twin's by an ulp)
    np.testing.assert_allclose(pcl_ddg.read(out).points, twin.points, rtol=0,
                               atol=0.25 * min(twin.las.scale))
    for key in ("intensity", "return_number", "number_of_returns", "classification", "red",
                "green", "blue", "point_source_id", "user_data", "scan_direction_flag",
                "edge_of_flight_line", "classification_flags", "scanner_channel"):
        np.testing.assert_array_equal(b[key], t[key], err_msg=key)
    np.testing.assert_array_equal(b["gps_time"].view(np.uint64), t["gps_time"].view(np.uint64))
    assert np.max(np.abs(b["scan_angle"].astype(int) - t["scan_angle"])) == 1  # rounding vs trunc


@pytest.mark.parametrize("point_format", range(11))
def test_every_format_written_from_the_tables(point_format, tmp_path):
    """A file of each format 0-10, its bytes written here, read field by field and written back
    to the same records."""
    rng = np.random.default_rng(100 + point_format)
    n = 500
    r = random_records(point_format, n, rng)
    xyz = np.stack([r["X"], r["Y"], r["Z"]], 1).astype(np.int64)
    returns = r["return_byte"] & (7 if point_format < 6 else 15)
    vlrs, encoding = [vlr("pcl_ddg", 1, b"kept, byte for byte\0", "a user VLR")], 0
    if point_format in (4, 5, 9, 10):
        # a wave packet descriptor (LASF_Spec 100: bits, compression, samples, spacing, gain,
        # offset); the packets in an external file (global encoding bit 2)
        vlrs.append(vlr("LASF_Spec", 100, struct.pack("<BBIIdd", 16, 0, 80, 1000, 0.5, -1.0)))
        encoding = 1 << 2
    scale, offset = (0.001, 0.002, 0.0005), (1000.0, -250.0, 12.5)
    raw = las14(point_format, r.tobytes(), n, MINIMUM_SIZE[point_format], scale, offset, xyz,
                returns, vlrs, encoding)
    path = tmp_path / f"format{point_format}.las"
    path.write_bytes(raw)
    m = pcl_ddg.read(path)
    h = check_against_the_specification(path, raw, m)
    assert h["point_format"] == point_format and h["points"] == n

    out = tmp_path / f"again{point_format}.las"
    pcl_ddg.write(out, m.points, fields=m.fields, las=m.las)
    written = out.read_bytes()
    w = parse_header(written)
    assert (w["version"], w["point_format"], w["record_length"]) == (
        (1, 4), point_format, MINIMUM_SIZE[point_format])
    assert w["global_encoding"] == encoding
    assert [(v["user"], v["id"], v["payload"]) for v in parse_vlrs(written, w)] == \
        [(v["user"], v["id"], v["payload"]) for v in parse_vlrs(raw, h)]
    np.testing.assert_array_equal(record_bytes(written, w), record_bytes(raw, h))
    # the recomputed header: the same bounds and counts by return as written here
    for key in ("min_x", "max_x", "min_y", "max_y", "min_z", "max_z", "count", "by_return"):
        assert w[key] == h[key], key
    assert w["legacy_count"] == (n if point_format < 6 else 0)
    if point_format < 6:
        assert w["legacy_by_return"] == h["legacy_by_return"]


# --- Extra Bytes arrays with a scale and an offset ----------------------------------------------


def eb_descriptor(data_type: int, options: int, name: str, scale=(0, 0, 0), offset=(0, 0, 0),
                  description: str = "") -> bytes:
    d = bytearray(192)
    d[2], d[3] = data_type, options
    d[4:36] = name.encode().ljust(32, b"\0")
    struct.pack_into("<3d", d, 112, *scale)
    struct.pack_into("<3d", d, 136, *offset)
    d[160:192] = description.encode().ljust(32, b"\0")
    return bytes(d)


# (name, data type, options, scale[3], offset[3]); 16 = long[2] (int32), 23 = unsigned short[3],
# 22 = char[3] (int8), 25 = unsigned long[3] (uint32), 11 = unsigned char[2], 14 = short[2]
EB_DIMS = [
    ("pair", 16, EB_SCALE_BIT | EB_OFFSET_BIT, (0.01, 0.5, 0), (100.0, -3.0, 0)),
    ("colour 3", 23, EB_SCALE_BIT, (0.1, 0.25, 2.0), (0, 0, 0)),
    ("shift", 22, EB_OFFSET_BIT, (0, 0, 0), (-7.5, 1000.0, 0.125)),
    ("wide", 25, EB_SCALE_BIT | EB_OFFSET_BIT, (1e-3, 1.0, 4.0), (1e6, -5e9, 0.0)),
    ("plain pair", 11, 0, (0, 0, 0), (0, 0, 0)),
    ("amplitude", 6, EB_SCALE_BIT | EB_OFFSET_BIT, (0.001, 0, 0), (-2.0, 0, 0)),
    ("tilt", 14, EB_SCALE_BIT | EB_OFFSET_BIT, (0.5, 0.005, 0), (0.0, 90.0, 0)),
]


@pytest.mark.parametrize("point_format", [1, 6])
def test_scaled_extra_bytes_arrays(point_format, tmp_path):
    rng = np.random.default_rng(7 + point_format)
    n = 400
    sizes = [np.dtype(eb_layout(t, o)[0]).itemsize * eb_layout(t, o)[1]
             for _, t, o, _, _ in EB_DIMS]
    extra = sum(sizes)
    r = random_records(point_format, n, rng, extra)
    rb = r.view(np.uint8).reshape(n, -1)
    raw_values = {}
    at = MINIMUM_SIZE[point_format]
    for (name, data_type, options, _, _), size in zip(EB_DIMS, sizes):
        kind, count = eb_layout(data_type, options)
        t = np.dtype(kind)
        info = np.iinfo(t)
        values = rng.integers(info.min, info.max, (n, count), dtype=t.newbyteorder("="),
                              endpoint=True).astype(t)
        values[0], values[1] = info.min, info.max  # the ends of the range
        rb[:, at:at + size] = values.view(np.uint8).reshape(n, size)
        raw_values[name] = values if count > 1 else values[:, 0]
        at += size
    payload = b"".join(eb_descriptor(t, o, name, s, off, f"{name} description")
                       for name, t, o, s, off in EB_DIMS)
    xyz = np.stack([r["X"], r["Y"], r["Z"]], 1).astype(np.int64)
    returns = r["return_byte"] & (7 if point_format < 6 else 15)
    raw = las14(point_format, r.tobytes(), n, MINIMUM_SIZE[point_format] + extra,
                (0.01, 0.01, 0.01), (0.0, 0.0, 0.0), xyz, returns,
                [vlr("LASF_Spec", 4, payload, "Extra Bytes")])
    path = tmp_path / "arrays.las"
    path.write_bytes(raw)
    m = pcl_ddg.read(path)
    h = check_against_the_specification(path, raw, m)

    # the same, said per dimension from what this test wrote (not from the parsed VLR)
    for name, data_type, options, scale, offset in EB_DIMS:
        key = name.replace(" ", "_")
        got, stored = m.fields[key], raw_values[name]
        count = 2 if 11 <= data_type <= 20 else 3 if data_type > 20 else 1
        assert got.shape == ((n, count) if count > 1 else (n,)), key
        if options & (EB_SCALE_BIT | EB_OFFSET_BIT):
            assert got.dtype == np.float64, key
            for i in range(count):
                s = scale[i] if options & EB_SCALE_BIT else 1.0
                o = offset[i] if options & EB_OFFSET_BIT else 0.0
                element = got[:, i] if count > 1 else got
                column = stored[:, i] if count > 1 else stored
                np.testing.assert_array_equal(element, column.astype(np.float64) * s + o,
                                              err_msg=f"{key}[{i}]: raw * {s} + {o}")
        else:
            assert got.dtype == stored.dtype, key
            np.testing.assert_array_equal(got, stored, err_msg=key)
    assert [d[0] for d in m.las.extra_bytes] == [name.replace(" ", "_") for name, *_ in EB_DIMS]
    assert [d[1] for d in m.las.extra_bytes] == [payload[i:i + 192]
                                                 for i in range(0, len(payload), 192)]

    out = tmp_path / "again.las"
    pcl_ddg.write(out, m.points, fields=m.fields, las=m.las)
    written = out.read_bytes()
    w = parse_header(written)
    assert w["record_length"] == h["record_length"]
    assert [(v["user"], v["id"], v["payload"]) for v in parse_vlrs(written, w)] == \
        [(v["user"], v["id"], v["payload"]) for v in parse_vlrs(raw, h)]
    assert written[w["point_offset"]:] == raw[h["point_offset"]:]  # every record, bit for bit
