// SPDX-License-Identifier: MIT
// Copyright (c) 2026 The Scree authors
// The replay page's controls: an orbit camera (drag: rotate about the target, shift-drag or right-drag: pan,
// wheel: zoom; z stays up), play/pause, playback speed, the time scrubber, the frame counter and time.
// Playback follows the recording's clock: at speed 1 a recording with a frame interval of 1/30 s shows 30
// frames per second of wall time, whatever the display's refresh rate. A frame the renderer could not keep
// up with is skipped, not slowed down (up to stalls of 0.25 s). Test and measurement hooks: window.scree
// (see the end of the file).
"use strict";

(() => {
  const $ = (id) => document.getElementById(id);

  function showError(message) {
    $("loading").style.display = "none";
    const e = $("error");
    e.textContent = message;
    e.style.display = "block";
    window.scree = { error: message, ready: false };
  }

  class Orbit {
    constructor(camera, el, onChange) {
      this.camera = camera;
      this.target = new THREE.Vector3();
      this.distance = 10;
      this.azimuth = -Math.PI / 3;  // around z, from +x
      this.elevation = 0.35;  // above the x-y plane (rad)
      this.onChange = onChange;
      let drag = null;
      el.addEventListener("contextmenu", (e) => e.preventDefault());
      el.addEventListener("pointerdown", (e) => {
        drag = { x: e.clientX, y: e.clientY, pan: e.button === 2 || e.shiftKey };
        el.setPointerCapture(e.pointerId);
      });
      el.addEventListener("pointerup", (e) => { drag = null; el.releasePointerCapture(e.pointerId); });
      el.addEventListener("pointermove", (e) => {
        if (!drag) return;
        const dx = e.clientX - drag.x, dy = e.clientY - drag.y;
        drag.x = e.clientX; drag.y = e.clientY;
        if (drag.pan) {
          const s = this.distance * 0.0015;
          const right = new THREE.Vector3().setFromMatrixColumn(camera.matrix, 0);
          const up = new THREE.Vector3().setFromMatrixColumn(camera.matrix, 1);
          this.target.addScaledVector(right, -dx * s).addScaledVector(up, dy * s);
        } else {
          this.azimuth -= dx * 0.006;
          this.elevation = Math.min(1.55, Math.max(-1.55, this.elevation + dy * 0.006));
        }
        this.update();
      });
      el.addEventListener("wheel", (e) => {
        e.preventDefault();
        this.distance *= Math.exp(e.deltaY * 0.001);
        this.update();
      }, { passive: false });
    }
    frame(box) {
      const c = box.getCenter(new THREE.Vector3()), r = Math.max(0.1, box.getSize(new THREE.Vector3()).length() / 2);
      this.target.copy(c);
      this.distance = r / Math.sin((this.camera.fov * Math.PI) / 360) * 1.05;
      this.camera.near = this.distance / 1000;
      this.camera.far = this.distance * 100;
      this.camera.updateProjectionMatrix();
      this.update();
    }
    update() {
      const ce = Math.cos(this.elevation);
      this.camera.position.set(
        this.target.x + this.distance * ce * Math.cos(this.azimuth),
        this.target.y + this.distance * ce * Math.sin(this.azimuth),
        this.target.z + this.distance * Math.sin(this.elevation));
      this.camera.lookAt(this.target);
      this.camera.updateMatrixWorld();
      if (this.onChange) this.onChange();
    }
  }

  function decodeBase64(text) {
    text = text.trim();
    if (Uint8Array.fromBase64) return Promise.resolve(Uint8Array.fromBase64(text));
    return fetch("data:application/octet-stream;base64," + text).then((r) => r.arrayBuffer()).then((b) => new Uint8Array(b));
  }

  async function main() {
    const title = document.title.replace(/^Scree replay: /, "");
    const text = $("scree-recording").textContent;
    if (text.startsWith("@@")) throw new Error("this is the page template: no recording was embedded (use scree view FILE)");
    const t0 = performance.now();
    const bytes = await decodeBase64(text);
    const base64Ms = performance.now() - t0;
    const rec = await ScreeRecording.parse(bytes, title, (p) => {
      $("loading").textContent = `Decoding frames: ${Math.round(100 * p)}%`;
    });
    $("loading").style.display = "none";

    const view = $("view");
    const s = new ScreeScene.Scene(rec, view);
    const n = rec.frames.length;
    $("scene-name").textContent = rec.scene.name || title;
    $("counts").textContent = `${rec.scene.bodies.length} bodies, up to ${rec.maxParticles} particles ` +
      `(drawn as ${s.particleMode === "points" ? "sprites" : "meshes"}), ${n} frames`;
    $("frames").textContent = n - 1;
    $("speed-max").textContent = rec.maxSpeed.toPrecision(3);
    const lg = $("legend").getContext("2d");
    for (let i = 0; i < 120; ++i) {
      const c = ScreeScene.rampRgb(i / 119);
      lg.fillStyle = `rgb(${c[0]},${c[1]},${c[2]})`;
      lg.fillRect(i, 0, 1, 10);
    }
    const scrub = $("scrub");
    scrub.max = n - 1;

    const t0rec = rec.frames[0].time;
    const duration = rec.frames[n - 1].time - t0rec;
    const state = { playing: true, rate: 1, clock: 0, frame: 0, lastWall: null, dirty: true, refresh: true };
    // The frame shown at recording time t (from the first frame): the last one at or before t.
    const frameAt = (t) => {
      let lo = 0, hi = n - 1;
      while (lo < hi) {
        const mid = (lo + hi + 1) >> 1;
        if (rec.frames[mid].time - t0rec <= t + 1e-9) lo = mid; else hi = mid - 1;
      }
      return lo;
    };
    const orbit = new Orbit(s.camera, s.renderer.domElement, () => { state.dirty = true; });
    orbit.frame(s.viewBounds());  // leaves frame 0 shown
    s.showFrame(0, true);

    const playButton = $("play");
    const setPlaying = (on) => {
      state.playing = on;
      state.lastWall = null;
      playButton.textContent = on ? "Pause" : "Play";
    };
    playButton.addEventListener("click", () => setPlaying(!state.playing));
    window.addEventListener("keydown", (e) => { if (e.code === "Space") { e.preventDefault(); setPlaying(!state.playing); } });
    // `?t=SECONDS` opens the page paused at that recording time (links to a moment, screenshots).
    const startAt = parseFloat(new URLSearchParams(window.location.search).get("t"));
    if (Number.isFinite(startAt)) {
      state.frame = frameAt(Math.max(0, startAt));
      state.clock = rec.frames[state.frame].time - t0rec;
      setPlaying(false);
      state.dirty = true;
    }
    $("rate").addEventListener("change", (e) => { state.rate = parseFloat(e.target.value); });
    scrub.addEventListener("input", () => {
      state.frame = parseInt(scrub.value, 10);
      state.clock = rec.frames[state.frame].time - t0rec;
      state.dirty = true;
    });
    $("contacts").addEventListener("change", () => { state.dirty = true; state.refresh = true; });
    $("colour").addEventListener("change", (e) => { s.colourBy = e.target.value; state.dirty = true; state.refresh = true; });
    window.addEventListener("resize", () => { s.resize(view.clientWidth, view.clientHeight); state.dirty = true; });

    // Measurement: wall time between animation frames and time spent updating + rendering, last 600 frames.
    const stats = { intervals: [], workMs: [], rendered: 0, framesAdvanced: 0, clockTickMs: null };
    const keep = (a, v) => { a.push(v); if (a.length > 600) a.shift(); };
    let lastRaf = null;

    function tick() {
      // performance.now(), not the callback's timestamp: the first animation frame after a long load can
      // carry a begin-frame time from before it, which would jump the clock ahead. A stall of more than
      // 0.25 s advances the recording by 0.25 s (playback slows down rather than jumping).
      const now = performance.now();
      if (lastRaf !== null) keep(stats.intervals, now - lastRaf);
      lastRaf = now;
      const w0 = now;
      if (state.playing) {
        if (state.lastWall !== null) {
          state.clock += (Math.min(250, now - state.lastWall) / 1000) * state.rate;
          if (state.clock > duration + rec.scene.frameInterval) state.clock = 0;  // loop
        }
        state.lastWall = now;
        stats.clockTickMs = now;  // the page time at which framesAdvanced was last brought up to date
        const k = frameAt(state.clock);
        if (k !== state.frame) { stats.framesAdvanced += (k - state.frame + n) % n; state.frame = k; state.dirty = true; }
      }
      if (state.dirty) {
        if (s.shownFrame !== state.frame || state.refresh) s.showFrame(state.frame, $("contacts").checked);
        $("frame").textContent = state.frame;
        $("time").textContent = rec.frames[state.frame].time.toFixed(3);
        if (document.activeElement !== scrub) scrub.value = state.frame;
        s.render();
        stats.rendered++;
        state.dirty = false;
        state.refresh = false;
        keep(stats.workMs, performance.now() - w0);
      }
      requestAnimationFrame(tick);
    }
    requestAnimationFrame(tick);

    // Hooks for tests and measurements (test/test_viewer_page.py).
    window.scree = {
      ready: true,
      recording: rec,
      view: s,  // the ScreeScene.Scene (three.js objects), for experiments from the console
      stats,
      timings: { base64Ms, parseMs: rec.parseMs, decodeMs: rec.decodeMs, bytes: bytes.length },
      get frame() { return state.frame; },
      get clock() { return state.clock; },  // recording time played (s), from the first frame
      play() { setPlaying(true); },
      pause() { setPlaying(false); },
      project: (x, y, z) => s.project(x, y, z),
      // Position of body b in the shown frame.
      bodyPosition(b) { const p = rec.frames[state.frame].poses; return [p[7 * b], p[7 * b + 1], p[7 * b + 2]]; },
      bodyIndex(name) { return rec.scene.bodies.findIndex((b) => b.name === name); },
      // Draws the shown frame now (after pause(), so a screenshot shows what the hooks report).
      renderNow() { s.showFrame(state.frame, $("contacts").checked); s.render(); },
    };
  }

  window.addEventListener("load", () => {
    main().catch((e) => {
      // A file the reader refuses is the page's expected output, not a page error: shown, not thrown.
      showError(e instanceof ScreeRecording.FormatError ? e.message : `The replay page failed: ${e.message}`);
      if (!(e instanceof ScreeRecording.FormatError)) console.error(e);
    });
  });
})();
