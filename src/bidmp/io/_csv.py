"""Reading trajectory CSVs as loggers write them: a header (``t,x,y,z`` and the like, or mapped
columns), comment lines (``# units: mm``), any delimiter; a fast path for clean files and a
row-by-row one that names a bad line."""

from __future__ import annotations

import contextlib
import csv
import itertools
import logging
import re
import warnings
from pathlib import Path

import numpy as np

from .._checks import check_limit, check_path, get_limits, short_token

__all__ = ["declared_units"]

logger = logging.getLogger(__name__)

# CSVs read row by row (to name a bad line): Python rows take ~6x the bytes
_SLOW_CSV_BYTES = 256 << 20


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


def _note_ignored(path: Path, ignored: tuple[str, ...]) -> None:
    if ignored:
        shown = ", ".join(short_token(name, 28)[1:-1] for name in ignored[:8]) + (
            ", …" if len(ignored) > 8 else ""
        )
        logger.warning(
            "%s: ignored %d column(s) that are not time or the motion read: %s",
            path,
            len(ignored),
            shown,
        )


def declared_units(path) -> str:
    """The unit a CSV declares in a leading comment line ``# units: mm`` ("" if none)."""
    from .._units import check_units

    if not check_path(
        path
    ).is_file():  # a FIFO or a device: the reader refuses it; opening it would block
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


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def _csv_delimiter(sample: str) -> str:
    """``,`` or ``;`` (the more frequent in the sample; ``;`` when the first line, a header, has
    ``;`` and no ``,``: the rows' decimal commas then do not count), else a tab, else spaces (UR's
    RTDE recorder writes space-separated files)."""
    lines = [
        line for line in sample.splitlines() if line.strip() and not line.lstrip().startswith("#")
    ]
    if lines and ";" in lines[0] and "," not in lines[0]:
        return ";"
    body = "\n".join(lines) if lines else sample
    if body.count(";") > body.count(","):
        return ";"
    if "," in body:
        return ","
    return "\t" if "\t" in body else " "


_COMMA_NUMBER = r"[+-]?[0-9]+,[0-9]+(?:[eE][+-]?[0-9]+)?"  # a number with a decimal comma
_DECIMAL_COMMA = re.compile(rf"(?:^|[;\t ])\s*{_COMMA_NUMBER}\s*(?=$|[;\t ])")
_DECIMAL_CELL = re.compile(_COMMA_NUMBER)


def decimal_comma(sample: str, delimiter: str, declared: str, path) -> bool:
    """Whether the numbers are written with a decimal comma (``417,50``): declared
    (``decimal=comma``), or seen in the rows of a file separated by ``;``, tabs or spaces (where a
    comma can be nothing else). With ``,`` separators a decimal comma cannot be told from the
    separator: refused when declared."""
    if declared == "point":
        return False
    if delimiter == ",":
        if declared == "comma":
            raise ValueError(
                f"{path}: decimal=comma, but the columns are separated by commas too; write the "
                f"file with ';' separators (as spreadsheets do where the comma is the decimal mark)"
            )
        return False
    if declared == "comma":
        return True
    rows = [
        line
        for line in sample.splitlines()[1:]
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if any(_DECIMAL_COMMA.search(line) for line in rows):
        logger.info(
            "%s: numbers with a decimal comma (the columns separated by %r)", path, delimiter
        )
        return True
    return False


def _split(line: str, delimiter: str) -> list[str]:
    return line.split() if delimiter == " " else line.split(delimiter)


def _row_limit_error(path: Path) -> ValueError:
    limit = get_limits().max_samples
    return ValueError(
        f"{path}: more than {limit:,} rows, the limit max_samples; raise it with bidmp.set_limits(max_samples=...)"
    )


def _csv_fast(
    path: Path, decimal: str = "auto"
) -> tuple[tuple[str, ...] | None, np.ndarray, dict] | None:
    """The common case, parsed by NumPy's C reader (a 1e6-row recording in about a second):
    an optional header line, then plain numbers. Returns None for anything else (quotes, ragged or
    bad rows, odd text), which :func:`_csv_rows` then reads row by row to name the problem."""
    limits = get_limits()
    try:
        with open(path, newline="", encoding="utf-8-sig") as handle:
            sample = handle.read(4096)
            delimiter = _csv_delimiter(sample)
            comma = decimal_comma(sample, delimiter, decimal, path)
            handle.seek(0)
            columns, first = None, None
            while True:
                line = handle.readline(1 << 16)
                if not line or not line.endswith(("\n", "\r")) and len(line) >= 1 << 16:
                    return None  # empty, or a line too long for a plain row
                stripped = line.strip()
                if stripped and not stripped.startswith("#"):
                    break
            cells = [cell.strip() for cell in _split(stripped, delimiter)]
            if comma:
                cells = [cell.replace(",", ".") for cell in cells]
            if any(_parse_float(cell) is None for cell in cells):
                columns = tuple(cells)
            else:
                first = line
            lines = itertools.chain([first], handle) if first is not None else handle
            if comma:
                lines = (line.replace(",", ".") for line in lines)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # "empty input": the slow path words it
                values = np.loadtxt(
                    lines,
                    delimiter=None if delimiter == " " else delimiter,
                    comments="#",
                    ndmin=2,
                    dtype=np.float64,
                    max_rows=limits.max_samples + 1,
                    encoding=None,
                )
    except (ValueError, TypeError, OSError, UnicodeDecodeError, OverflowError, MemoryError):
        return None
    if values.shape[0] == 0 or values.shape[1] > limits.max_dims + 1:
        return None
    if columns is not None and values.shape[1] != len(columns):
        return None
    if values.shape[0] > limits.max_samples:
        raise _row_limit_error(path)
    return columns, values, {}


def _csv_rows(
    path: Path, decimal: str = "auto"
) -> tuple[tuple[str, ...] | None, np.ndarray, dict[int, tuple[str, ...]]]:
    """Row-by-row CSV reading with the csv module: quotes, comments, text columns (third: their
    cells by column index), and an error that names the first bad line (quoting at most a short
    token of it)."""
    limits = get_limits()
    max_rows = limits.max_samples + 1  # + a header
    max_columns = limits.max_dims + 1  # + a time column
    if path.stat().st_size > _SLOW_CSV_BYTES:  # Python rows take ~6x the file's size in memory
        raise ValueError(
            f"{path} is not a plain numeric CSV (one optional header line, then numbers in every row), "
            f"and at {path.stat().st_size / 2**20:.0f} MiB it is too large to read row by row to find the "
            f"bad line (limit {_SLOW_CSV_BYTES >> 20} MiB)"
        )
    rows: list[tuple[int, list[str]]] = []
    try:
        # utf-8-sig: Excel writes a byte-order mark at the start of UTF-8 files.
        with open(path, newline="", encoding="utf-8-sig") as handle:
            sample = handle.read(4096)
            delimiter = _csv_delimiter(sample)
            comma = decimal_comma(sample, delimiter, decimal, path)
            handle.seek(0)
            reader = csv.reader(handle, delimiter=delimiter, skipinitialspace=delimiter == " ")
            try:
                for row in reader:
                    if not any(row) or row[0].lstrip().startswith("#"):
                        continue
                    if len(row) > max_columns:
                        raise ValueError(
                            f"{path} line {reader.line_num}: {len(row):,} columns, more than the limit "
                            f"max_dims = {limits.max_dims} allows (plus a time column)"
                        )
                    cells = [cell.strip() for cell in row]
                    if comma:
                        cells = [
                            cell.replace(",", ".") if _is_decimal(cell) else cell for cell in cells
                        ]
                    rows.append((reader.line_num, cells))
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
        columns = tuple(first_row)
        rows = rows[1:]
        if not rows:
            raise ValueError(f"{path} has a header but no data rows")
    n_columns = len(columns) if columns else len(rows[0][1])
    return (columns, *_csv_values(rows, n_columns, path, named=columns is not None))


def _is_decimal(cell: str) -> bool:
    """A number written with a decimal comma (``-122,30``)."""
    return bool(_DECIMAL_CELL.fullmatch(cell))


def _csv_values(
    rows: list[tuple[int, list[str]]], n_columns: int, path: Path, named: bool = False
) -> tuple[np.ndarray, dict[int, tuple[str, ...]]]:
    """The numbers of the data rows (T, n_columns): NumPy's parser first (fast), and on failure a
    row-by-row pass that names the first bad line (quoting at most a short token of it). With a
    header (``named``), a column of text in every row (a ROS export's ``frame_id``) is NaN and
    listed second: the reader refuses it only if it is one the layout uses."""
    cells = [row for _, row in rows]
    with contextlib.suppress(ValueError, TypeError, OverflowError):
        values = np.array(cells, dtype=np.float64)
        if values.ndim == 2 and values.shape[1] == n_columns:
            return values, {}
    for number, row in rows:
        if len(row) != n_columns:
            raise ValueError(
                f"{path} line {number}: expected {n_columns} columns, found {len(row)}"
            )
    text = [
        column
        for column in range(n_columns)
        if named and all(_parse_float(row[column]) is None for row in cells)
    ]
    for number, row in rows:
        for column, cell in enumerate(row, 1):
            if column - 1 not in text and _parse_float(cell) is None:
                raise ValueError(
                    f"{path} line {number}, column {column}: {short_token(cell)} is not a number"
                )
    values = np.array(
        [
            [float("nan") if index in text else float(cell) for index, cell in enumerate(row)]
            for row in cells
        ]
    )
    return values, {column: tuple(row[column] for row in cells) for column in text}


def _data_line(path: Path, index: int, has_header: bool) -> int:
    """The file line (1-based) of data row ``index`` (0-based): blank and ``#`` lines, and the
    header, skipped as the readers skip them. For an error message: the file is read again."""
    seen = -1 if has_header else 0
    with open(path, encoding="utf-8-sig", errors="replace") as handle:
        for number, line in enumerate(handle, start=1):
            stripped = line.strip()
            if not stripped or stripped.startswith("#"):
                continue
            if seen == index:
                return number
            seen += 1
    return 0


def check_finite_rows(path: Path, values: np.ndarray, columns, names, has_header: bool) -> None:
    """Refuse a gap (NaN) or an infinite value in ``columns`` of ``values``, naming the file line
    a user opens the file at, the column and what to do (bidmp reads no gaps)."""
    used = values[:, list(columns)]
    bad = np.argwhere(~np.isfinite(used))
    if bad.size == 0:
        return
    row, column = (int(v) for v in bad[0])
    name = names[columns[column]] if names else f"{columns[column] + 1}"
    count = int(np.any(~np.isfinite(used), axis=1).sum())
    line = _data_line(path, row, has_header)
    value = float(used[row, column])
    word = "NaN" if np.isnan(value) else ("inf" if value > 0 else "-inf")
    raise ValueError(
        f"{path} line {line}: contains {word} in column {name} (data row {row + 1}; {count:,} "
        f"row{'s' if count != 1 else ''} with gaps in all); drop those rows with --columns "
        f"gaps=drop (columns='gaps=drop'), or fill the gaps (by interpolation, say): a motion is "
        f"read without gaps"
    )
