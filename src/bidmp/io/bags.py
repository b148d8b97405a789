"""ROS 1 and ROS 2 bags without ROS, through the pure-Python ``rosbags`` package (the ``ros`` extra:
``pip install 'bidmp[ros]'``).

Reading (:func:`read_bag`): a demonstration from

* ``geometry_msgs/PoseStamped`` or ``geometry_msgs/TransformStamped`` on a topic → poses
  ``x, y, z, qx, qy, qz, qw`` (m);
* ``tf2_msgs/TFMessage`` (``/tf``, ``/tf_static``) → the transform from a parent frame to a child
  frame chosen by name (the direct edge of the tree, as published) → poses (m);
* ``sensor_msgs/JointState`` → the positions of the joints chosen by name, or all (rad).

Times are the messages' header stamps (not when the recorder received them), seconds from the
first. A ROS 1 ``.bag`` file or a ROS 2 bag folder (SQLite or MCAP, with its ``metadata.yaml``). A bag without the topic, with a message type bidmp does not read, or with stamps
that do not increase gives a one-line error that lists what the bag contains.

Writing (:func:`write_bag`): a motion as a ``geometry_msgs/PoseStamped`` stream (one message per
sample, stamped ``origin + t``) or as one ``trajectory_msgs/JointTrajectory`` (positions,
velocities, accelerations, ``time_from_start``), ROS 2 MCAP by default, ROS 1 on request; written
beside the target and renamed into place (a bag folder or file appears whole or not at all).
"""

from __future__ import annotations

import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._checks import as_trajectory, as_vector, check_choice, check_path, check_real, require_extra, short_token, shown_path

__all__ = ["BagRecording", "read_bag", "write_bag", "is_bag"]

POSE_STAMPED = "geometry_msgs/msg/PoseStamped"
TRANSFORM_STAMPED = "geometry_msgs/msg/TransformStamped"
TF_MESSAGE = "tf2_msgs/msg/TFMessage"
JOINT_STATE = "sensor_msgs/msg/JointState"
JOINT_TRAJECTORY = "trajectory_msgs/msg/JointTrajectory"
_READABLE = (POSE_STAMPED, TRANSFORM_STAMPED, TF_MESSAGE, JOINT_STATE)
POSE_COLUMNS = ["x", "y", "z", "qx", "qy", "qz", "qw"]


def _rosbags():
    return require_extra("rosbags", "ros", "ROS bags")


@dataclass(frozen=True)
class BagRecording:
    """A demonstration read from a bag.

    Attributes
    ----------
    t : (n,)
        Header stamps in seconds from the first.
    values : (n, D)
        Poses ``x, y, z, qx, qy, qz, qw`` (m) or joint positions (rad).
    names : list of str
        The columns of ``values`` (the joint names for joint states).
    kind : {"pose", "joints"}
    units : str
        ``"m"`` for poses, ``"rad"`` for joints.
    source : str
        What was read (``topic /ee_pose``, ``tf base -> tool``, ...).
    stamp : float
        The first header stamp (s since the epoch): ``t`` is counted from it, in integer
        nanoseconds (exact).
    """

    t: np.ndarray
    values: np.ndarray
    names: list
    kind: str
    units: str
    source: str
    stamp: float


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
    listed = ", ".join(f"{topic} ({kind}, {count} messages)" for (topic, kind), count in sorted(counts.items()))
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
        raise ValueError(f"{shown_path(path)} is not a ROS bag (a ROS 1 .bag file or a ROS 2 bag folder with metadata.yaml)")
    reader = highlevel.AnyReader([path])
    try:
        reader.open()
    except RecursionError:  # rosbags parses message definitions recursively
        raise ValueError(f"cannot read bag {shown_path(path)}: its message definitions nest types too deeply") from None
    except Exception as exc:  # rosbags' own errors (AnyReaderError, a broken metadata.yaml, ...): one line
        raise ValueError(f"cannot read bag {shown_path(path)}: {type(exc).__name__}: {exc}") from None
    return reader


def read_bag(path, *, topic: str | None = None, tf: tuple[str, str] | None = None, joints=None) -> BagRecording:
    """A demonstration from a bag (module docstring).

    Parameters
    ----------
    path : str or Path
        A ROS 1 ``.bag`` file or a ROS 2 bag folder.
    topic : str, optional
        A ``PoseStamped``, ``TransformStamped`` or ``JointState`` topic (default: the bag's only
        one of these types; with ``tf``, ``/tf`` and ``/tf_static``).
    tf : (parent, child), optional
        Read the transform from frame ``parent`` to frame ``child`` from ``TFMessage`` topics.
    joints : list of str or True, optional
        Joint states: these joints, in this order (True: every joint of the first message).

    Returns
    -------
    BagRecording
    """
    _check_selection(topic, tf, joints)
    reader = _open(path)
    try:
        wanted = _wanted_connections(reader, topic, tf, joints)
        kind = "joints" if wanted[0].msgtype == JOINT_STATE else "pose"
        stamps, rows, names = [], [], None
        for connection, _, raw in reader.messages(connections=wanted):
            message = reader.deserialize(raw, connection.msgtype)
            for stamp, row, found in _rows(message, connection.msgtype, tf, joints, names):
                names = found if names is None else names
                stamps.append(stamp)
                rows.append(row)
        source = (f"tf {tf[0]} -> {tf[1]}" if tf is not None else f"topic {wanted[0].topic}")
        if not rows:
            raise ValueError(f"bag {shown_path(path)}: no {source} message in it; it has: {_contents(reader)}")
        steps = [later - earlier for earlier, later in zip(stamps, stamps[1:])]
        if any(step <= 0 for step in steps):
            first = next(index for index, step in enumerate(steps) if step <= 0)
            raise ValueError(f"bag {shown_path(path)}: the header stamps of {source} do not increase (message {first + 1} "
                             f"at {stamps[first] * 1e-9:.9f} s, the next at {stamps[first + 1] * 1e-9:.9f} s); "
                             f"it has: {_contents(reader)}")
    finally:
        reader.close()
    values = np.array(rows, dtype=float)
    t = np.array([stamp - stamps[0] for stamp in stamps], dtype=float) * 1e-9  # exact to the nanosecond
    return BagRecording(t, values, list(names), kind, "rad" if kind == "joints" else "m", source, stamps[0] * 1e-9)


def _check_selection(topic, tf, joints) -> None:
    """Refuse a topic, frame pair or joint list that could name nothing, before the bag is opened."""
    if topic is not None and (not isinstance(topic, str) or not topic.strip() or len(topic) > 256):
        raise ValueError(f"topic must be a topic name such as '/bidmp/pose', got {short_token(topic, 30)}")
    if tf is not None and (not isinstance(tf, (tuple, list)) or len(tf) != 2
                           or not all(isinstance(frame, str) and frame and len(frame) <= 256 for frame in tf)):
        raise ValueError(f"tf must be (parent frame, child frame), two names, got {short_token(tf, 30)}")
    if joints is not None and joints is not True and (
            not isinstance(joints, (list, tuple)) or not joints
            or not all(isinstance(name, str) and name and len(name) <= 256 for name in joints)):
        raise ValueError(f"joints must be a list of joint names or True (every joint), got {short_token(joints, 30)}")
    if tf is not None and joints is not None:
        raise ValueError("tf and joints: give one (a transform or joint states), not both")


def _wanted_connections(reader, topic, tf, joints) -> list:
    """The connections to read, refused in one line that lists the bag's contents."""
    if tf is not None:
        topics = {topic} if topic is not None else {"/tf", "/tf_static"}
        found = [c for c in reader.connections if c.topic in topics and c.msgtype == TF_MESSAGE]
        if not found:
            raise ValueError(f"tf: the bag has no TFMessage topic {' or '.join(sorted(topics))}; it has: {_contents(reader)}")
        return found
    if topic is None:
        types = (JOINT_STATE,) if joints is not None else (POSE_STAMPED, TRANSFORM_STAMPED)
        found = [c for c in reader.connections if c.msgtype in types]
        if len({c.topic for c in found}) != 1:
            wanted = "joints" if joints is not None else "topic"
            raise ValueError(f"{wanted}: name the topic to read: the bag has {len({c.topic for c in found})} topics of "
                             f"type {' or '.join(types)}; it has: {_contents(reader)}")
        return found
    found = [c for c in reader.connections if c.topic == topic]
    if not found:
        raise ValueError(f"topic {short_token(topic, 40)} is not in the bag; it has: {_contents(reader)}")
    if found[0].msgtype not in (POSE_STAMPED, TRANSFORM_STAMPED, JOINT_STATE):
        raise ValueError(f"topic {topic} carries {found[0].msgtype}, which bidmp does not read (it reads "
                         f"{', '.join(_READABLE)}; TFMessage with tf); it has: {_contents(reader)}")
    if (found[0].msgtype == JOINT_STATE) != (joints is not None):
        raise ValueError(f"topic {topic} carries {found[0].msgtype}: " + ("give joints, the joints to read" if joints is None
                                                                        else "joints are read from a JointState topic"))
    return found


def _rows(message, msgtype: str, tf, joints, names):
    """(stamp s, row, column names) of the samples one message holds."""
    if msgtype == POSE_STAMPED:
        p, q = message.pose.position, message.pose.orientation
        yield _stamp(message.header), [p.x, p.y, p.z, q.x, q.y, q.z, q.w], POSE_COLUMNS
    elif msgtype == TRANSFORM_STAMPED:
        yield _stamp(message.header), _transform_row(message), POSE_COLUMNS
    elif msgtype == TF_MESSAGE:
        for transform in message.transforms:
            if transform.header.frame_id.lstrip("/") == tf[0].lstrip("/") and transform.child_frame_id.lstrip("/") == tf[1].lstrip("/"):
                yield _stamp(transform.header), _transform_row(transform), POSE_COLUMNS
    else:
        available = list(message.name)
        chosen = available if joints is True else (names or list(joints))
        missing = [name for name in chosen if name not in available]
        if missing:
            raise ValueError(f"joint state without joint(s) {', '.join(missing)}; it names {', '.join(available)}")
        positions = np.asarray(message.position, dtype=float)
        yield _stamp(message.header), [positions[available.index(name)] for name in chosen], chosen


def _transform_row(stamped) -> list:
    p, q = stamped.transform.translation, stamped.transform.rotation
    return [p.x, p.y, p.z, q.x, q.y, q.z, q.w]


# -- writing --------------------------------------------------------------------------------------
def write_bag(path, t, values, *, kind: str, topic: str | None = None, names=None, velocities=None,
              accelerations=None, frame_id: str = "base", origin: float = 0.0, ros: int = 2) -> Path:
    """Write a motion to a bag (module docstring).

    Parameters
    ----------
    path : str or Path
        A folder (ROS 2) or a ``.bag`` file (ROS 1).
    t : (n,)
        Seconds from the start.
    values : (n, 3) or (n, 7) for ``kind="pose"`` (m; no orientation: identity), (n, J) for
        ``kind="joints"`` (rad).
    kind : {"pose", "joints"}
        A ``PoseStamped`` stream or one ``JointTrajectory``.
    topic : str, optional
        Default ``/bidmp/pose`` or ``/bidmp/joint_trajectory``.
    names : list of str, optional
        Joint names (default ``joint1`` ...).
    velocities, accelerations : (n, J), optional
        For the joint trajectory's points (rad/s, rad/s²).
    frame_id : str
        The header's frame.
    origin : float
        The first stamp, seconds since the epoch.
    ros : {1, 2}
        ROS 2 MCAP (default) or ROS 1.

    Returns
    -------
    Path
    """
    _rosbags()
    kind = check_choice(kind, "kind", ("pose", "joints"))
    if isinstance(ros, bool) or not isinstance(ros, int) or ros not in (1, 2):
        raise ValueError(f"ros must be 1 or 2, got {short_token(ros)}")
    t = as_vector(t, "t")
    if np.any(np.diff(t) <= 0):
        raise ValueError("t must increase from sample to sample (seconds)")
    values = as_trajectory(values, "values", min_points=1, allow_static=True)
    if values.shape[0] != t.size:
        raise ValueError(f"values has {values.shape[0]} rows but t has {t.size} times: one row per time")
    if kind == "pose" and values.shape[1] not in (3, 7):
        raise ValueError(f"values: a pose stream needs 3 (x, y, z) or 7 (with qx, qy, qz, qw) columns, got {values.shape[1]}")
    origin = check_real(origin, "origin", nonnegative=True)
    # Header stamps are whole seconds in a signed 32-bit field (ROS 2; ROS 1 an unsigned one).
    if origin + t[0] < 0 or origin + t[-1] >= 2**31:
        raise ValueError(f"t: origin + t must lie within [0, 2**31) s (a header stamp's seconds), "
                         f"got {origin + t[0]:.6g} to {origin + t[-1]:.6g} s")
    target = Path(check_path(path))
    if topic is None:
        topic = "/bidmp/pose" if kind == "pose" else "/bidmp/joint_trajectory"
    elif not isinstance(topic, str) or not topic.startswith("/") or len(topic) > 256 or not topic[1:].strip():
        raise ValueError(f"topic must be a ROS topic name such as '/bidmp/pose', got {short_token(topic, 30)}")
    if not isinstance(frame_id, str) or len(frame_id) > 256:
        raise TypeError(f"frame_id must be a frame name (text), got {short_token(frame_id, 30)}")
    if names is None:
        names = [f"joint{index + 1}" for index in range(values.shape[1])]
    elif (not isinstance(names, (list, tuple)) or len(names) != values.shape[1]
          or not all(isinstance(name, str) and name for name in names)):
        raise ValueError(f"names must be {values.shape[1]} joint names (text), one per column of values, "
                         f"got {short_token(names, 30)}")
    names = list(names)
    rates = []
    for rate, label in ((velocities, "velocities"), (accelerations, "accelerations")):
        if rate is not None:
            rate = as_trajectory(rate, label, min_points=1, allow_static=True)
            if rate.shape != values.shape:
                raise ValueError(f"{label} must have the shape of values {values.shape}, got {rate.shape}")
        rates.append(rate)
    velocities, accelerations = rates
    messages = _messages(ros, kind, t, values, names, velocities, accelerations, frame_id, origin)
    return _write_atomically(target, ros, topic, POSE_STAMPED if kind == "pose" else JOINT_TRAJECTORY, messages)


def _messages(ros: int, kind: str, t, values, names, velocities, accelerations, frame_id: str, origin: float):
    """(typestore, [(stamp ns, message), ...])."""
    from rosbags.typesys import Stores, get_typestore

    store = get_typestore(Stores.ROS2_HUMBLE if ros == 2 else Stores.ROS1_NOETIC)
    types = store.types

    start = int(round(origin * 1e9))  # stamps in integer nanoseconds: origin + t, each rounded once

    def header(nanoseconds: int):
        sec, nanosec = divmod(nanoseconds, 1_000_000_000)
        fields = {"stamp": types["builtin_interfaces/msg/Time"](sec=sec, nanosec=nanosec), "frame_id": frame_id}
        return types["std_msgs/msg/Header"](**({"seq": 0} if ros == 1 else {}), **fields)

    if kind == "pose":
        quaternions = values[:, 3:] if values.shape[1] == 7 else np.tile([0.0, 0.0, 0.0, 1.0], (len(t), 1))
        out = []
        for time, point, q in zip(t, values[:, :3], quaternions):
            pose = types["geometry_msgs/msg/Pose"](position=types["geometry_msgs/msg/Point"](*map(float, point)),
                                                   orientation=types["geometry_msgs/msg/Quaternion"](*map(float, q)))
            stamp = start + int(round(time * 1e9))
            out.append((stamp, types[POSE_STAMPED](header=header(stamp), pose=pose)))
        return store, out
    zeros = np.zeros_like(values)
    rates = (zeros if velocities is None else np.asarray(velocities, dtype=float),
             zeros if accelerations is None else np.asarray(accelerations, dtype=float))
    points = []
    for time, position, velocity, acceleration in zip(t, values, *rates):
        sec, nanosec = divmod(int(round(time * 1e9)), 1_000_000_000)
        points.append(types["trajectory_msgs/msg/JointTrajectoryPoint"](
            positions=position.copy(), velocities=velocity.copy(), accelerations=acceleration.copy(), effort=np.zeros(0),
            time_from_start=types["builtin_interfaces/msg/Duration"](sec=sec, nanosec=nanosec)))
    message = types[JOINT_TRAJECTORY](header=header(start), joint_names=names, points=points)
    return store, [(start, message)]


def _write_atomically(target: Path, ros: int, topic: str, msgtype: str, messages) -> Path:
    """Write into a temporary path beside ``target``, then rename it into place."""
    store, stamped = messages
    directory = target.parent if str(target.parent) else Path(".")
    if not directory.is_dir():
        raise ValueError(f"path: cannot write {shown_path(target)}: folder {shown_path(directory)} does not exist")
    if target.is_dir() and not is_bag(target):  # only a bag folder is replaced, never another folder
        raise ValueError(f"path: {shown_path(target)} is a folder that is not a ROS bag; give a new name")
    if target.exists() and not target.is_dir() and not target.is_file():
        raise ValueError(f"path: {shown_path(target)} is not a regular file (a device, pipe or socket)")
    if ros == 2 and target.is_file():  # a ROS 2 bag is a folder: it does not replace a file
        raise ValueError(f"path: {shown_path(target)} is a file; a ROS 2 bag is a folder (give a new name, or ros=1)")
    scratch = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=directory))
    built = scratch / target.name
    try:
        if ros == 2:
            from rosbags.rosbag2 import StoragePlugin, Writer

            writer, serialize = Writer(built, version=9, storage_plugin=StoragePlugin.MCAP), store.serialize_cdr
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
