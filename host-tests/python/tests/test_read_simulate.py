"""`impact.read` (the samples the analysis reads, an .IDE's own metadata) and
`impact.simulate` (the tool's `simulate --json`)."""

import json

import numpy as np
import pytest

import impact
from conftest import DATA, ROOT

IDE = DATA / "endaq-high-drop" / "High-Drop.IDE"


def test_read_gives_the_samples_the_analysis_reads(cli):
    r = impact.read(DATA / "afrl-drop-tower" / "series1_test1_full_100ms.csv", column="top_kgn")
    want = cli.json("analyze", DATA / "afrl-drop-tower" / "series1_test1_full_100ms.csv", "--column", "top_kgn")
    assert r.samples.dtype == np.float64 and len(r.samples) == want["samples"]
    assert r.rate_hz == want["sample_rate_hz"] and r.units == "kgn" and r.column == "top_kgn"
    assert r.to_m_s2 == 1000 * 9.80665
    assert r.to_frame().index.name == "time_s"


def test_read_says_what_it_chose_and_refuses_an_analysis_option():
    r = impact.read(DATA / "afrl-drop-tower" / "series1_test1_full_100ms.csv")
    assert len(r.notes) == 1 and r.notes[0].startswith("analysing bottom_kgn of 2 channels")
    with pytest.raises(impact.UsageError, match="spec: an analysis's option"):
        impact.read(IDE, spec="half-sine,100g,3ms")


def test_read_says_what_it_assumed(tmp_path):
    f = tmp_path / "bare.csv"
    f.write_text("time_s,accel\n" + "".join(f"{i * 1e-4:.4f},{(i % 7) * 0.1}\n" for i in range(100)))
    r = impact.read(f)
    assert r.units == "g"
    assert any("accel" in a for a in r.assumptions)


def test_an_ide_recording_brings_its_recorder_and_sensors():
    r = impact.read(IDE)
    rec = r.metadata["recorder"]
    assert (rec["part_number"], rec["serial"], rec["firmware"]) == ("LOG-0002-02kG-DC", 6468, "1.20.1")
    piezo = "832M1 PE Accelerometer"
    assert {"id": 9, "name": piezo, "serial": "5663-033"} in r.metadata["sensors"]
    assert r.metadata["calibration"]["serial"] == 4953
    # The channel analysed (8.0, the 2000 g piezo's X) names its sensor.
    ch8 = next(c for c in r.metadata["channels"] if c["id"] == 8)
    assert ch8["subchannels"][0]["sensor"] == piezo


def test_simulate_is_the_tools(cli):
    args = dict(mass=8.419e-3, v0=2.0, radius=6.35e-3, youngs=200e9, poisson=0.3)
    p = cli.run("simulate", "--model", "hertz", *impact._argv(args), "--json")
    assert p.returncode == 0, p.stderr
    want = json.loads(p.stdout)
    got = impact.simulate("hertz", **args)
    assert got.keys() == want.keys()
    for k, v in want.items():
        if isinstance(v, list) and isinstance(got[k], np.ndarray):
            assert got[k].tolist() == v
        else:
            assert got[k] == v, k


def test_a_refused_model_is_a_typed_error():
    with pytest.raises(impact.UsageError):
        impact.simulate("no-such-model", mass=1.0, v0=1.0)
    with pytest.raises(impact.SimulationError):
        impact.simulate("hertz", mass=-1.0, v0=2.0, radius=6.35e-3, youngs=200e9, poisson=0.3)
