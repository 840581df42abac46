#!/usr/bin/env python3
"""Peer phaseless Butterworth low-pass from SciPy, for `impact analyze --lowpass ORDER,CUTOFF`.

`scipy.signal.butter(order, cutoff, fs=rate, output='sos')` run forward and backward by
`scipy.signal.sosfiltfilt`, twice: with `padtype=None` (each pass starts at rest on its
first value, `sosfilt_zi` times that value: the core's scheme, `core/src/signal/lowpass.rs`)
and with SciPy's defaults (`padtype='odd'`, `padlen = 3 (2 len(sos) + 1 - ...)`), which
differ from it only near the ends. On:

* `half-sine`: 107 140 m/s² (10 925 g) for 100 us at 1 MS/s (samples 4000..4100 of 8000),
  zeros around it: the AFRL drop tower's pulse, which CFC 1000 turns into 3 118 g;
* `noisy`: the same plus uniform noise of +-2 % of its peak from a 64-bit LCG
  (`x = 6364136223846793005 x + 1442695040888963407 mod 2^64`, seed 46, `u = (x >> 11) / 2^53`,
  noise `0.04 A (u - 0.5)`), which `host-tests/tests/lowpass_peer.rs` draws the same way;

each at orders 2, 3, 4 and cut-offs 1, 10, 100 kHz, and order 8 at 10 kHz; and

* `afrl-test1`: the AFRL drop tower's series 1 test 1 (bottom channel, kgn x 9806.65, the
  whole 100 ms record at 1 MS/s) with the default padding, at orders 2 and 4 at 1 kHz and
  order 3 at 5 kHz: the filtered peak (sample, value) `impact analyze --lowpass` reports.

`host-tests/tests/lowpass_peer.rs` compares the core's filter and the tool with the stored
output; CI never runs this script (no network there).

Rerun (needs the network once):

    python3 -m venv /tmp/lp-venv && /tmp/lp-venv/bin/pip install numpy==2.4.6 scipy==1.17.1
    /tmp/lp-venv/bin/python scripts/peer_lowpass.py > scripts/peer_lowpass.csv

Output: CSV `case,order,cutoff_hz,sample,none,odd` after `#` lines naming the versions and
the date: for the synthetic cases every 50th sample and, as `sample` `peak:N`, the largest
|value| of the `none` run at sample N; for `afrl-test1` only its `peak:N` row (`none`
empty: the whole record has no sensible rest at its first sample to compare with).
"""

import datetime
import os

import numpy as np
import scipy
import scipy.signal as sig

KGN = 9806.65
HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.normpath(os.path.join(HERE, "..", "host-tests", "data"))
RATE = 1e6
N = 8000
START, WIDTH = 4000, 100
PEAK = 107140.0
EVERY = 50


def lcg_uniform(seed, n):
    x = seed
    out = np.empty(n)
    for i in range(n):
        x = (6364136223846793005 * x + 1442695040888963407) % 2**64
        out[i] = (x >> 11) / 2.0**53
    return out


def half_sine():
    a = np.zeros(N)
    i = np.arange(START, START + WIDTH + 1)
    a[i] = PEAK * np.sin(np.pi * (i - START) / WIDTH)
    return a


def noisy():
    return half_sine() + 0.04 * PEAK * (lcg_uniform(46, N) - 0.5)


def filtered(x, order, cutoff, padtype):
    sos = sig.butter(order, cutoff, fs=RATE, output="sos")
    if padtype is None:
        return sig.sosfiltfilt(sos, x, padtype=None)
    return sig.sosfiltfilt(sos, x)


def main():
    print(
        f"# scripts/peer_lowpass.py, {datetime.date.today()}: numpy {np.__version__}, "
        f"scipy {scipy.__version__}"
    )
    print("case,order,cutoff_hz,sample,none,odd")
    cases = [(o, c) for o in (2, 3, 4) for c in (1000.0, 10000.0, 100000.0)]
    cases.append((8, 10000.0))
    for name, x in (("half-sine", half_sine()), ("noisy", noisy())):
        for order, cutoff in cases:
            none = filtered(x, order, cutoff, None)
            odd = filtered(x, order, cutoff, "odd")
            for i in range(0, N, EVERY):
                print(f"{name},{order},{cutoff!r},{i},{float(none[i])!r},{float(odd[i])!r}")
            k = int(np.argmax(np.abs(none)))
            print(f"{name},{order},{cutoff!r},peak:{k},{float(none[k])!r},{float(odd[k])!r}")
    path = os.path.join(DATA, "afrl-drop-tower", "series1_test1_full_100ms.csv")
    rec = np.genfromtxt(path, delimiter=",", names=True)
    a = rec["bottom_kgn"] * KGN
    for order, cutoff in ((2, 1000.0), (4, 1000.0), (3, 5000.0)):
        odd = sig.sosfiltfilt(sig.butter(order, cutoff, fs=RATE, output="sos"), a)
        k = int(np.argmax(np.abs(odd)))
        print(f"afrl-test1,{order},{cutoff!r},peak:{k},,{float(odd[k])!r}")


if __name__ == "__main__":
    main()
