"""Trajectory files and model files: round trips, atomic writes and every kind of bad file."""

import json
import zipfile
from pathlib import Path

import numpy as np
import pytest
from conftest import curved_demo

import bidmp
from bidmp import DMP, ModelFileError
from bidmp.io import FORMAT_VERSION, load_trajectory, save_trajectory


@pytest.fixture
def fitted():
    return DMP(protocol="paper", alpha=40.0, K="pastor", n_kernels=30).fit(curved_demo(250, 3))


# --- trajectories ------------------------------------------------------------------------------
def write(path, text):
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    "text, expected",
    [
        ("x,y\n0,0\n1,2\n2,3\n", [[0, 0], [1, 2], [2, 3]]),
        (
            "0,0,0\n1,2,3\n2,3,5\n",
            [[0, 0, 0], [1, 2, 3], [2, 3, 5]],
        ),  # header-less 3 columns: x,y,z
        ("t,x,y\n0,0,0\n0.5,1,2\n1,2,3\n", [[0, 0], [1, 2], [2, 3]]),
        ("time,x,y,z\n0,0,0,0\n1,1,2,3\n2,2,3,5\n", [[0, 0, 0], [1, 2, 3], [2, 3, 5]]),
        ("0,0,0,0\n1,1,2,3\n2,2,3,5\n", [[0, 0, 0], [1, 2, 3], [2, 3, 5]]),  # 4 columns: t,x,y,z
        ("# recorded by hand\nX;Y\n0;0\n\n1;2\n2;3\n", [[0, 0], [1, 2], [2, 3]]),
    ],
)
def test_csv_variants(tmp_path, text, expected):
    np.testing.assert_array_equal(load_trajectory(write(tmp_path / "demo.csv", text)), expected)


def test_nonuniform_time_is_resampled_to_uniform_steps(tmp_path):
    times = np.array([0.0, 0.1, 0.5, 0.6, 1.0])
    positions = np.column_stack([times * 2.0, times**2])
    save_trajectory(positions, tmp_path / "demo.csv", times=times)
    y = load_trajectory(tmp_path / "demo.csv")
    grid = np.linspace(0.0, 1.0, 5)
    np.testing.assert_allclose(y[:, 0], 2.0 * grid)  # linear in time: exact after resampling
    np.testing.assert_allclose(y[:, 1], np.interp(grid, times, times**2))


@pytest.mark.parametrize("suffix", [".csv", ".npy"])
def test_trajectory_round_trip_is_exact(tmp_path, suffix):
    y = curved_demo(50, 3)
    path = save_trajectory(y, tmp_path / f"traj{suffix}")
    np.testing.assert_array_equal(load_trajectory(path), y)


def test_a_timed_npy_reads_back_its_stamps_and_refuses_nan_like_a_csv(tmp_path):
    """save_trajectory's timed .npy (records t, x, y, z) reads back exactly (it was refused as
    "not real numbers"), and a NaN in its stamps or positions is refused as a CSV's gap is."""
    from bidmp.io import read_trajectory

    y, t = curved_demo(60, 3), np.cumsum(np.random.default_rng(3).uniform(0.003, 0.005, 60))
    path = save_trajectory(y, tmp_path / "timed.npy", times=t)
    read, stamps = read_trajectory(path)
    np.testing.assert_array_equal(read, y)
    np.testing.assert_array_equal(stamps, t)
    for field, match in (("t", "time column contains NaN"), ("y", "contains NaN")):
        records = np.load(path)
        records[field][17] = np.nan
        np.save(tmp_path / f"nan_{field}.npy", records)
        with pytest.raises(ValueError, match=match):
            read_trajectory(tmp_path / f"nan_{field}.npy")


@pytest.mark.parametrize(
    "header, match",
    [
        ("t,x,y,z,x", "'x' 2 times \\(columns 2, 5\\)"),
        ("t,X(mm),y,z,x", "2 times"),  # one column read as x by its unit-free name, one by its own
        ("t,t,x,y", "2 time columns"),  # (refused before: two candidates)
        ("t,j1,j2,j1", "'j1' 2 times"),
    ],
)
def test_a_column_read_whose_name_repeats_is_refused(tmp_path, header, match):
    """Two columns of one name: which holds the value is unknown (the first was read, the other
    dropped as an ignored column): refused, naming it."""
    rows = "\n".join(",".join(str(v * k) for v in range(header.count(",") + 1)) for k in range(5))
    with pytest.raises(ValueError, match=match):
        bidmp.io.read_recording(write(tmp_path / "twice.csv", f"{header}\n{rows}\n"))


def test_a_joint_recording_declaring_a_length_is_refused_and_a_still_one_reads(tmp_path):
    """'# units: mm' on t,<joint names>: joints are angles, so the line or the reading is wrong:
    refused, naming both ways out; an arm that holds still is a joint record (verify judges
    such streams), while a fit of it is still refused as no motion."""
    from bidmp.cli import main

    rows = "\n".join(f"{0.01 * k},{0.1 * k},{-0.05 * k}" for k in range(50))
    with pytest.raises(ValueError, match="'# units: mm', a length, but its columns read as joints"):
        bidmp.io.read_recording(write(tmp_path / "mm.csv", f"# units: mm\nt,j1,j2\n{rows}\n"))
    assert (
        bidmp.io.read_recording(
            write(tmp_path / "rad.csv", f"# units: rad\nt,j1,j2\n{rows}\n")
        ).units
        == "rad"
    )
    still = "\n".join(f"{0.01 * k},0.3,-0.2" for k in range(50))
    recording = bidmp.io.read_recording(write(tmp_path / "still.csv", f"t,j1,j2\n{still}\n"))
    np.testing.assert_array_equal(recording.values, np.tile([0.3, -0.2], (50, 1)))
    assert main(["fit", str(tmp_path / "still.csv"), "-o", str(tmp_path / "m.npz")]) == 2


@pytest.mark.parametrize(
    "name, text, match",
    [
        ("empty.csv", "", "empty"),
        ("header_only.csv", "x,y\n", "no data rows"),
        ("words.csv", "x,y\n0,0\n1,abc\n2,2\n", "line 3, column 2: 'abc' is not a number"),
        ("ragged.csv", "x,y\n0,0\n1\n2,2\n", "line 3: expected 2 columns"),
        ("nan.csv", "x,y\n0,0\nnan,1\n2,2\n", "NaN"),
        ("short.csv", "x,y\n0,0\n1,1\n", "at least 3 points"),
        ("same.csv", "x,y\n1,1\n1,1\n1,1\n", "identical"),
        ("header.csv", "a,b\n0,0\n1,1\n2,2\n", "header a,b names no motion.*--columns"),
        ("onecol.csv", "1\n2\n3\n", "expected 2-4 columns"),
        (
            "time.csv",
            "t,x,y\n0,0,0\n1,1,1\n0.5,2,2\n",
            "must increase strictly: timestamp going back at sample 2",
        ),
        ("demo.json", "{}", "unsupported file type .json"),
    ],
)
def test_bad_trajectory_files(tmp_path, name, text, match):
    with pytest.raises(ValueError, match=match):
        load_trajectory(write(tmp_path / name, text))


# --- recordings as loggers write them -------------------------------------------
def logger_file(tmp_path, header, rows, name="log.csv"):
    path = tmp_path / name
    path.write_text(
        header + "\n" + "\n".join(",".join(repr(float(v)) for v in row) for row in rows) + "\n"
    )
    return path


def test_a_repeated_timestamp_is_dropped_with_a_warning(tmp_path, caplog):
    """before the fix, one repeated stamp refused the whole recording."""
    y, t = bidmp.demonstrations.recording("operator1_nut3")
    t = t.copy()
    t[100] = t[99]  # the logger wrote one stamp twice
    path = logger_file(tmp_path, "t,x,y,z", np.column_stack([t, y]))
    with caplog.at_level("WARNING"):
        positions, stamps = bidmp.io.read_trajectory(path)
    assert len(positions) == len(y) - 1 and np.all(np.diff(stamps) > 0)
    np.testing.assert_array_equal(positions[:100], y[:100])
    assert (
        "dropped 1 sample(s) whose timestamp repeats the one before (the first at sample 100"
        in caplog.text
    )
    prepared, _ = bidmp.prepare(y, t)  # prepare() and fit() take such stamps too
    assert bidmp.DMP().fit(y, t).n_steps_ == len(y) - 1 and prepared.t[0] == 0.0


def test_a_stamp_going_back_is_refused_with_values_that_can_be_told_apart():
    """before the fix, the message printed 1.7330868e+09 twice."""
    t = 1733086800.0 + np.arange(10) * 0.004
    t[5] = t[4] - 0.001
    with pytest.raises(
        ValueError,
        match=r"going back at sample 5: 1733086800\.015 s after 1733086800\.016 s \(-0\.9999 ms",
    ):
        bidmp.primitives.check_timestamps(t, 10)


def test_logger_headers_extra_columns_and_a_column_mapping(tmp_path, caplog):
    y, t = bidmp.demonstrations.recording("operator2_nut5")
    force = np.sin(np.arange(len(t)))
    plain = logger_file(
        tmp_path,
        "timestamp,x,y,z,force,gripper",
        np.column_stack([t, y, force, force > 0]),
        "a.csv",
    )
    with caplog.at_level("WARNING"):
        positions, stamps = bidmp.io.read_trajectory(plain)
    np.testing.assert_array_equal(positions, y)
    np.testing.assert_array_equal(stamps, t)
    assert "ignored 2 column(s) that are not time or the motion read: force, gripper" in caplog.text
    named = logger_file(
        tmp_path,
        "stamp,ee_z,force,ee_x,ee_y",
        np.column_stack([t, y[:, 2], force, y[:, 0], y[:, 1]]),
        "b.csv",
    )
    positions, stamps = bidmp.io.read_trajectory(named, columns="t=stamp,x=ee_x,y=ee_y,z=ee_z")
    np.testing.assert_array_equal(positions, y)
    np.testing.assert_array_equal(stamps, t)
    with pytest.raises(
        ValueError, match="no column 'ee_q' for z .*the header has stamp,ee_z,force,ee_x,ee_y"
    ):
        bidmp.io.read_trajectory(named, columns="t=stamp,x=ee_x,y=ee_y,z=ee_q")
    with pytest.raises(ValueError, match="unknown role 'w'"):
        bidmp.io.read_trajectory(named, columns="t=stamp,w=ee_x")


def test_missing_and_bad_npy_files(tmp_path):
    with pytest.raises(ValueError, match="does not exist"):
        load_trajectory(tmp_path / "nope.csv")
    (tmp_path / "junk.npy").write_bytes(b"definitely not numpy")
    with pytest.raises(ValueError, match="not an .npy array"):
        load_trajectory(tmp_path / "junk.npy")
    np.save(tmp_path / "obj.npy", np.array([{"a": 1}], dtype=object), allow_pickle=True)
    with pytest.raises(ValueError, match="holds object data"):
        load_trajectory(tmp_path / "obj.npy")
    np.save(tmp_path / "flat.npy", np.arange(10.0))
    with pytest.raises(ValueError, match=r"shape \(T, D\)"):
        load_trajectory(tmp_path / "flat.npy")


# --- model files -----------------------------------------------------------------------------
def test_save_load_is_bit_exact(tmp_path, fitted):
    path = bidmp.save(fitted, tmp_path / "model.npz")
    loaded = bidmp.load(path)
    assert isinstance(loaded, DMP)
    assert loaded.get_params() == fitted.get_params()
    for name in ("weights_", "start_", "goal_", "centres_", "widths_"):
        np.testing.assert_array_equal(getattr(loaded, name), getattr(fitted, name))
    goals = np.random.default_rng(0).normal(size=(4, 3))
    np.testing.assert_array_equal(loaded.rollout_many(goals), fitted.rollout_many(goals))
    assert loaded.endpoint_gain() == fitted.endpoint_gain()


def test_suffix_is_added_and_no_temp_files_are_left(tmp_path, fitted):
    path = bidmp.save(fitted, tmp_path / "model")
    assert path.name == "model.npz"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.npz"]


def test_failed_write_keeps_the_old_file(tmp_path, fitted, monkeypatch):
    path = bidmp.save(fitted, tmp_path / "model.npz")
    before = path.read_bytes()

    def broken_savez(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(np, "savez", broken_savez)
    with pytest.raises(OSError, match="disk full"):
        bidmp.save(DMP(protocol="paper").fit(curved_demo(100, 2)), path)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["model.npz"]


def test_file_has_no_pickles_and_versioned_json_metadata(tmp_path, fitted):
    path = bidmp.save(fitted, tmp_path / "model.npz")
    with np.load(path, allow_pickle=False) as archive:
        meta = json.loads(archive["__bidmp__"].tobytes())
        assert all(archive[name].dtype != object for name in archive.files)
    assert meta["format_version"] == FORMAT_VERSION
    assert meta["class"] == "DMP"
    assert meta["state"]["params"]["K"] == "pastor"


def rewrite_meta(path, change):
    with np.load(path, allow_pickle=False) as archive:
        arrays = {name: archive[name] for name in archive.files}
    meta = json.loads(arrays["__bidmp__"].tobytes())
    change(meta, arrays)
    arrays["__bidmp__"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    np.savez(path, **arrays)


@pytest.mark.parametrize(
    "corrupt, match",
    [
        (lambda p: p.write_bytes(b"\x00garbage" * 50), "not a bidmp model file"),
        (
            lambda p: p.write_bytes(p.read_bytes()[: len(p.read_bytes()) // 2]),
            "not a readable bidmp model file",
        ),
        (lambda p: np.savez(p, weights=np.ones(3)), "without bidmp metadata"),
        (
            lambda p: np.save(p.with_suffix(".npy"), np.ones(3)) or p.with_suffix(".npy").rename(p),
            "plain .npy",
        ),
        (
            lambda p: rewrite_meta(p, lambda m, a: m.update(format_version=FORMAT_VERSION + 1)),
            "newer|upgrade bidmp",
        ),
        (
            lambda p: rewrite_meta(p, lambda m, a: m.update(format="something-else")),
            "unknown metadata format",
        ),
        (
            lambda p: rewrite_meta(p, lambda m, a: m.update({"class": "Pickle"})),
            "unknown model class 'Pickle'",
        ),
        (lambda p: rewrite_meta(p, lambda m, a: a.pop("weights_")), "corrupt"),
        (
            lambda p: rewrite_meta(p, lambda m, a: a.update(weights_=np.ones((3, 3)))),
            "corrupt.*weights_",
        ),
        (
            lambda p: rewrite_meta(p, lambda m, a: m["state"]["params"].update(alpha=-1)),
            "corrupt.*alpha",
        ),
    ],
)
def test_bad_model_files_give_clear_errors(tmp_path, fitted, corrupt, match):
    path = bidmp.save(fitted, tmp_path / "model.npz")
    corrupt(path)
    with pytest.raises(ModelFileError, match=match):
        bidmp.load(path)


def test_object_arrays_are_refused_not_unpickled(tmp_path, fitted):
    path = bidmp.save(fitted, tmp_path / "model.npz")
    with zipfile.ZipFile(path, "a") as archive:
        import io

        buffer = io.BytesIO()
        np.save(buffer, np.array([object()], dtype=object), allow_pickle=True)
        archive.writestr("evil.npy", buffer.getvalue())
    with pytest.raises(ModelFileError, match="not a bidmp model file .member 'evil' holds object"):
        bidmp.load(path)


def test_missing_model_file_and_unsupported_objects(tmp_path):
    with pytest.raises(ModelFileError, match="does not exist"):
        bidmp.load(tmp_path / "absent.npz")
    with pytest.raises(TypeError, match="model must be one of"):
        bidmp.save(object(), tmp_path / "x.npz")
    with pytest.raises(bidmp.NotFittedError):
        bidmp.save(DMP(protocol="paper"), tmp_path / "x.npz")


def test_format_1_dmp_files_still_load(tmp_path, fitted):
    path = bidmp.save(fitted, tmp_path / "old.npz")

    def to_format_1(meta, arrays):
        meta["format_version"] = 1
        meta["state"]["params"]["fit"] = meta["state"]["params"].pop("regression")  # its old name

    rewrite_meta(path, to_format_1)
    old = bidmp.load(path)
    assert old.regression == fitted.regression
    np.testing.assert_array_equal(old.rollout(), fitted.rollout())


def test_format_1_bidmp_files_are_refused(tmp_path, fitted):
    from bidmp.demonstrations import minimum_jerk

    demo = minimum_jerk([[0, 0, 1], [1, 1, 0], [2, 0, 0]], 60)
    model = bidmp.BiDMP(DMP(protocol="paper").fit(demo)).learn(
        demo + np.linspace(0, 1, 60)[:, None]
    )
    path = bidmp.save(model, tmp_path / "old.npz")
    assert bidmp.load(path).n_skills == 2
    rewrite_meta(path, lambda meta, arrays: meta.update(format_version=1))
    with pytest.raises(ModelFileError, match="did not vanish with the phase"):
        bidmp.load(path)
    assert FORMAT_VERSION == 5


def test_a_format_3_robot_model_rolls_out_as_it_did():
    """tests/data/format3_robot_dmp.npz and its rollouts (to its goal and to a goal 150 mm away)
    were written by bidmp 0.3 (before the robot protocol). Format 3 knew only explicit Euler, so
    the file loads with integrator="euler" and its rollouts are unchanged."""
    data = Path(__file__).parents[1] / "data"
    model = bidmp.load(data / "format3_robot_dmp.npz")
    assert model.protocol == "robot" and model.integrator == "euler"
    expected = np.load(data / "format3_robot_rollout.npy")
    np.testing.assert_allclose(model.rollout(), expected[0], rtol=0, atol=1e-9)
    np.testing.assert_allclose(
        model.rollout(model.goal_ + [150, 25, 0]), expected[1], rtol=0, atol=1e-9
    )
    fresh = bidmp.DMP().fit(model.rollout())  # a model fitted today has the exact integrator
    assert fresh.integrator is None and fresh.settings().integrator == "exact"


def test_format_2_dmp_files_load_as_the_paper_protocol(tmp_path, fitted):
    path = bidmp.save(fitted, tmp_path / "m.npz")

    def to_format_2(meta, arrays):
        meta["format_version"] = 2
        for key in ("protocol", "goal_rate"):
            meta["state"]["params"].pop(key)
        meta["state"].pop("duration_")
        meta["state"].pop("units_")

    rewrite_meta(path, to_format_2)
    old = bidmp.load(path)
    assert old.protocol == "paper" and old.duration_ == pytest.approx(
        (fitted.n_steps_ - 1) / fitted.n_steps_
    )
    np.testing.assert_array_equal(old.rollout(), fitted.rollout())
