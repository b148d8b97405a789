"""The FCI judge (``bidmp.sim.fci.judge_commands``) against a plain, slow reading of the same
tables (property-based): streams drawn by hypothesis (1-60 commands of 7 joints, started
anywhere from a little outside a joint's range to inside it, ramps up to past the velocity
limits, noise from far under to far over the jerk limits) are judged by the module and by the
loop below, written from the module's docstring and libfranka's description, not from its code:
the arm at rest three cycles before the first command and held three after the last, each cycle
each joint's position, first, second and third difference checked against its limit one by
one. The first cycle with a breach is the verdict; within it position, acceleration, velocity,
jerk in that order, and the lowest joint."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from bidmp.sim.fci import FCI_LIMITS, judge_commands

DT = 1e-3
TOLERANCE = 1e-3  # libfranka's kJointVelocityLimitsTolerance


def _velocity_room(limits, joint: int, q: float) -> tuple[float, float]:
    """(lowest, highest) velocity of ``joint`` from position ``q`` (the previous command): the
    fixed limit, or on an arm with position-based limits the braking room to each stop (less the
    offset), never past the fixed limit, narrowed by the tolerance, never past a standstill."""
    v_max = limits.velocity[joint]
    if limits.velocity_offset is None:
        return -v_max, v_max
    offset, braking = limits.velocity_offset[joint], limits.deceleration[joint]
    towards_upper = math.sqrt(max(0.0, 2.0 * braking * (limits.upper[joint] - q)))
    towards_lower = math.sqrt(max(0.0, 2.0 * braking * (q - limits.lower[joint])))
    highest = min(v_max, max(0.0, towards_upper - offset)) - TOLERANCE
    lowest = max(-v_max, min(0.0, offset - towards_lower)) + TOLERANCE
    return min(lowest, 0.0), max(highest, 0.0)


def plain_verdict(q: np.ndarray, robot: str):
    """(quantity, joint 1-7, sample) of the first breach, or None: a loop over cycles and joints."""
    limits = FCI_LIMITS[robot]
    rows = [list(q[0])] * 3 + [list(row) for row in q] + [list(q[-1])] * 3
    for sample in range(len(rows) - 3):
        cycle = sample + 3
        breaches = {}
        for joint in range(7):
            p = [rows[cycle - back][joint] for back in range(4)]  # now, 1, 2, 3 cycles before
            v = [(p[k] - p[k + 1]) / DT for k in range(3)]
            a = [(v[k] - v[k + 1]) / DT for k in range(2)]
            j = (a[0] - a[1]) / DT
            lowest, highest = _velocity_room(limits, joint, p[1])
            checks = (
                ("position", not limits.lower[joint] <= p[0] <= limits.upper[joint]),
                ("velocity", not lowest <= v[0] <= highest),
                ("acceleration", abs(a[0]) > limits.acceleration[joint]),
                ("jerk", abs(j) > limits.jerk[joint]),
            )
            for quantity, broken in checks:
                if broken and quantity not in breaches:
                    breaches[quantity] = joint + 1
        for quantity in ("position", "acceleration", "velocity", "jerk"):
            if quantity in breaches:
                return quantity, breaches[quantity], sample
    return None


_SEVEN = {"min_size": 7, "max_size": 7}


@st.composite
def streams(draw):
    """(robot, commands (T, 7) rad): per joint a start (a little outside the range, inside it, or
    within a few mrad of a stop, where the FR3's velocity bound falls to a standstill), a
    jerk-limited acceleration of drawn jerk (1e-6 to 1.3 times the limit) and cap (0 to 1.3
    times the acceleration limit), from rest; noise of a drawn size on top. Short streams, and
    long ones (past 0.26 s: time to reach a velocity limit within the acceleration limit)."""
    robot = draw(st.sampled_from(sorted(FCI_LIMITS)))
    limits = FCI_LIMITS[robot]
    count = draw(st.one_of(st.integers(1, 60), st.integers(250, 400)))
    lower, upper = np.array(limits.lower), np.array(limits.upper)
    near_stop = st.one_of(st.floats(0.0, 0.002), st.floats(0.998, 1.0))
    where = np.array(draw(st.lists(st.one_of(st.floats(-0.02, 1.02), near_stop), **_SEVEN)))
    start = lower + where * (upper - lower)
    jerk = np.array(draw(st.lists(st.floats(-6.0, 0.12), **_SEVEN)))
    signs = np.array(draw(st.lists(st.sampled_from([-1.0, 1.0]), **_SEVEN)))
    cap = np.array(draw(st.lists(st.floats(0.0, 1.3), **_SEVEN))) * np.array(limits.acceleration)
    t = np.arange(count)[:, None] * DT
    acceleration = signs * np.minimum(10.0**jerk * np.array(limits.jerk) * t, cap)
    velocity = np.cumsum(acceleration, axis=0) * DT
    path = start + np.cumsum(velocity, axis=0) * DT
    # noise of a drawn size: 1e-12 rad (nothing) to 1e-5 rad a cycle (jerks of 1e4 rad/s³)
    size = 10.0 ** draw(st.floats(-12.0, -5.0))
    seed = draw(st.integers(0, 2**32 - 1))
    noise = np.random.default_rng(seed).standard_normal((count, 7)) * size
    return robot, path + noise


def test_the_judge_gives_the_plain_loops_first_breach():
    """Every drawn stream judged alike; over the draw, every verdict reached (the strategy's own
    reach: a draw that never breaks a limit, or only one, would test nothing)."""
    seen = set()

    @settings(max_examples=200, deadline=None, derandomize=True, database=None)
    @given(streams())
    def judged_alike(stream):
        robot, q = stream
        verdict = judge_commands(q, robot)
        expected = plain_verdict(q, robot)
        if expected is None:
            assert verdict.ok, verdict.reason()
        else:
            assert not verdict.ok
            assert (verdict.quantity, verdict.joint, verdict.sample) == expected, verdict.reason()
            assert verdict.after_end == (expected[2] >= len(q))
        seen.add(None if expected is None else expected[0])

    judged_alike()
    assert seen == {"position", "velocity", "acceleration", "jerk", None}, seen
