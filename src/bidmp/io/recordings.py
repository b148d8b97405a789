"""A recording as a robot's logger wrote it: positions, poses or joints, with its stamps, its
columns' own names and the unit its convention fixes. One reader for CSVs (:func:`read_recording`)
and bags (:func:`bidmp.io.bags.read_bag`) alike; :func:`bidmp.io.read_trajectory` and
:func:`bidmp.io.read_poses` are its two narrow views."""

from __future__ import annotations

import dataclasses
import logging
import os
from dataclasses import dataclass

import numpy as np

from .._checks import as_trajectory, check_path, short_token
from .._units import UNITS
from ._columns import Layout, parse_columns, resolve, split_unit, times_in_seconds
from ._conventions import _TIME_DIVISORS
from ._npy import _read_npy_trajectory

__all__ = ["Recording", "read_recording", "recording_kind", "is_joint_recording"]

logger = logging.getLogger(__name__)

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
    repeated : tuple of (int, float)
        The samples dropped because their stamp repeats the one before: (data row, 1-based
        among the file's data rows; the stamp, s). A command stream judged sample by sample
        refuses them; a demonstration loses nothing.
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
    repeated: tuple = ()


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
        decimal = (mapping or {}).get("decimal", "auto")
        parsed = _csv_fast(path, decimal)
        header, values, text = parsed if parsed is not None else _csv_rows(path, decimal)
        if header is None:
            if mapping is not None and set(mapping) - {"decimal"}:
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
            used = (*layout.time, *layout.values, *layout.orientation)
            if (mapping or {}).get("gaps") == "drop":
                values, text = _without_gaps(path, values, text, used, header)
            check_finite_rows(path, values, used, header, True)
            times = times_in_seconds(values, layout, path)
            _check_time_unit(path, times, layout, header)
            positions = _values(values, layout, path)
            if layout.kind == "joints" and layout.units == "deg":
                positions = np.radians(positions)  # joints are read in radians
                layout = dataclasses.replace(layout, units="rad")
                logger.info(
                    "%s: joint angles in degrees (by the columns' names), read in radians", path
                )
            if layout.orientation:  # read beside the positions, filtered with them
                orientation = _quaternions(
                    values[:, list(layout.orientation)],
                    layout.rotation,
                    path,
                    layout.euler,
                    layout.angles,
                )
                positions = np.hstack([positions, orientation])
    else:
        raise ValueError(
            f"{path}: unsupported file type {short_token(suffix)[1:-1] if suffix else '(none)'}; use .csv or .npy"
        )
    kind = "positions" if layout is None else layout.kind
    # an arm standing still is a joint record as good as any (a command stream may hold still)
    positions = as_trajectory(positions, name=str(path), allow_static=kind in ("pose", "joints"))
    repeated = ()
    if times is not None:
        repeated = _repeated_stamps(times)
        positions, times = drop_repeated_stamps(positions, times, f"{path}: the time column")
    if layout is not None and layout.rotation is not None:
        turns = positions[:, 3:7] if kind == "pose" else positions[:, 3:]
        _check_orientation_jumps(path, turns, times)
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
        names = (
            _joint_names(path, layout, text, header) if layout.names_from else list(layout.names)
        )
        units, source = _units(path, layout, declared, names), layout.label
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
        repeated,
    )


def _units(path, layout: Layout, declared: str, names: list) -> str:
    """The unit of a file read with a header: the one it declares (``# units: mm``), else its
    columns' convention. A length declared on joints is refused: their angles are radians, and
    a length there says the columns are positions read as joints, or the line is wrong."""
    if layout.kind == "joints" and declared in UNITS:
        shown = ", ".join(short_token(name, 16)[1:-1] for name in names[:3])
        raise ValueError(
            f"{path} declares '# units: {declared}', a length, but its columns read as joints "
            f"({shown}{', …' if len(names) > 3 else ''}: radians): declare '# units: rad' or "
            f"none; positions are named x,y,z (or --columns)"
        )
    return declared or layout.units


def _repeated_stamps(times: np.ndarray) -> tuple:
    """(data row 1-based, stamp s) of each sample whose stamp repeats the one before."""
    rows = np.flatnonzero(np.diff(times) == 0) + 1
    return tuple((int(row) + 1, float(times[row])) for row in rows)


def _headerless(values: np.ndarray, path) -> np.ndarray:
    # x,y[,z] or t,x,y,z (add a header "t,x,y" to mark a time column)
    if values.shape[1] in (
        2,
        3,
        4,
    ):
        return values
    raise ValueError(
        f"{path}: expected 2-4 columns (x,y[,z] or t,x,y,z) without a header, found {values.shape[1]}"
    )


def _values(values: np.ndarray, layout: Layout, path="the recording") -> np.ndarray:
    """The value columns of ``values`` in the layout's order; a pose's rotation as a quaternion."""
    data = values[:, list(layout.values)]
    if layout.kind != "pose":
        return data
    turns = _quaternions(data[:, 3:], layout.rotation, path, layout.euler, layout.angles)
    return np.hstack([data[:, :3], turns])


def _quaternions(
    rotation: np.ndarray, kind: str, path="the recording", euler: str = "", angles: str = ""
) -> np.ndarray:
    """Rotation columns as quaternions ``qx, qy, qz, qw``: as they are, from a rotation vector
    (UR's axis-angle, radians), or from Euler angles in the declared sequence and unit.

    A rotation vector's angle lies in [0, π] (a longer one is the same rotation the other way
    round, which loggers do not write): one longer is no axis-angle in radians (an angle in
    degrees, or roll/pitch/yaw put in its place) and is refused, saying so — read as radians it
    would turn the tool by a wrong angle about a wrong axis, silently. Euler angles declared in
    radians beyond ±2π are degrees: refused too."""
    from scipy.spatial.transform import Rotation

    if kind not in ("rotvec", "euler") or not np.all(np.isfinite(rotation)):
        return rotation  # (a bad value: as_trajectory names it)
    if kind == "euler":
        largest = float(np.max(np.abs(rotation))) if rotation.size else 0.0
        if angles == "rad" and largest > 2.0 * np.pi + 1e-9:
            raise ValueError(
                f"{path}: the Euler angles are declared in radians but reach {largest:.4g}: "
                f"degrees? Declare angles=deg"
            )
        return Rotation.from_euler(euler, rotation, degrees=angles == "deg").as_quat()
    lengths = np.linalg.norm(rotation, axis=1)
    over = np.flatnonzero(lengths > np.pi + _ROTVEC_SLACK)
    if over.size:
        row = int(over[0])  # the first, where a user looking at the file finds it
        raise ValueError(
            f"{path}: the rotation-vector columns (rx, ry, rz: an axis times an angle in radians, "
            f"at most π) reach length {lengths[row]:.4g} at data row {row + 1}: degrees, or "
            f"roll/pitch/yaw? Declare Euler angles with their sequence and unit (--columns "
            f"x=..,y=..,z=..,e1=..,e2=..,e3=..,euler=xyz,angles=deg), or write the rotation as a "
            f"rotation vector in radians or a quaternion (qx, qy, qz, qw)"
        )
    return Rotation.from_rotvec(rotation).as_quat()


# A logger rounding a half turn may write an angle a little over π (UR's controller: 1e-4); a
# wrong convention (roll/pitch/yaw, degrees) is off by far more.
_ROTVEC_SLACK = 1e-3
# Between two samples a hand-guided tool turns far less than this (rad/s; a wrist spins at
# about 3): an orientation that does is read in a wrong convention.
_MAX_TURN_RATE = 20.0
_MAX_TURN_UNTIMED = np.pi / 2  # per row, in a file without times


def _check_orientation_jumps(path, quaternions: np.ndarray, times) -> None:
    """Refuse orientations that jump between neighbouring samples faster than a tool turns
    (:data:`_MAX_TURN_RATE`; without times, more than a quarter turn a row): Euler angles read in
    another sequence, or a rotation vector that is something else, wrap into such jumps."""
    q = np.asarray(quaternions, dtype=float)
    norms = np.linalg.norm(q, axis=1) if q.ndim == 2 else np.zeros(0)
    if q.shape[0] < 2 or not np.all(np.isfinite(norms)) or np.any(norms < 1e-9):
        return  # (a zero or broken quaternion: the pose checks refuse it, naming the row)
    q = q / norms[:, None]
    steps = 2.0 * np.arccos(np.clip(np.abs(np.sum(q[1:] * q[:-1], axis=1)), 0.0, 1.0))
    if times is None:
        bad = np.flatnonzero(steps > _MAX_TURN_UNTIMED)
    else:
        dt = np.diff(np.asarray(times, dtype=float))
        bad = np.flatnonzero((steps > np.radians(5.0)) & (steps > _MAX_TURN_RATE * dt))
    if bad.size:
        row = int(bad[0])
        raise ValueError(
            f"{path}: the orientation jumps {np.degrees(steps[row]):.1f} deg between data rows "
            f"{row + 1} and {row + 2}"
            + ("" if times is None else f" ({1e3 * float(dt[row]):.3g} ms apart)")
            + ": no tool turns that fast, so the rotation columns are read in a wrong convention "
            "(Euler angles in another sequence or unit, angles read as a rotation vector); "
            "declare theirs (--columns ...,euler=<sequence>,angles=deg|rad)"
        )


def _without_gaps(path, values: np.ndarray, text: dict, used, header):
    """``gaps=drop``: the rows with a gap (NaN) or inf in a used column dropped, with a warning."""
    keep = np.all(np.isfinite(values[:, list(used)]), axis=1)
    dropped = int((~keep).sum())
    if dropped:
        logger.warning(
            "%s: dropped %d row%s with gaps (gaps=drop), first at data row %d",
            path,
            dropped,
            "s" if dropped != 1 else "",
            int(np.argmin(keep)) + 1,
        )
    return values[keep], {
        column: tuple(np.asarray(cells, dtype=object)[keep]) for column, cells in text.items()
    }


def _check_time_unit(path, times, layout, header) -> None:
    """A time column assumed to hold seconds whose rate says it holds milliseconds (or µs, ns):
    refused with the declaration that reads it (its rate in each unit shown)."""
    if times is None or layout.time_declared or len(times) < 2 or not np.all(np.isfinite(times)):
        return
    span = float(times[-1] - times[0])
    if span <= 0.0:
        return
    from ..primitives.timing import MAX_RATE_HZ, MIN_RATE_HZ

    rate = (len(times) - 1) / span
    if rate >= MIN_RATE_HZ:
        return
    # the first unit in which the stamps give a robot's rate (ms when none does)
    unit = next(
        (u for u in ("ms", "us", "ns") if MIN_RATE_HZ <= rate * _TIME_DIVISORS[u] <= MAX_RATE_HZ),
        "ms",
    )
    name = header[layout.time[0]]
    raise ValueError(
        f"{path}: the time column {short_token(name, 30)} read as seconds gives {rate:.3g} Hz; "
        f"if it holds {unit}, declare it: --columns time={unit} "
        f"(or name the column {split_unit(name)[0]}({unit}))"
    )


def _joint_names(path, layout, text: dict, header) -> list:
    """A JointState export's joint names, from its name columns: the same in every row."""
    names = []
    for column in layout.names_from:
        cells = text.get(column)
        if not cells:
            raise ValueError(
                f"{path}: column {short_token(header[column], 30)} should hold a joint's name (text)"
            )
        if any(cell != cells[0] for cell in cells):
            row = next(index for index, cell in enumerate(cells) if cell != cells[0])
            raise ValueError(
                f"{path}: the joint names change at data row {row + 1} (column "
                f"{short_token(header[column], 30)}: {short_token(cells[0], 20)} then "
                f"{short_token(cells[row], 20)}): the positions' order changes; split the file where it does"
            )
        names.append(cells[0])
    if len(set(names)) != len(names):
        raise ValueError(f"{path}: a joint name repeats among {', '.join(names)}")
    return names
