"""goals moved during execution (``stepper.set_goal``).

Checked on the measured motion (the stepper's commands at 1 kHz), on random demonstrations that
end in a straight approach (mm and m, random durations and approach lengths), random shifts in
every direction and random update times: the new goal is reached at rest, the acceleration stays
within the limits the motion was timed to, and the final approach is a translated copy of the
plain one (≤ 0.5 mm lateral over its length, independently measured against the plain rollout).
"""

import logging

import numpy as np
import pytest

from bidmp import DMP
from bidmp.demonstrations import minimum_jerk
from bidmp.primitives.goal_shift import _PEAKS
from bidmp.primitives.goals import _smoothstep_derivatives


def run(stepper, n, dt, update=None):
    commands = []
    for index in range(n):
        if update is not None and index == update[0]:
            update[1](stepper)
        commands.append(stepper.step(dt))
    return tuple(np.array([command[k] for command in commands]) for k in range(3))


@pytest.mark.parametrize("seed", range(8))
def test_a_goal_moved_half_way_is_reached_at_rest_within_the_limits_with_the_approach_kept(seed):
    rng = np.random.default_rng(seed)
    unit = float(rng.choice([1.0, 1e-3]))
    goal = rng.uniform(-150, 150, 3)
    descent = rng.uniform(30, 80)
    start = goal + np.append(
        rng.uniform(-200, 200, 2), descent + rng.uniform(60, 200)
    )  # above the approach
    demonstration = minimum_jerk(
        np.array([start, goal + [0, 0, descent], goal]) * unit, int(rng.integers(200, 500))
    )
    duration = float(rng.uniform(2, 5))
    dmp = DMP(keep_approach=True).fit(demonstration, np.linspace(0, duration, len(demonstration)))
    dt = 0.001
    plain = dmp.trajectory(dt=dt)
    limits = {"max_acceleration": 1.2 * float(np.max(np.linalg.norm(plain.ydd, axis=1)))}
    shift = rng.normal(size=3)
    shift *= 5.0 * unit / np.linalg.norm(shift)  # 5 mm, any direction
    new_goal = dmp.goal_ + shift
    half = int(round(0.5 * duration / dt))
    y, yd, ydd = run(
        dmp.stepper(), len(plain.t), dt, (half, lambda s: s.set_goal(new_goal, limits=limits))
    )
    assert np.linalg.norm(y[-1] - new_goal) <= 1e-3 * unit + np.linalg.norm(plain.y[-1] - dmp.goal_)
    assert (
        np.linalg.norm(yd[-1]) <= np.linalg.norm(plain.yd[-1]) + 1e-6 * unit
    )  # at rest as the plain motion is
    assert np.max(np.linalg.norm(ydd, axis=1)) <= limits["max_acceleration"]
    # No step in the command: consecutive accelerations differ by what a smooth motion allows.
    assert (
        np.max(np.linalg.norm(np.diff(ydd, axis=0), axis=1))
        <= 2.0 * np.max(np.linalg.norm(np.diff(plain.ydd, axis=0), axis=1)) + 1e-9
    )
    # The last approach height (the lower half of the demonstrated descent, as the nut task's last
    # 28.5 mm of its 40): the moved motion is the plain one plus the shift.
    low = (
        np.arange(len(plain.t))
        > np.flatnonzero(plain.y[:, 2] > dmp.goal_[2] + 0.5 * descent * unit)[-1]
    )
    lateral = (y[low] - plain.y[low] - shift)[:, :2]
    assert np.max(np.linalg.norm(lateral, axis=1)) <= 0.5 * unit  # 0.5 mm


def test_before_the_update_the_motion_is_the_plain_one_and_updates_add_up():
    demonstration = minimum_jerk([[0, 0, 100], [200, 0, 100], [200, 0, 0]], 400)
    dmp = DMP(keep_approach=True).fit(demonstration, np.linspace(0, 4, 400))
    plain = dmp.trajectory(dt=0.001)
    stepper = dmp.stepper()
    first, second = np.array([3.0, 0, 0]), np.array([0, -4.0, 0])

    def update(s):
        s.set_goal(dmp.goal_ + first)
        s.set_goal(dmp.goal_ + first + second)

    y, _, _ = run(stepper, len(plain.t), 0.001, (1500, update))
    np.testing.assert_allclose(y[:1500], plain.y[:1500], atol=1e-9)
    np.testing.assert_allclose(stepper.target, dmp.goal_ + first + second)
    assert np.linalg.norm(y[-1] - (dmp.goal_ + first + second)) < 1e-3


def test_a_late_update_is_blended_over_the_limits_and_said_to_tilt_the_approach(caplog):
    demonstration = minimum_jerk([[0, 0, 100], [200, 0, 100], [200, 0, 0]], 400)
    dmp = DMP(keep_approach=True).fit(demonstration, np.linspace(0, 4, 400))
    stepper = dmp.stepper()
    for _ in range(3900):
        stepper.step(0.001)
    with caplog.at_level(logging.WARNING):
        blend = stepper.set_goal(
            dmp.goal_ + [5.0, 0, 0], limits={"max_acceleration": 100.0, "max_jerk": 1000.0}
        )
    assert any("approach" in record.getMessage() for record in caplog.records)
    # A quarter of each limit on its own: 5 mm needs sqrt(5 · 7.51 / 25) s and cbrt(5 · 52.5 / 250) s.
    assert blend == pytest.approx(
        max(np.sqrt(5 * 7.5132 / 25.0), np.cbrt(5 * 52.5 / 250.0)), rel=1e-4
    )
    with pytest.raises(ValueError, match="goal"):
        stepper.set_goal([1.0, 2.0])
    with pytest.raises(ValueError, match="blend"):
        stepper.set_goal(dmp.goal_, blend=-1.0)


def test_a_goal_moved_after_the_goal_share_is_complete_without_limits_is_blended_not_jumped():
    """A goal moved 5 mm at 95 % of the motion, no limits given (the command jumped 5 mm in one 1 ms
    step before): the offset is blended within a quarter of the motion's own peaks (measured here on
    the commands: speed, acceleration), never in zero time, and the new goal is reached at rest."""
    demonstration = minimum_jerk([[0, 0, 100], [200, 0, 100], [200, 0, 0]], 400)
    dmp = DMP().fit(demonstration, np.linspace(0, 4, 400))
    own = dmp.trajectory(dt=0.001)
    own_speed, own_acceleration = (
        np.linalg.norm(own.yd, axis=1).max(),
        np.linalg.norm(own.ydd, axis=1).max(),
    )
    stepper = dmp.stepper()
    commands = []
    for step in range(12000):
        if step == int(0.95 * 4000):
            blend = stepper.set_goal(dmp.goal_ + [5.0, 0.0, 0.0])
        commands.append(stepper.step(0.001))
    assert blend > 0.0
    y = np.array([c[0] for c in commands])
    offset = y[int(0.95 * 4000) :] - np.array([c[0] for c in commands])[int(0.95 * 4000)]
    speed = np.linalg.norm(np.diff(y, axis=0), axis=1) / 0.001
    assert (
        speed.max() <= own_speed * (1 + 1e-6) + 0.25 * own_speed
    )  # the motion's own plus a quarter
    assert (
        np.linalg.norm(np.diff(y[-3:], axis=0)) <= 1e-9
        and np.linalg.norm(y[-1] - (dmp.goal_ + [5, 0, 0])) <= 1e-3
    )
    acceleration = np.linalg.norm(np.diff(y, n=2, axis=0), axis=1) / 0.001**2
    assert acceleration[int(0.95 * 4000) :].max() <= 1.3 * own_acceleration
    assert offset.shape[0] > 0


def test_the_blends_peak_derivatives_are_the_constants_used():
    u = np.linspace(0.0, 1.0, 400001)
    first, second = _smoothstep_derivatives(u)
    third = np.gradient(second, u)
    np.testing.assert_allclose(
        [first.max(), np.abs(second).max(), np.abs(third).max()], _PEAKS, rtol=1e-4
    )


def test_a_pose_goal_moved_mid_motion_is_reached_and_the_reported_rates_are_the_motions():
    """``set_goal_pose``: position and orientation reach the new pose at rest; the angular velocity
    the stepper reports is the one of its own quaternions (central differences, measured here)."""
    from scipy.spatial.transform import Rotation

    from bidmp import CartesianDMP
    from bidmp.primitives import angle_between

    s = np.linspace(0.0, 1.0, 300)
    turn = Rotation.from_rotvec(np.outer(10 * s**3 - 15 * s**4 + 6 * s**5, [0.2, -0.4, 2.5]))
    poses = np.hstack(
        [
            minimum_jerk(np.array([[0.0, 0, 150], [120, 30, 60], [120, 30, 0]]), 300),
            (turn * Rotation.from_euler("x", 180, degrees=True)).as_quat(),
        ]
    )
    model = CartesianDMP().fit(poses, np.linspace(0.0, 3.0, 300), units="mm")
    new_pose = poses[-1].copy()
    new_pose[:3] += [4.0, -3.0, 0.0]
    new_pose[3:] = (
        Rotation.from_rotvec([0.0, 0.0, 0.2]) * Rotation.from_quat(poses[-1, 3:])
    ).as_quat()
    stepper, dt, commands = model.stepper(), 0.001, []
    for index in range(3300):
        if index == 1500:
            stepper.set_goal_pose(new_pose)
        commands.append(stepper.step(dt))
    pose = np.array([c[0] for c in commands])
    velocity = np.array([c[1] for c in commands])
    assert np.linalg.norm(pose[-1, :3] - new_pose[:3]) < 1e-2
    assert angle_between(pose[-1:, 3:], new_pose[None, 3:])[0] < 1e-3
    assert np.linalg.norm(velocity[-1]) < 1e-2
    # ω from the quaternions themselves: R(t+dt) R(t-dt)^-1 as a rotation vector over 2 dt.
    rotations = Rotation.from_quat(pose[:, 3:])
    measured = (rotations[2:] * rotations[:-2].inv()).as_rotvec() / (2 * dt)
    np.testing.assert_allclose(
        velocity[1:-1, 3:], measured, atol=2e-3 * max(np.abs(measured).max(), 1.0)
    )
