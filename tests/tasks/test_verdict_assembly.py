"""Where the contract's checks are assembled into one verdict (``Contract.judge``): each input a
caller hands it must count — the target's own axis, the simulator's contacts, the tool's tilt,
a pose path's positions. Each motion here is built to differ from a passing one in that input
alone, and the expected verdict is decided by geometry written here (distances from an axis, a
tilted cylinder against a post), not by the library's metrics. ``make mutation`` plants the bugs
these catch (a dropped argument, a wrong frame)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bidmp import Scene
from bidmp.tasks.contract import Contract

TOOL_RADIUS, TOOL_LENGTH, MARGIN = 10.0, 100.0, 3.0
POST_X, POST_RADIUS, POST_TOP = 60.0, 5.0, 78.0


@pytest.fixture(scope="module")
def contract() -> Contract:
    scene = Scene.from_dict(
        {
            "tool": {"radius": TOOL_RADIUS, "length": TOOL_LENGTH},
            "margin": MARGIN,
            "standoff": {"plate": 1.0},
            "parts": [
                {"type": "plate", "label": "plate", "at": [0, 0, -2], "size": [400, 400, 5]},
                {
                    "type": "cylinder",
                    "label": "post",
                    "at": [POST_X, 0, -2],
                    "radius": POST_RADIUS,
                    "height": POST_TOP + 2.0,
                },
            ],
        },
        units="mm",
    )
    return Contract(1.75, 25.0, scene, "mm")


def _along(target, axis, height=60.0, n=200) -> np.ndarray:
    """A straight descent onto ``target`` along ``axis`` (unit, pointing out of the part)."""
    return np.asarray(target) + np.outer(np.linspace(1.0, 0.0, n) ** 2, height * np.asarray(axis))


def test_engagement_is_judged_along_the_targets_own_axis(contract):
    tilt = np.radians(20.0)
    axis = np.array([np.sin(tilt), 0.0, np.cos(tilt)])  # a nut on a 20 degree bracket
    target = np.array([-40.0, 0.0, 0.0])
    on_axis = _along(target, axis)
    vertical = _along(target, [0.0, 0.0, 1.0])
    # geometry here: how far each comes off the tilted axis within the approach height
    for path, expect in ((on_axis, True), (vertical, False)):
        offset = path - target
        along = offset @ axis
        off = np.linalg.norm(offset - np.outer(along, axis), axis=1)
        band = along <= 25.0
        assert bool(off[band].max() <= 1.75) is expect
        verdict = contract.judge(path, target, label="b", axis=axis, exclude=["plate"])
        assert verdict.engaged is expect, (expect, verdict.reason())
    # and the vertical descent is engaged on a level nut: the axis argument decides
    level = contract.judge(vertical, target, label="b", exclude=["plate"])
    assert level.engaged


def test_the_simulators_contacts_fail_a_motion_whose_path_is_clear(contract):
    target = np.array([-40.0, 0.0, 0.0])
    path = _along(target, [0.0, 0.0, 1.0])
    assert contract.judge(path, target, label="a", exclude=["plate"]).ok
    touched = contract.judge(path, target, label="a", exclude=["plate"], contacts={"post": 0.4})
    assert not touched.ok and not touched.clear and "clearance" in touched.failed


def _tool_against_post(path, body_direction) -> float:
    """The least distance (mm) between the tool's cylinder (its axis from the mouth along
    ``body_direction`` for its length) and the post's, minus both radii: sampled along the
    tool's axis every 0.5 mm, each point's horizontal distance from the post's axis below its
    top (a lower bound on the true gap would be tighter; this one can only overstate it)."""
    s = np.linspace(0.0, TOOL_LENGTH, 201)
    gaps = []
    for mouth in path:
        points = mouth + np.outer(s, body_direction)
        below = points[:, 2] <= POST_TOP
        if np.any(below):
            across = np.hypot(points[below, 0] - POST_X, points[below, 1])
            gaps.append(across.min() - TOOL_RADIUS - POST_RADIUS)
    return float(min(gaps))


def test_a_tilted_tools_clearance_is_judged_with_its_tilt(contract):
    """The mouth comes straight down 25 mm from the post's axis (10 mm clear of it upright);
    the same path with the tool leaning 30 degrees towards the post sweeps its body into it."""
    target = np.array([POST_X - 25.0, 0.0, 0.0])
    path = _along(target, [0.0, 0.0, 1.0])
    lean = np.radians(30.0)
    body = np.array([np.sin(lean), 0.0, np.cos(lean)])  # from the mouth up along the tool
    tool_z = -body  # the tool frame's z points out of the mouth
    frame, _ = Rotation.align_vectors([tool_z], [[0.0, 0.0, 1.0]])
    leaning = np.repeat(frame.as_quat()[None], len(path), axis=0)
    down = np.repeat(np.array([[1.0, 0.0, 0.0, 0.0]]), len(path), axis=0)
    assert _tool_against_post(path, [0.0, 0.0, 1.0]) >= MARGIN
    assert _tool_against_post(path, body) < 0.0  # the leaning tool cuts into the post
    upright = contract.judge(path, target, label="p", exclude=["plate"], orientations=down)
    assert upright.clear
    tilted = contract.judge(path, target, label="p", exclude=["plate"], orientations=leaning)
    assert not tilted.clear and tilted.clearance.part == "post"


def test_a_pose_path_is_judged_on_its_positions(contract):
    target = np.array([-40.0, 0.0, 0.0])
    positions = _along(target, [0.0, 0.0, 1.0])
    positions[-1] += [1.0, 0.0, 0.0]  # ends 1 mm off: within the 1.75 mm threshold
    quaternions = np.repeat(np.array([[1.0, 0.0, 0.0, 0.0]]), len(positions), axis=0)
    pose_target = np.concatenate([target, [0.0, 1.0, 0.0, 0.0]])  # another frame, same point
    verdict = contract.judge(
        np.hstack([positions, quaternions]), pose_target, label="q", exclude=["plate"]
    )
    assert verdict.end_error == pytest.approx(1.0, abs=1e-12) and verdict.reached


def test_engagement_is_judged_only_where_it_applies():
    """No approach height (the rule off), or a 2-D path (a handwriting shape): no engagement is
    judged, and a motion that ends on its target meets the contract; with the height and a 3-D
    path that comes in sideways, it is judged and fails."""
    sideways = np.column_stack([np.linspace(-60.0, 0.0, 100), np.zeros(100), np.zeros(100)])
    target = np.zeros(3)
    off = Contract(1.75, None, None, "mm").judge(sideways, target, label="s")
    assert off.engaged is None and off.ok
    flat = Contract(1.75, 25.0, None, "mm").judge(sideways[:, :2], target[:2], label="s")
    assert flat.engaged is None and flat.ok
    on = Contract(1.75, 25.0, None, "mm").judge(sideways, target, label="s")
    assert on.engaged is False and not on.ok


def test_a_motion_exactly_at_the_threshold_is_engaged():
    """The threshold is inclusive ("within 1.75 mm"): a descent 1.75 mm beside the axis (a
    distance that is exact in binary) ends and comes down exactly at it, and meets the contract."""
    target = np.zeros(3)
    path = _along(target, [0.0, 0.0, 1.0]) + [1.75, 0.0, 0.0]
    verdict = Contract(1.75, 25.0, None, "mm").judge(path, target, label="e")
    assert verdict.approach_error == 1.75 and verdict.end_error == 1.75
    assert verdict.engaged and verdict.ok


def test_the_tools_alignment_is_judged_when_a_pose_contract_is_given_its_frames():
    """A pose contract (tool axis within 2 degrees of the target's over the approach): the tool
    coming down tilted 5 degrees fails it, upright meets it, and without frames it is not judged."""
    target = np.zeros(3)
    path = _along(target, [0.0, 0.0, 1.0])
    pose_contract = Contract(1.75, 25.0, None, "mm", alignment_threshold=2.0)
    down = Rotation.from_quat([1.0, 0.0, 0.0, 0.0])
    tilted = Rotation.from_euler("y", 5.0, degrees=True) * down
    for frame, expect in ((down, True), (tilted, False)):
        frames = np.repeat(frame.as_quat()[None], len(path), axis=0)
        # geometry here: the tool's axis against the target's (+z, the tool's z pointing down)
        angle = np.degrees(np.arccos(np.clip(-frame.apply([0.0, 0.0, 1.0])[2], -1.0, 1.0)))
        assert bool(angle <= 2.0) is expect
        verdict = pose_contract.judge(path, target, label="r", orientations=frames)
        assert verdict.aligned is expect and verdict.ok is expect
    assert pose_contract.judge(path, target, label="r").aligned is None


def test_clearance_is_judged_where_the_scene_applies_and_a_callers_is_taken_as_given(contract):
    """Beside the post, inside its margin (geometry here: 60 - 5 - 10 - 43 = 2 mm < 3 mm): the
    scene's clearance fails it; a target the scene does not apply to judges no clearance; and a
    clearance the caller measured already (the executed tool's) is the verdict's, not the path's."""
    from bidmp.scene.clearance import Clearance

    target = np.array([43.0, 0.0, 0.0])
    path = _along(target, [0.0, 0.0, 1.0])
    assert POST_X - POST_RADIUS - TOOL_RADIUS - target[0] == pytest.approx(2.0)
    near = contract.judge(path, target, label="n", exclude=["plate"])
    assert not near.clear and near.clearance.part == "post"
    assert near.clearance.distance == pytest.approx(2.0, abs=0.05)
    elsewhere = contract.judge(path, target, label="n", exclude=["plate"], applies=False)
    assert elsewhere.clearance is None and elsewhere.ok
    far = np.array([-40.0, 0.0, 0.0])
    measured = Clearance(-0.8, "post", far, margin=MARGIN)  # what the arm did, not the plan
    given = contract.judge(_along(far, [0, 0, 1]), far, label="g", clearance=measured)
    assert given.clearance is measured and not given.clear and not given.ok


def test_commands_are_judged_when_there_are_commands_and_limits():
    """Joint commands one joint steps 0.01 rad in 1 ms (10 rad/s, past any arm's velocity limit:
    geometry here) fail a contract with limits; without commands, or without limits, the rule is
    not judged."""
    from bidmp.sim.robots import PANDA

    target = np.zeros(3)
    path = _along(target, [0.0, 0.0, 1.0])
    commands = np.zeros((50, 7))
    commands[25:, 0] = 0.01
    assert 0.01 / 1e-3 > max(PANDA.velocity)
    with_limits = Contract(1.75, 25.0, None, "mm", limits=PANDA)
    jump = with_limits.judge(path, target, label="c", commands=commands)
    assert jump.within_limits is False and not jump.ok and jump.limits.joint == 0
    assert with_limits.judge(path, target, label="c").within_limits is None
    no_limits = Contract(1.75, 25.0, None, "mm")
    assert no_limits.judge(path, target, label="c", commands=commands).within_limits is None
