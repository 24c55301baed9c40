#!/usr/bin/env python3
"""Writes the small synthetic LAS seeds of fuzz_las (every version and point format, VLRs,
EVLRs, an Extra Bytes VLR, undocumented extra bytes), from the LAS 1.4 R15 tables.
Run from fuzz/: python3 make_las_seeds.py (writes seeds/las/)"""
import struct

SIZES = [20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67]
HEADER = {0: 227, 1: 227, 2: 227, 3: 235, 4: 375}


def vlr(user, rid, data, desc=b"seed"):
    return struct.pack("<H16sHH32s", 0, user, rid, len(data), desc) + data


def evlr(user, rid, data, desc=b"seed"):
    return struct.pack("<H16sHQ32s", 0, user, rid, len(data), desc) + data


def descriptor(dtype, name, options=0):
    d = bytearray(192)
    d[2], d[3] = dtype, options
    d[4:4 + len(name)] = name
    d[160:160 + len(name)] = name
    return bytes(d)


def las(minor, fmt, points=3, vlrs=b"", nvlr=0, extra=0, evlrs=b"", nevlr=0, gap=b"",
        encoding=0):
    hs = HEADER[minor]
    rl = SIZES[fmt] + extra
    offset = hs + len(vlrs) + len(gap)
    recs = b""
    for i in range(points):
        r = bytearray(rl)
        struct.pack_into("<iiiH", r, 0, 1000 * i - 7, -2000 * i, 30 * i + 5, 100 + i)
        r[14] = (1 + i % 2) | (2 << (4 if fmt >= 6 else 3))
        r[15 if fmt < 6 else 16] = 2 + i
        for k in range(SIZES[fmt], rl):
            r[k] = (17 * i + k) & 0xFF
        recs += bytes(r)
    end = offset + len(recs)
    h = bytearray(hs)
    h[0:4] = b"LASF"
    h[24], h[25] = 1, minor
    struct.pack_into("<H", h, 6, encoding)
    h[26:26 + 4] = b"seed"
    struct.pack_into("<HIIBHI", h, 94, hs, offset, nvlr, fmt, rl, 0 if fmt >= 6 else points)
    struct.pack_into("<5I", h, 111, points, 0, 0, 0, 0)
    struct.pack_into("<3d3d", h, 131, 0.01, 0.01, 0.001, 1000.0, -50.0, 0.0)
    struct.pack_into("<6d", h, 179, 1000.0, 999.9, -50.0, -50.1, 0.1, 0.0)
    if minor >= 3 and nevlr:
        struct.pack_into("<Q", h, 227, end)
    if minor >= 4:
        struct.pack_into("<QIQ", h, 235, end if nevlr else 0, nevlr, points)
    return bytes(h) + vlrs + gap + recs + evlrs


proj = vlr(b"LASF_Projection", 34735, struct.pack("<8H", 1, 1, 0, 1, 1024, 0, 1, 1))
seeds = {
    "v10_f0_gap.las": las(0, 0, vlrs=proj, nvlr=1, gap=b"\xdd\xcc"),
    "v11_f1.las": las(1, 1),
    "v12_f2_undocumented.las": las(2, 2, extra=5),
    "v12_f3.las": las(2, 3, vlrs=proj, nvlr=1),
    "v13_f4_waveform.las": las(3, 4, evlrs=evlr(b"LASF_Spec", 65535, b"\x00" * 16), nevlr=1,
                               encoding=2),
    "v13_f5.las": las(3, 5),
    "v14_f6_evlr.las": las(4, 6, evlrs=evlr(b"LASF_Projection", 2112, b"GEOGCS[]\x00"), nevlr=1),
    "v14_f7.las": las(4, 7, points=0),
    "v14_f8_extra_bytes.las": las(
        4, 8, extra=1 + 2 + 4 + 8 + 6 + 3,
        vlrs=vlr(b"LASF_Spec", 4, descriptor(1, b"a") + descriptor(4, b"b") +
                 descriptor(9, b"NormalX") + descriptor(10, b"d") + descriptor(23, b"rgb") +
                 descriptor(0, b"raw", 3)), nvlr=1),
    "v14_f9.las": las(4, 9),
    "v14_f10.las": las(4, 10, extra=2, vlrs=vlr(b"LASF_Spec", 4, descriptor(3, b"u")), nvlr=1),
}
for name, data in seeds.items():
    with open("seeds/las/" + name, "wb") as f:
        f.write(data)
