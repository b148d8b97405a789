"""Files: trajectories (CSV / NPY) and model files (``.npz`` + JSON metadata, never pickles).

Every write goes to a temporary file in the target folder and is then renamed over the target,
so an interrupted write never leaves a half-written file behind.

Model file layout (format version 1): an uncompressed ``.npz`` archive holding the model's arrays
under their attribute names plus ``__bidmp__``, a uint8 array with UTF-8 JSON::

    {"format": "bidmp-model", "format_version": 1, "class": "DMP",
     "bidmp_version": "0.1.0", "state": {...class-specific, e.g. constructor params...}}

It is read with ``allow_pickle=False``, so loading a file can never execute code.
"""

from __future__ import annotations

import contextlib
import csv
import json
import logging
import os
import tempfile
import zipfile
from collections.abc import Iterator
from pathlib import Path

import numpy as np

from ._checks import as_trajectory

__all__ = [
    "ModelFileError",
    "FORMAT_VERSION",
    "save_model",
    "load_model",
    "load_trajectory",
    "save_trajectory",
    "atomic_write",
]

logger = logging.getLogger(__name__)

FORMAT_VERSION = 2
# Format 2 (bidmp 0.2): Bi-DMP increments are gated by the phase and the DMP's regression is stored
# as "regression". Format-1 DMP and BLS files still load; format-1 Bi-DMP files do not, because
# their blocks were trained on the ungated increment and would roll out wrongly.
_MIN_VERSION = {"BiDMP": 2}
_FORMAT_NAME = "bidmp-model"
_META_KEY = "__bidmp__"
# Model classes that may appear in a file: name -> (module, attribute). Imported lazily so that
# reading a DMP does not import the whole pipeline.
_MODEL_CLASSES = {
    "DMP": ("bidmp.dmp", "DMP"),
    "BLS": ("bidmp.bls", "BLS"),
    "BiDMP": ("bidmp.incremental", "BiDMP"),
}


class ModelFileError(ValueError):
    """A model file is missing, corrupt, truncated, foreign, or from a newer bidmp."""


# ---------------------------------------------------------------------------------------------
# Atomic writes
# ---------------------------------------------------------------------------------------------
@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "wb") -> Iterator:
    """Open a temporary file beside ``path``; on success fsync it and rename it onto ``path``.

    On any exception the temporary file is removed and ``path`` is left as it was.
    """
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    if not directory.is_dir():
        raise ValueError(f"cannot write {path}: folder {directory} does not exist")
    fd, tmp_name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=directory)
    try:
        with os.fdopen(fd, mode, **({} if "b" in mode else {"encoding": "utf-8", "newline": ""})) as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp_name, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp_name)
        raise


# ---------------------------------------------------------------------------------------------
# Model files
# ---------------------------------------------------------------------------------------------
def _model_class(name: str):
    import importlib

    module_name, attribute = _MODEL_CLASSES[name]
    return getattr(importlib.import_module(module_name), attribute)


def save_model(model, path: str | os.PathLike) -> Path:
    """Save a fitted model to ``path`` (``.npz``; the suffix is added if missing).

    Returns
    -------
    path : Path
        The path written.
    """
    from . import __version__

    class_name = type(model).__name__
    if class_name not in _MODEL_CLASSES or not hasattr(model, "_get_state"):
        raise TypeError(f"model must be one of {', '.join(sorted(_MODEL_CLASSES))}, got {class_name}")
    state, arrays = model._get_state()
    if _META_KEY in arrays:
        raise ValueError(f"array name {_META_KEY!r} is reserved")
    meta = {
        "format": _FORMAT_NAME,
        "format_version": FORMAT_VERSION,
        "class": class_name,
        "bidmp_version": __version__,
        "state": state,
    }
    payload = {name: np.asarray(value) for name, value in arrays.items()}
    payload[_META_KEY] = np.frombuffer(json.dumps(meta, allow_nan=False).encode("utf-8"), dtype=np.uint8)
    path = Path(path)
    if path.suffix != ".npz":
        path = path.with_name(path.name + ".npz")
    with atomic_write(path, "wb") as handle:
        np.savez(handle, **payload)
    logger.debug("saved %s to %s", class_name, path)
    return path


def load_model(path: str | os.PathLike):
    """Load a model written by :func:`save_model`.

    Raises
    ------
    ModelFileError
        If the file is missing, not an ``.npz`` archive, truncated or corrupt, has no bidmp
        metadata (a foreign file), was written by a newer format version, or its contents are
        inconsistent.
    """
    path = Path(path)
    if not path.is_file():
        raise ModelFileError(f"model file {path} does not exist")
    try:
        archive = np.load(path, allow_pickle=False)
        if not isinstance(archive, np.lib.npyio.NpzFile):
            raise ModelFileError(f"{path} is not a bidmp model file (a plain .npy array, not an .npz archive)")
        with archive:
            if _META_KEY not in archive.files:
                raise ModelFileError(f"{path} is not a bidmp model file (an .npz archive without bidmp metadata)")
            meta = json.loads(archive[_META_KEY].tobytes().decode("utf-8"))
            # Fresh C-contiguous copies: computing with them then takes the same BLAS paths as
            # the saved model did, so rollouts after loading are bit-identical.
            arrays = {name: np.array(archive[name], order="C") for name in archive.files if name != _META_KEY}
    except ModelFileError:
        raise
    except (zipfile.BadZipFile, zipfile.LargeZipFile, EOFError, OSError, ValueError, KeyError, UnicodeDecodeError) as exc:
        raise ModelFileError(f"{path} is not a readable bidmp model file ({type(exc).__name__}: {exc})") from exc

    if not isinstance(meta, dict) or meta.get("format") != _FORMAT_NAME:
        raise ModelFileError(f"{path} is not a bidmp model file (unknown metadata format)")
    version = meta.get("format_version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise ModelFileError(f"{path} has an invalid format_version {version!r}")
    if version > FORMAT_VERSION:
        raise ModelFileError(
            f"{path} was written in model format {version} by bidmp {meta.get('bidmp_version', '?')}; "
            f"this bidmp reads format {FORMAT_VERSION} or older: upgrade bidmp"
        )
    class_name = meta.get("class")
    if class_name not in _MODEL_CLASSES:
        raise ModelFileError(f"{path} holds an unknown model class {class_name!r}")
    if version < _MIN_VERSION.get(class_name, 1):
        raise ModelFileError(
            f"{path} holds a {class_name} in model format {version} (bidmp {meta.get('bidmp_version', '?')}), whose "
            f"learned increments did not vanish with the phase; this bidmp cannot use it: learn the skills again"
        )
    try:
        model = _model_class(class_name)._from_state(meta["state"], arrays)
    except (KeyError, TypeError, ValueError) as exc:
        raise ModelFileError(f"{path} is corrupt: {class_name} state is inconsistent ({exc})") from exc
    return model


# ---------------------------------------------------------------------------------------------
# Trajectories
# ---------------------------------------------------------------------------------------------
_TIME_NAMES = ("t", "time")
_POSITION_HEADERS = (("x", "y"), ("x", "y", "z"))


def _parse_float(text: str) -> float | None:
    try:
        return float(text)
    except ValueError:
        return None


def _read_csv(path: Path) -> tuple[np.ndarray, np.ndarray | None]:
    """Read a CSV trajectory; return (positions (T, D), times (T,) or None)."""
    try:
        with open(path, newline="", encoding="utf-8") as handle:
            sample = handle.read(4096)
            handle.seek(0)
            delimiter = ";" if sample.count(";") > sample.count(",") else ","
            rows = [(number, [cell.strip() for cell in row]) for number, row in enumerate(csv.reader(handle, delimiter=delimiter), 1)]
    except UnicodeDecodeError:
        raise ValueError(f"{path} is not a text CSV file") from None
    rows = [(number, row) for number, row in rows if any(row) and not row[0].startswith("#")]
    if not rows:
        raise ValueError(f"{path} is empty: no data rows")

    columns: tuple[str, ...] | None = None
    first_number, first_row = rows[0]
    if any(_parse_float(cell) is None for cell in first_row):
        columns = tuple(cell.lower() for cell in first_row)
        rows = rows[1:]
        if not rows:
            raise ValueError(f"{path} has a header but no data rows")
    n_columns = len(columns) if columns else len(rows[0][1])

    values = np.empty((len(rows), n_columns))
    for index, (number, row) in enumerate(rows):
        if len(row) != n_columns:
            raise ValueError(f"{path} line {number}: expected {n_columns} columns, found {len(row)}")
        for column, cell in enumerate(row):
            value = _parse_float(cell)
            if value is None:
                raise ValueError(f"{path} line {number}: {cell!r} is not a number")
            values[index, column] = value

    if columns is not None:
        has_time = columns[0] in _TIME_NAMES
        names = columns[1:] if has_time else columns
        if names not in _POSITION_HEADERS:
            raise ValueError(
                f"{path}: header {','.join(columns)} not understood; expected x,y[,z] or t,x,y[,z]"
            )
    elif n_columns in (2, 3):
        has_time = False  # header-less: positions only (add a header "t,x,y" to mark a time column)
    elif n_columns == 4:
        has_time = True
    else:
        raise ValueError(f"{path}: expected 2-4 columns (x,y[,z] or t,x,y,z), found {n_columns}")
    if has_time:
        return values[:, 1:], values[:, 0]
    return values, None


def _resample_uniform(positions: np.ndarray, times: np.ndarray, source: str) -> np.ndarray:
    """Resample positions given at ``times`` onto a uniform grid with the same number of samples."""
    if not np.all(np.isfinite(times)):
        raise ValueError(f"{source}: the time column contains NaN or inf")
    steps = np.diff(times)
    if np.any(steps <= 0):
        row = int(np.argmax(steps <= 0)) + 1
        raise ValueError(f"{source}: time must increase strictly (row {row} does not)")
    if np.ptp(steps) <= 1e-9 * np.mean(steps):
        return positions
    logger.info("%s: time stamps are not uniform; resampling to %d uniform samples", source, len(times))
    grid = np.linspace(times[0], times[-1], len(times))
    return np.column_stack([np.interp(grid, times, column) for column in positions.T])


def load_trajectory(path: str | os.PathLike) -> np.ndarray:
    """Read a demonstration from ``.csv`` or ``.npy``.

    CSV: one sample per row, comma (or semicolon) separated, ``#`` comments allowed. An optional
    header names the columns ``x,y[,z]`` or ``t,x,y[,z]`` (``time`` also works). Without a header
    2 or 3 columns are positions and 4 columns are ``t,x,y,z``. With a time column the samples are
    resampled to uniform time steps (a DMP assumes them).
    NPY: a float array of shape (T, D), read with ``allow_pickle=False``.

    Returns
    -------
    y : array, shape (T, D)
        Validated: finite, at least 3 points, not all identical.
    """
    path = Path(path)
    if not path.is_file():
        raise ValueError(f"demonstration file {path} does not exist")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        try:
            positions = np.load(path, allow_pickle=False)
        except (ValueError, OSError, EOFError) as exc:
            raise ValueError(f"{path} is not a readable .npy array ({exc})") from None
        if not np.issubdtype(positions.dtype, np.number):
            raise ValueError(f"{path} holds {positions.dtype} data, not numbers")
    elif suffix in (".csv", ".txt"):
        positions, times = _read_csv(path)
        if times is not None:
            positions = _resample_uniform(positions, times, str(path))
    else:
        raise ValueError(f"{path}: unsupported file type {suffix or '(none)'}; use .csv or .npy")
    return as_trajectory(positions, name=str(path))


def save_trajectory(y, path: str | os.PathLike, times=None) -> Path:
    """Write a trajectory ``y`` (T, D) to ``path``: ``.csv`` (header ``[t,]x,y[,z]``; ``times``
    (T,) in seconds adds the ``t`` column) or ``.npy``, atomically.

    The argument order is the same as :func:`save_model` (what, then where).
    """
    if isinstance(y, (str, os.PathLike)) and not isinstance(path, (str, os.PathLike)):
        raise TypeError("save_trajectory takes (y, path): the trajectory first, then the file (as save_model)")
    path = Path(path)
    y = np.asarray(y, dtype=np.float64)
    if y.ndim != 2:
        raise ValueError(f"y must have shape (T, D), got {y.shape}")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        with atomic_write(path, "wb") as handle:
            np.save(handle, y, allow_pickle=False)
        return path
    if suffix != ".csv":
        raise ValueError(f"{path}: unsupported file type {suffix or '(none)'}; use .csv or .npy")
    names = ["x", "y", "z"][: y.shape[1]] if y.shape[1] <= 3 else [f"x{i}" for i in range(y.shape[1])]
    data = y
    if times is not None:
        times = np.asarray(times, dtype=np.float64).reshape(-1)
        if times.shape[0] != y.shape[0]:
            raise ValueError(f"times has {times.shape[0]} entries for {y.shape[0]} samples")
        names = ["t", *names]
        data = np.column_stack([times, y])
    with atomic_write(path, "w") as handle:
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(names)
        writer.writerows([[repr(float(v)) for v in row] for row in data])
    return path
