"""Goals that move during execution (:meth:`bidmp.primitives.stepper.DMPStepper.set_goal`).

A goal moved by Δ mid-motion is not written into the running system's goal: with ``K = αβ`` that
would step its input by ``αβ Δ (1 - gate)``, an acceleration step at once, and with the approach
gate already closed the whole offset would arrive as a spring transient during the final approach.
Instead the command is offset by ``Δ s((t - t₀) / T)``, ``s`` the 7th-order smoothstep (zero
velocity, acceleration and jerk at both ends), over the time ``T`` from the update to where the
DMP's own goal share is complete (the start of the final approach with ``keep_approach``, else
where the goal's share reaches 1): the system is linear, so this is the motion the DMP would have
made to the new goal from the update on with its offset applied smoothly, it reaches the new goal
at rest, and a final approach that starts after the blend is a translated copy of the old one.
``T`` is never shorter than what keeps the offset's own peaks within a share of the limits.
"""

from __future__ import annotations

import numpy as np

from .._checks import as_vector, short_token
from .goals import _smoothstep, _smoothstep_derivatives
from .limits import MotionLimits

__all__ = []

# Peaks of the 7th-order smoothstep's derivatives on [0, 1]: s' 35/16, s'' 7.513, s''' 52.5
# (numerically, tests/primitives/test_goal_shift.py checks them): an offset Δ over T peaks at |Δ| s^(k) / T^k.
_PEAKS = (35.0 / 16.0, 7.5132, 52.5)
_LIMIT_SHARE = 0.25  # of each limit an online goal's offset may use on its own


def _shortest_blend(delta: np.ndarray, limits: dict | None) -> float:
    """The shortest blend (s) whose offset ``delta`` (D,) keeps its own peak speed, acceleration and
    jerk within :data:`_LIMIT_SHARE` of ``limits`` (``max_velocity`` ... in units/s, /s², /s³;
    scalars, on the norm); 0 without limits."""
    size = float(np.linalg.norm(delta))
    shortest = 0.0
    if isinstance(limits, MotionLimits):
        limits = {key: value for key, value in limits.caps().items() if key != "norm"}
    if limits is not None and (
        not isinstance(limits, dict)
        or set(limits) - {"max_velocity", "max_acceleration", "max_jerk"}
    ):
        raise ValueError(
            f"limits must be a dict of max_velocity, max_acceleration and max_jerk (units/s, /s², /s³), "
            f"got {short_token(limits, 40)}"
        )
    for power, key in enumerate(("max_velocity", "max_acceleration", "max_jerk"), start=1):
        limit = None if not limits else limits.get(key)
        if limit is not None and size > 0.0:
            limit = float(np.min(as_vector(limit, f"limits[{key!r}]", positive=True)))
            shortest = max(
                shortest, (size * _PEAKS[power - 1] / (_LIMIT_SHARE * limit)) ** (1.0 / power)
            )
    return shortest


class _GoalShifts:
    """The smooth offsets of every goal update so far: summed for positions (:meth:`at`), composed
    for orientations (``PoseStepper``, from :meth:`profiles`)."""

    def __init__(self, n_dims: int) -> None:
        self._shifts: list[tuple[np.ndarray, float, float]] = []  # (delta, start s, duration s)
        self.total = np.zeros(n_dims)

    def add(self, delta: np.ndarray, start: float, duration: float) -> None:
        self._shifts.append((delta.copy(), float(start), float(duration)))
        self.total = self.total + delta

    def __bool__(self) -> bool:
        return bool(self._shifts)

    def profiles(self, t: float):
        """Per update, in the order given: ``(delta, s, ṡ, s̈)`` at motion time ``t`` (s) — the
        share of ``delta`` applied and its rates (1/s, 1/s²)."""
        for delta, start, duration in self._shifts:
            if duration <= 0.0:
                yield delta, 1.0, 0.0, 0.0
                continue
            # any t, inf too: the smoothstep is flat outside [0, 1]
            u = np.array(min(max((t - start) / duration, -1.0), 2.0))
            first, second = _smoothstep_derivatives(u)
            yield delta, float(_smoothstep(u)), float(first) / duration, float(second) / duration**2

    def at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Offset (D,), its velocity and acceleration at motion time ``t`` (s)."""
        offset, velocity, acceleration = (np.zeros_like(self.total) for _ in range(3))
        for delta, share, rate, rate_rate in self.profiles(t):
            offset, velocity, acceleration = (
                offset + share * delta,
                velocity + rate * delta,
                acceleration + rate_rate * delta,
            )
        return offset, velocity, acceleration


def _goal_complete_time(goal_response: np.ndarray, period: float, tolerance: float = 1e-6) -> float:
    """The time (s) from which the response of the position to a unit goal shift stays within
    ``tolerance`` of 1 (``goal_response`` (n,) on a grid ``period`` s apart): where the DMP's own
    goal offset is complete (the final approach's start with the approach gate)."""
    off = np.flatnonzero(np.abs(goal_response - 1.0) > tolerance)
    if off.size == 0:
        return 0.0
    return float(min(off[-1] + 1, goal_response.shape[0] - 1) * period)
