"""The reproducers an independent fuzz campaign found, each refused cleanly or answered correctly.

Each case is a structure guard of a refusal: the call must raise ``ValueError`` or ``TypeError`` in
one line of at most 300 characters that names the argument — not NumPy's, SciPy's, pybullet's or
Python's own words, not a hang, not a silent NaN. The CLI cases must exit 2 with one line on stderr.
Two cases are correctness checks against an independent oracle (said in their docstrings).
"""

from __future__ import annotations

import json
import os
import re
from pathlib import Path

import numpy as np
import pytest
from conftest import minimum_jerk

import bidmp
from bidmp.cli import main

T = np.linspace(0.0, 2.0, 200)


@pytest.fixture(scope="module")
def demo():
    return minimum_jerk(np.zeros(3), np.array([120.0, 40.0, -30.0]), 200)


@pytest.fixture(scope="module")
def dmp(demo):
    return bidmp.DMP().fit(demo, T, units="mm")


@pytest.fixture(scope="module")
def scene():
    return bidmp.tasks.load("nut-unscrewing").scene


def refused(call, *names, kinds=(ValueError, TypeError)):
    """Run ``call``; it must refuse in one short line naming one of ``names``."""
    with pytest.raises(kinds) as caught:
        call()
    message = str(caught.value)
    assert "\n" not in message and len(message) <= 300, message
    assert any(name in message for name in names), f"{message!r} names none of {names}"
    return message


# -- bounds on total work -------------------------------------------------------------------------
def test_two_million_broadcast_goals_are_refused_before_any_work(dmp):
    goals = np.broadcast_to(dmp.goal_, (2_000_000, 3))
    refused(lambda: list(dmp.iter_rollouts(goals)), "goals")


def test_fifty_million_broadcast_quaternions_are_refused_at_once():
    quaternions = np.broadcast_to([0.0, 0.0, 0.0, 1.0], (50_000_000, 4))
    refused(lambda: bidmp.primitives.continuous_quaternions(quaternions), "q")


def test_a_tp_gmm_methods_rollouts_to_two_million_goals_are_refused(demo):
    method = bidmp.tasks.methods.get("tpgmm")
    goals = np.broadcast_to(demo[-1], (2_000_000, 3))
    task = bidmp.tasks.methods.Task(demonstration=demo, goals=demo[-1:])
    model, _ = method.fit(task)
    refused(lambda: method.rollouts(model, goals), "goals")


# -- files -----------------------------------------------------------------------------------------
def test_an_empty_layers_file_is_named_and_bidmp_view_exits_2(tmp_path, capsys):
    empty = tmp_path / "view_layers.npz"
    empty.write_bytes(b"")
    refused(lambda: bidmp.plotting.load_layers(empty), "view_layers.npz")
    assert main(["view", str(tmp_path), "-o", str(tmp_path / "v.html")]) == 2
    assert len(capsys.readouterr().err.strip().splitlines()) == 1


def test_a_scenario_nested_five_thousand_deep_is_refused():
    data = json.loads(bidmp.tasks.builtin_text("nut-unscrewing"))
    deep: list = []
    for _ in range(5_000):
        deep = [deep]
    data["description"] = deep
    refused(lambda: bidmp.tasks.from_dict(data), "description")


def test_a_bag_with_three_thousand_nested_types_is_refused(tmp_path):
    pytest.importorskip("rosbags")
    from rosbags.rosbag1 import Writer

    path = tmp_path / "deep.bag"
    n_types = 3_000
    sections = ["pkg/T0 a"] + [
        f"{'=' * 80}\nMSG: pkg/T{i}\n" + (f"pkg/T{i + 1} a" if i < n_types - 1 else "int32 x")
        for i in range(n_types)
    ]
    with Writer(path) as writer:
        connection = writer.add_connection(
            "/deep", "pkg/msg/Deep", msgdef="\n".join(sections), md5sum="0" * 32
        )
        writer.write(connection, 1, b"\x00\x00\x00\x00")
    refused(lambda: bidmp.io.read_bag(path, topic="/deep"), "deep.bag")


# -- values out of range and arguments of the wrong kind --------------------------------------------
def test_a_target_clearance_of_1e308_is_refused(scene):
    refused(lambda: scene.check_targets({"c": 1e308}), "c", "targets")


def test_bls_predict_of_none_is_refused():
    rng = np.random.default_rng(0)
    X, Y = rng.normal(size=(40, 3)), rng.normal(size=(40, 2))
    model = bidmp.BLS(n_windows=2, n_mapped=4, n_enhance=8).fit(X, Y)
    refused(lambda: model.predict(None), "X")


def test_via_points_with_limits_given_as_a_list_or_with_an_unknown_key_are_refused(dmp):
    via = [(0.5, dmp.goal_ * 0.5)]
    refused(lambda: dmp.trajectory(via=via, limits=[{"velocity": 100.0}]), "limits")
    refused(
        lambda: dmp.trajectory(via=via, limits={"velocity": 100.0, "speed": 3.0}), "speed", "limits"
    )


def test_robot_models_of_the_wrong_shape_or_from_places_a_scenario_may_not_read(tmp_path):
    pytest.importorskip("pybullet")
    limits = {"lower": [0] * 7, "upper": [1] * 7, "velocity": [1] * 7, "acceleration": [1] * 7}
    refused(lambda: bidmp.sim.robot_model([{"model": "panda"}]), "spec")
    refused(lambda: bidmp.sim.robot_model({"urdf": "a.urdf", "limits": limits}), "flange")
    fifo = tmp_path / "arm.urdf"
    os.mkfifo(fifo)
    for urdf in ("/etc/passwd", "/dev/zero", str(fifo), "file:///etc/passwd"):
        refused(
            lambda urdf=urdf: bidmp.sim.robot_model(
                {"urdf": urdf, "flange": "x", "limits": limits}
            ),
            "urdf",
        )


def test_a_rack_slot_at_nan_and_nan_integrator_settings_are_refused():
    job = bidmp.tasks.load("cell-removal").job
    refused(lambda: job.slot(float("nan")), "index")
    refused(lambda: bidmp.primitives.StepIntegrator(25.0, float("nan"), 1.0, True), "beta")


def test_a_task_with_a_nan_seed_or_an_infinite_goal_is_refused(demo):
    refused(
        lambda: bidmp.tasks.methods.Task(demonstration=demo, goals=[[0.0, 0.0, -np.inf]]), "goals"
    )
    refused(
        lambda: bidmp.tasks.methods.Task(demonstration=demo, goals=demo[-1:], seed=float("nan")),
        "seed",
    )


def test_a_pose_stepper_with_an_infinite_measurement_is_refused():
    t = np.linspace(0.0, 2.0, 100)
    positions = minimum_jerk(np.zeros(3), np.array([100.0, 0.0, 50.0]), 100)
    angles = np.linspace(0.0, 1.0, 100)
    poses = np.column_stack([positions, np.zeros((100, 2)), np.sin(angles / 2), np.cos(angles / 2)])
    stepper = bidmp.CartesianDMP().fit(poses, t, units="mm").stepper()
    refused(lambda: stepper.step(0.01, y_measured=-np.inf), "y_measured")


def test_bags_with_numbers_for_joint_names_or_integer_times_are_refused(tmp_path):
    pytest.importorskip("rosbags")
    t, q = np.linspace(0.0, 1.0, 20), np.zeros((20, 7))
    refused(
        lambda: bidmp.io.write_bag(
            tmp_path / "b.bag", t, q, kind="joints", names=np.arange(7.0), ros=1
        ),
        "names",
    )
    from rosbags.highlevel import AnyReader

    written = bidmp.io.write_bag(
        tmp_path / "c.bag", np.arange(20, dtype=np.int64), q, kind="joints", ros=1
    )
    with AnyReader([written]) as reader:  # read by rosbags itself: integer seconds are seconds
        ((connection, _, raw),) = reader.messages()
        points = reader.deserialize(raw, connection.msgtype).points
    assert [point.time_from_start.sec for point in points] == list(range(20))


def test_writing_a_bag_never_deletes_a_folder_that_is_not_a_bag(tmp_path):
    pytest.importorskip("rosbags")
    folder = tmp_path / "mine"
    folder.mkdir()
    (folder / "thesis.tex").write_text("keep me")
    t, q = np.linspace(0.0, 1.0, 20), np.zeros((20, 7))
    refused(lambda: bidmp.io.write_bag(folder, t, q, kind="joints", ros=2), "mine", "path")
    assert (folder / "thesis.tex").read_text() == "keep me"


def test_segments_free_with_unequal_ends_is_refused(scene, demo):
    checker = scene.checker()
    refused(lambda: checker.segments_free(demo[:1], demo[1:80]), "start points")


def test_tools_time_scaling_cells_and_meshes_refuse_what_they_cannot_represent(scene, demo):
    refused(lambda: bidmp.Tool(1.0, 10**400), "length")
    one = bidmp.Trajectory(np.zeros(1), demo[:1], np.zeros((1, 3)), np.zeros((1, 3)))
    refused(
        lambda: bidmp.primitives.time_scale(one, max_velocity=100.0), "trajectory", "samples", "y"
    )
    motion = bidmp.DMP().fit(demo, T, units="mm").trajectory()
    refused(lambda: bidmp.primitives.time_scale(motion, max_velocity=1e-300), "max_velocity")
    refused(lambda: bidmp.sim.RobotCell(scene, base=[[0.0, -450.0, 0.0]]), "base")
    refused(
        lambda: bidmp.plotting.solid_mesh("box", [np.inf, 0.0, 0.0], np.eye(3), (1.0, 1.0, 1.0)),
        "centre",
    )


# -- the command line: exit 2, one line ------------------------------------------------------------
@pytest.mark.parametrize(
    "argv",
    [
        ["sim", "--targets", "zz", "--no-pictures", "--workers", "1"],
        ["fit", "{demo}", "-o", "{out}/m.npz", "--cutoff", "+inf"],
        ["rollout", "{model}", "-o", "{out}/r.csv", "--bag", ""],
        ["view", "{out}", "-o", ""],
    ],
)
def test_the_command_line_refuses_in_one_line_with_exit_2(argv, tmp_path, demo, capsys):
    path = bidmp.io.save_trajectory(demo, tmp_path / "demo.csv", times=T)
    model = bidmp.io.save_model(bidmp.DMP().fit(demo, T, units="mm"), tmp_path / "m.npz")
    argv = [part.format(demo=path, model=model, out=tmp_path) for part in argv]
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "internal error" not in err, err


def test_a_urdf_whose_meshes_point_at_system_files_exits_2(tmp_path, capsys):
    pybullet_data = pytest.importorskip("pybullet_data")
    shipped = Path(pybullet_data.getDataPath()) / "kuka_iiwa" / "model.urdf"
    text = re.sub(r'filename="[^"]+"', 'filename="/etc/passwd"', shipped.read_text())
    (tmp_path / "arm.urdf").write_text(text)
    spec = json.loads(bidmp.tasks.builtin_text("nut-unscrewing-iiwa"))
    spec["robot"] = {
        "urdf": "arm.urdf",
        "flange": "lbr_iiwa_link_7",
        "limits": {
            "lower": [-2.9] * 7,
            "upper": [2.9] * 7,
            "velocity": [1.0] * 7,
            "acceleration": [5.0] * 7,
        },
    }
    (tmp_path / "cell.json").write_text(json.dumps(spec))
    code = main(
        [
            "sim",
            "--scenario",
            str(tmp_path / "cell.json"),
            "--methods",
            "dmp",
            "--targets",
            "3",
            "--no-pictures",
            "--workers",
            "1",
            "--out",
            str(tmp_path / "out"),
        ]
    )
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and "internal error" not in err, err
    assert "mesh" in err and "/etc/passwd" in err


# -- correct results where a library bug used to sit -----------------------------------------------
def test_a_pose_bi_dmp_learns_an_extension_whose_orientation_stays_still():
    """Independent oracle: an extension holding one orientation is reproduced holding it (the
    quaternion's angle to it, computed here from the dot product, stays below 1e-6 rad); the
    position goal is reached within 1e-3 of the extent."""
    t = np.linspace(0.0, 2.0, 120)
    positions = minimum_jerk(np.zeros(3), np.array([100.0, 0.0, 50.0]), 120)
    turn = np.linspace(0.0, 0.8, 120)
    poses = np.column_stack([positions, np.zeros((120, 2)), np.sin(turn / 2), np.cos(turn / 2)])
    model = bidmp.CartesianBiDMP(cartesian={"n_weights": 20}).fit(poses, t, units="mm")
    held = np.array([0.0, 0.0, np.sin(0.4), np.cos(0.4)])
    extension = np.column_stack([positions + [0.0, 80.0, 0.0], np.tile(held, (120, 1))])
    model.learn(extension, duration=2.0)
    rolled = model.trajectory(extension[-1])
    angles = 2.0 * np.arccos(np.clip(np.abs(rolled.q @ held), 0.0, 1.0))
    assert np.max(angles) < 1e-6
    assert np.linalg.norm(rolled.y[-1] - extension[-1, :3]) < 1e-3 * np.ptp(positions, axis=0).max()


def test_drop_repeated_stamps_names_a_label_that_is_not_text():
    """Found by the full public-surface sweep (35 273 calls): ``name`` of -inf with ragged stamps
    was refused in words that named neither argument."""
    from bidmp.primitives import drop_repeated_stamps

    with pytest.raises(
        TypeError, match=r"^name \(what the messages call the stamps\) must be text, got float$"
    ):
        drop_repeated_stamps(np.zeros((3, 2)), [[0.0], [1.0, 2.0]], name=-np.inf)
    y, t = drop_repeated_stamps(np.arange(8.0).reshape(4, 2), [0.0, 1.0, 1.0, 2.0])
    np.testing.assert_array_equal(t, [0.0, 1.0, 2.0])
    np.testing.assert_array_equal(y, [[0.0, 1.0], [2.0, 3.0], [6.0, 7.0]])


# -- six that an earlier campaign found and a second still reproduced ------------------------------
def test_a_viewers_scalar_or_bool_target_is_refused_where_the_layers_are_made(tmp_path, demo):
    """A scalar target failed deep in the drawing (an IndexError of plotly's coordinates), in the
    viewer and in a view file read back; a 2-D target lies at z = 0 where it is drawn."""
    from bidmp.plotting import ViewLayers, load_layers, view_figure

    for target in (5.0, np.array(5.0), True, [1.0, 2.0, 3.0, 4.0]):
        refused(lambda t=target: ViewLayers("x", "mm", demo, targets={"a": t}), "targets['a']")
    refused(lambda: ViewLayers("x", "mm", demo, targets=5.0), "targets")
    figure = view_figure(ViewLayers("x", "mm", demo[:, :2], targets={"a": [4.0, 5.0]}))
    drawn = next(trace for trace in figure.data if trace.name == "targets")
    assert (drawn.x[0], drawn.y[0], drawn.z[0]) == (4.0, 5.0, 0.0)
    # a view file whose target is one number: named by its path
    path = bidmp.plotting.save_layers(tmp_path / "v.npz", ViewLayers("x", "mm", demo))
    with np.load(path) as archive:
        arrays = {name: archive[name] for name in archive.files}
    meta = json.loads(arrays["meta"].tobytes())
    meta["targets"] = {"a": 5.0}
    arrays["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)
    np.savez(tmp_path / "bad.npz", **arrays)
    refused(lambda: load_layers(tmp_path / "bad.npz"), "bad.npz")


def test_a_bool_where_a_scene_point_or_label_goes_is_refused(scene, demo):
    """scene.applies_to(True) answered True; target_parts("1", True) answered ["1"] without
    looking at the point. NumPy reads True as 1.0: a flag where a point goes is refused."""
    refused(lambda: scene.applies_to(True), "label")
    refused(lambda: scene.target_parts("1", True), "point")
    refused(lambda: scene.parts_at(np.array([True, False, True])), "point")
    refused(lambda: scene.check_targets({"x": [True, False, True]}), "targets['x']")
    refused(lambda: bidmp.DMP().fit(demo, T).trajectory(np.array([True, True, False])), "goal")
    nut = bidmp.tasks.load("nut-unscrewing").targets["1"]
    assert scene.target_parts("1", nut) == ["1"]


def test_run_cell_refuses_an_array_for_the_demonstrations_index_before_any_work():
    from bidmp.experiments.lasa_cells import run_cell

    refused(lambda: run_cell("Sshape", np.array([0, 1]), ("dmp-paper",), 20), "demo")
    refused(lambda: run_cell("Sshape", np.zeros((60, 3)), ("dmp-paper",), 20), "demo")
    refused(lambda: run_cell("Sshape", 9, ("dmp-paper",), 20), "demo")
    refused(lambda: run_cell("Sshape", 0, "dmp-paper", 20), "methods")
    refused(lambda: run_cell("Sshape", 0, ("dmp-paper",), 0.5), "every")


def _estimators_with_constraints():
    from bidmp.baselines import GMMRegressor
    from bidmp.primitives import MultiDMP, ProDMP, ProMP, RhythmicDMP, RhythmicPoseDMP

    return [RhythmicDMP, RhythmicPoseDMP, ProMP, ProDMP, MultiDMP, bidmp.BiDMP, GMMRegressor]


@pytest.mark.parametrize("cls", _estimators_with_constraints(), ids=lambda c: c.__name__)
def test_set_params_refuses_a_nan_by_name_and_changes_nothing(cls):
    """RhythmicDMP.set_params(alpha=nan) stored it (a model file then failed in JSON's words,
    naming nothing). Each declared parameter is checked where it is set, all before any is
    set; a bad one changes none."""
    estimator = cls()
    before = estimator.get_params(deep=False)
    for name in cls._parameter_constraints:
        # with another parameter set to its own value first: nothing is set when one is refused
        other = next((k for k in before if k != name), name)
        for bad in (float("nan"), np.inf, "text"):
            refused(
                lambda n=name, b=bad, o=other: estimator.set_params(**{o: before[o], n: b}), name
            )
    assert estimator.get_params(deep=False) == before
    for name in cls._parameter_constraints:  # fit refuses the same (a constructor stores)
        with pytest.raises((ValueError, TypeError), match=rf"^{name} "):
            cls(**{name: float("nan")})._check_constraints()


@pytest.mark.parametrize("seed", range(3))
def test_a_quaternion_of_huge_or_tiny_components_is_the_same_rotation(seed, scene):
    """Components of 1e300 overflowed the norm (inf, and a RuntimeWarning), of 1e-300 underflowed
    it to 0 ("a zero quaternion"). Scaled by a power of two first, each is the rotation of its
    direction. Oracle: the same call on the unit quaternion."""
    import warnings

    from bidmp.primitives import continuous_log, orientation_from_log, principal_log
    from bidmp.tasks import axis_deviation

    rng = np.random.default_rng(seed)
    q, goal = (v / np.linalg.norm(v, axis=-1, keepdims=True) for v in rng.normal(size=(2, 5, 4)))
    error = rng.normal(0.0, 0.5, (5, 3))
    path = np.column_stack([np.zeros(5), np.zeros(5), np.linspace(40.0, 0.0, 5)])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for scale in (1e300, 1e-300, 10.0 ** rng.uniform(-300, 300), 10.0 ** rng.uniform(0, 300)):
            np.testing.assert_allclose(
                principal_log(q * scale, goal[0] * scale), principal_log(q, goal[0]), atol=1e-12
            )
            np.testing.assert_allclose(
                continuous_log(q, goal[0] * scale), continuous_log(q, goal[0]), atol=1e-12
            )
            np.testing.assert_allclose(
                orientation_from_log(error, goal * scale), orientation_from_log(error, goal),
                atol=1e-12,
            )  # fmt: skip
            if scale < 1.0:
                continue  # (below 1e-12 these two call a quaternion zero: a refusal)
            assert axis_deviation(path, q * scale, path[-1], 30.0) == pytest.approx(
                axis_deviation(path, q, path[-1], 30.0), abs=1e-9
            )
            far = path + [200.0, 200.0, 0.0]
            assert scene.clearance(far, orientations=q * scale).distance == pytest.approx(
                scene.clearance(far, orientations=q).distance, rel=1e-8
            )


def test_time_scale_of_one_sample_with_a_jerk_limit_is_refused_by_name(demo):
    """np.gradient of one sample was an IndexError; the jerk needs two samples or more."""
    motion = bidmp.DMP().fit(demo, T, units="mm").trajectory()
    one = bidmp.Trajectory(motion.t[:1], motion.y[:1], motion.yd[:1], motion.ydd[:1])
    refused(lambda: bidmp.time_scale(one, max_jerk=10.0), "max_jerk")
    refused(lambda: bidmp.time_scale(one, max_velocity=1.0, max_jerk=10.0), "max_jerk")
    two = bidmp.Trajectory(motion.t[:2], motion.y[:2], motion.yd[:2], motion.ydd[:2])
    jerk = np.linalg.norm(np.gradient(two.ydd, two.t, axis=0), axis=1).max()
    scaled = bidmp.time_scale(two, max_jerk=jerk / 8.0)  # twice the time: a jerk 8 times smaller
    np.testing.assert_allclose(scaled.t, 2.0 * two.t, rtol=1e-12)
