"""The transfer G-PRM found, made as smooth as what it imitates (``approach="keep"``, issue 21.2).

G-PRM scores its roadmap paths by their Fréchet similarity to the *template*, the imitated piece
mapped onto seg → the new target. Its answer is a shortest path through Gaussian samples: on the
nut task's far nuts it strays 21–35 mm sideways from a straight template and is 13–16 % longer,
and a polyline sampled at the robot's rate has an acceleration spike at every vertex. So:

* **the template, where it is free.** It is what G-PRM's score measures similarity to (its own
  similarity is 1, every roadmap path's is lower), so where no part is in the way it is the best
  answer G-PRM's objective can give, with the piece's own smoothness;
* **otherwise the roadmap path, shortcut and smoothed.** Greedy shortcutting (from each kept
  vertex, the farthest later vertex a free straight move reaches) removes the sampling's detours;
  the shortcut polyline is resampled and smoothed (Savitzky–Golay, ends pinned), the widest
  smoothing window whose result is still free winning, so corners are rounded only as far as the
  parts allow. Every candidate is checked by the same collision callback the roadmap used (with a
  scene: continuously, with the planning margin).
"""

from __future__ import annotations

import logging

import numpy as np
from scipy.signal import savgol_filter

from .._trajectory import arclength, interp_columns
from .roadmap import CollisionCallback, _edges_free

__all__ = ["refine_transfer", "path_is_free", "shortcut", "smoothest_free", "lifted_route"]

logger = logging.getLogger(__name__)

_RESAMPLED = 200  # points of the shortcut polyline before smoothing
_WINDOWS = (81, 41, 21, 11)  # Savitzky–Golay windows tried, widest first (points of _RESAMPLED)


def path_is_free(path: np.ndarray, is_free: CollisionCallback | None) -> bool:
    """Whether every straight piece of the polyline ``path`` (n, D) is free (True without a callback)."""
    if is_free is None:
        return True
    return bool(np.all(_edges_free(path[:-1], path[1:], is_free)))


def shortcut(path: np.ndarray, is_free: CollisionCallback | None) -> np.ndarray:
    """Greedy shortcutting: from each kept vertex, straight to the farthest later vertex a free
    straight move reaches (the next vertex always does: the path's own pieces are free)."""
    kept, index, last = [0], 0, path.shape[0] - 1
    while index < last:
        later = np.arange(index + 1, last + 1)
        if is_free is None:
            index = last
        else:
            free = _edges_free(np.repeat(path[index][None], later.size, axis=0), path[later], is_free)
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


def refine_transfer(path: np.ndarray, template: np.ndarray, is_free: CollisionCallback | None) -> tuple[np.ndarray, str]:
    """The transfer to use in place of G-PRM's ``path`` (n, D), from seg to the new target, and how
    it was made: ``"template"``, ``"smoothed"`` (the shortcut path, smoothed) or ``"shortcut"``
    (the shortcut polyline, where no smoothing stays free). See the module docstring."""
    ends_match = np.allclose(template[[0, -1]], path[[0, -1]], rtol=0.0,
                             atol=1e-9 * max(float(np.ptp(path, axis=0).max()), 1.0))
    if ends_match and path_is_free(template, is_free):
        # Smoothed too: the template is the piece scaled, and scaling a 10 mm piece of a recording
        # onto 200 mm scales its sensor noise 20-fold into kinks the timing would see as jerk.
        smooth = smoothest_free(template, is_free)
        return (template if smooth is None else smooth), "template"
    polyline = shortcut(path, is_free)
    smooth = smoothest_free(polyline, is_free) if arclength(polyline)[-1] > 0.0 else None
    if smooth is not None:
        return smooth, "smoothed"
    logger.debug("no smoothing of the shortcut transfer stays free: its polyline is used")
    return polyline, "shortcut"


def smoothest_free(polyline: np.ndarray, is_free: CollisionCallback | None) -> np.ndarray | None:
    """The polyline smoothed with the widest window whose result is free; None when none is."""
    for window in _WINDOWS:
        candidate = _smoothed(polyline, window)
        if path_is_free(candidate, is_free):
            return candidate
    return None


_LIFTS = (0.1, 0.2, 0.4, 0.8, 1.6, 3.2)  # heights tried over the higher end, in chord lengths


def lifted_route(seg: np.ndarray, end: np.ndarray, is_free: CollisionCallback | None) -> np.ndarray | None:
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
        if path_is_free(route, is_free):
            return route
    return None
