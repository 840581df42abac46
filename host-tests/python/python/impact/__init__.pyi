# Type stubs of the `impact` package (editors and type checkers complete and check from
# them). The runtime is __init__.py over the Rust extension `_impact`.
import os
from typing import Any, Iterable, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt
import pandas as pd

__version__: str

PathLike = Union[str, os.PathLike[str]]

class ImpactError(Exception):
    """What the impact tool refused or could not do; its message is the tool's."""

class UsageError(ImpactError):
    """An option the tool does not take, or a value it refuses (`mass=` is `--mass`)."""

class ReadError(ImpactError):
    """The recording (or a file an option names) could not be read."""

class AnalysisError(ImpactError):
    """The recording was read but could not be analysed with these settings."""

class SimulationError(ImpactError):
    """The model or its parameters refused."""

class Recording:
    samples: npt.NDArray[np.float64]
    time_s: npt.NDArray[np.float64]
    rate_hz: float
    column: str
    units: str
    to_m_s2: Optional[float]
    assumptions: list[str]
    resampled: bool
    jitter: float
    axes: dict[str, npt.NDArray[np.float64]]
    metadata: dict[str, Any]
    notes: list[str]
    def to_frame(self) -> pd.DataFrame: ...

def read(
    path: PathLike,
    *,
    column: Union[str, int, None] = ...,
    units: Optional[str] = ...,
    axes: Optional[Sequence[Union[str, int]]] = ...,
    rate: Optional[float] = ...,
    time_column: Union[str, int, None] = ...,
    time_unit: Optional[str] = ...,
    resample: bool = ...,
    delimiter: Optional[str] = ...,
    decimal_comma: bool = ...,
    raw_channels: Optional[int] = ...,
    raw_type: Optional[str] = ...,
    mass: Optional[float] = ...,
    gain: Optional[float] = ...,
    invert: bool = ...,
    scene: Optional[PathLike] = ...,
) -> Recording: ...

class Analysis:
    json: dict[str, Any]
    notes: list[str]
    judged: int
    failed: int
    column: Optional[str]
    units: Optional[str]
    impacts: pd.DataFrame
    null_reasons: pd.DataFrame
    spectra: list[Optional[dict[str, npt.NDArray[np.float64]]]]
    @property
    def passed(self) -> Optional[bool]: ...
    @property
    def assumptions(self) -> list[str]: ...

def analyze(
    source: Union[PathLike, npt.ArrayLike],
    *,
    rate: Optional[float] = ...,
    units: Optional[str] = ...,
    name: str = ...,
    column: Union[str, int, None] = ...,
    axes: Optional[Sequence[Union[str, int]]] = ...,
    mass: Optional[float] = ...,
    v0: Optional[float] = ...,
    drop_height: Optional[float] = ...,
    train: Optional[str] = ...,
    spec: Optional[str] = ...,
    srs: bool = ...,
    cfc: Optional[int] = ...,
    range: Optional[str] = ...,
    trigger: Optional[str] = ...,
    edge: Optional[str] = ...,
    scene: Optional[PathLike] = ...,
    plot: Optional[PathLike] = ...,
    **options: Any,
) -> Analysis: ...
def spec(source: Union[PathLike, npt.ArrayLike], spec: str, **options: Any) -> Analysis: ...

class SeriesStatistics:
    json: dict[str, Any]
    table: pd.DataFrame
    @property
    def left_out(self) -> dict[str, int]: ...
    @property
    def pass_rate(self) -> Optional[dict[str, Any]]: ...
    @property
    def bounces(self) -> list[dict[str, Any]]: ...

def statistics(analyses: Iterable[Analysis]) -> SeriesStatistics: ...

class Series:
    json: dict[str, Any]
    notes: list[str]
    impacts: pd.DataFrame
    null_reasons: pd.DataFrame
    spectra: list[Optional[dict[str, npt.NDArray[np.float64]]]]
    statistics: SeriesStatistics
    @property
    def failures(self) -> dict[tuple[str, str], str]: ...
    @property
    def passed(self) -> Optional[bool]: ...

def series(files: Sequence[PathLike], **options: Any) -> Series: ...
def simulate(model: str, **options: Any) -> dict[str, Any]: ...
