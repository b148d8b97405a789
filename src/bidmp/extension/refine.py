"""The transfer G-PRM found, made as smooth as what it imitates (``approach="keep"``).

G-PRM scores its roadmap paths by their Fréchet similarity to the *template*, the imitated piece
mapped onto seg → the new target. Its answer is a shortest path through Gaussian samples: on the
nut task's far nuts it strays 21–35 mm sideways from a straight template and is 13–16 % longer,
and a polyline sampled at the robot's rate has an acceleration spike at every vertex. So:

* **the template, where it is free.** It is what G-PRM's score measures similarity to (its own
  similarity is 1, every roadmap path's is lower), so where no part is in the way it is the best
  answer G-PRM's objective can give, with the piece's own smoothness;
* **otherwise the roadmap path, shortcut and smoothed.** Greedy shortcutting (from each kept
  vertex, the farthest later vertex a free straight move reaches) removes the sampling's detours;
  the shortcut polyline is then replaced by the smoothest free least-squares quintic spline
  (fewest knots first, its bow away from the chord widened by up to 1.5 where a fit cuts a
  corner into a part). A quintic spline has continuous curvature and curvature rate, so the
  transfer can be timed through its bends without jerk spikes; a Savitzky–Golay smoothing of the
  polyline (tried before, still used for the template's sensor noise) had to keep narrow windows
  next to a post, and the tight bends it kept made the transfer around a post take three times
  as long as the free one (log dimensionless jerk -17 against the template's -10.4 in
  ``tests/extension/test_extension_timing.py``'s post; -10.1 to -10.7 now). Beside it two bows from the
  template (or the chord), each scaled to the least that is free: the route's offset reduced to one
  half-sine bow (its curvature spread over the whole transfer), and the least-jerk bow through the
  point where the route is furthest from the template (two quintics meeting there, flat at the
  top: the shape of the least rough route through a clearance point). Each candidate is timed like
  the demonstration and the one whose timed transfer is smoothest (largest log dimensionless jerk)
  is kept (:func:`bidmp.extension.extend`). Every candidate is checked by the same collision
  callback the roadmap used (with a scene: continuously, with the margin).
"""

from __future__ import annotations

import logging

import numpy as np

from .._trajectory import arclength, interp_columns, savgol_filter
from .roadmap import CollisionCallback, _edges_free

__all__ = []

logger = logging.getLogger(__name__)

_RESAMPLED = 200  # points of the shortcut polyline before smoothing
_TAUT = 60  # points along the shortcut polyline, shortcut once more
# Savitzky–Golay windows tried on the template, widest first (points of _RESAMPLED)
_WINDOWS = (
    81,
    41,
    21,
    11,
)
# interior knots of the route's quintic spline, fewest (smoothest) first
_KNOTS = (
    0,
    1,
    2,
    3,
    4,
    6,
    8,
    12,
    16,
    24,
    32,
)
# Shares of the spline's offset from the template (or chord) tried, widest first: 1.5 where a fit
# cuts a corner into a part, down to 0.1 where G-PRM's wide samples went further round than needed.
_SHARES = (1.5, 1.25, 1.1, 1.0, 0.9, 0.8, 0.7, 0.6, 0.5, 0.4, 0.3, 0.2, 0.1)
_BISECTIONS = 4  # then between the last free share and the first blocked one
# a spline at most this much longer than the shortcut route is taken; else more knots
_LONGER = 1.02
_SLACK = 1.05  # a bow is widened this much beyond the least free share, where that is free


def _path_is_free(path: np.ndarray, is_free: CollisionCallback | None) -> bool:
    """Whether every straight piece of the polyline ``path`` (n, D) is free (True without a callback)."""
    if is_free is None:
        return True
    return bool(np.all(_edges_free(path[:-1], path[1:], is_free)))


def _shortcut(path: np.ndarray, is_free: CollisionCallback | None) -> np.ndarray:
    """Greedy shortcutting: from each kept vertex, straight to the farthest later vertex a free
    straight move reaches (the next vertex always does: the path's own pieces are free)."""
    kept, index, last = [0], 0, path.shape[0] - 1
    while index < last:
        later = np.arange(index + 1, last + 1)
        if is_free is None:
            index = last
        else:
            free = _edges_free(
                np.repeat(path[index][None], later.size, axis=0), path[later], is_free
            )
            free[0] = True  # the path's own piece
            index = int(later[np.flatnonzero(free)[-1]])
        kept.append(index)
    return path[kept]


def _smoothed(polyline: np.ndarray, window: int) -> np.ndarray:
    """``polyline`` resampled by arc length to :data:`_RESAMPLED` points and smoothed with a cubic
    Savitzky–Golay window, its two ends kept exactly."""
    s = arclength(polyline)
    dense = interp_columns(np.linspace(0.0, s[-1], _RESAMPLED), s, polyline)
    smooth = savgol_filter(dense, window, 3, axis=0, mode="interp")
    lam = np.linspace(0.0, 1.0, _RESAMPLED)[:, None]
    smooth += (1.0 - lam) * (dense[0] - smooth[0]) + lam * (dense[-1] - smooth[-1])
    return smooth


def _spline_fit(polyline: np.ndarray, n_knots: int) -> np.ndarray:
    """``polyline`` resampled by arc length to :data:`_RESAMPLED` points and fitted by a quintic
    least-squares B-spline with ``n_knots`` evenly spaced interior knots, its ends kept exactly."""
    from scipy.interpolate import make_lsq_spline

    s = arclength(polyline)
    dense = interp_columns(np.linspace(0.0, s[-1], _RESAMPLED), s, polyline)
    u = np.linspace(0.0, 1.0, _RESAMPLED)
    knots = np.concatenate([np.zeros(6), np.linspace(0.0, 1.0, n_knots + 2)[1:-1], np.ones(6)])
    weights = np.ones(_RESAMPLED)
    # the ends held in the fit, so the exact pinning below moves the rest by little
    weights[[0, -1]] = 1e6
    fit = make_lsq_spline(u, dense, knots, k=5, w=weights)(u)
    fit += (1.0 - u[:, None]) * (dense[0] - fit[0]) + u[:, None] * (dense[-1] - fit[-1])
    return fit


def _smoothest_free_route(
    polyline: np.ndarray, is_free: CollisionCallback | None, base: np.ndarray | None = None
) -> np.ndarray | None:
    """The smoothest free quintic spline through a route's polyline, pulled as close to ``base``
    (the template, else the chord; same ends) as the parts allow (see the module docstring);
    None when no candidate is free."""
    if polyline.shape[0] < 3 or arclength(polyline)[-1] <= 0.0:
        return polyline if _path_is_free(polyline, is_free) else None
    u = np.linspace(0.0, 1.0, _RESAMPLED)
    if base is None:  # the chord (every fit keeps the polyline's ends)
        reference = polyline[0] + u[:, None] * (polyline[-1] - polyline[0])
    else:
        s = arclength(base)
        reference = interp_columns(u * s[-1], s, base)
    route_length, best, best_length = arclength(polyline)[-1], None, np.inf
    for n_knots in _KNOTS:
        offset = _spline_fit(polyline, n_knots) - reference
        # From the widest offset down: the last free one before the first that is not (the
        # offset's free set is an interval above some share for a single part in the way).
        free_share, blocked_share = None, 0.0
        for share in _SHARES:
            if not _path_is_free(reference + share * offset, is_free):
                blocked_share = share
                break
            free_share = share
        if free_share is None:
            continue
        if blocked_share > 0.0:  # closer to the part, as far as it stays free
            free_share = _least_free_share(
                reference, offset, blocked_share, free_share, is_free, _BISECTIONS
            )
        candidate = reference + free_share * offset
        length = arclength(candidate)[-1]
        if length <= _LONGER * route_length:
            bows = [
                _bump_route(polyline, reference, is_free, route_length),
                _least_jerk_bow(polyline, reference, is_free, route_length),
            ]
            return [candidate] + [bow for bow in bows if bow is not None]
        # a bow much longer than the route: more knots, if one is free
        if best is None or length < best_length:
            best, best_length = candidate, length
    return None if best is None else [best]


def _least_jerk_bow(
    polyline: np.ndarray,
    reference: np.ndarray,
    is_free: CollisionCallback | None,
    route_length: float,
) -> np.ndarray | None:
    """The least-jerk bow from ``reference`` through the point where the route is furthest from it:
    two quintics in the reference's arc-length share meeting there, at the route's offset with no
    slope across, at rest in value, slope and curvature at both ends; scaled to the least that is
    free (bisection). None when no scale up to 3 is free or it is over 1.03 times the route's length."""
    s = arclength(polyline)
    u = np.linspace(0.0, 1.0, reference.shape[0])
    offset = interp_columns(u * s[-1], s, polyline) - reference
    size = np.linalg.norm(offset, axis=1)
    top = int(np.argmax(size))
    if size[top] <= 0.0 or not 0 < top < len(u) - 1:
        return None
    return _least_free_bow(
        reference, np.outer(_quintic_bump(u, u[top]), offset[top]), is_free, route_length
    )


def _quintic_bump(u: np.ndarray, apex: float) -> np.ndarray:
    """The least-jerk profile on [0, 1] that is 1 with zero slope at ``apex`` and 0 with zero slope and
    curvature at both ends: a quintic on each side, their curvature at the apex the least-jerk one."""

    def piece(duration: float, curvature: float) -> np.ndarray:
        T = duration
        matrix = np.array(
            [
                [1, 0, 0, 0, 0, 0],
                [0, 1, 0, 0, 0, 0],
                [0, 0, 2, 0, 0, 0],
                [1, T, T**2, T**3, T**4, T**5],
                [0, 1, 2 * T, 3 * T**2, 4 * T**3, 5 * T**4],
                [0, 0, 2, 6 * T, 12 * T**2, 20 * T**3],
            ]
        )
        return np.linalg.solve(matrix, [0.0, 0.0, 0.0, 1.0, 0.0, curvature])

    def jerk(coefficients: np.ndarray, duration: float) -> float:
        third = np.polynomial.Polynomial(
            [6 * coefficients[3], 24 * coefficients[4], 60 * coefficients[5]]
        )
        integral = (third**2).integ()
        return float(integral(duration) - integral(0.0))

    def total(curvature: float) -> float:
        return jerk(piece(apex, curvature), apex) + jerk(piece(1.0 - apex, curvature), 1.0 - apex)

    low, mid, high = total(-1.0), total(0.0), total(1.0)
    curvature = -(high - low) / (2.0 * (high - 2.0 * mid + low))
    left, right = (
        np.polynomial.Polynomial(piece(apex, curvature)),
        np.polynomial.Polynomial(piece(1.0 - apex, curvature)),
    )
    return np.where(u <= apex, left(np.minimum(u, apex)), right(np.maximum(1.0 - u, 0.0)))


def _bump_route(
    polyline: np.ndarray,
    reference: np.ndarray,
    is_free: CollisionCallback | None,
    route_length: float,
) -> np.ndarray | None:
    """The route's offset from ``reference`` (same samples) reduced to its half-sine component
    ``c sin(πu)`` and scaled to the least that is free (bisection): one even bow, its curvature
    spread over the whole transfer. None when no scale up to 3 is free or it is over 1.03 times
    the route's length."""
    s = arclength(polyline)
    u = np.linspace(0.0, 1.0, reference.shape[0])
    offset = interp_columns(u * s[-1], s, polyline) - reference
    bow = np.outer(np.sin(np.pi * u), offset.T @ np.sin(np.pi * u) / np.sum(np.sin(np.pi * u) ** 2))
    return _least_free_bow(reference, bow, is_free, route_length)


def _least_free_bow(
    reference: np.ndarray, bow: np.ndarray, is_free: CollisionCallback | None, route_length: float
) -> np.ndarray | None:
    """``reference + share * bow`` for the least free ``share`` up to 3 (a coarse search, then
    bisection, then the slack), or None when none is free or it is over 1.03 times the route's length."""
    blocked, free = 0.0, None
    for share in (0.5, 0.75, 1.0, 1.25, 1.5, 2.0, 2.5, 3.0):
        if _path_is_free(reference + share * bow, is_free):
            free = share
            break
        blocked = share
    if free is None:
        return None
    candidate = _slack(
        reference, bow, _least_free_share(reference, bow, blocked, free, is_free, 6), is_free
    )
    return candidate if arclength(candidate)[-1] <= 1.03 * route_length else None


def _slack(
    reference: np.ndarray, bow: np.ndarray, share: float, is_free: CollisionCallback | None
) -> np.ndarray:
    """The bow at ``share`` widened by :data:`_SLACK` where that is free too: a bow at the least free
    share has no room left, and the timing's blends at the transfer's ends move its samples a hair."""
    wider = reference + _SLACK * share * bow
    return wider if _path_is_free(wider, is_free) else reference + share * bow


def _least_free_share(
    reference: np.ndarray,
    offset: np.ndarray,
    blocked: float,
    free: float,
    is_free: CollisionCallback | None,
    steps: int,
) -> float:
    """Bisection between a share of ``offset`` whose route is blocked and one whose route is free:
    the free share closest to the blocked one after ``steps`` halvings."""
    for _ in range(steps):
        middle = (blocked + free) / 2.0
        if _path_is_free(reference + middle * offset, is_free):
            free = middle
        else:
            blocked = middle
    return free


def _refine_transfer(
    path: np.ndarray, template: np.ndarray, is_free: CollisionCallback | None
) -> tuple[list, str]:
    """The transfers that may replace G-PRM's ``path`` (n, D), from seg to the new target (one or
    more free candidates; the caller keeps the one whose timed transfer is smoothest), and how they
    were made: ``"template"``, ``"smoothed"`` (the shortcut path, smoothed, and the bows) or
    ``"shortcut"`` (the shortcut polyline, where no smoothing stays free). See the module docstring."""
    ends_match = np.allclose(
        template[[0, -1]],
        path[[0, -1]],
        rtol=0.0,
        atol=1e-9 * max(float(np.ptp(path, axis=0).max()), 1.0),
    )
    if ends_match and _path_is_free(template, is_free):
        # Smoothed too: the template is the piece scaled, and scaling a 10 mm piece of a recording
        # onto 200 mm scales its sensor noise 20-fold into kinks the timing would see as jerk.
        smooth = _smoothest_free(template, is_free)
        return [template if smooth is None else smooth], "template"
    polyline = _shortcut(path, is_free)
    # again through points along its pieces: corners cut where the vertices alone cannot
    if polyline.shape[0] > 2:
        s = arclength(polyline)
        polyline = _shortcut(interp_columns(np.linspace(0.0, s[-1], _TAUT), s, polyline), is_free)
    smooth = (
        _smoothest_free_route(polyline, is_free, template if ends_match else None)
        if arclength(polyline)[-1] > 0.0
        else None
    )
    if smooth:
        return smooth, "smoothed"
    logger.debug("no smoothing of the shortcut transfer stays free: its polyline is used")
    return [polyline], "shortcut"


def _smoothest_free(polyline: np.ndarray, is_free: CollisionCallback | None) -> np.ndarray | None:
    """The polyline smoothed with the widest window whose result is free; None when none is."""
    for window in _WINDOWS:
        candidate = _smoothed(polyline, window)
        if _path_is_free(candidate, is_free):
            return candidate
    return None


_LIFTS = (0.1, 0.2, 0.4, 0.8, 1.6, 3.2)  # heights tried over the higher end, in chord lengths


def _lifted_route(
    seg: np.ndarray, end: np.ndarray, is_free: CollisionCallback | None
) -> np.ndarray | None:
    """Over what is in the way: up from seg, across at one height, down to ``end`` — the lowest of
    :data:`_LIFTS` above the higher of the two ends whose three straight moves are free (3-D
    paths only; None when none is). What a person does over a cable duct across the table, and
    what G-PRM's samples around the straight line never reach."""
    if seg.shape[0] != 3:
        return None
    chord = float(np.linalg.norm(end - seg))
    top = max(seg[2], end[2])
    for lift in _LIFTS:
        height = top + lift * max(chord, 1e-300)
        route = np.array([seg, [seg[0], seg[1], height], [end[0], end[1], height], end])
        if _path_is_free(route, is_free):
            return route
    return None
