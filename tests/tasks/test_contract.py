"""The motion contract (bidmp.tasks.contract) and the repairs (bidmp.tasks.repair) in small: each rule
against a motion made here to break it, the reasons in words, the units."""

import numpy as np
import pytest

from bidmp.demonstrations import minimum_jerk
from bidmp.tasks import scenarios
from bidmp.tasks.contract import ENGAGE_RISE_MM, Contract, command_peaks, mm
from bidmp.tasks.repair import REPAIRS, Repairer

SCENE = {
    "tool": {"radius": 10.0, "length": 100.0},
    "margin": 3.0,
    "standoff": {"plate": 1.0},
    "parts": [
        {"type": "plate", "label": "plate", "at": [0, 0, -2], "size": [400, 400, 5]},
        {"type": "cylinder", "label": "post", "at": [60, 0, -2], "radius": 5.0, "height": 80.0},
    ],
}


def contract(units: str = "mm", post=(60.0, 0.0)) -> Contract:
    from bidmp import Scene

    f = {"mm": 1.0, "cm": 0.1, "m": 1e-3}[units]
    scene = {
        "tool": {k: v * f for k, v in SCENE["tool"].items()},
        "margin": 3.0 * f,
        "standoff": {"plate": 1.0 * f},
        "parts": [
            {**SCENE["parts"][0], "at": [0, 0, -2 * f], "size": [400 * f, 400 * f, 5 * f]},
            {
                **SCENE["parts"][1],
                "at": [post[0] * f, post[1] * f, -2 * f],
                "radius": 5 * f,
                "height": 80 * f,
            },
        ],
    }
    return Contract(1.75 * f, 25.0 * f, Scene.from_dict(scene, units=units), units)


def descent(target, height=60.0, n=200):
    """Straight down onto ``target`` from ``height`` above: a motion that meets the contract."""
    return np.asarray(target) + np.outer(np.linspace(1.0, 0.0, n) ** 2, [0.0, 0.0, height])


def test_a_straight_descent_meets_it_and_each_rule_fails_on_its_own_breach():
    """Independent oracle: each motion is built here to break exactly one rule."""
    c, target = contract(), np.zeros(3)
    assert c.judge(descent(target), target, label="t", exclude=["nothing"] if False else ()).ok
    short = descent(target)[:-60]  # stops 5.3 mm above the target
    assert c.judge(short, target, label="t").failed == ["end"]
    tilted = descent(target) + np.outer(
        np.linspace(1.0, 0.0, 200), [3.0, 0.0, 0.0]
    )  # comes in 3 mm off the axis
    tilted[-1] = target
    assert c.judge(tilted, target, label="t").failed == ["engagement"]
    dip = np.vstack(
        [descent(target)[:-1], target - [0.0, 0.0, 0.2], target]
    )  # 0.2 mm below, back up
    verdict = c.judge(dip, target, label="t")
    assert verdict.failed == ["engagement"] and "monotone" in verdict.reason()
    assert c.judge(
        np.vstack([descent(target)[:-1], target - [0, 0, 0.1], target]), target, label="t"
    ).ok  # under 0.15
    beside = np.array(
        [40.0, 0.0, 0.0]
    )  # the socket 40 mm from the post's axis: 40 - 5 - 10 = 25 clear
    assert c.judge(descent(beside), beside, label="t").ok
    close = np.array([60.0 - 5 - 10 - 2.0, 0.0, 0.0])  # 2 mm from the post: inside the 3 mm margin
    verdict = c.judge(descent(close), close, label="t")
    assert (
        verdict.failed == ["clearance"]
        and "passes 2.00 mm from post, inside the 3 mm it must keep" in verdict.reason()
    )


def test_the_verdicts_are_the_same_in_mm_cm_and_m():
    """The same motions, scaled: every rule gives the same verdict (the tolerances are in mm)."""
    for units, f in (("mm", 1.0), ("cm", 0.1), ("m", 1e-3)):
        c, target = contract(units), np.zeros(3)
        dip = np.vstack([descent(target * f, 60 * f)[:-1], (target - [0, 0, 0.2]) * f, target * f])
        small = np.vstack(
            [descent(target * f, 60 * f)[:-1], (target - [0, 0, 0.1]) * f, target * f]
        )
        close = np.array([43.0, 0.0, 0.0]) * f
        assert c.judge(dip, target * f).failed == ["engagement"]
        assert c.judge(small, target * f).ok
        assert c.judge(descent(close, 60 * f), close).failed == ["clearance"]
    assert mm(ENGAGE_RISE_MM, "m") == pytest.approx(1.5e-4) and mm(1.0, "cm") == pytest.approx(0.1)


def test_commands_are_judged_in_both_directions_and_from_rest():
    """Independent oracle: a quintic joint move whose peaks are known in closed form, run forward and
    backward (a limit check without the absolute value passes every negative violation)."""
    from types import SimpleNamespace

    limits = SimpleNamespace(velocity=[1.0, 1.0], acceleration=[10.0, 10.0], jerk=[1000.0, 1000.0])
    t = np.arange(0.0, 1.0 + 1e-9, 1e-3)
    s = 10 * t**3 - 15 * t**4 + 6 * t**5
    for sign in (1.0, -1.0):
        q = np.column_stack(
            [sign * 0.5 * s, np.zeros_like(s)]
        )  # peak speed 0.5 * 1.875 = 0.94 rad/s
        peaks = command_peaks(q, limits)
        assert peaks.within and peaks.velocity == pytest.approx(0.9375, rel=1e-3)
        fast = np.column_stack([sign * 0.6 * s, np.zeros_like(s)])  # 1.125 rad/s
        peaks = command_peaks(fast, limits)
        assert not peaks.within and peaks.joint == 0 and "velocity 1.12" in peaks.reason()
    jump = np.column_stack([np.r_[np.zeros(5), np.full(5, 1e-4)], np.zeros(10)])
    assert not command_peaks(jump, limits).within


def test_a_repair_order_names_only_repairs_and_needs_a_scene():
    scenario = scenarios.load("nut-unscrewing")
    with pytest.raises(ValueError, match="order names 'teleport', which is no repair"):
        Repairer(Contract.of(scenario), scenario.demonstration, order=("lift", "teleport"))
    with pytest.raises(ValueError, match="repairs need the contract's scene"):
        Repairer(Contract.of(scenario, geometry=False), scenario.demonstration)
    assert REPAIRS == ("lift", "avoid", "extend", "margin", "route")


@pytest.mark.parametrize("how", ["lift", "avoid", "extend"])
def test_each_repair_alone_keeps_the_contract_past_a_post(how):
    """A skill whose motion to a far goal passes a post within the margin: each repair on its own
    brings it within the contract, or says why; the lift and the extension must (an independent
    check of the clearance: the post's axis and the tool's radius along the densified path)."""
    from bidmp import DMP

    demo = minimum_jerk([[-100, -120, 150], [0, 0, 35], [0, 0, 0]], 300)
    dmp = DMP().fit(demo, np.linspace(0, 3, 300), units="mm")
    post = np.array(
        [60.0, -33.0]
    )  # on the skill's way to the goal, the tool's mouth 66 mm up there
    c = contract(post=post)
    goal = np.array([120.0, 0.0, 0.0])
    repairer = Repairer(c, demo, order=(how,))
    repaired = repairer.repair(dmp, goal, "far", exclude=())
    assert c.judge(dmp.trajectory(goal).y, goal).failed == ["clearance"]  # it needs one
    if how == "avoid" and not repaired.ok:
        assert repaired.attempts[0].note
        return
    assert repaired.ok and repaired.how == how, repaired.reason()
    path = repaired.motion
    dense = np.vstack(
        [a + np.linspace(0, 1, 30)[:, None] * (b - a) for a, b in zip(path[:-1], path[1:])]
    )
    tall = dense[:, 2] < 78.0 + 3.0  # the tool's mouth below the post's top plus the margin
    assert np.all(np.linalg.norm(dense[tall, :2] - post, axis=1) >= 5.0 + 10.0 + 3.0 - 1e-6)
    assert np.linalg.norm(path[-1] - goal) <= 1.75


def test_a_pose_motion_that_never_comes_down_says_so_not_inf_degrees():
    """A motion that stays over the target has no final approach to measure the tool's tilt on
    (axis_deviation is inf): the reason says that in words."""
    from bidmp.tasks.contract import Contract

    contract = Contract(1.75, 28.5, None, "mm", alignment_threshold=2.0)
    path = np.column_stack([np.zeros(50), np.zeros(50), np.linspace(200.0, 60.0, 50)])
    down = np.repeat([[1.0, 0.0, 0.0, 0.0]], 50, axis=0)
    verdict = contract.judge(path, [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0], orientations=down)
    assert not verdict.ok and np.isinf(verdict.axis_deviation)
    reason = verdict.reason()
    assert "inf" not in reason and "never comes down along the target's axis" in reason, reason
