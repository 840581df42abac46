#!/usr/bin/env python3
"""Writes the WAV and .npy fixtures of host-tests/tests/formats.rs from the bundled AFRL record
(host-tests/data/afrl-drop-tower/series1_test1_full_100ms.csv, rows 5000..25000 of test 1):

- host-tests/fixtures/afrl-test1-int16.wav: 2 channels (bottom, top), 16-bit integer PCM,
  codes = round_half_even(kg_n * 1000), written by CPython's standard `wave` module;
- host-tests/fixtures/afrl-test1-float32.wav: 1 channel (bottom), 32-bit float PCM in kg_n,
  written by scipy.io.wavfile;
- host-tests/fixtures/afrl-test1-int16.npy: rows 8000..18000, shape (10000, 2) int16 codes as
  above, C order, written by numpy.save;
- host-tests/fixtures/afrl-test1-float32-fortran.npy: the same rows, shape (10000, 2) float32
  kg_n in Fortran order, written by numpy.save;
- host-tests/fixtures/afrl-test1-2ch.i16: the int16 codes above, two channels interleaved,
  little-endian, written by numpy's tofile;
- host-tests/fixtures/afrl-test1.f32: the bottom channel's float32 kg_n, little-endian, by
  numpy's tofile;
- host-tests/fixtures/afrl-test1.tdms: group `afrl`, channels `bottom_kgn` (float64 kg_n) and
  `top_codes` (int16 codes), both with wf_increment 1e-6, written by npTDMS 1.13.0;
- host-tests/fixtures/afrl-test1-units.tdms: group `afrl`, the bottom channel whose names
  carry no unit, its unit in NI's `unit_string` property: `bottom` (float64 g, "g"),
  `bottom_si` (float64 m/s², "m/s^2", g = 9.80665 m/s²) and `bare` (float64 g, no
  unit_string), wf_increment 1e-6, written by npTDMS 1.13.0.

Made with CPython 3.11.7 (`wave`), numpy 2.4.6, scipy 1.17.1 and npTDMS 1.13.0:
    python3 -m venv /tmp/wavpy && /tmp/wavpy/bin/pip install numpy==2.4.6 scipy==1.17.1 npTDMS==1.13.0
    /tmp/wavpy/bin/python scripts/make_format_fixtures.py
"""
import csv
import pathlib
import struct
import wave

import numpy as np
import scipy.io.wavfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOURCE = ROOT / "host-tests/data/afrl-drop-tower/series1_test1_full_100ms.csv"
OUT = ROOT / "host-tests/fixtures"
FIRST, LAST = 5000, 25000  # data rows (0-based), LAST exclusive
RATE = 1_000_000

with open(SOURCE) as f:
    rows = list(csv.reader(f))[1:]
rows = rows[FIRST:LAST]
bottom = [float(r[1]) for r in rows]
top = [float(r[2]) for r in rows]

OUT.mkdir(parents=True, exist_ok=True)
with wave.open(str(OUT / "afrl-test1-int16.wav"), "wb") as w:
    w.setnchannels(2)
    w.setsampwidth(2)
    w.setframerate(RATE)
    frames = b"".join(
        struct.pack("<hh", round(b * 1000.0), round(t * 1000.0)) for b, t in zip(bottom, top)
    )
    w.writeframes(frames)

scipy.io.wavfile.write(OUT / "afrl-test1-float32.wav", RATE, np.array(bottom, dtype=np.float32))
# .npy: a shorter window (rows 8000..18000 of the record: 3000..13000 of the slice above).
b = np.array(bottom[3000:13000])
t = np.array(top[3000:13000])
codes = np.stack([np.round(b * 1000.0), np.round(t * 1000.0)], axis=1).astype(np.int16)
np.save(OUT / "afrl-test1-int16.npy", codes)
np.save(OUT / "afrl-test1-float32-fortran.npy", np.asfortranarray(np.stack([b, t], axis=1).astype(np.float32)))
codes.astype("<i2").tofile(OUT / "afrl-test1-2ch.i16")
b.astype("<f4").tofile(OUT / "afrl-test1.f32")
from nptdms import ChannelObject, TdmsWriter

with TdmsWriter(str(OUT / "afrl-test1.tdms")) as w:
    w.write_segment([
        ChannelObject("afrl", "bottom_kgn", b.astype(np.float64), properties={"wf_increment": 1e-6}),
        ChannelObject("afrl", "top_codes", codes[:, 1].copy(), properties={"wf_increment": 1e-6}),
    ])
g = b.astype(np.float64) * 1000.0
with TdmsWriter(str(OUT / "afrl-test1-units.tdms")) as w:
    w.write_segment([
        ChannelObject("afrl", "bottom", g, properties={"wf_increment": 1e-6, "unit_string": "g"}),
        ChannelObject("afrl", "bottom_si", g * 9.80665, properties={"wf_increment": 1e-6, "unit_string": "m/s^2"}),
        ChannelObject("afrl", "bare", g, properties={"wf_increment": 1e-6}),
    ])
print("wrote", sorted(p.name for p in OUT.glob("*.*")))
