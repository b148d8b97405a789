"""What a via-point rollout hands on is used: a start and goal given with the via-points, a caller's
forcing increment beside them, and every via-point's distance in the reach the end's check is
measured against. Several of everything: two or three via-points, two units (mm and m), demonstrations
of several lengths and durations. References independent of the code under test: the via samples
read off the rollout, and the end's move under the least-norm change measured by perturbed
rollouts (one per kernel, as tests/primitives/test_via.py does)."""

from __future__ import annotations

import numpy as np
import pytest

from bidmp import DMP
from bidmp.demonstrations import minimum_jerk


def _dmp(seed: int):
    """A robot-protocol DMP learned from a random demonstration: (rng, unit, dmp)."""
    rng = np.random.default_rng(seed)
    unit = (1.0, 1e-3)[seed % 2]
    points = np.cumsum(rng.uniform(-80, 80, (3, 3)), axis=0) * unit
    n, duration = (120, 260, 390)[seed % 3], float(rng.uniform(1.5, 3.5))
    dmp = DMP(protocol="robot", n_kernels=int(rng.integers(25, 50))).fit(
        minimum_jerk(points, n), np.linspace(0, duration, n)
    )
    return rng, unit, dmp


def _at(trajectory, t) -> np.ndarray:
    return np.array([np.interp(t, trajectory.t, column) for column in trajectory.y.T])


@pytest.mark.parametrize("seed", range(4))
def test_via_points_are_passed_from_a_start_and_goal_given_with_them(seed):
    """The motion from a new start to a new goal through two or three via-points near it passes
    each exactly and starts at the start given: the via solve sees the start and goal the
    rollout runs from."""
    rng, unit, dmp = _dmp(seed)
    start = dmp.start_ + rng.uniform(-30, 30, 3) * unit
    goal = dmp.goal_ + rng.uniform(-30, 30, 3) * unit
    plain = dmp.trajectory(goal, start=start, dt=0.002)
    motion = plain.t[-1]
    times = np.sort(rng.choice(np.linspace(0.15, 0.5, 8), size=2 + seed % 2, replace=False))
    times = times * dmp.duration_ * dmp.settings().tau
    points = np.array([_at(plain, t) for t in times]) + rng.uniform(-6, 6, (times.size, 3)) * unit
    result = dmp.trajectory(goal, start=start, dt=0.002, via=list(zip(times, points)))
    assert motion > times[-1]
    np.testing.assert_allclose(result.y[0], start, atol=1e-9 * max(unit, 1e-3))
    for t, point in zip(times, points):
        assert np.max(np.abs(_at(result, t) - point)) <= 1e-6 * max(unit, 1e-3)


@pytest.mark.parametrize("seed", range(2))
def test_a_callers_forcing_increment_is_kept_beside_the_via_points(seed):
    """A caller's forcing increment (a bump on every kernel) and two via-points: the rollout
    passes the via-points and keeps the bump — it is the bumped motion plus a change that is
    zero at the via samples' own residual: the same via-points with the bump's motion as the
    baseline give the same result as with it built in."""
    rng, unit, dmp = _dmp(seed)
    n_kernels = dmp.weights_.shape[0]
    bump_weights = rng.uniform(-20, 20, (n_kernels, 3)) * unit

    def bump(_, rows):
        return rows @ bump_weights

    bumped = dmp.trajectory(dt=0.002, forcing_increment=bump)
    plain = dmp.trajectory(dt=0.002)
    motion = dmp.duration_ * dmp.settings().tau
    times = np.array([0.25, 0.45]) * motion
    points = np.array([_at(bumped, t) for t in times]) + rng.uniform(-4, 4, (2, 3)) * unit
    via = list(zip(times, points))
    result = dmp.trajectory(dt=0.002, via=via, forcing_increment=bump)
    for t, point in via:
        assert np.max(np.abs(_at(result, t) - point)) <= 1e-6 * max(unit, 1e-3)
    # the bump is in the motion: away from the via-points it follows the bumped motion's shape,
    # not the plain one's (the via change is small: the points are 4 units off the bumped path)
    late = result.t >= 0.8 * motion
    off_bumped = np.max(np.abs(result.y[late] - bumped.y[late]))
    off_plain = np.max(np.abs(result.y[late] - plain.y[late]))
    assert off_bumped < 0.5 * off_plain, (off_bumped, off_plain)


def _end_move(dmp, dt, times, points):
    """(how far the least-norm change moves the end, how fast it leaves it moving): the change
    from perturbed rollouts (one per kernel), the end from the rollout with it."""
    plain = dmp.trajectory(dt=dt)
    response = np.empty((times.size, dmp.weights_.shape[0]))
    for kernel in range(response.shape[1]):
        moved = dmp.trajectory(
            dt=dt,
            forcing_increment=lambda _, rows, kernel=kernel: rows[:, [kernel]] @ np.ones((1, 3)),
        )
        response[:, kernel] = [_at(moved, t)[0] - _at(plain, t)[0] for t in times]
    change = np.linalg.pinv(response) @ (points - np.array([_at(plain, t) for t in times]))
    changed = dmp.trajectory(dt=dt, forcing_increment=lambda _, rows: rows @ change)
    moved_end = changed.y[-1] - plain.y[-1]
    speed = (changed.y[-1] - changed.y[-2]) - (plain.y[-1] - plain.y[-2])
    return float(np.linalg.norm(moved_end)), float(np.linalg.norm(speed)) / dt, plain.t[-1]


@pytest.mark.parametrize("seed", range(3))
def test_the_ends_check_measures_the_reach_of_every_via_point(seed):
    """A late via-point may move the end by at most 1e-4 of the motion's reach (start, goal and
    every via-point). An early via-point on the path and a late one far off it: the far one
    makes the reach; the change is refused exactly when the measured end move is past the share
    of that whole reach (a reach of the near points alone would refuse what is allowed)."""
    rng, unit, dmp = _dmp(seed)
    dt = 0.002
    plain = dmp.trajectory(dt=dt)
    motion = dmp.duration_ * dmp.settings().tau
    decisive = 0
    for late in (0.58, 0.75):
        times = np.array([0.2, late]) * motion
        far = rng.normal(size=3)
        far *= 1000.0 * unit / np.linalg.norm(far)
        points = np.array([_at(plain, times[0]), _at(plain, times[1]) + far])
        corners = np.vstack([dmp.goal_, dmp.start_, points])
        reach = np.max(np.linalg.norm(corners[:, None] - corners[None], axis=2))
        near = np.max(np.linalg.norm(corners[:3, None] - corners[None, :3], axis=2))
        off, speed, horizon = _end_move(dmp, dt, times, points)
        share = max(off / (1e-4 * reach), speed / (1e-2 * reach / horizon))
        if 0.8 < share < 1.25:
            continue  # too near the line for finite differences to decide
        # (generous limits: the swing's own check stays out of the way of the far point)
        via = list(zip(times, points))
        if share < 1.0:
            dmp.trajectory(dt=dt, via=via, limits={"max_velocity": 1e9 * unit})
            decisive += share * reach / near > 1.25  # refused on the near points' reach alone
        else:
            with pytest.raises(ValueError, match="put the via-points earlier"):
                dmp.trajectory(dt=dt, via=via, limits={"max_velocity": 1e9 * unit})
    assert decisive >= 1
