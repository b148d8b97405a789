"""The time-optimal timing of a joint path, checked from outside: the commands sampled at 1 kHz and
differenced here (velocity, acceleration, jerk as an arm's interface computes them), the path's
waypoints, the ends at rest, against TOPP-RA's own bang-bang optimum and a uniform timing."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bidmp.planning import time_path

pytest.importorskip("toppra")


def differences(timed, dt=1e-3):
    """Velocity, acceleration, jerk of the path sampled every ``dt`` seconds (rest held at the ends)."""
    count = int(np.ceil(timed.duration / dt)) + 1
    q = timed(np.linspace(0.0, 1.0, count))
    q = np.vstack([q[:1]] * 3 + [q] + [q[-1:]] * 3)
    step = timed.duration / (count - 1)
    v = np.diff(q, axis=0) / step
    a = np.diff(v, axis=0) / step
    j = np.diff(a, axis=0) / step
    return q, v, a, j


def random_path(seed: int, joints: int, points: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    return np.cumsum(rng.normal(0.0, 0.4, (points, joints)), axis=0)


@settings(max_examples=12, deadline=None)
@given(st.integers(0, 10_000), st.integers(2, 7), st.integers(2, 9))
def test_a_timed_path_passes_its_waypoints_within_the_limits_from_rest_to_rest(
    seed, joints, points
):
    path = random_path(seed, joints, points)
    rng = np.random.default_rng(seed + 1)
    velocity = rng.uniform(1.0, 3.0, joints)
    acceleration = rng.uniform(5.0, 20.0, joints)
    jerk = rng.uniform(500.0, 8000.0, joints)
    timed = time_path(path, velocity, acceleration, jerk, margin=0.9)
    q, v, a, j = differences(timed)
    # its ends, at rest
    assert np.allclose(q[0], path[0], atol=1e-12) and np.allclose(q[-1], path[-1], atol=1e-12)
    assert np.allclose(timed(np.array([0.0, 1.0]), 1), 0.0, atol=1e-9)
    assert np.allclose(timed(np.array([0.0, 1.0]), 2), 0.0, atol=1e-6)
    # every waypoint on the way, in order
    dense = timed(np.linspace(0.0, 1.0, 20_001))
    for waypoint in path:
        assert np.min(np.linalg.norm(dense - waypoint, axis=1)) < 2e-3
    # the limits, by the differences (1 % for the sampling of the peaks)
    assert np.all(np.max(np.abs(v), axis=0) <= 0.9 * velocity * 1.01)
    assert np.all(np.max(np.abs(a), axis=0) <= 0.9 * acceleration * 1.01)
    assert np.all(np.max(np.abs(j), axis=0) <= 0.9 * jerk * 1.02)
    # and no faster than any joint can cover its largest step at its top speed
    assert timed.duration >= np.max(np.abs(np.diff(path, axis=0)).sum(axis=0) / velocity) * 0.999


def test_the_time_optimal_timing_is_near_toppras_optimum_and_beats_the_uniform_one():
    """TOPP-RA's own bang-bang profile is the fastest under the velocity and acceleration limits:
    ours may not be faster (it would break a limit), and is within 35 % of it (smoothed for the
    jerk); a minimum-jerk law along the same path is slower."""
    import toppra
    import toppra.algorithm as algorithm
    import toppra.constraint as constraint

    from bidmp.planning.timing import _uniform

    path = random_path(4, 6, 7)
    velocity, acceleration = np.full(6, 2.0), np.full(6, 10.0)
    timed = time_path(path, velocity, acceleration, None, margin=1.0)
    assert timed.timing == "time-optimal"
    lengths = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
    grid = np.linspace(0.0, 1.0, 200)
    reference = algorithm.TOPPRA(
        [
            constraint.JointVelocityConstraint(np.column_stack([-velocity, velocity])),
            constraint.JointAccelerationConstraint(np.column_stack([-acceleration, acceleration])),
        ],
        toppra.SplineInterpolator(grid, timed.geometric(grid)),
        parametrizer="ParametrizeConstAccel",
    ).compute_trajectory(0.0, 0.0)
    assert reference.duration * 0.999 <= timed.duration <= 1.35 * reference.duration
    uniform = _uniform(timed.geometric, [velocity, acceleration, None], 1.0)
    assert timed.duration < uniform.duration
    assert lengths[-1] > 0


def test_a_path_that_does_not_move_or_limits_of_the_wrong_size_are_refused():
    with pytest.raises(ValueError, match="waypoints must move"):
        time_path(np.zeros((3, 2)), [1.0, 1.0], [1.0, 1.0])
    with pytest.raises(ValueError, match="velocity must have 2 entries"):
        time_path(np.eye(2), [1.0], [1.0, 1.0])
    with pytest.raises(ValueError, match="acceleration must be > 0"):
        time_path(np.eye(2), [1.0, 1.0], [1.0, 0.0])
    with pytest.raises(ValueError, match="margin must be <= 1"):
        time_path(np.eye(2), [1.0, 1.0], [1.0, 1.0], margin=1.5)


@pytest.mark.parametrize(
    "binding, velocity, acceleration, jerk",
    [
        ("velocity", 0.5, 200.0, 1e5),
        ("acceleration", 20.0, 2.0, None),
        ("acceleration", 20.0, 2.0, 1e6),
        ("jerk", 20.0, 200.0, 5.0),
    ],
)
@pytest.mark.parametrize("seed", [1, 2])
def test_each_limit_binds_where_it_is_the_tightest_and_the_reported_peaks_are_the_motions(
    binding, velocity, acceleration, jerk, seed
):
    """Timed as fast as the limits allow: the limit that binds (by the limits chosen) is reached,
    to within 3 % of the margin, by the motion's own 1 kHz differences (taken here), and no limit
    is passed; ``TimedPath.peaks`` are those measured peaks (what a plan reports and a job
    refuses a plan by): the binding one to 3 %, the others never below them (the analytic jerk of a
    cubic path steps where 1 kHz differences average the step)."""
    path = random_path(seed, 4, 5)
    limits = {
        "velocity": np.full(4, velocity),
        "acceleration": np.full(4, acceleration),
        "jerk": None if jerk is None else np.full(4, jerk),
    }
    timed = time_path(path, limits["velocity"], limits["acceleration"], limits["jerk"], margin=0.8)
    _, v, a, j = differences(timed)
    measured = {
        "velocity": float(np.max(np.abs(v) / limits["velocity"])),
        "acceleration": float(np.max(np.abs(a) / limits["acceleration"])),
        "jerk": 0.0 if jerk is None else float(np.max(np.abs(j) / limits["jerk"])),
    }
    assert measured[binding] >= 0.8 * 0.97, (binding, measured)
    assert all(value <= 0.8 * 1.02 for value in measured.values()), measured
    for kind, reported in zip(("velocity", "acceleration", "jerk"), timed.peaks):
        assert reported >= measured[kind] * 0.97 - 1e-9, (kind, timed.peaks, measured)
        if kind == binding:
            assert reported == pytest.approx(measured[kind], rel=0.03), (kind, timed.peaks)
        assert reported <= 0.8 + 1e-9, (kind, timed.peaks)
