"""A recording as a robot's logger wrote it: positions, poses or joints, with its stamps, its
columns' own names and the unit its convention fixes. One reader for CSVs (:func:`read_recording`)
and bags (:func:`bidmp.io.bags.read_bag`) alike; :func:`bidmp.io.read_trajectory` and
:func:`bidmp.io.read_poses` are its two narrow views."""

from __future__ import annotations

import os
from dataclasses import dataclass

import numpy as np

from .._checks import as_trajectory, check_path, short_token
from ._columns import Layout, parse_columns, resolve, times_in_seconds
from ._npy import _read_npy_trajectory

__all__ = ["Recording", "read_recording", "recording_kind", "is_joint_recording"]

KINDS = ("positions", "pose", "joints")


@dataclass(frozen=True)
class Recording:
    """A demonstration read from a file or a bag.

    Attributes
    ----------
    t : (n,) or None
        Stamps in seconds (as recorded in a CSV; from the first header stamp in a bag), None for
        a file without a time column.
    values : (n, D)
        Positions ``x, y[, z]``; poses ``x, y, z, qx, qy, qz, qw`` (a rotation vector in the file
        is turned into the quaternion); or joint positions.
    names : list of str
        The file's own names of the value columns (a joint recording's joint names).
    kind : {"positions", "pose", "joints"}
    units : str
        The unit the file declares (``# units: mm``) or its logger's convention fixes (metres for
        ROS and UR RTDE poses, radians for joints); "" when unknown.
    source : str
        What was read (``UR RTDE actual_TCP_pose_0..5``, ``topic /ee_pose``, ...).
    stamp : float
        The first stamp (s since the epoch for a logger's stamps; 0 without a time column).
    ignored : tuple of str
        The file's columns that were not read (a CSV's).
    orientation : (n, 4) or None
        Positions picked from a pose group (``columns="position=actual_TCP_pose"``): the tool's
        orientation beside them, ``qx, qy, qz, qw``.
    """

    t: np.ndarray | None
    values: np.ndarray
    names: list
    kind: str
    units: str
    source: str
    stamp: float
    ignored: tuple = ()
    orientation: np.ndarray | None = None


def _header_line(path) -> str:
    """The first line that is not a comment ("" if none or unreadable)."""
    try:
        with open(path, encoding="utf-8-sig") as handle:
            for _ in range(64):
                line = handle.readline(1 << 16)
                if not line:
                    return ""
                if line.strip() and not line.lstrip().startswith("#"):
                    return line.strip()
    except (OSError, UnicodeDecodeError):
        return ""
    return ""


def recording_kind(path: str | os.PathLike, *, columns=None) -> str:
    """What a CSV recording holds by its header (and ``columns``): ``"positions"``, ``"pose"``,
    ``"joints"``, or ``""`` when that is not known without reading it (no header, not a CSV, a
    header that names no motion or several: :func:`read_recording` says why)."""
    from ._csv import _csv_delimiter, _is_number, _split

    path = check_path(path)
    if path.suffix.lower() not in (".csv", ".txt") or not path.is_file():
        return (
            ""  # (a FIFO or a device is refused by the reader, never opened here: it would block)
        )
    line = _header_line(path)
    header = tuple(name.strip() for name in _split(line, _csv_delimiter(line)))
    if not line or all(not name or _is_number(name) for name in header):
        return ""
    try:
        return resolve(header, parse_columns(columns), path).kind
    except ValueError:
        return ""


def is_joint_recording(path) -> bool:
    """Whether a CSV's header is a joint-space recording (``t, <joint names>``, or a logger's
    joint columns such as UR RTDE ``actual_q_0..5``): its values are joint angles, in radians
    unless it declares otherwise."""
    return recording_kind(path) == "joints"


def read_recording(path: str | os.PathLike, *, columns=None) -> Recording:
    """Read a demonstration from a CSV (with or without a header) or an ``.npy`` array.

    The header's names say what the columns hold, as robot loggers write them (plain ``t,x,y,z``
    and ``x,y,z,qx,qy,qz,qw``, UR RTDE ``timestamp`` + ``actual_TCP_pose_0..5`` or
    ``actual_q_0..5``, ROS exports ``header.stamp`` + ``pose.position.x`` ..., ``t, <joint
    names>``); ``columns`` decides where they do not (:mod:`bidmp.io._columns`). A file whose
    columns hold several motions is refused with the candidates listed. Comma, semicolon, tab or
    space separated; ``#`` comments; ``# units: mm`` declares the unit. Samples whose stamp
    repeats the one before are dropped, with a warning; stamps going back are refused.

    Returns
    -------
    Recording
    """
    from ..primitives.timing import drop_repeated_stamps
    from ._csv import (
        _check_file,
        _csv_fast,
        _csv_rows,
        _note_ignored,
        check_finite_rows,
        declared_units,
    )

    path = check_path(path)
    _check_file(path, "demonstration file")
    suffix = path.suffix.lower()
    if suffix == ".npy":
        if columns is not None:
            raise ValueError(
                f"{path}: a column mapping applies to CSV files with a header, not to .npy arrays"
            )
        positions, times = _read_npy_trajectory(path)
        layout = None
    elif suffix in (".csv", ".txt"):
        mapping = parse_columns(columns)
        parsed = _csv_fast(path)
        header, values, text = parsed if parsed is not None else _csv_rows(path)
        if header is None:
            if mapping is not None:
                raise ValueError(
                    f"{path} has no header, so --columns / columns= cannot name its columns"
                )
            positions, times, layout = _headerless(values, path), None, None
            if values.shape[1] == 4:
                positions, times = values[:, 1:], values[:, 0]
        else:
            layout = resolve(header, mapping, path)
            used_text = set(text) & {*layout.time, *layout.values}
            if used_text:
                raise ValueError(
                    f"{path}: column {short_token(header[min(used_text)], 30)} holds text, not numbers"
                )
            _note_ignored(path, layout.ignored)
            check_finite_rows(
                path, values, (*layout.time, *layout.values, *layout.orientation), header, True
            )
            times = times_in_seconds(values, layout, path)
            positions = _values(values, layout, path)
            if layout.orientation:  # read beside the positions, filtered with them
                orientation = _quaternions(
                    values[:, list(layout.orientation)], layout.rotation, path
                )
                positions = np.hstack([positions, orientation])
    else:
        raise ValueError(
            f"{path}: unsupported file type {short_token(suffix)[1:-1] if suffix else '(none)'}; use .csv or .npy"
        )
    kind = "positions" if layout is None else layout.kind
    positions = as_trajectory(positions, name=str(path), allow_static=kind == "pose")
    if times is not None:
        positions, times = drop_repeated_stamps(positions, times, f"{path}: the time column")
    orientation = None
    if layout is not None and layout.orientation:
        positions, orientation = positions[:, :3], positions[:, 3:]
        positions = as_trajectory(positions, name=str(path))
    declared = declared_units(path) if suffix in (".csv", ".txt") else ""
    if layout is None:
        names, units, source = (
            [],
            declared,
            f"{'an .npy array' if suffix == '.npy' else 'columns without a header'}",
        )
    else:
        names, units, source = list(layout.names), declared or layout.units, layout.label
    return Recording(
        times,
        positions,
        names,
        kind,
        units,
        source,
        float(times[0]) if times is not None else 0.0,
        () if layout is None else layout.ignored,
        orientation,
    )


def _headerless(values: np.ndarray, path) -> np.ndarray:
    if values.shape[1] in (
        2,
        3,
        4,
    ):  # x,y[,z] or t,x,y,z (add a header "t,x,y" to mark a time column)
        return values
    raise ValueError(
        f"{path}: expected 2-4 columns (x,y[,z] or t,x,y,z) without a header, found {values.shape[1]}"
    )


def _values(values: np.ndarray, layout: Layout, path="the recording") -> np.ndarray:
    """The value columns of ``values`` in the layout's order; a pose's rotation as a quaternion."""
    data = values[:, list(layout.values)]
    if layout.kind != "pose":
        return data
    return np.hstack([data[:, :3], _quaternions(data[:, 3:], layout.rotation, path)])


def _quaternions(rotation: np.ndarray, kind: str, path="the recording") -> np.ndarray:
    """Rotation columns as quaternions ``qx, qy, qz, qw``: as they are, or from a rotation vector
    (UR's axis-angle, radians). A rotation vector longer than 2π is no axis-angle in radians (an
    angle in degrees, or roll/pitch/yaw put in its place): refused, saying so — read as radians
    it would turn the tool by a wrong angle about a wrong axis, silently."""
    if kind != "rotvec" or not np.all(np.isfinite(rotation)):
        return rotation  # (a bad value: as_trajectory names it)
    lengths = np.linalg.norm(rotation, axis=1)
    over = np.flatnonzero(lengths > 2.0 * np.pi + 1e-9)
    if over.size:
        row = int(over[0])  # the first, where a user looking at the file finds it
        raise ValueError(
            f"{path}: the rotation-vector columns (rx, ry, rz: an axis times an angle in radians) "
            f"reach length {lengths[row]:.4g} at data row {row + 1} (> 2π): degrees, or roll/pitch/"
            f"yaw? Write the rotation as a rotation vector in radians, or as a quaternion "
            f"(qx, qy, qz, qw)"
        )
    from scipy.spatial.transform import Rotation

    return Rotation.from_rotvec(rotation).as_quat()
