"""a robot engineer's own files, as their loggers write them. The same motion logged
by UR's RTDE recorder (space-separated, ``timestamp`` + ``actual_TCP_pose_0..5`` with an axis-angle
rotation), exported from ROS (``header.stamp`` split in sec/nanosec, ``pose.position.x``, a text
``frame_id``; ``rostopic echo -p`` with nanosecond stamps) and written as a plain ``t,x,y,z(,q)``
CSV fits the same model; a file holding several motions is refused with its candidates; the three
silent mistakes (a wrong unit, no time column, a goal in another unit) are each one refusal.

The reference quaternions are built here from the axis and angle by hand (not by the reader's
SciPy call), and the stamps lie on a 1/512 s grid so that seconds, sec + nanosec and the epoch
are exact in every format: the models must then agree to 1e-9."""

import numpy as np
import pytest

import bidmp
from bidmp.cli import main
from bidmp.io import load_model

N = 700


def _motion():
    """A recorded nut approach in metres with a turning tool, on jittered ~200 Hz stamps (epoch s)."""
    y, _ = bidmp.demonstrations.recording("operator1_nut3")
    y = y[:: max(1, len(y) // N)][:N] / 1000.0
    ticks = np.concatenate(
        [[0], np.cumsum(np.random.default_rng(7).integers(2, 4, N - 1))]
    )  # 2-3 ticks of 1/512 s
    t = 1_732_000_000 + ticks / 512.0
    s = (t - t[0]) / (t[-1] - t[0])
    angle = np.pi * 0.9 - 0.8 * s  # about a tilted axis, from 162 to 116 degrees
    axis = np.column_stack([np.ones(N), 0.3 * np.sin(3 * s), 0.2 + 0 * s])
    axis /= np.linalg.norm(axis, axis=1, keepdims=True)
    rotvec = axis * angle[:, None]
    quaternion = np.column_stack(
        [axis * np.sin(angle / 2)[:, None], np.cos(angle / 2)]
    )  # qx, qy, qz, qw by hand
    return t, y, rotvec, quaternion


def _write(path, header, columns, sep=",", units=None, text=None):
    rows = np.column_stack(columns)
    with open(path, "w") as handle:
        if units:
            handle.write(f"# units: {units}\n")
        handle.write(sep.join(header) + "\n")
        for row in rows:
            cells = [repr(float(v)) for v in row]
            if text is not None:
                cells.insert(text[0], text[1])
            handle.write(sep.join(cells) + "\n")
    return path


def _fit(tmp_path, name, source, *options):
    model = tmp_path / f"{name}.npz"
    assert main(["fit", str(source), "-o", str(model), *options]) == 0
    return load_model(model)


def _same(a, b, atol=1e-9):
    if hasattr(a, "position_"):
        for part in ("position_", "orientation_"):
            np.testing.assert_allclose(
                getattr(a, part).weights_, getattr(b, part).weights_, atol=atol, rtol=0
            )
    else:
        np.testing.assert_allclose(a.weights_, b.weights_, atol=atol, rtol=0)
    assert a.units_ == b.units_ == "m" and a.duration_ == pytest.approx(b.duration_, abs=1e-9)


def test_rtde_and_ros_exports_fit_the_model_of_the_plain_csv(tmp_path, capsys):
    t, y, rotvec, q = _motion()
    plain = _write(tmp_path / "plain.csv", ["t", "x", "y", "z"], [t, y], units="m")
    plain_pose = _write(
        tmp_path / "plain_pose.csv",
        ["t", "x", "y", "z", "qx", "qy", "qz", "qw"],
        [t, y, q],
        units="m",
    )
    rtde = _write(
        tmp_path / "rtde.csv",
        [
            "timestamp",
            *(f"actual_TCP_pose_{i}" for i in range(6)),
            *(f"actual_TCP_speed_{i}" for i in range(6)),
        ],
        [t, y, rotvec, np.zeros((N, 6))],
        sep=" ",
    )
    sec = np.floor(t)
    ros2 = _write(
        tmp_path / "ros2.csv",
        [
            "header.stamp.sec",
            "header.stamp.nanosec",
            "header.frame_id",
            *(f"pose.position.{a}" for a in "xyz"),
            *(f"pose.orientation.{a}" for a in "xyzw"),
        ],
        [sec, np.round((t - sec) * 1e9), y, q],
        text=(2, "base_link"),
    )
    reference, reference_pose = (
        _fit(tmp_path, "plain", plain),
        _fit(tmp_path, "plain_pose", plain_pose),
    )
    capsys.readouterr()
    _same(
        _fit(tmp_path, "rtde", rtde), reference_pose
    )  # metres by RTDE's convention, no --units needed
    assert "read UR RTDE actual_TCP_pose_0..5" in capsys.readouterr().out
    _same(_fit(tmp_path, "ros2", ros2), reference_pose)
    _same(
        _fit(tmp_path, "rtde_positions", rtde, "--columns", "t=timestamp,position=actual_TCP_pose"),
        reference,
    )
    _same(_fit(tmp_path, "ros2_positions", ros2, "--columns", "position=pose"), reference)
    # rostopic echo -p: receive time %time and the header stamp, both in integer nanoseconds; the
    # header stamp is the one read. A float64 holds a 19-digit nanosecond count to 256 ns, so the
    # durations agree to 1e-6 s and the weights (up to 3.4) to 1e-5, not 1e-9.
    ns = sec.astype(np.int64) * 1_000_000_000 + np.round((t - sec) * 1e9).astype(np.int64)
    echo = tmp_path / "echo.csv"
    with open(echo, "w") as handle:
        handle.write(
            "%time,field.header.seq,field.header.stamp,field.header.frame_id,"
            + ",".join(f"field.pose.position.{a}" for a in "xyz")
            + ","
            + ",".join(f"field.pose.orientation.{a}" for a in "xyzw")
            + "\n"
        )
        for k in range(N):
            late = ns[k] + 3_000_000 + (k % 5) * 1_000_000  # received 3-7 ms after the stamp
            handle.write(
                f"{late},{k},{ns[k]},base,"
                + ",".join(repr(float(v)) for v in [*y[k], *q[k]])
                + "\n"
            )
    from_echo = _fit(tmp_path, "echo", echo)
    assert from_echo.duration_ == pytest.approx(reference_pose.duration_, abs=1e-6)
    _same(from_echo, reference_pose, atol=1e-5)


def test_a_file_with_several_motions_is_refused_with_its_candidates(tmp_path, capsys):
    t, y, rotvec, _ = _motion()
    header = [
        "timestamp",
        *(f"{kind}_TCP_pose_{i}" for kind in ("actual", "target") for i in range(6)),
        *(f"actual_q_{i}" for i in range(6)),
    ]
    full = _write(
        tmp_path / "rtde_full.csv",
        header,
        [t, y, rotvec, y + 1e-4, rotvec, np.outer(np.linspace(0, 1, N), np.arange(1, 7))],
        sep=" ",
    )
    assert main(["fit", str(full), "-o", str(tmp_path / "m.npz")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "3 motions" in err[0]
    for candidate in ("pose=actual_TCP_pose", "pose=target_TCP_pose", "joints=actual_q"):
        assert candidate in err[0]
    # The user says which: the commanded pose this time (1e-4 m off the measured one).
    commanded = _fit(tmp_path, "commanded", full, "--columns", "pose=target_TCP_pose")
    assert commanded.position_.start_ == pytest.approx(y[0] + 1e-4, abs=1e-3)
    joints = bidmp.io.read_recording(full, columns="joints=actual_q")
    assert (
        joints.kind == "joints"
        and joints.names == [f"actual_q_{i}" for i in range(6)]
        and joints.units == "rad"
    )
    # Two time columns are as ambiguous as two poses.
    two = _write(tmp_path / "two.csv", ["t", "timestamp", "x", "y", "z"], [t, t + 0.5, y])
    with pytest.raises(ValueError, match="2 time columns \\(t, timestamp\\).*columns= t=t"):
        bidmp.io.read_trajectory(two)
    assert bidmp.io.read_trajectory(two, columns="t=timestamp")[1][0] == t[0] + 0.5


def test_the_three_silent_mistakes_are_each_one_refusal(tmp_path, capsys):
    t, y, _, _ = _motion()

    def refused(argv, *expected):
        capsys.readouterr()
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1, err
        for text in expected:
            assert text in err[0], err[0]

    # 1. Metre numbers declared as mm (peaking at 0.15 "mm/s"), and mm numbers declared as m.
    as_mm = _write(tmp_path / "as_mm.csv", ["t", "x", "y", "z"], [t, y], units="mm")
    refused(
        ["fit", str(as_mm), "-o", str(tmp_path / "a.npz")],
        "slower than any robot moves",
        "is it in m?",
    )
    as_m = _write(tmp_path / "as_m.csv", ["t", "x", "y", "z"], [t, y * 1000.0], units="m")
    refused(
        ["fit", str(as_m), "-o", str(tmp_path / "b.npz"), "--raw"],
        "faster than any robot moves",
        "is it in mm?",
    )
    # 2. A misspelt time column: no longer 1 s in all; --no-time says it on purpose.
    misspelt = _write(tmp_path / "misspelt.csv", ["tme", "x", "y", "z"], [t, y], units="m")
    refused(
        ["fit", str(misspelt), "-o", str(tmp_path / "c.npz")],
        "has no time column",
        "other columns: tme",
        "--no-time",
    )
    plain = _write(tmp_path / "plain.csv", ["t", "x", "y", "z"], [t, y], units="m")
    _same(
        _fit(tmp_path, "named", misspelt, "--columns", "t=tme,x=x,y=y,z=z"),
        _fit(tmp_path, "plain", plain),
    )
    paper = _fit(tmp_path, "paper", misspelt, "--no-time")
    assert paper.duration_ == pytest.approx(
        (paper.n_steps_ - 1) / paper.n_steps_
    )  # the paper's 1 s convention
    # 3. A goal in mm for a metre model: refused, nothing written.
    refused(
        [
            "rollout",
            str(tmp_path / "named.npz"),
            "--goal",
            "150",
            "20",
            "0",
            "-o",
            str(tmp_path / "g.csv"),
        ],
        "beyond any robot's reach",
        "is it in cm or mm?",
    )
    assert not (tmp_path / "g.csv").exists()
    # ... and a goal within reach that the motion could only reach at 10 m/s or more: refused too.
    refused(
        [
            "rollout",
            str(tmp_path / "named.npz"),
            "--goal",
            "4",
            "0",
            "0",
            "--duration",
            "0.2",
            "-o",
            str(tmp_path / "g.csv"),
        ],
        "the rolled-out motion peaks at",
        "faster than any robot moves",
    )
    assert not (tmp_path / "g.csv").exists()


def test_joint_names_stay_on_the_model_and_in_every_file(tmp_path, capsys):
    names = [
        "shoulder_pan_joint",
        "shoulder_lift_joint",
        "elbow_joint",
        "wrist_1_joint",
        "wrist_2_joint",
        "wrist_3_joint",
    ]
    s = np.linspace(0.0, 1.0, 400)
    q = np.outer(10 * s**3 - 15 * s**4 + 6 * s**5, [0.4, -0.3, 0.5, 0.2, -0.6, 0.9]) + [
        0.0,
        -1.57,
        1.2,
        -1.2,
        -1.57,
        0.0,
    ]
    recording = _write(tmp_path / "j.csv", ["t", *names], [np.linspace(0, 4, 400), q])
    model = _fit(tmp_path, "j", recording)
    assert model.names_ == names and model.units_ == "rad"
    assert "joints shoulder_pan_joint, shoulder_lift_joint" in capsys.readouterr().out
    assert (
        main(["rollout", str(tmp_path / "j.npz"), "-o", str(tmp_path / "r.csv"), "--rate", "100"])
        == 0
    )
    header = (tmp_path / "r.csv").read_text().splitlines()[1].split(",")
    assert header == ["t", *names, *(f"v{n}" for n in names), *(f"a{n}" for n in names)]
    # The rollout reads back as the same joints (its velocity columns are not taken for joints).
    again = bidmp.io.read_recording(tmp_path / "r.csv")
    assert again.kind == "joints" and again.names == names and again.ignored == ()
    # The same for the library's own trajectory.
    trajectory = bidmp.DMP().fit(q, np.linspace(0, 4, 400), units="rad", names=names).trajectory()
    assert trajectory.names == tuple(names) and trajectory.columns()[0][1:7] == names
    with pytest.raises(ValueError, match="names must name the 6 dimension"):
        bidmp.DMP().fit(q, names=names[:5])
    with pytest.raises(ValueError, match="two dimensions have the same name"):
        bidmp.DMP().fit(q, names=[names[0]] * 6)


def test_a_position_model_keeps_the_orientation_its_demonstration_held(tmp_path, capsys):
    """positions picked from an RTDE pose (the tool pointing down, 0.06 deg of sensor
    noise) keep that orientation; the bag a rollout writes carries it in every PoseStamped (the
    closed form of the axis-angle, here by hand). A demonstration that turns the tool is told it
    loses the turn, and its rollout is a PointStamped stream: no orientation is made up."""
    pytest.importorskip("rosbags")
    from rosbags.highlevel import AnyReader

    t, y, rotvec, _ = _motion()
    angle = np.pi * 0.999
    noisy = np.array([angle, 0.0, 0.0]) + np.random.default_rng(5).normal(0.0, 1e-3, (N, 3))
    held = _write(
        tmp_path / "held.csv",
        ["timestamp", *(f"actual_TCP_pose_{i}" for i in range(6))],
        [t, y, noisy],
        sep=" ",
    )
    model = _fit(tmp_path, "held", held, "--columns", "t=timestamp,position=actual_TCP_pose")
    assert "orientation held within" in capsys.readouterr().out
    expected = np.array(
        [np.sin(angle / 2), 0.0, 0.0, np.cos(angle / 2)]
    )  # qx, qy, qz, qw of a turn about x
    assert (
        min(
            np.linalg.norm(model.held_orientation_ - expected),
            np.linalg.norm(model.held_orientation_ + expected),
        )
        < 2e-3
    )
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "held.npz"),
                "-o",
                str(tmp_path / "r.csv"),
                "--rate",
                "50",
                "--bag",
                str(tmp_path / "held_bag"),
            ]
        )
        == 0
    )
    with AnyReader([tmp_path / "held_bag"]) as reader:
        (connection,) = reader.connections
        read = [reader.deserialize(raw, connection.msgtype) for _, _, raw in reader.messages()]
    assert connection.msgtype == "geometry_msgs/msg/PoseStamped"
    quaternions = np.array(
        [
            [m.pose.orientation.x, m.pose.orientation.y, m.pose.orientation.z, m.pose.orientation.w]
            for m in read
        ]
    )
    np.testing.assert_allclose(
        quaternions, np.broadcast_to(model.held_orientation_, quaternions.shape), atol=0
    )
    # The turning tool of _motion(): the turn is dropped, and said to be.
    turning = _write(
        tmp_path / "turning.csv",
        ["timestamp", *(f"actual_TCP_pose_{i}" for i in range(6))],
        [t, y, rotvec],
        sep=" ",
    )
    capsys.readouterr()
    plain = _fit(tmp_path, "turning", turning, "--columns", "t=timestamp,position=actual_TCP_pose")
    assert (
        "which a position model drops" in capsys.readouterr().out
        and plain.held_orientation_ is None
    )
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "turning.npz"),
                "-o",
                str(tmp_path / "r2.csv"),
                "--rate",
                "50",
                "--bag",
                str(tmp_path / "point_bag"),
            ]
        )
        == 0
    )
    assert (
        "PointStamped: the model knows no orientation and none is made up"
        in capsys.readouterr().out
    )


def test_joints_chosen_by_name_in_the_order_given(tmp_path):
    names = ["panda_joint1", "panda_joint2", "panda_finger_joint1", "panda_joint3"]
    s = np.linspace(0.0, 1.0, 200)
    values = np.column_stack([s * 0.5, -s * 0.3, 0.04 + 0 * s, s * 0.2])
    path = _write(tmp_path / "js.csv", ["stamp", *names], [np.linspace(0.0, 2.0, 200), values])
    picked = bidmp.io.read_recording(path, columns="joints=panda_joint3|panda_joint1")
    assert picked.names == ["panda_joint3", "panda_joint1"] and picked.ignored == (
        "panda_joint2",
        "panda_finger_joint1",
    )
    np.testing.assert_array_equal(picked.values, values[:, [3, 0]])
    with pytest.raises(ValueError, match="no column 'panda_joint9' for joints"):
        bidmp.io.read_recording(path, columns="joints=panda_joint9|panda_joint1")


def test_rotation_vectors_in_degrees_or_rpy_are_refused_not_read_as_radians(tmp_path, capsys):
    """A TMflow-style export's roll/pitch/yaw in degrees put in rx, ry, rz was read as radians (the
    learned start 177.5 deg off, the tool up). A rotation vector longer than π is no axis-angle in
    radians (its angle lies in [0, π]): refused naming the row, for degrees and for roll/pitch/yaw
    in radians alike; the same motion in radians reads, each quaternion SciPy's
    from_rotvec of its row (the independent reference)."""
    from scipy.spatial.transform import Rotation

    from bidmp.io import read_poses

    n = 120
    s = np.linspace(0.0, 1.0, n)
    positions = np.column_stack([400.0 * s, 50.0 * s**2, 300.0 - 100.0 * s])
    turns = Rotation.from_euler(
        "xyz", np.column_stack([np.full(n, 177.5), 20 * s, 90 * s]), degrees=True
    )
    radians = turns.as_rotvec()
    header = "t,x,y,z,rx,ry,rz"
    good, bad = tmp_path / "radians.csv", tmp_path / "degrees.csv"
    t = np.linspace(0.0, 2.4, n)[:, None]
    np.savetxt(good, np.hstack([t, positions, radians]), delimiter=",", header=header, comments="")
    rpy_degrees = turns.as_euler("xyz", degrees=True)
    np.savetxt(
        bad, np.hstack([t, positions, rpy_degrees]), delimiter=",", header=header, comments=""
    )
    poses, _ = read_poses(good)
    expected = Rotation.from_rotvec(radians).as_quat()
    same_sign = np.sign(np.sum(poses[:, 3:] * expected, axis=1))[:, None]
    np.testing.assert_allclose(poses[:, 3:] * same_sign, expected, atol=1e-12)
    with pytest.raises(ValueError, match=r"at most π\) reach length 177.5 at data row 1: degrees"):
        read_poses(bad)
    # roll/pitch/yaw in radians put there: the tool down (roll 177.5 deg) and turning about z
    # makes vectors longer than π from the first row that turns by more than 0.05 rad
    rpy_radians = turns.as_euler("xyz")
    np.savetxt(
        bad, np.hstack([t, positions, rpy_radians]), delimiter=",", header=header, comments=""
    )
    first = int(np.argmax(np.linalg.norm(rpy_radians, axis=1) > np.pi + 1e-3)) + 1
    with pytest.raises(ValueError, match=rf"at data row {first}: degrees, or roll/pitch/yaw"):
        read_poses(bad)
    assert main(["fit", str(bad), "-o", str(tmp_path / "m.npz")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "rotation vector in radians" in err[0], err


def test_a_gap_is_refused_at_the_file_line_a_user_opens(tmp_path, capsys):
    """A NaN was reported at "row 1000" of a file whose line 1002 holds it (a comment and a header
    before the data), with no advice. The line is found here by reading the file's text."""
    t = np.linspace(0.0, 2.0, 2000)
    y = np.column_stack([t, np.sin(t), np.cos(t)])
    y[999, 1] = np.nan
    path = tmp_path / "gap.csv"
    with open(path, "w") as handle:
        handle.write("# units: mm\nt,x,y,z\n")
        np.savetxt(handle, np.column_stack([t, y]), delimiter=",")
    line = next(n for n, text in enumerate(path.read_text().splitlines(), 1) if "nan" in text)
    assert main(["fit", str(path), "-o", str(tmp_path / "m.npz")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert f"line {line}: contains NaN in column y (data row 1000" in err[0], err
    assert "fill the gaps" in err[0]
