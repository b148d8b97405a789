"""Your own robot in the simulator: the KUKA iiwa of pybullet_data on the nut task,
a URDF named in a scenario, its validation, and the one-line message for targets out of reach."""

import json

import numpy as np
import pytest

pytest.importorskip("pybullet")

from bidmp import sim  # noqa: E402
from bidmp.cli import main  # noqa: E402
from bidmp.tasks import ScenarioError, evaluate, scenarios  # noqa: E402


def nut_spec(**robot):
    spec = json.loads(scenarios.builtin_text("nut-unscrewing"))
    spec["robot"] = robot
    return spec


@pytest.fixture(scope="module")
def iiwa():
    return scenarios.load("nut-unscrewing-iiwa")


def test_the_iiwa_runs_the_nut_task_within_its_own_limits(iiwa):
    report = sim.execution_report(iiwa, ["bidmp"])
    labels = ["1", "11", "12"]  # the demonstration's start side, and the two furthest nuts
    result = sim.simulate(iiwa, ["bidmp"], targets=labels, report=report, workers=1)
    assert result.robot == "iiwa" and result.limits == sim.IIWA
    method = result.methods["bidmp"]
    assert method.task_successes == 3 and method.contacts == 0 and method.within_limits == 3
    for _label, target in method.targets.items():
        # The measured motion against the iiwa's limits, not the Panda's (the iiwa's joint speeds
        # are 0.75-1.2 rad/s lower: a plan timed to the Panda would break them).
        assert target.measured_peak_velocity <= 1.0 and target.measured_peak_acceleration <= 1.0
        assert target.peak_jerk <= 1.0 and target.measured_error <= iiwa.success_threshold
    assert "KUKA LBR iiwa" in result.summary()
    assert result.to_dict()["robot"]["model"] == "iiwa"


def test_plans_are_timed_to_the_arm_own_limits(iiwa):
    """The same path on the iiwa with its limits, then with every limit halved: the joint speeds
    stay within each model's own velocity limits, and the motion takes between 2^(1/3) times
    (jerk-bound) and 2 times (velocity-bound) as long: a property of time scaling."""
    import dataclasses

    report = evaluate(iiwa, ["bidmp"], geometry=False)
    rollout = report.methods["bidmp"].rollouts["11"]
    full = sim.ROBOT_MODELS["iiwa"]
    halved = dataclasses.replace(
        full,
        limits=sim.JointLimits(
            full.limits.lower,
            full.limits.upper,
            *(
                tuple(v / 2 for v in getattr(full.limits, name))
                for name in ("velocity", "acceleration", "jerk")
            ),
        ),
    )
    durations = []
    for model in (full, halved):
        with sim.RobotCell(iiwa.scene, iiwa.units, [50.0, -550.0, 0.0], 90.0, model) as cell:
            plan = cell.plan(rollout, "11")
            grid = np.linspace(0.0, 1.0, 4001)
            speeds = np.abs(plan.spline(grid, 1)) / plan.duration
            assert np.all(
                speeds.max(axis=0)
                <= np.asarray(model.limits.velocity) * sim.backend.LIMIT_MARGIN * 1.001
            )
            durations.append(plan.duration)
    assert 2 ** (1 / 3) - 1e-3 <= durations[1] / durations[0] <= 2.0 + 1e-3


def test_a_base_too_close_names_what_is_out_of_reach():
    scenario = scenarios.from_dict(nut_spec(model="iiwa", base=[50, -450, 0], yaw=90))
    targets = sim.simulate(scenario, ["dmp"], targets=["3", "4"], workers=1).methods["dmp"].targets
    for (
        target
    ) in targets.values():  # every motion starts there: every target is a row with the reason
        assert not target.ran and target.reason.startswith(
            "the demonstration's start is unreachable: for the iiwa at base"
        )
        assert "\n" not in target.reason


def test_the_default_placement_of_the_iiwa_reaches_the_task():
    spec = nut_spec(model="iiwa")
    scenario = scenarios.from_dict(spec)
    base, _ = sim.robot_placement(scenario)
    assert base[1] == pytest.approx(-120.0 - 430.0)  # its standoff, not the Panda's 330 mm
    result = sim.simulate(scenario, ["bidmp"], targets=["3"], workers=1)
    assert result.methods["bidmp"].task_successes == 1


def test_a_urdf_named_in_the_scenario(tmp_path):
    limits = {
        "lower": [-2.9, -2.0, -2.9, -2.0, -2.9, -2.0, -3.0],
        "upper": [2.9, 2.0, 2.9, 2.0, 2.9, 2.0, 3.0],
        "velocity": [1.0] * 7,
        "acceleration": [5.0] * 7,
        "jerk": [500.0] * 7,
    }
    spec = nut_spec(
        urdf="kuka_iiwa/model.urdf",
        flange="lbr_iiwa_link_7",
        limits=limits,
        rest=[0.0, 0.5, 0.0, -1.4, 0.0, 1.2, 0.0],
        base=[50, -550, 0],
    )
    scenario = scenarios.from_dict(spec)
    result = sim.simulate(scenario, ["bidmp"], targets=["3"], workers=1)
    assert result.robot == "model" and result.limits.velocity == (1.0,) * 7
    target = result.methods["bidmp"].targets["3"]
    assert result.methods["bidmp"].task_successes == 1 and target.peak_velocity <= 1.0
    # A URDF in the scenario's folder is read from there; outside it, refused.
    (tmp_path / "arm.urdf").write_text("<robot name='x'></robot>")
    local = scenarios.from_dict(
        nut_spec(urdf="arm.urdf", flange="tool0", limits=limits), base_dir=tmp_path
    )
    assert local.robot.urdf == str((tmp_path / "arm.urdf").resolve())
    with pytest.raises(ValueError, match="no link 'tool0'"):
        sim.simulate(local, ["dmp"], targets=["3"], workers=1)


@pytest.mark.parametrize(
    "robot, message",
    [
        (
            {"model": "kr6"},
            r"robot.model: expected one of \['panda', 'fr3', 'iiwa', 'xarm6', 'ur5'\]",
        ),
        ({"model": "iiwa", "urdf": "a.urdf"}, "not both"),
        ({"flange": "x"}, "describe your own"),
        ({"urdf": "a.urdf"}, "robot.flange"),
        ({"urdf": "a.txt", "flange": "x"}, r"robot.urdf: expected the path of a .urdf"),
        ({"urdf": "a.urdf", "flange": "x", "limits": {"lower": [0] * 7}}, "robot.limits: expected"),
        (
            {
                "urdf": "a.urdf",
                "flange": "x",
                "limits": {
                    "lower": [0] * 7,
                    "upper": [1] * 7,
                    "velocity": [1] * 6,
                    "acceleration": [1] * 7,
                },
            },
            r"robot.limits.velocity: expected 7",
        ),
        (
            {
                "urdf": "a.urdf",
                "flange": "x",
                "limits": {
                    "lower": [1] * 7,
                    "upper": [0] * 7,
                    "velocity": [1] * 7,
                    "acceleration": [1] * 7,
                },
            },
            "lower must be below upper",
        ),
        (
            {
                "urdf": "a.urdf",
                "flange": "x",
                "limits": {
                    "lower": [0] * 7,
                    "upper": [1] * 7,
                    "velocity": [-1] * 7,
                    "acceleration": [1] * 7,
                },
            },
            r"velocity\[0\]: must be > 0",
        ),
        ({"speed": 3}, r"unknown \['speed'\]"),
    ],
)
def test_robot_keys_are_validated_by_name(robot, message):
    with pytest.raises(ScenarioError, match=message):
        scenarios.from_dict(nut_spec(**robot))


def test_a_urdf_outside_the_scenario_folder_is_refused(tmp_path):
    outside = tmp_path / "arm.urdf"
    outside.write_text("<robot/>")
    inner = tmp_path / "cell"
    inner.mkdir()
    limits = {"lower": [0] * 7, "upper": [1] * 7, "velocity": [1] * 7, "acceleration": [1] * 7}
    with pytest.raises(ScenarioError, match="outside the scenario's folder"):
        scenarios.from_dict(nut_spec(urdf="../arm.urdf", flange="x", limits=limits), base_dir=inner)


def test_bidmp_sim_runs_the_iiwa_scenario(tmp_path, capsys):
    code = main(
        [
            "sim",
            "--scenario",
            "nut-unscrewing-iiwa",
            "--methods",
            "bidmp",
            "--targets",
            "3",
            "--no-pictures",
            "--workers",
            "1",
            "--out",
            str(tmp_path),
        ]
    )
    out = capsys.readouterr().out
    assert code == 0 and "KUKA LBR iiwa 7 R800" in out
    written = json.loads((tmp_path / "sim_results.json").read_text())
    assert written["robot"]["model"] == "iiwa"
    assert written["limits"]["velocity_rad_s"] == list(sim.IIWA.velocity)


def test_the_iiwa_runs_the_nut_job(iiwa):
    """On another arm: the same job, its plans timed to the iiwa's own limits."""
    from bidmp.sim.job import run_job

    report = run_job(iiwa, targets=["3", "12"])
    assert report.robot == "iiwa" and report.removed == 2
    assert all(not target.contacts and target.within_limits for target in report.targets)


# --- arms of six joints ---------------------------------------------------------------------
def dh_forward(q) -> np.ndarray:
    """Independent oracle: the UR5's flange pose (4, 4) from Universal Robots' published classic DH
    table, the product Rz(theta) Tz(d) Tx(a) Rx(alpha) written out here (not read from the URDF)."""
    table = (
        (0.089159, 0.0, np.pi / 2),
        (0.0, -0.425, 0.0),
        (0.0, -0.39225, 0.0),
        (0.10915, 0.0, np.pi / 2),
        (0.09465, 0.0, -np.pi / 2),
        (0.0823, 0.0, 0.0),
    )
    pose = np.eye(4)
    for (d, a, alpha), theta in zip(table, q):
        ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
        pose = pose @ np.array(
            [
                [ct, -st * ca, st * sa, a * ct],
                [st, ct * ca, -ct * sa, a * st],
                [0, sa, ca, d],
                [0, 0, 0, 1],
            ]
        )
    return pose


def test_the_ur5_urdf_is_its_published_dh_kinematics():
    """Independent oracle: PyBullet's forward kinematics of the written URDF against the DH product
    for 50 random joint vectors, the flange's position to 1 µm and its frame to 1e-6; and the file is
    the one the tool writes (structure guard)."""
    import sys
    from pathlib import Path

    p = sim.pybullet.world._pybullet_module()
    urdf = sim.UR5_MODEL.urdf if hasattr(sim, "UR5_MODEL") else sim.ROBOT_MODELS["ur5"].urdf
    tools = Path(__file__).resolve().parents[2] / "tools"
    sys.path.insert(0, str(tools))
    try:
        import ur5_urdf
    finally:
        sys.path.remove(str(tools))
    assert Path(urdf).read_text() == ur5_urdf.urdf()
    client = p.connect(p.DIRECT)
    try:
        robot = p.loadURDF(urdf, useFixedBase=True, physicsClientId=client)
        names = [
            p.getJointInfo(robot, j, physicsClientId=client)[12].decode()
            for j in range(p.getNumJoints(robot, physicsClientId=client))
        ]
        flange = names.index("flange")
        rng = np.random.default_rng(0)
        for _ in range(50):
            q = rng.uniform(-np.pi, np.pi, 6)
            for joint in range(6):
                p.resetJointState(robot, joint, q[joint], physicsClientId=client)
            state = p.getLinkState(
                robot, flange, computeForwardKinematics=1, physicsClientId=client
            )
            expected = dh_forward(q)
            np.testing.assert_allclose(state[4], expected[:3, 3], atol=1e-6)
            np.testing.assert_allclose(
                np.array(p.getMatrixFromQuaternion(state[5])).reshape(3, 3),
                expected[:3, :3],
                atol=1e-6,
            )
    finally:
        p.disconnect(client)


def test_six_axis_inverse_kinematics_puts_the_tool_where_asked_by_an_independent_forward_model():
    """Independent oracle: the UR5's IK (the tool pointing down, full pose) along a path, each
    solution's flange checked by the DH product: the tool's mouth on the point to 0.05 mm, pointing
    straight down, every joint within its limits."""
    points = np.array([[0.45, 0.1, 0.25], [0.5, -0.05, 0.12], [0.38, 0.2, 0.3]])
    joints = sim.inverse_kinematics(points, "ur5", units="m", tool_length=0.1)
    assert joints.shape == (3, 6)
    for q, point in zip(joints, points):
        flange = dh_forward(q)
        mouth = flange[:3, 3] + flange[:3, 2] * 0.1  # the tool along the flange's z
        assert np.linalg.norm(mouth - point) <= 5e-5
        assert flange[2, 2] <= -1 + 1e-6  # pointing down
        assert np.all(np.abs(q) <= 2 * np.pi)


@pytest.mark.parametrize("arm", ["xarm6", "ur5"])
def test_a_six_axis_arm_takes_a_far_nut_off_within_its_limits(arm):
    """The built-in nut task on the 6-axis arms (the whole 14-nut job: make readme's job_xarm6.md and
    job_ur5.md): the furthest nut, every phase within the contract and the arm's published limits."""
    scenario = scenarios.load(f"nut-unscrewing-{arm}")
    report = sim.run_job(scenario, targets=["12"])
    record = report.targets[0]
    assert (
        report.robot == arm and record.removed and record.within_limits and not record.contacts
    ), record.reason
    assert len(sim.joint_names(arm)) == 6


def test_a_six_joint_urdf_with_seven_limits_names_the_arm_and_its_joints(tmp_path):
    limits = {
        "lower": [-6.0] * 7,
        "upper": [6.0] * 7,
        "velocity": [3.0] * 7,
        "acceleration": [15.0] * 7,
    }
    spec = nut_spec(urdf="xarm/xarm6_robot.urdf", flange="link6", limits=limits, base=[50, -400, 0])
    with pytest.raises(
        ValueError,
        match=r"robot 'xarm6_robot' has 6 movable joints up to its flange 'link6'; the "
        r"simulator drives its 7 limits",
    ):
        sim.simulate(scenarios.from_dict(spec), ["bidmp"], targets=["3"], workers=1)
    spec["robot"]["limits"]["velocity"] = [3.0] * 6
    with pytest.raises(
        ScenarioError, match=r"robot.limits.velocity.*expected 7 numbers, one per joint"
    ):
        scenarios.from_dict(spec)


def test_joint_limits_and_the_robot_for_a_six_joint_model(tmp_path, capsys):
    """A 6-joint recording (the UR5's joints along a path): --joint-limits ur5 times it to the UR5's
    limits; a 7-joint arm's limits are refused naming both counts; the JointTrajectory after IK
    carries the UR5's six joints."""
    points = np.column_stack(
        [np.linspace(0.4, 0.5, 60), np.linspace(0.0, 0.1, 60), np.full(60, 0.2)]
    )
    q = sim.inverse_kinematics(points, "ur5", units="m")
    names = sim.joint_names("ur5")
    table = np.column_stack([np.linspace(0.0, 2.0, 60), q])
    (tmp_path / "q.csv").write_text(
        "t,"
        + ",".join(names)
        + "\n"
        + "\n".join(",".join(f"{v:.9g}" for v in row) for row in table)
    )
    assert main(["fit", str(tmp_path / "q.csv"), "-o", str(tmp_path / "q.npz")]) == 0
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "q.npz"),
                "--joint-limits",
                "ur5",
                "-o",
                str(tmp_path / "r.csv"),
            ]
        )
        == 0
    )
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "q.npz"),
                "--joint-limits",
                "panda",
                "-o",
                str(tmp_path / "r.csv"),
            ]
        )
        == 2
    )
    assert "that arm has 7 joints; this model has 6 dimensions" in capsys.readouterr().err


@pytest.mark.parametrize("model", ["panda", "iiwa", "ur5"])
def test_the_planning_copy_without_geometry_solves_and_measures_to_the_same_bits(model, tmp_path):
    """The planning copy of the arm is loaded without its links' meshes (they were most of its
    loading time): inverse and forward kinematics must give exactly what the full URDF gives,
    over a chain of IK calls each seeded by the last (the reference: the full URDF in a world of
    its own)."""
    import pybullet as p

    from bidmp.sim.pybullet.world import _kinematic_urdf, _tool_urdf
    from bidmp.sim.robots import ROBOT_MODELS

    arm = ROBOT_MODELS[model]
    text = _tool_urdf(arm, 0.012, 0.1)
    light = _kinematic_urdf(text)
    assert "<visual" in text and "<visual" not in light and "<collision" not in light
    assert _kinematic_urdf("<robot><link") == "<robot><link"  # unreadable: returned whole
    (tmp_path / "full.urdf").write_text(text)
    (tmp_path / "light.urdf").write_text(light)
    worlds = [p.connect(p.DIRECT) for _ in range(2)]
    try:
        bodies = [
            p.loadURDF(str(tmp_path / name), useFixedBase=True, physicsClientId=world)
            for name, world in zip(("full.urdf", "light.urdf"), worlds)
        ]
        n_joints = p.getNumJoints(bodies[0], physicsClientId=worlds[0])
        names = [
            p.getJointInfo(bodies[0], j, physicsClientId=worlds[0])[12].decode()
            for j in range(n_joints)
        ]
        tcp = names.index("tcp")
        movable = [
            j
            for j in range(n_joints)
            if p.getJointInfo(bodies[0], j, physicsClientId=worlds[0])[2] != p.JOINT_FIXED
        ]
        lower, upper = list(arm.limits.lower), list(arm.limits.upper)
        rng = np.random.default_rng(5)
        q = list(arm.rest)
        for _ in range(40):
            frames = []
            for body, world in zip(bodies, worlds):
                for joint, angle in zip(movable, q):
                    p.resetJointState(body, joint, angle, 0.0, physicsClientId=world)
                state = p.getLinkState(body, tcp, computeForwardKinematics=1, physicsClientId=world)
                frames.append(state[4:6])
            assert frames[0] == frames[1]
            goal = (np.array(frames[0][0]) + rng.normal(0.0, 0.01, 3)).tolist()
            solved = [
                p.calculateInverseKinematics(
                    body,
                    tcp,
                    goal,
                    [1.0, 0.0, 0.0, 0.0],
                    lowerLimits=lower,
                    upperLimits=upper,
                    jointRanges=[b - a for a, b in zip(lower, upper)],
                    restPoses=q,
                    maxNumIterations=40,
                    physicsClientId=world,
                )
                for body, world in zip(bodies, worlds)
            ]
            assert solved[0] == solved[1]
            q = list(solved[0][: len(movable)])
    finally:
        for world in worlds:
            p.disconnect(world)
