#!/usr/bin/env python3
"""docs/watch.png and docs/watch-bench.png: `impact watch` during a session, as an engineer at
the bench sees it (the page, and its bench view at 1920 x 1080).

Sixteen drops of a 60 g body on a stiff pad (`impact synth`, 0.84-0.96 m/s and one at
1.25 m/s), each 0.25 s apart, run on the emulated board in real time with its windows and a
110 g / 2.45 ms half-sine specification (`impact emulate --log`). The board's log is then
replayed into `impact watch --replay` at the pace it was written, and headless Chromium,
driven over its DevTools protocol, photographs the page once it shows the impact asked for
(a plain `chromium --screenshot` photographs the page before its first update arrives).

    scripts/watch_screenshot.py [OUT_DIR]   (needs target/release/impact or $IMPACT, QEMU, chromium)

The screenshot part works on any `impact watch` page:

    scripts/watch_screenshot.py --url http://127.0.0.1:8017/?bench --after 1 --size 1920,1080 OUT.png

waits for the page's first impact (or --after N: impact N shown), then writes OUT.png.
Standard library only.
"""
import argparse
import base64
import json
import math
import os
import socket
import struct
import subprocess
import sys
import tempfile
import time
import urllib.request

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
IMPACT = os.environ.get("IMPACT", os.path.join(ROOT, "target", "release", "impact"))
SPEC = "half-sine,110g,2.45ms"


class DevTools:
    """A minimal client of Chromium's DevTools protocol over one WebSocket (RFC 6455: text
    frames, client frames masked)."""

    def __init__(self, ws_url):
        host, _, path = ws_url[len("ws://"):].partition("/")
        name, _, port = host.partition(":")
        self.sock = socket.create_connection((name, int(port)), timeout=30)
        key = base64.b64encode(os.urandom(16)).decode()
        self.sock.sendall((f"GET /{path} HTTP/1.1\r\nHost: {host}\r\nUpgrade: websocket\r\n"
                           f"Connection: Upgrade\r\nSec-WebSocket-Key: {key}\r\n"
                           "Sec-WebSocket-Version: 13\r\n\r\n").encode())
        head = b""
        while b"\r\n\r\n" not in head:
            chunk = self.sock.recv(4096)
            if not chunk:
                raise ConnectionError("DevTools closed the connection")
            head += chunk
        if b" 101 " not in head.split(b"\r\n")[0]:
            raise ConnectionError(f"DevTools refused the WebSocket: {head[:80]!r}")
        self.buf = head.split(b"\r\n\r\n", 1)[1]
        self.next_id = 0

    def _read(self, n):
        while len(self.buf) < n:
            chunk = self.sock.recv(1 << 16)
            if not chunk:
                raise ConnectionError("DevTools closed the connection")
            self.buf += chunk
        out, self.buf = self.buf[:n], self.buf[n:]
        return out

    def _frame(self):
        b0, b1 = self._read(2)
        n = b1 & 0x7F
        if n == 126:
            n = struct.unpack(">H", self._read(2))[0]
        elif n == 127:
            n = struct.unpack(">Q", self._read(8))[0]
        return b0 & 0x0F, b0 & 0x80, self._read(n)

    def call(self, method, **params):
        self.next_id += 1
        data = json.dumps({"id": self.next_id, "method": method, "params": params}).encode()
        mask = os.urandom(4)
        n = len(data)
        head = bytes([0x81]) + (bytes([0x80 | n]) if n < 126 else
                                bytes([0x80 | 126]) + struct.pack(">H", n) if n < 1 << 16 else
                                bytes([0x80 | 127]) + struct.pack(">Q", n))
        self.sock.sendall(head + mask + bytes(b ^ mask[i % 4] for i, b in enumerate(data)))
        message = b""
        while True:
            op, fin, payload = self._frame()
            if op in (0x1, 0x0):
                message += payload
                if fin:
                    reply = json.loads(message)
                    message = b""
                    if reply.get("id") == self.next_id:
                        if "error" in reply:
                            raise RuntimeError(f"{method}: {reply['error']}")
                        return reply.get("result", {})
            elif op == 0x8:
                raise ConnectionError("DevTools closed the WebSocket")

    def evaluate(self, expression):
        r = self.call("Runtime.evaluate", expression=expression, returnByValue=True)
        return r.get("result", {}).get("value")


def shoot(url, out, size=(1400, 1000), after=0, timeout=60.0):
    """Opens `url` in headless Chromium, waits until the page shows impact `after` (or a
    later one) of its run, lets it draw, and writes the page's screenshot to `out`."""
    profile = tempfile.mkdtemp(prefix="watch-shot-profile-")
    browser = subprocess.Popen(
        ["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
         "--remote-debugging-port=0", f"--window-size={size[0]},{size[1]}",
         f"--user-data-dir={profile}", "about:blank"],
        stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    try:
        port = None
        for line in browser.stderr:
            if "DevTools listening on ws://" in line:
                port = int(line.split("ws://")[1].split("/")[0].rsplit(":", 1)[1])
                break
        if port is None:
            raise RuntimeError("chromium did not open its DevTools port")
        tabs = json.load(urllib.request.urlopen(f"http://127.0.0.1:{port}/json"))
        page = next(t for t in tabs if t.get("type") == "page")
        dt = DevTools(page["webSocketDebuggerUrl"])
        dt.call("Page.navigate", url=url)
        t0 = time.monotonic()
        shown = "(S.last && Number.isFinite(S.last.index) ? S.last.index : -1)"
        while (lambda v: -1 if v is None else v)(dt.evaluate(shown)) < after:
            if time.monotonic() - t0 > timeout:
                raise TimeoutError(f"{url}: impact {after} not shown within {timeout:.0f} s")
            time.sleep(0.05)
        # The page held at that impact (its link closed: no later one arrives; the page says
        # LINK LOST only after 4 s), then the next redraw (200 ms) and the charts' layout.
        dt.evaluate("link.es && link.es.close()")
        time.sleep(0.5)
        png = base64.b64decode(dt.call("Page.captureScreenshot", format="png")["data"])
        with open(out, "wb") as f:
            f.write(png)
    finally:
        browser.kill()
        browser.wait()


def session(work):
    """The sixteen drops emulated in real time: the board's log file."""
    day = os.path.join(work, "day.csv")
    with open(day, "w") as f:
        f.write("time_s,accel_g\n")
        for k in range(16):
            v0 = 1.25 if k == 11 else 0.9 * (1 + 0.07 * math.sin(1.7 * k))
            drop = os.path.join(work, "drop.csv")
            subprocess.run([IMPACT, "synth", "--model", "nonlinear", "--mass", "0.06", "--v0", f"{v0:.4f}",
                            "--stiffness", "1e5", "--damping", "0.5", "--full-scale", "2000",
                            "--duration", "0.25", "--seed", str(k + 1), "-o", drop],
                           check=True, capture_output=True)
            for line in open(drop).read().splitlines()[1:]:
                t, a = line.split(",")
                f.write(f"{float(t) + 0.25 * k:.9f},{a}\n")
    log = os.path.join(work, "day.log")
    subprocess.run([IMPACT, "emulate", day, "--realtime", "--mass", "0.06", "--v0", "0.9", "--v0-every",
                    "--waveforms", "8", "--spec", SPEC, "--log", log, "--json"],
                   capture_output=True)
    if not os.path.exists(log):
        sys.exit("impact emulate made no log")
    # The board still live in the picture: the log without its last line (the summary).
    live = os.path.join(work, "live.log")
    with open(live, "w") as f:
        f.writelines(l for l in open(log) if " summary " not in l)
    return live


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("out", nargs="?", help="output folder (docs/), or the PNG with --url")
    ap.add_argument("--url", help="photograph this impact watch page instead of making the docs' session")
    ap.add_argument("--after", type=int, default=0, help="wait until this impact index is shown (default: the first)")
    ap.add_argument("--size", default="1400,1000", help="window size, W,H")
    a = ap.parse_args()
    size = tuple(int(x) for x in a.size.split(","))
    if a.url:
        out = a.out or "watch.png"
        shoot(a.url, out, size, a.after)
        print(f"wrote {out}")
        return
    out_dir = os.path.abspath(a.out or os.path.join(ROOT, "docs"))
    work = tempfile.mkdtemp(prefix="watch-shot-")
    log = session(work)
    # About 3.5 s into the session: impact 13 (the failed drop, 11, in the trend); the bench
    # view at the failed drop itself.
    for name, query, size, after, speed in [("watch.png", "", (1400, 1000), 13, "1"),
                                            ("watch-bench.png", "?bench", (1920, 1080), 11, "1")]:
        watch = subprocess.Popen([IMPACT, "watch", "--replay", log, "--speed", speed, "--spec", SPEC,
                                  "--listen", "127.0.0.1:0", "--session", os.path.join(work, f"{name}.log")],
                                 stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
        try:
            addr = watch.stderr.readline().split("http://")[1].split("/")[0]
            shoot(f"http://{addr}/{query}", os.path.join(out_dir, name), size, after=after)
        finally:
            watch.kill()
            watch.wait()
    print(f"wrote {out_dir}/watch.png and watch-bench.png")


if __name__ == "__main__":
    main()
