#!/usr/bin/env python3
"""Writes the TDMS fixtures of host-tests/tests/hostile_readers.rs (issue #45) and npTDMS's own
read of them, the peer the Rust reader is checked against (CI has no network: the test reads
the stored files and numbers).

The values are the `afrl/top_codes` channel of host-tests/fixtures/afrl-test1.tdms (10 000 int16
codes at wf_increment 1e-6, an AFRL drop: see scripts/make_format_fixtures.py), as npTDMS reads
them. The segments are written by hand (struct), as NI's own writers lay them out, since
npTDMS's writer makes one chunk a segment and never interleaves:

- host-tests/fixtures/tdms-chunks/multi-chunk.tdms: group `afrl`, channels `top_codes` (int16,
  2 500 values a chunk, wf_increment 1e-6) and `counter` (uint32, 25 values a chunk: 0, 1, ...).
  Segment 1 (metadata, new object list, raw data): 3 chunks; segment 2 (raw data only, the
  previous segment's objects and indexes): 1 chunk. A raw data size a multiple of the chunk
  size, as NI's DAQmx and LabVIEW writers leave it.
- host-tests/fixtures/tdms-chunks/interleaved.tdms: group `afrl`, channels `top_codes` (int16,
  wf_increment 1e-6) and `row` (uint8, the row's index mod 256), interleaved (ToC bit 5):
  rows of one value of each. Segment 1 (metadata, new object list): 2 chunks of 2 500 rows;
  segment 2 (metadata naming both objects with raw data index 0, "as before", not a new
  list): 2 chunks of 2 500 rows.
- host-tests/fixtures/tdms-chunks/peer.csv: npTDMS's read of each file's channels: the value
  count, the sum (float64), the first and last values and the values at indexes 2499, 2500,
  7499 and 7500 (the chunks' and segments' seams).

Made with CPython 3.11.7, numpy 2.4.6 and npTDMS 1.13.0:
    python3 -m venv /tmp/tdmspy && /tmp/tdmspy/bin/pip install numpy==2.4.6 npTDMS==1.13.0
    /tmp/tdmspy/bin/python scripts/make_tdms_chunk_fixtures.py
"""
import pathlib
import struct

import numpy as np
from nptdms import TdmsFile

ROOT = pathlib.Path(__file__).resolve().parent.parent
OUT = ROOT / "host-tests" / "fixtures" / "tdms-chunks"

META, NEW_LIST, RAW, INTERLEAVED = 1 << 1, 1 << 2, 1 << 3, 1 << 5
INT16, UINT8, UINT32, DOUBLE = 2, 5, 7, 10


def string(s):
    b = s.encode()
    return struct.pack("<I", len(b)) + b


def obj(path, index, props=()):
    """An object's metadata: its path, raw data index (None: no data; 0: as before; else
    (type, count)) and properties ((name, DOUBLE, value))."""
    out = string(path)
    if index is None:
        out += struct.pack("<I", 0xFFFFFFFF)
    elif index == 0:
        out += struct.pack("<I", 0)
    else:
        dtype, count = index
        out += struct.pack("<IIIQ", 20, dtype, 1, count)
    out += struct.pack("<I", len(props))
    for name, dtype, value in props:
        assert dtype == DOUBLE
        out += string(name) + struct.pack("<Id", dtype, value)
    return out


def segment(toc, objects, data):
    meta = b""
    if toc & META:
        meta = struct.pack("<I", len(objects)) + b"".join(objects)
    lead = b"TDSm" + struct.pack("<IIQQ", toc, 4713, len(meta) + len(data), len(meta))
    return lead + meta + data


def main():
    codes = TdmsFile.read(ROOT / "host-tests" / "fixtures" / "afrl-test1.tdms")["afrl"]["top_codes"][:]
    codes = np.asarray(codes, dtype="<i2")
    assert len(codes) == 10_000
    inc = [("wf_increment", DOUBLE, 1e-6)]
    OUT.mkdir(parents=True, exist_ok=True)

    # Multi-chunk: 2 500 codes and 25 counters a chunk.
    per, cper = 2500, 25
    counter = np.arange(4 * cper, dtype="<u4")

    def chunk(k):
        return codes[k * per:(k + 1) * per].tobytes() + counter[k * cper:(k + 1) * cper].tobytes()

    objs = [
        obj("/", None),
        obj("/'afrl'", None),
        obj("/'afrl'/'top_codes'", (INT16, per), inc),
        obj("/'afrl'/'counter'", (UINT32, cper)),
    ]
    data1 = b"".join(chunk(k) for k in range(3))
    multi = segment(META | NEW_LIST | RAW, objs, data1) + segment(RAW, [], chunk(3))
    (OUT / "multi-chunk.tdms").write_bytes(multi)

    # Interleaved: rows of (int16 code, uint8 row index), 2 500 rows a chunk.
    rows = np.zeros(10_000, dtype=[("code", "<i2"), ("row", "u1")])
    rows["code"] = codes
    rows["row"] = np.arange(10_000) % 256
    objs = [
        obj("/", None),
        obj("/'afrl'", None),
        obj("/'afrl'/'top_codes'", (INT16, per), inc),
        obj("/'afrl'/'row'", (UINT8, per)),
    ]
    seg1 = segment(META | NEW_LIST | RAW | INTERLEAVED, objs, rows[:5000].tobytes())
    again = [obj("/'afrl'/'top_codes'", 0), obj("/'afrl'/'row'", 0)]
    seg2 = segment(META | RAW | INTERLEAVED, again, rows[5000:].tobytes())
    (OUT / "interleaved.tdms").write_bytes(seg1 + seg2)

    # npTDMS's own read of both.
    lines = ["file,channel,count,sum,first,last,v2499,v2500,v7499,v7500"]
    for name in ["multi-chunk.tdms", "interleaved.tdms"]:
        f = TdmsFile.read(OUT / name)
        for g in f.groups():
            for c in g.channels():
                v = np.asarray(c[:], dtype=np.float64)
                at = lambda i: repr(float(v[i])) if i < len(v) else ""
                lines.append(",".join([
                    name, f"{g.name}/{c.name}", str(len(v)), repr(float(v.sum())),
                    at(0), at(len(v) - 1), at(2499), at(2500), at(7499), at(7500),
                ]))
    (OUT / "peer.csv").write_text("\n".join(lines) + "\n")
    print("\n".join(lines))


if __name__ == "__main__":
    main()
