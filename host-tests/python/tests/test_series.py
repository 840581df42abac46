"""A series, in one process and on Dask: the same rows and statistics as
`impact analyze FILES… --json`."""

import json
import pathlib
import sys

import pytest

import impact
from conftest import DATA, ROOT

HAMMER = sorted((DATA / "pyfrf-impact-hammer").glob("*.csv"))
AFRL = sorted((DATA / "afrl-drop-tower").glob("*.csv"))


def test_a_series_is_the_tools(cli):
    want = cli.json("analyze", *HAMMER)
    s = impact.series(HAMMER)
    assert s.json == want
    assert len(s.impacts) == want["impacts"]
    assert list(s.impacts.columns[:2]) == ["file", "channel"]
    assert s.statistics.table.loc["peak_acceleration_m_s2", "mean"] == next(
        x["mean"] for x in want["statistics"] if x["metric"] == "peak_acceleration_m_s2"
    )


def test_a_failed_recording_is_an_entry_not_an_exception(cli, tmp_path):
    bad = tmp_path / "empty.csv"
    bad.write_text("time_s,accel_g\n")
    p = cli.run("analyze", HAMMER[0], bad, "--json")
    assert p.returncode == 1
    s = impact.series([HAMMER[0], bad])
    assert s.json == json.loads(p.stdout)
    ((file, _), message), = s.failures.items()
    assert file == str(bad)
    assert message == json.loads(p.stdout)["entries"][1]["error"]


def test_a_series_verdict_is_the_exit_status(cli):
    p = cli.run("analyze", *AFRL, "--spec", "half-sine,10000g,0.5ms", "--json")
    assert p.returncode == 3
    s = impact.series(AFRL, spec="half-sine,10000g,0.5ms")
    assert s.passed is False
    assert impact.series(AFRL).passed is None
    assert s.null_reasons.shape[0] == len(s.impacts)


def test_bounce_statistics_gathered_are_the_series(cli, tmp_path):
    trains = []
    for seed in (1, 2):
        f = tmp_path / f"train{seed}.csv"
        p = cli.run("synth", "--model", "nonlinear", "--mass", "0.06", "--v0", "1.3357", "--stiffness", "1e4",
                    "--damping", "0.5", "--bounces", "4", "--duration", "1.5", "--seed", str(seed), "-o", f)
        assert p.returncode == 0, p.stderr
        trains.append(f)
    options = dict(mass=0.06, v0=1.3357, train="flight")
    want = cli.json("analyze", *trains, *impact._argv(options))
    assert want["bounce_statistics"], "the trains' bounces compared"
    got = impact.statistics([impact.analyze(f, **options) for f in trains]).json
    for key in ("impacts", "statistics", "statistics_left_out", "bounce_statistics"):
        assert got.get(key) == want.get(key), key


def test_statistics_gathered_from_single_analyses_are_the_series(cli):
    files = HAMMER + AFRL
    want = cli.json("analyze", *files, "--spec", "half-sine,100g,1ms")
    analyses = [impact.analyze(f, spec="half-sine,100g,1ms") for f in files]
    got = impact.statistics(analyses).json
    for key in ("impacts", "spec", "statistics", "statistics_left_out"):
        assert got.get(key) == want.get(key), key
    assert got.get("bounce_statistics", []) == want.get("bounce_statistics", [])


def test_the_dask_example_gathers_the_series_statistics(cli):
    pytest.importorskip("dask.bag")
    sys.path.insert(0, str(ROOT / "host-tests" / "python" / "examples"))
    import dask_series

    want = cli.json("analyze", *HAMMER, "--units", "n", "--mass", "1.0")
    analyses, stats = dask_series.series_statistics(HAMMER, units="n", mass=1.0)
    assert [a.json for a in analyses] == [
        {k: v for k, v in e.items() if k not in ("file", "channel", "notes")} for e in want["entries"]
    ]
    assert stats.json["statistics"] == want["statistics"]
    assert stats.left_out == want["statistics_left_out"]


def test_statistics_refuse_what_is_not_impacts():
    with pytest.raises(impact.UsageError, match="not impacts"):
        impact._impact.statistics('[{"peak": 1}]')
