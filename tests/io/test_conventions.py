"""Loggers' conventions the project had not seen: each file read right, or refused in one line
that says what to do — never read wrong. The files are written here the way their loggers write
them (a TMflow-style export: ``;`` separators, decimal commas, time in ms, positions in mm,
roll/pitch/yaw in degrees; a ``rostopic echo -p /joint_states`` export of a Panda with
franka_ros's joint names; a KUKA-style file with A, B, C angles and a row with a gap), and every
value read is checked against an independent computation: SciPy's ``from_euler`` of the row, the
numbers the file was written from."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bidmp
from bidmp.cli import main
from bidmp.io import read_poses, read_recording

N = 240


def _motion(n: int = N):
    s = np.linspace(0.0, 1.0, n)
    positions = np.column_stack([417.5 - 80.0 * s, -122.3 + 60.0 * s**2, 300.0 - 120.0 * s])
    rpy = np.column_stack([np.full(n, 179.0) - 3.0 * s, 2.0 + 10.0 * s, -90.0 + 75.0 * s])
    return s, positions, rpy


def _comma(value: float) -> str:
    return f"{value:.4f}".replace(".", ",")


def tmflow_export(path, n: int = N, header=None):
    """A TMflow-style export: ``;``, decimal commas, ``Time(ms)``, ``X(mm)``, ``RX(deg)`` (RPY)."""
    s, positions, rpy = _motion(n)
    ms = 8.0 * np.arange(n)  # 125 Hz
    lines = [header or "Time(ms);X(mm);Y(mm);Z(mm);RX(deg);RY(deg);RZ(deg)"]
    for row in range(n):
        lines.append(
            ";".join([_comma(ms[row]), *map(_comma, positions[row]), *map(_comma, rpy[row])])
        )
    path.write_text("\n".join(lines) + "\n")
    return ms / 1e3, positions, rpy


def test_a_tmflow_export_is_refused_by_its_names_and_read_right_when_declared(tmp_path, capsys):
    path = tmp_path / "tm.csv"
    seconds, positions, rpy = tmflow_export(path)
    # by the names: RX(deg) cannot be a rotation vector: the fix names the declaration
    with pytest.raises(ValueError, match=r"name deg: a rotation vector is an axis times an angle"):
        read_poses(path)
    assert main(["fit", str(path), "-o", str(tmp_path / "m.npz")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "euler=xyz,angles=deg" in err[0], err
    # declared: Euler xyz (the unit from the names), time in ms and mm from the names
    declared = "t=Time,x=X,y=Y,z=Z,e1=RX,e2=RY,e3=RZ,euler=xyz"
    recording = read_recording(path, columns=declared)
    assert recording.kind == "pose" and recording.units == "mm"
    np.testing.assert_allclose(recording.t, seconds, rtol=0, atol=1e-12)
    np.testing.assert_allclose(recording.values[:, :3], np.round(positions, 4), atol=1e-9)
    expected = Rotation.from_euler("xyz", np.round(rpy, 4), degrees=True).as_quat()
    sign = np.sign(np.sum(recording.values[:, 3:] * expected, axis=1))[:, None]
    np.testing.assert_allclose(recording.values[:, 3:] * sign, expected, atol=1e-12)
    # the start's tool axis points down (roll 179 deg), not up as when the degrees were radians
    down = Rotation.from_quat(recording.values[0, 3:]).apply([0.0, 0.0, 1.0])
    assert down[2] < -0.99
    # the command line fits it, with the declaration
    out = tmp_path / "m.npz"
    assert main(["fit", str(path), "--columns", declared, "-o", str(out)]) == 0, (
        capsys.readouterr().err
    )


def test_a_declaration_that_contradicts_the_names_is_refused(tmp_path):
    path = tmp_path / "tm.csv"
    tmflow_export(path)
    with pytest.raises(ValueError, match="angles=rad but the Euler-angle columns name deg"):
        read_recording(path, columns="x=X,y=Y,z=Z,e1=RX,e2=RY,e3=RZ,euler=xyz,angles=rad")
    with pytest.raises(ValueError, match=r"time=s but the column 'Time\(ms\)' names ms"):
        read_recording(path, columns="time=s,x=X,y=Y,z=Z,e1=RX,e2=RY,e3=RZ,euler=xyz")
    with pytest.raises(ValueError, match="need their axis sequence, e.g. euler=xyz"):
        read_recording(path, columns="x=X,y=Y,z=Z,e1=RX,e2=RY,e3=RZ")
    with pytest.raises(ValueError, match="euler=xzz is no axis sequence"):
        read_recording(path, columns="x=X,y=Y,z=Z,e1=RX,e2=RY,e3=RZ,euler=xzz")
    # decimal commas cannot be told from ',' separators
    plain = tmp_path / "plain.csv"
    plain.write_text("t,x,y,z\n0,1,2,3\n0.1,1,2,3\n")
    with pytest.raises(ValueError, match="decimal=comma, but the columns are separated by commas"):
        read_recording(plain, columns="decimal=comma")


def test_roll_pitch_yaw_by_name_are_declared_never_guessed(tmp_path):
    """``x,y,z,roll,pitch,yaw`` or KUKA's ``X,Y,Z,A,B,C``: the names give no sequence."""
    for names, sequence in (("roll,pitch,yaw", "xyz"), ("A,B,C", "ZYX")):
        path = tmp_path / "rpy.csv"
        rows = "".join(f"{0.1 * k:.1f},{k},2,3,10,20,30\n" for k in range(5))
        path.write_text(f"t,x,y,z,{names}\n{rows}")
        with pytest.raises(
            ValueError, match=rf"are Euler angles.*euler={sequence},angles=deg\|rad"
        ):
            read_recording(path)
        first, second, third = names.split(",")
        read = read_recording(
            path,
            columns=f"x=x,y=y,z=z,e1={first},e2={second},e3={third},euler={sequence},angles=deg",
        )
        expected = Rotation.from_euler(sequence, [10, 20, 30], degrees=True).as_quat()
        assert abs(abs(float(read.values[0, 3:] @ expected)) - 1.0) < 1e-12


def franka_joint_states(path, n: int = 1500, names=None):
    """``rostopic echo -p /joint_states`` of a Panda under franka_ros: ``%time`` and
    ``field.header.stamp`` in ns, a ``frame_id``, ``field.name0..8`` (text),
    ``field.position0..8``, velocities and efforts."""
    names = names or [f"panda_joint{i}" for i in range(1, 8)] + [
        "panda_finger_joint1",
        "panda_finger_joint2",
    ]
    k = len(names)
    t = 1_700_000_000_000_000_000 + 1_000_000 * np.arange(n)  # 1 kHz, ns
    ramp = 0.5 - 0.5 * np.cos(np.linspace(0.0, np.pi, n))  # a rest-to-rest move over 1.5 s
    q = 0.6 * ramp[:, None] * np.linspace(1.0, -1.0, k)[None] + np.linspace(-1.0, 1.0, k)[None]
    header = ["%time", "field.header.seq", "field.header.stamp", "field.header.frame_id"]
    header += [f"field.name{i}" for i in range(k)] + [f"field.position{i}" for i in range(k)]
    header += [f"field.velocity{i}" for i in range(k)] + [f"field.effort{i}" for i in range(k)]
    lines = [",".join(header)]
    for row in range(n):
        cells = [str(t[row] + 3000), str(row), str(t[row]), ""]
        cells += names + [repr(float(v)) for v in q[row]]
        cells += ["0.0"] * k + ["0.1"] * k
        lines.append(",".join(cells))
    path.write_text("\n".join(lines) + "\n")
    return (t - t[0]) / 1e9, q, names


def test_a_franka_ros_joint_state_export_keeps_its_joint_names(tmp_path, capsys):
    """The names were lost (``field.position0..`` went into the FollowJointTrajectory goal)."""
    path = tmp_path / "joint_states.csv"
    seconds, q, names = franka_joint_states(path)
    for columns in (None, "joints=position"):
        recording = read_recording(path, columns=columns)
        assert recording.kind == "joints" and recording.names == names
        np.testing.assert_array_equal(recording.values, q)
        # (epoch nanoseconds as a float64: 256 ns apart at this size)
        np.testing.assert_allclose(recording.t - recording.t[0], seconds, rtol=0, atol=1e-6)
    out = tmp_path / "j.npz"
    assert main(["fit", str(path), "-o", str(out)]) == 0, capsys.readouterr().err
    model = bidmp.io.load_model(out)
    assert list(model.names_) == names
    # names that change order mid-file: the positions would change meaning
    swapped = tmp_path / "swapped.csv"
    franka_joint_states(swapped)
    lines = swapped.read_text().splitlines()
    lines[50] = lines[50].replace("panda_joint1,panda_joint2", "panda_joint2,panda_joint1")
    swapped.write_text("\n".join(lines) + "\n")
    with pytest.raises(ValueError, match="the joint names change at data row 50"):
        read_recording(swapped)


def kuka_file(path, n: int = 300, gap_row: int = 150):
    """A KUKA-style file: ``;``, decimal commas, ``Time``, X, Y, Z (mm), A, B, C (deg, ZYX)
    and one row whose values the logger lost (``NaN``)."""
    s, positions, rpy = _motion(n)
    abc = rpy[:, ::-1]  # A about z, B about y, C about x
    lines = ["# KRC export", "Time;X;Y;Z;A;B;C"]
    for row in range(n):
        values = [0.004 * row, *positions[row], *abc[row]]
        cells = [_comma(v) for v in values]
        if row == gap_row:
            cells[2] = "NaN"
        lines.append(";".join(cells))
    path.write_text("\n".join(lines) + "\n")
    return positions, abc


def test_a_kuka_style_file_with_a_gap_is_refused_at_its_line_and_read_when_dropped(
    tmp_path, capsys
):
    path = tmp_path / "kuka.csv"
    positions, abc = kuka_file(path)
    declared = "x=X,y=Y,z=Z,e1=A,e2=B,e3=C,euler=ZYX,angles=deg"
    line = next(n for n, text in enumerate(path.read_text().splitlines(), 1) if "NaN" in text)
    with pytest.raises(ValueError, match=rf"line {line}: contains NaN in column Y.*gaps=drop"):
        read_recording(path, columns=declared)
    assert main(["fit", str(path), "--columns", declared, "-o", str(tmp_path / "m")]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "gaps=drop" in err[0], err
    read = read_recording(path, columns=declared + ",gaps=drop")
    keep = np.arange(len(positions)) != 150
    assert read.values.shape[0] == keep.sum()
    np.testing.assert_allclose(read.values[:, :3], np.round(positions[keep], 4), atol=1e-9)
    expected = Rotation.from_euler("ZYX", np.round(abc[keep], 4), degrees=True).as_quat()
    sign = np.sign(np.sum(read.values[:, 3:] * expected, axis=1))[:, None]
    np.testing.assert_allclose(read.values[:, 3:] * sign, expected, atol=1e-12)


@pytest.mark.parametrize(
    ("name", "divisor"),
    [("Time(ms)", 1e3), ("time_ms", 1e3), ("t [us]", 1e6), ("timestamp_ns", 1e9), ("t", 1.0)],
)
def test_time_units_from_the_columns_name(tmp_path, name, divisor):
    path = tmp_path / "t.csv"
    seconds = 0.002 * np.arange(400)
    y = np.column_stack([seconds * divisor, np.sin(seconds), np.cos(seconds), seconds])
    np.savetxt(path, y, delimiter=",", header=f"{name},x,y,z", comments="", fmt="%.17g")
    np.testing.assert_allclose(read_recording(path).t, seconds, rtol=1e-12, atol=1e-15)


def test_milliseconds_read_as_seconds_are_refused_with_the_declaration(tmp_path, capsys):
    path = tmp_path / "ms.csv"
    ms = 2.0 * np.arange(400)  # 500 Hz in ms, which read as seconds is 0.5 Hz
    np.savetxt(
        path, np.column_stack([ms, np.sin(ms / 1e3), ms / 1e3, ms / 1e3]), delimiter=",",
        header="t,x,y,z", comments="",
    )  # fmt: skip
    with pytest.raises(
        ValueError, match=r"gives 0.5 Hz; if it holds ms, declare it: --columns time=ms"
    ):
        read_recording(path)
    np.testing.assert_allclose(read_recording(path, columns="time=ms").t, ms / 1e3, atol=1e-15)
    assert main(["fit", str(path), "-o", str(tmp_path / "m.npz")]) == 2
    assert "time=ms" in capsys.readouterr().err


def test_orientations_that_jump_are_refused(tmp_path):
    """A tool wobbling within 5 deg, logged in degrees at 125 Hz and declared in radians: every
    angle is within 2π, so only the rate tells: 0.3 deg a sample read as radians is a turn of
    about 37 rad/s, which no hand-guided tool makes. Refused naming the rows; in degrees it reads
    (each quaternion SciPy's from_euler of its row)."""
    n = 200
    t = 0.008 * np.arange(n)
    wobble = np.column_stack([5.0 * np.sin(2 * np.pi * t), 3.0 * np.cos(2 * np.pi * t), 0 * t])
    path = tmp_path / "wobble.csv"
    positions = np.column_stack([100 * t, 50 * t, 300 - 20 * t])
    np.savetxt(path, np.hstack([t[:, None], positions, wobble]), delimiter=",",
               header="t,x,y,z,a,b,c", comments="")  # fmt: skip
    declared = "x=x,y=y,z=z,e1=a,e2=b,e3=c,euler=xyz,angles="
    with pytest.raises(
        ValueError, match=r"jumps \d+.\d deg between data rows 1 and 2 \(8 ms apart\)"
    ):
        read_recording(path, columns=declared + "rad")
    read = read_recording(path, columns=declared + "deg")
    expected = Rotation.from_euler("xyz", wobble, degrees=True).as_quat()
    sign = np.sign(np.sum(read.values[:, 3:] * expected, axis=1))[:, None]
    np.testing.assert_allclose(read.values[:, 3:] * sign, expected, atol=1e-12)


def test_joints_in_degrees_are_read_in_radians(tmp_path):
    path = tmp_path / "deg.csv"
    t = 0.01 * np.arange(200)
    degrees = np.column_stack([30 * np.sin(t), 10 * t, -45 + 0 * t])
    np.savetxt(path, np.column_stack([t, degrees]), delimiter=",",
               header="t,j1 (deg),j2 (deg),j3 (deg)", comments="")  # fmt: skip
    read = read_recording(path)
    assert (
        read.kind == "joints"
        and read.units == "rad"
        and read.names == ["j1 (deg)", "j2 (deg)", "j3 (deg)"]
    )
    np.testing.assert_allclose(read.values, np.radians(degrees), rtol=1e-15)


def test_a_zero_quaternion_row_is_left_to_the_pose_checks_by_the_jump_check(tmp_path):
    """Found by make fuzz: the jump check divided by a zero quaternion's norm (a NumPy warning
    leaked). A pose file is read as written (its quaternions are checked where a model fits them,
    as read_poses says): read without a warning, refused by the fit naming the zero quaternion."""
    import warnings

    from bidmp import CartesianDMP

    path = tmp_path / "zero.csv"
    path.write_text("t,x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,0,0\n0.1,1,0,0,0,0,0,1\n0.2,2,0,0,0,0,0,1\n")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        poses, t = read_poses(path)
    with pytest.raises(ValueError, match="zero quaternion"):
        CartesianDMP().fit(poses, t)
