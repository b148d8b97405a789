"""Files: trajectories (CSV / NPY) and model files (``.npz`` + JSON metadata, never pickles).

**Writes** go to a temporary file beside the target (``.NAME.PID.XXXX.bidmp-tmp``) that is then
renamed over it, so an interrupted write never leaves a half-written file; temporaries left by a
killed writer are removed by the next write of the same file. New files get the mode the umask
allows (``0666 & ~umask``); an overwritten file keeps its mode. An output that is a symlink is
written through (its target is replaced); a folder or a device is refused.

**Reads** never trust a file: sizes are checked from the headers before anything is allocated
(:class:`bidmp.Limits`), JSON is parsed with a depth and size cap and without NaN/Infinity, and
every array read from a model file is checked for dtype, shape and finiteness by the model class.

Model file layout (format version 2): an ``.npz`` archive (a zip of ``.npy`` members, stored or
deflated) holding the model's arrays under their attribute names plus ``__bidmp__``, a uint8
array with UTF-8 JSON::

    {"format": "bidmp-model", "format_version": 2, "class": "DMP",
     "bidmp_version": "0.2.0", "state": {...class-specific, e.g. constructor params...}}

It is read member by member with ``allow_pickle=False``, so loading a file can never execute
code, and a member the model does not ask for is never read.
"""

from __future__ import annotations

import contextlib
import csv
import glob
import itertools
import json
import logging
import os
import re
import stat
import tempfile
import time
import warnings
import zipfile
from collections.abc import Iterator, Mapping
from pathlib import Path

import numpy as np

from .._checks import as_trajectory, check_bytes, check_limit, get_limits, short_token
from ._columns import TIME_NAMES, parse_columns

__all__ = [
    "ModelFileError",
    "FORMAT_VERSION",
    "save_model",
    "load_model",
    "load_trajectory",
    "read_trajectory",
    "read_poses",
    "save_poses",
    "save_trajectory",
    "atomic_write",
    "load_json",
]

logger = logging.getLogger(__name__)

FORMAT_VERSION = 4
# Format 4 (bidmp 0.4): a DMP stores its integrator ("exact" for the robot protocol); files without
# one load with explicit Euler, so a format-3 robot model rolls out as it did. Format 3 (bidmp 0.3): a DMP keeps its protocol, duration_ (s) and units_. Format 2 (bidmp 0.2):
# Bi-DMP increments are gated by the phase and the DMP's regression is stored as "regression".
# Format-1 and -2 DMP and BLS files still load (as protocol "paper", 1 s, no units); format-1
# Bi-DMP files do not, because their blocks were trained on the ungated increment.
_MIN_VERSION = {"BiDMP": 2}
_FORMAT_NAME = "bidmp-model"
_META_KEY = "__bidmp__"
_META_MAX_BYTES = 16 << 20
_MAX_MEMBERS = 100_000
# Model classes that may appear in a file: name -> (module, attribute). Imported lazily so that
# reading a DMP does not import the whole pipeline.
_MODEL_CLASSES = {
    "DMP": ("bidmp.primitives.dmp", "DMP"),
    "BLS": ("bidmp.incremental.bls", "BLS"),
    "BiDMP": ("bidmp.incremental.bidmp", "BiDMP"),
    "CartesianDMP": ("bidmp.primitives.cartesian", "CartesianDMP"),
    "CartesianBiDMP": ("bidmp.incremental.cartesian", "CartesianBiDMP"),
}
_ZIP_MAGIC = b"PK\x03\x04"
_EMPTY_ZIP_MAGIC = b"PK\x05\x06"
_NPY_MAGIC = b"\x93NUMPY"


class ModelFileError(ValueError):
    """A model file is missing, corrupt, truncated, foreign, or from a newer bidmp."""


# ---------------------------------------------------------------------------------------------
# Atomic writes
# ---------------------------------------------------------------------------------------------
_TMP_SUFFIX = ".bidmp-tmp"
_STALE_AFTER_S = 24 * 3600.0  # a temporary this old is stale even if its writer's PID was reused


def _umask() -> int:
    """The process umask, read without changing it where the OS allows (Linux /proc)."""
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status", encoding="ascii") as handle:
            for line in handle:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _pid_alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True  # exists, owned by someone else
    return True


def _clear_stale_temporaries(directory: Path, name: str) -> None:
    """Remove temporaries of ``name`` whose writer is gone (killed mid-write) or that are old.

    A temporary of a live writer (another process writing the same file right now) is kept.
    """
    pattern = re.compile(rf"^\.{re.escape(name)}\.(\d+)\.[^.]+{re.escape(_TMP_SUFFIX)}$")
    for entry in directory.glob(f".{glob.escape(name)}.*{_TMP_SUFFIX}"):
        match = pattern.match(entry.name)
        if match is None:
            continue
        with contextlib.suppress(OSError):
            age = time.time() - entry.lstat().st_mtime
            if not _pid_alive(int(match.group(1))) or age > _STALE_AFTER_S:
                entry.unlink()
                logger.info("removed a stale temporary file %s", entry)


def _destination(path: str | os.PathLike) -> Path:
    """The file a write to ``path`` replaces: the path itself, or a symlink's target (written
    through). Folders, devices, pipes and sockets are refused."""
    path = Path(path)
    if str(path) in ("", "."):
        raise ValueError("the output path is empty")
    target = Path(os.path.realpath(path)) if path.is_symlink() else path
    if target.exists():
        if target.is_dir():
            raise ValueError(f"cannot write {path}: it is a folder; give a file name")
        if not stat.S_ISREG(target.stat().st_mode):
            raise ValueError(f"cannot write {path}: it is not a regular file (a device, pipe or socket)")
    directory = target.parent if str(target.parent) else Path(".")
    if not directory.is_dir():
        raise ValueError(f"cannot write {path}: folder {directory} does not exist")
    return target


@contextlib.contextmanager
def atomic_write(path: str | os.PathLike, mode: str = "wb") -> Iterator:
    """Open a temporary file beside ``path``; on success fsync it and rename it onto ``path``.

    On any exception the temporary file is removed and ``path`` is left as it was. The file gets
    the existing file's mode, or ``0666 & ~umask`` if it is new. A symlink is written through.
    """
    target = _destination(path)
    directory = target.parent if str(target.parent) else Path(".")
    _clear_stale_temporaries(directory, target.name)
    try:
        file_mode = stat.S_IMODE(target.stat().st_mode)
    except FileNotFoundError:
        file_mode = 0o666 & ~_umask()
    fd, tmp_name = tempfile.mkstemp(prefix=f".{target.name}.{os.getpid()}.", suffix=_TMP_SUFFIX, dir=directory)
    try:
        os.fchmod(fd, file_mode)
        with os.fdopen(fd, mode, **({} if "b" in mode else {"encoding": "utf-8", "newline": ""})) as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp_name, target)
    except BaseException:
        with contextlib.suppress(OSError):
            os.unlink(tmp_name)
        raise
    with contextlib.suppress(OSError):  # make the rename itself durable
        dir_fd = os.open(directory, os.O_RDONLY)
        try:
            os.fsync(dir_fd)
        finally:
            os.close(dir_fd)


# ---------------------------------------------------------------------------------------------
# JSON with bounds
# ---------------------------------------------------------------------------------------------
_JSON_STRING = re.compile(rb'"(?:[^"\\]|\\.)*"')


def _json_depth(data: bytes) -> int:
    """Maximum nesting depth of ``[``/``{`` in a JSON text, strings excluded (no parsing)."""
    codes = np.frombuffer(_JSON_STRING.sub(b'""', data), dtype=np.uint8)
    steps = (np.isin(codes, (ord("["), ord("{")))).astype(np.int64) - np.isin(codes, (ord("]"), ord("}")))
    return int(np.max(np.cumsum(steps), initial=0))


def _finite_float(text: str) -> float:
    value = float(text)
    if not np.isfinite(value):
        raise ValueError(f"number {short_token(text)} is out of the float64 range")
    return value


def _no_constant(name: str):
    raise ValueError(f"{name} is not allowed (JSON numbers must be finite)")


def load_json(data: bytes | str, source: str):
    """Parse JSON text from an untrusted file with bounded size and depth, finite numbers only.

    Raises
    ------
    ValueError
        Naming ``source`` and what was wrong (too large, too deep, not UTF-8, not JSON).
    """
    if isinstance(data, str):
        data = data.encode("utf-8", "surrogatepass")
    limits = get_limits()
    if len(data) > limits.max_json_bytes:
        raise ValueError(f"{source}: JSON of {len(data):,} bytes exceeds the limit max_json_bytes = "
                         f"{limits.max_json_bytes:,}; raise it with bidmp.set_limits(max_json_bytes=...)")
    depth = _json_depth(data)
    if depth > limits.max_json_depth:
        raise ValueError(f"{source}: JSON nested {depth} levels deep exceeds the limit max_json_depth = "
                         f"{limits.max_json_depth}; raise it with bidmp.set_limits(max_json_depth=...)")
    try:
        text = data.decode("utf-8-sig")
        return json.loads(text, parse_float=_finite_float, parse_constant=_no_constant)
    except UnicodeDecodeError:
        raise ValueError(f"{source}: not UTF-8 text") from None
    except RecursionError:  # pragma: no cover - the depth cap comes first
        raise ValueError(f"{source}: JSON nested too deeply") from None
    except json.JSONDecodeError as exc:
        raise ValueError(f"{source}: not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})") from None
    except ValueError as exc:  # a non-finite number, an integer of too many digits
        raise ValueError(f"{source}: {exc}") from None


# ---------------------------------------------------------------------------------------------
# .npy headers: check before allocating
# ---------------------------------------------------------------------------------------------
def _read_npy_header(stream, what: str, check=None) -> tuple[tuple, np.dtype]:
    """Read an ``.npy`` header from ``stream``; refuse object dtypes and sizes over the limits."""
    magic = stream.read(len(_NPY_MAGIC))
    if magic != _NPY_MAGIC:
        raise ValueError(f"{what} is not an .npy array")
    version = tuple(stream.read(2))
    try:  # the header is a Python literal: a corrupt one can fail in many ways
        if version == (1, 0):
            shape, _, dtype = np.lib.format.read_array_header_1_0(stream)
        elif version in ((2, 0), (3, 0)):
            shape, _, dtype = np.lib.format.read_array_header_2_0(stream)
        else:
            raise ValueError(f"{what} has an unknown .npy format version {version}")
    except ValueError:
        raise
    except Exception as exc:  # noqa: BLE001 - numpy parses the header with ast/tokenize, which fail in many ways
        raise ValueError(f"{what} has a corrupt .npy header ({type(exc).__name__})") from None
    if not (isinstance(shape, tuple) and all(isinstance(n, int) and n >= 0 for n in shape)):
        raise ValueError(f"{what} has a corrupt .npy header (shape {short_token(shape, 30)})")
    if dtype.hasobject or dtype.kind not in "fiub":
        raise ValueError(f"{what} holds {dtype} data, not real numbers")
    if len(shape) > 8:
        raise ValueError(f"{what} has {len(shape)} dimensions")
    if check is not None:  # the caller's own expectations first: they give the clearer message
        check(shape, dtype)
    n_elements = int(np.prod(shape, dtype=object))
    check_bytes(n_elements, what, dtype.itemsize)
    return shape, dtype


def _read_npy(open_stream, what: str, check=None) -> np.ndarray:
    """Read an array from the stream factory ``open_stream`` after checking its header
    (``check(shape, dtype)`` may refuse more)."""
    with open_stream() as stream:
        _read_npy_header(stream, what, check)
    with open_stream() as stream:
        try:
            return np.lib.format.read_array(stream, allow_pickle=False)
        except (ValueError, EOFError, OSError):
            raise
        except Exception as exc:  # noqa: BLE001 - as above: a corrupt header or body
            raise ValueError(f"{what} is not a readable .npy array ({type(exc).__name__})") from None


# ---------------------------------------------------------------------------------------------
# Model files
# ---------------------------------------------------------------------------------------------
def _model_class(name: str):
    import importlib

    module_name, attribute = _MODEL_CLASSES[name]
    return getattr(importlib.import_module(module_name), attribute)


def _model_path(path: str | os.PathLike) -> Path:
    """The model file to write: ``path`` with ``.npz`` added when missing. The given path is
    checked first, so ``-o somefolder`` or ``-o /dev/null`` are refused, not turned into
    ``somefolder.npz``."""
    path = Path(path)
    _destination(path)
    if path.suffix != ".npz":
        path = path.with_name(path.name + ".npz")
    return path


def save_model(model, path: str | os.PathLike) -> Path:
    """Save a fitted model to ``path`` (``.npz``; the suffix is added if missing).

    Returns
    -------
    path : Path
        The path written.
    """
    from .. import __version__

    class_name = type(model).__name__
    if class_name not in _MODEL_CLASSES or not hasattr(model, "_get_state"):
        raise TypeError(f"model must be one of {', '.join(sorted(_MODEL_CLASSES))}, got {class_name}")
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name, got {type(path).__name__}")
    path = _model_path(path)
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
    with atomic_write(path, "wb") as handle:
        np.savez(handle, **payload)
    logger.debug("saved %s to %s", class_name, path)
    return path


class _Members(Mapping):
    """The arrays of an open model archive, read lazily: a member is decompressed and parsed
    only when a model class asks for it, after its ``.npy`` header passed the size limits."""

    def __init__(self, archive: zipfile.ZipFile, source: str) -> None:
        self._archive = archive
        self._source = source
        self._infos = {info.filename[:-4]: info for info in archive.infolist() if info.filename.endswith(".npy")}

    def __getitem__(self, name: str) -> np.ndarray:
        info = self._infos.get(name)
        if info is None:
            raise KeyError(f"missing member {name}")
        try:
            return _read_npy(lambda: self._archive.open(info), f"member {name}")
        except (ValueError, EOFError, OSError, zipfile.BadZipFile, NotImplementedError, RuntimeError) as exc:
            message = str(exc) if str(exc).startswith("member ") else f"member {name} is unreadable ({type(exc).__name__}: {exc})"
            raise ValueError(message) from None

    def __iter__(self):
        return (name for name in self._infos if name != _META_KEY)

    def __len__(self) -> int:
        return sum(1 for _ in self)


def _check_archive(archive: zipfile.ZipFile, path: Path) -> None:
    """Refuse archives numpy wrote no part of: encrypted or unusually compressed members,
    declared sizes over the limits, absurd member counts."""
    infos = archive.infolist()
    if len(infos) > _MAX_MEMBERS:
        raise ModelFileError(f"{path} is not a bidmp model file ({len(infos):,} archive members)")
    budget = get_limits().max_array_bytes + (64 << 10)
    for info in infos:
        if info.flag_bits & 0x1:
            raise ModelFileError(f"{path} is not a bidmp model file (member {info.filename} is encrypted)")
        if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
            raise ModelFileError(f"{path} is not a bidmp model file (member {info.filename} uses an unsupported "
                                 f"compression, method {info.compress_type})")
        if info.file_size > budget:
            raise ModelFileError(f"{path}: member {info.filename} declares {info.file_size / 2**30:.3g} GiB, over the limit "
                                 f"max_array_bytes = {get_limits().max_array_bytes:,}; raise it with "
                                 f"bidmp.set_limits(max_array_bytes=...)")
        if not info.filename.endswith(".npy"):
            raise ModelFileError(f"{path} is not a bidmp model file (member {short_token(info.filename, 40)} is not an .npy array)")
        # Every member's header (a few hundred bytes) is checked, so that a pickled or oversized
        # member is refused even if the model would never ask for it; the data are not read.
        try:
            with archive.open(info) as stream:
                _read_npy_header(stream, f"member {short_token(info.filename[:-4], 40)}")
        except (ValueError, EOFError, OSError, zipfile.BadZipFile, NotImplementedError, RuntimeError) as exc:
            raise ModelFileError(f"{path} is not a bidmp model file ({exc})") from None


def _read_meta(members: _Members, path: Path) -> dict:
    if _META_KEY not in members._infos:
        raise ModelFileError(f"{path} is not a bidmp model file (an .npz archive without bidmp metadata)")

    def check(shape, dtype):
        if dtype != np.uint8 or len(shape) != 1 or shape[0] > _META_MAX_BYTES:
            raise ValueError(f"{path} is not a bidmp model file (its metadata member is not UTF-8 JSON bytes)")

    try:
        raw = _read_npy(lambda: members._archive.open(members._infos[_META_KEY]), "the metadata member", check)
        meta = load_json(raw.tobytes(), f"{path} metadata")
    except (ValueError, EOFError, OSError, zipfile.BadZipFile, NotImplementedError, RuntimeError) as exc:
        raise ModelFileError(f"{path} is not a readable bidmp model file ({exc})") from None
    if not isinstance(meta, dict) or meta.get("format") != _FORMAT_NAME:
        raise ModelFileError(f"{path} is not a bidmp model file (unknown metadata format)")
    return meta


def load_model(path: str | os.PathLike):
    """Load a model written by :func:`save_model`.

    Only the members the model needs are read, each after its header passed the size limits, and
    the model class validates every array (dtype, shape, finite) before it is used.

    Raises
    ------
    ModelFileError
        If the file is missing, not an ``.npz`` archive, truncated or corrupt, has no bidmp
        metadata (a foreign file), was written by a newer format version, or its contents are
        inconsistent (the message names the member).
    """
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name, got {type(path).__name__}")
    path = Path(path)
    if not path.is_file():
        raise ModelFileError(f"model file {path} does not exist" + (" (it is a folder)" if path.is_dir() else ""))
    check_limit(path.stat().st_size, "max_file_bytes", f"the size of {path} in bytes")
    try:
        with open(path, "rb") as handle:
            magic = handle.read(4)
    except OSError as exc:
        raise ModelFileError(f"cannot read {path}: {exc.strerror or exc}") from None
    if magic == _NPY_MAGIC[:4]:
        raise ModelFileError(f"{path} is not a bidmp model file (a plain .npy array, not an .npz archive)")
    if magic not in (_ZIP_MAGIC, _EMPTY_ZIP_MAGIC):
        raise ModelFileError(f"{path} is not a bidmp model file (not an .npz archive)")
    try:
        archive = zipfile.ZipFile(path)
    except (zipfile.BadZipFile, zipfile.LargeZipFile, OSError, EOFError, ValueError, NotImplementedError) as exc:
        raise ModelFileError(f"{path} is not a readable bidmp model file ({type(exc).__name__}: {exc})") from None
    with archive:
        _check_archive(archive, path)
        members = _Members(archive, str(path))
        meta = _read_meta(members, path)
        version = meta.get("format_version")
        if not isinstance(version, int) or isinstance(version, bool) or version < 1:
            raise ModelFileError(f"{path} has an invalid format_version {short_token(version)}")
        if version > FORMAT_VERSION:
            raise ModelFileError(
                f"{path} was written in model format {version} by bidmp {short_token(meta.get('bidmp_version', '?'), 20)}; "
                f"this bidmp reads format {FORMAT_VERSION} or older: upgrade bidmp"
            )
        class_name = meta.get("class")
        if not isinstance(class_name, str) or class_name not in _MODEL_CLASSES:
            raise ModelFileError(f"{path} holds an unknown model class {short_token(class_name, 20)}")
        if version < _MIN_VERSION.get(class_name, 1):
            raise ModelFileError(
                f"{path} holds a {class_name} in model format {version} (bidmp {short_token(meta.get('bidmp_version', '?'), 20)}), "
                f"whose learned increments did not vanish with the phase; this bidmp cannot use it: learn the skills again"
            )
        state = meta.get("state")
        if not isinstance(state, dict):
            raise ModelFileError(f"{path} is corrupt: its metadata has no state object")
        try:
            return _model_class(class_name)._from_state(state, members)
        except MemoryError:
            raise ModelFileError(f"{path}: a member is too large to load") from None
        except KeyError as exc:
            detail = exc.args[0] if exc.args and str(exc.args[0]).startswith("missing member") else f"missing key {exc}"
            raise ModelFileError(f"{path} is corrupt: {class_name} state is inconsistent ({detail})") from None
        except (TypeError, ValueError, AttributeError, IndexError, RecursionError, OverflowError,
                zipfile.BadZipFile, EOFError, OSError) as exc:
            raise ModelFileError(f"{path} is corrupt: {class_name} state is inconsistent ({exc})") from None


# ---------------------------------------------------------------------------------------------
# Trajectories
# ---------------------------------------------------------------------------------------------
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
    from ._columns import select_poses, select_positions

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
    if not selection.values:
        shown = ",".join(short_token(c, 12)[1:-1] for c in header[:8]) + (",…" if len(header) > 8 else "")
        raise ValueError(f"{path}: header {shown} names no positions; expected x,y[,z] with an optional t/time/timestamp "
                         f"column, or name them with a column mapping (--columns t=stamp,x=ee_x,y=ee_y,z=ee_z)")
    _note_ignored(path, selection.ignored)
    times = None if selection.time is None else values[:, selection.time]
    return values[:, list(selection.values)], times


def declared_units(path) -> str:
    """The unit a CSV declares in a leading comment line ``# units: mm`` ("" if none)."""
    from .._units import check_units

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


def load_trajectory(path: str | os.PathLike) -> np.ndarray:
    """Read a demonstration from ``.csv`` or ``.npy`` as positions on a uniform time grid.

    See :func:`read_trajectory` for the formats; with timestamps the samples are resampled to
    uniform time steps over the same span (a DMP assumes them). Use :func:`read_trajectory` to
    keep the stamps (``bidmp.DMP.fit(y, t)`` and :func:`bidmp.prepare` take them).

    Returns
    -------
    y : array, shape (T, D)
        Validated: finite, at least 3 points, not all identical, within the limits.
    """
    from ..primitives.timing import uniform_time

    y, times = read_trajectory(path)
    if times is not None:
        y, _ = uniform_time(y, times)
    return y


def read_trajectory(path: str | os.PathLike, *, columns=None) -> tuple[np.ndarray, np.ndarray | None]:
    """Read a demonstration from ``.csv`` or ``.npy``: positions and, if the file has them,
    timestamps in seconds (as recorded: any monotone stamps, epoch-like or jittered).

    CSV: one sample per row, comma (or semicolon) separated, ``#`` comments allowed, UTF-8 with
    or without a byte-order mark. An optional header names the columns: ``x,y[,z]`` with an
    optional time column ``t`` (or ``time``, ``timestamp``), other columns ignored with a
    warning that names them; ``columns`` maps other names, e.g. ``"t=stamp,x=ee_x,y=ee_y,z=ee_z"``
    (see :mod:`bidmp._columns`). A timed trajectory written by bidmp (``t,x,y[,z],vx,…,ax,…``)
    reads its positions and times. Without a header 2 or 3 columns are positions and 4 columns
    are ``t,x,y,z``. Samples whose timestamp repeats the one before are dropped, with a warning.
    NPY: a float array of shape (T, D) (positions), or a structured array of shape (T,) with
    fields ``t, x, y[, z]`` (and optionally ``vx … az``), as :func:`save_trajectory` writes a
    :class:`bidmp.Trajectory`; read with ``allow_pickle=False`` after its header passed the
    size limits.

    Returns
    -------
    (y, t) : array (T, D) and array (T,) or None
    """
    from ..primitives.timing import drop_duplicate_stamps

    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name, got {type(path).__name__}")
    path = Path(path)
    _check_file(path, "demonstration file")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        with open(path, "rb") as handle:
            magic = handle.read(4)
        if magic in (_ZIP_MAGIC, _EMPTY_ZIP_MAGIC):
            raise ValueError(f"{path} is an .npz archive (a model file?), not an .npy array of shape (T, D)")
        try:
            positions = _read_npy(lambda: open(path, "rb"), str(path), _check_npy_trajectory(path))
        except (EOFError, OSError) as exc:
            raise ValueError(f"{path} is not a readable .npy array ({type(exc).__name__})") from None
        except ValueError as exc:
            message = str(exc)
            raise ValueError(message if str(path) in message else f"{path} is not a readable .npy array ({message})") from None
        times = None
        if positions.dtype.names is not None:
            fields = _timed_fields(positions.dtype)
            times = np.asarray(positions["t"], dtype=np.float64)
            positions = np.column_stack([np.asarray(positions[name], dtype=np.float64) for name in fields])
    elif suffix in (".csv", ".txt"):
        positions, times = _read_csv(path, columns)
    else:
        raise ValueError(f"{path}: unsupported file type {short_token(suffix)[1:-1] if suffix else '(none)'}; use .csv or .npy")
    if columns is not None and suffix == ".npy":
        raise ValueError(f"{path}: a column mapping applies to CSV files with a header, not to .npy arrays")
    positions = as_trajectory(positions, name=str(path))
    if times is not None:
        positions, times = drop_duplicate_stamps(positions, times, f"{path}: the time column")
    return positions, times


def save_trajectory(y, path: str | os.PathLike, times=None, *, units: str | None = None) -> Path:
    """Write a trajectory to ``path`` (``.csv`` or ``.npy``), atomically.

    ``y`` is positions (T, D), optionally with ``times`` (T,) in seconds, or a
    :class:`bidmp.Trajectory`:

    * CSV: header ``x,y[,z]``, ``t,x,y[,z]`` (with times) or ``t,x,y,z,vx,vy,vz,ax,ay,az`` (a
      Trajectory: s, units, units/s, units/s²);
    * NPY: a float array (T, D) of positions, or with times or a Trajectory a structured array
      of shape (T,) with the same named fields (``np.load(path)["t"]``, ``["vx"]``, …), still
      without pickles.

    A CSV starts with a comment ``# units: mm`` when the unit is known (``units``, or the
    Trajectory's), which :func:`declared_units` reads back. The argument order is the same as
    :func:`save_model` (what, then where). Non-finite values are refused: a file a robot may
    execute never holds NaN or inf.
    """
    from ..primitives.timing import Trajectory

    if isinstance(y, (str, os.PathLike)) and not isinstance(path, (str, os.PathLike)):
        raise TypeError("save_trajectory takes (y, path): the trajectory first, then the file (as save_model)")
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name, got {type(path).__name__}")
    path = Path(path)
    if isinstance(y, Trajectory):
        if times is not None:
            raise TypeError("times is given by the Trajectory itself")
        names, data = y.columns()
        for name, column in (("t", y.t), ("yd", y.yd), ("ydd", y.ydd)):
            if not np.all(np.isfinite(column)):
                raise ValueError(f"the trajectory's {name} contains NaN or inf")
        return _write_columns(as_trajectory(y.y, "y", min_points=1, allow_static=True), names, data, path,
                              y.units if units is None else units)
    y = as_trajectory(y, "y", min_points=1, allow_static=True)
    _destination(path)
    suffix = path.suffix.lower()
    if suffix not in (".npy", ".csv"):
        raise ValueError(f"{path}: unsupported file type {short_token(suffix)[1:-1] if suffix else '(none)'}; use .csv or .npy")
    if suffix == ".npy" and times is None:
        with atomic_write(path, "wb") as handle:
            np.save(handle, y, allow_pickle=False)
        return path
    units = units or ""
    names = ["x", "y", "z"][: y.shape[1]] if y.shape[1] <= 3 else [f"x{i}" for i in range(y.shape[1])]
    data = y
    if times is not None:
        times = np.asarray(times, dtype=np.float64).reshape(-1)
        if times.shape[0] != y.shape[0]:
            raise ValueError(f"times has {times.shape[0]} entries for {y.shape[0]} samples")
        if not np.all(np.isfinite(times)):
            raise ValueError("times contains NaN or inf")
        names = ["t", *names]
        data = np.column_stack([times, y])
    return _write_columns(y, names, data, path, units)


def _write_columns(y: np.ndarray, names: list[str], data: np.ndarray, path: Path, units: str = "") -> Path:
    """Write named columns as CSV (a ``# units:`` comment when known, a header row) or as a
    structured ``.npy`` (one field each)."""
    from .._units import check_units

    units = check_units(units)
    _destination(path)
    suffix = path.suffix.lower()
    if suffix not in (".npy", ".csv"):
        raise ValueError(f"{path}: unsupported file type {short_token(suffix)[1:-1] if suffix else '(none)'}; use .csv or .npy")
    if suffix == ".npy":
        records = np.empty(data.shape[0], dtype=[(name, np.float64) for name in names])
        for index, name in enumerate(names):
            records[name] = data[:, index]
        with atomic_write(path, "wb") as handle:
            np.save(handle, records, allow_pickle=False)
        return path
    with atomic_write(path, "w") as handle:
        if units:
            handle.write(f"# units: {units}\n")
        writer = csv.writer(handle, lineterminator="\n")
        writer.writerow(names)
        writer.writerows([[repr(float(v)) for v in row] for row in data])
    return path


def read_poses(path: str | os.PathLike, *, columns=None) -> tuple[np.ndarray, np.ndarray | None]:
    """Read a pose recording (CSV with a header): poses ``(T, 7)`` as ``x, y, z, qx, qy, qz,
    qw`` (scalar last) and timestamps (s) or None.

    The header must name the columns ``x, y, z, qx, qy, qz, qw`` in any order, and optionally a
    time column ``t`` (``time``, ``timestamp``); other columns are ignored with a warning (a
    timed pose trajectory written by :func:`save_poses` reads too). ``columns`` maps other names
    (as :func:`read_trajectory`). The quaternion's order is taken from the names, never guessed
    from the numbers; ``qw`` first or last both read. Quaternions are checked by
    :class:`bidmp.CartesianDMP` (sign flips, unit length) when it fits them. Samples whose
    timestamp repeats the one before are dropped, with a warning.
    """
    from ._columns import select_poses
    from ..primitives.timing import drop_duplicate_stamps

    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name, got {type(path).__name__}")
    path = Path(path)
    _check_file(path, "pose file")
    if path.suffix.lower() not in (".csv", ".txt"):
        raise ValueError(f"{path}: pose recordings are read from .csv files with a header")
    mapping = parse_columns(columns)
    parsed = _csv_fast(path)
    header, values = parsed if parsed is not None else _csv_rows(path)
    accepted = "t,x,y,z,qw,qx,qy,qz or t,x,y,z,qx,qy,qz,qw (t optional)"
    if header is None:
        raise ValueError(f"{path}: a pose file needs a header naming the columns ({accepted})")
    selection = select_poses(header, mapping, path)
    if not selection.values:
        shown = ",".join(short_token(c, 12)[1:-1] for c in header[:8]) + (",…" if len(header) > 8 else "")
        raise ValueError(f"{path}: header {shown} does not name a pose; accepted headers: {accepted}")
    written = {"vx", "vy", "vz", "wx", "wy", "wz", "ax", "ay", "az", "dwx", "dwy", "dwz"}  # save_poses' own columns
    if not set(selection.ignored) <= written:
        _note_ignored(path, selection.ignored)
    poses = as_trajectory(values[:, list(selection.values)], name=str(path), allow_static=True)
    if selection.time is None:
        return poses, None
    return drop_duplicate_stamps(poses, values[:, selection.time], f"{path}: the time column")


def save_poses(poses, path: str | os.PathLike, times=None, *, units: str | None = None) -> Path:
    """Write poses ``(T, 7)`` (x, y, z, qx, qy, qz, qw) or a :class:`bidmp.cartesian.PoseTrajectory`
    to a CSV with the header ``[t,]x,y,z,qx,qy,qz,qw`` (a trajectory adds ``vx..vz, wx..wz,
    ax..az, dwx..dwz``: units/s, rad/s, units/s², rad/s², as :meth:`PoseTrajectory.columns`),
    atomically; with a known unit (``units`` or the trajectory's) a first line ``# units: mm``."""
    from ..primitives.cartesian import PoseTrajectory

    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name, got {type(path).__name__}")
    path = Path(path)
    names = ["x", "y", "z", "qx", "qy", "qz", "qw"]
    if isinstance(poses, PoseTrajectory):
        names, data = poses.columns()
        units = poses.units if units is None else units
    else:
        data = as_trajectory(poses, "poses", min_points=1, allow_static=True)
        if data.shape[1] != 7:
            raise ValueError(f"poses must have 7 columns (x, y, z, qx, qy, qz, qw), got {data.shape[1]}")
        if times is not None:
            times = np.asarray(times, dtype=np.float64).reshape(-1)
            if times.shape[0] != data.shape[0] or not np.all(np.isfinite(times)):
                raise ValueError(f"times must be {data.shape[0]} finite numbers")
            data, names = np.column_stack([times, data]), ["t", *names]
    if not np.all(np.isfinite(data)):
        raise ValueError("the poses contain NaN or inf")
    if path.suffix.lower() != ".csv":
        raise ValueError(f"{path}: poses are written as .csv")
    return _write_columns(data, names, data, path, units or "")
