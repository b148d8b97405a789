"""Generated FR3 joint-position command streams (1 kHz) for judging bidmp's FCI judge against
libfranka: smooth moves, planted steps in position, velocity, acceleration and jerk at random
samples and joints, plain DMPs started at rest, moves to and past the ends of the ranges. Each
kind is sized around its threshold (about half of it to twice it), so both verdicts occur.

Used by tests/sim/test_libfranka.py (a few of each) and benchmarks/bench_libfranka.py (240).
Nothing here judges: the streams are built from closed forms of their own.
"""

from __future__ import annotations

import numpy as np

DT = 1e-3
HOME = np.array([0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785])  # franka-sim's start pose
# The FR3's limits as published (typed here, not read from bidmp: the streams must not be built
# by the judge they test)
LOWER = np.array([-2.7501, -1.7918, -2.9065, -3.0481, -2.8101, 0.54092, -3.0196])
UPPER = np.array([2.7501, 1.7918, 2.9065, -0.1458, 2.8101, 4.5205, 3.0196])
VELOCITY, ACCELERATION, JERK = 2.62, 10.0, 5000.0  # joints 1-4 (5-7 are faster: 5.26, 4.18)

KINDS = ("smooth", "position", "velocity", "acceleration", "jerk", "dmp", "range")


def quintic(start, goal, n: int) -> np.ndarray:
    u = np.linspace(0.0, 1.0, n)[:, None]
    return start + (goal - start) * (10 * u**3 - 15 * u**4 + 6 * u**5)


def stream(kind: str, rng: np.random.Generator) -> np.ndarray:
    """One stream (T, 7) rad of ``kind`` (one of :data:`KINDS`)."""
    start = HOME + rng.uniform(-0.2, 0.2, 7)
    joint = int(rng.integers(4))  # joints 1-4: the ones whose limits are those typed above
    size = float(np.exp(rng.uniform(np.log(0.5), np.log(2.0))))  # of the threshold
    n = int(rng.integers(400, 800))
    if kind == "smooth":  # a quintic whose peak acceleration is `size` times the limit
        duration = (n - 1) * DT
        distance = size * ACCELERATION * duration**2 / 5.7735
        goal = start.copy()
        goal[joint] += distance * rng.choice([-1.0, 1.0])
        return quintic(start, goal, n)
    q = np.repeat(start[None], n, axis=0)
    at = int(rng.integers(50, n - 300))
    steps = np.arange(1, n - at + 1, dtype=float)
    if kind == "position":  # a jump s: third differences s, -2 s, s (/dt³): the largest is size x
        # the jerk limit
        q[at:, joint] += size * JERK * DT**3 / 2
    elif (
        kind == "velocity"
    ):  # a ramp: its second difference (at its start) is size x the jerk limit
        q[at:, joint] += size * JERK * DT**2 * steps * DT
    elif kind == "acceleration":  # an acceleration switched on, off, reversed, off: steps of
        # size x (jerk limit x dt) in the acceleration, so a jerk of size x the limit at each
        a = size * JERK * DT
        m = 60
        profile = np.zeros(n - at)
        profile[:m], profile[2 * m : 3 * m] = a, -a
        velocity = np.cumsum(profile) * DT
        q[at:, joint] += np.cumsum(velocity) * DT
    elif kind == "jerk":  # a jerk held for a few samples, then reversed: the acceleration peaks
        # at size x its limit (a triangle), the jerk stays within its limit
        j = 0.8 * JERK
        m = int(round(size * ACCELERATION / (j * DT)))
        jerk = np.zeros(n - at)
        jerk[:m], jerk[m : 2 * m] = j, -j
        jerk[2 * m + 40 : 3 * m + 40], jerk[3 * m + 40 : 4 * m + 40] = -j, j
        acceleration = np.cumsum(jerk) * DT
        q[at:, joint] += np.cumsum(np.cumsum(acceleration) * DT) * DT
    elif kind == "dmp":  # a DMP's spring from rest: its first jerk is alpha beta dq / (tau² dt)
        alpha, beta, tau = 25.0, 6.25, 3.0
        gap = size * JERK * tau**2 * DT / (alpha * beta) * rng.choice([-1.0, 1.0])
        goal = start.copy()
        goal[joint] += gap
        y, v, rows = start.copy(), np.zeros(7), [start.copy()]
        for _ in range(3200):  # long enough to be at rest at the end (|v| < 1e-4 rad/s)
            v = v + alpha * (beta * (goal - y) - tau * v) / tau**2 * DT
            y = y + v * DT
            rows.append(y.copy())
        return np.array(rows)
    elif kind == "range":  # slowly to a range's end: short of it by up to 20 mrad or past it
        side = int(rng.integers(2))
        edge = (LOWER if side == 0 else UPPER)[joint]
        inward = 1.0 if side == 0 else -1.0
        begin = start.copy()
        begin[joint] = edge + inward * 0.15
        end = begin.copy()
        end[joint] = edge + inward * rng.uniform(-0.01, 0.02)
        return quintic(begin, end, int(rng.integers(500, 1500)))
    else:
        raise ValueError(f"kind must be one of {KINDS}, got {kind!r}")
    return q


def streams(count: int, seed: int) -> list[tuple[str, np.ndarray]]:
    """``count`` streams, the kinds in turn, from ``seed``."""
    rng = np.random.default_rng(seed)
    return [
        (KINDS[index % len(KINDS)], stream(KINDS[index % len(KINDS)], rng))
        for index in range(count)
    ]
