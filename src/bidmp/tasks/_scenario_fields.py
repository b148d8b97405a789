"""Readers of a scenario file's values (:mod:`bidmp.tasks.scenarios`): numbers, points, lists of
points, pose rows, files inside the scenario's folder and the demonstration. Each refuses a bad
value with a :class:`~bidmp.tasks.scenarios.ScenarioError` naming the file and the key, and
quotes a rejected value short."""

from __future__ import annotations

import json
import math
import os
from numbers import Integral, Real
from pathlib import Path

import numpy as np

from .._checks import get_limits, short_token
from ..demonstrations.datasets import minimum_jerk

_MINIMUM_JERK_KEYS = {"via", "n_steps", "noise", "seed"}


class ScenarioError(ValueError):
    """A scenario file is malformed; the message names the key."""


# ---------------------------------------------------------------------------------------------
# Validation
# ---------------------------------------------------------------------------------------------
_MIN_DEMONSTRATION = 10  # samples: what segmentation (and so the extension) needs


def _fail(source: str, key: str, message: str):
    # The key is the file's (a user's key may be any length) and the message may list choices:
    # each is shown short, so that the one line stays within 300 characters.
    key = key if len(key) <= 60 else key[:59] + "…"
    text = f"scenario {source}: {key}: {message}"
    raise ScenarioError(text if len(text) <= 300 else text[:299] + "…")


def _shown(value) -> str:
    """A rejected JSON value, quoted short (never a whole file's worth)."""
    try:
        text = json.dumps(value)
    except (TypeError, ValueError, RecursionError):  # (data nested thousands deep)
        text = type(value).__name__
    return text if len(text) <= 24 else short_token(text, 20)


def _number(value, source, key, positive=False):
    if isinstance(value, bool) or not isinstance(value, Real):
        _fail(source, key, f"expected a number, got {_shown(value)}")
    try:  # an integer of hundreds of digits is a Real that no float holds
        finite = math.isfinite(float(value))
    except OverflowError:
        finite = False
    if not finite:
        _fail(source, key, f"expected a finite number, got {_shown(value)}")
    if positive and value <= 0:
        _fail(source, key, f"must be > 0, got {value}")
    if abs(value) > get_limits().max_abs_value:
        _fail(
            source,
            key,
            f"{value:.3g} is beyond the limit max_abs_value = {get_limits().max_abs_value:g}",
        )
    return float(value)


def _point(value, source, key, n_dims=None):
    if (
        not isinstance(value, list)
        or not value
        or not all(isinstance(v, Real) and not isinstance(v, bool) for v in value)
    ):
        _fail(source, key, f"expected a point [x, y(, z)] of numbers, got {_shown(value)}")
    if len(value) > get_limits().max_dims:
        _fail(
            source,
            key,
            f"has {len(value)} coordinates, more than the limit max_dims = {get_limits().max_dims}",
        )
    point = np.asarray(value, dtype=float)
    if not np.all(np.isfinite(point)):
        _fail(source, key, "contains a non-finite number")
    if np.max(np.abs(point)) > get_limits().max_abs_value:
        _fail(
            source,
            key,
            f"has a coordinate beyond the limit max_abs_value = {get_limits().max_abs_value:g} "
            f"(raise it with bidmp.set_limits(max_abs_value=...))",
        )
    if n_dims is not None and point.shape[0] != n_dims:
        _fail(source, key, f"has {point.shape[0]} coordinates, expected {n_dims}")
    return point


def _points(value, source, key, n_dims=None, minimum=2):
    if not isinstance(value, list) or len(value) < minimum:
        _fail(source, key, f"expected a list of at least {minimum} points")
    if len(value) > get_limits().max_samples:
        _fail(
            source,
            key,
            f"{len(value):,} points exceed the limit max_samples = {get_limits().max_samples:,}",
        )
    points = [_point(p, source, f"{key}[{i}]", n_dims) for i, p in enumerate(value)]
    if len({p.shape[0] for p in points}) != 1:
        _fail(source, key, "points have different numbers of coordinates")
    return np.stack(points)


def _inside(path: Path, base_dir, source: str, key: str, body: str, allow_outside: bool) -> Path:
    """Resolve a file named in a scenario; unless allowed, it must lie inside the scenario's
    folder once ``..`` and symlinks are resolved."""
    if allow_outside:
        return path
    base = Path(os.path.realpath(base_dir))
    resolved = Path(os.path.realpath(path))
    if os.path.isabs(body) or os.path.commonpath([base, resolved]) != str(base):
        _fail(
            source,
            key,
            f"{short_token(body, 40)} lies outside the scenario's folder {base}; files are read from "
            f"there only (allow_outside_files=True, or 'bidmp ... --allow-outside-files', lifts this)",
        )
    return resolved


def _prepared_file(path, units: str, reading: dict) -> tuple[np.ndarray, float | None]:
    """A demonstration file as ``bidmp fit`` reads it: by the same reader
    (:func:`bidmp.io.read_recording`, with ``reading["columns"]``: the roles and conventions of
    ``--columns``), its unit the one it declares (``# units: mm``, ``X(mm)``) or
    ``reading["units"]`` (``--units``), converted to the scenario's; a timed recording prepared
    (idle ends trimmed, filtered, uniform time) and refused if no robot moves so (its peak speed
    in the scenario's unit). Returns the positions (or poses) and the pace the person showed: the
    prepared motion's peak tool speed (scene units per second; None without time stamps)."""
    from .._units import check_speed, conversion
    from ..demonstrations.preparation import prepare, prepare_poses
    from ..io.recordings import read_recording

    recording = read_recording(path, columns=reading.get("columns"))
    if recording.kind == "joints":
        raise ValueError(
            f"{path}: its columns read as joints ({recording.source}); a scenario's demonstration "
            f"is the tool's path: positions or poses (name them with columns: x=..,y=..,z=..)"
        )
    given, declared = reading.get("units", ""), recording.units
    if given and declared and given != declared:
        raise ValueError(
            f"{path} is in {declared} (declared in the file) but units says {given}: drop one"
        )
    values, unit = recording.values, given or declared
    if unit and units and unit != units:
        # a length converted as bidmp fit --units converts it; a quaternion has none
        values = values.copy()
        values[:, :3] *= conversion(unit, units)
    if recording.t is None:
        return values, None
    if recording.kind == "pose":
        values, times, _ = prepare_poses(values, recording.t)
    else:
        motion = prepare(values, recording.t)[0]
        values, times = motion.y, motion.t
    pace = _peak_speed(values[:, :3], times)
    check_speed(pace, units, f"{path}: the demonstration")
    return values, pace


def _peak_speed(positions: np.ndarray, t: np.ndarray) -> float:
    """The largest tool speed of a uniformly timed motion (units per second)."""
    return float(np.max(np.linalg.norm(np.gradient(positions, t, axis=0), axis=1)))


def _demonstration(value, source, key, base_dir, allow_outside=False, units: str = ""):  # noqa: C901 - one branch per documented option or part kind, each a line
    """A scenario's demonstration and its pace (peak tool speed in scene units per second, None
    when it has no time: a generated or listed one). A ``"file"`` takes the reading options of
    ``bidmp fit`` beside it (:data:`_FILE_KEYS`)."""
    kinds = (
        [kind for kind in value if kind in _DEMONSTRATION_KINDS] if isinstance(value, dict) else []
    )
    if len(kinds) != 1:
        _fail(
            source,
            key,
            'expected exactly one of {"minimum_jerk": {...}}, {"points": [...]} or {"file": "..."}',
        )
    kind, body = kinds[0], value[kinds[0]]
    if kind == "file":
        reading = _file_reading(value, source, key)
    elif len(value) != 1:
        other = sorted(set(value) - {kind})[0]
        _fail(
            source,
            f"{key}.{short_token(other, 30)[1:-1]}",
            f'unknown key (only a "file" demonstration takes {", ".join(sorted(_FILE_KEYS))})',
        )
    if kind == "minimum_jerk":
        if not isinstance(body, dict):
            _fail(source, f"{key}.minimum_jerk", "expected an object")
        unknown = sorted(set(body) - _MINIMUM_JERK_KEYS)
        if unknown:
            _fail(
                source,
                f"{key}.minimum_jerk.{unknown[0]}",
                f"unknown key (known: {', '.join(sorted(_MINIMUM_JERK_KEYS))})",
            )
        if "via" not in body:
            _fail(source, f"{key}.minimum_jerk.via", "missing")
        via = _points(body["via"], source, f"{key}.minimum_jerk.via")
        n_steps = body.get("n_steps", 200)
        if (
            isinstance(n_steps, bool)
            or not isinstance(n_steps, Integral)
            or n_steps < _MIN_DEMONSTRATION
        ):
            _fail(
                source,
                f"{key}.minimum_jerk.n_steps",
                f"expected an integer >= {_MIN_DEMONSTRATION}, got {_shown(n_steps)}",
            )
        if n_steps > get_limits().max_samples:
            _fail(
                source,
                f"{key}.minimum_jerk.n_steps",
                f"{n_steps:,} exceeds the limit max_samples = {get_limits().max_samples:,}",
            )
        noise = _number(body.get("noise", 0.0), source, f"{key}.minimum_jerk.noise")
        if noise < 0:
            _fail(source, f"{key}.minimum_jerk.noise", "must be >= 0")
        seed = body.get("seed", 0)
        if isinstance(seed, bool) or not isinstance(seed, Integral) or not 0 <= seed < 2**63:
            _fail(
                source,
                f"{key}.minimum_jerk.seed",
                f"expected an integer in [0, 2**63), got {_shown(seed)}",
            )
        try:
            return minimum_jerk(via, int(n_steps), noise, int(seed)), None
        except (TypeError, ValueError) as exc:
            _fail(source, f"{key}.minimum_jerk", str(exc))
    if kind == "points":
        points = _points(body, source, f"{key}.points", minimum=_MIN_DEMONSTRATION)
        if not np.any(points != points[0]):
            _fail(source, f"{key}.points", "all points are identical: there is no motion to learn")
        return points, None
    if kind == "file":
        if not isinstance(body, str) or not body or "\x00" in body:
            _fail(source, f"{key}.file", "expected a file name")
        path = _inside(
            Path(body) if os.path.isabs(body) else Path(base_dir) / body,
            base_dir,
            source,
            f"{key}.file",
            body,
            allow_outside,
        )
        try:
            trajectory, pace = _prepared_file(path, units, reading)
        except (TypeError, ValueError, OSError) as exc:
            _fail(source, f"{key}.file", str(exc))
        if trajectory.shape[0] < _MIN_DEMONSTRATION:
            _fail(
                source,
                f"{key}.file",
                f"has {trajectory.shape[0]} samples; a demonstration needs at least {_MIN_DEMONSTRATION}",
            )
        return trajectory, pace
    _fail(
        source,
        key,
        f"unknown demonstration kind {short_token(kind, 20)} (expected minimum_jerk, points or file)",
    )


_DEMONSTRATION_KINDS = ("minimum_jerk", "points", "file")
# a "file" demonstration's reading options, those of bidmp fit: --columns (the roles and
# conventions: time=ms, decimal=comma, euler=xyz, angles=deg, gaps=drop) and --units
_FILE_KEYS = {"columns", "units"}


def _file_reading(value: dict, source: str, key: str) -> dict:
    """The reading options beside ``"file"``, checked as ``bidmp fit`` checks its options (the
    column mapping parsed now, so a bad role names its key before the file is opened)."""
    from .._units import UNITS
    from ..io._columns import parse_columns

    unknown = sorted(set(value) - {"file", *_FILE_KEYS})
    if unknown:
        _fail(
            source,
            f"{key}.{short_token(unknown[0], 30)[1:-1]}",
            f"unknown key (a file's options: {', '.join(sorted(_FILE_KEYS))})",
        )
    reading = {}
    if "columns" in value:
        columns = value["columns"]
        if not isinstance(columns, (str, dict)) or not columns:
            _fail(
                source,
                f"{key}.columns",
                'expected a column mapping, "t=Time,x=X,..." or {"t": "Time", "x": "X", ...}, '
                f"got {_shown(columns)}",
            )
        try:
            parse_columns(columns)
        except (TypeError, ValueError) as exc:
            _fail(source, f"{key}.columns", str(exc))
        reading["columns"] = columns
    if "units" in value:
        if value["units"] not in UNITS:
            _fail(
                source,
                f"{key}.units",
                f"expected the file's length unit, one of {', '.join(UNITS)}, got {_shown(value['units'])}",
            )
        reading["units"] = value["units"]
    return reading


def _pose_points(points: np.ndarray, source: str, key: str, generated: bool) -> np.ndarray:
    """Pose rows (x, y, z, qx, qy, qz, qw): quaternions must be unit (a generator's are
    normalised: it interpolates them component by component)."""
    quaternions = points[:, 3:]
    norms = np.linalg.norm(quaternions, axis=1)
    if np.any(norms < 1e-9):
        _fail(source, key, "a quaternion is zero, which is no rotation")
    if generated:
        points = points.copy()
        points[:, 3:] = quaternions / norms[:, None]
    elif np.any(np.abs(norms - 1.0) > 1e-6):
        _fail(
            source,
            key,
            f"quaternions must be of unit length (one is {norms[np.argmax(np.abs(norms - 1))]:.6g})",
        )
    return points


_ROBOT_MODELS = ("panda", "fr3", "iiwa", "xarm6", "ur5")
MIN_JOINTS = 6  # the arms the simulator drives: serial, six joints or more
_LIMIT_KEYS = ("lower", "upper", "velocity", "acceleration", "jerk")


def _joint_values(
    value, source: str, key: str, positive: bool = False, count: int | None = None
) -> list:
    """One number per joint (rad, rad/s, ... or N m): ``count`` of them, else six or more."""
    if not isinstance(value, list) or (
        len(value) != count if count is not None else len(value) < MIN_JOINTS
    ):
        wanted = f"{count}" if count is not None else f"{MIN_JOINTS} or more"
        _fail(
            source, key, f"expected {wanted} numbers, one per joint of the arm, got {_shown(value)}"
        )
    return [_number(v, source, f"{key}[{i}]", positive=positive) for i, v in enumerate(value)]


def _robot(data, source: str, base_dir=".", allow_outside: bool = False) -> dict:
    """The ``"robot"`` key, validated: where ``bidmp sim`` puts the arm (``base``, ``yaw``) and
    which arm: ``"model"`` (panda, the default, iiwa, xarm6 or ur5) or its own ``"urdf"`` (a file in
    the scenario's folder, or a model shipped by pybullet_data) with ``"flange"`` (the link the tool
    is mounted on) and ``"limits"`` (one value per joint, six joints or more: lower, upper in rad;
    velocity, acceleration, jerk in rad/s, rad/s², rad/s³; jerk optional), ``"rest"`` and
    ``"effort"`` optional (one per joint)."""
    robot = data.get("robot", {})
    allowed = {"base", "yaw", "model", "urdf", "flange", "limits", "rest", "effort"}
    if not isinstance(robot, dict) or set(robot) - allowed:
        unknown = sorted(set(robot) - allowed) if isinstance(robot, dict) else []
        _fail(
            source,
            "robot",
            f"expected keys among {sorted(allowed)}" + (f"; unknown {unknown}" if unknown else ""),
        )
    robot = dict(robot)
    if "base" in robot:
        robot["base"] = _point(robot["base"], source, "robot.base", 3).tolist()
    if "yaw" in robot:
        robot["yaw"] = _number(robot["yaw"], source, "robot.yaw")
    if "model" in robot and (
        not isinstance(robot["model"], str) or robot["model"] not in _ROBOT_MODELS
    ):
        _fail(
            source,
            "robot.model",
            f"expected one of {list(_ROBOT_MODELS)}, got {_shown(robot['model'])}",
        )
    if "urdf" not in robot:
        if set(robot) & {"flange", "limits", "rest", "effort"}:
            _fail(
                source,
                "robot",
                '"flange", "limits", "rest" and "effort" describe your own "urdf"; name it',
            )
        return robot
    if "model" in robot:
        _fail(source, "robot", 'give "model" (a built-in arm) or "urdf" (your own), not both')
    if not isinstance(robot["urdf"], str) or not robot["urdf"].endswith(".urdf"):
        _fail(
            source, "robot.urdf", f"expected the path of a .urdf file, got {_shown(robot['urdf'])}"
        )
    local = Path(base_dir) / robot["urdf"]
    if local.exists() or os.path.isabs(robot["urdf"]):  # else: a model shipped by pybullet_data
        robot["urdf"] = str(
            _inside(local, base_dir, source, "robot.urdf", robot["urdf"], allow_outside)
        )
    if not isinstance(robot.get("flange"), str) or not robot["flange"]:
        _fail(source, "robot.flange", "expected the name of the URDF link the tool is mounted on")
    limits = robot.get("limits")
    if (
        not isinstance(limits, dict)
        or set(limits) - set(_LIMIT_KEYS)
        or not set(_LIMIT_KEYS[:4]) <= set(limits)
    ):
        _fail(
            source,
            "robot.limits",
            f"expected {{{', '.join(_LIMIT_KEYS)}}} (jerk optional), one value per joint each",
        )
    count = len(limits["lower"]) if isinstance(limits["lower"], list) else None
    robot["limits"] = {
        name: _joint_values(
            values,
            source,
            f"robot.limits.{name}",
            positive=name not in ("lower", "upper"),
            count=count if name != "lower" else None,
        )
        for name, values in limits.items()
    }
    count = len(robot["limits"]["lower"])
    if any(low >= high for low, high in zip(robot["limits"]["lower"], robot["limits"]["upper"])):
        _fail(source, "robot.limits", "lower must be below upper for every joint")
    for name in ("rest", "effort"):
        if name in robot:
            robot[name] = _joint_values(
                robot[name], source, f"robot.{name}", positive=name == "effort", count=count
            )
    _check_rest_within(robot, source)
    return robot


def _check_rest_within(robot: dict, source: str) -> None:
    """A given start pose (``robot.rest``) lies within the arm's ``robot.limits``."""
    lower, upper = robot["limits"]["lower"], robot["limits"]["upper"]
    for joint, (q, low, high) in enumerate(zip(robot.get("rest", ()), lower, upper), start=1):
        if not low <= q <= high:
            _fail(
                source,
                "robot.rest",
                f"joint {joint} at {q:g} rad is outside its limits [{low:g}, {high:g}] "
                "(robot.limits); the start pose must lie within them",
            )
