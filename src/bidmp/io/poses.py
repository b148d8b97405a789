"""Pose files: positions and unit quaternions (``t,x,y,z,qx,qy,qz,qw``), with the velocities and
angular velocities of a timed pose trajectory when written from one."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from .._checks import _as_bounded_array, as_trajectory, check_path, short_token
from .._units import check_units
from ._columns import parse_columns
from ._csv import _check_file, _csv_fast, _csv_rows, _note_ignored
from .trajectories import _write_columns

__all__ = ['read_poses', 'save_poses']

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
    from ..primitives.timing import _drop_duplicate_stamps
    from ._columns import select_poses

    path = check_path(path)
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
    return _drop_duplicate_stamps(poses, values[:, selection.time], f"{path}: the time column")


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
            raise ValueError(f"poses must have 7 columns (x, y, z, qx, qy, qz, qw), got {data.shape[1]}")
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
