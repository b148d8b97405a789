"""joint-space recordings (``t,<joint names>``) fit a joint-space DMP (one dimension per
joint); ``bidmp rollout --joint-limits panda`` (or one limit per joint) times the motion so every
joint stays within its own velocity, acceleration and jerk limit, measured on the written samples
(velocity and acceleration as written, jerk by differences of the written accelerations)."""

import numpy as np

from bidmp.cli import main
from bidmp.sim.robots import PANDA

NAMES = [f"panda_joint{k}" for k in range(1, 8)]


def _joint_csv(path, rng, duration=3.0, n=300):
    s = np.linspace(0.0, 1.0, n)
    q = np.array([0, -0.785, 0, -2.356, 0, 1.571, 0.785]) + np.outer(
        10 * s**3 - 15 * s**4 + 6 * s**5, rng.uniform(-1.2, 1.2, 7)
    )
    np.savetxt(
        path,
        np.column_stack([s * duration, q]),
        delimiter=",",
        header="t," + ",".join(NAMES),
        comments="",
    )
    return q


def _rows(path):
    lines = [line for line in path.read_text().splitlines() if line and not line.startswith("#")][
        1:
    ]
    return np.array([[float(v) for v in line.split(",")] for line in lines])


def test_a_joint_space_motion_at_full_speed_stays_within_every_joints_limits(tmp_path, capsys):
    rng = np.random.default_rng(0)
    for trial in range(3):
        q = _joint_csv(tmp_path / "j.csv", rng, duration=float(rng.uniform(0.5, 3.0)))
        assert main(["fit", str(tmp_path / "j.csv"), "-o", str(tmp_path / "j.npz"), "--raw"]) == 0
        assert (
            main(
                [
                    "rollout",
                    str(tmp_path / "j.npz"),
                    "--rate",
                    "1000",
                    "--joint-limits",
                    "panda",
                    "--fastest",
                    "-o",
                    str(tmp_path / "r.csv"),
                ]
            )
            == 0
        )
        rows = _rows(tmp_path / "r.csv")
        t, position, velocity, acceleration = (
            rows[:, 0],
            rows[:, 1:8],
            rows[:, 8:15],
            rows[:, 15:22],
        )
        jerk = np.diff(acceleration, axis=0) / np.diff(t)[:, None]
        shares = [
            np.max(np.abs(velocity) / PANDA.velocity),
            np.max(np.abs(acceleration) / PANDA.acceleration),
            np.max(np.abs(jerk) / PANDA.jerk),
        ]
        assert max(shares) <= 1.0 + 1e-6, (trial, shares)
        assert max(shares) >= 0.99  # --fastest: one of them binds
        np.testing.assert_allclose(position[-1], q[-1], atol=1e-3)
    capsys.readouterr()


def test_one_limit_per_joint_is_per_joint_and_a_wrong_count_is_refused(tmp_path, capsys):
    _joint_csv(tmp_path / "j.csv", np.random.default_rng(1))
    assert main(["fit", str(tmp_path / "j.csv"), "-o", str(tmp_path / "j.npz"), "--raw"]) == 0
    limits = [0.1, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7]
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "j.npz"),
                "--rate",
                "500",
                "--max-speed",
                *map(str, limits),
                "-o",
                str(tmp_path / "r.csv"),
            ]
        )
        == 0
    )
    velocity = _rows(tmp_path / "r.csv")[:, 8:15]
    assert np.all(np.max(np.abs(velocity), axis=0) <= np.array(limits) * (1 + 1e-6))
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "j.npz"),
                "--max-speed",
                "1",
                "2",
                "-o",
                str(tmp_path / "r.csv"),
            ]
        )
        == 2
    )
    assert "one per dimension" in capsys.readouterr().err


def test_rollout_plot_shows_a_joint_space_motion_and_its_rates(tmp_path, capsys):
    """``--plot`` on a 7-joint model (before: refused, a path plot takes 1-3 dimensions): the
    joints against time beside speed and acceleration; a PNG of real size."""
    _joint_csv(tmp_path / "j.csv", np.random.default_rng(2))
    assert main(["fit", str(tmp_path / "j.csv"), "-o", str(tmp_path / "j.npz"), "--raw"]) == 0
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "j.npz"),
                "--rate",
                "100",
                "-o",
                str(tmp_path / "r.csv"),
                "--plot",
                str(tmp_path / "r.png"),
            ]
        )
        == 0
    )
    data = (tmp_path / "r.png").read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 20_000
    width, height = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
    assert width > 1.8 * height  # two panels side by side


def test_a_joint_recording_is_in_radians_and_refuses_a_length_unit(tmp_path, capsys):
    _joint_csv(tmp_path / "j.csv", np.random.default_rng(2))
    assert main(["fit", str(tmp_path / "j.csv"), "-o", str(tmp_path / "j.npz"), "--raw"]) == 0
    assert "units rad" in capsys.readouterr().out
    from bidmp.io.models import load_model

    assert load_model(tmp_path / "j.npz").units_ == "rad"
    assert (
        main(
            [
                "fit",
                str(tmp_path / "j.csv"),
                "-o",
                str(tmp_path / "k.npz"),
                "--raw",
                "--units",
                "mm",
            ]
        )
        == 2
    )
    assert (
        "its columns read as joints" in capsys.readouterr().err
    )  # and how to say they are positions


def _fk(q, robot):
    """Forward kinematics of the bare arm (no tool), on an independent PyBullet world."""
    import pybullet as p
    import pybullet_data

    client = p.connect(p.DIRECT)
    try:
        urdf = {"panda": "franka_panda/panda.urdf", "iiwa": "kuka_iiwa/model.urdf"}[robot]
        body = p.loadURDF(
            f"{pybullet_data.getDataPath()}/{urdf}", useFixedBase=True, physicsClientId=client
        )
        movable = [
            j
            for j in range(p.getNumJoints(body, physicsClientId=client))
            if p.getJointInfo(body, j, physicsClientId=client)[2] != p.JOINT_FIXED
        ][:7]
        for joint, value in zip(movable, q):
            p.resetJointState(body, joint, float(value), physicsClientId=client)
        flange = movable[-1] + (
            1 if robot == "panda" else 0
        )  # the Panda's flange link8 follows joint 7
        return np.array(
            p.getLinkState(body, flange, computeForwardKinematics=1, physicsClientId=client)[4]
        )
    finally:
        p.disconnect(client)


def test_rollout_to_a_cartesian_goal_through_the_robots_inverse_kinematics(tmp_path, capsys):
    import pytest

    pytest.importorskip("pybullet")
    _joint_csv(tmp_path / "j.csv", np.random.default_rng(3))
    assert main(["fit", str(tmp_path / "j.csv"), "-o", str(tmp_path / "j.npz"), "--raw"]) == 0
    rng = np.random.default_rng(4)
    for robot in ("panda", "iiwa"):
        goal = np.array([rng.uniform(0.45, 0.6), rng.uniform(-0.2, 0.2), rng.uniform(0.2, 0.45)])
        assert (
            main(
                [
                    "rollout",
                    str(tmp_path / "j.npz"),
                    "--robot",
                    robot,
                    "--cartesian-goal",
                    *map(str, goal),
                    "--joint-limits",
                    robot,
                    "-o",
                    str(tmp_path / "r.csv"),
                ]
            )
            == 0
        )
        end = _rows(tmp_path / "r.csv")[-1, 1:8]
        # The independent FK of the motion's last joints puts the flange on the goal.
        assert np.linalg.norm(_fk(end, robot) - goal) <= 1e-3, robot
    capsys.readouterr()
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "j.npz"),
                "--cartesian-goal",
                "3",
                "0",
                "0",
                "-o",
                str(tmp_path / "r.csv"),
            ]
        )
        == 2
    )
    assert "reach" in capsys.readouterr().err


def test_joint_limits_from_a_scenarios_own_robot(tmp_path, capsys):
    """--joint-limits SCENARIO: the limits of the robot the scenario names (here its own URDF's,
    slower than any built-in arm), each joint within its own, one of them binding."""
    import json

    from bidmp.tasks import scenarios

    spec = json.loads(scenarios.builtin_text("nut-unscrewing"))
    velocity = [0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6]
    spec["robot"] = {
        "urdf": "kuka_iiwa/model.urdf",
        "flange": "lbr_iiwa_link_7",
        "limits": {
            "lower": [-2.9] * 7,
            "upper": [2.9] * 7,
            "velocity": velocity,
            "acceleration": [2.0] * 7,
            "jerk": [50.0] * 7,
        },
    }
    (tmp_path / "cell.json").write_text(json.dumps(spec))
    _joint_csv(tmp_path / "j.csv", np.random.default_rng(5))
    assert main(["fit", str(tmp_path / "j.csv"), "-o", str(tmp_path / "j.npz"), "--raw"]) == 0
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "j.npz"),
                "--rate",
                "1000",
                "--joint-limits",
                str(tmp_path / "cell.json"),
                "--fastest",
                "-o",
                str(tmp_path / "r.csv"),
            ]
        )
        == 0
    )
    rows = _rows(tmp_path / "r.csv")
    t, velocities, accelerations = rows[:, 0], rows[:, 8:15], rows[:, 15:22]
    jerk = np.diff(accelerations, axis=0) / np.diff(t)[:, None]
    shares = [
        np.max(np.abs(velocities) / velocity),
        np.max(np.abs(accelerations) / 2.0),
        np.max(np.abs(jerk) / 50.0),
    ]
    assert max(shares) <= 1.0 + 1e-6 and max(shares) >= 0.99, shares
    capsys.readouterr()
