"""Timing a generated path like the demonstration it extends: arc-length profiles
that join the demonstration with continuous position, speed and (``"keep"``) acceleration.

* :func:`_time_path` (the paper's protocol, ``approach="paper"``): a cubic profile from the
  demonstration's speed at seg to rest, at the imitated piece's mean speed.
* :func:`_timed_transfer` (``approach="keep"``): a quintic profile along the path that leaves
  and arrives with the demonstration's speed along it, plus short quintic blends at the two
  joins that add what a profile along the path cannot keep (the velocity across it at a corner,
  the acceleration), so that velocity and acceleration are continuous where the transfer meets
  the demonstration; over the shortest duration (at least the imitated piece's own) whose peak
  speed, acceleration and jerk, measured on the samples, are at most the demonstration's own. A
  longer transfer takes longer, as a person's would; the demonstration around it keeps its
  timing.
"""

from __future__ import annotations

import logging

import numpy as np

from .._checks import check_int
from .._kernels import motion_peaks as _compiled_peaks
from .._trajectory import _PAIRWISE_COLUMNS, arclength, interp_columns, savgol_filter

__all__ = []

logger = logging.getLogger(__name__)

_GROWTH = 1.01  # candidate durations grow by this factor ...
_LONGEST = 40.0  # ... up to this multiple of the imitated piece's own duration
# samples of the local fits for the demonstration's velocity and acceleration at the joins
_DERIVATIVE_WINDOW = 11
_SPEED_SHARES = (1.0, 0.75, 0.5, 0.25, 0.0)  # of the end speeds along the path, tried in turn
_NEGLIGIBLE = 1.02  # with no duration within the peaks, a longer one is taken only if 2 % better
_JOIN_SLACK = 1.1  # peaks over the joins (with the demonstration's samples around them) may reach this times its own


def _motion_peaks(points: np.ndarray, dt: float) -> np.ndarray:
    """Peak speed, acceleration and jerk of samples ``points`` (n, D) ``dt`` apart, by first,
    second and third finite differences (units/time, /time², /time³); 0 where too short.

    A transfer's duration search measures a few hundred profiles: a compiled pass of the same
    arithmetic (:func:`bidmp._kernels.motion_peaks`) for fewer than eight columns, NumPy's
    differences otherwise (its sums over eight or more columns are pairwise, not in order)."""
    points = np.asarray(points, dtype=float)
    if 0 < points.shape[1] < _PAIRWISE_COLUMNS:
        return _compiled_peaks(points, dt)
    peaks = np.zeros(3)
    difference = points
    for order in range(3):
        difference = np.diff(difference, axis=0) / dt
        if difference.shape[0]:
            peaks[order] = float(np.max(np.linalg.norm(difference, axis=1)))
    return peaks


def _arc_profile(
    length: float, start_speed: float, end_speed: float, duration: float, n_steps: int
) -> np.ndarray:
    """Cubic Hermite arc length at ``u = k / n_steps``, k = 1..n_steps, from 0 to ``length`` with
    speeds ``start_speed`` and ``end_speed`` at the ends. Speeds that would make the profile run
    back (outside the Fritsch–Carlson disc α² + β² <= 9) are scaled down together."""
    alpha, beta = start_speed * duration / length, end_speed * duration / length
    radius = float(np.hypot(alpha, beta))
    if radius > 3.0:
        logger.debug(
            "transfer end speeds scaled by %.3f to keep the arc-length profile monotone",
            3.0 / radius,
        )
        alpha, beta = 3.0 * alpha / radius, 3.0 * beta / radius
    u = np.arange(1, n_steps + 1) / n_steps
    return length * (3 * u**2 - 2 * u**3 + alpha * (u - 2 * u**2 + u**3) + beta * (u**3 - u**2))


def _time_path(
    path: np.ndarray, start_speed: float, mean_speed: float, dt: float
) -> tuple[np.ndarray, float]:
    """Time a geometric path: a cubic arc-length profile from ``start_speed`` to rest.

    ``s(u) = L (3u² − 2u³) + a (u − 2u² + u³)`` on ``u ∈ [0, 1]`` with ``a = start_speed · D``;
    ``D = L / mean_speed``, shortened if needed so that ``a ≤ 3L`` (then ``s`` never runs back).

    Returns
    -------
    (positions, duration) : positions sampled every ``dt`` from u = 0 (excluded) to u = 1
    (included), shape (n, D), and the duration D.
    """
    s = arclength(path)
    length = s[-1]
    if length <= 0.0:
        return path[-1:].copy(), dt
    duration = length / max(mean_speed, 1e-300)
    if start_speed > 0.0:
        duration = min(duration, 3.0 * length / start_speed)
    n_steps = max(int(round(duration / dt)), 1)
    check_int(
        n_steps,
        "the generated transfer's samples (its length at the demonstrated piece's speed)",
        limit="max_steps",
    )
    arc = _arc_profile(length, start_speed, 0.0, duration, n_steps)
    positions = interp_columns(arc, s, path)
    positions[-1] = path[-1]
    return positions, n_steps * dt


def _quintic_profile(
    length: float, ends: tuple[float, float, float, float], duration: float, n_steps: int
) -> np.ndarray:
    """Quintic Hermite arc length at ``u = k / n_steps``, k = 1..n_steps: from 0 to ``length``
    over ``duration``, leaving at speed and tangential acceleration ``ends[0:2]``, arriving at
    ``ends[2:4]``."""
    start_speed, start_acceleration, end_speed, end_acceleration = ends
    u = np.arange(1, n_steps + 1) / n_steps
    u2, u3, u4, u5 = u**2, u**3, u**4, u**5
    return (
        length * (10 * u3 - 15 * u4 + 6 * u5)
        + start_speed * duration * (u - 6 * u3 + 8 * u4 - 3 * u5)
        + end_speed * duration * (-4 * u3 + 7 * u4 - 3 * u5)
        + start_acceleration * duration**2 * (0.5 * u2 - 1.5 * u3 + 1.5 * u4 - 0.5 * u5)
        + end_acceleration * duration**2 * (0.5 * u3 - u4 + 0.5 * u5)
    )


class _Joins:
    """The demonstration's velocity and acceleration (vectors) where the transfer leaves it (seg)
    and where the kept approach takes over, and their components along the transfer's own
    direction there (0 where it turns away by 90° or more), which its arc-length profile keeps."""

    def __init__(
        self,
        y: np.ndarray,
        seg_index: int,
        approach_index: int,
        dt: float,
        path: np.ndarray,
        point_at,
    ) -> None:
        # Local cubic fits (Savitzky–Golay derivatives): a recording's noise would swamp plain
        # second differences at one sample.
        window = min(_DERIVATIVE_WINDOW, len(y) - 1 + len(y) % 2)
        if window > 3:
            velocity = savgol_filter(y, window, 3, deriv=1, delta=dt, axis=0)
            acceleration = savgol_filter(y, window, 3, deriv=2, delta=dt, axis=0)
        else:
            velocity = np.gradient(y, dt, axis=0)
            acceleration = np.gradient(velocity, dt, axis=0)
        ends = approach_index < len(y) - 1  # an approach of one sample ends at rest
        zero = np.zeros(y.shape[1])
        self.velocities = (velocity[seg_index], velocity[approach_index] if ends else zero)
        self.accelerations = (
            acceleration[seg_index],
            acceleration[approach_index] if ends else zero,
        )
        self.directions = (_unit(path[1] - path[0]), _unit(path[-1] - path[-2]))
        # The path's own bend at its ends: moving along it at speed v adds v² p''(s) to the
        # acceleration, which the blends must take out too (else the acceleration steps at the
        # join, a jerk spike of one sample whatever the duration).
        self.bends = (np.zeros(y.shape[1]), np.zeros(y.shape[1]))
        if hasattr(point_at, "derivative"):
            tangent, bend = point_at.derivative(1), point_at.derivative(2)
            ends = (0.0, float(point_at.t[-1]))
            self.directions = tuple(_unit(tangent(end)) for end in ends)
            self.bends = tuple(
                bend(end) / max(float(np.dot(tangent(end), tangent(end))), 1e-300) for end in ends
            )
        speeds = [max(float(v @ d), 0.0) for v, d in zip(self.velocities, self.directions)]
        # The profile along the path: leave and arrive with the speed along it (accelerations are
        # left to the blends: kept over the whole transfer, they would make a long one run back).
        self.along = (speeds[0], 0.0, speeds[1], 0.0)

    def mismatches(self, along: tuple[float, float, float, float]) -> tuple[np.ndarray, ...]:
        """What a profile along the path with end speeds and accelerations ``along`` leaves out:
        (Δv, Δa) at the start, then at the end."""
        out = []
        for end in (0, 1):
            d = self.directions[end]
            speed = along[2 * end]
            out += [
                self.velocities[end] - speed * d,
                self.accelerations[end] - along[2 * end + 1] * d - speed**2 * self.bends[end],
            ]
        return tuple(out)


def _unit(vector: np.ndarray) -> np.ndarray:
    norm = np.linalg.norm(vector)
    return vector / norm if norm > 0.0 else vector


# Peaks of the quintic Hermite basis on [0, 1] (2nd and 3rd derivatives of the velocity and
# acceleration blends): a blend of a velocity step Δv over τ peaks at 3.94 |Δv| / τ in
# acceleration and 36 |Δv| / τ² in jerk; of an acceleration step Δa, at |Δa| and 9 |Δa| / τ.
_BLEND_ACCELERATION, _BLEND_JERK, _BLEND_JERK_A = 3.94, 36.0, 9.0


def _blend_time(
    delta_v: np.ndarray, delta_a: np.ndarray, limit: np.ndarray, longest: float
) -> float:
    """The shortest blend (at most ``longest``) that adds no more than 80 % of the acceleration and
    jerk limits: how far a corner at a join is rounded."""
    dv, da = float(np.linalg.norm(delta_v)), float(np.linalg.norm(delta_a))
    if dv == 0.0 and da == 0.0:
        return 0.0
    acceleration, jerk = 0.8 * max(limit[1], 1e-300), 0.8 * max(limit[2], 1e-300)
    # The two blends' peaks add: 3.94 dv / τ + da <= acceleration and 36 dv / τ² + 9 da / τ <= jerk.
    by_acceleration = (
        _BLEND_ACCELERATION * dv / (acceleration - da) if acceleration > da else longest
    )
    by_jerk = (
        _BLEND_JERK_A * da + np.sqrt((_BLEND_JERK_A * da) ** 2 + 4.0 * jerk * _BLEND_JERK * dv)
    ) / (2.0 * jerk)
    return min(max(by_acceleration, by_jerk), longest)


def _corner_blends(
    times: np.ndarray, duration: float, mismatches: tuple, limit: np.ndarray
) -> np.ndarray:
    """Offsets (n, D) that vanish with their first two derivatives outside a short window at each
    end and give the transfer the demonstration's velocity and acceleration vectors at the joins
    (quintic Hermite blends): a corner between the transfer and the piece it joins is rounded
    instead of turned in one sample."""
    dv0, da0, dv1, da1 = mismatches
    offsets = np.zeros((times.shape[0], dv0.shape[0]))
    # A blend is zero to the bit outside its window (its polynomial is exactly 0 at u = 0 and
    # u = 1): it is evaluated on the window's samples only, with a sample's margin each side.
    step = times[1] - times[0] if times.shape[0] > 1 else max(float(times[0]), 1e-300)
    tau = _blend_time(dv0, da0, limit, duration / 2)
    if tau > 0.0:
        window = slice(0, min(times.shape[0], int(np.ceil(tau / step)) + 2))
        u = np.clip(times[window] / tau, 0.0, 1.0)[:, None]
        u2, u3, u4, u5 = u**2, u**3, u**4, u**5
        offsets[window] += dv0 * tau * (u - 6 * u3 + 8 * u4 - 3 * u5) + da0 * tau**2 * (
            0.5 * u2 - 1.5 * u3 + 1.5 * u4 - 0.5 * u5
        )
    tau = _blend_time(dv1, da1, limit, duration / 2)
    if tau > 0.0:
        window = slice(max(int(np.floor((duration - tau) / step)) - 2, 0), times.shape[0])
        u = np.clip((times[window] - (duration - tau)) / tau, 0.0, 1.0)[:, None]
        u3, u4, u5 = u**3, u**4, u**5
        offsets[window] += dv1 * tau * (-4 * u3 + 7 * u4 - 3 * u5) + da1 * tau**2 * (
            0.5 * u3 - u4 + 0.5 * u5
        )
    return offsets


# a path turning less at every vertex is taken as samples of a smooth curve
_SMOOTH_TURN = np.radians(5.0)


def _path_function(path: np.ndarray, s: np.ndarray):
    """Points at arc lengths along ``path``: a cubic spline by arc length through its vertices when
    it samples a smooth curve (every vertex turns less than 5°), else the polyline itself (its
    corners are the route's, checked as such). A polyline through a smooth curve's samples turns
    at every vertex in one time step: at the robot's rate that is an acceleration and jerk spike
    per vertex, which the timing would answer by slowing the whole transfer down."""
    from scipy.interpolate import make_interp_spline

    pieces = np.diff(path, axis=0)
    lengths = np.linalg.norm(pieces, axis=1)
    smooth = path.shape[0] >= 4 and np.all(lengths > 0.0)
    if smooth:
        cosines = np.sum(pieces[1:] * pieces[:-1], axis=1) / (lengths[1:] * lengths[:-1])
        smooth = bool(np.all(cosines >= np.cos(_SMOOTH_TURN)))
    return (
        make_interp_spline(s, path, k=3) if smooth else (lambda arc: interp_columns(arc, s, path))
    )


def _timed_transfer(
    path: np.ndarray,
    y: np.ndarray,
    seg_index: int,
    approach_index: int,
    approach: np.ndarray,
    dt: float,
) -> np.ndarray:
    """Samples along ``path`` (excluding its start, ending exactly at its end) from the
    demonstration ``y`` at ``seg_index`` to the kept ``approach`` (its samples after ``path``'s
    end; it began at ``approach_index`` in ``y``), timed as the module docstring says.

    The duration is the shortest of ``n0 · 1.01^k`` samples (``n0 = approach_index − seg_index``,
    up to 40 n0) whose profile never runs back and whose peak speed, acceleration and jerk are
    within the demonstration's along the transfer and within 1.1 times them over the joins (the
    samples from three before seg to three into the approach); when none is, the one with the
    smallest excess (logged). The profile keeps the demonstration's speed
    and tangential acceleration along the path at the joins; what it cannot keep (the velocity
    across the path at a corner) is blended in over the shortest window the limits allow.
    """
    s = arclength(path)
    n_own = max(approach_index - seg_index, 1)
    if s[-1] <= 0.0 or path.shape[0] < 2:
        return np.repeat(path[-1:], n_own, axis=0)
    point_at = _path_function(path, s)
    joins = _Joins(y, seg_index, approach_index, dt, path, point_at)
    limit = _motion_peaks(y, dt)
    before, after = y[max(seg_index - 3, 0) : seg_index + 1], approach[:3]
    best, best_excess, n_steps = None, np.inf, n_own
    while n_steps <= _LONGEST * n_own:
        check_int(n_steps, "the generated transfer's samples", limit="max_steps")
        duration = n_steps * dt
        for share in _SPEED_SHARES:  # the largest share of the end speeds that never runs back
            along = tuple(share * value for value in joins.along)
            arc = _quintic_profile(s[-1], along, duration, n_steps)
            if np.all(np.diff(arc, prepend=0.0) >= -1e-12 * s[-1]):
                break
        positions = point_at(arc)
        positions += _corner_blends(
            np.arange(1, n_steps + 1) * dt, duration, joins.mismatches(along), limit
        )
        positions[-1] = path[-1]
        # Within the demonstration's peaks along the transfer; at the joins, where a
        # recording's noise meets a smooth profile in the third differences, within 1.1x.
        inside = _motion_peaks(np.vstack([path[:1], positions]), dt) / np.maximum(limit, 1e-300)
        joined = _motion_peaks(np.vstack([before, positions, after]), dt) / np.maximum(
            _JOIN_SLACK * limit, 1e-300
        )
        excess = float(max(inside.max(), joined.max()))
        if excess <= 1.0 + 1e-9:
            return positions
        if excess < best_excess / _NEGLIGIBLE:  # a longer transfer must earn its time
            best, best_excess = positions, excess
        n_steps = max(n_steps + 1, int(np.ceil(n_steps * _GROWTH)))
    logger.info(
        "the transfer's peaks exceed the demonstration's by %.0f %% at best (%d samples)",
        100 * (best_excess - 1),
        len(best),
    )
    return best
