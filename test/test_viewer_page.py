#!/usr/bin/python3
# SPDX-License-Identifier: MIT
# Copyright (c) 2026 The Scree authors
"""The replay page (scree/io/viewer_page.h) in headless Chromium, driven over the DevTools protocol.

  test_viewer_page.py --view-page BUILD/model/io/viewer/scree_view_page --chromium /usr/bin/chromium
                      [--workdir DIR] [--screenshot OUT.png] [--perf PARTICLES FRAMES]

1. Writes a 60-frame tower10 recording with test/make_test_recording.py (an implementation of
   docs/recording.md independent of the C++ writer) and turns it into a page with scree_view_page (the C++
   embedding, scree::io::writeViewerPage).
2. Loads the page and asserts: it reads the recording; the frame counter (#frame and the page's state)
   advances over 1 s of wall time; the page's decoded box positions are the ones the generator wrote (to
   1e-12 m: the poses are float64 and round-trip exactly); the screenshot is not blank (many colours); the
   pixels at the projected centres of the bottom, middle and top boxes have the boxes' orange hue, and the
   pixels 1 m above the top box and 2 m beside the tower (projected the same way) do not; the console has no
   errors and no exception was thrown.
3. The scrubber shows the frame asked for, and the terrain's heights (rectangles applied forward and
   replayed back) are the recorded ones.
4. With ?particles=points (the sprite renderer) the page runs without console errors.
5. Corrupted files (a flipped byte, a newer major version, a truncated file) each show their message in the
   page (#error) instead of a scene.
With --perf: writes a PARTICLES x FRAMES recording of moving particles, loads it and prints the decode time
and the frame rate (requestAnimationFrame intervals while playing) instead of the checks.
Only the Python standard library and PIL (python3-pil). Exit status 0 when every check passes.
"""
import argparse
import base64
import http.client
import io
import json
import os
import shutil
import socket
import struct
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import make_test_recording as mtr  # noqa: E402

WIDTH, HEIGHT = 1024, 768
FAILURES = []


def check(cond, what):
    print(("ok:   " if cond else "FAIL: ") + what, flush=True)
    if not cond:
        FAILURES.append(what)


class WebSocket:
    """Just enough of RFC 6455 for the DevTools protocol: masked text frames out, any frames in."""

    def __init__(self, url):
        assert url.startswith("ws://")
        hostport, path = url[5:].split("/", 1)
        host, port = hostport.split(":")
        self.sock = socket.create_connection((host, int(port)), timeout=60)
        key = base64.b64encode(os.urandom(16)).decode()
        req = (f"GET /{path} HTTP/1.1\r\nHost: {hostport}\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
               f"Sec-WebSocket-Key: {key}\r\nSec-WebSocket-Version: 13\r\n\r\n")
        self.sock.sendall(req.encode())
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise RuntimeError("websocket handshake: connection closed")
            head += chunk
        head, self.buf = head.split(b"\r\n\r\n", 1)
        if b" 101 " not in head.split(b"\r\n")[0]:
            raise RuntimeError("websocket handshake refused: " + head.decode(errors="replace"))

    def send(self, text):
        data = text.encode()
        n = len(data)
        hdr = bytes([0x81])
        if n < 126:
            hdr += bytes([0x80 | n])
        elif n < 65536:
            hdr += bytes([0x80 | 126]) + struct.pack(">H", n)
        else:
            hdr += bytes([0x80 | 127]) + struct.pack(">Q", n)
        mask = os.urandom(4)
        self.sock.sendall(hdr + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))

    def _read(self, n):
        while len(self.buf) < n:
            chunk = self.sock.recv(1 << 20)
            if not chunk:
                raise RuntimeError("websocket closed")
            self.buf += chunk
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def recv(self):
        message = b""
        while True:
            b0, b1 = self._read(2)
            n = b1 & 0x7F
            if n == 126:
                n = struct.unpack(">H", self._read(2))[0]
            elif n == 127:
                n = struct.unpack(">Q", self._read(8))[0]
            payload = self._read(n)
            opcode = b0 & 0x0F
            if opcode in (0x1, 0x0, 0x2):
                message += payload
                if b0 & 0x80:
                    return message.decode()
            elif opcode == 0x8:
                raise RuntimeError("websocket closed by the browser")


class Page:
    """One page target: commands by id, events collected as they come."""

    def __init__(self, ws_url):
        self.ws = WebSocket(ws_url)
        self.next_id = 0
        self.events = []

    def call(self, method, **params):
        self.next_id += 1
        mid = self.next_id
        self.ws.send(json.dumps({"id": mid, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv())
            if msg.get("id") == mid:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                return msg["result"]
            if "method" in msg:
                self.events.append(msg)

    def eval(self, expr):
        r = self.call("Runtime.evaluate", expression=expr, returnByValue=True, awaitPromise=True)
        if "exceptionDetails" in r:
            raise RuntimeError(f"evaluating {expr}: {r['exceptionDetails']}")
        return r["result"].get("value")

    def console_errors(self):
        errs = []
        for e in self.events:
            m, p = e["method"], e.get("params", {})
            if m == "Runtime.exceptionThrown":
                errs.append("exception: " + json.dumps(p.get("exceptionDetails", {}))[:400])
            elif m == "Runtime.consoleAPICalled" and p.get("type") in ("error", "assert"):
                errs.append("console." + p["type"] + ": " + json.dumps(p.get("args", []))[:400])
            elif m == "Log.entryAdded" and p.get("entry", {}).get("level") == "error":
                errs.append("log: " + p["entry"].get("text", "")[:400])
        return errs


class Browser:
    def __init__(self, chromium, workdir):
        self.profile = tempfile.mkdtemp(prefix="chromium-", dir=workdir)
        args = [chromium, "--headless", "--no-sandbox", "--use-gl=angle", "--use-angle=swiftshader",
                "--enable-unsafe-swiftshader", "--no-first-run", "--no-default-browser-check", "--mute-audio",
                "--hide-scrollbars", f"--window-size={WIDTH},{HEIGHT}", "--remote-debugging-port=0",
                f"--user-data-dir={self.profile}", "about:blank"]
        self.proc = subprocess.Popen(args, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        port_file = os.path.join(self.profile, "DevToolsActivePort")
        for _ in range(300):
            if os.path.exists(port_file) and open(port_file).read().strip().count("\n") >= 1:
                break
            time.sleep(0.1)
        else:
            self.close()
            raise RuntimeError("chromium did not open its DevTools port")
        self.port = int(open(port_file).read().split("\n")[0])

    def page(self):
        conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=30)
        conn.request("GET", "/json/list")
        targets = json.loads(conn.getresponse().read())
        page = next(t for t in targets if t["type"] == "page")
        p = Page(page["webSocketDebuggerUrl"])
        for domain in ("Runtime", "Log", "Page"):
            p.call(domain + ".enable")
        return p

    def close(self):
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        shutil.rmtree(self.profile, ignore_errors=True)


def open_page(browser, html, timeout=60, query=""):
    """Navigates to the page and waits until it has read its recording (or reported an error)."""
    p = browser.page()
    p.call("Page.navigate", url="file://" + os.path.abspath(html) + query)
    t0 = time.time()
    while time.time() - t0 < timeout:
        state = p.eval("window.scree ? {ready: window.scree.ready, error: window.scree.error || null} : null")
        if state and (state["ready"] or state["error"]):
            return p, state
        time.sleep(0.1)
    raise RuntimeError(f"{html}: the page did not finish loading in {timeout} s")


def make_page(view_page, rec_bytes, workdir, name):
    rec = os.path.join(workdir, name + ".screerec")
    html = os.path.join(workdir, name + ".html")
    with open(rec, "wb") as f:
        f.write(rec_bytes)
    subprocess.run([view_page, rec, html], check=True)
    return html


def is_orange(px):
    r, g, b = px[:3]
    return r > g + 20 and g > b and r - b > 60  # the boxes' (230, 120, 40), lit anywhere from dark to bright


def is_background(px):
    return all(abs(a - b) <= 8 for a, b in zip(px[:3], (0x1E, 0x22, 0x28)))


def run_checks(args, browser):
    from PIL import Image

    frames = 60
    html = make_page(args.view_page, mtr.tower10(frames), args.workdir, "tower10")
    page, state = open_page(browser, html)
    check(state["ready"] and not state["error"], f"the page reads the tower10 recording (error: {state['error']})")
    if not state["ready"]:
        return
    n = page.eval("window.scree.recording.frames.length")
    check(n == frames, f"the page decoded {n} frames (the file has {frames})")
    # The page plays on the recording's clock (30 frames/s at speed 1, looping after the last frame), counting
    # the frames it advances (stats.framesAdvanced, wraps included) and stamping the page time of the animation
    # frame that last brought the count up to date (stats.clockTickMs). Between two such stamps t0 < t1 it advances
    # at least 1 frame (over a second) and at most 30 (t1 - t0) + 1: its clock cannot run ahead of the page's
    # own. The bound uses the page's stamps, not the test's wall clock: on a loaded machine an animation frame can
    # be late, so the count read at the start may lag the wall clock by up to the page's 0.25 s stall cap and then
    # catch up (seen in CI under the sanitizers: 37 frames in 1.01 s of test wall time). Chromium can also miss
    # animation frames for a while, so after the first second the test waits up to 10 s more before calling the
    # counter stuck.
    read = "[window.scree.stats.framesAdvanced, window.scree.stats.clockTickMs]"
    w0 = time.time()
    a0, t0 = page.eval(read)
    time.sleep(1.0)
    a1, t1 = page.eval(read)
    while a1 == a0 and time.time() - w0 < 11.0:
        time.sleep(0.2)
        a1, t1 = page.eval(read)
    adv = a1 - a0
    span = (t1 - t0) / 1000.0 if t0 is not None and t1 is not None else float("nan")
    check(adv >= 1 and adv <= 30 * span + 1,
          f"the frame counter advances while playing: {adv} frames in {span:.3f} s of page time "
          f"({time.time() - w0:.2f} s of test wall time)")
    fnow, shown = page.eval("[window.scree.frame, document.getElementById('frame').textContent]")
    check(shown.strip() == str(fnow), f"#frame shows the page's frame ({shown}, page state {fnow})")
    # Freeze the frame, draw it, then read positions and the screenshot of the same frame.
    page.eval("window.scree.pause(); window.scree.renderNow(); true")
    frame = page.eval("window.scree.frame")
    boxes = []
    for k in (0, 5, 9):
        b = page.eval(f"window.scree.bodyIndex('box{k}')")
        pos = page.eval(f"window.scree.bodyPosition({b})")
        want = mtr.tower_box_z(k, frame)
        check(abs(pos[2] - want) < 1e-12 and abs(pos[0]) < 1e-12 and abs(pos[1]) < 1e-12,
              f"box{k} at frame {frame}: page z = {pos[2]!r}, the generator wrote {want!r}")
        boxes.append((k, pos))
    shot = page.call("Page.captureScreenshot", format="png")
    img = Image.open(io.BytesIO(base64.b64decode(shot["data"]))).convert("RGB")
    if args.screenshot:
        img.save(args.screenshot)
    ncolours = len(img.getcolors(1 << 20) or [])
    check(ncolours > 200, f"the screenshot is not blank: {ncolours} distinct colours")
    inner = page.eval("[window.innerWidth, window.innerHeight, window.devicePixelRatio]")
    scale = inner[2]
    want_size = (round(inner[0] * scale), round(inner[1] * scale))
    check(img.size == want_size, f"the screenshot is the viewport: {img.size} pixels (viewport {want_size})")

    def pixel_at(x, y, z):
        q = page.eval(f"window.scree.project({x}, {y}, {z})")
        u, v = int(round(q["x"] * scale)), int(round(q["y"] * scale))
        return (u, v), (img.getpixel((u, v)) if 0 <= u < img.size[0] and 0 <= v < img.size[1] else None)

    top = None
    for k, pos in boxes:
        (u, v), px = pixel_at(*pos)
        check(px is not None and is_orange(px), f"box{k}'s projected centre ({u}, {v}) is the box's colour: {px}")
        top = pos
    (u, v), px = pixel_at(top[0], top[1], top[2] + 1.0)
    check(px is not None and is_background(px), f"1 m above the top box ({u}, {v}) is background: {px}")
    (u, v), px = pixel_at(top[0] + 2.0, top[1] + 2.0, top[2] - 2.0)
    check(px is not None and not is_orange(px), f"2 m beside the tower ({u}, {v}) is not the boxes' colour: {px}")
    errs = page.console_errors()
    check(not errs, "no console errors or exceptions" + ("".join("\n      " + e for e in errs)))

    # The scrubber: moving it shows that frame, and the terrain mesh then holds the heights the generator
    # wrote up to that frame (float32, exact), forward (rectangles applied in order) and back (replayed from
    # the initial heights).
    for target in (37, 12, 55):
        got = page.eval(f"""(() => {{ const s = document.getElementById('scrub'); s.value = {target};
            s.dispatchEvent(new Event('input')); window.scree.renderNow();
            const z = Array.from(window.scree.view.terrains[0].geo.attributes.position.array).filter((_, i) => i % 3 == 2);
            return [window.scree.frame, z]; }})()""")
        want = mtr.terrain_heights(target)
        check(got[0] == target and got[1] == want,
              f"scrubbing to frame {target}: the terrain holds the recorded heights (frame {got[0]}, "
              f"{sum(a != b for a, b in zip(got[1], want))} of {len(want)} vertices differ)")

    # The other particle renderer (sphere sprites, the software-GL default above 2000 particles): its shaders
    # compile and it draws the same frame without errors.
    page, state = open_page(browser, os.path.join(args.workdir, "tower10.html"), query="?particles=points")
    time.sleep(0.5)
    mode = page.eval("window.scree.ready && window.scree.view.particleMode")
    errs = page.console_errors()
    check(mode == "points" and not errs, f"?particles=points draws sprites ({mode}) without console errors"
          + "".join("\n      " + e for e in errs))

    # Files the reader refuses: the page says why.
    base = mtr.tower10(frames)
    b = bytearray(base)
    first = base.find(b"FRAM")
    third = base.find(b"FRAM", base.find(b"FRAM", first + 8) + 8)
    b[third + 20] ^= 0x55
    cases = [("crc", bytes(b), "CRC-32 mismatch in chunk"),
             ("version", mtr.header(mtr.MAJOR + 1, 3) + base[16:], "was written in recording format 2.3; this reader reads 1.x"),
             ("truncated", base[: len(base) * 2 // 3], "truncated")]
    for name, data, want in cases:
        html = make_page(args.view_page, data, args.workdir, "bad_" + name)
        page, state = open_page(browser, html)
        msg = page.eval("document.getElementById('error').textContent")
        visible = page.eval("getComputedStyle(document.getElementById('error')).display")
        check(not state["ready"] and want in msg and visible == "block", f"{name}: the page shows \"{msg}\"")


def process_cpu_seconds(root_pid):
    """CPU seconds (user + system) used so far by each process type ('gpu-process', 'renderer', 'browser')
    under chromium's process root_pid (Linux /proc)."""
    parents, kinds, ticks = {}, {}, {}
    for d in os.listdir("/proc"):
        if not d.isdigit():
            continue
        try:
            stat = open(f"/proc/{d}/stat").read()
            cmd = open(f"/proc/{d}/cmdline").read().replace("\0", " ").split()
        except OSError:
            continue
        fields = stat[stat.rfind(")") + 2:].split()
        pid = int(d)
        parents[pid] = int(fields[1])
        ticks[pid] = int(fields[11]) + int(fields[12])
        kind = next((a[7:] for a in cmd if a.startswith("--type=")), "browser")
        kinds[pid] = kind
    out = {}
    for pid in ticks:
        p = pid
        while p in parents and p != root_pid and p > 1:
            p = parents[p]
        if p == root_pid:
            out[kinds[pid]] = out.get(kinds[pid], 0) + ticks[pid] / os.sysconf("SC_CLK_TCK")
    return out


def run_perf(args, browser):
    nparticles, nframes = args.perf
    t0 = time.time()
    data = mtr.perf(nframes, nparticles)
    print(f"recording: {nparticles} particles x {nframes} frames, {len(data) / 1e6:.1f} MB, "
          f"written in {time.time() - t0:.1f} s")
    html = make_page(args.view_page, data, args.workdir, "perf")
    print(f"page: {os.path.getsize(html) / 1e6:.1f} MB")
    t0 = time.time()
    page, state = open_page(browser, html, timeout=600, query=args.query)
    load = time.time() - t0
    if not state["ready"]:
        check(False, "perf page loads: " + str(state["error"]))
        return
    tm = page.eval("window.scree.timings")
    print(f"load {load:.1f} s wall: base64 {tm['base64Ms']:.0f} ms, chunks+CRC {tm['parseMs']:.0f} ms, "
          f"inflate+delta {tm['decodeMs']:.0f} ms")
    page.eval("window.scree.stats.intervals.length = 0; window.scree.stats.workMs.length = 0; "
              "window.scree.stats.framesAdvanced = 0; true")
    f0 = page.eval("window.scree.frame")
    cpu0 = process_cpu_seconds(browser.proc.pid)
    time.sleep(args.seconds)
    st = page.eval("window.scree.stats")
    cpu1 = process_cpu_seconds(browser.proc.pid)
    iv = sorted(st["intervals"])
    wk = sorted(st["workMs"])
    med = iv[len(iv) // 2]
    mean = sum(iv) / len(iv)
    print(f"animation frames: {len(iv)} intervals, median {med:.1f} ms ({1000 / med:.1f} fps), "
          f"mean {mean:.1f} ms ({1000 / mean:.1f} fps), 90th percentile {iv[int(0.9 * len(iv))]:.1f} ms")
    print(f"update+render per drawn frame: median {wk[len(wk) // 2]:.1f} ms, "
          f"90th percentile {wk[int(0.9 * len(wk))]:.1f} ms; recording frames advanced in {args.seconds:g} s: "
          f"{st['framesAdvanced']} (from frame {f0})")
    drawn = max(1, len(iv))
    print("CPU time per drawn frame (software GL runs in the gpu-process): " + ", ".join(
        f"{k} {1000 * (cpu1.get(k, 0) - cpu0.get(k, 0)) / drawn:.0f} ms" for k in sorted(cpu1)))
    print(f"load average during the run: {open('/proc/loadavg').read().split()[0]} on {os.cpu_count()} cores")
    errs = page.console_errors()
    check(not errs, "no console errors" + "".join("\n      " + e for e in errs))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--view-page", required=True)
    ap.add_argument("--chromium", default="/usr/bin/chromium")
    ap.add_argument("--workdir", default=None)
    ap.add_argument("--screenshot", default=None)
    ap.add_argument("--perf", type=int, nargs=2, metavar=("PARTICLES", "FRAMES"))
    ap.add_argument("--query", default="", help="appended to the page's URL with --perf (e.g. ?aa=1)")
    ap.add_argument("--seconds", type=float, default=10.0, help="playing time measured with --perf")
    args = ap.parse_args()
    own = args.workdir is None
    args.workdir = args.workdir or tempfile.mkdtemp(prefix="scree-viewer-")
    os.makedirs(args.workdir, exist_ok=True)
    browser = Browser(args.chromium, args.workdir)
    try:
        run_perf(args, browser) if args.perf else run_checks(args, browser)
    finally:
        browser.close()
        if own:
            shutil.rmtree(args.workdir, ignore_errors=True)
    if FAILURES:
        print(f"{len(FAILURES)} check(s) failed")
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
