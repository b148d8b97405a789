"""Atomic writes: a temporary file beside the target (``.NAME.PID.XXXX.bidmp-tmp``) renamed over it,
so an interrupted write never leaves a half-written file; temporaries left by a killed writer are
removed by the next write of the same file. New files get the mode the umask allows (``0666 &
~umask``); an overwritten file keeps its mode. An output that is a symlink is written through (its
target is replaced); a folder or a device is refused."""

from __future__ import annotations

import contextlib
import glob
import logging
import os
import re
import stat
import tempfile
import time
from collections.abc import Iterator
from pathlib import Path

from .._checks import check_path, shown_path

__all__ = ["atomic_write"]

logger = logging.getLogger(__name__)


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
    path = check_path(path)
    if str(path) in ("", "."):
        raise ValueError("the output path is empty")
    target = Path(os.path.realpath(path)) if path.is_symlink() else path
    if target.exists():
        if target.is_dir():
            raise ValueError(f"cannot write {path}: it is a folder; give a file name")
        if not stat.S_ISREG(target.stat().st_mode):
            raise ValueError(
                f"cannot write {path}: it is not a regular file (a device, pipe or socket)"
            )
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
    fd, tmp_name = tempfile.mkstemp(
        prefix=f".{target.name}.{os.getpid()}.", suffix=_TMP_SUFFIX, dir=directory
    )
    try:
        os.fchmod(fd, file_mode)
        with os.fdopen(
            fd, mode, **({} if "b" in mode else {"encoding": "utf-8", "newline": ""})
        ) as handle:
            yield handle
            handle.flush()
            os.fsync(handle.fileno())
        os.replace(tmp_name, target)
    except OSError as exc:
        with contextlib.suppress(OSError):
            os.unlink(tmp_name)
        # A full disk says "No space left on device" without the file: name it (the old one stays).
        error = OSError(
            exc.errno,
            f"cannot write {shown_path(target)} ({exc.strerror or exc}); nothing was replaced",
        )
        # the whole path, for a caller that says where the file was going (a run folder's
        # writer: bidmp.io.runs); the message shows its end only. Not in str(error).
        error.filename2 = str(target)
        raise error from None
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
