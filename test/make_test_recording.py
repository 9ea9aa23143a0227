#!/usr/bin/python3
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
"""Writes a valid Scree recording (docs/recording.md) without the C++ writer, for the replay page's tests.

It is an independent implementation of the format (zlib, struct and binascii.crc32 only), so the page's
reader is checked against the document rather than against scree::io::RecordingWriter. Nothing is simulated:
the motions are closed-form so the test knows where everything is.

Scenes:
  tower10  10 boxes of 0.6 m stacked on a ground box; each starts 2 cm above its resting place and falls
           onto it within the first 10 frames (then rests, so later frames are deltas of zero). Off to the
           side (y < -2): a sphere, a capsule, a cylinder, a convex tetrahedron, a line, a plane body and
           a 9 x 7 height field whose heights change in rectangles; 24 particles falling (XOR-delta frames)
           that are replaced by 30 new ones at frame 30 (a key frame); contact points under each box; an
           unknown chunk the reader must skip.
  perf     N particles (default 10,000) moving on circles for F frames (default 600), every coordinate
           changing every frame (nonzero deltas), over a ground box: the replay page's speed figure.

Usage: make_test_recording.py OUT [--scene tower10|perf] [--frames F] [--particles N]
                                  [--corrupt crc|version|truncate]
"""
import argparse
import binascii
import math
import struct
import zlib

MAJOR, MINOR = 1, 0
H = 1.0 / 60.0
FRAME_INTERVAL = 2 * H  # 30 frames/s, the writer records every 2nd step

TOWER_BOX_HALF = 0.3
TOWER_N = 10
TOWER_GAP = 0.02
TOWER_FALL_FRAMES = 10


def s_str(s):
    b = s.encode("utf-8")
    return struct.pack("<I", len(b)) + b


def chunk(tag, payload):
    assert len(tag) == 4
    return tag + struct.pack("<I", len(payload)) + payload + struct.pack("<I", binascii.crc32(payload) & 0xFFFFFFFF)


def geom(material, shape_type, params, pos=(0, 0, 0), rot=(0, 0, 0, 1)):
    return struct.pack("<I3d4dB", material, *pos, *rot, shape_type) + params


def body(name, motion, geoms):
    return s_str(name) + struct.pack("<BI", motion, len(geoms)) + b"".join(geoms)


def scene_chunk(name, materials, bodies, particle_materials):
    p = s_str(name) + struct.pack("<dd3d", H, FRAME_INTERVAL, 0.0, 0.0, -9.81)
    p += struct.pack("<I", len(materials))
    for mname, rgb in materials:
        p += s_str(mname) + bytes(rgb)
    p += struct.pack("<I", len(bodies)) + b"".join(bodies)
    p += struct.pack("<I", len(particle_materials))
    for mname, rgb in particle_materials:
        p += s_str(mname) + bytes(rgb)
    return chunk(b"SCNE", p)


def hfld_chunk(nx, ny, elem, pos, rot, heights):
    assert len(heights) == nx * ny
    p = struct.pack("<IId3d4d", nx, ny, elem, *pos, *rot) + struct.pack("<%df" % len(heights), *heights)
    return chunk(b"HFLD", p)


def f32_bits(values):
    """float32 bit patterns (u32) of a list of floats."""
    return list(struct.unpack("<%dI" % len(values), struct.pack("<%df" % len(values), *values)))


class FrameEncoder:
    """Keeps the previous frame's particle arrays for the XOR delta."""

    def __init__(self):
        self.prev = None  # (ids, pos bits, speed bits, radii, materials)

    def frame(self, index, time, poses, ids, pos, speeds, radii, mats, terrains, contacts):
        raw = struct.pack("<IdI", index, time, len(poses))
        for p in poses:
            raw += struct.pack("<7d", *p)
        n = len(ids)
        pos_bits = f32_bits(pos)
        speed_bits = f32_bits(speeds)
        delta = self.prev is not None and self.prev[0] == ids
        radii_present = not delta or self.prev[3] != f32_bits(radii) or self.prev[4] != mats
        flags = (1 if delta else 0) | (2 if radii_present else 0)
        raw += struct.pack("<BI", flags, n)
        if delta:
            _, ppos, pspeed, _, _ = self.prev
            raw += struct.pack("<%dI" % n, *([0] * n))  # ids XOR the previous ids
            raw += struct.pack("<%dI" % (3 * n), *[a ^ b for a, b in zip(pos_bits, ppos)])
            raw += struct.pack("<%dI" % n, *[a ^ b for a, b in zip(speed_bits, pspeed)])
        else:
            raw += struct.pack("<%dI" % n, *ids)
            raw += struct.pack("<%dI" % (3 * n), *pos_bits)
            raw += struct.pack("<%dI" % n, *speed_bits)
        if radii_present:  # stored plain, also in a delta frame (docs/recording.md)
            raw += struct.pack("<%df" % n, *radii) + struct.pack("<%dH" % n, *mats)
        self.prev = (list(ids), pos_bits, speed_bits, f32_bits(radii), list(mats))
        raw += struct.pack("<I", len(terrains))
        for rects in terrains:
            raw += struct.pack("<I", len(rects))
            for (i0, j0, w, h, heights) in rects:
                assert len(heights) == w * h
                raw += struct.pack("<4I", i0, j0, w, h) + struct.pack("<%df" % len(heights), *heights)
        raw += struct.pack("<I", len(contacts))
        for c in contacts:
            raw += struct.pack("<7f", *c)
        return chunk(b"FRAM", struct.pack("<I", len(raw)) + zlib.compress(raw, 6))


def header(major=MAJOR, minor=MINOR):
    return b"SCREEREC" + struct.pack("<HHI", major, minor, 0)


TERRAIN_NX, TERRAIN_NY, TERRAIN_ELEM = 9, 7, 0.25


def terrain_initial():
    return [0.05 * math.sin(i) for i in range(TERRAIN_NX * TERRAIN_NY)]


def terrain_rects(f):
    """The tower10 terrain's changed rectangles at frame f: (i0, j0, w, h, heights)."""
    if f > 0 and f % 5 == 0:
        i0, j0, w, h = (f // 5) % (TERRAIN_NX - 2), 1, 2, 3
        return [(i0, j0, w, h, [0.1 + 0.01 * f + 0.02 * q for q in range(w * h)])]
    return []


def terrain_heights(frame):
    """The tower10 terrain's heights (float32 values) after the rectangles of frames 1..frame."""
    h = terrain_initial()
    for f in range(1, frame + 1):
        for i0, j0, w, hh, values in terrain_rects(f):
            for j in range(hh):
                for i in range(w):
                    h[(j0 + j) * TERRAIN_NX + i0 + i] = values[j * w + i]
    return list(struct.unpack("<%df" % len(h), struct.pack("<%df" % len(h), *h)))


def tower_box_z(k, frame):
    """Centre height of box k (0 = bottom) at a frame: 2 cm above rest, falling to rest in 10 frames."""
    rest = TOWER_BOX_HALF * (2 * k + 1)
    s = min(1.0, frame / TOWER_FALL_FRAMES)
    return rest + TOWER_GAP * (1.0 - s * s)


def tower10(frames):
    materials = [("ground", (110, 110, 110)), ("box", (230, 120, 40)), ("other", (60, 160, 220))]
    bodies = [body("ground", 0, [geom(0, 1, struct.pack("<3d", 4.0, 4.0, 0.5), pos=(0, 0, -0.5))])]
    for k in range(TOWER_N):
        bodies.append(body("box%d" % k, 2, [geom(1, 1, struct.pack("<3d", *(TOWER_BOX_HALF,) * 3))]))
    s2 = math.sqrt(0.5)
    others = [
        ("sphere", 2, [geom(2, 0, struct.pack("<d", 0.3))], (-1.5, -3.0, 0.3)),
        ("capsule", 2, [geom(2, 2, struct.pack("<dd", 0.2, 0.6))], (-0.5, -3.0, 0.5)),
        ("cylinder", 2, [geom(2, 3, struct.pack("<dd", 0.25, 0.5), rot=(s2, 0, 0, s2))], (0.5, -3.0, 0.25)),
        ("tetra", 2, [geom(2, 5, struct.pack("<I12f", 4, 0, 0, 0, 0.5, 0, 0, 0, 0.5, 0, 0, 0, 0.5)
                           + struct.pack("<I12I", 4, 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3))], (1.5, -3.0, 0.0)),
        ("rope", 1, [geom(0xFFFFFFFF, 7, struct.pack("<6d", 0, 0, 0, 0, 0, 1.0))], (2.5, -3.0, 0.0)),
        ("floor_plane", 0, [geom(0, 4, struct.pack("<4d", 0, 0, 1, -0.01))], (0, 0, 0)),
        ("terrain", 0, [geom(0, 6, struct.pack("<I", 0))], (0, 0, 0)),
    ]
    for name, motion, g, _ in others:
        bodies.append(body(name, motion, g))
    out = header() + scene_chunk("tower10", materials, bodies, [("sand", (220, 200, 120)), ("gravel", (150, 150, 160))])
    out += hfld_chunk(TERRAIN_NX, TERRAIN_NY, TERRAIN_ELEM, (-1.0, -6.0, 0.0), (0, 0, 0, 1), terrain_initial())
    out += chunk(b"XTRA", b"a chunk from a newer minor version: skipped")
    enc = FrameEncoder()
    for f in range(frames):
        t = f * FRAME_INTERVAL
        poses = [(0, 0, 0, 0, 0, 0, 1)]
        for k in range(TOWER_N):
            poses.append((0, 0, tower_box_z(k, f), 0, 0, 0, 1))
        for _, _, _, p in others:
            poses.append((*p, 0, 0, 0, 1))
        if f < 30:
            ids = list(range(100, 124))
            base = [(-2.0 + 0.2 * (i % 6), 2.0 + 0.2 * (i // 6), 1.5) for i in range(24)]
            radii, mats = [0.05] * 24, [0] * 24
        else:
            ids = list(range(200, 230))
            base = [(2.0 + 0.15 * (i % 6), 2.0 + 0.15 * (i // 6), 1.0) for i in range(30)]
            radii, mats = [0.04] * 30, [1] * 30
        fall_t = (f % 30) * FRAME_INTERVAL
        z_drop = min(0.5 * 9.81 * fall_t * fall_t, 1.0)
        pos = []
        for x, y, z in base:
            pos += [x, y, max(z - z_drop, radii[0])]
        speeds = [9.81 * fall_t if z_drop < 1.0 else 0.0] * len(ids)
        rects = terrain_rects(f)
        contacts = [(0, 0, TOWER_BOX_HALF * 2 * k, 0, 0, 1, 9.81 * 216 * (TOWER_N - k)) for k in range(TOWER_N)]
        out += enc.frame(f, t, poses, ids, pos, speeds, radii, mats, [rects], contacts)
    out += chunk(b"ENDR", struct.pack("<I", frames))
    return out


def perf(frames, n):
    materials = [("ground", (110, 110, 110))]
    bodies = [body("ground", 0, [geom(0, 1, struct.pack("<3d", 6.0, 6.0, 0.5), pos=(0, 0, -0.5))])]
    out = header() + scene_chunk("perf", materials, bodies, [("sand", (220, 200, 120))])
    enc = FrameEncoder()
    side = int(math.ceil(n ** (1.0 / 3.0)))
    base = [((i % side) * 0.1 - side * 0.05, ((i // side) % side) * 0.1 - side * 0.05, 0.05 + (i // (side * side)) * 0.1)
            for i in range(n)]
    ids = list(range(n))
    radii, mats = [0.045] * n, [0] * n
    for f in range(frames):
        t = f * FRAME_INTERVAL
        pos = []
        speeds = []
        for i, (x, y, z) in enumerate(base):
            w = 1.0 + 0.5 * (i % 7) / 7.0  # rad/s, every particle moves every frame
            r = 0.05
            pos += [x + r * math.cos(w * t + i), y + r * math.sin(w * t + i), z]
            speeds.append(r * w)
        out += enc.frame(f, t, [(0, 0, 0, 0, 0, 0, 1)], ids, pos, speeds, radii, mats, [], [])
    out += chunk(b"ENDR", struct.pack("<I", frames))
    return out


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("--scene", default="tower10", choices=["tower10", "perf"])
    ap.add_argument("--frames", type=int, default=None)
    ap.add_argument("--particles", type=int, default=10000)
    ap.add_argument("--corrupt", choices=["crc", "version", "truncate"], default=None)
    a = ap.parse_args()
    if a.scene == "tower10":
        data = tower10(a.frames or 60)
    else:
        data = perf(a.frames or 600, a.particles)
    if a.corrupt == "crc":  # flip a byte inside the third frame's payload (after the header and SCNE)
        b = bytearray(data)
        first = data.find(b"FRAM")
        third = data.find(b"FRAM", data.find(b"FRAM", first + 8) + 8)
        b[third + 20] ^= 0x55
        data = bytes(b)
    elif a.corrupt == "version":
        data = header(MAJOR + 1, 0) + data[16:]
    elif a.corrupt == "truncate":
        data = data[: len(data) * 2 // 3]
    with open(a.out, "wb") as f:
        f.write(data)


if __name__ == "__main__":
    main()
