"""precursors: the scalar elastic model of frictional precursors (Taloni, Benassi,
Sandfeld, Zapperi), from Python.

The Rust crate ``precursors`` behind numpy arrays: scenes, the quasi-static driver and its
events, the state between events as ``(Ny, Nx)`` float64 arrays (row ``iy``, column
``ix``), stress probes, checkpoints, runs, sweeps, merges and figures. Units are SI.
"""

# Imported under private names: `dir(precursors)` lists the package's own names only.
from pathlib import Path as _Path
from typing import Any as _Any, Dict as _Dict, Union as _Union

import numpy as _np

from ._errors import (
    CudaUnavailableError,
    NotConvergedError,
    PrecursorsError,
    PrecursorsOSError,
    PrecursorsValueError,
)
from ._precursors import (
    ATTACHED,
    BROKEN,
    DETACHED,
    Checkpoint,
    Driver,
    Event,
    PlaneStress,
    PointStress,
    Scene,
    __version__,
    fit_power_law,
    merge_files as _merge_files,
    stats_files as _stats_files,
    movie,
    plot,
    run,
    sweep,
)
from ._scene import SurfaceSpectrum
from ._tables import read_table

__all__ = [
    "ATTACHED",
    "BROKEN",
    "DETACHED",
    "Checkpoint",
    "Driver",
    "Event",
    "CudaUnavailableError",
    "NotConvergedError",
    "PlaneStress",
    "PointStress",
    "PrecursorsError",
    "PrecursorsOSError",
    "PrecursorsValueError",
    "Scene",
    "SurfaceSpectrum",
    "__version__",
    "fit_power_law",
    "merge",
    "movie",
    "plot",
    "read_table",
    "read_tables",
    "run",
    "stats",
    "sweep",
]


def read_tables(directory: _Union[str, _Path]) -> _Dict[str, _Dict[str, _np.ndarray]]:
    """The tables of a run directory (``events``, ``curve``, ``contact_map``, those a
    finished run derives from them, ``per_avalanche`` and ``fronts``, and ``profiles``
    when the run records them; those that are complete) as dicts of columns (see
    ``read_table``)."""
    directory = _Path(directory)
    return {
        name: read_table(directory / f"{name}.csv")
        for name in ("events", "curve", "contact_map", "per_avalanche", "fronts", "profiles")
        if (directory / f"{name}.csv").is_file()
    }


def stats(directory: _Union[str, _Path], **options: _Any) -> _Dict[str, _Dict[str, _np.ndarray]]:
    """The statistics of a run or sweep directory (as ``precursors stats``: avalanche
    sizes, force drops, energies and front leaps pooled per point, their power-law fits
    and log-binned distributions, written as ``power_laws.csv`` and ``distributions.csv``
    in it), returned by file name without ``.csv`` as dicts of columns. ``options``:
    ``bootstrap``, ``goodness``, ``confidence``, ``min_tail``, ``bins_per_decade``,
    ``seed``, ``include_spanning`` (pool the spanning avalanche and those after it too;
    docs/statistics.md)."""
    return {_Path(p).stem: read_table(p) for p in _stats_files(directory, **options)}


def merge(directory: _Union[str, _Path]) -> _Dict[str, _Dict[str, _np.ndarray]]:
    """Merges the runs of a sweep directory (as ``precursors merge``: the ensemble
    statistics as CSV files in it) and returns the merged tables, by file name without
    ``.csv``, as dicts of columns."""
    return {_Path(p).stem: read_table(p) for p in _merge_files(directory)}
