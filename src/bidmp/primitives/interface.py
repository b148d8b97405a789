"""The one call every point-to-point kind answers, and the probabilistic kinds' own.

:class:`MotionPrimitive` is what the CLI, the tasks, the repairer and the viewer call, whatever
the kind (the DMPs, pose DMPs and Bi-DMPs, the ProMP, the probabilistic DMP, MultiDMP):
``trajectory(goal=None, *, start=None, start_velocity=None, duration=None, dt=None, via=(),
limits=None)`` with one meaning — from ``start`` (at ``start_velocity``) through each via-point
``(t, point)`` at ``t`` seconds to ``goal``, over ``duration`` seconds sampled every ``dt``,
within ``limits`` (a :class:`bidmp.MotionLimits`: slowed uniformly where a cap binds; with
via-points checked, not re-timed, since the points would move in time). A probabilistic kind
answers with its mean conditioned on what is given (its docstring says so; the spread is
:class:`ProbabilisticPrimitive`'s). The rhythmic kinds read ``goal`` as their anchor and keep
their own keywords (cycles, frequency, amplitude): they are not point-to-point.

MP_PyTorch's ``ProbabilisticMPInterface`` is the anchor for the second protocol.

Layer 1: the package's own math.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from .._checks import as_points, check_real, short_token
from .limits import MotionLimits, as_motion_limits
from .timing import Trajectory, scale_factor

__all__ = ["MotionPrimitive", "ProbabilisticPrimitive"]


@runtime_checkable
class MotionPrimitive(Protocol):
    """A fitted point-to-point primitive: one call for a timed motion (module docstring)."""

    def trajectory(
        self,
        goal=None,
        *,
        start=None,
        start_velocity=None,
        duration: float | None = None,
        dt: float | None = None,
        via=(),
        limits: MotionLimits | dict | None = None,
    ):
        """The motion from ``start`` through ``via`` to ``goal`` (module docstring)."""


@runtime_checkable
class ProbabilisticPrimitive(MotionPrimitive, Protocol):
    """A point-to-point primitive with a distribution over motions: conditioned on points
    (exactly or with a variance) it is another of its kind; its spread is a standard deviation
    per sample."""

    def conditioned(self, *, start=None, start_velocity=None, goal=None, via=()):
        """A copy conditioned exactly on the given start, start velocity, via-points and goal."""

    def std(self, times=None, n_steps: int = 100) -> np.ndarray:
        """(T, D): the positions' standard deviation (units) at ``times`` (s)."""


# -- what the kinds share -------------------------------------------------------------------------
def _none_if_empty(via):
    """``via`` with an empty sequence (the interface's default, ``()``) read as None: no
    via-points."""
    if via is not None and not isinstance(via, (str, bytes)) and hasattr(via, "__len__"):
        if len(via) == 0:
            return None
    return via


def _refuse_start_velocity(start_velocity, kind: str) -> None:
    """A pose kind's motion starts at rest: a start velocity is refused, naming the kind."""
    if start_velocity is not None:
        raise ValueError(
            f"start_velocity: a {kind}'s motion starts at rest (a moving start is not supported "
            "for poses); give None"
        )


def _via_points(via, n_dims: int, duration: float) -> tuple[np.ndarray, np.ndarray]:
    """``via`` — a sequence of ``(t, point)`` — as times (K,) (s, in (0, duration]) and points
    (K, D); K may be 0 (``()`` or None)."""
    if via is None:
        return np.zeros(0), np.zeros((0, n_dims))
    if isinstance(via, (str, bytes, dict)) or not hasattr(via, "__len__"):
        raise TypeError(f"via must be a sequence of (t, point) pairs, got {type(via).__name__}")
    times, points = [], []
    for index, pair in enumerate(via):
        if not hasattr(pair, "__len__") or isinstance(pair, (str, bytes)) or len(pair) != 2:
            raise ValueError(
                f"via[{index}] must be a (t, point) pair, got {short_token(repr(pair), 40)}"
            )
        t = check_real(pair[0], f"via[{index}]'s time", positive=True)
        if t > duration * (1.0 + 1e-12):
            raise ValueError(
                f"via[{index}]'s time {t:.6g} s is past the motion's duration {duration:.6g} s"
            )
        times.append(t)
        points.append(as_points(pair[1], n_dims, f"via[{index}]'s point")[0])
    if not times:
        return np.zeros(0), np.zeros((0, n_dims))
    return np.asarray(times, dtype=float), np.vstack(points)


def _within_limits(
    motion_over, duration: float, limits, *, has_via: bool, bounds: tuple[float, float]
) -> Trajectory:
    """``motion_over(duration)`` (a :class:`Trajectory` over that many seconds, the same path at
    any duration) within ``limits``: as given when it meets them (a cap never hurries it, unless
    ``fastest``), otherwise uniformly slowed to the shortest duration that does. Via-points are
    at fixed times: a motion through them is checked, not re-timed, and one that breaks a cap
    raises. ``bounds``: the durations (s) the kind can run."""
    limits = as_motion_limits(limits)
    motion = motion_over(duration)
    if limits is None:
        return motion
    caps = limits.caps()
    factor = scale_factor(motion, **caps)
    if factor <= 1.0 and not limits.fastest:
        return motion
    if has_via:
        if factor > 1.0:
            raise ValueError(
                f"limits: the motion through the via-points breaks a cap by {factor:.4g}x in "
                "time; via-points are at fixed times, so it is not re-timed (move them later or "
                "give a longer duration)"
            )
        return motion
    # Uniform time scaling is exact for these kinds (their positions are functions of t /
    # duration): the factor lands on the binding cap to rounding. A kind that runs whole steps
    # of dt rounds the duration down; one step more absorbs that (and the peaks between
    # samples, which move with the grid).
    for _ in range(8):
        step = float(motion.t[1] - motion.t[0]) if len(motion) > 1 else 0.0
        longer = motion.duration * factor * (1.0 + 1e-9) + (step if factor > 1.0 else 0.0)
        duration = float(np.clip(longer, *bounds))
        motion = motion_over(duration)
        factor = scale_factor(motion, **caps)
        if factor <= 1.0:
            return motion
    raise ValueError(
        f"limits: no duration within [{bounds[0]:.3g}, {bounds[1]:.3g}] s meets them "
        f"({factor:.4g}x over at {duration:.6g} s)"
    )
