#!/usr/bin/env python3
"""Peer shock spectra from enDAQ's Python library, for `impact analyze --srs`.

enDAQ's `endaq.calc.shock.shock_spectrum` (ISO 18431-4 filters; the residual from zero
padding of half the lowest period) in `srs` and `pvss` modes, damping 0.05, and
`enveloping_half_sine`, at the bands `impact analyze --srs` uses (1000 x 2^(k/6) Hz from
10 Hz to an eighth of the rate), on:

* `half-sine`: 1000 m/s² for 1 ms at 1 MS/s, 5 ms of zeros before and 14 ms after;
* `afrl-test1`: the AFRL drop tower's series 1 test 1 (bottom channel, kgn x 9806.65), over
  the window `impact analyze --srs` reports for its impact (samples 9816..22441) less the
  baseline it reports (-2.418687105178833 m/s²): the same input, so that the comparison
  checks the spectra, not the window. `host-tests/tests/recordings.rs` checks that the
  window and baseline are still these before comparing.

`host-tests/tests/recordings.rs` compares `impact analyze --srs` with the stored output; CI
never runs this script (no network there).

Rerun (needs the network once):

    python3 -m venv /tmp/peer && /tmp/peer/bin/pip install endaq==1.5.3
    /tmp/peer/bin/python scripts/peer_srs.py > scripts/peer_srs.csv

Output: CSV `case,quantity,frequency_hz,value` after `#` lines naming the versions and the
date; quantities `srs_m_s2`, `pvss_m_s` per band, `half_sine_amplitude_m_s2` and
`half_sine_duration_s` (frequency empty).
"""

import datetime
import os

import numpy as np
import pandas as pd
import scipy
import endaq
import endaq.calc.shock as shock

G = 9.80665
HERE = os.path.dirname(os.path.abspath(__file__))
SIGNALS = os.path.normpath(os.path.join(HERE, "..", "host-tests", "data"))
DAMP = 0.05


def bands(rate, per_octave=6, low=10.0):
    k = np.ceil(per_octave * np.log2(low / 1000.0) - 1e-9)
    out = []
    while True:
        f = 1000.0 * 2.0 ** (k / per_octave)
        if f > rate / 8.0:
            return np.array(out)
        out.append(f)
        k += 1


def spectra(case, accel, rate, rows):
    t = np.arange(len(accel)) / rate
    df = pd.DataFrame({"a": accel}, index=pd.Index(t, name="time"))
    freqs = bands(rate)
    srs = shock.shock_spectrum(df, freqs=freqs, damp=DAMP, mode="srs", max_time=None)
    pvss = shock.shock_spectrum(df, freqs=freqs, damp=DAMP, mode="pvss", max_time=None)
    for f, v in zip(freqs, srs["a"].to_numpy()):
        rows.append((case, "srs_m_s2", float(f), float(v)))
    for f, v in zip(freqs, pvss["a"].to_numpy()):
        rows.append((case, "pvss_m_s", float(f), float(v)))
    half = shock.enveloping_half_sine(pvss, damp=DAMP)
    rows.append((case, "half_sine_amplitude_m_s2", "", float(half.amplitude["a"])))
    rows.append((case, "half_sine_duration_s", "", float(half.duration["a"])))


def main():
    rows = []
    rate = 1e6
    n = round(1e-3 * rate)
    pulse = 1000.0 * np.sin(np.pi * np.arange(n + 1) / n)
    accel = np.concatenate([np.zeros(5000), pulse, np.zeros(14000)])
    spectra("half-sine", accel, rate, rows)

    path = os.path.join(SIGNALS, "afrl-drop-tower", "series1_test1_full_100ms.csv")
    data = pd.read_csv(path)
    bottom = data["bottom_kgn"].to_numpy() * 1000.0 * G
    window = bottom[9816:22441] - (-2.418687105178833)
    spectra("afrl-test1", window, 1e6, rows)

    print(f"# scripts/peer_srs.py, {datetime.date.today().isoformat()}: endaq {endaq.__version__}, "
          f"numpy {np.__version__}, scipy {scipy.__version__}, pandas {pd.__version__}")
    print("case,quantity,frequency_hz,value")
    for case, q, f, v in rows:
        print(f"{case},{q},{f!r},{v!r}" if f != "" else f"{case},{q},,{v!r}")


if __name__ == "__main__":
    main()
