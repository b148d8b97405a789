"""Pose skills (issue 13): CartesianDMP against movement_primitives and closed forms, pose files,
pose Bi-DMP, the pose extension and the tilted pack."""

import json
import warnings

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bidmp
from bidmp.cartesian import CartesianBiDMP, CartesianDMP, angle_between, left_jacobian, pose_forgetting, prepare_poses
from bidmp.datasets import kinesthetic_recording, minimum_jerk
from bidmp.extension import extend_pose_demonstration
from bidmp.io import read_poses, save_poses

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
    goal[3:] = (Rotation.from_euler("z", 90, degrees=True) * Rotation.from_quat(demo[-1, 3:])).as_quat()
    for query in (None, goal):
        trajectory = model.trajectory(goal=query)
        assert np.max(np.abs(np.linalg.norm(trajectory.orientation, axis=1) - 1.0)) <= 1e-12
    assert np.degrees(angle_between(trajectory.orientation[-1:], goal[None, 3:]))[0] <= 0.1
    assert np.linalg.norm(trajectory.position[-1] - goal[:3]) <= 0.15
    # The angular velocity is the derivative of the orientation (world frame): the explicit-Euler
    # step from sample l to l + 1, to first order in dt.
    dt = trajectory.t[1] - trajectory.t[0]
    step = Rotation.from_quat(trajectory.orientation[1:]) * Rotation.from_quat(trajectory.orientation[:-1]).inv()
    numeric = step.as_rotvec() / dt
    assert np.max(np.linalg.norm(numeric - trajectory.angular_velocity[:-1], axis=1)) <= \
        0.01 * np.max(np.linalg.norm(numeric, axis=1))


def test_left_jacobian_against_finite_differences():
    rng = np.random.default_rng(0)
    for r in rng.normal(0.0, 1.0, size=(5, 3)):
        rdot = rng.normal(size=3)
        h = 1e-6
        numeric = (Rotation.from_rotvec(r + h * rdot) * Rotation.from_rotvec(r).inv()).as_rotvec() / h
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
    rows = np.column_stack([t, positions, quaternions[:, [3, 0, 1, 2]]])  # the logger writes qw first
    path.write_text("t,x,y,z,qw,qx,qy,qz\n" + "\n".join(",".join(repr(float(v)) for v in row) for row in rows))
    poses, stamps = read_poses(path)
    np.testing.assert_allclose(poses[:, 3:], quaternions, atol=1e-12)
    with pytest.warns(UserWarning, match="not of unit length"):
        prepared, prepared_t, info = prepare_poses(poses, stamps, units="mm")
    model = CartesianDMP().fit(prepared, prepared_t, units="mm")
    from scipy.spatial.transform import Slerp

    reproduction = model.trajectory()  # the motion, then 10 % at rest (robot protocol)
    motion = reproduction.t <= prepared_t[-1]
    truth = Slerp(t - t[0], rotations)(reproduction.t[motion] + info.start_s)
    rms = np.sqrt(np.mean(np.degrees(angle_between(reproduction.orientation[motion], truth.as_quat())) ** 2))
    assert rms <= 0.5
    # Fitted raw, the sensor noise (0.05 degrees per sample) is differentiated twice: far worse.
    with pytest.warns(UserWarning, match="not of unit length"):
        raw = CartesianDMP().fit(poses, stamps).trajectory()
    raw_truth = Slerp(t - t[0], rotations)(np.clip(raw.t, 0, t[-1] - t[0]))
    assert np.sqrt(np.mean(np.degrees(angle_between(raw.orientation, raw_truth.as_quat())) ** 2)) > 2 * rms


def test_agreement_with_movement_primitives_cartesian_dmp(demo):
    mp = pytest.importorskip("movement_primitives.dmp")
    t = np.linspace(0.0, 2.0, len(demo))
    metres = demo.copy()
    metres[:, :3] /= 1000.0
    scalar_first = np.hstack([metres[:, :3], metres[:, [6, 3, 4, 5]]])
    peer = mp.CartesianDMP(execution_time=2.0, dt=t[1], n_weights_per_dim=50, int_dt=0.001)
    peer.imitate(t, scalar_first)
    peer.configure(start_y=scalar_first[0], goal_y=scalar_first[-1])
    theirs = peer.open_loop()[1][:, [4, 5, 6, 3]]
    # The same gains (alpha_y = 25, beta_y = 6.25), 50 weights, and the phase decaying to 0.01.
    ours = CartesianDMP(protocol="paper", alpha=25.0, beta=6.25, K="paper", n_kernels=50,
                        alpha_phase=-np.log(0.01)).fit(metres, t).trajectory(dt=t[1])
    n = min(len(theirs), len(ours.t))
    extent = angle_between(demo[:1, 3:], demo[-1:, 3:])[0]
    assert np.max(angle_between(ours.orientation[:n], theirs[:n])) <= 0.01 * extent


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
    with pytest.raises(ValueError, match="accepted headers: t,x,y,z,qw,qx,qy,qz or t,x,y,z,qx,qy,qz,qw"):
        read_poses(path)
    pose = tmp_path / "q.csv"
    pose.write_text("t,x,y,z,qx,qy,qz,qw\n0,0,0,0,0,0,0,1\n0.1,1,0,0,0,0,0,1\n0.2,2,0,0,0,0,0,1\n")
    with pytest.raises(ValueError, match="a pose recording: read it with bidmp.io.read_poses"):
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
    forgetting = pose_forgetting(CartesianDMP().fit(base), [demo, second], skill="nearest")
    assert np.all(forgetting == 0.0)
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        bidmp.save(model, f"{folder}/poses.npz")
        again = bidmp.load(f"{folder}/poses.npz")
    for query in (demo[-1], second[-1], base[-1]):
        np.testing.assert_array_equal(again.rollout(query), model.rollout(query))


def test_the_kept_approach_keeps_its_pose_relative_to_the_target():
    flat = pose_demo([[-80, -120, 200], [0, 0, 40], [0, 0, 0]], [0.0, 0.0, 0.0])
    tilt = Rotation.from_euler("x", 30, degrees=True)
    target = np.concatenate([[150.0, 25.0, 20.0], (tilt * Rotation.from_quat(flat[-1, 3:])).as_quat()])
    extension, orientations = extend_pose_demonstration(flat, target, seed=0)
    start = extension.approach_index
    kept = extension.complete[start:]
    expected = target[:3] + tilt.apply(flat[start:, :3] - flat[-1, :3])
    np.testing.assert_allclose(kept, expected, rtol=0, atol=1e-9)
    assert np.max(angle_between(orientations[start:], (tilt * Rotation.from_quat(flat[start:, 3:])).as_quat())) <= 1e-9
    assert np.max(np.abs(np.linalg.norm(orientations, axis=1) - 1.0)) <= 1e-12


@pytest.fixture(scope="module")
def tilted_report():
    return bidmp.evaluate("nut-unscrewing-tilted", ["dmp", "bidmp"])


def test_tilted_pack_bidmp_succeeds_on_every_nut_including_the_axis(tilted_report):
    result = tilted_report.methods["bidmp"]
    assert result.task_successes == 14 and result.aligned == 14 and result.engaged == 14 and result.collision_free == 14
    assert max(result.axis_deviations.values()) <= 2.0
    data = tilted_report.to_dict()["methods"]["bidmp"]
    assert data["aligned"] == 14 and data["targets"]["12"]["axis_deviation"] is not None
    assert tilted_report.methods["dmp"].task_successes == 8


def test_tilted_pack_in_the_simulator(tilted_report):
    pytest.importorskip("pybullet")
    from bidmp import sim

    result = sim.simulate(tilted_report.scenario, ["bidmp"], targets=["12", "6"], report=tilted_report, workers=1)
    method = result.methods["bidmp"]
    assert method.task_successes == 2 and method.aligned == 2
    assert json.dumps(result.to_dict())  # serialisable


def test_cli_fits_and_rolls_out_a_pose_recording(tmp_path, capsys):
    from bidmp.cli import main

    positions, t = kinesthetic_recording([[0, 0, 120], [60, -40, 60], [120, 10, 0]], seed=4)
    s = (t - t[0]) / (t[-1] - t[0])
    quaternions = (Rotation.from_rotvec(np.outer(s, [0.2, 0.1, 0.6])) * DOWN).as_quat()
    save_poses(np.hstack([positions, quaternions]), tmp_path / "poses.csv", times=t)
    assert main(["fit", str(tmp_path / "poses.csv"), "-o", str(tmp_path / "m.npz"), "--units", "mm"]) == 0
    assert "pose DMP" in capsys.readouterr().out
    goal = [150.0, 20.0, 0.0, *(Rotation.from_euler("z", 45, degrees=True) * DOWN).as_quat()]
    assert main(["rollout", str(tmp_path / "m.npz"), "--goal", *map(str, goal), "-o", str(tmp_path / "r.csv")]) == 0
    poses, stamps = read_poses(tmp_path / "r.csv")
    assert np.linalg.norm(poses[-1, :3] - goal[:3]) <= 0.15
    assert np.degrees(angle_between(poses[-1:, 3:], np.array(goal[3:])[None]))[0] <= 0.1
    assert main(["rollout", str(tmp_path / "m.npz"), "--goal", "1", "2", "-o", str(tmp_path / "x.csv")]) == 2
