"""Run folders: a command's output folder holds one run, whole, or the one before it.

A command that writes a folder (``bidmp demo``, ``sim``, ``job``, ``reproduce``, ``benchmark``)
writes it through :func:`run_folder`: its files go into a new hidden folder beside the output
(``.NAME.bidmp-new-PID-XXXXXXXX``), then ``manifest.json`` is written last (the run's id, the
command, every file's name, size and SHA-256), then the new folder is swapped in. Where the system
can (Linux's ``renameat2(RENAME_EXCHANGE)``), the swap is one atomic exchange of the two folders;
elsewhere it is two renames, and a run killed between them is put back by the next run into the
same folder. The earlier run is then deleted whole: no file of it survives beside the new one.
So at every instant the output folder is one complete run (the earlier one, or the new one), a
run that fails or is killed leaves the earlier one as it was, and a reader (``bidmp verify``)
refuses a file the manifest does not list, or whose content changed.

An existing output folder is replaced only if it is empty or a bidmp run whose every file its
manifest lists; a folder that holds anything else (a user's own files, a run of bidmp before 0.6,
another run inside it) is refused, naming a file, unless ``overwrite=True`` (``--overwrite``).
One command at a time writes a folder: a lock (``.NAME.bidmp-lock`` beside it, held with
``flock`` while the command runs) makes a second one refuse at once. A resumable command
(``partial=True``: the LASA benchmark) writes into ``.NAME.bidmp-partial`` instead, which a failed
or killed run leaves in place for ``resume=True`` to go on from.
"""

from __future__ import annotations

import contextlib
import ctypes
import errno
import hashlib
import json
import logging
import os
import re
import shutil
import stat
import tempfile
import uuid
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path

from .._checks import check_path, shown_path
from .atomic import _umask, atomic_write

__all__ = [
    "MANIFEST",
    "RunManifest",
    "RunFolder",
    "run_folder",
    "read_manifest",
    "check_run_files",
    "update_manifest",
    "OutputFiles",
    "output_files",
]

logger = logging.getLogger(__name__)

MANIFEST = "manifest.json"
_FORMAT = "bidmp-run"  # the manifest's "format": what tells a run's manifest from any manifest.json
_VERSION = 1
_MAX_MANIFEST_BYTES = 64 * 2**20  # a run of a million files' names stays under it
_LOCK_TRIES = 5  # a lock file unlinked by its holder between our open and our flock: try again


# ---------------------------------------------------------------------------------------------
# The manifest
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class RunManifest:
    """What ``manifest.json`` says of a run: its id, the command that wrote it, the bidmp version
    and every file (``name`` relative to the run folder, with ``/``) -> ``(bytes, sha256 hex)``."""

    run: str
    command: str
    bidmp: str
    files: dict = field(default_factory=dict)

    def __post_init__(self) -> None:
        for name in ("run", "command", "bidmp"):
            if not isinstance(getattr(self, name), str):
                raise TypeError(f"{name} must be text, got {type(getattr(self, name)).__name__}")
        if not isinstance(self.files, dict) or not all(
            isinstance(name, str)
            and isinstance(entry, tuple)
            and len(entry) == 2
            and isinstance(entry[0], int)
            and not isinstance(entry[0], bool)
            and entry[0] >= 0
            and isinstance(entry[1], str)
            and re.fullmatch(r"[0-9a-f]{64}", entry[1])
            for name, entry in self.files.items()
        ):
            raise TypeError(
                "files must map each file's name (text) to (its size in bytes, its SHA-256 in hex)"
            )

    def to_dict(self) -> dict:
        return {
            "format": _FORMAT,
            "version": _VERSION,
            "run": self.run,
            "command": self.command,
            "bidmp": self.bidmp,
            "files": [
                {"name": name, "bytes": size, "sha256": digest}
                for name, (size, digest) in sorted(self.files.items())
            ],
        }


def _sha256(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as handle:
        for block in iter(lambda: handle.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def _files(folder: Path) -> list[str]:
    """Every file under ``folder`` (its own manifest aside), relative, with ``/``, sorted. Empty
    folders are not files; a symlink is listed as what it is (a file a run did not write)."""
    names = []
    for root, dirs, files in os.walk(folder):
        dirs.sort()
        base = Path(root).relative_to(folder)
        for name in files + [d for d in dirs if (Path(root) / d).is_symlink()]:
            relative = (base / name).as_posix()
            if relative != MANIFEST:
                names.append(relative)
    return sorted(names)


def _manifest_problem(data) -> str | None:
    """Why ``data`` (a parsed manifest.json) is not a run's manifest (None: it is)."""
    if not isinstance(data, dict) or data.get("format") != _FORMAT:
        return "it is not a bidmp run's manifest"
    if data.get("version") != _VERSION:
        return f"its version {str(data.get('version'))[:20]!r} is not {_VERSION}"
    files = data.get("files")
    if not isinstance(files, list) or not all(
        isinstance(entry, dict)
        and isinstance(entry.get("name"), str)
        and isinstance(entry.get("sha256"), str)
        and re.fullmatch(r"[0-9a-f]{64}", entry["sha256"])
        and isinstance(entry.get("bytes"), int)
        and not isinstance(entry.get("bytes"), bool)
        for entry in files
    ):
        return "its file list is malformed"
    if not all(isinstance(data.get(key), str) for key in ("run", "command", "bidmp")):
        return "its run, command or bidmp version is missing"
    return None


def read_manifest(folder) -> RunManifest | None:
    """The run manifest of ``folder`` (``folder/manifest.json``), or None if it has none.

    A ``manifest.json`` that is not a bidmp run's (another tool's, no ``"format": "bidmp-run"``)
    is None too; one that says it is a run's but is broken raises ``ValueError`` naming it.
    """
    from .strict_json import load_json

    path = Path(check_path(folder, "folder")) / MANIFEST
    if not path.is_file():
        return None
    if path.stat().st_size > _MAX_MANIFEST_BYTES:
        raise ValueError(f"{shown_path(path)} is over {_MAX_MANIFEST_BYTES >> 20} MB")
    data = load_json(path.read_bytes(), shown_path(path))
    if not isinstance(data, dict) or data.get("format") != _FORMAT:
        return None
    problem = _manifest_problem(data)
    if problem is not None:
        raise ValueError(f"{shown_path(path)}: {problem}")
    return RunManifest(
        data["run"],
        data["command"],
        data["bidmp"],
        {entry["name"]: (entry["bytes"], entry["sha256"]) for entry in data["files"]},
    )


def _write_manifest(folder: Path, command: str) -> RunManifest:
    """Hash every file of ``folder`` and write its manifest (last: a folder with a manifest is a
    complete run). The run's id is random by intent: it names this run among every other."""
    from .. import __version__

    files = {}
    for name in _files(folder):
        path = folder / name
        if path.is_symlink() or not path.is_file():
            raise ValueError(f"{name}: a run writes regular files only")
        files[name] = (path.stat().st_size, _sha256(path))
    manifest = RunManifest(uuid.uuid4().hex, command, __version__, files)
    with atomic_write(folder / MANIFEST, "w") as handle:
        json.dump(manifest.to_dict(), handle, indent=1)
        handle.write("\n")
    return manifest


def _run_of(path: Path) -> tuple[Path, RunManifest] | None:
    """The run folder holding ``path`` (the nearest folder above it with a run's manifest) and its
    manifest; None if no folder above it is a run."""
    for folder in Path(os.path.abspath(path)).parents:
        manifest = read_manifest(folder)
        if manifest is not None:
            return folder, manifest
    return None


def check_run_files(paths, name: str = "paths") -> list:
    """Refuse files of a run folder that its run did not write as they are now.

    For each of ``paths`` inside a run folder (a folder above it has a run's ``manifest.json``):
    the manifest must list it and its SHA-256 must be the listed one, else ``ValueError`` naming
    the file (a file of an earlier run left beside a new one, or one changed since). A file in no
    run folder passes. Returns ``(path, run folder or None, manifest or None)`` per path.
    ``name``: what the messages call ``paths`` (a command's argument).
    """
    if not isinstance(paths, (list, tuple)):
        raise TypeError(
            f"{name} must be a list of file paths, got {type(paths).__name__}"
            + (" (one path: give a list of it)" if isinstance(paths, (str, os.PathLike)) else "")
        )
    checked = []
    for given in paths:
        path = Path(check_path(given, name))
        found = _run_of(path)
        if found is None:
            checked.append((given, None, None))
            continue
        folder, manifest = found
        relative = Path(os.path.abspath(path)).relative_to(folder)
        listed = manifest.files.get(relative.as_posix())
        # the run folder as the path was given (j/commands/x.csv: j)
        shown = (
            path.parents[len(relative.parts) - 1]
            if len(relative.parts) <= len(path.parents)
            else folder
        )
        where = shown_path(shown / MANIFEST)
        if listed is None:
            raise ValueError(
                f"{given}: not a file of the run in {shown_path(shown)} ({where} does not list "
                f"it: left by an earlier run, or put there since); run the command again"
            )
        if not path.is_file() or _sha256(path) != listed[1]:
            raise ValueError(
                f"{given}: changed since its run wrote it (its SHA-256 is not the one {where} "
                f"lists); run the command again"
            )
        checked.append((given, folder, manifest))
    return checked


# ---------------------------------------------------------------------------------------------
# Swapping folders
# ---------------------------------------------------------------------------------------------
_RENAME_EXCHANGE = 2
_AT_FDCWD = -100


def _renameat2():
    """libc's renameat2 (Linux, glibc 2.28+), or None."""
    try:
        function = ctypes.CDLL(None, use_errno=True).renameat2
    except (AttributeError, OSError):
        return None
    function.argtypes = [
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_int,
        ctypes.c_char_p,
        ctypes.c_uint,
    ]
    function.restype = ctypes.c_int
    return function


def _exchange(first: Path, second: Path) -> bool:
    """Swap two folders in one atomic step; False where the system or file system cannot."""
    function = _renameat2()
    if function is None:
        return False
    if function(_AT_FDCWD, os.fsencode(first), _AT_FDCWD, os.fsencode(second), _RENAME_EXCHANGE):
        code = ctypes.get_errno()
        if code in (errno.EINVAL, errno.ENOSYS, errno.ENOTSUP, errno.EOPNOTSUPP):
            return False
        raise OSError(code, os.strerror(code), str(second))
    return True


def _fsync_folder(folder: Path) -> None:
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def _remove(path: Path) -> None:
    """Delete a folder (or file) left by a run; a failure is logged, not raised."""
    try:
        if path.is_dir() and not path.is_symlink():
            shutil.rmtree(path)
        elif path.exists() or path.is_symlink():
            path.unlink()
    except OSError as exc:
        logger.warning("could not remove %s (%s): the next run into the folder will", path, exc)


# ---------------------------------------------------------------------------------------------
# The run folder
# ---------------------------------------------------------------------------------------------
class RunFolder:
    """A run being written: :attr:`path` is where its files go, :attr:`out` where they appear.

    Made by :func:`run_folder`; see the module's docstring.
    """

    def __init__(self, out: Path, final: Path, path: Path, command: str, earlier) -> None:
        self.out = out  # the folder as the user named it
        self.final = final  # ... its real path (a symlink's target)
        self.path = path  # the new run's files are written here
        self.command = command
        self.earlier = (
            earlier  # what was there: None (nothing, or an empty folder), a RunManifest, or "files"
        )
        self.manifest: RunManifest | None = None  # the new run's, once it is in place

    def shown(self, path) -> Path:
        """Where a file written under :attr:`path` is once the run is in place (for messages)."""
        path = Path(path)
        try:
            return self.out / path.relative_to(self.path)
        except ValueError:
            return path

    def state(self) -> str:
        """What the output folder holds while this run is not in place: the earlier run, as it was."""
        out = shown_path(self.out)
        if isinstance(self.earlier, RunManifest):
            return (
                f"{out} still holds the earlier run, unchanged ({len(self.earlier.files)} files "
                f"of '{self.earlier.command}')"
            )
        if self.earlier == "files":
            return f"{out} holds its files as it did"
        return f"{out} was not written" if not self.final.exists() else f"{out} is as it was"


def _lock_path(final: Path) -> Path:
    return final.parent / f".{final.name}.bidmp-lock"


def _acquire(final: Path, out) -> int:
    """Hold the folder's lock (an exclusive flock on ``.NAME.bidmp-lock`` beside it); another
    holder is refused at once, naming its process. Where the system has no flock (Windows):
    no lock (-1)."""
    try:
        import fcntl
    except ImportError:
        return -1
    path = _lock_path(final)
    for _ in range(_LOCK_TRIES):
        fd = os.open(path, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            holder = os.pread(fd, 32, 0).decode("ascii", "replace").strip() or "?"
            os.close(fd)
            raise ValueError(
                f"{shown_path(out)} is being written by another bidmp command (process {holder}): "
                f"wait for it to finish, or give another output folder"
            ) from None
        except OSError:
            os.close(fd)
            raise
        with contextlib.suppress(FileNotFoundError):
            # the holder before us may have unlinked the file between our open and our flock
            if os.fstat(fd).st_ino == os.stat(path).st_ino:
                os.ftruncate(fd, 0)
                os.pwrite(fd, str(os.getpid()).encode(), 0)
                return fd
        os.close(fd)
    raise OSError(errno.EAGAIN, f"cannot lock {shown_path(out)}: its lock file keeps changing")


def _release(final: Path, fd: int) -> None:
    if fd < 0:
        return
    with contextlib.suppress(OSError):
        os.unlink(_lock_path(final))
    os.close(fd)


def _siblings(final: Path) -> list[Path]:
    """The leftovers of earlier runs beside ``final``: new folders never swapped in, old ones
    never deleted (their writers were killed)."""
    pattern = re.compile(rf"^\.{re.escape(final.name)}\.bidmp-(new|old)-\d+-[A-Za-z0-9_]+$")
    return sorted(
        entry for entry in final.parent.iterdir() if pattern.match(entry.name) is not None
    )


def _recover(final: Path) -> None:
    """Clear what killed runs left beside ``final`` (the lock is held: no run is writing). Where
    a run was killed between the two renames of a swap (systems without an atomic exchange), the
    earlier run is put back first."""
    leftovers = _siblings(final)
    if not final.exists() and not final.is_symlink():
        old = [entry for entry in leftovers if ".bidmp-old-" in entry.name and entry.is_dir()]
        if old:
            os.rename(old[-1], final)
            logger.warning("%s: put back the earlier run a killed run had moved aside", final)
            leftovers.remove(old[-1])
    for entry in leftovers:
        _remove(entry)


def _earlier(final: Path, out, overwrite: bool):
    """What the output folder holds now (None: nothing or an empty folder; a RunManifest; or
    "files": a folder --overwrite replaces), refusing one that holds files no run wrote."""
    if not final.exists():
        return None
    if not final.is_dir():
        raise ValueError(f"{shown_path(out)} is a file, not a folder: give an output folder")
    names = _files(final)
    problem, manifest = None, None
    try:
        manifest = read_manifest(final)
    except (OSError, ValueError) as exc:
        problem = f"its {MANIFEST} is unreadable ({str(exc)[:120]})"
    if manifest is None and problem is None:
        if not names and not (final / MANIFEST).exists():
            return None  # an empty folder (or one of empty folders)
        problem = f"it is not a bidmp run (no {MANIFEST} of a run; bidmp before 0.6 wrote none)"
    if manifest is not None:
        foreign = [name for name in names if name not in manifest.files]
        if foreign:
            more = f" and {len(foreign) - 1} more" if len(foreign) > 1 else ""
            problem = f"it holds {foreign[0]}{more}, which its run (in {MANIFEST}) did not write"
    if problem is None:
        return manifest
    if overwrite:
        return "files"
    raise ValueError(
        f"{shown_path(out)}: {problem}; give a new or empty folder, or --overwrite to replace "
        f"the folder whole (every file in it is deleted)"
    )


def _final(out) -> Path:
    out = Path(check_path(out, "out"))
    if str(out) in ("", "."):
        out = Path(".")
    final = Path(os.path.realpath(out))
    if final.parent == final:
        raise ValueError(f"out: {shown_path(out)} is the root folder; give an output folder")
    here = Path.cwd().resolve()
    if final == here or final in here.parents:
        raise ValueError(
            f"out: {shown_path(out)} is the folder you are in (or holds it): a run replaces its "
            f"folder whole; give a folder inside it"
        )
    return final


@contextlib.contextmanager
def run_folder(
    out,
    command: str,
    *,
    overwrite: bool = False,
    partial: bool = False,
    resume: bool = False,
) -> Iterator[RunFolder]:
    """Write a run into folder ``out``: yield a :class:`RunFolder` whose ``path`` the command
    writes into; on success its manifest is written and the run swapped in (the earlier run in
    ``out`` deleted), on any exception the earlier run is left as it was.

    Parameters
    ----------
    out : str or Path
        The output folder (made, with its parents, if missing). A symlink is written through.
    command : str
        The command line that writes the run, for the manifest (``bidmp job --targets 3``).
    overwrite : bool
        Replace a folder that holds files no bidmp run wrote (else ``ValueError`` naming one).
    partial : bool
        Write into ``.NAME.bidmp-partial`` beside ``out``, which a failed or killed run leaves
        for ``resume``.
    resume : bool
        With ``partial``: go on from the partial folder a failed run left (else it is cleared).

    Raises
    ------
    ValueError
        ``out`` is a file, the folder you are in, being written by another command, or holds
        files no run wrote (without ``overwrite``).
    OSError
        A write failed (a full disk): its message names the file and says what ``out`` holds.
    """
    if not isinstance(command, str) or not command:
        raise TypeError("command must be the command line that writes the run (text)")
    if resume and not partial:
        raise ValueError("resume goes on from a partial run: give partial=True")
    given = Path(check_path(out, "out"))
    final = _final(given)
    # the folders above it this run makes: a run that fails takes them away again (empty)
    made = [folder for folder in [final.parent, *final.parent.parents] if not folder.exists()]
    final.parent.mkdir(parents=True, exist_ok=True)
    try:
        lock = _acquire(final, given)
    except BaseException:
        _remove_empty(made)
        raise
    done = False
    try:
        _recover(final)
        earlier = _earlier(final, given, overwrite)
        if partial:
            path = final.parent / f".{final.name}.bidmp-partial"
            if not resume:
                _remove(path)
            path.mkdir(exist_ok=True)
            _remove(path / MANIFEST)
        else:
            _remove(final.parent / f".{final.name}.bidmp-partial")
            path = Path(
                tempfile.mkdtemp(prefix=f".{final.name}.bidmp-new-{os.getpid()}-", dir=final.parent)
            )
            os.chmod(path, 0o777 & ~_umask())
        run = RunFolder(given, final, path, command, earlier)
        try:
            yield run
            run.manifest = _write_manifest(path, command)
            _swap(run)
            done = True
        except OSError as exc:
            if not partial:
                _remove(path)
            raise _failure(exc, run, partial) from None
        except BaseException:
            if not partial:
                _remove(path)
            raise
    finally:
        _release(final, lock)
        if not done:
            _remove_empty(made)


def _remove_empty(folders) -> None:
    """Remove the folders (innermost first) that a run made above its output, if still empty."""
    for folder in folders:
        try:
            folder.rmdir()
        except OSError:
            return


def _failure(exc: OSError, run: RunFolder, partial: bool = False) -> OSError:
    """The error of a run that was not put in place: the file it could not write (where it would
    have been), why, and what the output folder holds (the earlier run, unchanged)."""
    # atomic_write gives the whole path as filename2 (its message shows the end of it)
    target = exc.filename2 or exc.filename
    if target:
        reason = os.strerror(exc.errno) if exc.errno else str(exc.strerror or exc)
        what = f"cannot write {shown_path(run.shown(target))} ({reason})"
    else:
        what = str(exc.strerror or exc)
    if partial:
        kept = f"its files so far are kept in {shown_path(run.path.name)} beside it, to resume"
        return OSError(exc.errno, f"{what}; {run.state()}; {kept}")
    return OSError(exc.errno, f"{what}; no file of this run was kept: {run.state()}")


def _swap(run: RunFolder) -> None:
    """Put the finished run in place of the earlier one and delete the earlier one."""
    try:
        _swap_folders(run)
    except OSError as exc:
        raise OSError(
            exc.errno,
            f"cannot put the new run in place of {shown_path(run.out)} "
            f"({os.strerror(exc.errno) if exc.errno else exc})",
        ) from None


def _swap_folders(run: RunFolder) -> None:
    final, new = run.final, run.path
    if run.earlier is None and not final.exists():
        os.rename(new, final)
    elif _exchange(new, final):
        _fsync_folder(final.parent)
        _remove(new)  # now the earlier run (or the empty folder)
        return
    elif run.earlier is None and not any(final.iterdir()):
        os.rename(new, final)  # onto an empty folder
    else:
        old = Path(
            tempfile.mkdtemp(prefix=f".{final.name}.bidmp-old-{os.getpid()}-", dir=final.parent)
        )
        os.rmdir(old)
        os.rename(final, old)
        try:
            os.rename(new, final)
        except OSError:
            os.rename(old, final)
            raise
        _fsync_folder(final.parent)
        _remove(old)
        return
    _fsync_folder(final.parent)


def update_manifest(folder, name: str) -> None:
    """After a command rewrote one file of a run (``bidmp view`` its page): the manifest's entry
    of ``name`` (relative to ``folder``, with ``/``) updated to the file as it is now, under the
    folder's lock. A folder that is not a run is left alone."""
    folder = Path(check_path(folder, "folder"))
    if not isinstance(name, str) or not name:
        raise TypeError(
            f"name must be a file's name in the run folder (text), got {type(name).__name__}"
        )
    relative = Path(check_path(name, "name"))
    if relative.is_absolute() or ".." in relative.parts or relative.as_posix() == MANIFEST:
        raise ValueError(
            f"name must be a file's name inside the run folder, got {shown_path(name)}"
        )
    final = Path(os.path.realpath(folder))
    manifest = read_manifest(final)
    if manifest is None:
        return
    path = final / relative
    if path.is_symlink() or not path.is_file():
        raise ValueError(
            f"name: {shown_path(name)} is not a file of the run in {shown_path(folder)}"
        )
    name = relative.as_posix()
    lock = _acquire(final, folder)
    try:
        files = dict(manifest.files)
        files[name] = (path.stat().st_size, _sha256(path))
        updated = RunManifest(manifest.run, manifest.command, manifest.bidmp, files)
        with atomic_write(final / MANIFEST, "w") as handle:
            json.dump(updated.to_dict(), handle, indent=1)
            handle.write("\n")
    finally:
        _release(final, lock)


# ---------------------------------------------------------------------------------------------
# Several output files of one command
# ---------------------------------------------------------------------------------------------
class OutputFiles:
    """Outputs of one command at places of the user's choosing (``bidmp rollout``'s ``-o``,
    ``--bag``, ``--plot``), written beside their places and put in place together
    (:func:`output_files`)."""

    def __init__(self) -> None:
        self._staged: list = []  # (given, final, staged, scratch folder)

    def path(self, output) -> Path:
        """Where to write ``output`` (a file, or a ROS 2 bag's folder): a path of the same name in
        a new hidden folder beside it."""
        given = Path(check_path(output, "output"))
        final = (
            Path(os.path.realpath(given)) if given.is_symlink() else Path(os.path.abspath(given))
        )
        if not final.parent.is_dir():
            raise ValueError(
                f"cannot write {shown_path(given)}: folder {shown_path(given.parent)} does not exist"
            )
        _clear_dead_scratch(final)
        scratch = Path(
            tempfile.mkdtemp(prefix=f".{final.name}.bidmp-new-{os.getpid()}-", dir=final.parent)
        )
        self._staged.append((given, final, scratch / final.name, scratch))
        return scratch / final.name

    def shown(self, written):
        """A written path (or a message naming it) as the user named the output."""
        text = str(written)
        for given, _, staged, _ in self._staged:
            text = text.replace(str(staged), str(given))
        return Path(text) if isinstance(written, Path) else text

    def _check(self) -> list:
        """The outputs written, each checked against what is at its place now (before any is
        put there: a file never replaces a folder, a bag folder only a bag folder)."""
        ready = []
        for given, final, staged, scratch in self._staged:
            if not staged.exists():
                # a writer that adds a suffix (save_model's .npz) wrote a name of its own
                inside = list(scratch.iterdir())
                if len(inside) != 1:
                    continue  # (not written: the command failed before it, or chose not to)
                staged = inside[0]
                final, given = final.parent / staged.name, given.parent / staged.name
            if staged.is_dir():
                if final.exists() and not (final.is_dir() and (final / "metadata.yaml").is_file()):
                    raise ValueError(
                        f"cannot write {shown_path(given)}: it is a "
                        f"{'folder that is not a ROS bag' if final.is_dir() else 'file'}; give a new name"
                    )
            elif final.exists() and not stat.S_ISREG(final.stat().st_mode):
                raise ValueError(
                    f"cannot write {shown_path(given)}: it is "
                    f"{'a folder' if final.is_dir() else 'not a regular file'}; give a file name"
                )
            ready.append((given, final, staged))
        return ready

    def _commit(self) -> None:
        ready = self._check()
        done = []
        for given, final, staged in ready:
            try:
                if staged.is_dir() and final.exists():
                    if not _exchange(staged, final):
                        shutil.rmtree(final)
                        os.rename(staged, final)
                else:
                    os.replace(staged, final)
            except OSError as exc:
                rest = [shown_path(g) for g, _, _ in ready[len(done) :]]
                raise OSError(
                    exc.errno,
                    f"cannot put {shown_path(given)} in place ({os.strerror(exc.errno or 0)}); "
                    f"replaced {', '.join(done) or 'none'}, not {', '.join(rest)}",
                ) from None
            done.append(shown_path(given))
            _fsync_folder(final.parent)

    def _clean(self) -> None:
        for _, _, _, scratch in self._staged:
            _remove(scratch)


def _clear_dead_scratch(final: Path) -> None:
    """Remove the hidden folders a killed command left beside ``final`` (their process is gone)."""
    from .atomic import _pid_alive

    pattern = re.compile(rf"^\.{re.escape(final.name)}\.bidmp-new-(\d+)-[A-Za-z0-9_]+$")
    for entry in final.parent.iterdir():
        match = pattern.match(entry.name)
        if match is not None and not _pid_alive(int(match.group(1))):
            _remove(entry)


@contextlib.contextmanager
def output_files() -> Iterator[OutputFiles]:
    """Several outputs of one command that appear together or not at all: each is written at
    ``files.path(output)`` (beside its place), and when the block ends without an error they are
    put in place one after another (a rename each), after every one was written and checked. On
    an error none is: the message says which would have been written and that none was replaced.

    A kill while they are put in place (a few renames) can leave some new and some old; a
    failure there names those replaced and those not.
    """
    files = OutputFiles()
    try:
        yield files
        files._commit()
    except OSError as exc:
        target = exc.filename2 or exc.filename
        if not target:
            raise
        names = ", ".join(shown_path(given) for given, _, _, _ in files._staged)
        raise OSError(
            exc.errno,
            f"cannot write {shown_path(files.shown(Path(target)))} "
            f"({os.strerror(exc.errno) if exc.errno else exc}); none of {names} was replaced",
        ) from None
    finally:
        files._clean()
