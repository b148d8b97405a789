"""What a scenario hands the contract, and what the contract hands its checks, is used: a pose
scenario's alignment threshold and each target's own (tilted) axis reach the contract and the
simulator's task; the tool's alignment is judged against the target's axis, not world z; the
commands' period given is the one their peaks are taken with. Several of everything: two targets
tilted differently (and a third upright), two alignment thresholds, three command periods, two
arms. Expected values from geometry and closed forms written here."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bidmp.sim.backend import JointLimits
from bidmp.sim.report import _SimTask
from bidmp.sim.robots import PANDA
from bidmp.tasks import scenarios
from bidmp.tasks.contract import Contract

TILTED = (
    Path(scenarios.__file__).parent.parent / "data" / "scenarios" / "nut-unscrewing-tilted.json"
)
DOWN = Rotation.from_quat([1.0, 0.0, 0.0, 0.0])  # the tool pointing down (its z along -z)
SIX = JointLimits(
    lower=(-3.0,) * 6,
    upper=(3.0,) * 6,
    velocity=(1.0, 1.2, 1.4, 1.6, 1.8, 2.0),
    acceleration=(2.0, 2.5, 3.0, 3.0, 3.0, 3.0),
)


def _scenario(alignment: float):
    """The tilted pack with target 2 turned 20 degrees about y instead (the others 30 about x)
    and target 5 upright: three targets, three axes."""
    data = json.loads(TILTED.read_text(encoding="utf-8"))
    data = copy.deepcopy(data)
    data["alignment_threshold"] = alignment
    data["targets"]["2"] = [
        *data["targets"]["2"][:3],
        *(Rotation.from_euler("y", 20.0, degrees=True) * DOWN).as_quat(),
    ]
    data["targets"]["5"] = [*data["targets"]["5"][:3], *DOWN.as_quat()]
    data.pop("scene")
    data.pop("job", None)
    return scenarios.from_dict(data)


def _axis(quaternion) -> np.ndarray:
    """The axis out of a pose target: minus its tool z (the tool comes in along it)."""
    return -Rotation.from_quat(quaternion[3:7]).apply([0.0, 0.0, 1.0])


@pytest.mark.parametrize("alignment", [2.0, 3.5])
def test_a_pose_scenarios_alignment_and_each_targets_axis_reach_the_contract_and_the_task(
    alignment,
):
    scenario = _scenario(alignment)
    labels = ["1", "2", "5", "3"]
    assert Contract.of(scenario).alignment_threshold == alignment
    assert Contract.of(scenario, PANDA).limits is PANDA
    task = _SimTask.of(scenario, labels)
    assert task.alignment_threshold == alignment
    axes = {label: _axis(np.asarray(scenario.targets[label])) for label in labels}
    assert not np.allclose(axes["1"], axes["2"]) and np.allclose(axes["5"], [0.0, 0.0, 1.0])
    for label in labels:
        np.testing.assert_allclose(task.axes[label], axes[label], atol=1e-6)
    built = task.contract(None, SIX)
    assert built.alignment_threshold == alignment and built.limits is SIX


@pytest.mark.parametrize("degrees", [(25.0, "y"), (-35.0, "x")])
def test_the_tools_alignment_is_judged_against_the_targets_own_tilted_axis(degrees):
    """Down a target's tilted axis with the tool's axis on it: aligned; the same path with the
    tool upright, or turned onto the other target's axis: not."""
    angle, about = degrees
    turn = Rotation.from_euler(about, angle, degrees=True)
    axis = turn.apply([0.0, 0.0, 1.0])
    target = np.array([40.0, -20.0, 10.0])
    path = target + np.linspace(40.0, 0.0, 100)[:, None] * axis
    contract = Contract(1.75, 28.5, None, "mm", alignment_threshold=2.0)
    other = Rotation.from_euler("x" if about == "y" else "y", 15.0, degrees=True)
    for frame, expect in ((turn * DOWN, True), (DOWN, False), (other * DOWN, False)):
        frames = np.repeat(frame.as_quat()[None], len(path), axis=0)
        # geometry here: the angle between the tool's axis (minus its z) and the target's
        tool_axis = -frame.apply([0.0, 0.0, 1.0])
        assert bool(np.degrees(np.arccos(np.clip(tool_axis @ axis, -1.0, 1.0))) <= 2.0) is expect
        verdict = contract.judge(path, target, label="t", axis=axis, orientations=frames)
        assert verdict.engaged is True
        assert verdict.aligned is expect, (frame.as_quat(), verdict.axis_deviation)


@pytest.mark.parametrize("limits", [SIX, PANDA], ids=["six-joint", "panda"])
@pytest.mark.parametrize("dt", [1e-3, 2e-3, 4e-3])
def test_the_commands_peaks_are_taken_at_the_period_given(dt, limits):
    """A minimum-jerk stroke of 0.6 rad over 1.5 s on joint 1, sampled every ``dt``: its peak
    velocity and acceleration as fractions of this arm's limits are the closed forms' (1.875 A/T
    and 10/sqrt(3) A/T²) whatever the period."""
    amplitude, seconds = 0.6, 1.5
    tau = np.linspace(0.0, 1.0, int(round(seconds / dt)) + 1)
    q0 = 0.5 * (np.asarray(limits.lower) + np.asarray(limits.upper))
    commands = np.repeat(q0[None], tau.size, axis=0)
    commands[:, 0] += amplitude * (10 * tau**3 - 15 * tau**4 + 6 * tau**5)
    path = np.linspace([0.0, 0.0, 40.0], [0.0, 0.0, 0.0], 50)
    verdict = Contract(1.75, 25.0, None, "mm", limits=limits).judge(
        path, np.zeros(3), commands=commands, dt=dt
    )
    peaks = verdict.limits
    assert peaks.velocity == pytest.approx(
        1.875 * amplitude / seconds / limits.velocity[0], rel=2e-2
    )
    assert peaks.acceleration == pytest.approx(
        10.0 / np.sqrt(3.0) * amplitude / seconds**2 / limits.acceleration[0], rel=5e-2
    )
    assert verdict.within_limits is True
