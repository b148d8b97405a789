"""Threshold families of FR3 joint-position command streams (1 kHz), for judging bidmp's FCI judge
against libfranka where it matters: at the limits.

A family is one stream shape scaled by a factor, ``q(f) = base + f · shape``: its velocity,
acceleration and jerk grow with ``f`` and, where it moves towards a stop, so does how close it
comes. Each is built so that one limit of one joint, its *kind*, is the one reached first, near
``f = 1``, with every other limit well clear there:

``range``
    The joint at rest 50-150 mrad inside a stop, then one jump towards it, landing on the stop
    at ``f = 1``. A jump, because nothing else reaches an FR3's stop: its velocity limits fall to
    zero within ``offset² / (2 · deceleration)`` of each stop (3.6-11.1 mm), so a stream within
    them comes to rest short of the stop. The jump breaks the acceleration limit in its cycle;
    landing past the stop, the range is broken in that same cycle, and the range is judged first.
    So both of a range pair are rejected: landing short by the acceleration (the velocity
    discontinuity), landing past by the range. Its threshold is where the reflex changes
    (:func:`inside`): the stop.
``velocity``
    A smooth rest-to-rest move (raised-cosine ramps of the acceleration up to 8.5 rad/s²) whose
    cruise is the joint's flat velocity limit at ``f = 1``, far enough from the stop it moves
    towards that the position-based limit is not lower there.
``position-based velocity``
    A smooth move towards a stop: up to a cruise of 50-90 % of the flat limit (less where it
    could not brake within 1 rad), then braking gently (1.5-4 rad/s²) to rest, started where its
    speed at ``f = 1`` just touches the limit the position gives (the FR3's ``min(v_max, -offset
    + sqrt(2 · deceleration · distance to the stop))``). Fast and gentle, because franka-sim
    judges this limit at the simulated arm's measured position, not at the last command as
    libfranka's rate limiter does: where the limit falls steeply (slow, near the stop) or the
    arm lags far behind its commands (hard braking), the simulated arm's tracking moves its
    verdict by up to 1 % (measured: docs/results/libfranka.md).
``acceleration``
    Two raised-sine bumps of the acceleration, one up and one (longer) down, the first peaking at
    the 10 rad/s² limit at ``f = 1``, its jerk at most a third of the limit.
``jerk``
    Steps of the acceleration (a held acceleration switched on, off and reversed): the first
    step's jerk is the 5000 rad/s³ limit at ``f = 1``, its acceleration half of the limit.

The families are built from the published tables typed here and closed forms, not from bidmp:
the streams must not be made by the judge they test. Which factor is "at the threshold" is found
by bisection (:func:`bisect`), by whichever judge the caller passes; :func:`inside` says which
side of it a judge's verdict puts a stream.

Used by tests/sim/test_libfranka.py (a few families) and benchmarks/bench_libfranka.py (all).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

DT = 1e-3
HOME = np.array([0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785])  # franka-sim's start pose
# The FR3's limits as published (its URDF's <limit> and <position_based_velocity_limits>,
# libfranka >= 0.10's rate_limiting.h), typed here, not read from bidmp
LOWER = np.array([-2.7501, -1.7918, -2.9065, -3.0481, -2.8101, 0.54092, -3.0196])
UPPER = np.array([2.7501, 1.7918, 2.9065, -0.1458, 2.8101, 4.5205, 3.0196])
VELOCITY = np.array([2.62, 2.62, 2.62, 2.62, 5.26, 4.18, 5.26])
OFFSET = np.array([0.30, 0.20, 0.20, 0.30, 0.35, 0.35, 0.35])
DECELERATION = np.array([6.0, 2.585, 3.5, 4.0, 17.0, 5.5, 17.0])
ACCELERATION, JERK = 10.0, 5000.0

LIMIT_KINDS = ("range", "velocity", "position-based velocity", "acceleration", "jerk")
# what libfranka calls the reflex each kind's stream raises past its threshold
REFLEXES = {
    "range": "joint_motion_generator_position_limits_violation",
    "velocity": "joint_motion_generator_velocity_limits_violation",
    "position-based velocity": "joint_motion_generator_velocity_limits_violation",
    "acceleration": "joint_motion_generator_velocity_discontinuity",
    "jerk": "joint_motion_generator_acceleration_discontinuity",
}


def inside(kind: str, accepted: bool, reflexes) -> bool:
    """Whether a judge's verdict (``accepted``, else the ``reflexes`` it named) puts a stream of
    ``kind`` inside its threshold: accepted; for ``range``, whose streams are all rejected (see
    the module docstring), not rejected for the range."""
    if kind == "range":
        return REFLEXES["range"] not in reflexes
    return bool(accepted)


_LEAD, _TAIL = 5, 5  # samples at rest before and after each move


@dataclass(frozen=True)
class Family:
    """Streams ``base + factor · shape`` (T, 7) rad; ``kind`` (one of :data:`LIMIT_KINDS`) of
    joint ``joint`` (1-7) is the limit reached first, near factor 1; ``towards``: +1 or -1, the
    stop it moves towards (the upper or the lower); ``label``: its parameters, in words."""

    kind: str
    joint: int
    towards: int
    base: np.ndarray
    shape: np.ndarray
    label: str

    def at(self, factor: float) -> np.ndarray:
        return self.base + factor * self.shape


def envelope(joint: int, q, towards: int):
    """The FR3's nominal velocity limit (rad/s, positive) of ``joint`` (0-based) at positions
    ``q`` moving towards its upper (``towards`` = +1) or lower (-1) stop: ``min(v_max, max(0,
    -offset + sqrt(2 · deceleration · distance to that stop)))``."""
    distance = UPPER[joint] - q if towards > 0 else q - LOWER[joint]
    room = np.sqrt(np.maximum(0.0, 2.0 * DECELERATION[joint] * distance))
    return np.minimum(VELOCITY[joint], np.maximum(0.0, room - OFFSET[joint]))


def _rise(n: int) -> np.ndarray:
    """A raised-cosine ramp from 0 to 1 in ``n`` samples (both ends excluded)."""
    return (1.0 - np.cos(np.pi * np.arange(1, n + 1) / (n + 1))) / 2.0


def _bump(n: int) -> np.ndarray:
    """A raised-sine bump of ``n`` samples peaking at exactly 1."""
    bump = np.sin(np.pi * np.arange(1, n + 1) / (n + 1)) ** 2
    return bump / bump.max()


def _plateau(gain: float, peak: float, ramp: int) -> np.ndarray:
    """An acceleration (rad/s²) with raised-cosine ramps of ``ramp`` samples up to and down from
    about ``peak``, held between, that gains exactly ``gain`` rad/s."""
    hold = max(0, int(round(gain / (peak * DT))) - ramp)
    profile = np.concatenate([_rise(ramp), np.ones(hold), _rise(ramp)[::-1]])
    return profile * gain / (profile.sum() * DT)


def _moved(acceleration: np.ndarray) -> np.ndarray:
    """Displacement (rad) of ``acceleration`` (rad/s², one per ms) from rest, with samples at rest
    before and after: its first difference / dt is the velocity, its second the acceleration."""
    padded = np.concatenate([np.zeros(_LEAD), acceleration, np.zeros(_TAIL)])
    return np.cumsum(np.cumsum(padded) * DT) * DT


def _pose(rng: np.random.Generator) -> np.ndarray:
    """franka-sim's start pose, every joint moved by up to 0.15 rad."""
    return HOME + rng.uniform(-0.15, 0.15, 7)


def _family(kind, joint, towards, pose, start, moved, label) -> Family:
    base = np.tile(pose, (moved.shape[0], 1))
    base[:, joint] = start
    shape = np.zeros_like(base)
    shape[:, joint] = towards * moved
    return Family(kind, joint + 1, towards, base, shape, label)


def family(kind: str, joint: int, rng: np.random.Generator) -> Family:
    """One family of ``kind`` for ``joint`` (1-7), its free parameters drawn from ``rng``."""
    if kind not in LIMIT_KINDS:
        raise ValueError(f"kind must be one of {LIMIT_KINDS}, got {kind!r}")
    j = joint - 1
    towards = int(rng.choice([-1, 1]))
    stop = UPPER[j] if towards > 0 else LOWER[j]
    pose = _pose(rng)
    if kind == "range":
        gap = rng.uniform(0.05, 0.15)
        at, held = int(rng.integers(10, 60)), int(rng.integers(10, 40))
        moved = np.concatenate([np.zeros(at), np.full(held, gap)])
        label = f"jump of {gap * 1e3:.0f} mrad onto the stop at sample {at}"
        return _family(kind, j, towards, pose, stop - towards * gap, moved, label)
    if kind == "velocity":
        ramp, cruise = int(rng.integers(30, 80)), int(rng.integers(20, 60))
        up = _plateau(VELOCITY[j], 8.5, ramp)
        moved = _moved(np.concatenate([up, np.zeros(cruise), -up]))
        start = _flat_start(j, towards, moved, rng)
        label = f"{VELOCITY[j]} rad/s for {cruise} ms, ramps of {ramp} ms"
        return _family(kind, j, towards, pose, start, moved, label)
    if kind == "position-based velocity":
        share = rng.uniform(0.5, 0.9)
        braking = rng.uniform(1.5, 4.0)
        cruise, ramp = int(rng.integers(30, 200)), int(rng.integers(20, 80))
        # braked over at most 1 rad (the move has to fit between the stops)
        speed = min(share * VELOCITY[j], math.sqrt(2.0 * braking * 1.0))
        moved = _moved(
            np.concatenate(
                [
                    _plateau(speed, 5.0, ramp),
                    np.zeros(cruise),
                    -_plateau(speed, braking, ramp),
                ]
            )
        )
        start = _touching_start(j, towards, moved)
        label = f"{speed:.2f} rad/s for {cruise} ms, braking at {braking:.1f} rad/s²"
        return _family(kind, j, towards, pose, start, moved, label)
    start = _middle_start(j, rng)
    if kind == "acceleration":
        first, second = int(rng.integers(20, 120)), 0
        second = int(rng.integers(first, 3 * first))
        gap = int(rng.integers(0, 60))
        down = -_bump(second) * _bump(first).sum() / _bump(second).sum()
        moved = _moved(
            np.concatenate([ACCELERATION * _bump(first), np.zeros(gap), ACCELERATION * down])
        )
        label = f"bumps of {first} and {second} ms, {gap} ms apart"
        return _family(kind, j, towards, pose, start, moved, label)
    held, gap = int(rng.integers(3, 60)), int(rng.integers(1, 40))
    back = int(rng.integers(held, 3 * held + 1))
    step = JERK * DT
    acceleration = np.concatenate(
        [np.full(held, step), np.zeros(gap), np.full(back, -step * held / back)]
    )
    label = f"{step:.0f} rad/s² held {held} ms, {gap} ms off, reversed for {back} ms"
    return _family(kind, j, towards, pose, start, _moved(acceleration), label)


def _middle_start(j: int, rng: np.random.Generator) -> float:
    """A start in the middle half of ``j``'s range (its velocity limit is the flat one there)."""
    centre, half = (UPPER[j] + LOWER[j]) / 2, (UPPER[j] - LOWER[j]) / 2
    return centre + rng.uniform(-0.25, 0.25) * half


def _flat_start(j: int, towards: int, moved: np.ndarray, rng) -> float:
    """A start from which ``moved`` (towards the ``towards`` stop) stays where the position-based
    limit is at least 1/0.9 of its speed even at factor 1.05, at least 0.1 rad from either stop."""
    candidates = []
    for start in np.linspace(LOWER[j] + 0.1, UPPER[j] - 0.1, 400):
        q = start + towards * 1.05 * moved
        if q.min() < LOWER[j] + 0.05 or q.max() > UPPER[j] - 0.05:
            continue
        speed = np.abs(np.diff(q)) / DT
        limit = envelope(j, q[1:], towards)
        below_flat = limit < VELOCITY[j]
        if np.all(speed[below_flat] <= 0.9 * limit[below_flat]):
            candidates.append(start)
    if not candidates:
        raise ValueError(f"no start keeps joint {j + 1}'s move in its flat velocity limit")
    return float(rng.choice(candidates))


def _touching_start(j: int, towards: int, moved: np.ndarray) -> float:
    """The start from which ``moved``'s speed, towards the ``towards`` stop, just touches the
    position-based velocity limit (the largest ratio of speed to limit is 1), by bisection."""

    def ratio(start: float) -> float:
        q = start + towards * moved
        limit = envelope(j, q[1:], towards)
        speed = np.abs(np.diff(q)) / DT
        with np.errstate(divide="ignore"):
            return float(np.max(np.where(speed > 0, speed / np.maximum(limit, 1e-300), 0.0)))

    far = (LOWER[j] if towards > 0 else UPPER[j]) + towards * 0.1
    near = (UPPER[j] if towards > 0 else LOWER[j]) - towards * float(np.abs(moved).max())
    if ratio(far) >= 1.0 or ratio(near) <= 1.0:
        raise ValueError(f"joint {j + 1}'s move cannot be placed to touch its limit")
    for _ in range(100):
        middle = (far + near) / 2
        far, near = (middle, near) if ratio(middle) < 1.0 else (far, middle)
    return far


def families(per: int, seed: int, joints=range(1, 8), kinds=LIMIT_KINDS) -> list[Family]:
    """``per`` families of each kind for each joint, drawn from ``seed``."""
    rng = np.random.default_rng(seed)
    return [family(kind, joint, rng) for joint in joints for kind in kinds for _ in range(per)]


def bisect(passes, family: Family, low=0.9, high=1.1, rel=0.005, tries=8) -> tuple:
    """(just passing, just failing) factors of ``family``, within ``rel`` of each other: the
    bracket [low, high] widened until ``passes(family.at(low))`` and not at ``high``, then
    halved (geometrically) until ``high / low - 1 <= rel``."""
    for _ in range(tries):
        if passes(family.at(low)):
            break
        low /= 1.25
    else:
        raise ValueError(f"{family.kind} joint {family.joint}: no passing factor down to {low}")
    for _ in range(tries):
        if not passes(family.at(high)):
            break
        high *= 1.25
    else:
        raise ValueError(f"{family.kind} joint {family.joint}: no failing factor up to {high}")
    while high / low - 1.0 > rel:
        middle = math.sqrt(low * high)
        low, high = (middle, high) if passes(family.at(middle)) else (low, middle)
    return low, high
