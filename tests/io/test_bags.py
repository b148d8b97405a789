"""ROS bags without ROS. The bags are written here with rosbags' own writers and
typestores (not with bidmp's), each holding what a robot's recorder would: other topics beside the
one read, other frames on /tf, more joints than asked for, header stamps that differ from the
receive times. Each fits to the same model as the equivalent CSV written from the same numbers
(≤ 1e-9), and what bidmp writes reads back through rosbags with the right types, stamps and values."""

import sys
from pathlib import Path

import numpy as np
import pytest
from rosbags.highlevel import AnyReader
from rosbags.typesys import Stores, get_typestore

from bidmp.cli import main
from bidmp.demonstrations import minimum_jerk
from bidmp.io import load_model

START_NS = 1_700_000_000_123_456_789  # a header stamp far from zero, in nanoseconds
N = 240
RECEIVED_LATE_NS = 3_000_000  # the recorder wrote each message 3 ms after its stamp


def _header(types, ns, frame, ros):
    stamp = types["builtin_interfaces/msg/Time"](
        sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000
    )
    return types["std_msgs/msg/Header"](
        **({"seq": 0} if ros == 1 else {}), stamp=stamp, frame_id=frame
    )


def _stamps(rng):
    steps = rng.integers(3_500_000, 4_500_000, N - 1)  # jittered ~250 Hz
    return START_NS + np.concatenate([[0], np.cumsum(steps)])


def _write(path: Path, ros: int, topics: list, store=None, storage: str = "mcap"):
    """``topics``: [(topic, msgtype, [(stamp ns, message), ...])] into a ROS 1 file or ROS 2
    folder (``storage``: "mcap" or "sqlite3")."""
    store = store or get_typestore(Stores.ROS1_NOETIC if ros == 1 else Stores.ROS2_HUMBLE)
    if ros == 1:
        from rosbags.rosbag1 import Writer

        writer, serialize = Writer(path), store.serialize_ros1
    else:
        from rosbags.rosbag2 import StoragePlugin, Writer

        plugin = StoragePlugin.MCAP if storage == "mcap" else StoragePlugin.SQLITE3
        writer, serialize = (
            Writer(path, version=9, storage_plugin=plugin),
            store.serialize_cdr,
        )
    with writer:
        for topic, msgtype, messages in topics:
            connection = writer.add_connection(topic, msgtype, typestore=store)
            for ns, message in messages:
                writer.write(connection, int(ns) + RECEIVED_LATE_NS, serialize(message, msgtype))
    return store


def _csv(path: Path, stamps, columns, values, units="m"):
    t = (np.asarray(stamps) - stamps[0]).astype(np.int64) * 1e-9
    with open(path, "w") as handle:
        if units:
            handle.write(f"# units: {units}\n")
        handle.write(",".join(["t", *columns]) + "\n")
        for time, row in zip(t, values):
            handle.write(",".join(repr(float(v)) for v in [time, *row]) + "\n")


def _poses(rng):
    positions = minimum_jerk(np.array([[0.0, 0.0, 0.3], [0.12, 0.05, 0.3], [0.12, 0.05, 0.2]]), N)
    angles = np.linspace(0.0, 0.6, N)
    quaternions = np.column_stack(
        [np.sin(angles / 2) * 0.6, np.zeros(N), np.sin(angles / 2) * 0.8, np.cos(angles / 2)]
    )
    return np.hstack([positions + rng.normal(0, 1e-5, positions.shape), quaternions])


def _pose_messages(store, stamps, poses, ros, frame="base"):
    types = store.types
    out = []
    for ns, row in zip(stamps, poses):
        pose = types["geometry_msgs/msg/Pose"](
            position=types["geometry_msgs/msg/Point"](*row[:3]),
            orientation=types["geometry_msgs/msg/Quaternion"](*row[3:]),
        )
        out.append(
            (
                ns,
                types["geometry_msgs/msg/PoseStamped"](
                    header=_header(types, int(ns), frame, ros), pose=pose
                ),
            )
        )
    return out


def _table(path: Path) -> np.ndarray:
    """A CSV's numbers (comment lines and the header left out)."""
    lines = [line for line in path.read_text().splitlines() if line and not line.startswith("#")][
        1:
    ]
    return np.array([[float(v) for v in line.split(",")] for line in lines])


def _fit(tmp_path, source, *options):
    model = tmp_path / f"{Path(source).name}.npz"
    assert main(["fit", str(source), "-o", str(model), *options]) == 0
    return load_model(model)


def test_a_ros2_mcap_pose_bag_fits_the_model_of_the_same_csv(tmp_path):
    rng = np.random.default_rng(1)
    stamps, poses = _stamps(rng), _poses(rng)
    store = get_typestore(Stores.ROS2_HUMBLE)
    other = [(ns, store.types["std_msgs/msg/String"](data="noise")) for ns in stamps[::10]]
    _write(
        tmp_path / "poses",
        2,
        [
            ("/ee_pose", "geometry_msgs/msg/PoseStamped", _pose_messages(store, stamps, poses, 2)),
            ("/log", "std_msgs/msg/String", other),
        ],
    )
    _csv(tmp_path / "poses.csv", stamps, ["x", "y", "z", "qx", "qy", "qz", "qw"], poses)
    from_bag = _fit(tmp_path, tmp_path / "poses", "--topic", "/ee_pose")
    from_csv = _fit(tmp_path, tmp_path / "poses.csv")
    assert from_bag.units_ == "m" == from_csv.units_
    for part in ("position_", "orientation_"):
        np.testing.assert_allclose(
            getattr(from_bag, part).weights_, getattr(from_csv, part).weights_, atol=1e-9, rtol=0
        )


def test_a_ros1_tf_bag_reads_the_chosen_edge_of_the_tree(tmp_path):
    rng = np.random.default_rng(2)
    stamps, poses = _stamps(rng), _poses(rng)
    store = get_typestore(Stores.ROS1_NOETIC)
    from rosbags.typesys import get_types_from_msg

    store.register(
        get_types_from_msg("geometry_msgs/TransformStamped[] transforms", "tf2_msgs/msg/TFMessage")
    )
    types = store.types
    messages = []
    for ns, row in zip(stamps, poses):
        transforms = []
        for parent, child, values in (
            ("world", "base", [1.0, 2.0, 0.0, 0, 0, 0, 1]),
            ("base", "tool", row),
        ):
            transform = types["geometry_msgs/msg/Transform"](
                translation=types["geometry_msgs/msg/Vector3"](*values[:3]),
                rotation=types["geometry_msgs/msg/Quaternion"](*values[3:]),
            )
            transforms.append(
                types["geometry_msgs/msg/TransformStamped"](
                    header=_header(types, int(ns), parent, 1),
                    child_frame_id=child,
                    transform=transform,
                )
            )
        messages.append((ns, types["tf2_msgs/msg/TFMessage"](transforms=transforms)))
    _write(tmp_path / "tf.bag", 1, [("/tf", "tf2_msgs/msg/TFMessage", messages)], store)
    _csv(tmp_path / "tf.csv", stamps, ["x", "y", "z", "qx", "qy", "qz", "qw"], poses)
    from_bag = _fit(tmp_path, tmp_path / "tf.bag", "--tf", "base", "tool")
    from_csv = _fit(tmp_path, tmp_path / "tf.csv")
    np.testing.assert_allclose(
        from_bag.position_.weights_, from_csv.position_.weights_, atol=1e-9, rtol=0
    )


def test_a_joint_state_bag_fits_the_joint_space_model_of_the_same_csv(tmp_path):
    rng = np.random.default_rng(3)
    stamps = _stamps(rng)
    s = np.linspace(0.0, 1.0, N)
    names = [f"panda_joint{k}" for k in range(1, 8)]
    q = np.array([0, -0.785, 0, -2.356, 0, 1.571, 0.785]) + np.outer(
        10 * s**3 - 15 * s**4 + 6 * s**5, rng.uniform(-0.5, 0.5, 7)
    )
    store = get_typestore(Stores.ROS2_HUMBLE)
    types = store.types
    order = rng.permutation(7)  # the driver publishes its own order, with the gripper too
    messages = [
        (
            ns,
            types["sensor_msgs/msg/JointState"](
                header=_header(types, int(ns), "", 2),
                name=[names[k] for k in order] + ["panda_finger_joint1"],
                position=np.append(row[order], 0.04),
                velocity=np.zeros(0),
                effort=np.zeros(0),
            ),
        )
        for ns, row in zip(stamps, q)
    ]
    _write(tmp_path / "joints", 2, [("/joint_states", "sensor_msgs/msg/JointState", messages)])
    _csv(tmp_path / "joints.csv", stamps, names, q, units="")
    from_bag = _fit(tmp_path, tmp_path / "joints", "--joints", *names)
    from_csv = _fit(tmp_path, tmp_path / "joints.csv")
    assert from_bag.n_dims_ == 7
    np.testing.assert_allclose(from_bag.weights_, from_csv.weights_, atol=1e-9, rtol=0)
    np.testing.assert_allclose(
        from_bag.goal_, q[-1], atol=1e-3
    )  # the chosen order, not the driver's


def _read_all(path):
    with AnyReader([path]) as reader:
        (connection,) = reader.connections
        return connection, [
            reader.deserialize(raw, connection.msgtype) for _, _, raw in reader.messages()
        ]


def test_rolled_out_motions_read_back_as_ros_messages(tmp_path):
    """stamps from the given start (not 1970), the user's topic and frame, no made-up
    orientation (a position model writes PointStamped, or PoseStamped holding the orientation
    it is given), joint names from the recording in the JointTrajectory and the FollowJointTrajectory
    goal (read back through rosbags from the definitions the bag carries)."""
    demonstration = minimum_jerk([[0, 0, 60], [100, 0, 60], [100, 0, 0]], 300)
    np.savetxt(
        tmp_path / "d.csv",
        np.column_stack([np.linspace(0, 3, 300), demonstration]),
        delimiter=",",
        header="# units: mm\nt,x,y,z",
        comments="",
    )
    assert main(["fit", str(tmp_path / "d.csv"), "-o", str(tmp_path / "m.npz"), "--raw"]) == 0
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "m.npz"),
                "--rate",
                "50",
                "-o",
                str(tmp_path / "r.csv"),
                "--bag",
                str(tmp_path / "out"),
                "--frame",
                "panda_link0",
                "--stamp",
                "2026-12-03T14:00:00.25Z",
                "--bag-topic",
                "/cell/tool_point",
            ]
        )
        == 0
    )
    rows = _table(tmp_path / "r.csv")
    connection, read = _read_all(tmp_path / "out")
    assert (
        connection.msgtype == "geometry_msgs/msg/PointStamped"
        and connection.topic == "/cell/tool_point"
    )
    stamps = np.array([m.header.stamp.sec + 1e-9 * m.header.stamp.nanosec for m in read])
    start = 1_796_306_400.25  # 2026-12-03T14:00:00.25Z, by hand: 20 790 days after 1970-01-01, then 14 h
    assert 20_790 * 86_400 + 14 * 3_600 + 0.25 == start
    np.testing.assert_allclose(stamps - start, rows[:, 0], atol=1e-6)
    positions = np.array([[m.point.x, m.point.y, m.point.z] for m in read])
    np.testing.assert_allclose(positions, rows[:, 1:4] / 1000.0, atol=1e-12)  # mm -> m
    assert {m.header.frame_id for m in read} == {"panda_link0"}
    # The same motion holding a given orientation: PoseStamped, that quaternion in every message.
    held = [1.0, 0.0, 0.0, 0.0]  # tool pointing down
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "m.npz"),
                "--rate",
                "50",
                "-o",
                str(tmp_path / "r2.csv"),
                "--bag",
                str(tmp_path / "held"),
                "--stamp",
                "1796306400.25",
                "--orientation",
                *map(str, held),
            ]
        )
        == 0
    )
    connection, read = _read_all(tmp_path / "held")
    assert (
        connection.msgtype == "geometry_msgs/msg/PoseStamped" and connection.topic == "/bidmp/pose"
    )
    assert {
        (m.pose.orientation.x, m.pose.orientation.y, m.pose.orientation.z, m.pose.orientation.w)
        for m in read
    } == {tuple(held)}
    assert (
        read[0].header.stamp.sec == 1_796_306_400
        and abs(read[0].header.stamp.nanosec - 250_000_000) <= 1
    )
    # A joint-space model: one JointTrajectory in a ROS 1 bag, with the recording's joint names.
    names = [
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    ]
    q = np.column_stack([np.linspace(0, 1, 300) ** 2 * k * 0.2 for k in range(1, 7)])
    np.savetxt(
        tmp_path / "j.csv",
        np.column_stack([np.linspace(0, 3, 300), q]),
        delimiter=",",
        header="t," + ",".join(names),
        comments="",
    )
    assert main(["fit", str(tmp_path / "j.csv"), "-o", str(tmp_path / "j.npz"), "--raw"]) == 0
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "j.npz"),
                "--rate",
                "50",
                "-o",
                str(tmp_path / "jr.csv"),
                "--bag",
                str(tmp_path / "j.bag"),
                "--ros1",
            ]
        )
        == 0
    )
    header = (tmp_path / "jr.csv").read_text().splitlines()[1].split(",")
    assert header == ["t", *names, *(f"v{n}" for n in names), *(f"a{n}" for n in names)]
    joints = _table(tmp_path / "jr.csv")
    connection, (message,) = _read_all(tmp_path / "j.bag")
    assert (
        connection.msgtype == "trajectory_msgs/msg/JointTrajectory"
        and list(message.joint_names) == names
    )
    np.testing.assert_allclose(
        [p.time_from_start.sec + 1e-9 * p.time_from_start.nanosec for p in message.points],
        joints[:, 0],
        atol=1e-9,
    )
    np.testing.assert_allclose([p.positions for p in message.points], joints[:, 1:7], atol=1e-12)
    np.testing.assert_allclose([p.velocities for p in message.points], joints[:, 7:13], atol=1e-12)
    # The goal a ROS 2 controller takes, in ROS 2 and ROS 1 bags.
    for ros, out in ((2, tmp_path / "goal"), (1, tmp_path / "goal.bag")):
        assert (
            main(
                [
                    "rollout",
                    str(tmp_path / "j.npz"),
                    "--rate",
                    "50",
                    "-o",
                    str(tmp_path / "jr.csv"),
                    "--bag",
                    str(out),
                    "--follow",
                    *(["--ros1"] if ros == 1 else []),
                ]
            )
            == 0
        )
        connection, (goal,) = _read_all(out)
        assert connection.msgtype == (
            "control_msgs/action/FollowJointTrajectory_Goal"
            if ros == 2
            else "control_msgs/msg/FollowJointTrajectoryGoal"
        )
        assert list(goal.trajectory.joint_names) == names and len(goal.path_tolerance) == 0
        np.testing.assert_allclose(
            [p.positions for p in goal.trajectory.points], joints[:, 1:7], atol=1e-12
        )


def test_a_bag_with_receive_jitter_fits_the_model_of_its_csv_and_real_jumps_back_are_refused(
    tmp_path, capsys
):
    """messages received 0-4 ms after their stamps, and 0-9 ms (then out of receive
    order: transport jitter), are put in the order of their stamps: the same model as the CSV of
    the same samples; two messages with one stamp, or a
    stamp 0.5 s back (a clock reset), are refused in one line that lists the bag."""
    rng = np.random.default_rng(4)
    stamps, poses = _stamps(rng), _poses(rng)
    store = get_typestore(Stores.ROS2_HUMBLE)
    messages = _pose_messages(store, stamps, poses, 2)
    _csv(tmp_path / "j.csv", stamps, ["x", "y", "z", "qx", "qy", "qz", "qw"], poses)
    from_csv = _fit(tmp_path, tmp_path / "j.csv")
    for delay_ms in (4, 9):
        received = stamps + rng.integers(0, delay_ms * 1_000_000 + 1, N)
        order = np.argsort(received, kind="stable")
        assert (delay_ms == 9) == bool(np.any(order != np.arange(N)))  # 9 ms: really out of order
        _write(
            tmp_path / f"j{delay_ms}",
            2,
            [
                (
                    "/ee_pose",
                    "geometry_msgs/msg/PoseStamped",
                    [(received[i] - RECEIVED_LATE_NS, messages[i][1]) for i in order],
                )
            ],
        )
        from_bag = _fit(tmp_path, tmp_path / f"j{delay_ms}")
        for part in ("position_", "orientation_"):
            np.testing.assert_allclose(
                getattr(from_bag, part).weights_,
                getattr(from_csv, part).weights_,
                atol=1e-9,
                rtol=0,
            )
    repeated = list(messages)
    repeated[11] = (
        stamps[11],
        _pose_messages(store, [stamps[10]], poses[11:12], 2)[0][1],
    )  # stamped as message 10
    back = list(messages)
    back[100] = (
        stamps[100],
        _pose_messages(store, [stamps[100] - 500_000_000], poses[100:101], 2)[0][1],
    )
    capsys.readouterr()
    for name, bag, expected in (
        ("r", repeated, "repeat: two messages stamped"),
        ("b", back, "jump back in time"),
    ):
        _write(
            tmp_path / name,
            2,
            [
                ("/ee_pose", "geometry_msgs/msg/PoseStamped", bag),
                (
                    "/log",
                    "std_msgs/msg/String",
                    [(stamps[0], store.types["std_msgs/msg/String"](data="x"))],
                ),
            ],
        )
        assert (
            main(
                ["fit", str(tmp_path / name), "-o", str(tmp_path / "m.npz"), "--topic", "/ee_pose"]
            )
            == 2
        )
        err = capsys.readouterr().err.strip().splitlines()
        assert (
            len(err) == 1
            and expected in err[0]
            and "/ee_pose (geometry_msgs/msg/PoseStamped, 240 messages)" in err[0]
        )


def test_a_bag_without_the_topic_or_of_a_foreign_type_says_what_it_holds(tmp_path, capsys):
    rng = np.random.default_rng(4)
    stamps, poses = _stamps(rng), _poses(rng)
    store = get_typestore(Stores.ROS2_HUMBLE)
    _write(
        tmp_path / "b",
        2,
        [
            ("/ee_pose", "geometry_msgs/msg/PoseStamped", _pose_messages(store, stamps, poses, 2)),
            (
                "/log",
                "std_msgs/msg/String",
                [(stamps[0], store.types["std_msgs/msg/String"](data="x"))],
            ),
        ],
    )
    for options, expected in (
        (["--topic", "/nope"], "topic '/nope' is not in the bag"),
        (["--topic", "/log"], "does not read"),
    ):
        assert main(["fit", str(tmp_path / "b"), "-o", str(tmp_path / "m.npz"), *options]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert (
            len(err) == 1
            and expected in err[0]
            and "/ee_pose (geometry_msgs/msg/PoseStamped, 240 messages)" in err[0]
        )


def test_without_the_ros_extra_bag_input_says_how_to_install_it(tmp_path, capsys, monkeypatch):
    (tmp_path / "b").mkdir()
    (tmp_path / "b" / "metadata.yaml").write_text("rosbag2_bagfile_information: {}\n")
    assert (
        main(["fit", str(tmp_path / "b"), "-o", str(tmp_path / "m.npz")]) == 2
    )  # a broken bag: one line
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "cannot read" in err[0]
    for name in [
        module for module in sys.modules if module == "rosbags" or module.startswith("rosbags.")
    ]:
        monkeypatch.setitem(sys.modules, name, None)  # as if the extra were not installed
    monkeypatch.setitem(sys.modules, "rosbags", None)
    monkeypatch.setitem(sys.modules, "rosbags.highlevel", None)
    assert main(["fit", str(tmp_path / "b"), "-o", str(tmp_path / "m.npz")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "pip install 'bidmp[ros]'" in err[0]


def test_a_position_motion_leaves_as_the_robots_joint_trajectory_after_ik(tmp_path):
    """bidmp rollout --robot panda --bag: the JointTrajectory's points, put through an independent
    forward kinematics (a bare Panda in its own PyBullet world, the tool's length added along the
    flange's z), land on the rolled-out Cartesian samples."""
    pytest.importorskip("pybullet")
    import pybullet as p
    import pybullet_data
    from scipy.spatial.transform import Rotation

    demonstration = minimum_jerk([[400, -100, 350], [500, 50, 300], [550, 100, 200]], 200)
    np.savetxt(
        tmp_path / "d.csv",
        np.column_stack([np.linspace(0, 2, 200), demonstration]),
        delimiter=",",
        header="# units: mm\nt,x,y,z",
        comments="",
    )
    assert main(["fit", str(tmp_path / "d.csv"), "-o", str(tmp_path / "m.npz"), "--raw"]) == 0
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "m.npz"),
                "--rate",
                "25",
                "-o",
                str(tmp_path / "r.csv"),
                "--robot",
                "panda",
                "--tool-length",
                "0.1",
                "--base",
                "0",
                "0",
                "50",
                "--bag",
                str(tmp_path / "out"),
            ]
        )
        == 0
    )
    rows = _table(tmp_path / "r.csv")
    with AnyReader([tmp_path / "out"]) as reader:
        (connection,) = reader.connections
        assert connection.msgtype == "trajectory_msgs/msg/JointTrajectory"
        (message,) = [
            reader.deserialize(raw, connection.msgtype) for _, _, raw in reader.messages()
        ]
    assert list(message.joint_names) == [f"panda_joint{k}" for k in range(1, 8)]
    times = np.array(
        [q.time_from_start.sec + 1e-9 * q.time_from_start.nanosec for q in message.points]
    )
    np.testing.assert_allclose(times, rows[:, 0], atol=1e-9)
    client = p.connect(p.DIRECT)
    try:
        body = p.loadURDF(
            f"{pybullet_data.getDataPath()}/franka_panda/panda.urdf",
            useFixedBase=True,
            physicsClientId=client,
        )
        tips = []
        for point in message.points:
            for joint, value in enumerate(point.positions):
                p.resetJointState(body, joint, value, physicsClientId=client)
            position, orientation = p.getLinkState(
                body, 8, computeForwardKinematics=1, physicsClientId=client
            )[4:6]
            tips.append(np.array(position) + Rotation.from_quat(orientation).apply([0, 0, 0.1]))
    finally:
        p.disconnect(client)
    expected = (rows[:, 1:4] - [0, 0, 50]) / 1000.0  # the model's mm, relative to the base, in m
    assert np.max(np.linalg.norm(np.array(tips) - expected, axis=1)) <= 1e-4


def test_the_scenarios_robot_where_it_stands_gives_the_same_joint_trajectory(tmp_path):
    """--robot SCENARIO: the scenario's arm at its base and yaw with its tool; the same as
    naming them by hand (the nut task's Panda at (50, -450, 0) mm facing +y, a 100 mm socket)."""
    pytest.importorskip("pybullet")
    recording = (
        Path(__file__).resolve().parents[2]
        / "src"
        / "bidmp"
        / "data"
        / "recordings"
        / "operator1_nut3.csv"
    )
    assert main(["fit", str(recording), "--units", "mm", "-o", str(tmp_path / "m.npz")]) == 0
    common = ["rollout", str(tmp_path / "m.npz"), "--goal", "150", "0", "0", "--rate", "50"]
    assert (
        main(
            common
            + [
                "-o",
                str(tmp_path / "a.csv"),
                "--robot",
                "nut-unscrewing",
                "--bag",
                str(tmp_path / "a"),
            ]
        )
        == 0
    )
    assert (
        main(
            common
            + [
                "-o",
                str(tmp_path / "b.csv"),
                "--robot",
                "panda",
                "--base",
                "50",
                "-450",
                "0",
                "--yaw",
                "90",
                "--tool-length",
                "0.1",
                "--bag",
                str(tmp_path / "b"),
            ]
        )
        == 0
    )
    points = []
    for name in ("a", "b"):
        with AnyReader([tmp_path / name]) as reader:
            (connection,) = reader.connections
            (message,) = [
                reader.deserialize(raw, connection.msgtype) for _, _, raw in reader.messages()
            ]
        points.append(np.array([point.positions for point in message.points]))
    assert points[0].shape[1] == 7
    np.testing.assert_allclose(points[0], points[1], atol=1e-12)


# -- joint states as drivers publish them -----------------------------------------------------------
BAG_KINDS = (("ros1", 1, "mcap"), ("mcap", 2, "mcap"), ("sqlite3", 2, "sqlite3"))


def joint_state_bag(path: Path, ros: int, storage: str, messages) -> Path:
    """A bag with one ``sensor_msgs/JointState`` topic, ``/joint_states``: ``messages`` are
    (stamp ns, names, positions) each, written as given (no check of their lengths)."""
    store = get_typestore(Stores.ROS1_NOETIC if ros == 1 else Stores.ROS2_HUMBLE)
    types = store.types
    written = [
        (
            ns,
            types["sensor_msgs/msg/JointState"](
                header=_header(types, int(ns), "", ros),
                name=list(names),
                position=np.asarray(positions, dtype=float),
                velocity=np.zeros(0),
                effort=np.zeros(0),
            ),
        )
        for ns, names, positions in messages
    ]
    _write(path, ros, [("/joint_states", "sensor_msgs/msg/JointState", written)], store, storage)
    return path


def _bag_path(tmp_path, label, ros):
    return tmp_path / (f"{label}.bag" if ros == 1 else label)


@pytest.mark.parametrize(("label", "ros", "storage"), BAG_KINDS)
def test_joint_states_in_another_order_per_message_keep_each_joint_its_column(
    tmp_path, capsys, label, ros, storage
):
    """A driver that lists its joints in another order from one message to the next: each
    column still holds its own joint's positions (read by name in every message), in ROS 1, ROS 2
    MCAP and ROS 2 SQLite bags; ``bidmp fit BAG --joints`` learns the joints' own goals."""
    from bidmp.io import read_bag

    rng = np.random.default_rng(7)
    names = ["j0", "j1", "j2"]
    s = np.linspace(0.0, 1.0, N)[:, None]
    q = np.array([0.1, -0.4, 0.9]) + (10 * s**3 - 15 * s**4 + 6 * s**5) * np.array([0.5, -0.3, 0.8])
    stamps = _stamps(rng)
    orders = [np.arange(3)] + [rng.permutation(3) for _ in range(N - 1)]
    assert sum(not np.array_equal(order, np.arange(3)) for order in orders) > N // 2
    messages = [
        (ns, [names[k] for k in order], row[order]) for ns, row, order in zip(stamps, q, orders)
    ]
    bag = joint_state_bag(_bag_path(tmp_path, label, ros), ros, storage, messages)
    recording = read_bag(bag, joints=True)
    assert recording.names == names and recording.kind == "joints"
    np.testing.assert_array_equal(recording.values, q)
    # a chosen order: the columns in it
    chosen = read_bag(bag, joints=["j2", "j0"])
    np.testing.assert_array_equal(chosen.values, q[:, [2, 0]])
    model = _fit(tmp_path, bag, "--joints")
    assert model.names_ == names
    np.testing.assert_allclose(model.goal_, q[-1], atol=1e-3)


@pytest.mark.parametrize(("label", "ros", "storage"), BAG_KINDS)
def test_joint_states_with_nan_short_positions_or_a_name_twice_are_refused_in_one_line(
    tmp_path, capsys, label, ros, storage
):
    """A NaN position (as a CSV's gap is refused), positions fewer than the names, a joint named
    twice: each a one-line error naming the message and the topic (exit 2 from ``bidmp fit``),
    never a traceback or a silently wrong column."""
    from bidmp.io import read_bag

    rng = np.random.default_rng(8)
    names = ["a", "b", "c"]
    stamps = _stamps(rng)[:40]
    q = np.column_stack([np.linspace(0.0, 0.5, 40) * k for k in (1, 2, 3)])

    def messages(number, names_there, positions_there):
        rows = [(ns, names, row) for ns, row in zip(stamps, q)]
        rows[number - 1] = (stamps[number - 1], names_there, positions_there)
        return rows

    cases = (
        ("nan", messages(17, names, [0.1, np.nan, 0.3]), ("NaN in b", "message 17")),
        ("short", messages(5, names, [0.1, 0.2]), ("2 positions for 3 joint names", "message 5")),
        ("twice", messages(9, ["a", "b", "a"], [0.1, 0.2, 0.3]), ("'a' twice", "message 9")),
    )
    for case, rows, expected in cases:
        bag = joint_state_bag(_bag_path(tmp_path, f"{label}_{case}", ros), ros, storage, rows)
        with pytest.raises(ValueError) as raised:
            read_bag(bag, joints=True)
        assert all(text in str(raised.value) for text in expected), str(raised.value)
        assert "/joint_states" in str(raised.value)
        capsys.readouterr()
        assert main(["fit", str(bag), "-o", str(tmp_path / "m.npz"), "--joints"]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and all(text in err[0] for text in expected), err
    with pytest.raises(ValueError, match="named twice"):
        read_bag(bag, joints=["a", "a"])
