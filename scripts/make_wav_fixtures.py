#!/usr/bin/env python3
"""Writes the WAV fixtures of host-tests/tests/formats.rs from the bundled AFRL record
(../shared/signals/afrl-drop-tower/series1_test1_full_100ms.csv, rows 5000..25000 of test 1):

- host-tests/fixtures/afrl-test1-int16.wav: 2 channels (bottom, top), 16-bit integer PCM,
  codes = round_half_even(kg_n * 1000), written by CPython's standard `wave` module;
- host-tests/fixtures/afrl-test1-float32.wav: 1 channel (bottom), 32-bit float PCM in kg_n,
  written by scipy.io.wavfile.

Made with CPython 3.11.7 (`wave`), numpy 2.4.6 and scipy 1.17.1:
    python3 -m venv /tmp/wavpy && /tmp/wavpy/bin/pip install numpy==2.4.6 scipy==1.17.1
    /tmp/wavpy/bin/python scripts/make_wav_fixtures.py
"""
import csv
import pathlib
import struct
import wave

import numpy as np
import scipy.io.wavfile

ROOT = pathlib.Path(__file__).resolve().parent.parent
SOURCE = ROOT / "../shared/signals/afrl-drop-tower/series1_test1_full_100ms.csv"
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
print("wrote", sorted(p.name for p in OUT.glob("*.wav")))
