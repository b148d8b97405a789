"""Reading trajectory CSVs as loggers write them: a header (``t,x,y,z`` and the like, or mapped
columns), comment lines (``# units: mm``), any delimiter; a fast path for clean files and a
row-by-row one that names a bad line."""

from __future__ import annotations

import contextlib
import csv
import itertools
import logging
import warnings
from pathlib import Path

import numpy as np

from .._checks import check_limit, check_path, get_limits, short_token
from ._columns import TIME_NAMES, parse_columns

__all__ = ['declared_units']

logger = logging.getLogger(__name__)


_TIME_NAMES = TIME_NAMES

_SLOW_CSV_BYTES = 256 << 20  # CSVs read row by row (to name a bad line): Python rows take ~6x the bytes
_POSITION_HEADERS = (("x", "y"), ("x", "y", "z"))


def _parse_float(text: str) -> float | None:
    try:
        return float(text)
    except (ValueError, OverflowError):
        return None


def _check_file(path: Path, what: str) -> None:
    if not path.exists():
        raise ValueError(f"{what} {path} does not exist")
    if path.is_dir():
        raise ValueError(f"{what} {path} is a folder, not a file")
    if not path.is_file():
        raise ValueError(f"{what} {path} is not a regular file")
    check_limit(path.stat().st_size, "max_file_bytes", f"the size of {path} in bytes")


def _timed_columns(columns: tuple[str, ...]) -> int | None:
    """For a header ``t,x,y[,z],vx,…,ax,…`` (what :func:`save_trajectory` writes for a
    :class:`bidmp.Trajectory`): the number of position columns; None for other headers."""
    if not columns or columns[0] not in _TIME_NAMES:
        return None
    for names in _POSITION_HEADERS:
        if columns[1:] == (*names, *(f"v{n}" for n in names), *(f"a{n}" for n in names)):
            return len(names)
    return None


def _note_ignored(path: Path, ignored: tuple[str, ...]) -> None:
    if ignored:
        shown = ", ".join(short_token(name, 16)[1:-1] for name in ignored[:8]) + (", …" if len(ignored) > 8 else "")
        logger.warning("%s: ignored %d column(s) that are not time or positions: %s", path, len(ignored), shown)


def _read_csv(path: Path, columns=None) -> tuple[np.ndarray, np.ndarray | None]:
    """Read a CSV trajectory; return (positions (T, D), times (T,) or None). ``columns``: a
    column mapping (:func:`bidmp._columns.parse_columns`)."""
    from ._columns import select_joints, select_poses, select_positions

    mapping = parse_columns(columns)
    parsed = _csv_fast(path)
    header, values = parsed if parsed is not None else _csv_rows(path)
    n_columns = values.shape[1]
    if header is None:
        if mapping is not None:
            raise ValueError(f"{path} has no header, so --columns / columns= cannot name its columns")
        if n_columns in (2, 3):  # header-less: positions only (add a header "t,x,y" to mark a time column)
            return values, None
        if n_columns == 4:
            return values[:, 1:], values[:, 0]
        raise ValueError(f"{path}: expected 2-4 columns (x,y[,z] or t,x,y,z) without a header, found {n_columns}")
    n_positions = _timed_columns(header)
    if n_positions is not None and mapping is None:  # a timed trajectory written by bidmp
        return values[:, 1 : 1 + n_positions], values[:, 0]
    if mapping is None and select_poses(header, None, path).values:
        raise ValueError(f"{path}: a pose recording: read it with bidmp.io.read_poses / bidmp.CartesianDMP (its header "
                         f"names qx, qy, qz, qw)")
    selection = select_positions(header, mapping, path)
    if not selection.values and mapping is None:  # t, <joint names>: a joint-space recording
        selection = select_joints(header)
    if not selection.values:
        shown = ",".join(short_token(c, 12)[1:-1] for c in header[:8]) + (",…" if len(header) > 8 else "")
        raise ValueError(f"{path}: header {shown} names no positions; expected x,y[,z] with an optional t/time/timestamp "
                         f"column, t,<joint names> for joint space, or name them with a column mapping (--columns "
                         f"t=stamp,x=ee_x,y=ee_y,z=ee_z)")
    _note_ignored(path, selection.ignored)
    times = None if selection.time is None else values[:, selection.time]
    return values[:, list(selection.values)], times


def declared_units(path) -> str:
    """The unit a CSV declares in a leading comment line ``# units: mm`` ("" if none)."""
    from .._units import check_units

    if not check_path(path).is_file():  # a FIFO or a device: the reader refuses it; opening it would block
        return ""
    try:
        with open(path, encoding="utf-8-sig") as handle:
            for _ in range(16):
                line = handle.readline(4096).strip()
                if not line.startswith("#"):
                    break
                key, _, value = line[1:].partition(":")
                if key.strip().lower() == "units":
                    return check_units(value.strip(), f"{path}: the declared units")
    except (OSError, UnicodeDecodeError):
        return ""
    return ""


def is_joint_recording(path) -> bool:
    """Whether a CSV's header is a joint-space recording ``t, <joint names>`` (no position or
    quaternion named): its values are joint angles, in radians unless it declares otherwise."""
    from ._columns import select_joints, select_positions

    path = check_path(path)
    if not path.is_file():
        return False
    try:
        with open(path, encoding="utf-8-sig") as handle:
            for _ in range(16):
                line = handle.readline(1 << 16).strip()
                if line and not line.startswith("#"):
                    break
    except (OSError, UnicodeDecodeError):
        return False
    header = tuple(name.strip() for name in line.split(_csv_delimiter(line)))
    if not line or not any(name and not _is_number(name) for name in header):
        return False
    return not select_positions(header, None, path).values and bool(select_joints(header).values)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _csv_delimiter(sample: str) -> str:
    return ";" if sample.count(";") > sample.count(",") else ","


def _row_limit_error(path: Path) -> ValueError:
    limit = get_limits().max_samples
    return ValueError(f"{path}: more than {limit:,} rows, the limit max_samples; raise it with bidmp.set_limits(max_samples=...)")


def _csv_fast(path: Path) -> tuple[tuple[str, ...] | None, np.ndarray] | None:
    """The common case, parsed by NumPy's C reader (a 1e6-row recording in about a second):
    an optional header line, then plain numbers. Returns None for anything else (quotes, ragged or
    bad rows, odd text), which :func:`_csv_rows` then reads row by row to name the problem."""
    limits = get_limits()
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            delimiter = _csv_delimiter(handle.read(4096))
            handle.seek(0)
            columns, first = None, None
            while True:
                line = handle.readline(1 << 16)
                if not line or not line.endswith(("\n", "\r")) and len(line) >= 1 << 16:
                    return None  # empty, or a line too long for a plain row
                stripped = line.strip()
                if stripped and not stripped.startswith("#"):
                    break
            cells = [cell.strip() for cell in stripped.split(delimiter)]
            if any(_parse_float(cell) is None for cell in cells):
                columns = tuple(cell.lower() for cell in cells)
            else:
                first = line
            lines = itertools.chain([first], handle) if first is not None else handle
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # "empty input": the slow path words it
                values = np.loadtxt(lines, delimiter=delimiter, comments="#", ndmin=2, dtype=np.float64,
                                    max_rows=limits.max_samples + 1, encoding=None)
    except (ValueError, TypeError, OSError, UnicodeDecodeError, OverflowError, MemoryError):
        return None
    if values.shape[0] == 0 or values.shape[1] > limits.max_dims + 1:
        return None
    if columns is not None and values.shape[1] != len(columns):
        return None
    if values.shape[0] > limits.max_samples:
        raise _row_limit_error(path)
    return columns, values


def _csv_rows(path: Path) -> tuple[tuple[str, ...] | None, np.ndarray]:
    """Row-by-row CSV reading with the csv module: quotes, comments, and an error that names the
    first bad line (quoting at most a short token of it)."""
    limits = get_limits()
    max_rows = limits.max_samples + 1  # + a header
    max_columns = limits.max_dims + 1  # + a time column
    if path.stat().st_size > _SLOW_CSV_BYTES:  # Python rows take ~6x the file's size in memory
        raise ValueError(f"{path} is not a plain numeric CSV (one optional header line, then numbers in every row), "
                         f"and at {path.stat().st_size / 2**20:.0f} MiB it is too large to read row by row to find the "
                         f"bad line (limit {_SLOW_CSV_BYTES >> 20} MiB)")
    rows: list[tuple[int, list[str]]] = []
    try:
        # utf-8-sig: Excel writes a byte-order mark at the start of UTF-8 files.
        with open(path, newline="", encoding="utf-8-sig") as handle:
            delimiter = _csv_delimiter(handle.read(4096))
            handle.seek(0)
            reader = csv.reader(handle, delimiter=delimiter)
            try:
                for row in reader:
                    if not any(row) or row[0].lstrip().startswith("#"):
                        continue
                    if len(row) > max_columns:
                        raise ValueError(f"{path} line {reader.line_num}: {len(row):,} columns, more than the limit "
                                         f"max_dims = {limits.max_dims} allows (plus a time column)")
                    rows.append((reader.line_num, [cell.strip() for cell in row]))
                    if len(rows) > max_rows:
                        raise _row_limit_error(path)
            except csv.Error as exc:
                raise ValueError(f"{path} line {reader.line_num}: not a CSV row ({exc})") from None
    except UnicodeDecodeError:
        raise ValueError(f"{path} is not a UTF-8 text CSV file") from None
    if not rows:
        raise ValueError(f"{path} is empty: no data rows")

    columns: tuple[str, ...] | None = None
    _, first_row = rows[0]
    if any(_parse_float(cell) is None for cell in first_row):
        columns = tuple(cell.lower() for cell in first_row)
        rows = rows[1:]
        if not rows:
            raise ValueError(f"{path} has a header but no data rows")
    n_columns = len(columns) if columns else len(rows[0][1])
    return columns, _csv_values(rows, n_columns, path)


def _csv_values(rows: list[tuple[int, list[str]]], n_columns: int, path: Path) -> np.ndarray:
    """The numbers of the data rows (T, n_columns): NumPy's parser first (fast), and on failure a
    row-by-row pass that names the first bad line (quoting at most a short token of it)."""
    cells = [row for _, row in rows]
    with contextlib.suppress(ValueError, TypeError, OverflowError):
        values = np.array(cells, dtype=np.float64)
        if values.ndim == 2 and values.shape[1] == n_columns:
            return values
    for number, row in rows:
        if len(row) != n_columns:
            raise ValueError(f"{path} line {number}: expected {n_columns} columns, found {len(row)}")
        for column, cell in enumerate(row, 1):
            if _parse_float(cell) is None:
                raise ValueError(f"{path} line {number}, column {column}: {short_token(cell)} is not a number")
    raise ValueError(f"{path}: the data rows could not be read as numbers")  # pragma: no cover


def _check_npy_trajectory(path: Path):
    limits = get_limits()

    def check(shape, dtype):
        if dtype.names is not None:  # a timed trajectory: one record per sample
            if len(shape) != 1 or not _timed_fields(dtype):
                raise ValueError(f"{path} holds records with fields {', '.join(dtype.names[:8])}; expected t, x, y[, z] "
                                 f"(and optionally vx, … ax, …) in shape (T,)")
            if shape[0] > limits.max_samples:
                raise ValueError(f"{path} has {shape[0]:,} samples, over the limit max_samples = {limits.max_samples:,}")
            return
        if dtype.kind not in "fiu":
            raise ValueError(f"{path} holds {dtype} data, not numbers")
        if len(shape) != 2:
            raise ValueError(f"{path} must hold an array of shape (T, D), got shape {shape}")
        if shape[0] > limits.max_samples:
            raise ValueError(f"{path} has {shape[0]:,} samples, over the limit max_samples = {limits.max_samples:,}; "
                             f"raise it with bidmp.set_limits(max_samples=...)")
        if shape[1] > limits.max_dims:
            raise ValueError(f"{path} has {shape[1]:,} columns, over the limit max_dims = {limits.max_dims}")

    return check


def _timed_fields(dtype: np.dtype) -> tuple[str, ...] | None:
    """The position fields of a structured timed-trajectory dtype (``t`` plus x, y[, z]; real
    numbers), or None."""
    names = dtype.names or ()
    if "t" not in names:
        return None
    for positions in reversed(_POSITION_HEADERS):
        if all(name in names for name in positions) and all(dtype[n].kind in "fiu" and dtype[n].shape == () for n in ("t", *positions)):
            return positions
    return None
