"""Pose files: positions and unit quaternions (``t,x,y,z,qx,qy,qz,qw``), with the velocities and
angular velocities of a timed pose trajectory when written from one."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .._checks import _as_bounded_array, as_trajectory, check_path
from .._units import check_units
from .trajectories import _write_columns

__all__ = ["read_poses", "save_poses"]


def read_poses(path: str | os.PathLike, *, columns=None) -> tuple[np.ndarray, np.ndarray | None]:
    """Read a pose recording (CSV with a header): poses ``(T, 7)`` as ``x, y, z, qx, qy, qz,
    qw`` (scalar last) and timestamps (s) or None.

    The header must name the columns ``x, y, z, qx, qy, qz, qw`` in any order (or a rotation
    vector ``rx, ry, rz`` in radians, or a logger's own names: UR RTDE ``actual_TCP_pose_0..5``,
    ROS ``pose.position.x`` … ``pose.orientation.w``), and optionally a time column; other
    columns are ignored with a warning (a timed pose trajectory written by :func:`save_poses`
    reads too). ``columns`` decides (as :func:`read_trajectory`, e.g.
    ``pose=target_TCP_pose``). The quaternion's order is taken from the names, never guessed
    from the numbers; ``qw`` first or last both read. Quaternions are checked by
    :class:`bidmp.CartesianDMP` (sign flips, unit length) when it fits them. Samples whose
    timestamp repeats the one before are dropped, with a warning.
    """
    from .recordings import read_recording

    path = check_path(path)
    if path.suffix.lower() not in (".csv", ".txt"):
        raise ValueError(f"{path}: pose recordings are read from .csv files with a header")
    recording = read_recording(path, columns=columns)
    if recording.kind != "pose":
        accepted = "x,y,z with qx,qy,qz,qw or rx,ry,rz, a UR RTDE actual_TCP_pose_0..5, a ROS pose.position/orientation"
        raise ValueError(
            f"{path}: its columns ({recording.source}) hold {recording.kind}, not poses; a pose file's header "
            f"names {accepted} (t optional)"
        )
    return recording.values, recording.t


def save_poses(poses, path: str | os.PathLike, times=None, *, units: str | None = None) -> Path:
    """Write poses ``(T, 7)`` (x, y, z, qx, qy, qz, qw) or a :class:`bidmp.primitives.cartesian.PoseTrajectory`
    to a CSV with the header ``[t,]x,y,z,qx,qy,qz,qw`` (a trajectory adds ``vx..vz, wx..wz,
    ax..az, dwx..dwz``: units/s, rad/s, units/s², rad/s², as :meth:`PoseTrajectory.columns`),
    atomically; with a known unit (``units`` or the trajectory's) a first line ``# units: mm``."""
    from ..primitives.cartesian import PoseTrajectory

    path = check_path(path)
    names = ["x", "y", "z", "qx", "qy", "qz", "qw"]
    if isinstance(poses, PoseTrajectory):
        names, data = poses.columns()
        units = poses.units if units is None else units
    else:
        data = as_trajectory(poses, "poses", min_points=1, allow_static=True)
        if data.shape[1] != 7:
            raise ValueError(
                f"poses must have 7 columns (x, y, z, qx, qy, qz, qw), got {data.shape[1]}"
            )
        if times is not None:
            times = _as_bounded_array(times, "times", max_ndim=1).reshape(-1)
            if times.shape[0] != data.shape[0] or not np.all(np.isfinite(times)):
                raise ValueError(f"times must be {data.shape[0]} finite numbers")
            data, names = np.column_stack([times, data]), ["t", *names]
    if not np.all(np.isfinite(data)):
        raise ValueError("the poses contain NaN or inf")
    if path.suffix.lower() != ".csv":
        raise ValueError(f"{path}: poses are written as .csv")
    return _write_columns(data, names, data, path, check_units(units, "units"))
