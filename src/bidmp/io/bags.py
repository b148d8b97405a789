"""ROS 1 and ROS 2 bags without ROS, through the pure-Python ``rosbags`` package (the ``ros`` extra:
``pip install 'bidmp[ros]'``).

Reading (:func:`read_bag`): a demonstration from

* ``geometry_msgs/PoseStamped`` or ``geometry_msgs/TransformStamped`` on a topic → poses
  ``x, y, z, qx, qy, qz, qw`` (m); ``geometry_msgs/PointStamped`` → positions ``x, y, z`` (m);
* ``tf2_msgs/TFMessage`` (``/tf``, ``/tf_static``) → the transform from a parent frame to a child
  frame chosen by name (the direct edge of the tree, as published) → poses (m);
* ``sensor_msgs/JointState`` → the positions of the joints chosen by name, or all (rad).

Times are the messages' header stamps (not when the recorder received them), seconds from the
first; the messages are put in the order of their stamps, as transport jitter leaves them a few
milliseconds out of receive order. Two messages with one stamp, or a stamp more than
:data:`MAX_STAMP_DISORDER` s before one already received (a clock reset, a replayed log), are
refused. A ROS 1 ``.bag`` file or a ROS 2 bag folder (SQLite or MCAP, with its
``metadata.yaml``). A bag without the topic, with a message type bidmp does not read, or with
such stamps gives a one-line error that lists what the bag contains.

Writing (:func:`write_bag`): a motion as a ``geometry_msgs/PoseStamped`` stream (one message per
sample, stamped ``origin + t``; positions alone with an orientation held throughout, or a
``geometry_msgs/PointStamped`` stream: no orientation is ever made up), as one
``trajectory_msgs/JointTrajectory`` (positions, velocities, accelerations,
``time_from_start``), or as one ``control_msgs/FollowJointTrajectory`` goal, the action a ROS 2
joint trajectory controller takes (its type registered from the message definition); ROS 2 MCAP by
default, ROS 1 on request; stamped from a given start (``"now"`` or seconds since the epoch);
written beside the target and renamed into place (a bag folder or file appears whole or not at
all).
"""

from __future__ import annotations

import logging
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from .._checks import (
    as_trajectory,
    as_vector,
    check_choice,
    check_path,
    check_real,
    require_extra,
    short_token,
    shown_path,
)
from .recordings import Recording

logger = logging.getLogger(__name__)

__all__ = ["read_bag", "write_bag", "is_bag", "start_stamp"]

POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
TRANSFORM_STAMPED = "geometry_msgs/msg/TransformStamped"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
JOINT_STATE = "sensor_msgs/msg/JointState"
JOINT_TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
POINT_STAMPED = "geometry_msgs/msg/PointStamped"
FOLLOW_JOINT_TRAJECTORY = {
    2: "control_msgs/action/FollowJointTrajectory_Goal",
    1: "control_msgs/msg/FollowJointTrajectoryGoal",
}
# s: transport jitter reorders messages by milliseconds; more is a jump back in time
MAX_STAMP_DISORDER = 0.1
# The goal of control_msgs' FollowJointTrajectory action (ROS 2 Humble's control_msgs 4, ROS 1's
# Noetic control_msgs 1.5), with the two tolerance messages it uses: rosbags' typestores do not
# ship control_msgs, so the types are registered from these definitions.
_FOLLOW_DEFINITIONS = {
    2: {
        "control_msgs/msg/JointTolerance": "string name\nfloat64 position\nfloat64 velocity\nfloat64 acceleration\n",
        "control_msgs/msg/JointComponentTolerance": (
            "uint16 X_AXIS=1\nuint16 Y_AXIS=2\nuint16 Z_AXIS=3\nuint16 TRANSLATION=4\nuint16 ROTATION=5\n"
            "string joint_name\nuint16 component\nfloat64 position\nfloat64 velocity\nfloat64 acceleration\n"
        ),
        "control_msgs/action/FollowJointTrajectory_Goal": (
            "trajectory_msgs/JointTrajectory trajectory\n"
            "trajectory_msgs/MultiDOFJointTrajectory multi_dof_trajectory\n"
            "control_msgs/JointTolerance[] path_tolerance\n"
            "control_msgs/JointComponentTolerance[] component_path_tolerance\n"
            "control_msgs/JointTolerance[] goal_tolerance\n"
            "control_msgs/JointComponentTolerance[] component_goal_tolerance\n"
            "builtin_interfaces/Duration goal_time_tolerance\n"
        ),
    },
    1: {
        "control_msgs/msg/JointTolerance": "string name\nfloat64 position\nfloat64 velocity\nfloat64 acceleration\n",
        "control_msgs/msg/FollowJointTrajectoryGoal": (
            "trajectory_msgs/JointTrajectory trajectory\n"
            "control_msgs/JointTolerance[] path_tolerance\n"
            "control_msgs/JointTolerance[] goal_tolerance\n"
            "duration goal_time_tolerance\n"
        ),
    },
}
_READABLE = (
    POSE_STAMPED,
    TRANSFORM_STAMPED,
    "geometry_msgs/msg/PointStamped",
    TF_MESSAGE,
    JOINT_STATE,
)
POSE_COLUMNS = ["x", "y", "z", "qx", "qy", "qz", "qw"]


def _rosbags():
    return require_extra("rosbags", "ros", "ROS bags")


def is_bag(path) -> bool:
    """Whether ``path`` is a ROS bag: a ``.bag`` file or a folder with ``metadata.yaml``."""
    path = Path(check_path(path, "path"))  # a name beyond the system's lengths is refused by name
    if path.is_dir():
        return (path / "metadata.yaml").is_file()
    return path.suffix.lower() == ".bag" and path.is_file()


def _contents(reader) -> str:
    """What a bag holds, for a message: ``/topic (type, n messages)``."""
    counts: dict = {}
    for connection in reader.connections:
        key = (connection.topic, connection.msgtype)
        counts[key] = counts.get(key, 0) + connection.msgcount
    listed = ", ".join(
        f"{topic} ({kind}, {count} messages)" for (topic, kind), count in sorted(counts.items())
    )
    return listed or "no topics"


def _stamp(header) -> int:
    """The header stamp in integer nanoseconds (a float of seconds since the epoch keeps 0.2 µs)."""
    return int(header.stamp.sec) * 1_000_000_000 + int(header.stamp.nanosec)


def _open(path):
    """An AnyReader on the bag at ``path``."""
    highlevel = require_extra("rosbags.highlevel", "ros", "ROS bags")
    path = Path(check_path(path))
    if not path.exists():
        raise ValueError(f"bag {shown_path(path)} does not exist")
    if not is_bag(path):
        raise ValueError(
            f"{shown_path(path)} is not a ROS bag (a ROS 1 .bag file or a ROS 2 bag folder with metadata.yaml)"
        )
    reader = highlevel.AnyReader([path])
    try:
        reader.open()
    except RecursionError:  # rosbags parses message definitions recursively
        raise ValueError(
            f"cannot read bag {shown_path(path)}: its message definitions nest types too deeply"
        ) from None
    except (
        Exception
    ) as exc:  # rosbags' own errors (AnyReaderError, a broken metadata.yaml, ...): one line
        raise ValueError(
            f"cannot read bag {shown_path(path)}: {type(exc).__name__}: {exc}"
        ) from None
    return reader


def read_bag(
    path, *, topic: str | None = None, tf: tuple[str, str] | None = None, joints=None
) -> Recording:
    """A demonstration from a bag (module docstring).

    Parameters
    ----------
    path : str or Path
        A ROS 1 ``.bag`` file or a ROS 2 bag folder.
    topic : str, optional
        A ``PoseStamped``, ``TransformStamped``, ``PointStamped`` or ``JointState`` topic (default:
        the bag's only one of these types; with ``tf``, ``/tf`` and ``/tf_static``).
    tf : (parent, child), optional
        Read the transform from frame ``parent`` to frame ``child`` from ``TFMessage`` topics.
    joints : list of str or True, optional
        Joint states: these joints, in this order (True: every joint of the first message).

    Returns
    -------
    Recording
    """
    _check_selection(topic, tf, joints)
    reader = _open(path)
    try:
        wanted = _wanted_connections(reader, topic, tf, joints)
        kind = {JOINT_STATE: "joints", POINT_STAMPED: "positions"}.get(wanted[0].msgtype, "pose")
        stamps, rows, numbers, names = [], [], [], None
        for number, (connection, _, raw) in enumerate(reader.messages(connections=wanted), 1):
            message = reader.deserialize(raw, connection.msgtype)
            where = f"bag {shown_path(path)}: message {number} on {connection.topic}"
            for stamp, row, found in _rows(message, connection.msgtype, tf, joints, names, where):
                names = found if names is None else names
                stamps.append(stamp)
                rows.append(row)
                numbers.append(number)
        source = f"tf {tf[0]} -> {tf[1]}" if tf is not None else f"topic {wanted[0].topic}"
        if not rows:
            raise ValueError(
                f"bag {shown_path(path)}: no {source} message in it; it has: {_contents(reader)}"
            )
        order = _stamp_order(
            stamps, f"bag {shown_path(path)}: the header stamps of {source}", _contents(reader)
        )
    finally:
        reader.close()
    values = np.array(rows, dtype=float)
    _check_finite(values, (stamps, numbers), names, f"bag {shown_path(path)}: {source}")
    stamps = [stamps[index] for index in order]
    values = values[order]
    # exact to the nanosecond
    t = np.array([stamp - stamps[0] for stamp in stamps], dtype=float) * 1e-9
    return Recording(
        t, values, list(names), kind, "rad" if kind == "joints" else "m", source, stamps[0] * 1e-9
    )


def _stamp_order(stamps: list, what: str, contents: str) -> np.ndarray:
    """The messages' order by their header stamps (stable), refusing a stamp repeated or one more
    than :data:`MAX_STAMP_DISORDER` before the latest already received."""
    received = np.asarray(stamps, dtype=np.int64)
    latest = np.maximum.accumulate(received)
    behind = latest - received
    if np.any(behind > MAX_STAMP_DISORDER * 1e9):
        index = int(np.argmax(behind > MAX_STAMP_DISORDER * 1e9))
        raise ValueError(
            f"{what} jump back in time (message {index + 1} at {received[index] * 1e-9:.9f} s, "
            f"{behind[index] * 1e-9:.6g} s before one received earlier; more than the "
            f"{MAX_STAMP_DISORDER:g} s transport jitter reorders); it has: {contents}"
        )
    order = np.argsort(received, kind="stable")
    ordered = received[order]
    if np.any(np.diff(ordered) == 0):
        index = int(np.argmax(np.diff(ordered) == 0))
        raise ValueError(
            f"{what} repeat: two messages stamped {ordered[index] * 1e-9:.9f} s (messages "
            f"{order[index] + 1} and {order[index + 1] + 1}); it has: {contents}"
        )
    moved = int(np.sum(order != np.arange(order.size)))
    if moved:
        logger.info(
            "%s: %d message(s) out of receive order, put in the order of their stamps "
            "(at most %.3g ms apart)",
            what,
            moved,
            float(behind.max()) * 1e-6,
        )
    return order


def _check_selection(topic, tf, joints) -> None:
    """Refuse a topic, frame pair or joint list that could name nothing, before the bag is opened."""
    if topic is not None and (not isinstance(topic, str) or not topic.strip() or len(topic) > 256):
        raise ValueError(
            f"topic must be a topic name such as '/bidmp/pose', got {short_token(topic, 30)}"
        )
    if tf is not None and (
        not isinstance(tf, (tuple, list))
        or len(tf) != 2
        or not all(isinstance(frame, str) and frame and len(frame) <= 256 for frame in tf)
    ):
        raise ValueError(
            f"tf must be (parent frame, child frame), two names, got {short_token(tf, 30)}"
        )
    if (
        joints is not None
        and joints is not True
        and (
            not isinstance(joints, (list, tuple))
            or not joints
            or not all(isinstance(name, str) and name and len(name) <= 256 for name in joints)
        )
    ):
        raise ValueError(
            f"joints must be a list of joint names or True (every joint), got {short_token(joints, 30)}"
        )
    if isinstance(joints, (list, tuple)) and len(set(joints)) != len(joints):
        repeated = next(name for name in joints if list(joints).count(name) > 1)
        raise ValueError(f"joints: joint {short_token(repeated, 30)} is named twice")
    if tf is not None and joints is not None:
        raise ValueError("tf and joints: give one (a transform or joint states), not both")


def _wanted_connections(reader, topic, tf, joints) -> list:
    """The connections to read, refused in one line that lists the bag's contents."""
    if tf is not None:
        topics = {topic} if topic is not None else {"/tf", "/tf_static"}
        found = [c for c in reader.connections if c.topic in topics and c.msgtype == TF_MESSAGE]
        if not found:
            raise ValueError(
                f"tf: the bag has no TFMessage topic {' or '.join(sorted(topics))}; it has: {_contents(reader)}"
            )
        return found
    if topic is None:
        types = (
            (JOINT_STATE,)
            if joints is not None
            else (POSE_STAMPED, TRANSFORM_STAMPED, POINT_STAMPED)
        )
        found = [c for c in reader.connections if c.msgtype in types]
        if len({c.topic for c in found}) != 1:
            wanted = "joints" if joints is not None else "topic"
            raise ValueError(
                f"{wanted}: name the topic to read: the bag has {len({c.topic for c in found})} topics of "
                f"type {' or '.join(types)}; it has: {_contents(reader)}"
            )
        return found
    found = [c for c in reader.connections if c.topic == topic]
    if not found:
        raise ValueError(
            f"topic {short_token(topic, 40)} is not in the bag; it has: {_contents(reader)}"
        )
    if found[0].msgtype not in (POSE_STAMPED, TRANSFORM_STAMPED, POINT_STAMPED, JOINT_STATE):
        raise ValueError(
            f"topic {topic} carries {found[0].msgtype}, which bidmp does not read (it reads "
            f"{', '.join(_READABLE)}; TFMessage with tf); it has: {_contents(reader)}"
        )
    if (found[0].msgtype == JOINT_STATE) != (joints is not None):
        raise ValueError(
            f"topic {topic} carries {found[0].msgtype}: "
            + (
                "give joints, the joints to read"
                if joints is None
                else "joints are read from a JointState topic"
            )
        )
    return found


def _rows(message, msgtype: str, tf, joints, names, where: str):
    """(stamp s, row, column names) of the samples one message holds (``where``: the message, for
    errors)."""
    if msgtype == POSE_STAMPED:
        p, q = message.pose.position, message.pose.orientation
        yield _stamp(message.header), [p.x, p.y, p.z, q.x, q.y, q.z, q.w], POSE_COLUMNS
    elif msgtype == POINT_STAMPED:
        p = message.point
        yield _stamp(message.header), [p.x, p.y, p.z], POSE_COLUMNS[:3]
    elif msgtype == TRANSFORM_STAMPED:
        yield _stamp(message.header), _transform_row(message), POSE_COLUMNS
    elif msgtype == TF_MESSAGE:
        for transform in message.transforms:
            if transform.header.frame_id.lstrip("/") == tf[0].lstrip(
                "/"
            ) and transform.child_frame_id.lstrip("/") == tf[1].lstrip("/"):
                yield _stamp(transform.header), _transform_row(transform), POSE_COLUMNS
    else:
        yield _joint_row(message, joints, names, where)


def _listed(names, limit: int = 8) -> str:
    """Joint names for a message: the first ``limit``, each short."""
    shown = ", ".join(short_token(name, 30)[1:-1] for name in names[:limit])
    return shown + (f", … ({len(names)} in all)" if len(names) > limit else "")


def _joint_row(message, joints, names, where: str) -> tuple:
    """(stamp, positions, names) of one ``JointState``: the positions picked by joint name, so a
    driver that lists its joints in another order from one message to the next (two publishers
    on one topic, a reordered driver) still gives each column its own joint. ``names``: the
    joints the first message chose (None for the first); a name listed twice, or positions that
    do not match the names one for one, are refused: which position is whose is unknown."""
    available = [str(name) for name in message.name]
    positions = np.asarray(message.position, dtype=float).reshape(-1)
    seen = set()
    for name in available:
        if name in seen:
            raise ValueError(
                f"{where}: the joint state names joint {short_token(name, 30)} twice "
                f"({_listed(available)}): which position is its is unknown"
            )
        seen.add(name)
    if positions.size != len(available):
        raise ValueError(
            f"{where}: the joint state has {positions.size} positions for {len(available)} "
            f"joint names ({_listed(available)}): a position per name is needed to tell whose is whose"
        )
    chosen = names or (available if joints is True else list(joints))
    missing = [name for name in chosen if name not in seen]
    if missing:
        raise ValueError(
            f"{where}: the joint state has no joint(s) {_listed(missing, 4)}; it names "
            f"{_listed(available)}"
        )
    column = {name: index for index, name in enumerate(available)}
    return _stamp(message.header), positions[[column[name] for name in chosen]].tolist(), chosen


def _check_finite(values: np.ndarray, messages: tuple, names, what: str) -> None:
    """Refuse a NaN or infinite value read from a bag, as a CSV's gap is refused: the message
    (its number in receive order and its stamp; ``messages`` = (stamps ns, numbers), one per row)
    and the column, and how many rows have one."""
    stamps, numbers = messages
    bad = ~np.isfinite(values)
    if not bad.any():
        return
    row, column = (int(v) for v in np.argwhere(bad)[0])
    value = float(values[row, column])
    word = "NaN" if np.isnan(value) else ("inf" if value > 0 else "-inf")
    count = int(bad.any(axis=1).sum())
    raise ValueError(
        f"{what}: {word} in {short_token(names[column], 30)[1:-1]} at message {numbers[row]} "
        f"(stamped {stamps[row] * 1e-9:.9f} s; {count:,} sample{'s' if count != 1 else ''} "
        f"with NaN or inf in all): a motion is read without gaps; drop those messages or fill them"
    )


def _transform_row(stamped) -> list:
    p, q = stamped.transform.translation, stamped.transform.rotation
    return [p.x, p.y, p.z, q.x, q.y, q.z, q.w]


# -- writing --------------------------------------------------------------------------------------
def write_bag(  # noqa: C901, PLR0913 - the public call spells its options out, as users pass them; one branch per documented option or part kind, each a line
    path,
    t,
    values,
    *,
    kind: str,
    topic: str | None = None,
    names=None,
    velocities=None,
    accelerations=None,
    frame_id: str = "base",
    origin: float | str = "now",
    ros: int = 2,
    orientation=None,
) -> Path:
    """Write a motion to a bag (module docstring).

    Parameters
    ----------
    path : str or Path
        A folder (ROS 2) or a ``.bag`` file (ROS 1).
    t : (n,)
        Seconds from the start.
    values : (n, 3) or (n, 7) for ``kind="pose"`` (m), (n, J) for ``kind="joints"`` or
        ``"follow"`` (rad).
    kind : {"pose", "joints", "follow"}
        A ``PoseStamped`` stream (a ``PointStamped`` stream for positions without
        ``orientation``), one ``JointTrajectory``, or one ``FollowJointTrajectory`` goal.
    topic : str, optional
        Default ``/bidmp/pose`` (``/bidmp/point``), ``/bidmp/joint_trajectory`` or
        ``/bidmp/follow_joint_trajectory/goal``.
    names : list of str, optional
        Joint names (default ``joint1`` ...).
    velocities, accelerations : (n, J), optional
        For the joint trajectory's points (rad/s, rad/s²).
    frame_id : str
        The header's frame.
    origin : float or "now"
        The first stamp, seconds since the epoch; ``"now"`` (the default): the time of writing.
    ros : {1, 2}
        ROS 2 MCAP (default) or ROS 1.
    orientation : (4,), optional
        ``qx, qy, qz, qw``: the orientation a position stream (3 columns) holds throughout, written
        as a PoseStamped stream.

    Returns
    -------
    Path
    """
    _rosbags()
    kind = check_choice(kind, "kind", ("pose", "joints", "follow"))
    if isinstance(ros, bool) or not isinstance(ros, int) or ros not in (1, 2):
        raise ValueError(f"ros must be 1 or 2, got {short_token(ros)}")
    t = as_vector(t, "t")
    if np.any(np.diff(t) <= 0):
        raise ValueError("t must increase from sample to sample (seconds)")
    values = as_trajectory(values, "values", min_points=1, allow_static=True)
    if values.shape[0] != t.size:
        raise ValueError(
            f"values has {values.shape[0]} rows but t has {t.size} times: one row per time"
        )
    if kind == "pose" and values.shape[1] not in (3, 7):
        raise ValueError(
            f"values: a pose stream needs 3 (x, y, z) or 7 (with qx, qy, qz, qw) columns, got {values.shape[1]}"
        )
    if orientation is not None:
        if kind != "pose" or values.shape[1] != 3:
            raise ValueError(
                "orientation is the held orientation of a position stream (kind='pose', 3 columns)"
            )
        orientation = as_vector(orientation, "orientation", length=4)
        if not abs(np.linalg.norm(orientation) - 1.0) <= 1e-6:
            raise ValueError(
                f"orientation must be a unit quaternion qx, qy, qz, qw; its norm is {np.linalg.norm(orientation):.6g}"
            )
    origin = start_stamp(origin)
    # Header stamps are whole seconds in a signed 32-bit field (ROS 2; ROS 1 an unsigned one).
    if origin + t[0] < 0 or origin + t[-1] >= 2**31:
        raise ValueError(
            f"t: origin + t must lie within [0, 2**31) s (a header stamp's seconds), "
            f"got {origin + t[0]:.6g} to {origin + t[-1]:.6g} s"
        )
    target = Path(check_path(path))
    msgtype = {
        "pose": POSE_STAMPED if values.shape[1] == 7 or orientation is not None else POINT_STAMPED,
        "joints": JOINT_TRAJECTORY,
        "follow": FOLLOW_JOINT_TRAJECTORY[ros],
    }[kind]
    if topic is None:
        topic = {
            POSE_STAMPED: "/bidmp/pose",
            POINT_STAMPED: "/bidmp/point",
            JOINT_TRAJECTORY: "/bidmp/joint_trajectory",
        }.get(msgtype, "/bidmp/follow_joint_trajectory/goal")
    elif (
        not isinstance(topic, str)
        or not topic.startswith("/")
        or len(topic) > 256
        or not topic[1:].strip()
    ):
        raise ValueError(
            f"topic must be a ROS topic name such as '/bidmp/pose', got {short_token(topic, 30)}"
        )
    if not isinstance(frame_id, str) or len(frame_id) > 256:
        raise TypeError(f"frame_id must be a frame name (text), got {short_token(frame_id, 30)}")
    if names is None:
        names = [f"joint{index + 1}" for index in range(values.shape[1])]
    elif (
        not isinstance(names, (list, tuple))
        or len(names) != values.shape[1]
        or not all(isinstance(name, str) and name for name in names)
    ):
        raise ValueError(
            f"names must be {values.shape[1]} joint names (text), one per column of values, "
            f"got {short_token(names, 30)}"
        )
    names = list(names)
    rates = []
    for rate, label in ((velocities, "velocities"), (accelerations, "accelerations")):
        if rate is not None:
            rate = as_trajectory(rate, label, min_points=1, allow_static=True)
            if rate.shape != values.shape:
                raise ValueError(
                    f"{label} must have the shape of values {values.shape}, got {rate.shape}"
                )
        rates.append(rate)
    velocities, accelerations = rates
    if orientation is not None:
        values = np.hstack([values, np.tile(orientation, (values.shape[0], 1))])
    messages = _messages(
        ros, msgtype, (t, values, velocities, accelerations), names, frame_id, origin
    )
    return _write_atomically(target, ros, topic, msgtype, messages)


def start_stamp(origin) -> float:
    """The first stamp of a bag, seconds since the epoch: ``"now"``, a number, or an ISO 8601
    time (``2026-12-03T14:00:00Z``; without a zone: UTC)."""
    import datetime

    if isinstance(origin, str):
        if origin.strip().lower() == "now":
            import time

            return time.time()
        try:
            moment = datetime.datetime.fromisoformat(origin.strip().replace("Z", "+00:00"))
        except ValueError:
            try:
                return start_stamp(float(origin))
            except ValueError:
                raise ValueError(
                    f"origin must be 'now', seconds since the epoch or an ISO 8601 time "
                    f"(2026-12-03T14:00:00Z), got {short_token(origin, 30)}"
                ) from None
        if moment.tzinfo is None:
            moment = moment.replace(tzinfo=datetime.UTC)
        return start_stamp(moment.timestamp())
    return check_real(origin, "origin", nonnegative=True)


def _store(ros: int, msgtype: str):
    """The typestore for ``ros``, with control_msgs' goal registered when it is wanted."""
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE if ros == 2 else Stores.ROS1_NOETIC)
    if msgtype == FOLLOW_JOINT_TRAJECTORY[ros]:
        types = {}
        for name, definition in _FOLLOW_DEFINITIONS[ros].items():
            types.update(get_types_from_msg(definition, name))
        store.register(types)
    return store


def _messages(ros: int, msgtype: str, motion: tuple, names, frame_id: str, origin: float):
    """(typestore, [(stamp ns, message), ...]) of ``motion`` = (times (n,) s, values (n, D),
    velocities and accelerations (n, D) or None)."""
    t, values, velocities, accelerations = motion
    store = _store(ros, msgtype)
    types = store.types

    # Stamps in integer nanoseconds, origin + t, each rounded once (the whole seconds apart: a float
    # of 1.8e18 ns would keep only 256 ns).
    start = int(origin) * 1_000_000_000 + int(round((origin - int(origin)) * 1e9))

    def header(nanoseconds: int):
        sec, nanosec = divmod(nanoseconds, 1_000_000_000)
        fields = {
            "stamp": types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec),
            "frame_id": frame_id,
        }
        return types["std_msgs/msg/Header"](**({"seq": 0} if ros == 1 else {}), **fields)

    def duration(seconds: float):
        sec, nanosec = divmod(int(round(seconds * 1e9)), 1_000_000_000)
        return types["builtin_interfaces/msg/Duration"](sec=sec, nanosec=nanosec)

    if msgtype in (POSE_STAMPED, POINT_STAMPED):
        out = []
        for time, row in zip(t, values):
            point = types["geometry_msgs/msg/Point"](*map(float, row[:3]))
            stamp = start + int(round(time * 1e9))
            if msgtype == POINT_STAMPED:
                out.append((stamp, types[POINT_STAMPED](header=header(stamp), point=point)))
                continue
            pose = types["geometry_msgs/msg/Pose"](
                position=point,
                orientation=types["geometry_msgs/msg/Quaternion"](*map(float, row[3:])),
            )
            out.append((stamp, types[POSE_STAMPED](header=header(stamp), pose=pose)))
        return store, out
    zeros = np.zeros_like(values)
    rates = (
        zeros if velocities is None else np.asarray(velocities, dtype=float),
        zeros if accelerations is None else np.asarray(accelerations, dtype=float),
    )
    points = [
        types["trajectory_msgs/msg/JointTrajectoryPoint"](
            positions=position.copy(),
            velocities=velocity.copy(),
            accelerations=acceleration.copy(),
            effort=np.zeros(0),
            time_from_start=duration(time),
        )
        for time, position, velocity, acceleration in zip(t, values, *rates)
    ]
    trajectory = types[JOINT_TRAJECTORY](header=header(start), joint_names=names, points=points)
    if msgtype == JOINT_TRAJECTORY:
        return store, [(start, trajectory)]
    goal = {"trajectory": trajectory, "path_tolerance": [], "goal_tolerance": []}
    if ros == 2:
        goal |= {
            "multi_dof_trajectory": types["trajectory_msgs/msg/MultiDOFJointTrajectory"](
                header=header(start), joint_names=[], points=[]
            ),
            "component_path_tolerance": [],
            "component_goal_tolerance": [],
            "goal_time_tolerance": duration(0.0),
        }
    else:
        goal["goal_time_tolerance"] = types["builtin_interfaces/msg/Duration"](sec=0, nanosec=0)
    return store, [(start, types[msgtype](**goal))]


def _write_atomically(target: Path, ros: int, topic: str, msgtype: str, messages) -> Path:
    """Write into a temporary path beside ``target``, then rename it into place."""
    store, stamped = messages
    directory = target.parent if str(target.parent) else Path(".")
    if not directory.is_dir():
        raise ValueError(
            f"path: cannot write {shown_path(target)}: folder {shown_path(directory)} does not exist"
        )
    # only a bag folder is replaced, never another folder
    if target.is_dir() and not is_bag(target):
        raise ValueError(
            f"path: {shown_path(target)} is a folder that is not a ROS bag; give a new name"
        )
    if target.exists() and not target.is_dir() and not target.is_file():
        raise ValueError(
            f"path: {shown_path(target)} is not a regular file (a device, pipe or socket)"
        )
    if ros == 2 and target.is_file():  # a ROS 2 bag is a folder: it does not replace a file
        raise ValueError(
            f"path: {shown_path(target)} is a file; a ROS 2 bag is a folder (give a new name, or ros=1)"
        )
    scratch = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=directory))
    built = scratch / target.name
    try:
        if ros == 2:
            from rosbags.rosbag2 import StoragePlugin, Writer

            writer, serialize = (
                Writer(built, version=9, storage_plugin=StoragePlugin.MCAP),
                store.serialize_cdr,
            )
        else:
            from rosbags.rosbag1 import Writer

            writer, serialize = Writer(built), store.serialize_ros1
        with writer:
            connection = writer.add_connection(topic, msgtype, typestore=store)
            for stamp, message in stamped:
                writer.write(connection, stamp, serialize(message, msgtype))
        if target.is_dir():
            shutil.rmtree(target)
        os.replace(built, target)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    return target
