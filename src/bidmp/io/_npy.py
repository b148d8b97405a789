"""Reading ``.npy`` data (alone or as a member of an ``.npz``): the header checked (shape, dtype,
size within the limits) before anything is allocated, never a pickle."""

from __future__ import annotations

import contextlib
import zipfile
from collections.abc import Iterator, Mapping
from pathlib import Path

import numpy as np

from .._checks import check_bytes, check_limit, get_limits, short_token

_ZIP_MAGIC = b"PK\x03\x04"
_EMPTY_ZIP_MAGIC = b"PK\x05\x06"
_NPY_MAGIC = b"\x93NUMPY"
_MAX_MEMBERS = 100_000


def _read_npy_header(
    stream, what: str, check=None, records: bool = False
) -> tuple[tuple, np.dtype]:
    """Read an ``.npy`` header from ``stream``; refuse object dtypes and sizes over the limits
    (``records``: records of real-number fields are read too, as a timed trajectory's)."""
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
    if dtype.hasobject or (dtype.kind not in "fiub" and not (records and _real_records(dtype))):
        raise ValueError(f"{what} holds {dtype} data, not real numbers")
    if len(shape) > 8:
        raise ValueError(f"{what} has {len(shape)} dimensions")
    if check is not None:  # the caller's own expectations first: they give the clearer message
        check(shape, dtype)
    n_elements = int(np.prod(shape, dtype=object))
    check_bytes(n_elements, what, dtype.itemsize)
    return shape, dtype


def _real_records(dtype: np.dtype) -> bool:
    """Whether ``dtype`` is a record of named real-number scalars (``t, x, y, z``, …)."""
    names = dtype.names or ()
    return bool(names) and all(
        dtype[name].kind in "fiu" and dtype[name].shape == () for name in names
    )


def _read_npy(open_stream, what: str, check=None, records: bool = False) -> np.ndarray:
    """Read an array from the stream factory ``open_stream`` after checking its header
    (``check(shape, dtype)`` may refuse more; ``records``: :func:`_read_npy_header`'s)."""
    with open_stream() as stream:
        _read_npy_header(stream, what, check, records)
    with open_stream() as stream:
        try:
            return np.lib.format.read_array(stream, allow_pickle=False)
        except (ValueError, EOFError, OSError):
            raise
        except Exception as exc:  # noqa: BLE001 - as above: a corrupt header or body
            raise ValueError(
                f"{what} is not a readable .npy array ({type(exc).__name__})"
            ) from None


class NpzMembers(Mapping):
    """The arrays of an open ``.npz`` archive, read lazily: a member is decompressed and parsed only
    when asked for, after its ``.npy`` header passed the size limits."""

    def __init__(self, archive: zipfile.ZipFile, error: type[Exception]) -> None:
        self._archive = archive
        self._error = error
        self._infos = {
            info.filename[:-4]: info
            for info in archive.infolist()
            if info.filename.endswith(".npy")
        }

    @property
    def names(self) -> set[str]:
        """Every member's name (metadata members too)."""
        return set(self._infos)

    def read(self, name: str, check=None) -> np.ndarray:
        """Member ``name`` (``check(shape, dtype)`` may refuse it by its header first)."""
        info = self._infos.get(name)
        if info is None:
            raise KeyError(f"missing member {name}")
        try:
            return _read_npy(lambda: self._archive.open(info), f"member {name}", check)
        except (
            ValueError,
            EOFError,
            OSError,
            zipfile.BadZipFile,
            NotImplementedError,
            RuntimeError,
        ) as exc:
            message = (
                str(exc)
                if str(exc).startswith("member ")
                else f"member {name} is unreadable ({type(exc).__name__}: {exc})"
            )
            raise ValueError(message) from None

    def __getitem__(self, name: str) -> np.ndarray:
        return self.read(name)

    def __iter__(self):
        return (name for name in self._infos if not name.startswith("__"))

    def __len__(self) -> int:
        return sum(1 for _ in self)


@contextlib.contextmanager
def read_npz(path: Path, kind: str, error: type[Exception] = ValueError) -> Iterator[NpzMembers]:
    """The members of the ``.npz`` file ``path`` (a ``kind``, such as "bidmp model file"), checked
    before anything is read: a regular file within the size limit (a pipe or device is refused
    without opening it, which could block), a zip archive by its magic bytes, every member an
    ``.npy`` array stored or deflated, unencrypted, its declared size and header within the limits
    (a pickled or oversized member is refused even if it would never be asked for). The file is
    closed however reading ends; a problem raises ``error`` naming ``path``."""
    if not path.is_file():
        # a FIFO, a device or a socket: opening it could block
        if path.exists() and not path.is_dir():
            raise error(f"{kind} {path} is not a regular file (a pipe, device or socket)")
        raise error(
            f"{kind} {path} does not exist" + (" (it is a folder)" if path.is_dir() else "")
        )
    check_limit(path.stat().st_size, "max_file_bytes", f"the size of {path} in bytes")
    try:
        with open(path, "rb") as handle:
            magic = handle.read(4)
    except OSError as exc:
        raise error(f"cannot read {path}: {exc.strerror or exc}") from None
    if magic == _NPY_MAGIC[:4]:
        raise error(f"{path} is not a {kind} (a plain .npy array, not an .npz archive)")
    if magic not in (_ZIP_MAGIC, _EMPTY_ZIP_MAGIC):
        raise error(f"{path} is not a {kind} (not an .npz archive)")
    try:
        archive = zipfile.ZipFile(path)
    except (
        zipfile.BadZipFile,
        zipfile.LargeZipFile,
        OSError,
        EOFError,
        ValueError,
        NotImplementedError,
    ) as exc:
        raise error(f"{path} is not a readable {kind} ({type(exc).__name__}: {exc})") from None
    with archive:
        _check_archive(archive, path, kind, error)
        yield NpzMembers(archive, error)


def _check_archive(archive: zipfile.ZipFile, path: Path, kind: str, error: type[Exception]) -> None:
    """Refuse archives numpy wrote no part of: encrypted or unusually compressed members,
    declared sizes over the limits, absurd member counts."""
    infos = archive.infolist()
    if len(infos) > _MAX_MEMBERS:
        raise error(f"{path} is not a {kind} ({len(infos):,} archive members)")
    budget = get_limits().max_array_bytes + (64 << 10)
    for info in infos:
        if info.flag_bits & 0x1:
            raise error(f"{path} is not a {kind} (member {info.filename} is encrypted)")
        if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
            raise error(
                f"{path} is not a {kind} (member {info.filename} uses an unsupported "
                f"compression, method {info.compress_type})"
            )
        if info.file_size > budget:
            raise error(
                f"{path}: member {info.filename} declares {info.file_size / 2**30:.3g} GiB, over the limit "
                f"max_array_bytes = {get_limits().max_array_bytes:,}; raise it with "
                f"bidmp.set_limits(max_array_bytes=...)"
            )
        if not info.filename.endswith(".npy"):
            raise error(
                f"{path} is not a {kind} (member {short_token(info.filename, 40)} is not an .npy array)"
            )
        try:  # the header only (a few hundred bytes): the data are not read
            with archive.open(info) as stream:
                _read_npy_header(stream, f"member {short_token(info.filename[:-4], 40)}")
        except (
            ValueError,
            EOFError,
            OSError,
            zipfile.BadZipFile,
            NotImplementedError,
            RuntimeError,
        ) as exc:
            raise error(f"{path} is not a {kind} ({exc})") from None


_POSITION_HEADERS = (("x", "y"), ("x", "y", "z"))


def _read_npy_trajectory(path: Path) -> tuple[np.ndarray, np.ndarray | None]:
    """An ``.npy`` demonstration: a float array (T, D), or a structured timed trajectory."""
    with open(path, "rb") as handle:
        magic = handle.read(4)
    if magic in (_ZIP_MAGIC, _EMPTY_ZIP_MAGIC):
        raise ValueError(
            f"{path} is an .npz archive (a model file?), not an .npy array of shape (T, D)"
        )
    try:
        positions = _read_npy(
            lambda: open(path, "rb"), str(path), _check_npy_trajectory(path), records=True
        )
    except (EOFError, OSError) as exc:
        raise ValueError(f"{path} is not a readable .npy array ({type(exc).__name__})") from None
    except ValueError as exc:
        message = str(exc)
        raise ValueError(
            message if str(path) in message else f"{path} is not a readable .npy array ({message})"
        ) from None
    times = None
    if positions.dtype.names is not None:
        fields = _timed_fields(positions.dtype)
        times = np.asarray(positions["t"], dtype=np.float64)
        positions = np.column_stack(
            [np.asarray(positions[name], dtype=np.float64) for name in fields]
        )
    return positions, times


def _check_npy_trajectory(path: Path):
    limits = get_limits()

    def check(shape, dtype):
        if dtype.names is not None:  # a timed trajectory: one record per sample
            if len(shape) != 1 or not _timed_fields(dtype):
                raise ValueError(
                    f"{path} holds records with fields {', '.join(dtype.names[:8])}; expected t, x, y[, z] "
                    f"(and optionally vx, … ax, …) in shape (T,)"
                )
            if shape[0] > limits.max_samples:
                raise ValueError(
                    f"{path} has {shape[0]:,} samples, over the limit max_samples = {limits.max_samples:,}"
                )
            return
        if dtype.kind not in "fiu":
            raise ValueError(f"{path} holds {dtype} data, not numbers")
        if len(shape) != 2:
            raise ValueError(f"{path} must hold an array of shape (T, D), got shape {shape}")
        if shape[0] > limits.max_samples:
            raise ValueError(
                f"{path} has {shape[0]:,} samples, over the limit max_samples = {limits.max_samples:,}; "
                f"raise it with bidmp.set_limits(max_samples=...)"
            )
        if shape[1] > limits.max_dims:
            raise ValueError(
                f"{path} has {shape[1]:,} columns, over the limit max_dims = {limits.max_dims}"
            )

    return check


def _timed_fields(dtype: np.dtype) -> tuple[str, ...] | None:
    """The position fields of a structured timed-trajectory dtype (``t`` plus x, y[, z]; real
    numbers), or None."""
    names = dtype.names or ()
    if "t" not in names:
        return None
    for positions in reversed(_POSITION_HEADERS):
        if all(name in names for name in positions) and all(
            dtype[n].kind in "fiu" and dtype[n].shape == () for n in ("t", *positions)
        ):
            return positions
    return None
