"""Impact analysis from Python: the ``impact`` tool's own Rust code, its results as NumPy
arrays and pandas DataFrames.

>>> import impact
>>> a = impact.analyze("host-tests/data/afrl-drop-tower/series1_test1_full_100ms.csv")
>>> a.impacts[["start_s", "peak_acceleration_m_s2", "delta_v_m_s"]]

Keyword arguments are ``impact analyze``'s options, by their long names with ``_`` for
``-`` (``mass=0.06`` is ``--mass 0.06``, ``srs=True`` is ``--srs``, ``axes=["x", "y", "z"]``
is ``--axes x,y,z``); ``impact analyze --help`` lists them all, and a refused option or
value raises :class:`UsageError` with the tool's message. Every number is the tool's: the
same, bit for bit, as ``impact analyze --json`` on the same input.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any, Iterable, Mapping, Optional, Sequence, Union

import numpy as np
import pandas as pd

from . import _impact
from ._impact import (
    AnalysisError,
    ImpactError,
    ReadError,
    SimulationError,
    UsageError,
)

__version__ = _impact.__version__

__all__ = [
    "Analysis",
    "AnalysisError",
    "ImpactError",
    "ReadError",
    "Recording",
    "Series",
    "SeriesStatistics",
    "SimulationError",
    "UsageError",
    "analyze",
    "read",
    "series",
    "simulate",
    "spec",
    "statistics",
]

PathLike = Union[str, "os.PathLike[str]"]


def _value(v: Any) -> str:
    """An option's value as the command line writes it (a float's shortest exact text)."""
    if isinstance(v, bool):
        raise UsageError("a true/false option is a flag: give it as True (or leave it out)")
    if isinstance(v, float):
        return repr(v)
    if isinstance(v, (np.floating, np.integer)):
        return repr(v.item())
    if isinstance(v, os.PathLike):
        return os.fspath(v)
    return str(v)


def _argv(options: Mapping[str, Any]) -> list[str]:
    """Keyword arguments as ``impact analyze``'s options: ``True`` a flag, ``None`` and
    ``False`` left out, a list joined with commas; each value joined to its flag
    (``--column=-top``), so none is taken for an option."""
    argv: list[str] = []
    for key, v in options.items():
        if v is None or v is False:
            continue
        flag = "--" + key.replace("_", "-")
        if v is True:
            argv.append(flag)
        elif isinstance(v, (list, tuple)):
            argv.append(f"{flag}={','.join(_value(x) for x in v)}")
        else:
            argv.append(f"{flag}={_value(v)}")
    return argv


def _path(p: Any, what: str = "a recording") -> str:
    """A path as the command line takes it, after every option (``--``): never read as an
    option, and never ``-`` (the tool's standard input, not a Python script's)."""
    if not isinstance(p, (str, os.PathLike)):
        raise UsageError(f"{what}: a path (str or os.PathLike), not {type(p).__name__}")
    text = os.fspath(p)
    if not isinstance(text, str):
        raise UsageError(f"{what}: a str path, not bytes")
    if text == "-":
        raise UsageError("'-' is the command line's standard input: give a file's path, or an array")
    return text


def _command(path: str, options: Mapping[str, Any]) -> list[str]:
    return _argv(options) + ["--", path]


# --- reading ---------------------------------------------------------------------------


@dataclass(frozen=True, eq=False)
class Recording:
    """One channel of a recording as the tool reads it.

    ``samples`` are in the file's ``units`` (``"g"``, ``"m/s2"``, ``"kgn"``, ``"n"``);
    ``samples * to_m_s2`` is the signal in m/s² (``to_m_s2`` is None for a force without a
    mass). ``assumptions`` says what the tool assumed that the file did not (a unit);
    ``notes`` what it chose (a channel of several). ``metadata`` holds an enDAQ ``.IDE``'s
    recorder and channels (empty for other formats).
    """

    samples: np.ndarray
    time_s: np.ndarray
    rate_hz: float
    column: str
    units: str
    to_m_s2: Optional[float]
    assumptions: list
    resampled: bool
    jitter: float
    axes: dict = field(default_factory=dict)
    metadata: dict = field(default_factory=dict)
    notes: list = field(default_factory=list)

    def to_frame(self) -> pd.DataFrame:
        """The samples against time (``time_s`` the index), one column per axis too."""
        cols = {self.column or "samples": self.samples}
        cols.update(self.axes)
        return pd.DataFrame(cols, index=pd.Index(self.time_s, name="time_s"))


# The options that say how a recording is read and what its values are (the rest of
# `impact analyze`'s are the analysis's, which `read` does not run).
_READ_OPTIONS = frozenset({
    "column", "axes", "rate", "time_column", "time_unit", "resample", "delimiter",
    "decimal_comma", "raw_channels", "raw_type", "units", "mass", "gain", "invert", "scene",
})


def read(path: PathLike, *, column: Any = None, units: Optional[str] = None, **options: Any) -> Recording:
    """Reads one channel of a recording (CSV, TSV, LabVIEW text, WAV, ``.npy``, TDMS,
    enDAQ ``.IDE``, raw), with ``impact analyze``'s reading options (``column=``,
    ``axes=``, ``rate=``, ``time_column=``, ``time_unit=``, ``units=``, ``mass=``…)."""
    other = sorted(set(options) - _READ_OPTIONS)
    if other:
        raise UsageError(f"read() reads a recording; {', '.join(other)}: an analysis's option (impact.analyze)")
    d = _impact.read(_command(_path(path), dict(column=column, units=units, **options)))
    meta = json.loads(d["metadata_json"]) if d["metadata_json"] else {}
    return Recording(
        samples=d["samples"],
        time_s=d["time_s"],
        rate_hz=d["rate_hz"],
        column=d["column"],
        units=d["units"],
        to_m_s2=d["to_m_s2"],
        assumptions=list(d["assumptions"]),
        resampled=d["resampled"],
        jitter=d["jitter"],
        axes=dict(d["axes"]),
        metadata=meta,
        notes=list(d["notes"]),
    )


# --- analysis --------------------------------------------------------------------------

# Per-impact lists that are arrays (one value per oscillator), kept out of the DataFrame.
_SPECTRUM_ARRAYS = ("frequency_hz", "srs_m_s2", "pvss_m_s")


def _flatten(d: Mapping[str, Any], prefix: str = "") -> dict:
    """A nested JSON object as one row: ``fits.hertz.k``; ``null_reasons`` and the shock
    spectrum's arrays left out (they are the Analysis's own)."""
    row: dict = {}
    for k, v in d.items():
        name = prefix + k
        if name == "null_reasons" or (prefix == "shock_spectrum." and k in _SPECTRUM_ARRAYS):
            continue
        if isinstance(v, dict):
            row.update(_flatten(v, name + "."))
        else:
            row[name] = v
    return row


_FIELDS: list = []


def _fields() -> list:
    """An impact's columns when nothing is known (the table of no impact has them)."""
    if not _FIELDS:
        _FIELDS.extend(_flatten(json.loads(_impact.impact_fields())))
    return _FIELDS


def _impacts_frame(impacts: Sequence[Mapping[str, Any]], extra: Optional[list] = None) -> pd.DataFrame:
    """One row per impact, the JSON's field names as columns (nested ones joined with
    ``.``); a null number is NaN (its reason in ``null_reasons``). A nested object null in
    one impact and present in another (``bounce``) is its fields' columns, NaN there."""
    rows = [_flatten(i) for i in impacts]
    names = {k for r in rows for k in r}
    parents = {k for k in names if any(n.startswith(k + ".") for n in names)}
    rows = [{k: v for k, v in r.items() if k not in parents} for r in rows]
    if extra is not None:
        rows = [{**e, **r} for e, r in zip(extra, rows)]
    if rows:
        df = pd.DataFrame.from_records(rows)
    else:
        df = pd.DataFrame(columns=(list(extra[0]) if extra else []) + _fields())
    if "index" in df.columns and extra is None:
        df = df.set_index("index", drop=False)
        df.index.name = None
    return df


def _null_reasons_frame(impacts: Sequence[Mapping[str, Any]], index) -> pd.DataFrame:
    """Why each null field is null: one row per impact, one column per field that is null
    somewhere (None where the field has a value)."""
    return pd.DataFrame.from_records([i.get("null_reasons", {}) for i in impacts], index=index)


def _spectra(impacts: Sequence[Mapping[str, Any]]) -> list:
    """Each impact's shock spectra as arrays (None for an impact without)."""
    out = []
    for i in impacts:
        s = i.get("shock_spectrum")
        out.append(None if s is None else {k: np.asarray(s[k], dtype=np.float64) for k in _SPECTRUM_ARRAYS})
    return out


@dataclass(eq=False)
class Analysis:
    """One recording's analysis: what ``impact analyze --json`` prints, as Python.

    - ``impacts``: a DataFrame, one row per impact, the JSON's SI field names as columns
      (``peak_acceleration_m_s2``, ``cor``, ``spec.pass``, ``fits.hertz.k``…), a null as
      NaN/None;
    - ``null_reasons``: why each null is null (same rows, one column per field);
    - ``spectra``: with ``srs=True``, each impact's ``frequency_hz``, ``srs_m_s2`` and
      ``pvss_m_s`` arrays;
    - ``json``: the whole JSON (the settings, assumptions, the spec, trains…);
    - ``notes``: what the tool noted (stderr's ``note:`` lines);
    - ``column``/``units``: the channel analysed and its units (``g``, ``m/s2``, ``kgn``,
      ``n``), as the table's first line names them;
    - ``judged``/``failed``: impacts judged against ``spec=`` and how many failed.
      A failed verdict is a result, not an exception: ``passed`` is False.
    """

    json: dict
    notes: list
    judged: int
    failed: int
    column: Optional[str] = None
    units: Optional[str] = None
    impacts: pd.DataFrame = field(init=False, repr=False)
    null_reasons: pd.DataFrame = field(init=False, repr=False)
    spectra: list = field(init=False, repr=False)

    def __post_init__(self) -> None:
        imps = self.json.get("impacts", [])
        self.impacts = _impacts_frame(imps)
        self.null_reasons = _null_reasons_frame(imps, self.impacts.index)
        self.spectra = _spectra(imps)

    @property
    def passed(self) -> Optional[bool]:
        """Whether every judged impact passed the spec (None without ``spec=`` or when no
        impact could be judged)."""
        return None if self.judged == 0 else self.failed == 0

    @property
    def assumptions(self) -> list:
        """What the tool assumed that neither the file nor the options said."""
        return list(self.json.get("assumptions", []))

    def __getstate__(self):
        keep = ("json", "notes", "judged", "failed", "column", "units")
        return {k: getattr(self, k) for k in keep}

    def __setstate__(self, state) -> None:
        self.__dict__.update(state)
        self.__post_init__()

    def __repr__(self) -> str:
        v = "" if self.passed is None else f", {self.judged - self.failed} of {self.judged} pass"
        return f"<impact.Analysis: {len(self.impacts)} impacts{v}>"


def _analysed(result) -> Analysis:
    text, notes, judged, failed, column, units = result
    return Analysis(json=json.loads(text), notes=list(notes), judged=judged, failed=failed, column=column, units=units)


def _samples(source: Any) -> np.ndarray:
    """An array's samples as float64 (the array itself when it is float64, C-contiguous and
    aligned); real numbers only."""
    arr = np.asarray(source)
    if arr.dtype.kind not in "fiu":
        raise UsageError(f"an array of real numbers (float or integer), not {arr.dtype}")
    arr = np.require(arr, dtype=np.float64, requirements=["C", "A"])
    if arr.ndim != 1:
        raise UsageError(f"an array is one channel: 1-D samples, not shape {arr.shape}")
    return arr


def analyze(source: Union[PathLike, np.ndarray, Sequence[float]], *, rate: Optional[float] = None, units: Optional[str] = None, name: str = "array", **options: Any) -> Analysis:
    """Analyses a recording (a path) or samples in memory (an array with ``rate=`` in S/s
    and ``units=``; evenly spaced from time 0; ``name`` labels it), as ``impact analyze``
    does.

    Common options: ``mass=`` (kg), ``v0=`` (m/s), ``drop_height=`` (m), ``train="flight"``,
    ``spec="half-sine,100g,3ms"``, ``srs=True``, ``cfc=1000``, ``column=``, ``axes=``,
    ``range=``, ``trigger=``; every other ``impact analyze`` option by its name.

    A float64 array (C-contiguous, aligned) is read where it lies, without a copy; another
    dtype or a list is converted once. The analysis itself takes about 12 bytes a sample
    more (its signal and counts, as the command line's), refused with the need if that
    memory cannot be had. The array is read with the GIL released: do not write to it from
    another thread meanwhile.
    """
    opts = dict(rate=rate, units=units, **options)
    if isinstance(source, (str, os.PathLike, bytes)):
        return _analysed(_impact.analyze_file(_command(_path(source), opts)))
    arr = _samples(source)
    return _analysed(_impact.analyze_array(_command(str(name), opts), arr))


def spec(source: Union[PathLike, np.ndarray], spec: str, **options: Any) -> Analysis:
    """Judges every impact against a specified pulse (``spec="half-sine,100g,3ms"``; the
    standards' tolerances as ``impact analyze --spec``); ``analysis.passed`` and the
    ``spec.*`` columns hold the verdicts, ``analysis.json["spec"]`` the spec as judged."""
    return analyze(source, spec=spec, **options)


# --- series ----------------------------------------------------------------------------


@dataclass(eq=False)
class SeriesStatistics:
    """A series' statistics as ``impact analyze FILES… --json`` gives them.

    ``table``: one row per metric (n, mean, sd, cv, min, max; over the comparable impacts:
    complete, unclipped, each drop's first); ``left_out``: the impacts left out, by why;
    ``pass_rate``: with a spec; ``bounces``: the later bounces' statistics, by bounce."""

    json: dict
    table: pd.DataFrame = field(init=False)

    def __post_init__(self) -> None:
        columns = ["metric", "n", "mean", "sd", "cv", "min", "max", "null_reason"]
        self.table = pd.DataFrame.from_records(self.json.get("statistics", []), columns=columns).set_index("metric")

    @property
    def left_out(self) -> dict:
        return dict(self.json.get("statistics_left_out", {}))

    @property
    def pass_rate(self) -> Optional[dict]:
        return self.json.get("spec")

    @property
    def bounces(self) -> list:
        return list(self.json.get("bounce_statistics", []))


def statistics(analyses: Iterable[Analysis]) -> SeriesStatistics:
    """The series' statistics over analyses made one by one (on other processes or
    machines: Dask, Ray, Spark), in the series' order: the tool's own computation, equal to
    ``impact analyze FILES… --json``'s on the same recordings."""
    impacts = [i for a in analyses for i in a.json.get("impacts", [])]
    return SeriesStatistics(json=json.loads(_impact.statistics(json.dumps(impacts))))


@dataclass(eq=False)
class Series:
    """A test series (``impact analyze FILES…``): every recording's impacts in one
    DataFrame (``file`` and ``channel`` first), why each null is null, the spectra, the
    statistics, and the recordings that failed (each with its error: a failed recording is
    a result, not an exception). ``notes`` are the notes of the whole run; each recording's
    own are its entry's (``json["entries"][k]["notes"]``)."""

    json: dict
    notes: list
    impacts: pd.DataFrame = field(init=False, repr=False)
    null_reasons: pd.DataFrame = field(init=False, repr=False)
    spectra: list = field(init=False, repr=False)
    statistics: SeriesStatistics = field(init=False, repr=False)

    def __post_init__(self) -> None:
        rows, extra = [], []
        for e in self.json.get("entries", []):
            for i in e.get("impacts", []):
                rows.append(i)
                extra.append({"file": e["file"], "channel": e["channel"]})
        # (No impact: the columns still there, `file` and `channel` first.)
        self.impacts = _impacts_frame(rows, extra if rows else [{"file": None, "channel": None}])
        self.null_reasons = _null_reasons_frame(rows, self.impacts.index)
        self.spectra = _spectra(rows)
        self.statistics = SeriesStatistics(json={k: v for k, v in self.json.items() if k != "entries"})

    @property
    def failures(self) -> dict:
        """Each recording that failed: its file and channel, and the tool's message."""
        return {(e["file"], e["channel"]): e["error"] for e in self.json.get("entries", []) if "error" in e}

    @property
    def passed(self) -> Optional[bool]:
        """Whether every judged impact of the series passed (None without a spec, or when
        none could be judged); as the command line's exit status 3."""
        rate = self.json.get("spec")
        if not rate or not rate.get("judged"):
            return None
        return rate["passed"] == rate["judged"]


def series(files: Iterable[PathLike], **options: Any) -> Series:
    """Analyses recordings (files, folders, quoted patterns such as ``"runs/*.csv"``) with
    the same options, in parallel on this machine, as ``impact analyze FILES…``; for many
    machines map :func:`analyze` with Dask and gather with :func:`statistics`."""
    if isinstance(files, (str, os.PathLike, bytes)):
        raise UsageError("series() takes a list of recordings (one path: impact.analyze)")
    paths = [_path(f) for f in files]
    if not paths:
        raise UsageError("a series needs at least one recording")
    text, notes = _impact.series(_command(paths[0], options), paths)
    return Series(json=json.loads(text), notes=list(notes))


# --- simulation ------------------------------------------------------------------------


def simulate(model: str, **options: Any) -> dict:
    """One impact of a contact model (``hertz``, ``linear``, ``kelvin-voigt``,
    ``two-phase``, ``nonlinear``…) on a rigid wall or a target, as ``impact simulate
    --json``: ``impact.simulate("hertz", mass=8.419e-3, v0=2, radius=6.35e-3,
    youngs=200e9, poisson=0.3)``. The result is the JSON as a dict; its time series, if any,
    as NumPy arrays."""
    out = json.loads(_impact.simulate(_argv(dict(model=model, **options)) + ["--"]))
    return _arrays(out)


def _arrays(v: Any) -> Any:
    """Lists of numbers in a JSON value as float64 arrays (recursively)."""
    if isinstance(v, dict):
        return {k: _arrays(x) for k, x in v.items()}
    if isinstance(v, list) and v and all(isinstance(x, (int, float)) and not isinstance(x, bool) for x in v):
        return np.asarray(v, dtype=np.float64)
    if isinstance(v, list):
        return [_arrays(x) for x in v]
    return v
