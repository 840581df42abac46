#!/usr/bin/env python3
"""docs/watch.png: `impact watch` during a session, as an engineer at the bench sees it.

Sixteen drops of a 60 g body on a stiff pad (`impact synth`, 0.84-0.96 m/s and one at
1.25 m/s), each 0.25 s apart, run on the emulated board in real time with its windows and a
110 g / 2.45 ms half-sine specification; the board's log is then replayed into `impact
watch` at the pace it was written, and headless Chromium photographs the page about 3.5 s in,
while the board is live.

    scripts/watch_screenshot.py [OUT.png]   (needs target/release/impact or $IMPACT, QEMU, chromium)
"""
import math
import os
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
IMPACT = os.environ.get("IMPACT", os.path.join(ROOT, "target", "release", "impact"))
SPEC = "half-sine,110g,2.45ms"


def main():
    out = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "docs", "watch.png"))
    work = tempfile.mkdtemp(prefix="watch-shot-")
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
    subprocess.run([IMPACT, "emulate", day, "--realtime", "--mass", "0.06", "--v0", "0.9",
                    "--waveforms", "8", "--spec", SPEC, "--log", log, "--json"],
                   check=True, capture_output=True)
    lines = [l for l in open(log).read().splitlines() if " summary " not in l]
    watch = subprocess.Popen([IMPACT, "watch", "--spec", SPEC, "--listen", "127.0.0.1:0",
                              "--session", os.path.join(work, "session.log")],
                             stdin=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    addr = watch.stderr.readline().split("http://")[1].split("/")[0]
    threading.Thread(target=lambda: watch.stderr.read(), daemon=True).start()
    start = time.monotonic()
    shot = None
    for line in lines:
        try:
            t = float(line.split()[0])
        except (ValueError, IndexError):
            t = 0.0
        while time.monotonic() - start < t:
            time.sleep(0.005)
        if shot is None and t > 2.0:
            shot = subprocess.Popen(["chromium", "--headless", "--no-sandbox", "--disable-gpu", "--hide-scrollbars",
                                     "--window-size=1400,1000", f"--screenshot={out}", "--timeout=2500",
                                     f"--user-data-dir={os.path.join(work, 'profile')}", f"http://{addr}/"],
                                    stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        watch.stdin.write(line + "\n")
        watch.stdin.flush()
    shot.wait(timeout=60)
    watch.kill()
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
