"""The protocol's tasks (the CLFD data vendored with bidmp, MIT, ``bidmp/data/clfd/LICENSE``) and
the chart in which a pose task is learned: positions with the orientation's logarithm at a
reference orientation, a flat space in which any primitive of positions learns poses."""

from __future__ import annotations

import os
import re
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ..._checks import (
    _as_bounded_array,
    _check_finite,
    _check_magnitude,
    _limit,
    as_point,
    check_choice,
    check_path,
    printable,
    shown_path,
)
from ..._norms import row_norms

__all__ = ["CLFD_DATASETS", "ClfdTask", "TangentChart", "clfd_tasks"]

DATA = Path(__file__).resolve().parents[2] / "data" / "clfd"
CLFD_DATASETS = ("lasa", "robottasks")
# RoboTasks9's files hold no time stamps (1000 samples resampled from 60 Hz recordings of
# different lengths): a uniform time over 1 s. No metric depends on it (they compare samples);
# it only sets a DMP's time constant.
_ROBOTTASKS_DURATION_S = 1.0


@dataclass(frozen=True)
class ClfdTask:
    """One task of the protocol.

    Attributes
    ----------
    name : str
    positions : array (M, T, D)
        The M demonstrations' positions (raw units of the data set).
    times : array (M, T)
        Their time stamps, s.
    orientations : array (M, T, 4) or None
        Unit quaternions **w, x, y, z** of a pose task (RoboTasks9), None for positions only.
    """

    name: str
    positions: np.ndarray
    times: np.ndarray
    orientations: np.ndarray | None = None

    def __post_init__(self) -> None:
        """Check the arrays (a method learns from them as they are) and keep them as float64."""
        if not isinstance(self.name, str) or not 0 < len(self.name) <= 200:
            raise TypeError(f"name must be the task's name (text), got {type(self.name).__name__}")
        positions = _as_bounded_array(self.positions, "positions", 3)
        if positions.ndim != 3 or min(positions.shape) < 1 or positions.shape[1] < 2:
            raise ValueError(
                "positions must be (M, T, D): M demonstrations of T >= 2 samples, got shape "
                f"{positions.shape}"
            )
        _check_finite(positions, "positions")
        _check_magnitude(positions, "positions")
        times = _as_bounded_array(self.times, "times", 2)
        if times.shape != positions.shape[:2]:
            raise ValueError(
                f"times must be (M, T) = {positions.shape[:2]}, one stamp per sample of positions, "
                f"got shape {times.shape}"
            )
        _check_finite(times, "times")
        _check_magnitude(times, "times")
        if np.any(np.diff(times, axis=1) <= 0.0):
            raise ValueError("times must increase along each demonstration (s)")
        orientations = self.orientations
        if orientations is not None:
            orientations = _as_bounded_array(orientations, "orientations", 3)
            if orientations.shape != positions.shape[:2] + (4,):
                raise ValueError(
                    f"orientations must be (M, T, 4) = {positions.shape[:2] + (4,)} quaternions "
                    f"w, x, y, z, one per sample of positions, got shape {orientations.shape}"
                )
            _check_finite(orientations, "orientations")
            if np.any(row_norms(orientations) < 1e-9):
                raise ValueError("orientations holds a zero quaternion, which is no rotation")
        object.__setattr__(self, "positions", positions)
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "orientations", orientations)

    @property
    def poses(self) -> np.ndarray:
        """(M, T, D [+ 4]): the positions, then the quaternion of a pose task."""
        if self.orientations is None:
            return self.positions
        return np.concatenate([self.positions, self.orientations], axis=2)


def clfd_tasks(dataset: str = "lasa", folder=None) -> list[ClfdTask]:
    """The protocol's tasks in the order they are learned: ``"lasa"``, the 26 LASA shapes (7
    demonstrations each, raw LASA units), or ``"robottasks"``, RoboTasks9's 9 pose tasks (9
    demonstrations each, position and quaternion).

    ``folder``: a copy of the data folder to read (``LASA/`` and ``robottasks/`` as in
    ``bidmp/data/clfd``; default the copy bundled with bidmp). Every file is checked — a
    missing, truncated, empty or garbled one, a member missing, an array of the wrong shape or not
    finite is refused naming the file, never NumPy's or zipfile's own error."""
    check_choice(dataset, "dataset", CLFD_DATASETS)
    folder = DATA if folder is None else check_path(folder, "folder")
    if dataset == "robottasks":
        root = folder / "robottasks"
        tasks = []
        for file_name in _sequence(root / "robottasks_pos_ori_sequence_all.txt", ".npy"):
            path = root / "pos_ori" / file_name
            data = _read(path, "a RoboTasks9 task (.npy)", _read_npy)
            if data.ndim != 3 or data.shape[2] != 7:
                _refuse(path, f"holds shape {data.shape}, not (M, T, 7) poses")
            t = np.linspace(0.0, _ROBOTTASKS_DURATION_S, data.shape[1])
            times = np.broadcast_to(t, data.shape[:2]).copy()
            tasks.append(_task(path, Path(file_name).stem, data[:, :, :3], times, data[:, :, 3:]))
        return tasks
    root = folder / "LASA"
    order = _sequence(root / "lasa_numpy_sequence_all.txt", ".npz")
    names = _read(root / "lasa_names.json", "the LASA shapes' names (.json)", _read_names)
    tasks = []
    for file_name in order:
        path = root / "lasa_numpy" / file_name
        index = int(re.fullmatch(_LASA_FILE, file_name).group(1))
        if index >= len(names):
            _refuse(path, f"is shape {index}, but lasa_names.json names only {len(names)} shapes")
        positions, times = _read(path, "a LASA task (.npz)", _read_npz)
        tasks.append(_task(path, names[index], positions, times))
    return tasks


# the files a sequence may name: plain names in the task folder (no path of their own)
_LASA_FILE = r"task_x(\d{1,4})_y\d{1,4}\.npz"
_ROBOTTASKS_FILE = r"[A-Za-z0-9_-]{1,100}\.npy"
_MAX_TASKS = 1000


def _refuse(path: Path, what: str):
    raise ValueError(f"folder: {shown_path(path)} {what}")


def _read(path: Path, kind: str, reader):
    """``reader(path)`` of a data file, every way a damaged one fails turned into one line that
    names it and says what it should be."""
    try:
        size = os.stat(path).st_size
    except OSError as exc:
        reason = f"cannot be read ({printable(exc.strerror or type(exc).__name__)})"
    else:
        if size > _limit("max_file_bytes"):
            _refuse(path, f"is {size:,} bytes, more than max_file_bytes (bidmp.set_limits)")
        try:
            return reader(path)
        except zipfile.BadZipFile:
            reason = f"is not {kind}: not a zip archive (truncated or another file)"
        except EOFError:
            reason = f"is not {kind}: it ends early (truncated or empty)"
        except (OSError, ValueError, KeyError, IndexError) as exc:
            text = str(exc)
            # (NumPy's refusal of a pickle is a paragraph on trusting the file)
            text = "it holds Python objects, not arrays" if "pickle" in text else text
            reason = f"is not {kind}: {printable(text or type(exc).__name__)[:100]}"
    _refuse(path, reason)


def _sequence(path: Path, suffix: str) -> list[str]:
    """The task files a sequence file names, in order: plain file names, one per line."""
    order = _read(path, "a task sequence (.txt)", lambda p: p.read_text(encoding="utf-8").split())
    pattern = _LASA_FILE if suffix == ".npz" else _ROBOTTASKS_FILE
    if not 1 <= len(order) <= _MAX_TASKS:
        _refuse(path, f"names {len(order)} task files, not 1 to {_MAX_TASKS}")
    for file_name in order:
        if not re.fullmatch(pattern, file_name):
            _refuse(path, f"names {printable(file_name)[:40]!r}, not a task file ({suffix})")
    return order


def _read_names(path: Path) -> list[str]:
    from ...io.strict_json import load_json

    names = load_json(path.read_bytes(), "lasa_names.json")
    if not isinstance(names, (dict, list)) or not all(
        isinstance(name, str) and 0 < len(name) <= 200 for name in names
    ):
        raise ValueError("it is not a list (or mapping) of the shapes' names")
    return list(names)


def _read_npy(path: Path) -> np.ndarray:
    # opened here, so that it is closed whatever NumPy makes of it
    with open(path, "rb") as handle:
        return _numbers(np.load(handle, allow_pickle=False), "the array")


def _read_npz(path: Path) -> tuple[np.ndarray, np.ndarray]:
    with open(path, "rb") as handle:
        archive = np.load(handle, allow_pickle=False)
        if not isinstance(archive, np.lib.npyio.NpzFile):
            raise ValueError("it is one array, not an archive of pos and t")
        with archive:
            missing = [name for name in ("pos", "t") if name not in archive.files]
            if missing:
                raise ValueError(f"it has no member {missing[0]!r}")
            return _numbers(archive["pos"], "pos"), _numbers(archive["t"], "t")


def _numbers(array: np.ndarray, what: str) -> np.ndarray:
    if not isinstance(array, np.ndarray) or array.dtype.kind not in "fiu":
        raise ValueError(
            f"{what} holds {getattr(array, 'dtype', type(array).__name__)}, not numbers"
        )
    return array.astype(float)


def _task(path: Path, name: str, positions, times, orientations=None) -> ClfdTask:
    """The task of one file, its arrays checked; a bad one is refused naming the file."""
    try:
        return ClfdTask(name, positions, times, orientations)
    except (ValueError, TypeError) as exc:
        reason = f"holds a bad task: {printable(str(exc))[:120]}"
    _refuse(path, reason)


def _xyzw(q: np.ndarray) -> np.ndarray:
    return q[..., [1, 2, 3, 0]]


def _wxyz(q: np.ndarray) -> np.ndarray:
    return q[..., [3, 0, 1, 2]]


class TangentChart:
    """Poses ↔ flat curves: ``[p, log(q_ref⁻¹ ⊗ q)]`` with the rotation vector (rad) of each
    orientation relative to ``reference`` — the unit sphere of quaternions mapped to its tangent
    space at the reference, where straight lines are geodesics through it. Exact both ways (to
    rounding) for rotations within π of the reference; the protocol's tasks turn by at most
    about 2 rad from their first demonstration's start. ``reference=None``: positions only, the
    identity both ways.

    Parameters
    ----------
    reference : array (4,) or None
        Unit quaternion **w, x, y, z**.
    """

    def __init__(self, reference: np.ndarray | None = None):
        if reference is not None:
            reference = as_point(reference, 4, "reference")
            norm = float(row_norms(reference))
            if norm < 1e-9:
                raise ValueError("reference must be a unit quaternion (w, x, y, z), got zero")
            reference = reference / norm
        self.reference = reference

    def _checked(self, values, name: str, rotation: int) -> np.ndarray:
        """``values`` (..., width) as float64: finite, 1 to 3 axes, with D >= 1 position columns
        before the ``rotation`` columns of a pose (none without a reference)."""
        array = _as_bounded_array(values, name, 3)
        least = 1 if self.reference is None else rotation + 1
        if array.ndim == 0 or array.shape[-1] < least:
            what = "positions" if self.reference is None else f"positions and {rotation} rotation"
            raise ValueError(
                f"{name} must be (..., {'D' if self.reference is None else f'D + {rotation}'}) "
                f"({what} columns), got shape {array.shape}"
            )
        _check_finite(array, name)
        _check_magnitude(array, name)
        return array

    @classmethod
    def of_task(cls, task: ClfdTask) -> TangentChart:
        """The chart at the task's first demonstration's start orientation (positions only: the
        identity)."""
        return cls(None if task.orientations is None else task.orientations[0, 0])

    def curves(self, poses: np.ndarray) -> np.ndarray:
        """(..., D + 3) of poses (..., D + 4); positions (..., D) unchanged without a reference."""
        poses = self._checked(poses, "poses", 4)
        if self.reference is None:
            return poses
        relative = Rotation.from_quat(_xyzw(self.reference)).inv() * Rotation.from_quat(
            _xyzw(poses[..., -4:].reshape(-1, 4))
        )
        rotvec = relative.as_rotvec().reshape(poses.shape[:-1] + (3,))
        return np.concatenate([poses[..., :-4], rotvec], axis=-1)

    def poses(self, curves: np.ndarray) -> np.ndarray:
        """(..., D + 4) of curves (..., D + 3): :meth:`curves` undone."""
        curves = self._checked(curves, "curves", 3)
        if self.reference is None:
            return curves
        absolute = Rotation.from_quat(_xyzw(self.reference)) * Rotation.from_rotvec(
            curves[..., -3:].reshape(-1, 3)
        )
        q = _wxyz(absolute.as_quat()).reshape(curves.shape[:-1] + (4,))
        return np.concatenate([curves[..., :-3], q], axis=-1)
