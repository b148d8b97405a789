"""What a simulated run measures is handed on from its own source: each field of a target's row
(the commanded end, the measured end, the tracking, the contacts, the peaks of the commands and
of the measured joints, the limits' verdict) from the execution's own array, in the scene's
unit, judged by the arm's own tables along the target's own axis. Unit tests of the wiring on a
made-up execution (no simulator): several of everything — two units, two arms (the Panda and a
six-joint arm with other limits), two targets tilted differently, commands within and past the
limits — so that a field taken from a neighbour, a unit applied twice or not at all, or another
arm's tables, changes a number checked here. Expected values from the numbers built here
(closed forms of a minimum-jerk stroke), not from the code under test."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bidmp.sim.backend import JointLimits
from bidmp.sim.report import SimMethod, SimTarget, _measure, _SimTask
from bidmp.sim.robots import PANDA

# a six-joint arm with limits unlike the Panda's (rad, rad/s, rad/s²; no jerk limit, no FCI)
SLOW = JointLimits(
    lower=(-3.0,) * 6,
    upper=(3.0,) * 6,
    velocity=(1.0, 1.2, 1.4, 1.6, 1.8, 2.0),
    acceleration=(2.0, 2.5, 3.0, 3.0, 3.0, 3.0),
)
ARMS = {"panda": PANDA, "six-joint": SLOW}
METRES = {"mm": 1e-3, "m": 1.0}  # metres per scene unit
# two targets (metres), tilted differently: the tool comes in along minus each axis
AXES = {
    "A": Rotation.from_euler("y", 25.0, degrees=True).apply([0.0, 0.0, 1.0]),
    "B": Rotation.from_euler("x", -35.0, degrees=True).apply([0.0, 0.0, 1.0]),
}
TARGETS_M = {"A": np.array([0.30, 0.10, 0.05]), "B": np.array([0.20, -0.15, 0.08])}
COMMAND_DT = 1e-3  # s
RECORD_DT = 0.002  # s: the simulator records every 2 ms


def _across(axis):
    """Two unit vectors across ``axis`` (a frame of it)."""
    first = np.cross(axis, [0.0, 1.0, 0.0])
    first /= np.linalg.norm(first)
    return first, np.cross(axis, first)


def _stroke(q0, joint: int, amplitude: float, seconds: float) -> np.ndarray:
    """1 kHz commands (T, J): a minimum-jerk stroke of ``amplitude`` rad on ``joint`` from ``q0``
    over ``seconds`` (peak velocity 1.875 A/T, peak acceleration 10/sqrt(3) A/T²), at rest at
    both ends."""
    tau = np.linspace(0.0, 1.0, int(round(seconds / COMMAND_DT)) + 1)
    commands = np.repeat(np.asarray(q0, dtype=float)[None], tau.size, axis=0)
    commands[:, joint] += amplitude * (10 * tau**3 - 15 * tau**4 + 6 * tau**5)
    return commands


def _ramp(n_joints: int, joint: int, speed: float) -> np.ndarray:
    """Measured joint velocities (n, J) every 2 ms: ``joint`` brought to ``speed`` rad/s at
    0.5 rad/s² (within both arms' accelerations), then held."""
    t = np.arange(int(speed / 0.5 / RECORD_DT) + 400) * RECORD_DT
    velocities = np.zeros((t.size, n_joints))
    velocities[:, joint] = np.minimum(0.5 * t, speed)
    return velocities


def _execution(label: str, unit: float, arm: JointLimits, fast: bool, rushed: bool):
    """(plan, run) of a made-up motion to ``label``: down its own axis from 40 mm out, the
    commanded path ending 0.3 mm off the target across the axis, the measured one 0.8 mm off,
    the commanded tool 0.4 mm from the measured one (another direction across), a 2 mm contact
    with a post; the commands a stroke on joint 1 within the arm's limits or past them
    (``fast``); the measured joint 2 at 0.9 rad/s, or (``rushed``) 1.45 (past the six-joint
    arm's 1.2 plus the noise allowance, within the Panda's)."""
    axis, target = AXES[label], TARGETS_M[label]
    side, other = _across(axis)
    out = np.linspace(0.040, 0.0, 120)[:, None] * axis
    measured = target + out + 0.8e-3 * side
    q0 = 0.5 * (np.asarray(arm.lower) + np.asarray(arm.upper))
    amplitude, seconds = (1.0, 1.2) if fast else (0.5, 1.5)
    plan = SimpleNamespace(
        points=target + out + 0.3e-3 * side,
        duration=1.7,
        peak_velocity=0.11,  # (what the planner promised: the commands' peaks are what counts)
        peak_acceleration=0.12,
        peak_jerk=0.13,
        orientations=None,  # (not a route that turns the tool)
    )
    velocities = _ramp(arm.n_joints, 1, 1.45 if rushed else 0.9)
    run = SimpleNamespace(
        tcp=measured,
        commanded_tcp=measured + 0.4e-3 * other,
        tcp_orientation=None,
        commands=_stroke(q0, 0, amplitude, seconds),
        contacts={"post": 0.002},
        joint_velocities=velocities,
        disturbed=None,
        times=np.arange(velocities.shape[0]) * RECORD_DT,
        paused=0.0,
    )
    return plan, run


def _task(units: str) -> _SimTask:
    mm = 1e-3 / METRES[units]  # scene units per millimetre
    return _SimTask(
        {label: (point / METRES[units]).tolist() for label, point in TARGETS_M.items()},
        units,
        1.75 * mm,
        28.5 * mm,
        {label: axis.tolist() for label, axis in AXES.items()},
        None,
    )


@pytest.mark.parametrize("rushed", [False, True], ids=["joints-calm", "joints-rushed"])
@pytest.mark.parametrize("fast", [False, True], ids=["within", "past"])
@pytest.mark.parametrize("arm", sorted(ARMS))
@pytest.mark.parametrize("units", sorted(METRES))
def test_each_field_of_a_measured_target_comes_from_its_own_source(units, arm, fast, rushed):
    limits, unit, task = ARMS[arm], METRES[units], _task(units)
    mm = 1e-3 / unit
    for label in ("A", "B"):
        target = np.asarray(task.targets[label])
        plan, run = _execution(label, unit, limits, fast, rushed)
        row = _measure(task, label, target, (plan, run), unit, False, (limits, None, ()))
        # the ends, the tracking and the contacts, in the scene's unit
        assert row.commanded_error == pytest.approx(0.3 * mm, rel=1e-6)
        assert row.measured_error == pytest.approx(0.8 * mm, rel=1e-6)
        assert row.tracking_error == pytest.approx(0.4 * mm, rel=1e-6)
        assert row.contacts == {"post": pytest.approx(2.0 * mm)}
        # the descent judged along the target's own (tilted) axis: on it, 0.8 mm across
        assert row.engaged is True and row.approach_error == pytest.approx(0.8 * mm, rel=1e-3)
        # the commands' peaks against this arm's tables (closed forms of the stroke)
        amplitude, seconds = (1.0, 1.2) if fast else (0.5, 1.5)
        velocity = 1.875 * amplitude / seconds / limits.velocity[0]
        acceleration = 10.0 / np.sqrt(3.0) * amplitude / seconds**2 / limits.acceleration[0]
        assert row.peak_velocity == pytest.approx(velocity, rel=1e-2)
        assert row.peak_acceleration == pytest.approx(acceleration, rel=2e-2)
        # the measured joints' peak against this arm's tables too
        speed = 1.45 if rushed else 0.9
        assert row.measured_peak_velocity == pytest.approx(speed / limits.velocity[1], rel=1e-9)
        commands_within = velocity <= 1.0 and acceleration <= 1.0
        breach = speed > limits.velocity[1] + 0.1
        assert bool(row.measured_breach) is breach, row.measured_breach
        assert row.verdict.limits is not None
        assert bool(row.verdict.limits.within) == commands_within
        assert bool(row.within_limits) == (commands_within and not breach)
        assert row.motion_time == pytest.approx(1.7)
        assert not row.task_success(task.success_threshold)  # the 2 mm contact


def test_end_successes_count_the_measured_end_not_the_commanded_one():
    """A method's end-point count is of the measured ends: two targets whose command ended on
    target but whose arm stopped 2 mm off, and one the other way round."""

    def row(label, commanded, measured):
        return SimTarget(
            label, commanded, measured, None, None, {}, 0.1, 0.1, 0.1, 0.1, 1.0, 0.0, True
        )

    method = SimMethod(
        "dmp", {"1": row("1", 0.1, 2.0), "2": row("2", 0.2, 2.5), "3": row("3", 2.4, 0.3)}, 1.75
    )
    assert method.end_successes == 1
