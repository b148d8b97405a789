"""Trajectory files: positions with or without timestamps, as CSV (``t,x,y,z``, ``# units:``) or
NPY, read and written (atomically)."""

from __future__ import annotations

import csv
import os
from pathlib import Path

import numpy as np

from .._checks import _as_bounded_array, as_trajectory, check_path, short_token
from .._units import check_units
from ._csv import declared_units
from .atomic import _destination, atomic_write
from .recordings import is_joint_recording

__all__ = [
    "load_trajectory",
    "read_trajectory",
    "save_trajectory",
    "declared_units",
    "is_joint_recording",
]


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


def read_trajectory(
    path: str | os.PathLike, *, columns=None
) -> tuple[np.ndarray, np.ndarray | None]:
    """Read a demonstration from ``.csv`` or ``.npy``: positions and, if the file has them,
    timestamps in seconds (as recorded: any monotone stamps, epoch-like or jittered).

    CSV: one sample per row, comma, semicolon, tab or space separated, ``#`` comments allowed,
    UTF-8 with or without a byte-order mark. An optional header names the columns: ``x,y[,z]``
    with a time column ``t`` (``time``, ``timestamp``, ``stamp``, a ROS ``header.stamp``), a
    robot logger's own names (UR RTDE, ROS exports, ``t,<joint names>``: see
    :func:`bidmp.io.read_recording`), other columns ignored with a warning that names them;
    ``columns`` decides, e.g. ``"t=stamp,x=ee_x,y=ee_y,z=ee_z"`` or
    ``"t=timestamp,position=actual_TCP_pose"``. A timed trajectory written by bidmp
    (``t,x,y[,z],vx,…,ax,…``) reads its positions and times. Without a header 2 or 3 columns are positions and 4 columns
    are ``t,x,y,z``. Samples whose timestamp repeats the one before are dropped, with a warning.
    NPY: a float array of shape (T, D) (positions), or a structured array of shape (T,) with
    fields ``t, x, y[, z]`` (and optionally ``vx … az``), as :func:`save_trajectory` writes a
    :class:`bidmp.Trajectory`; read with ``allow_pickle=False`` after its header passed the
    size limits.

    Returns
    -------
    (y, t) : array (T, D) and array (T,) or None
    """
    from .recordings import read_recording

    recording = read_recording(path, columns=columns)
    if recording.kind == "pose":
        raise ValueError(
            f"{check_path(path)}: a pose recording ({recording.source}): read it with bidmp.io.read_poses / "
            f"bidmp.CartesianDMP, or pick its positions with --columns / columns= (x=..,y=..,z=.. or "
            f"position=<prefix>)"
        )
    return recording.values, recording.t


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
        raise TypeError(
            "save_trajectory takes (y, path): the trajectory first, then the file (as save_model)"
        )
    path = check_path(path)
    if isinstance(y, Trajectory):
        if times is not None:
            raise TypeError("times is given by the Trajectory itself")
        names, data = y.columns()
        for name, column in (("t", y.t), ("yd", y.yd), ("ydd", y.ydd)):
            if not np.all(np.isfinite(column)):
                raise ValueError(f"the trajectory's {name} contains NaN or inf")
        return _write_columns(
            as_trajectory(y.y, "y", min_points=1, allow_static=True),
            names,
            data,
            path,
            y.units if units is None else units,
        )
    y = as_trajectory(y, "y", min_points=1, allow_static=True)
    _destination(path)
    suffix = path.suffix.lower()
    if suffix not in (".npy", ".csv"):
        raise ValueError(
            f"{path}: unsupported file type {short_token(suffix)[1:-1] if suffix else '(none)'}; use .csv or .npy"
        )
    if suffix == ".npy" and times is None:
        with atomic_write(path, "wb") as handle:
            np.save(handle, y, allow_pickle=False)
        return path
    units = check_units(units, "units")
    names = (
        ["x", "y", "z"][: y.shape[1]] if y.shape[1] <= 3 else [f"x{i}" for i in range(y.shape[1])]
    )
    data = y
    if times is not None:
        times = _as_bounded_array(times, "times", max_ndim=1).reshape(-1)
        if times.shape[0] != y.shape[0]:
            raise ValueError(f"times has {times.shape[0]} entries for {y.shape[0]} samples")
        if not np.all(np.isfinite(times)):
            raise ValueError("times contains NaN or inf")
        names = ["t", *names]
        data = np.column_stack([times, y])
    return _write_columns(y, names, data, path, units)


def _write_columns(
    y: np.ndarray, names: list[str], data: np.ndarray, path: Path, units: str = ""
) -> Path:
    """Write named columns as CSV (a ``# units:`` comment when known, a header row) or as a
    structured ``.npy`` (one field each)."""
    from .._units import check_units

    units = check_units(units)
    _destination(path)
    suffix = path.suffix.lower()
    if suffix not in (".npy", ".csv"):
        raise ValueError(
            f"{path}: unsupported file type {short_token(suffix)[1:-1] if suffix else '(none)'}; use .csv or .npy"
        )
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
