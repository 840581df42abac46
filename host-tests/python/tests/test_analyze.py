"""`impact.analyze` against `impact analyze --json`: the same numbers bit for bit, field by
field, on every bundled recording and with the options that add fields."""

import json
import math

import numpy as np
import pandas as pd
import pytest

import impact
from conftest import DATA, ROOT, recordings

AFRL = DATA / "afrl-drop-tower" / "series1_test1_full_100ms.csv"


def same_frame_as_json(df: pd.DataFrame, reasons: pd.DataFrame, impacts: list) -> None:
    """Every field of every impact of the JSON is its DataFrame cell (a null a NaN/None
    with its reason in `null_reasons`), and the frame has no other column."""
    assert len(df) == len(impacts)
    seen = set()
    for row, imp in enumerate(impacts):
        flat = impact._flatten(imp)
        seen.update(flat)
        for name, value in flat.items():
            cell = df.iloc[row][name]
            if value is None:
                assert cell is None or (isinstance(cell, float) and math.isnan(cell)), (name, cell)
                reason = imp["null_reasons"].get(name) or imp["null_reasons"].get(name.rsplit(".", 1)[0])
                if reason is not None:
                    assert reasons.iloc[row][name if name in reasons.columns else name.rsplit(".", 1)[0]] == reason
            elif isinstance(value, float):
                # Bit for bit: the same f64, not a close one.
                assert isinstance(cell, (float, np.floating)) and float(cell).hex() == value.hex(), (name, cell, value)
            elif isinstance(value, list):
                assert list(cell) == value, name
            else:
                assert cell == value, (name, cell, value)
    assert set(df.columns) == seen


@pytest.mark.parametrize("path", recordings(), ids=lambda p: str(p.relative_to(DATA)))
def test_every_bundled_recording_is_the_tools_bit_for_bit(cli, path):
    want, notes = cli.analysis("analyze", path)
    a = impact.analyze(path)
    assert a.json == want
    assert a.notes == notes
    assert len(a.impacts) >= 1
    same_frame_as_json(a.impacts, a.null_reasons, want["impacts"])


@pytest.mark.parametrize(
    "options",
    [
        dict(srs=True, spec="half-sine,10000g,0.5ms"),
        dict(cfc=1000, mass=0.5, v0=7.6, column="top_kgn"),
        dict(axes=["bottom_kgn", "top_kgn"], units="kgn"),
    ],
    ids=["srs-spec", "cfc-mass-v0-fit", "axes"],
)
def test_options_are_the_tools(cli, options):
    argv = impact._argv(options)
    want = cli.json("analyze", AFRL, *argv)
    a = impact.analyze(AFRL, **options)
    assert a.json == want
    same_frame_as_json(a.impacts, a.null_reasons, want["impacts"])


def test_a_failed_verdict_is_a_result_not_an_exception(cli):
    p = cli.run("analyze", AFRL, "--spec", "half-sine,10000g,0.5ms")
    assert p.returncode == 3
    a = impact.spec(AFRL, "half-sine,10000g,0.5ms")
    assert a.passed is False and a.failed == a.judged == 1
    assert a.impacts["spec.pass"].tolist() == [False]
    assert a.json["spec"]["standard"] == "iec-60068-2-27"


def test_spectra_are_arrays_of_the_json(cli):
    a = impact.analyze(AFRL, srs=True)
    s = a.spectra[0]
    want = cli.json("analyze", AFRL, "--srs")["impacts"][0]["shock_spectrum"]
    for k in ("frequency_hz", "srs_m_s2", "pvss_m_s"):
        assert s[k].dtype == np.float64 and s[k].tolist() == want[k]


def test_an_array_is_analysed_as_its_npy_file(cli, tmp_path):
    r = impact.read(AFRL, column="bottom_kgn")
    for dtype in (np.float64, np.float32):
        f = tmp_path / f"bottom-{np.dtype(dtype).name}.npy"
        samples = r.samples.astype(dtype)
        np.save(f, samples)
        want = cli.json("analyze", f, "--rate", repr(r.rate_hz), "--units", "kgn")
        # float64 read in place; float32 and a list converted as the .npy reader converts.
        for given in (samples, list(samples)):
            a = impact.analyze(given, rate=r.rate_hz, units="kgn")
            assert a.json["impacts"] == want["impacts"]
            assert a.json["sample_rate_hz"] == want["sample_rate_hz"]


def test_an_array_without_a_rate_or_units_or_with_a_files_option_is_refused():
    with pytest.raises(impact.UsageError, match="give units="):
        impact.analyze(np.zeros(100), rate=1000.0)
    # Its name is a label, not a header naming a unit.
    with pytest.raises(impact.UsageError, match="give units="):
        impact.analyze(np.zeros(100), rate=1000.0, name="run_n")
    with pytest.raises(impact.UsageError, match="rate="):
        impact.analyze(np.zeros(100), units="g")
    with pytest.raises(impact.UsageError, match="--column reads a file"):
        impact.analyze(np.zeros(100), rate=1000.0, units="g", column="x")
    with pytest.raises(impact.UsageError, match="1-D"):
        impact.analyze(np.zeros((10, 3)), rate=1000.0, units="g")
    for bad in (np.zeros(10, dtype=complex), np.zeros(10, dtype=bool), np.array(["1", "2"])):
        with pytest.raises(impact.UsageError, match="real numbers"):
            impact.analyze(bad, rate=1000.0, units="g")


def test_an_array_is_held_to_what_a_file_is(cli, tmp_path):
    """Two samples at least, every one finite: refused as the .npy reader refuses them."""
    pulse = np.zeros(4000)
    pulse[1000:1300] = 50 * np.sin(np.linspace(0, np.pi, 300))
    for bad, says in ((np.nan, "sample 1100 is NaN"), (np.inf, "sample 1100 is inf")):
        x = pulse.copy()
        x[1100] = bad
        np.save(tmp_path / "bad.npy", x)
        assert cli.run("analyze", tmp_path / "bad.npy", "--rate", "1e5", "--units", "g").returncode == 1
        with pytest.raises(impact.ReadError, match=says):
            impact.analyze(x, rate=1e5, units="g")
    for short in (np.zeros(0), np.zeros(1)):
        with pytest.raises(impact.ReadError, match="at least 2"):
            impact.analyze(short, rate=1e5, units="g")
    # Unaligned float64 bytes: copied once, not refused.
    buf = np.zeros(4001 * 8 + 1, dtype=np.uint8)
    odd = np.frombuffer(buf.data, dtype=np.float64, count=4000, offset=1)
    assert not odd.flags.aligned
    assert len(impact.analyze(odd, rate=1e5, units="g").impacts) == 0


def test_no_impact_still_has_the_columns():
    a = impact.analyze(np.zeros(1000), rate=1e3, units="g")
    assert len(a.impacts) == 0
    assert {"peak_acceleration_m_s2", "cor", "delta_v_m_s"} <= set(a.impacts.columns)


def test_paths_and_values_that_begin_with_a_dash_are_not_options(cli, tmp_path):
    dashed = tmp_path / "-run.csv"
    dashed.write_bytes(AFRL.read_bytes())
    p = cli.run("analyze", "--column=top_kgn", "--json", "--", dashed)
    assert p.returncode == 0, p.stderr
    assert impact.analyze(dashed, column="top_kgn").json == json.loads(p.stdout)
    with pytest.raises(impact.UsageError, match="standard input"):
        impact.analyze("-")
    with pytest.raises(impact.UsageError, match="a list of recordings"):
        impact.series(str(AFRL))


def test_notes_stay_with_their_own_analysis_across_threads():
    import threading

    chosen = "analysing bottom_kgn of 2 channels"
    results = {"named": [], "chosen": []}

    def run(key, **options):
        for _ in range(15):
            results[key].append(impact.analyze(AFRL, **options).notes)

    threads = [threading.Thread(target=run, args=("named",), kwargs=dict(column="bottom_kgn")),
               threading.Thread(target=run, args=("chosen",))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert all(n == [] for n in results["named"]), results["named"]
    assert all(len(n) == 1 and n[0].startswith(chosen) for n in results["chosen"]), results["chosen"]


def test_results_compare_without_raising():
    a = impact.analyze(AFRL, column="bottom_kgn")
    assert a == a and a != impact.analyze(AFRL, column="bottom_kgn")
    assert a in [a]


def test_errors_are_typed_and_carry_the_tools_message(cli, tmp_path):
    missing = tmp_path / "missing.csv"
    p = cli.run("analyze", missing)
    with pytest.raises(impact.ReadError) as e:
        impact.analyze(missing)
    assert str(e.value) in p.stderr
    with pytest.raises(impact.UsageError, match="--mass"):
        impact.analyze(AFRL, mass="heavy")
    with pytest.raises(impact.UsageError, match="--no-such-option"):
        impact.analyze(AFRL, no_such_option=1)
    # Every exception is an ImpactError.
    assert issubclass(impact.ReadError, impact.ImpactError)
    assert issubclass(impact.UsageError, impact.ImpactError)


def test_an_analysis_pickles_for_other_processes():
    import pickle

    a = impact.analyze(AFRL, srs=True)
    b = pickle.loads(pickle.dumps(a))
    assert b.json == a.json
    pd.testing.assert_frame_equal(b.impacts, a.impacts)
