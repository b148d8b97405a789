"""Joint limits where the robot moves: the commands as the arm's controller receives
them, every 1 ms, checked against the velocity, acceleration and jerk limits; the measured joints
reported beside them; and the 1 kHz rate limiter the closed loop sends its commands through.

What the Panda's interface (libfranka) checks, and so what counts here:

* every 1 kHz command's velocity, acceleration and jerk, by first, second and third differences
  of the commanded joint positions, within the limits;
* a motion starts and stops at rest: zero velocity *and acceleration*. The commands are checked
  with the start position held for three samples before them and the end position for three
  after (a jump in velocity or acceleration there shows in the differences), and the
  acceleration of the first and the last command must be at most :data:`AT_REST` of the limit.

The measured joints (the simulator's state) are judged too, as the robot's safety controller
judges the arm itself (:func:`_measured_breach`): their velocity within the limits (plus
0.1 rad/s for the estimate's noise, franka-sim's allowance: libfranka's
``joint_velocity_violation``) all the time, and their acceleration — differences over 10 ms
windows of the recorded joint velocities, the way a robot's own filtered state shows it —
within the limits outside a disturbance (a held joint stops at once: the world's doing, not the
arm's). Their peaks are reported beside the commands'.
"""

from __future__ import annotations

import numpy as np

from ..tasks.contract import AT_REST, PADDING, CommandPeaks, command_peaks
from .backend import SIM_STEP, JointLimits

__all__ = ["PADDING", "AT_REST"]

_WINDOW = 0.01  # s: the measured joints' estimator (differences over 10 ms windows)
MEASURED_VELOCITY_NOISE = 0.1  # rad/s over the velocity limit before a measured velocity counts


def _worst(values: np.ndarray, limit) -> float:
    """The largest ``|values| / limit`` over samples and joints (0 without a limit or samples)."""
    if limit is None or values.shape[0] == 0:
        return 0.0
    return float(np.max(np.abs(values) / np.asarray(limit, dtype=float)))


def _command_peaks(commands: np.ndarray, limits: JointLimits, dt: float = SIM_STEP) -> CommandPeaks:
    """The peaks of joint position commands (n, J) sent every ``dt`` seconds, from rest to rest: the
    contract's check (:func:`bidmp.tasks.contract.command_peaks`)."""
    return command_peaks(commands, limits, dt)


def _windowed_acceleration(velocities, record_step: float) -> tuple[np.ndarray, float]:
    """The measured joints' accelerations (rad/s²) by differences over 10 ms windows of their
    velocities (n, J) recorded every ``record_step`` s, and the windows' length (s)."""
    window = max(int(round(_WINDOW / record_step)), 1)
    step = window * record_step
    return np.diff(np.asarray(velocities, dtype=float)[::window], axis=0) / step, step


def _measured_peaks(
    velocities: np.ndarray, record_step: float, limits: JointLimits
) -> CommandPeaks:
    """Peaks of the measured joints from their recorded velocities (n, 7), one every
    ``record_step`` seconds: velocity as recorded, acceleration and jerk by differences over
    10 ms windows."""
    acceleration, step = _windowed_acceleration(velocities, record_step)
    jerk = np.diff(acceleration, axis=0) / step

    return CommandPeaks(
        _worst(np.asarray(velocities), limits.velocity),
        _worst(acceleration, limits.acceleration),
        _worst(jerk, limits.jerk),
    )


def _measured_breach(
    velocities: np.ndarray,
    record_step: float,
    limits: JointLimits,
    disturbed: tuple[float, float] | None = None,
) -> str:
    """The first breach of the measured joints (module docstring), or ``""``: ``velocities``
    (n, J) rad/s recorded every ``record_step`` s from the run's start; ``disturbed``: the
    (start, end) seconds of a disturbance, where the accelerations are not the arm's own."""
    velocities = np.asarray(velocities, dtype=float)
    over = np.abs(velocities) > np.asarray(limits.velocity, dtype=float) + MEASURED_VELOCITY_NOISE
    if over.any():
        row, joint = np.argwhere(over)[0]
        return (
            f"joint_velocity_violation: the measured joint {joint + 1} moved at "
            f"{velocities[row, joint]:.3g} rad/s at {row * record_step:.3f} s (limit "
            f"{limits.velocity[joint]:g})"
        )
    acceleration, step = _windowed_acceleration(velocities, record_step)
    ends = np.arange(1, acceleration.shape[0] + 1) * step  # each difference spans (end - step, end]
    counted = np.ones(ends.shape, dtype=bool)
    if disturbed is not None:  # differences that end before it, or begin once it is over
        counted = (ends < disturbed[0]) | (ends - step >= disturbed[1])
    over = (np.abs(acceleration) > np.asarray(limits.acceleration, dtype=float)) & counted[:, None]
    if over.any():
        row, joint = np.argwhere(over)[0]
        return (
            f"the measured joint {joint + 1} accelerated at {acceleration[row, joint]:.3g} rad/s² "
            f"at {ends[row]:.3f} s (limit {limits.acceleration[joint]:g}; 10 ms differences)"
        )
    return ""


class _RateLimiter:
    """A 1 kHz jerk-limited command generator that follows a moving target: cascaded
    proportional loops (position → velocity → acceleration → jerk, each three times faster than
    the one outside it) with the target's velocity fed forward and each level clipped to
    ``margin`` times its limit. So every command it returns is within the jerk and acceleration
    limits by construction and within the velocity limit up to the inner loop's overshoot, which
    :func:`_command_peaks` measures; it starts at rest at ``start`` and comes to rest at a target
    that stands still. (Clipping the differences of the target alone, as a plain rate limiter
    does, is not stable: on a held joint its error grows into a limit cycle.)"""

    # Loop gains (1/s): the acceleration loop 6.7 ms, the velocity loop 20 ms, position 67 ms.
    _GAINS = (15.0, 50.0, 150.0)

    def __init__(
        self, start: np.ndarray, limits: JointLimits, margin: float, dt: float = SIM_STEP
    ) -> None:
        self.position = np.asarray(start, dtype=float).copy()
        self.velocity = np.zeros_like(self.position)
        self.acceleration = np.zeros_like(self.position)
        self.dt = dt
        self.max_velocity = margin * np.asarray(limits.velocity, dtype=float)
        self.max_acceleration = margin * np.asarray(limits.acceleration, dtype=float)
        jerk = limits.jerk if limits.jerk is not None else np.full(self.position.shape, np.inf)
        self.max_jerk = margin * np.asarray(jerk, dtype=float)

    def __call__(
        self,
        target: np.ndarray,
        target_velocity: np.ndarray | None = None,
        target_acceleration: np.ndarray | None = None,
    ) -> np.ndarray:
        """The next command (J,) rad towards ``target``, moving at ``target_velocity`` (rad/s) with
        ``target_acceleration`` (rad/s²), both fed forward: a smooth target within the limits is
        followed without overshoot (the velocity fed forward alone, the lagging velocity loop
        overshoots where the target brakes)."""
        position_gain, velocity_gain, acceleration_gain = self._GAINS
        feed = 0.0 if target_velocity is None else np.asarray(target_velocity, dtype=float)
        feed_acceleration = (
            0.0 if target_acceleration is None else np.asarray(target_acceleration, dtype=float)
        )
        wanted_velocity = np.clip(
            feed + position_gain * (np.asarray(target, dtype=float) - self.position),
            -self.max_velocity,
            self.max_velocity,
        )
        wanted_acceleration = np.clip(
            feed_acceleration + velocity_gain * (wanted_velocity - self.velocity),
            -self.max_acceleration,
            self.max_acceleration,
        )
        jerk = np.clip(
            acceleration_gain * (wanted_acceleration - self.acceleration),
            -self.max_jerk,
            self.max_jerk,
        )
        self.acceleration = self.acceleration + jerk * self.dt
        self.velocity = self.velocity + self.acceleration * self.dt
        self.position = self.position + self.velocity * self.dt
        return self.position.copy()


# -- the closed loop's commands between its 100 Hz targets (any backend) --------------------
def _hermite(
    q0, v0, q1, v1, share: float, duration: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Position, velocity and acceleration at ``share`` (0-1) of the cubic from ``(q0, v0)`` to
    ``(q1, v1)`` over ``duration`` seconds (velocities per second)."""
    s, h = share, duration
    position = (
        (2 * s**3 - 3 * s**2 + 1) * q0
        + (s**3 - 2 * s**2 + s) * h * v0
        + (3 * s**2 - 2 * s**3) * q1
        + (s**3 - s**2) * h * v1
    )
    velocity = (
        (6 * s**2 - 6 * s) * (q0 - q1) / h + (3 * s**2 - 4 * s + 1) * v0 + (3 * s**2 - 2 * s) * v1
    )
    acceleration = ((12 * s - 6) * (q0 - q1) / h + (6 * s - 4) * v0 + (6 * s - 2) * v1) / h
    return position, velocity, acceleration


_AHEAD = 2e-3  # s: the joint velocity is the IK's own, by a step of the command's velocity this far ahead


def _joint_velocity(cell, q: np.ndarray, point_m: np.ndarray, velocity_m: np.ndarray) -> np.ndarray:
    """The joint velocities (rad/s) with which the IK's own solutions follow the tool's mouth moving
    at ``velocity_m`` (m/s) from ``point_m`` (m), where it is at joints ``q``: the IK solved
    :data:`_AHEAD` further along, from ``q`` (a redundant arm's least-norm Jacobian velocity takes
    another null-space path than its IK does, and the segments between the IK's targets then bend)."""
    if not np.any(velocity_m):
        return np.zeros_like(q)
    ahead, _ = cell.solve_ik(point_m + velocity_m * _AHEAD, q)
    return (ahead - q) / _AHEAD
