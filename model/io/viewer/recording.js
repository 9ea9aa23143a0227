// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The replay page's reader of Scree recordings (docs/recording.md), written for the browser: chunks are
// checked against their CRC-32 before anything is read from them, frames are inflated with the browser's
// DecompressionStream("deflate") (zlib format), and XOR-delta particle arrays are undone frame by frame.
// Every read is bounds-checked, so a truncated or corrupted file is reported (chunk, byte offset) instead of
// being drawn wrong. Plain script (no modules): the page inlines it, and node can load it for a quick check.
"use strict";

const ScreeRecording = (() => {
  const READ_MAJOR = 1;

  class FormatError extends Error {}

  // CRC-32, IEEE 802.3 polynomial (reflected 0xEDB88320), as zlib's crc32.
  const CRC_TABLE = (() => {
    const t = new Uint32Array(256);
    for (let n = 0; n < 256; ++n) {
      let c = n;
      for (let k = 0; k < 8; ++k) c = c & 1 ? 0xedb88320 ^ (c >>> 1) : c >>> 1;
      t[n] = c >>> 0;
    }
    return t;
  })();
  function crc32(bytes) {
    let c = 0xffffffff;
    for (let i = 0; i < bytes.length; ++i) c = CRC_TABLE[(c ^ bytes[i]) & 0xff] ^ (c >>> 8);
    return (c ^ 0xffffffff) >>> 0;
  }

  // Little-endian reader over a Uint8Array; `what` and `base` name the buffer and its file offset in errors.
  class Reader {
    constructor(bytes, what, base) {
      this.b = bytes;
      this.v = new DataView(bytes.buffer, bytes.byteOffset, bytes.byteLength);
      this.p = 0;
      this.what = what;
      this.base = base || 0;
    }
    need(n, field) {
      if (n < 0 || this.p + n > this.b.length)
        throw new FormatError(`${this.what}: ${field} needs ${n} bytes at byte offset ${this.base + this.p}, ` +
                              `but only ${this.b.length - this.p} remain (truncated or corrupted)`);
    }
    u8(f) { this.need(1, f); return this.v.getUint8(this.p++); }
    u16(f) { this.need(2, f); const x = this.v.getUint16(this.p, true); this.p += 2; return x; }
    u32(f) { this.need(4, f); const x = this.v.getUint32(this.p, true); this.p += 4; return x; }
    f32(f) { this.need(4, f); const x = this.v.getFloat32(this.p, true); this.p += 4; return x; }
    f64(f) { this.need(8, f); const x = this.v.getFloat64(this.p, true); this.p += 8; return x; }
    f64s(n, f) { const a = new Array(n); for (let i = 0; i < n; ++i) a[i] = this.f64(f); return a; }
    str(f) {
      const n = this.u32(f + " length");
      this.need(n, f);
      const s = new TextDecoder().decode(this.b.subarray(this.p, this.p + n));
      this.p += n;
      return s;
    }
    // A copy of n elements of 4 bytes (an aligned buffer, so typed views on it are allowed).
    words(n, f) {
      this.need(4 * n, f);
      const out = new Uint32Array(n);
      new Uint8Array(out.buffer).set(this.b.subarray(this.p, this.p + 4 * n));
      this.p += 4 * n;
      return out;
    }
    u16s(n, f) {
      this.need(2 * n, f);
      const out = new Uint16Array(n);
      new Uint8Array(out.buffer).set(this.b.subarray(this.p, this.p + 2 * n));
      this.p += 2 * n;
      return out;
    }
    bytes(n, f) { this.need(n, f); const s = this.b.subarray(this.p, this.p + n); this.p += n; return s; }
  }

  const SHAPES = ["sphere", "box", "capsule", "cylinder", "plane", "convex", "heightfield", "line"];

  function parseScene(r) {
    const scene = { name: r.str("scene name"), timeStep: r.f64("time step"), frameInterval: r.f64("frame interval") };
    scene.gravity = r.f64s(3, "gravity");
    const nm = r.u32("material count");
    scene.materials = [];
    for (let i = 0; i < nm; ++i) scene.materials.push({ name: r.str("material name"), rgb: [r.u8("colour"), r.u8("colour"), r.u8("colour")] });
    const nb = r.u32("body count");
    scene.bodies = [];
    for (let b = 0; b < nb; ++b) {
      const body = { name: r.str("body name"), motion: r.u8("motion"), geometries: [] };
      const ng = r.u32("geometry count");
      for (let g = 0; g < ng; ++g) {
        const geo = { material: r.u32("material index"), position: r.f64s(3, "geometry position"), rotation: r.f64s(4, "geometry rotation") };
        const type = r.u8("shape type");
        if (type >= SHAPES.length) throw new FormatError(`${r.what}: body ${b} geometry ${g}: unknown shape type ${type}`);
        geo.shape = SHAPES[type];
        switch (geo.shape) {
          case "sphere": geo.radius = r.f64("radius"); break;
          case "box": geo.halfExtents = r.f64s(3, "half extents"); break;
          case "capsule": case "cylinder": geo.radius = r.f64("radius"); geo.height = r.f64("height"); break;
          case "plane": geo.normal = r.f64s(3, "plane normal"); geo.offset = r.f64("plane offset"); break;
          case "convex": {
            const nv = r.u32("convex vertex count");
            geo.vertices = new Float32Array(r.words(3 * nv, "convex vertices").buffer);
            const nt = r.u32("convex triangle count");
            geo.triangles = r.words(3 * nt, "convex triangles");
            for (const i of geo.triangles) if (i >= nv) throw new FormatError(`${r.what}: body ${b}: convex triangle index ${i} >= vertex count ${nv}`);
            break;
          }
          case "heightfield": geo.terrain = r.u32("terrain index"); break;
          case "line": geo.a = r.f64s(3, "line a"); geo.b = r.f64s(3, "line b"); break;
        }
        body.geometries.push(geo);
      }
      scene.bodies.push(body);
    }
    const npm = r.u32("particle material count");
    scene.particleMaterials = [];
    for (let i = 0; i < npm; ++i) scene.particleMaterials.push({ name: r.str("particle material name"), rgb: [r.u8("colour"), r.u8("colour"), r.u8("colour")] });
    return scene;
  }

  function parseHeightField(r) {
    const nx = r.u32("nx"), ny = r.u32("ny");
    if (nx < 2 || ny < 2) throw new FormatError(`${r.what}: a height field needs at least 2 x 2 vertices, not ${nx} x ${ny}`);
    const hf = { nx, ny, elementSize: r.f64("element size"), position: r.f64s(3, "position"), rotation: r.f64s(4, "rotation") };
    hf.heights = new Float32Array(r.words(nx * ny, "heights").buffer);
    return hf;
  }

  async function inflate(bytes) {
    const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream("deflate"));
    return new Uint8Array(await new Response(stream).arrayBuffer());
  }

  // Decodes one inflated frame; `prev` is the previous decoded frame (for the XOR delta and the persisting
  // radii and materials).
  function parseFrame(r, rec, prev) {
    const f = { index: r.u32("frame index"), time: r.f64("simulation time") };
    const nb = r.u32("body count");
    if (nb !== rec.scene.bodies.length) throw new FormatError(`${r.what}: body count ${nb} differs from the scene's ${rec.scene.bodies.length}`);
    f.poses = new Float64Array(7 * nb);
    for (let i = 0; i < 7 * nb; ++i) f.poses[i] = r.f64("body poses");
    const flags = r.u8("particle flags");
    const n = r.u32("particle count");
    const delta = (flags & 1) !== 0, radiiPresent = (flags & 2) !== 0;
    if (delta && (!prev || prev.count !== n))
      throw new FormatError(`${r.what}: a delta frame needs a previous frame with the same particle count ${n}`);
    if (!delta && !radiiPresent && n > 0) throw new FormatError(`${r.what}: a key frame must carry the radii (flag bit 1)`);
    f.count = n;
    const ids = r.words(n, "particle ids");
    const pos = r.words(3 * n, "particle positions");
    const speed = r.words(n, "particle speeds");
    if (delta) {
      // A delta frame has the previous frame's ids (stored as zero XOR): they are shared, not copied.
      for (let i = 0; i < n; ++i)
        if (ids[i] !== 0) throw new FormatError(`${r.what}: a delta frame changes particle id ${i} (a key frame must)`);
      const pp = prev.posBits, ps = prev.speedBits;
      for (let i = 0; i < 3 * n; ++i) pos[i] ^= pp[i];
      for (let i = 0; i < n; ++i) speed[i] ^= ps[i];
    }
    f.ids = delta ? prev.ids : ids;
    f.posBits = pos;
    f.speedBits = speed;
    f.positions = new Float32Array(pos.buffer);
    f.speeds = new Float32Array(speed.buffer);
    if (radiiPresent) {  // stored plain, also in a delta frame (docs/recording.md)
      f.radii = new Float32Array(r.words(n, "particle radii").buffer);
      f.materials = r.u16s(n, "particle materials");
    } else {
      f.radii = prev ? prev.radii : new Float32Array(0);
      f.materials = prev ? prev.materials : new Uint16Array(0);
    }
    const nt = r.u32("terrain count");
    if (nt !== rec.heightFields.length) throw new FormatError(`${r.what}: terrain count ${nt} differs from the ${rec.heightFields.length} HFLD chunks`);
    f.terrainRects = [];
    for (let t = 0; t < nt; ++t) {
      const hf = rec.heightFields[t];
      const nr = r.u32("rectangle count");
      const rects = [];
      for (let q = 0; q < nr; ++q) {
        const i0 = r.u32("rectangle i0"), j0 = r.u32("rectangle j0"), w = r.u32("rectangle w"), h = r.u32("rectangle h");
        if (i0 + w > hf.nx || j0 + h > hf.ny)
          throw new FormatError(`${r.what}: terrain ${t} rectangle (${i0}, ${j0}, ${w} x ${h}) is outside its ${hf.nx} x ${hf.ny} grid`);
        rects.push({ i0, j0, w, h, heights: new Float32Array(r.words(w * h, "rectangle heights").buffer) });
      }
      f.terrainRects.push(rects);
    }
    const nc = r.u32("contact count");
    f.contacts = new Float32Array(r.words(7 * nc, "contacts").buffer);
    return f;  // bytes after this are fields of a newer minor version: skipped
  }

  // Parses a whole recording. `name` is used in messages; `onProgress(fraction)` is called while frames decode.
  async function parse(bytes, name, onProgress) {
    const t0 = performance.now();
    const head = new Reader(bytes, name, 0);
    const magic = new TextDecoder().decode(head.bytes(8, "magic"));
    if (magic !== "SCREEREC") throw new FormatError(`${name} is not a Scree recording (it does not start with "SCREEREC")`);
    const major = head.u16("major version"), minor = head.u16("minor version");
    head.u32("flags");
    if (major !== READ_MAJOR)
      throw new FormatError(`${name} was written in recording format ${major}.${minor}; this reader reads ${READ_MAJOR}.x`);
    const rec = { name, version: [major, minor], scene: null, heightFields: [], frames: [], frameChunks: [], skipped: [] };
    let ended = false;
    let nchunk = 0;
    while (head.p < bytes.length) {
      const at = head.p;
      const tag = new TextDecoder().decode(head.bytes(4, `chunk ${nchunk} tag`));
      const len = head.u32(`chunk ${nchunk} (${tag}) length`);
      const payload = head.bytes(len, `chunk ${nchunk} (${tag}) payload`);
      const crc = head.u32(`chunk ${nchunk} (${tag}) CRC-32`);
      if (crc32(payload) !== crc)
        throw new FormatError(`${name}: CRC-32 mismatch in chunk ${nchunk} (${tag}) at byte offset ${at}: the file is corrupted`);
      const what = `${name}: chunk ${nchunk} (${tag})`;
      const r = new Reader(payload, what, at + 8);
      if (nchunk === 0 && tag !== "SCNE") throw new FormatError(`${what}: the first chunk must be SCNE`);
      if (tag === "SCNE") {
        if (rec.scene) throw new FormatError(`${what}: a second SCNE chunk`);
        rec.scene = parseScene(r);
      } else if (tag === "HFLD") {
        rec.heightFields.push(parseHeightField(r));
      } else if (tag === "FRAM") {
        rec.frameChunks.push({ what, r });
      } else if (tag === "ENDR") {
        const count = r.u32("frame count");
        if (count !== rec.frameChunks.length)
          throw new FormatError(`${what}: says ${count} frames, the file holds ${rec.frameChunks.length}`);
        ended = true;
        break;
      } else {
        rec.skipped.push(tag);
      }
      ++nchunk;
    }
    if (!ended) throw new FormatError(`${name} has no ENDR chunk: the file is truncated`);
    for (const b of rec.scene.bodies)
      for (const g of b.geometries)
        if (g.shape === "heightfield" && g.terrain >= rec.heightFields.length)
          throw new FormatError(`${name}: body "${b.name}" refers to terrain ${g.terrain}, but there are ${rec.heightFields.length} HFLD chunks`);
    rec.parseMs = performance.now() - t0;

    // Inflate in batches (the streams run concurrently), then undo the deltas in order.
    const t1 = performance.now();
    const BATCH = 32;
    let prev = null;
    rec.maxSpeed = 0;
    rec.maxParticles = 0;
    rec.maxContacts = 0;
    for (let s = 0; s < rec.frameChunks.length; s += BATCH) {
      const batch = rec.frameChunks.slice(s, s + BATCH);
      const raws = await Promise.all(batch.map(async ({ what, r }) => {
        const rawLen = r.u32("raw length");
        let raw;
        try {
          raw = await inflate(r.bytes(r.b.length - r.p, "zlib stream"));
        } catch (e) {
          throw new FormatError(`${what}: the zlib stream does not inflate (${e.message})`);
        }
        if (raw.length !== rawLen) throw new FormatError(`${what}: inflates to ${raw.length} bytes, not the ${rawLen} it says`);
        return raw;
      }));
      for (let k = 0; k < batch.length; ++k) {
        const f = parseFrame(new Reader(raws[k], `${batch[k].what}, inflated`, 0), rec, prev);
        if (f.index !== s + k) throw new FormatError(`${batch[k].what}: frame index ${f.index}, expected ${s + k}`);
        for (let i = 0; i < f.count; ++i) if (f.speeds[i] > rec.maxSpeed) rec.maxSpeed = f.speeds[i];
        rec.maxParticles = Math.max(rec.maxParticles, f.count);
        rec.maxContacts = Math.max(rec.maxContacts, f.contacts.length / 7);
        if (prev) { delete prev.posBits; delete prev.speedBits; }
        rec.frames.push(f);
        prev = f;
      }
      if (onProgress) onProgress(Math.min(1, (s + batch.length) / rec.frameChunks.length));
    }
    delete rec.frameChunks;
    rec.decodeMs = performance.now() - t1;
    if (rec.frames.length === 0) throw new FormatError(`${name} holds no frames`);
    return rec;
  }

  return { parse, crc32, FormatError, READ_MAJOR };
})();

if (typeof module !== "undefined") module.exports = ScreeRecording;
