"""A new arm starts where it can work: a URDF arm given without a rest pose starts at the
demonstration's start (tool pointing down) solved by IK within its limits, not at the middle of
its ranges (for ±360° joints the zero pose, often stretched out, from which nothing is solved).

Two arms bidmp knows only from their URDF, in a cell in metres: the UR5's DH model written as a
user's file (its zero pose reaches out horizontally: from there the previous start reached none
of the nuts, "move the robot") and a TM5-700-like arm (tests/data/tm5_like, written by
tools/ur5_urdf.py --arm tm5-like). The oracle for "starts where it can work" is forward
kinematics of the chosen start, compared with the demonstration's start, and its joints against
the limits typed here."""

from __future__ import annotations

import json
import math
import pathlib
import shutil
import sys

import numpy as np
import pytest

pytest.importorskip("pybullet")

from bidmp import sim  # noqa: E402
from bidmp.tasks import scenarios  # noqa: E402

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
sys.path.insert(0, str(ROOT / "tests" / "tasks"))
from test_user_cells import spec as cell_spec  # noqa: E402
from test_user_cells import urdf_limits  # noqa: E402

DEG = math.pi / 180.0
ARMS = {
    "ur5-as-a-user-urdf": (
        ROOT / "src" / "bidmp" / "data" / "robots" / "ur5_dh.urdf",
        [360.0] * 6,
        [180.0] * 6,
    ),
    "tm5-like": (
        DATA / "tm5_like" / "tm5_like.urdf",
        [270.0, 180.0, 155.0, 180.0, 180.0, 270.0],
        [180.0, 180.0, 180.0, 225.0, 225.0, 225.0],
    ),
}


def _scenario(tmp_path, arm: str, **robot):
    urdf, ranges, speeds = ARMS[arm]
    shutil.copy(urdf, tmp_path / "arm.urdf")
    data = cell_spec("two_posts.json", "m")  # posts between the nut columns, in metres
    data["robot"] = {
        "urdf": "arm.urdf",
        "flange": "flange",
        "limits": urdf_limits(ranges, speeds),
        **robot,
    }
    (tmp_path / "cell.json").write_text(json.dumps(data))
    return scenarios.load(str(tmp_path / "cell.json")), ranges


@pytest.mark.parametrize("arm", sorted(ARMS))
def test_an_arm_without_a_rest_pose_starts_at_the_demonstration_and_does_the_job(tmp_path, arm):
    scenario, ranges = _scenario(tmp_path, arm)
    model = sim.robot_model(scenario.robot, scenario.base_dir)
    assert not model.rest_given and not any(model.rest)  # the ranges' middle: all zeros
    base, yaw = sim.robot_placement(scenario)
    cell = sim.run._open_world(sim.get_backend("pybullet"), scenario, base, yaw)
    try:
        start = np.asarray(cell.rest, dtype=float)
        tool = cell.tcp_position() / cell.unit  # forward kinematics of the start pose (m)
    finally:
        cell.close()
    assert np.linalg.norm(tool - scenario.demonstration[0, :3]) < 1e-4  # 0.1 mm
    assert np.all(np.abs(start) < np.asarray(ranges) * DEG)
    if arm != "ur5-as-a-user-urdf":  # the start pose is the point; the motions once for it
        return
    labels = ["3", "12"]  # the demonstrated nut and the farthest, past both posts
    result = sim.simulate(scenario, ["bidmp"], targets=labels, workers=1)
    assert result.methods["bidmp"].task_successes == 2, result.summary()
    job = sim.run_job(scenario, targets=labels)
    assert job.removed == 2, job.summary()


def test_a_rest_pose_outside_the_limits_is_refused_naming_it(tmp_path):
    with pytest.raises(scenarios.ScenarioError, match=r"robot\.rest.*joint 2 at 4 rad"):
        _scenario(tmp_path, "tm5-like", rest=[0.0, 4.0, 0.0, 0.0, 0.0, 0.0])


def test_a_point_out_of_reach_says_so_and_names_the_fix_that_helps(tmp_path):
    """1.2 m in front of the arm no joints within its limits put the tool at the demonstration's
    start pointing down, from any seed: the reason says so and names the fix that helps (move the
    base; a start pose would not), with how far the nearest solution stays from the point, which
    is at least how far the point lies past everything the arm's links and tool could stretch to
    from its shoulder (the TM5-700's published lengths, written here: 329, 311.5, 122.3, 106 and
    113.15 mm and the 0.1 m tool, end to end)."""
    scenario, _ = _scenario(tmp_path, "tm5-like", base=[0.0, -1.2, 0.0])
    result = sim.simulate(scenario, ["bidmp"], targets=["12"], workers=1)
    reason = result.methods["bidmp"].targets["12"].reason
    assert '"base"' in reason and '"rest"' not in reason, reason
    assert (
        "no joints within the limits put the tool there" in reason or "beyond its reach" in reason
    )
    start = np.asarray(scenario.demonstration[0, :3], dtype=float)
    shoulder = np.array([0.0, -1.2, 0.1452])
    short = np.linalg.norm(start - shoulder) - (0.329 + 0.3115 + 0.1223 + 0.106 + 0.11315 + 0.1)
    assert short > 0.0  # out of reach by the published lengths alone
    if "the nearest leaves" in reason:
        nearest = float(reason.split("the nearest leaves ")[1].split(" m")[0])
        assert nearest >= short - 1e-3, (nearest, short)


def test_a_rest_pose_set_on_the_arm_is_where_it_stands_and_where_it_starts():
    """``RobotCell.use_rest``: the arm stands at the new rest (its measured joints), the model
    keeps it for the next run, and a pose outside a joint's limits is refused naming the joint."""
    cell = sim.RobotCell(scenarios.load("nut-unscrewing").scene)
    try:
        limits = cell.limits
        middle = 0.5 * (np.asarray(limits.lower) + np.asarray(limits.upper))
        q = 0.7 * np.asarray(cell.rest) + 0.3 * middle
        cell.use_rest(q)
        assert cell.rest == tuple(q.tolist()) and cell.model.rest_given
        measured = [
            cell.p.getJointState(cell.robot, j, physicsClientId=cell.client)[0] for j in cell.arm
        ]
        np.testing.assert_allclose(measured, q, atol=1e-12)
        out = q.copy()
        out[3] = limits.upper[3] + 0.1
        with pytest.raises(ValueError, match="q: joint 4 .* outside its limits"):
            cell.use_rest(out)
        assert cell.rest == tuple(q.tolist())  # a refused pose changes nothing
    finally:
        cell.close()
