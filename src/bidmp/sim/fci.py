"""The Franka Control Interface's own limits as the judge of a 1 kHz joint command stream: the
tables of the Panda (FER) and the Franka Research 3 (FR3), and the check the robot makes of
every command a joint-position motion generator sends, named as libfranka names the reflex it
raises.

Sources (the numbers are typed from them, and pinned by ``tests/sim/test_fci.py``):

* **Panda (FER)**: position ranges and velocity limits from Franka's *control parameters* page
  (https://frankaemika.github.io/docs/control_parameters.html, "Limits for Panda"); acceleration
  and jerk limits from libfranka 0.9's ``include/franka/rate_limiting.h`` (``kMaxJointAcceleration``,
  ``kMaxJointJerk``, published there less ``kLimitEps`` = 1e-3, the target its own rate limiter
  aims at: the robot's threshold is the nominal value, which is used here);
* **FR3**: position ranges, velocity limits and the position-based velocity limits
  (``velocity_offset``, ``deceleration_limit``) from the FR3's URDF as the robot serves it to
  libfranka >= 0.10 (``<limit>`` and ``<position_based_velocity_limits>``, read by libfranka's
  ``JointVelocityLimitsConfig``), acceleration 10 rad/s² and jerk 5000 rad/s³ on every joint
  from libfranka >= 0.10's ``rate_limiting.h``.

The check, per sample of the stream (1 ms apart, the motion starting at rest where the arm
stands, as a motion generator's first command must, and ending at rest: the robot holds a finished
motion's last command, so a stream still moving at its end jumps to a standstill in one cycle, a
reflex libfranka raises as surely as any other): each joint's position within its range
(``joint_motion_generator_position_limits_violation``), its acceleration (second difference)
within its limit (``..._velocity_discontinuity``: the velocity jumped), its velocity (first
difference) within its limits, on the FR3 those of its position (``..._velocity_limits_violation``),
its jerk (third difference) within its limit (``..._acceleration_discontinuity``). The first
sample that breaks one is the verdict, with the joint, the value and the bound; at one sample
they are named in that order: a step in the commands breaks the velocity limit and the
acceleration limit at once, and the robot calls it a velocity discontinuity (franka-sim's
checker orders them so, from what the hardware reports for a step; measured against it:
``make franka-agreement``).

The FR3's position-based velocity limits are libfranka's own (``Robot::getUpperJointVelocityLimits``
and its deprecated twin ``computeUpperLimitsJointVelocity`` in ``rate_limiting.h``): the URDF's
envelope less ``kJointVelocityLimitsTolerance`` (1e-3 rad/s), at the previous command (the
``q_d`` libfranka's rate limiter evaluates them at: the robot judges a command's step from where
the last one left it), and never below a standstill (a joint held at rest at its stop is not
moving towards it).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import as_trajectory, check_choice, short_token

__all__ = [
    "FCI_LIMITS",
    "CartesianLimits",
    "FCILimits",
    "FCIVerdict",
    "judge_cartesian",
    "judge_commands",
    "match_joint_names",
]

COMMAND_PERIOD_S = 1e-3  # the FCI's control cycle: a joint-position command every millisecond


@dataclass(frozen=True)
class CartesianLimits:
    """The FCI's limits on a Cartesian motion generator's 1 kHz commands (the end effector's
    pose): (velocity, acceleration, jerk) of its translation (m/s, m/s², m/s³), of its rotation
    (rad/s, rad/s², rad/s³) and of the elbow (the redundancy angle; rad/s, rad/s², rad/s³)."""

    translation: tuple
    rotation: tuple
    elbow: tuple


@dataclass(frozen=True)
class FCILimits:
    """One arm's FCI limits, joint 1 to 7 (rad, rad/s, rad/s², rad/s³); ``velocity_offset`` and
    ``deceleration`` (rad/s, rad/s²): the position-based velocity limits (None: the velocity
    limit is the same everywhere), ``joint_names``: what libfranka's robot model calls them."""

    name: str
    lower: tuple
    upper: tuple
    velocity: tuple
    acceleration: tuple
    jerk: tuple
    velocity_offset: tuple | None
    deceleration: tuple | None
    joint_names: tuple
    source: str
    cartesian: CartesianLimits | None = None

    def velocity_bounds(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(lowest, highest) velocity (rad/s) each joint may be commanded at from positions
        ``q`` (T, 7; the previous command's): ``±velocity``, or on an arm with position-based
        limits libfranka's ``min(v_max, max(0, -offset + sqrt(2 · deceleration · (q_max - q))))
        - tolerance`` (and its mirror towards ``q_min``), ``tolerance`` its
        ``kJointVelocityLimitsTolerance`` of 1e-3 rad/s, and never past a standstill: within
        ``offset² / (2 · deceleration)`` of a stop nothing may move towards it, and standing
        still there is allowed."""
        q = np.asarray(q, dtype=float)
        v_max = np.asarray(self.velocity)
        if self.velocity_offset is None:
            return np.broadcast_to(-v_max, q.shape), np.broadcast_to(v_max, q.shape)
        offset, deceleration = np.asarray(self.velocity_offset), np.asarray(self.deceleration)
        upper_room = np.sqrt(np.maximum(0.0, 2.0 * deceleration * (np.asarray(self.upper) - q)))
        lower_room = np.sqrt(np.maximum(0.0, 2.0 * deceleration * (q - np.asarray(self.lower))))
        highest = np.minimum(v_max, np.maximum(0.0, -offset + upper_room)) - _VELOCITY_TOLERANCE
        lowest = np.maximum(-v_max, np.minimum(0.0, offset - lower_room)) + _VELOCITY_TOLERANCE
        return np.minimum(lowest, 0.0), np.maximum(highest, 0.0)


# libfranka's kJointVelocityLimitsTolerance: its position-based limits are narrowed by it
_VELOCITY_TOLERANCE = 1e-3

FCI_LIMITS = {
    "panda": FCILimits(
        "panda",
        lower=(-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973),
        upper=(2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973),
        velocity=(2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100),
        acceleration=(15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0),
        jerk=(7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0),
        velocity_offset=None,
        deceleration=None,
        joint_names=tuple(f"panda_joint{i}" for i in range(1, 8)),
        source="Franka control parameters (Limits for Panda); libfranka 0.9 rate_limiting.h",
        # Franka's control parameters, "Limits for Panda", Cartesian space
        cartesian=CartesianLimits(
            translation=(1.7, 13.0, 6500.0),
            rotation=(2.5, 25.0, 12500.0),
            elbow=(2.175, 10.0, 5000.0),
        ),
    ),
    "fr3": FCILimits(
        "fr3",
        lower=(-2.7501, -1.7918, -2.9065, -3.0481, -2.8101, 0.54092, -3.0196),
        upper=(2.7501, 1.7918, 2.9065, -0.1458, 2.8101, 4.5205, 3.0196),
        velocity=(2.62, 2.62, 2.62, 2.62, 5.26, 4.18, 5.26),
        acceleration=(10.0,) * 7,
        jerk=(5000.0,) * 7,
        velocity_offset=(0.30, 0.20, 0.20, 0.30, 0.35, 0.35, 0.35),
        deceleration=(6.0, 2.585, 3.5, 4.0, 17.0, 5.5, 17.0),
        joint_names=tuple(f"fr3_joint{i}" for i in range(1, 8)),
        # libfranka >= 0.10 rate_limiting.h: kMaxTranslational*, kMaxRotational*, kMaxElbow*
        cartesian=CartesianLimits(
            translation=(3.0, 9.0, 4500.0),
            rotation=(2.5, 17.0, 8500.0),
            elbow=(1.5, 10.0, 5000.0),
        ),
        source="the FR3 URDF as served to libfranka >= 0.10 (<limit>, "
        "<position_based_velocity_limits>); libfranka >= 0.10 rate_limiting.h",
    ),
}

# in the order they are named at one sample (the module docstring)
_REFLEXES = (
    ("position", "joint_motion_generator_position_limits_violation"),
    ("acceleration", "joint_motion_generator_velocity_discontinuity"),
    ("velocity", "joint_motion_generator_velocity_limits_violation"),
    ("jerk", "joint_motion_generator_acceleration_discontinuity"),
)


@dataclass(frozen=True)
class FCIVerdict:
    """What the FCI makes of a command stream: ``ok``, or the first breach: the reflex as
    libfranka names it, the quantity (position, velocity, acceleration, jerk), the joint (1-7),
    the sample (0-based), its value and the bound it passed (rad, rad/s, rad/s², rad/s³)."""

    ok: bool
    reflex: str = ""
    quantity: str = ""
    joint: int = 0
    sample: int = 0
    value: float = 0.0
    bound: float = 0.0
    after_end: bool = False  # in the hold after the last command: the motion did not end at rest
    # a Cartesian stream's breach: "translation" or "rotation" (joint is then 0); "": a joint's
    axis: str = ""

    def reason(self) -> str:
        if self.ok:
            return ""
        units = {"position": "rad", "velocity": "rad/s", "acceleration": "rad/s²", "jerk": "rad/s³"}
        if self.axis == "translation":
            units = {"velocity": "m/s", "acceleration": "m/s²", "jerk": "m/s³"}
        where = (
            "after the last command (held there: the motion does not end at rest)"
            if self.after_end
            else f"at sample {self.sample} ({self.sample * COMMAND_PERIOD_S:.3f} s)"
        )
        what = f"joint {self.joint}" if not self.axis else f"the end effector's {self.axis}"
        return (
            f"{self.reflex}: {what} {self.quantity} {self.value:.6g} "
            f"{units[self.quantity]} {where} against {self.bound:.6g}"
        )


def judge_commands(q, robot: str = "fr3") -> FCIVerdict:
    """The FCI's verdict on joint-position commands ``q`` (T, 7) rad, one per millisecond, the arm
    at rest at ``q[0]`` before the first and held at ``q[-1]`` after the last (module docstring),
    by ``robot``'s tables (``"panda"``, ``"fr3"``). A breach at sample ``T`` or later is the hold
    after the last command: the motion did not end at rest."""
    limits = FCI_LIMITS[check_choice(robot, "robot", tuple(FCI_LIMITS))]
    q = as_trajectory(q, "q", min_points=1, allow_static=True)
    if q.shape[1] != 7:
        raise ValueError(f"q must have 7 columns (joints 1-7), got {q.shape[1]}")
    # at rest where it stands: three samples before the first; held after the last for three
    # more, as the robot holds a finished motion's last command (a motion still moving then
    # jumps to a standstill in one cycle)
    stream = _at_rest_around(q)
    positions = stream[3:]
    velocity = np.diff(stream, axis=0) / COMMAND_PERIOD_S
    acceleration = np.diff(velocity, axis=0) / COMMAND_PERIOD_S
    jerk = np.diff(acceleration, axis=0) / COMMAND_PERIOD_S
    # sample i of the positions: its position, and the differences that end at it
    velocity, acceleration = velocity[2:], acceleration[1:]
    # the velocity limits at the previous command (libfranka's q_d): the step ending at sample i
    # is judged from where sample i - 1 left the joint
    lowest, highest = limits.velocity_bounds(stream[2:-1])
    out_of_range = (positions < np.asarray(limits.lower)) | (positions > np.asarray(limits.upper))
    too_fast = (velocity < lowest) | (velocity > highest)
    velocity_jump = np.abs(acceleration) > np.asarray(limits.acceleration)
    acceleration_jump = np.abs(jerk) > np.asarray(limits.jerk)
    over = {
        "position": out_of_range,
        "velocity": too_fast,
        "acceleration": velocity_jump,
        "jerk": acceleration_jump,
    }
    first = None
    for quantity, _ in _REFLEXES:  # the earliest sample; at one sample, in the reflexes' order
        rows = np.flatnonzero(over[quantity].any(axis=1))
        if rows.size and (first is None or rows[0] < first[1]):
            first = (quantity, int(rows[0]))
    if first is None:
        return FCIVerdict(True)
    quantity, row = first
    values = {
        "position": positions,
        "velocity": velocity,
        "acceleration": acceleration,
        "jerk": jerk,
    }
    joint = int(np.flatnonzero(over[quantity][row])[0])
    value = float(values[quantity][row, joint])
    bound = _bound(limits, quantity, value, joint, lowest[row], highest[row])
    reflex = dict(_REFLEXES)[quantity]
    return FCIVerdict(False, reflex, quantity, joint + 1, row, value, bound, row >= q.shape[0])


_HELD_AFTER = 3  # samples the arm is judged held at the last command after the motion


def _at_rest_around(samples: np.ndarray) -> np.ndarray:
    """``samples`` (T, k) with the first held for three samples before them (at rest where the
    arm stands) and the last for :data:`_HELD_AFTER` after (the robot holding a finished
    motion's last command)."""
    return np.vstack(
        [
            np.repeat(samples[:1], 3, axis=0),
            samples,
            np.repeat(samples[-1:], _HELD_AFTER, axis=0),
        ]
    )


_CARTESIAN_REFLEXES = (
    ("velocity", "cartesian_motion_generator_velocity_limits_violation"),
    ("acceleration", "cartesian_motion_generator_velocity_discontinuity"),
    ("jerk", "cartesian_motion_generator_acceleration_discontinuity"),
)


def judge_cartesian(positions, quaternions=None, robot: str = "fr3") -> FCIVerdict:
    """The FCI's verdict on a Cartesian pose motion generator's commands: end-effector positions
    ``positions`` (T, 3) in metres and, optionally, orientations ``quaternions`` (T, 4; x, y, z,
    w), one per millisecond, at rest before the first and held after the last as for joints
    (:func:`judge_commands`). The translation's speed, acceleration and jerk (norms of the first,
    second and third differences) and the rotation's (of the rotation vectors between
    consecutive orientations, and their differences) against ``robot``'s Cartesian limits. The
    first sample that breaks one is the verdict; at one sample translation before rotation."""
    from scipy.spatial.transform import Rotation

    limits = FCI_LIMITS[check_choice(robot, "robot", tuple(FCI_LIMITS))].cartesian
    positions = as_trajectory(positions, "positions", min_points=1, allow_static=True)
    if positions.shape[1] != 3:
        raise ValueError(f"positions must have 3 columns (x, y, z in m), got {positions.shape[1]}")
    padded = _at_rest_around(positions)
    rates = {"translation": np.diff(padded, axis=0) / COMMAND_PERIOD_S}
    if quaternions is not None:
        quaternions = as_trajectory(quaternions, "quaternions", min_points=1, allow_static=True)
        if quaternions.shape != (positions.shape[0], 4):
            raise ValueError(
                f"quaternions must be (T, 4) like positions' T = {positions.shape[0]}, got "
                f"{quaternions.shape}"
            )
        turned = Rotation.from_quat(_at_rest_around(quaternions))
        # the turn between consecutive commands, in the base frame, per second
        rates["rotation"] = (turned[1:] * turned[:-1].inv()).as_rotvec() / COMMAND_PERIOD_S
    first = None
    for axis, velocity in rates.items():
        acceleration = np.diff(velocity, axis=0) / COMMAND_PERIOD_S
        jerk = np.diff(acceleration, axis=0) / COMMAND_PERIOD_S
        # sample i: the differences that end at it (as judge_commands)
        values = {
            "velocity": np.linalg.norm(velocity[2:], axis=1),
            "acceleration": np.linalg.norm(acceleration[1:], axis=1),
            "jerk": np.linalg.norm(jerk, axis=1),
        }
        bounds = dict(zip(("velocity", "acceleration", "jerk"), getattr(limits, axis)))
        for quantity, reflex in _CARTESIAN_REFLEXES:
            rows = np.flatnonzero(values[quantity] > bounds[quantity])
            if rows.size and (first is None or rows[0] < first.sample):
                first = FCIVerdict(
                    False,
                    reflex,
                    quantity,
                    0,
                    int(rows[0]),
                    float(values[quantity][rows[0]]),
                    bounds[quantity],
                    int(rows[0]) >= positions.shape[0],
                    axis,
                )
    return first or FCIVerdict(True)


def _bound(limits: FCILimits, quantity: str, value: float, joint: int, lowest, highest) -> float:
    """The bound ``value`` passed, with its sign."""
    if quantity == "position":
        return limits.lower[joint] if value < limits.lower[joint] else limits.upper[joint]
    if quantity == "velocity":
        return float(lowest[joint] if value < lowest[joint] else highest[joint])
    table = limits.acceleration if quantity == "acceleration" else limits.jerk
    return math.copysign(table[joint], value)


def match_joint_names(names, robot: str) -> np.ndarray:
    """The columns of ``names`` (a motion file's joint names) in the robot's joint order, each
    name one of ``robot``'s (``panda_joint1..7``, ``fr3_joint1..7``) once: a ValueError naming
    the first named twice, the first that is not the robot's, or the first that is missing."""
    limits = FCI_LIMITS[check_choice(robot, "robot", tuple(FCI_LIMITS))]
    if (
        not isinstance(names, (list, tuple))
        or len(names) > 64
        or not all(isinstance(name, str) and len(name) <= 256 for name in names)
    ):
        raise TypeError(
            f"names must be a list of joint names (strings), got {type(names).__name__}"
        )
    twice = next((name for name in names if names.count(name) > 1), None)
    if twice is not None:
        raise ValueError(
            f"names: joint {short_token(twice, 30)} is named {names.count(twice)} times: which "
            f"column is its command is unknown"
        )
    unknown = [name for name in names if name not in limits.joint_names]
    if unknown:
        raise ValueError(
            f"names: joint {short_token(unknown[0], 30)} is not one of the {robot}'s "
            f"({', '.join(limits.joint_names)})"
        )
    missing = [name for name in limits.joint_names if name not in names]
    if missing:
        raise ValueError(f"names: the motion has no column for {missing[0]}")
    return np.array([names.index(name) for name in limits.joint_names], dtype=int)
