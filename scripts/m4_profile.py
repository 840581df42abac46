#!/usr/bin/env python3
"""Where the M4's instructions go: a per-function profile of one `impact bench m4` job.

Runs the m4-bench firmware under QEMU (mps2-an386, `-icount shift=0`) on the seed bench
impact (the recording `impact bench m4` uses), logging every executed translation block
(`-d in_asm,exec,nochain`), and prints the instructions per function, the scene's job minus a
baseline job (the same stream without the stage asked for). Example, the board's spectra:

    scripts/m4_profile.py "two_phase=0 nonlinear=0 hertz=0 srs=1"

Needs qemu-system-arm and arm-none-eabi-nm (binutils-arm-none-eabi); the log is large
(~270 MB for the spectra) and goes to a temporary directory.
"""
import bisect
import collections
import os
import re
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BASE = "two_phase=0 nonlinear=0 hertz=0"


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, cwd=ROOT, **kw)


def profile(elf, samples, scene, tmp):
    jobs = os.path.join(tmp, "jobs.txt")
    with open(jobs, "w") as f:
        f.write(f"scene {scene}\nstream job\n")
    log = os.path.join(tmp, "exec.log")
    run(["qemu-system-arm", "-machine", "mps2-an386", "-cpu", "cortex-m4", "-nographic",
         "-monitor", "none", "-serial", "null", "-semihosting-config",
         f"enable=on,target=native,arg=firmware,arg=count,arg={samples},arg={jobs}",
         "-kernel", elf, "-icount", "shift=0", "-d", "in_asm,exec,nochain", "-D", log],
        stdout=subprocess.DEVNULL)
    size, counts, cur = {}, collections.Counter(), None
    with open(log, errors="replace") as f:
        for line in f:
            if line.startswith("IN:"):
                cur = None
                continue
            m = re.match(r"0x([0-9a-f]{8}):", line)
            if m:
                pc = int(m.group(1), 16)
                if cur is None:
                    cur = pc
                    size[cur] = 0
                size[cur] += 1
                continue
            if line.startswith("Trace"):
                cur = None
                m = re.search(r"\[[0-9a-f]+/([0-9a-f]+)/", line)
                pc = int(m.group(1), 16)
                counts[pc] += size.get(pc, 1)
    os.remove(log)
    return counts


def main():
    scene = sys.argv[1] if len(sys.argv) > 1 else BASE + " srs=1"
    run(["cargo", "build", "--release", "-p", "impact-firmware", "--target",
         "thumbv7em-none-eabihf", "--no-default-features", "--features", "m4-bench",
         "--bin", "m4-bench"])
    elf = os.path.join(ROOT, "target/thumbv7em-none-eabihf/release/m4-bench")
    nm = run(["arm-none-eabi-nm", "-C", "--numeric-sort", elf],
             capture_output=True, text=True).stdout
    syms = []
    for l in nm.splitlines():
        p = l.split(" ", 2)
        if len(p) == 3 and p[1] in "tTwW":
            syms.append((int(p[0], 16) & ~1, p[2]))
    addrs = [a for a, _ in syms]

    def per_function(counts):
        out = collections.Counter()
        for pc, c in counts.items():
            i = bisect.bisect_right(addrs, pc) - 1
            out[syms[i][1] if i >= 0 else "?"] += c
        return out

    with tempfile.TemporaryDirectory() as tmp:
        samples = os.path.join(tmp, "seed.i16")
        synth = ["cargo", "run", "-q", "--release", "-p", "impact-host", "--bin", "impact",
                 "--", "synth", "--law", "two-phase", "--mass", "0.06", "--v0", "1.3357",
                 "--max-deformation", "0.0186", "--kr", "12376", "--permanent", "0.0182",
                 "--damping", "2", "--touch", "0.04", "--duration", "0.12", "--raw", samples]
        run(synth, stdout=subprocess.DEVNULL)
        job = per_function(profile(elf, samples, scene, tmp))
        base = per_function(profile(elf, samples, BASE, tmp))
    diff = {f: job[f] - base.get(f, 0) for f in job}
    total = sum(diff.values())
    print(f"{scene!r} minus {BASE!r}: {total} instructions")
    for f, c in sorted(diff.items(), key=lambda x: -x[1])[:25]:
        if c:
            print(f"{c:>10} {100 * c / max(total, 1):5.1f} %  {f[:110]}")


if __name__ == "__main__":
    main()
