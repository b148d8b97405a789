"""The protocol's tasks (the CLFD data vendored with bidmp, MIT, ``bidmp/data/clfd/LICENSE``) and
the chart in which a pose task is learned: positions with the orientation's logarithm at a
reference orientation, a flat space in which any primitive of positions learns poses."""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from ..._checks import as_point, check_choice

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

    @property
    def poses(self) -> np.ndarray:
        """(M, T, D [+ 4]): the positions, then the quaternion of a pose task."""
        if self.orientations is None:
            return self.positions
        return np.concatenate([self.positions, self.orientations], axis=2)


def clfd_tasks(dataset: str = "lasa") -> list[ClfdTask]:
    """The protocol's tasks in the order they are learned: ``"lasa"``, the 26 LASA shapes (7
    demonstrations each, raw LASA units), or ``"robottasks"``, RoboTasks9's 9 pose tasks (9
    demonstrations each, position and quaternion)."""
    check_choice(dataset, "dataset", CLFD_DATASETS)
    if dataset == "robottasks":
        folder = DATA / "robottasks"
        order = (folder / "robottasks_pos_ori_sequence_all.txt").read_text().split()
        tasks = []
        for file_name in order:
            data = np.load(folder / "pos_ori" / file_name).astype(float)
            t = np.linspace(0.0, _ROBOTTASKS_DURATION_S, data.shape[1])
            times = np.broadcast_to(t, data.shape[:2]).copy()
            tasks.append(ClfdTask(Path(file_name).stem, data[:, :, :3], times, data[:, :, 3:]))
        return tasks
    folder = DATA / "LASA"
    order = (folder / "lasa_numpy_sequence_all.txt").read_text().split()
    names = list(json.loads((folder / "lasa_names.json").read_text()))
    tasks = []
    for file_name in order:
        index = int(file_name.split("_")[1][1:])
        with np.load(folder / "lasa_numpy" / file_name) as archive:
            tasks.append(ClfdTask(names[index], archive["pos"].astype(float), archive["t"]))
    return tasks


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
            norm = float(np.linalg.norm(reference))
            if norm < 1e-9:
                raise ValueError("reference must be a unit quaternion (w, x, y, z), got zero")
            reference = reference / norm
        self.reference = reference

    @classmethod
    def of_task(cls, task: ClfdTask) -> TangentChart:
        """The chart at the task's first demonstration's start orientation (positions only: the
        identity)."""
        return cls(None if task.orientations is None else task.orientations[0, 0])

    def curves(self, poses: np.ndarray) -> np.ndarray:
        """(..., D + 3) of poses (..., D + 4); positions (..., D) unchanged without a reference."""
        poses = np.asarray(poses, dtype=float)
        if self.reference is None:
            return poses
        relative = Rotation.from_quat(_xyzw(self.reference)).inv() * Rotation.from_quat(
            _xyzw(poses[..., -4:].reshape(-1, 4))
        )
        rotvec = relative.as_rotvec().reshape(poses.shape[:-1] + (3,))
        return np.concatenate([poses[..., :-4], rotvec], axis=-1)

    def poses(self, curves: np.ndarray) -> np.ndarray:
        """(..., D + 4) of curves (..., D + 3): :meth:`curves` undone."""
        curves = np.asarray(curves, dtype=float)
        if self.reference is None:
            return curves
        absolute = Rotation.from_quat(_xyzw(self.reference)) * Rotation.from_rotvec(
            curves[..., -3:].reshape(-1, 3)
        )
        q = _wxyz(absolute.as_quat()).reshape(curves.shape[:-1] + (4,))
        return np.concatenate([curves[..., :-3], q], axis=-1)
