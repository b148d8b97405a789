"""Pose skills: CartesianDMP against movement_primitives and closed forms, pose files,
pose Bi-DMP, the pose extension and the tilted pack."""

import json
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bidmp
from bidmp.demonstrations import kinesthetic_recording, minimum_jerk
from bidmp.demonstrations.preparation import prepare_poses
from bidmp.extension import extend_pose_demonstration
from bidmp.incremental.cartesian import CartesianBiDMP, pose_forgetting
from bidmp.io import read_poses, save_poses
from bidmp.primitives import DMP, CartesianDMP, angle_between
from bidmp.primitives.so3 import _left_jacobian as left_jacobian

DOWN = Rotation.from_euler("x", 180, degrees=True)


def pose_demo(via, rotvec, n_steps=200, base=DOWN):
    positions = minimum_jerk(via, n_steps=n_steps)
    s = np.linspace(0.0, 1.0, n_steps)
    s = 10 * s**3 - 15 * s**4 + 6 * s**5
    return np.hstack([positions, (Rotation.from_rotvec(np.outer(s, rotvec)) * base).as_quat()])


@pytest.fixture(scope="module")
def demo():
    return pose_demo([[0, 0, 100], [80, 20, 40], [150, 25, 0]], [0.3, -0.8, 1.2])


def test_orientation_rollouts_stay_unit_and_reach_a_goal_turned_90_degrees(demo):
    model = CartesianDMP().fit(demo, np.linspace(0.0, 2.0, len(demo)), units="mm")
    goal = demo[-1].copy()
    goal[3:] = (
        Rotation.from_euler("z", 90, degrees=True) * Rotation.from_quat(demo[-1, 3:])
    ).as_quat()
    for query in (None, goal):
        trajectory = model.trajectory(goal=query)
        assert np.max(np.abs(np.linalg.norm(trajectory.q, axis=1) - 1.0)) <= 1e-12
    assert np.degrees(angle_between(trajectory.q[-1:], goal[None, 3:]))[0] <= 0.1
    assert np.linalg.norm(trajectory.y[-1] - goal[:3]) <= 0.15
    # The angular velocity is the derivative of the orientation (world frame): the explicit-Euler
    # step from sample l to l + 1, to first order in dt.
    dt = trajectory.t[1] - trajectory.t[0]
    step = Rotation.from_quat(trajectory.q[1:]) * Rotation.from_quat(trajectory.q[:-1]).inv()
    numeric = step.as_rotvec() / dt
    assert np.max(np.linalg.norm(numeric - trajectory.omega[:-1], axis=1)) <= 0.01 * np.max(
        np.linalg.norm(numeric, axis=1)
    )


def test_left_jacobian_against_finite_differences():
    rng = np.random.default_rng(0)
    for r in rng.normal(0.0, 1.0, size=(5, 3)):
        rdot = rng.normal(size=3)
        h = 1e-6
        numeric = (
            Rotation.from_rotvec(r + h * rdot) * Rotation.from_rotvec(r).inv()
        ).as_rotvec() / h
        np.testing.assert_allclose(left_jacobian(r)[0] @ rdot, numeric, atol=1e-5)


def test_a_recorded_pose_demonstration_is_reproduced_within_half_a_degree(tmp_path):
    positions, t = kinesthetic_recording([[0, 0, 120], [60, -40, 60], [120, 10, 0]], seed=3)
    rng = np.random.default_rng(3)
    # The wrist turns while the arm moves (a minimum-jerk turn over the span prepare() finds the
    # hand moving in), and rests with it.
    _, moving = bidmp.prepare(positions, t)
    s = np.clip((t - t[0] - moving.start_s) / (moving.end_s - moving.start_s), 0.0, 1.0)
    s = 10 * s**3 - 15 * s**4 + 6 * s**5
    rotations = Rotation.from_rotvec(np.outer(s, [0.5, 0.2, -0.9])) * DOWN
    noisy = rotations * Rotation.from_rotvec(rng.normal(0.0, np.radians(0.05), size=(len(t), 3)))
    quaternions = noisy.as_quat()
    quaternions[1::7] *= -1.0  # sign flips, as loggers write them
    quaternions[::11] *= 1.001  # slightly off unit length
    path = tmp_path / "poses.csv"
    rows = np.column_stack(
        [t, positions, quaternions[:, [3, 0, 1, 2]]]
    )  # the logger writes qw first
    path.write_text(
        "t,x,y,z,qw,qx,qy,qz\n" + "\n".join(",".join(repr(float(v)) for v in row) for row in rows)
    )
    poses, stamps = read_poses(path)
    np.testing.assert_allclose(poses[:, 3:], quaternions, atol=1e-12)
    with pytest.warns(UserWarning, match="not of unit length"):
        prepared, prepared_t, info = prepare_poses(poses, stamps, units="mm")
    model = CartesianDMP().fit(prepared, prepared_t, units="mm")
    from scipy.spatial.transform import Slerp

    reproduction = model.trajectory()  # the motion, then 10 % at rest (robot protocol)
    motion = reproduction.t <= prepared_t[-1]
    truth = Slerp(t - t[0], rotations)(reproduction.t[motion] + info.start_s)
    rms = np.sqrt(np.mean(np.degrees(angle_between(reproduction.q[motion], truth.as_quat())) ** 2))
    assert rms <= 0.1  # the README states 0.07 degrees
    # Fitted raw, the sensor noise (0.05 degrees per sample) is differentiated twice: far worse.
    with pytest.warns(UserWarning, match="not of unit length"):
        raw = CartesianDMP().fit(poses, stamps).trajectory()
    raw_truth = Slerp(t - t[0], rotations)(np.clip(raw.t, 0, t[-1] - t[0]))
    assert np.sqrt(np.mean(np.degrees(angle_between(raw.q, raw_truth.as_quat())) ** 2)) > 2 * rms


@pytest.mark.parametrize(
    "goal_turn, rate, bound",
    [
        (0.0, "demo", (0.0, 0.004)),  # the README: 0.32 % of the rotation
        (0.0, 1000.0, (0.0, 0.01)),  # 0.82 %: each side integrates Euler at its own step
        (
            30.0,
            "demo",
            (0.075, 0.095),
        ),  # 8.4-8.5 %: Ude's quaternion error and the log at the goal differ by design
        (30.0, 1000.0, (0.075, 0.095)),
    ],
)
def test_agreement_with_movement_primitives_cartesian_dmp(demo, goal_turn, rate, bound):
    """The same gains (alpha_y = 25, beta_y = 6.25), 50 weights and the phase decaying to 0.01 as
    movement_primitives' CartesianDMP (Ude 2014), at the demonstration's rate and at 1 kHz, to
    its goal and to one turned by 30 degrees. The difference, as a share of the demonstrated
    rotation, stays in the stated band: small for the demonstrated goal; for a turned goal the two
    formulations differ (by about 7 degrees), and both reach it."""
    mp = pytest.importorskip("movement_primitives.dmp")
    t = np.linspace(0.0, 2.0, len(demo))
    dt = t[1] if rate == "demo" else 1.0 / rate
    metres = demo.copy()
    metres[:, :3] /= 1000.0
    goal = metres[-1].copy()
    goal[3:] = (
        Rotation.from_euler("z", goal_turn, degrees=True) * Rotation.from_quat(metres[-1, 3:])
    ).as_quat()

    def scalar_first(poses):
        return np.hstack([poses[..., :3], poses[..., [6, 3, 4, 5]]])

    peer = mp.CartesianDMP(execution_time=2.0, dt=dt, n_weights_per_dim=50, int_dt=0.001)
    peer.imitate(t, scalar_first(metres))
    peer.configure(start_y=scalar_first(metres)[0], goal_y=scalar_first(goal))
    theirs = peer.open_loop()[1][:, [4, 5, 6, 3]]
    ours = (
        CartesianDMP(
            DMP(
                protocol="paper",
                alpha=25.0,
                beta=6.25,
                K="paper",
                n_kernels=50,
                alpha_phase=-np.log(0.01),
            )
        )
        .fit(metres, t)
        .trajectory(goal, dt=dt)
    )
    n = min(len(theirs), len(ours.t))
    extent = angle_between(demo[:1, 3:], demo[-1:, 3:])[0]
    difference = np.max(angle_between(ours.q[:n], theirs[:n])) / extent
    assert bound[0] <= difference <= bound[1]
    for end in (ours.q[-1:], theirs[-1:]):
        assert np.degrees(angle_between(end, goal[None, 3:]))[0] <= 0.2


def test_quaternions_are_made_continuous_normalised_or_refused(demo):
    flipped = demo.copy()
    flipped[50:, 3:] *= -1.0
    a = CartesianDMP().fit(demo).rollout()
    b = CartesianDMP().fit(flipped).rollout()
    assert np.max(angle_between(a[:, 3:], b[:, 3:])) <= 1e-9
    zero = demo.copy()
    zero[10, 3:] = 0.0
    with pytest.raises(ValueError, match="row 10 is a zero quaternion"):
        CartesianDMP().fit(zero)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        CartesianDMP().fit(demo)  # unit quaternions: no warning


def test_a_header_without_quaternion_names_is_refused(tmp_path):
    path = tmp_path / "p.csv"
    path.write_text("t,x,y,z,a,b,c,d\n0,0,0,0,0,0,0,1\n0.1,1,0,0,0,0,0,1\n0.2,2,0,0,0,0,0,1\n")
    with pytest.raises(
        ValueError,
        match=r"hold positions, not poses; a pose file.s header names x,y,z with qx,qy,qz,qw or rx,ry,rz",
    ):
        read_poses(path)
    pose = tmp_path / "q.csv"
    pose.write_text("t,x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,0,1\n0.1,1,0,0,0,0,0,1\n0.2,2,0,0,0,0,0,1\n")
    with pytest.raises(
        ValueError,
        match=r"a pose recording \(x,y,z,qx,qy,qz,qw\): read it with bidmp.io.read_poses",
    ):
        bidmp.io.read_trajectory(pose)
    poses, stamps = read_poses(pose)
    assert poses.shape == (3, 7) and stamps.tolist() == [0.0, 0.1, 0.2]


def test_pose_files_and_model_files_round_trip(tmp_path, demo):
    model = CartesianDMP().fit(demo, np.linspace(0.0, 2.0, len(demo)), units="mm")
    trajectory = model.trajectory()
    save_poses(trajectory, tmp_path / "out.csv")
    poses, stamps = read_poses(tmp_path / "out.csv")
    np.testing.assert_allclose(poses, trajectory.poses, rtol=0, atol=1e-12)
    bidmp.save(model, tmp_path / "pose.npz")
    again = bidmp.load(tmp_path / "pose.npz")
    np.testing.assert_array_equal(again.rollout(), model.rollout())


def test_pose_bidmp_learns_both_forcing_terms_and_forgets_nothing(demo):
    base = pose_demo([[0, 0, 100], [0, 0, 40], [0, 0, 0]], [0.0, 0.0, 0.5])
    second = pose_demo([[0, 0, 100], [-50, 60, 40], [-90, 120, 10]], [-0.3, 0.2, -0.6])
    model = CartesianBiDMP(CartesianDMP().fit(base)).learn(demo).learn(second)
    for skill_demo in (demo, second):
        rollout = model.rollout(skill_demo[-1])
        assert np.linalg.norm(rollout[-1, :3] - skill_demo[-1, :3]) <= 0.05
        assert np.degrees(angle_between(rollout[-1:, 3:], skill_demo[-1:, 3:]))[0] <= 0.05
    # Faithful: each learned pose skill reproduces its demonstration about as well as a pose
    # DMP fitted on it alone (positions within 5 %, orientation within 0.05 degrees of it).
    for skill, skill_demo in ((1, demo), (2, second)):
        learned = model.rollout(skill_demo[-1], skill=skill)[: len(skill_demo)]
        scratch = CartesianDMP().fit(skill_demo).rollout()[: len(skill_demo)]
        for poses in (learned, scratch):
            assert np.all(np.isfinite(poses))
        position_error = [
            np.sqrt(np.mean(np.sum((r[:, :3] - skill_demo[:, :3]) ** 2, axis=1)))
            for r in (learned, scratch)
        ]
        angle_error = [
            np.degrees(angle_between(r[:, 3:], skill_demo[:, 3:])).max() for r in (learned, scratch)
        ]
        assert (
            position_error[0] <= 1.05 * position_error[1] + 1e-6
            and angle_error[0] <= angle_error[1] + 0.05
        )
    # (pose_forgetting's "nearest" is zero by the library's construction: an architecture guard.)
    assert np.all(pose_forgetting(CartesianDMP().fit(base), [demo, second], skill="nearest") == 0.0)
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        bidmp.save(model, f"{folder}/poses.npz")
        again = bidmp.load(f"{folder}/poses.npz")
    for query in (demo[-1], second[-1], base[-1]):
        np.testing.assert_array_equal(again.rollout(query), model.rollout(query))


def test_the_kept_approach_keeps_its_pose_relative_to_the_target():
    flat = pose_demo([[-80, -120, 200], [0, 0, 40], [0, 0, 0]], [0.0, 0.0, 0.0])
    tilt = Rotation.from_euler("x", 30, degrees=True)
    target = np.concatenate(
        [[150.0, 25.0, 20.0], (tilt * Rotation.from_quat(flat[-1, 3:])).as_quat()]
    )
    extension = extend_pose_demonstration(flat, target, seed=0)
    orientations = extension.orientations
    np.testing.assert_array_equal(extension.poses, np.hstack([extension.complete, orientations]))
    start = extension.approach_index
    n = len(flat) - start  # the kept approach: the last n samples (the transfer may take longer)
    kept = extension.complete[-n:]
    expected = target[:3] + tilt.apply(flat[start:, :3] - flat[-1, :3])
    np.testing.assert_allclose(kept, expected, rtol=0, atol=1e-9)
    assert (
        np.max(
            angle_between(
                orientations[-n:], (tilt * Rotation.from_quat(flat[start:, 3:])).as_quat()
            )
        )
        <= 1e-9
    )
    assert np.max(np.abs(np.linalg.norm(orientations, axis=1) - 1.0)) <= 1e-12


@pytest.fixture(scope="module")
def tilted_report():
    return bidmp.evaluate("nut-unscrewing-tilted", ["dmp", "bidmp"])


def test_tilted_pack_bidmp_succeeds_on_every_nut_including_the_axis(tilted_report):
    result = tilted_report.methods["bidmp"]
    assert (
        result.task_successes == 14
        and result.aligned == 14
        and result.engaged == 14
        and result.collision_free == 14
    )
    assert max(result.axis_deviations.values()) <= 2.0
    data = tilted_report.to_dict()["methods"]["bidmp"]
    assert data["aligned"] == 14 and data["targets"]["12"]["axis_deviation"] is not None
    assert tilted_report.methods["dmp"].task_successes == 8


def test_tilted_pack_in_the_simulator(tilted_report):
    pytest.importorskip("pybullet")
    from bidmp import sim

    result = sim.simulate(tilted_report.scenario, ["bidmp"], targets=["12", "6"], workers=1)
    method = result.methods["bidmp"]
    assert method.task_successes == 2 and method.aligned == 2
    assert json.dumps(result.to_dict())  # serialisable


def test_cli_fits_and_rolls_out_a_pose_recording(tmp_path, capsys):
    from bidmp.cli import main

    positions, t = kinesthetic_recording([[0, 0, 120], [60, -40, 60], [120, 10, 0]], seed=4)
    s = (t - t[0]) / (t[-1] - t[0])
    quaternions = (Rotation.from_rotvec(np.outer(s, [0.2, 0.1, 0.6])) * DOWN).as_quat()
    save_poses(np.hstack([positions, quaternions]), tmp_path / "poses.csv", times=t)
    assert (
        main(["fit", str(tmp_path / "poses.csv"), "-o", str(tmp_path / "m.npz"), "--units", "mm"])
        == 0
    )
    assert "pose DMP" in capsys.readouterr().out
    goal = [150.0, 20.0, 0.0, *(Rotation.from_euler("z", 45, degrees=True) * DOWN).as_quat()]
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "m.npz"),
                "--goal",
                *map(str, goal),
                "-o",
                str(tmp_path / "r.csv"),
            ]
        )
        == 0
    )
    poses, stamps = read_poses(tmp_path / "r.csv")
    assert np.linalg.norm(poses[-1, :3] - goal[:3]) <= 0.15
    assert np.degrees(angle_between(poses[-1:, 3:], np.array(goal[3:])[None]))[0] <= 0.1
    assert (
        main(
            ["rollout", str(tmp_path / "m.npz"), "--goal", "1", "2", "-o", str(tmp_path / "x.csv")]
        )
        == 2
    )


# --- turns past 180 degrees, still parts, one pose API --------------------------------
def screw_turn(degrees, n_steps=400, pitch=1.25):
    """A nutrunner's demonstration: the socket turns ``degrees`` about its own (vertical) axis,
    minimum jerk, and rises by the M8 thread's pitch per turn (mm)."""
    s = minimum_jerk([[0.0], [1.0]], n_steps)[:, 0]
    axis = DOWN.apply([0.0, 0.0, 1.0])
    rotations = Rotation.from_rotvec(np.outer(s * np.radians(degrees), axis)) * DOWN
    positions = np.column_stack([np.zeros(n_steps), np.zeros(n_steps), s * pitch * degrees / 360.0])
    return np.column_stack([positions, rotations.as_quat()]), np.linspace(0.0, 4.0, n_steps)


def turned_angle(quaternions):
    """The whole angle (deg) turned from the first to the last orientation, several turns included."""
    from bidmp.primitives import orientation_error

    return np.degrees(np.linalg.norm(orientation_error(quaternions, quaternions[-1])[0]))


@pytest.mark.parametrize("degrees", [190, 270, 360, 720])
@pytest.mark.parametrize("protocol", ["robot", "paper"])
def test_turns_past_180_degrees_are_reproduced(degrees, protocol):
    """before the fix, SciPy's principal rotation vector wrapped at 180 degrees, and
    190 / 270 / 360 degree turns reproduced 155 / 178 / 171 degrees off."""
    poses, t = screw_turn(degrees)
    model = CartesianDMP(DMP(protocol=protocol)).fit(poses, t, units="mm")
    reproduction = model.rollout()[: len(poses)]
    # The README: robot 0.001-0.004 degrees, paper (explicit Euler) 0.1-0.4 degrees.
    assert np.degrees(angle_between(reproduction[:, 3:], poses[:, 3:])).max() <= (
        0.01 if protocol == "robot" else 0.5
    )
    assert turned_angle(reproduction[:, 3:]) == pytest.approx(degrees, abs=0.5)
    timed = model.trajectory()
    # The angular velocity integrates to the whole turn (an independent check of omega).
    turned = np.sum(0.5 * (timed.omega[1:] + timed.omega[:-1]) * np.diff(timed.t)[:, None], axis=0)
    assert np.degrees(np.linalg.norm(turned)) == pytest.approx(degrees, rel=0.01)


def test_a_multi_turn_skill_keeps_its_turns_for_a_new_start_and_goal():
    poses, t = screw_turn(720)
    model = CartesianDMP().fit(poses, t)
    axis = DOWN.apply([0.0, 0.0, 1.0])  # the tool axis the demonstration turns about
    goal = poses[-1].copy()
    goal[3:] = (
        Rotation.from_rotvec(np.radians(20) * axis) * Rotation.from_quat(poses[-1, 3:])
    ).as_quat()
    start = poses[0].copy()
    start[3:] = (
        Rotation.from_rotvec(np.radians(-15) * axis) * Rotation.from_quat(poses[0, 3:])
    ).as_quat()
    moved = model.trajectory(goal, start=start)
    assert np.degrees(angle_between(moved.q[-1:], goal[None, 3:]))[0] <= 0.1
    assert turned_angle(moved.q) == pytest.approx(
        720 + 20 + 15, abs=1.0
    )  # the same two turns, plus the offsets


def test_movement_primitives_agrees_on_a_270_degree_turn():
    mp = pytest.importorskip("movement_primitives.dmp")
    poses, t = screw_turn(270)
    metres = poses.copy()
    metres[:, :3] /= 1000.0
    scalar_first = np.hstack([metres[:, :3], metres[:, [6, 3, 4, 5]]])
    peer = mp.CartesianDMP(execution_time=t[-1], dt=t[1], n_weights_per_dim=50, int_dt=0.001)
    peer.imitate(t, scalar_first)
    peer.configure(start_y=scalar_first[0], goal_y=scalar_first[-1])
    theirs = peer.open_loop()[1][:, [4, 5, 6, 3]]
    ours = CartesianDMP().fit(metres, t).rollout()[: len(theirs)]
    # Both follow the whole turn: within 2 degrees of each other (movement_primitives itself is
    # 1.3 degrees off the demonstration here; bidmp 0.002).
    assert np.degrees(angle_between(ours[:, 3:], theirs)).max() <= 2.0
    assert np.degrees(angle_between(ours[:, 3:], poses[: len(ours), 3:])).max() <= 0.1


def test_a_constant_orientation_and_a_rotation_in_place_fit_and_reproduce():
    """before the fix, both were refused with "y is degenerate: all 200 points are
    identical", about the part that does not move."""
    positions = minimum_jerk([[0, 0, 100], [80, 20, 40], [150, 25, 0]], 300)
    t = np.linspace(0.0, 3.0, 300)
    straight_down = np.column_stack([positions, np.repeat(DOWN.as_quat()[None], 300, axis=0)])
    model = CartesianDMP().fit(straight_down, t, units="mm")
    reproduction = model.rollout()[:300]
    assert np.abs(reproduction[:, :3] - positions).max() <= 0.05
    assert np.degrees(angle_between(reproduction[:, 3:], straight_down[:, 3:])).max() <= 1e-9
    # A turned goal for a part that did not move: it turns in step with the motion's progress.
    goal = straight_down[-1].copy()
    goal[3:] = (Rotation.from_euler("z", 40, degrees=True) * DOWN).as_quat()
    moved = model.trajectory(goal)
    turned = np.degrees(angle_between(moved.q, np.repeat(DOWN.as_quat()[None], len(moved), axis=0)))
    assert turned[-1] == pytest.approx(40.0, abs=0.01)
    assert np.all(np.diff(turned) >= -1e-4 * 40) and turned.max() <= 40.0 * (
        1 + 1e-4
    )  # monotone, to 1e-4 of the turn
    progress = np.linalg.norm(moved.y - moved.y[0], axis=1) > 0.5 * np.linalg.norm(
        goal[:3] - moved.y[0]
    )
    assert 5.0 < turned[np.argmax(progress)] < 35.0  # half-way along the path, part of the turn

    in_place, t = screw_turn(90)
    in_place[:, :3] = [10.0, 20.0, 30.0]
    model = CartesianDMP().fit(in_place, t)
    reproduction = model.rollout()[: len(in_place)]
    assert np.abs(reproduction[:, :3] - in_place[:, :3]).max() <= 1e-9
    assert np.degrees(angle_between(reproduction[:, 3:], in_place[:, 3:])).max() <= 0.05
    moved = model.trajectory(np.r_[40.0, 20.0, 30.0, in_place[-1, 3:]])
    assert np.linalg.norm(moved.y[-1] - [40.0, 20.0, 30.0]) <= 0.01
    with pytest.raises(
        ValueError, match="poses: the demonstration does not move: all 400 poses are the same"
    ):
        CartesianDMP().fit(np.repeat(in_place[:1], 400, axis=0))


def test_the_pose_api_mirrors_the_position_api(demo, tmp_path):
    """PoseTrajectory mirrors Trajectory, the steppers return the same triple, goal_
    is named alike, CartesianBiDMP is an estimator with trajectory(), the pose extension returns
    one object and the pose CSV carries accelerations."""
    import dataclasses

    from sklearn.base import clone

    t = np.linspace(0.0, 2.0, len(demo))
    model = CartesianDMP().fit(demo, t, units="mm")
    assert model.goal_.shape == (7,) and model.start_.shape == (7,)
    motion = model.trajectory()
    position = model.position_.trajectory()
    for name in ("t", "y", "yd", "ydd", "units"):
        np.testing.assert_array_equal(getattr(motion, name), getattr(position, name))
    assert motion.duration == position.duration and len(motion) == len(position)
    assert motion.peak_speed() == position.peak_speed()
    with pytest.raises(dataclasses.FrozenInstanceError):
        motion.t = None
    names, data = motion.columns()
    assert names[:8] == ["t", "x", "y", "z", "qx", "qy", "qz", "qw"] and data.shape == (
        len(motion),
        len(names),
    )
    assert {"ax", "ay", "az", "dwx", "dwy", "dwz"} <= set(names)
    save_poses(motion, tmp_path / "m.csv")
    first, header = (tmp_path / "m.csv").read_text().splitlines()[:2]
    assert first == "# units: mm" and header.split(",") == names
    assert bidmp.io.declared_units(tmp_path / "m.csv") == "mm"
    np.testing.assert_allclose(read_poses(tmp_path / "m.csv")[0], motion.poses, atol=1e-12)
    # The angular acceleration is the derivative of the angular velocity.
    np.testing.assert_allclose(
        np.gradient(motion.omega, motion.t, axis=0)[2:-2],
        motion.omega_dot[2:-2],
        atol=0.02 * np.abs(motion.omega_dot).max(),
    )
    # Steppers: (command, velocity, acceleration), the pose ones 7 / 6 / 6 wide, equal to trajectory().
    stepper = model.stepper()
    commands = [stepper.step(motion.t[1]) for _ in range(len(motion))]
    assert [c.shape for c in commands[0]] == [(7,), (6,), (6,)]
    np.testing.assert_allclose(np.array([c[0] for c in commands]), motion.poses, atol=1e-8)
    np.testing.assert_allclose(
        np.array([c[1] for c in commands]), np.hstack([motion.yd, motion.omega]), atol=1e-6
    )
    np.testing.assert_allclose(
        np.array([c[2] for c in commands]),
        np.hstack([motion.ydd, motion.omega_dot]),
        atol=1e-4 * np.abs(motion.ydd).max(),
    )
    # CartesianBiDMP: parameters in __init__, clone, fit, trajectory.
    skills = CartesianBiDMP(model, bidmp.BiDMP(increments=(10,)))
    assert clone(skills).get_params()["bidmp__increments"] == (10,)
    fitted = CartesianBiDMP(bidmp=bidmp.BiDMP(increments=(10,))).fit(demo, t, units="mm")
    np.testing.assert_allclose(fitted.trajectory().poses, motion.poses, atol=1e-9)
    extension = extend_pose_demonstration(
        demo, np.r_[demo[-1, :3] + [60.0, 30.0, 0.0], demo[-1, 3:]], seed=0
    )
    skills.learn(extension.poses)
    learned = skills.trajectory(extension.poses[-1])
    assert np.linalg.norm(learned.y[-1] - extension.poses[-1, :3]) <= 0.1
    assert isinstance(learned, type(motion))


def test_pose_parameters_after_fit_follow_the_position_rules(demo):
    """Only tau may change after fit (it slows both parts); a learned parameter unfits the model."""
    from bidmp.primitives.cartesian import _PART_PARAMS

    assert set(_PART_PARAMS) == set(DMP().get_params())
    assert set(CartesianDMP(DMP()).get_params()) == {"dmp"} | {
        f"dmp__{name}" for name in _PART_PARAMS
    }
    t = np.linspace(0.0, 2.0, len(demo))
    model = CartesianDMP(DMP()).fit(demo, t)
    nominal = model.trajectory()
    model.set_params(dmp__tau=2.0)
    slow = model.trajectory()
    assert slow.duration == pytest.approx(2 * nominal.duration, abs=slow.t[1])  # within one sample
    n = min(len(slow.q[::2]), len(nominal))
    np.testing.assert_allclose(
        slow.q[::2][:n], nominal.q[:n], atol=1e-4
    )  # the same turn, twice as slow
    model.dmp.alpha = 80.0
    with pytest.raises(bidmp.NotFittedError, match="alpha"):
        model.rollout()
