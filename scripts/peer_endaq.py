#!/usr/bin/env python3
"""Peer numbers for the bundled recordings, from enDAQ's Python library and SciPy.

Independent of this repository's code: each recording is read with pandas, its sensor zero
taken as the median of a quiet stretch named below, its impacts found with
`endaq.calc.stats.find_peaks` (enDAQ's shock-event finder), the velocity change integrated
with `endaq.calc.integrate.integrals` over the contact (from 1 % of the peak) and over the
whole lobe (zero crossing to zero crossing), the width at half maximum by linear interpolation of
the two half-maximum crossings around the peak (and where a hammer strike crosses zero after
its peak), and the CFC 1000 peak with an own SAE J211
filter (two-pole Butterworth run forwards and backwards, J211's corner correction, on
SciPy's `lfilter`). `host-tests/tests/recordings.rs` compares `impact analyze` with the
stored output; CI never runs this script (no network there).

Rerun (needs the network once):

    python3 -m venv /tmp/peer && /tmp/peer/bin/pip install endaq==1.5.3
    /tmp/peer/bin/python scripts/peer_endaq.py > scripts/peer_endaq.csv

Output: CSV `case,quantity,value` after `#` lines naming the versions and the date. Units:
m/s² (deceleration positive), s, m/s.
"""

import datetime
import os
import sys

import numpy as np
import pandas as pd
import scipy
import scipy.signal
import endaq
import endaq.calc.integrate
import endaq.calc.stats

G = 9.80665
KGN = 1000.0 * G
HERE = os.path.dirname(os.path.abspath(__file__))
SIGNALS = os.path.normpath(os.path.join(HERE, "..", "host-tests", "data"))


def load(rel, column, scale, skip=1, rate=None):
    """The column in m/s² as a Series indexed by time in seconds."""
    path = os.path.join(SIGNALS, rel)
    df = pd.read_csv(path, skiprows=skip, header=None)
    if skip == 1:
        df.columns = pd.read_csv(path, nrows=0).columns.str.strip()
    x = df[column].to_numpy(dtype=float) * scale
    if rate is None:
        t = df[df.columns[0]].to_numpy(dtype=float)
    else:
        t = np.arange(len(x)) / rate
    return pd.Series(x, index=pd.Index(t, name="time_s"))


def half_width(t, y, i):
    """Width of the pulse through sample i at half its height (y already zeroed)."""
    half = y[i] / 2.0
    sign = np.sign(y[i])
    a = i
    while a > 0 and sign * y[a - 1] > sign * half:
        a -= 1
    b = i
    while b < len(y) - 1 and sign * y[b + 1] > sign * half:
        b += 1
    if a == 0 or b == len(y) - 1:
        return float("nan")

    def cross(j0, j1):
        f = (half - y[j0]) / (y[j1] - y[j0])
        return t[j0] + f * (t[j1] - t[j0])

    return cross(b, b + 1) - cross(a - 1, a)


def j211(y, rate, cls):
    """SAE J211-1 CFC filter: 2-pole Butterworth, forwards and backwards."""
    wd = 2.0 * np.pi * cls * 2.0775
    T = 1.0 / rate
    wa = np.sin(wd * T / 2.0) / np.cos(wd * T / 2.0)
    a0 = wa**2 / (1.0 + np.sqrt(2.0) * wa + wa**2)
    a1 = 2.0 * a0
    a2 = a0
    b1 = -2.0 * (wa**2 - 1.0) / (1.0 + np.sqrt(2.0) * wa + wa**2)
    b2 = (-1.0 + np.sqrt(2.0) * wa - wa**2) / (1.0 + np.sqrt(2.0) * wa + wa**2)
    b = [a0, a1, a2]
    a = [1.0, -b1, -b2]
    fwd = scipy.signal.lfilter(b, a, y)
    return scipy.signal.lfilter(b, a, fwd[::-1])[::-1]


def median_over(s, lo, hi):
    return float(np.median(s[(s.index >= lo) & (s.index < hi)]))


def separation(t, y, i):
    """Where the pulse through sample i first crosses zero after its peak (linear)."""
    sign = np.sign(y[i])
    b = i
    while b < len(y) - 1 and sign * y[b + 1] > 0:
        b += 1
    if b == len(y) - 1:
        return float("nan")
    return t[b] + y[b] / (y[b] - y[b + 1]) * (t[b + 1] - t[b])


def pulse(case, s, zero, time_distance, out, cfc=None, delta_v=False, contact=False):
    """The largest event's peak, time, FWHM (and Δv over its contact), measured from `zero`."""
    t = s.index.to_numpy()
    z = s - zero
    peaks = endaq.calc.stats.find_peaks(z.to_frame(), time_distance=time_distance)
    y = z.to_numpy()
    i = int(peaks[np.argmax(np.abs(y[peaks]))])
    out.append((case, "zero_m_s2", zero))
    out.append((case, "peak_m_s2", y[i]))
    out.append((case, "peak_time_s", t[i]))
    out.append((case, "fwhm_s", half_width(t, y, i)))
    if contact:
        out.append((case, "separation_time_s", separation(t, y, i)))
    if delta_v:
        # The contact: from the last sample within 1 % of the peak from zero before it (the
        # pulse has a slow foot of 3-5 % of its peak for 80 µs) to the first sample back
        # across zero after it.
        level = 0.01 * abs(y[i])
        a = i
        while a > 0 and abs(y[a]) > level:
            a -= 1
        b = i
        while b < len(y) - 1 and y[b] * np.sign(y[i]) > 0:
            b += 1
        window = z.iloc[a : b + 1].to_frame()
        v = endaq.calc.integrate.integrals(window, n=1, zero="start")[1]
        out.append((case, "delta_v_m_s", float(v.iloc[-1, 0])))
        # The whole lobe: from the zero crossing before the peak to the one after it (each
        # interpolated linearly between its two samples), the felt's slow compression
        # included.
        sign = np.sign(y[i])
        a = i
        while a > 0 and sign * y[a - 1] > 0:
            a -= 1
        b = i
        while b < len(y) - 1 and sign * y[b + 1] > 0:
            b += 1
        t0 = t[a - 1] + y[a - 1] / (y[a - 1] - y[a]) * (t[a] - t[a - 1])
        t1 = t[b] + y[b] / (y[b] - y[b + 1]) * (t[b + 1] - t[b])
        lobe = pd.Series(
            np.concatenate([[0.0], y[a : b + 1], [0.0]]),
            index=pd.Index(np.concatenate([[t0], t[a : b + 1], [t1]]), name="time_s"),
        )
        v = endaq.calc.integrate.integrals(lobe.to_frame(), n=1, zero="start")[1]
        out.append((case, "delta_v_lobe_m_s", float(v.iloc[-1, 0])))
        out.append((case, "lobe_start_s", t0))
    if cfc is not None:
        rate = 1.0 / np.median(np.diff(t))
        f = j211(y, rate, cfc)
        j = int(np.argmax(np.abs(f)))
        out.append((case, f"cfc{cfc}_peak_m_s2", f[j]))


def bounces(case, s, zero, out):
    """Every bounce on a DC channel: enDAQ's events beyond 2 g from the free-fall zero."""
    z = (s - zero).to_frame()
    peaks = endaq.calc.stats.find_peaks(z, time_distance=0.1, threshold=2.0 * G)
    t = s.index.to_numpy()
    out.append((case, "bounces", len(peaks)))
    for k, i in enumerate(peaks):
        out.append((case, f"bounce{k}_time_s", t[int(i)]))


def main():
    out = []
    full = "afrl-drop-tower/series1_test1_full_100ms.csv"
    for col in ["bottom_kgn", "top_kgn"]:
        s = load(full, col, KGN)
        # The sensor zero: quiet before the ramp (0-9.5 ms) and after the ringing (30-100 ms).
        t = s.index
        zero = float(np.median(s[(t < 0.0095) | (t >= 0.03)]))
        pulse(f"afrl-full-{col}", s, zero, 0.01, out, cfc=1000, delta_v=True)
    for f, name in [("afrl-drop-tower/accel_5.csv", "accel5"), ("afrl-drop-tower/accel_6.csv", "accel6")]:
        for c in range(1, 6):
            s = load(f, c, KGN, skip=2, rate=1e6)
            # These 5 ms files start inside the pre-impact ramp: its first 0.2 ms.
            pulse(f"afrl-{name}-test{c}", s, median_over(s, 0.0, 0.0002), 0.001, out)
    piezo = load("endaq-high-drop/High-Drop_2000g-PE_13.4-15.0s.csv", "z_g", G)
    pulse("endaq-piezo-z", piezo, median_over(piezo, 13.4, 14.5), 1.0, out)
    dc = load("endaq-high-drop/High-Drop_16g-DC_full.csv", "z_g", G)
    bounces("endaq-dc-z", dc, median_over(dc, 13.8, 14.5), out)
    water = load("impack-water-entry/4mps_sphere_1_100g-PR_9.9-10.6s.csv", "y_g", G)
    # The reading drifts from -14.6 to -4 m/s² before the entry: the 30 ms before the slam.
    pulse("impack-100g-y", water, median_over(water, 10.15, 10.182), 1.0, out)
    for n in range(1, 6):
        s = load(f"pyfrf-impact-hammer/measurement_{n}.csv", "force_n", 1.0)
        pulse(f"pyfrf-{n}", s, float(np.median(s)), 1.0, out, cfc=1000, contact=True)

    w = sys.stdout
    w.write(f"# made by scripts/peer_endaq.py on {datetime.date.today().isoformat()}\n")
    w.write(
        f"# endaq {endaq.__version__}, numpy {np.__version__}, scipy {scipy.__version__}, "
        f"pandas {pd.__version__}, python {sys.version.split()[0]}\n"
    )
    w.write("case,quantity,value\n")
    for case, q, v in out:
        w.write(f"{case},{q},{float(v)!r}\n")


if __name__ == "__main__":
    main()
