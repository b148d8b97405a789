"""A joint path timed as fast as its limits allow: the geometric path q(s) kept exactly, its time
law s(t) the time-optimal one under the velocity and acceleration limits (TOPP-RA, Pham & Pham
2018, the maintained ``toppra``), smoothed so that the motion starts and stops at rest with zero
acceleration, then slowed uniformly until its jerk is within the limit too.

Why not TOPP-RA's time law as it is: it is bang-bang in the path acceleration, so the joints'
acceleration jumps (the arm's interface refuses a jump at a start or stop, and its jerk limit any
jump at all). TOPP-RA's path acceleration averaged over a sliding window (of the width the jerk
limit asks for) keeps its pace where the path allows speed and where a bend asks for slowing,
with a continuous acceleration and a bounded jerk; the uniform stretch that follows is small.
Why not ruckig: its free version times motions between states, not along a given path
(intermediate waypoints are its paid edition's).
"""

from __future__ import annotations

import logging
from dataclasses import dataclass, field

import numpy as np
from scipy.interpolate import make_interp_spline

from .._checks import as_points, as_vector, check_real, require_extra

__all__ = ["TimedPath", "time_path"]

logger = logging.getLogger(__name__)

_GRID = 2001  # samples of the time law on which the peaks are measured
_LAW_SAMPLES = 4001  # samples of TOPP-RA's path acceleration that are averaged
_MIN_WINDOW = 0.01  # the averaging window, at least this share of the motion
_TOPP_KNOTS = 100  # samples of the path TOPP-RA's own spline passes through
_TOPP_GRID = 101  # TOPP-RA's grid along the path


@dataclass
class TimedPath:
    """A joint path and its timing: ``q(u)`` at normalised time ``u`` in [0, 1] (the motion lasts
    ``duration`` seconds), called as ``path(u, order)`` for the ``order``-th derivative with
    respect to ``u`` (as a SciPy spline is).

    Attributes
    ----------
    duration : float
        Seconds, from rest to rest.
    geometric : scipy.interpolate.BSpline
        q(s), s in [0, 1] the path's normalised length.
    law : scipy.interpolate.BSpline
        s(t), t in [0, duration]: the time law.
    timing : str
        "time-optimal" (TOPP-RA's pace, smoothed) or "uniform" (a minimum-jerk law along the path:
        where it was faster, or where TOPP-RA could not time the path).
    peaks : tuple of float
        The largest joint velocity, acceleration and jerk over the motion as fractions of the
        limits (0 for a limit not given).
    """

    duration: float
    geometric: object
    law: object
    timing: str
    peaks: tuple = field(default=(0.0, 0.0, 0.0))

    def __call__(self, u, order: int = 0) -> np.ndarray:
        """q (or its ``order``-th derivative with respect to u) at normalised times ``u``."""
        t = np.clip(np.asarray(u, dtype=float), 0.0, 1.0) * self.duration
        rates = _rates(self.geometric, self.law, t, order)
        return rates[order] * self.duration**order


def _rates(geometric, law, t: np.ndarray, order: int) -> list:
    """[q, q̇, q̈, q⃛][: order + 1] at times ``t`` by the chain rule through s(t)."""
    s = np.clip(law(t), 0.0, 1.0)
    q = geometric(s)
    out = [q]
    if order >= 1:
        sd = law(t, 1)[..., None]
        d1 = geometric(s, 1)
        out.append(d1 * sd)
    if order >= 2:
        sdd = law(t, 2)[..., None]
        d2 = geometric(s, 2)
        out.append(d2 * sd**2 + d1 * sdd)
    if order >= 3:
        sddd = law(t, 3)[..., None]
        out.append(geometric(s, 3) * sd**3 + 3.0 * d2 * sd * sdd + d1 * sddd)
    return out


def time_path(waypoints, velocity, acceleration, jerk=None, *, margin: float = 0.9) -> TimedPath:
    """Time ``waypoints`` as fast as ``margin`` of the limits allow, from rest to rest.

    Parameters
    ----------
    waypoints : array (k, d)
        The path's points (rad), at least 2, consecutive ones distinct somewhere; the path passes
        through each (a cubic spline in the path's normalised length: dense waypoints keep it
        close to the polygon through them).
    velocity, acceleration : array (d,)
        Limits per joint (rad/s, rad/s²).
    jerk : array (d,), optional
        rad/s³; None: not limited.
    margin : float
        The share of each limit the motion may reach (the simulator's 0.9), at least 1e-3.

    Returns
    -------
    TimedPath
        The faster of the time-optimal timing and a uniform one (both within the limits).
    """
    path = _waypoints(waypoints)
    d = path.shape[1]
    limits = []
    for name, value in (("velocity", velocity), ("acceleration", acceleration), ("jerk", jerk)):
        if value is None and name == "jerk":
            limits.append(None)
            continue
        limit = as_vector(value, name, positive=True)
        if limit.shape[0] != d:
            raise ValueError(
                f"{name} must have {d} entries, one per joint (column) of waypoints, got {limit.shape[0]}"
            )
        limits.append(limit)
    # below a thousandth of the limits a motion's duration is a thousand times the fastest (at
    # 1e-300 it overflowed, at 5e-324 it was inf)
    margin = check_real(margin, "margin", minimum=1e-3, maximum=1.0)
    keep = np.concatenate([[True], np.linalg.norm(np.diff(path, axis=0), axis=1) > 1e-12])
    path = path[keep]
    if path.shape[0] < 2:
        raise ValueError("waypoints must move: every waypoint is the same configuration")
    lengths = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(path, axis=0), axis=1))])
    s = lengths / lengths[-1]
    k = min(3, path.shape[0] - 1)
    geometric = make_interp_spline(s, path, k=k)
    candidates = [_uniform(geometric, limits, margin)]
    try:
        candidates.append(_optimal(geometric, s, limits, margin))
    except (ValueError, RuntimeError) as exc:  # TOPP-RA found no feasible profile (a cusp)
        logger.info("TOPP-RA could not time the path (%s): a uniform timing instead", exc)
    return min(candidates, key=lambda timed: timed.duration)


def _waypoints(waypoints) -> np.ndarray:
    """``waypoints`` checked: finite (k, d), 2 <= k within the samples' limit, 1 <= d <= 64."""
    from .._checks import _as_bounded_array, check_limit

    array = _as_bounded_array(waypoints, "waypoints", 2)
    if array.ndim != 2 or not 1 <= array.shape[1] <= 64 or array.shape[0] < 2:
        raise ValueError(
            f"waypoints must have shape (k, d): at least 2 points of 1 to 64 joints, got {array.shape}"
        )
    check_limit(array.shape[0], "max_samples", "waypoints: the number of points")
    return as_points(array, array.shape[1], "waypoints")


def _uniform(geometric, limits, margin) -> TimedPath:
    """A minimum-jerk law along the path (s = 10τ³ - 15τ⁴ + 6τ⁵), stretched to the limits."""
    tau = np.linspace(0.0, 1.0, 41)
    law = make_interp_spline(
        tau,
        10 * tau**3 - 15 * tau**4 + 6 * tau**5,
        k=5,
        bc_type=([(1, 0.0), (2, 0.0)], [(1, 0.0), (2, 0.0)]),
    )
    return _stretched(geometric, law, 1.0, limits, margin, "uniform")


def _optimal(geometric, s, limits, margin) -> TimedPath:
    """TOPP-RA's time law under the velocity and acceleration limits, smoothed (module
    docstring), stretched until the jerk is within its limit too."""
    toppra = require_extra("toppra", "plan", "time-optimal timing (bidmp.planning)")
    import toppra.algorithm as algorithm
    import toppra.constraint as constraint

    toppra.setup_logging("ERROR")  # its progress goes to its own logger, never printed by bidmp
    velocity, acceleration, _ = limits
    grid = np.linspace(0.0, 1.0, _TOPP_KNOTS)
    path = toppra.SplineInterpolator(grid, geometric(grid))
    problem = algorithm.TOPPRA(
        [
            constraint.JointVelocityConstraint(np.column_stack([-velocity, velocity]) * margin),
            constraint.JointAccelerationConstraint(
                np.column_stack([-acceleration, acceleration]) * margin
            ),
        ],
        path,
        parametrizer="ParametrizeConstAccel",
        gridpoints=np.linspace(0.0, 1.0, _TOPP_GRID),
    )
    _, path_speed, _ = problem.compute_parameterization(0.0, 0.0)
    if path_speed is None or not np.all(np.isfinite(path_speed)):
        raise RuntimeError("no feasible profile")
    # Between two grid points the path acceleration is constant: dt = 2 ds / (sd_i + sd_i+1).
    gridpoints = np.linspace(0.0, 1.0, path_speed.shape[0])
    mean = path_speed[:-1] + path_speed[1:]
    if np.any(mean <= 0.0):
        raise RuntimeError("the profile stops inside the path")
    steps = np.diff(gridpoints)
    stamps = np.concatenate([[0.0], np.cumsum(2.0 * steps / mean)])
    accelerations = (path_speed[1:] ** 2 - path_speed[:-1] ** 2) / (2.0 * steps)
    law = _jerk_limited(stamps, accelerations, geometric, limits, margin)
    return _stretched(geometric, law, float(law.duration), limits, margin, "time-optimal")


class _Law:
    """A time law s(t) given on a fine grid (a quintic spline through it), with its duration."""

    def __init__(self, times: np.ndarray, progress: np.ndarray):
        rest = [(1, 0.0), (2, 0.0)]
        self.duration = float(times[-1])
        self.spline = make_interp_spline(times, progress, k=5, bc_type=(rest, rest))

    def __call__(self, t, order: int = 0):
        return self.spline(np.clip(t, 0.0, self.duration), order)


def _jerk_limited(stamps, accelerations, geometric, limits, margin) -> _Law:
    """TOPP-RA's bang-bang path acceleration (``accelerations`` between ``stamps``) averaged over a
    sliding window: the acceleration then ramps between its levels (a trapezoid), the path speed
    is continuous and the jerk bounded by the largest jump over the window's width, which is
    chosen to bring the joints' jerk within its limit. The motion lasts the window longer."""
    duration = float(stamps[-1])
    count = _LAW_SAMPLES
    dt = duration / (count - 1)
    times = np.linspace(0.0, duration, count)
    segment = np.clip(np.searchsorted(stamps, times, side="right") - 1, 0, len(accelerations) - 1)
    acceleration = accelerations[segment]
    jerk_limit = limits[2]
    width = max(int(round(_MIN_WINDOW * duration / dt)), 2)
    if jerk_limit is not None:
        grid = np.linspace(0.0, 1.0, 201)
        tangent = np.max(np.abs(geometric(grid, 1)) / (margin * jerk_limit))  # s per (rad/s³)
        jump = 2.0 * float(np.max(np.abs(accelerations)))
        width = max(width, int(np.ceil(jump * tangent / dt)) + 1)
    width = min(width, count)
    padded = np.concatenate([np.zeros(width), acceleration, np.zeros(width)])
    smooth = np.convolve(padded, np.ones(width) / width, mode="full")[: count + 2 * width]
    speed = np.concatenate([[0.0], np.cumsum(0.5 * (smooth[1:] + smooth[:-1]) * dt)])
    progress = np.concatenate([[0.0], np.cumsum(0.5 * (speed[1:] + speed[:-1]) * dt)])
    moving = np.flatnonzero(speed > 1e-12 * max(float(np.max(speed)), 1e-300))
    first, last = max(int(moving[0]) - 1, 0), min(int(moving[-1]) + 1, progress.size - 1)
    times = (np.arange(first, last + 1) - first) * dt
    progress = progress[first : last + 1] / progress[last]
    keep = np.unique(np.linspace(0, times.size - 1, min(times.size, 400)).round().astype(int))
    return _Law(times[keep], progress[keep])


def _stretched(geometric, law, duration, limits, margin, timing) -> TimedPath:
    """The timing ``law`` on [0, ``duration``] slowed uniformly (t → c t) until every peak is at
    most ``margin`` of its limit."""
    t = np.linspace(0.0, duration, _GRID)
    rates = _rates(geometric, law, t, 3 if limits[2] is not None else 2)
    peaks = [
        0.0 if limit is None else float(np.max(np.abs(rates[order]) / limit))
        for order, limit in zip((1, 2, 3), limits)
    ]
    stretch = max(
        [1.0] + [(peak / margin) ** (1.0 / order) for order, peak in zip((1, 2, 3), peaks)]
    )
    if stretch > 1.0:
        law = _slower(law, duration, stretch)
        duration *= stretch
        peaks = [peak / stretch**order for order, peak in zip((1, 2, 3), peaks)]
    return TimedPath(float(duration), geometric, law, timing, tuple(peaks))


class _slower:
    """A time law ``law`` on [0, duration] run ``factor`` times slower: s(t / factor)."""

    def __init__(self, law, duration: float, factor: float):
        self.law, self.factor = law, factor

    def __call__(self, t, order: int = 0):
        return self.law(np.asarray(t) / self.factor, order) / self.factor**order
