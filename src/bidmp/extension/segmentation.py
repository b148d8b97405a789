"""1D-SEG: cut a demonstration at its curvature extrema (paper §3.1).

1. Resample by arc length (curvature must not depend on speed).
2. Smooth with Savitzky–Golay (window ≈ 5 % of T, odd, ≥ 7, order 3) and differentiate.
3. Curvature ``κ = ‖r′ × r″‖ / ‖r′‖³`` (2-D curves padded with z = 0), smoothed once more
   (window ≈ 3 % of T).
4. Alternating local maxima and minima of κ on the interior (5 % … 95 % of T).
5. Prune pairs whose curvature difference ("region distance", hence *1D*) is below
   ``ε = eps_frac · (max κ − min κ)``: ``"persistence"`` (default) repeatedly cancels the adjacent
   max/min pair with the smallest difference, so a larger ε gives a subset; ``"paper"`` makes one
   pass over consecutive (max, min) pairs.
6. The surviving extrema are the segmentation points.
"""

from __future__ import annotations

import heapq
from dataclasses import dataclass

import numpy as np

from .._checks import (
    as_indices,
    as_point,
    as_trajectory,
    check_choice,
    check_limit,
    check_real,
    numerically_guarded,
)
from .._trajectory import arclength, resample_arclength, savgol_filter

__all__ = [
    "curvature",
    "segment",
    "Segmentation",
    "Piece",
    "choose_piece",
]

_INTERIOR = (0.05, 0.95)
# Curvature is analysed on at most this many arc-length samples: 1/4096 of the path length is
# far finer than any corner a demonstration has, and it keeps a 1e6-sample recording to
# milliseconds (Savitzky–Golay windows are a fraction of the sample count, so their cost would
# otherwise grow with its square).
MAX_ANALYSIS_POINTS = 4096


def _odd_window(fraction: float, n_points: int, minimum: int) -> int:
    window = max(int(round(fraction * n_points)), minimum)
    window += 1 - window % 2
    return min(window, n_points - (1 - n_points % 2))


@numerically_guarded
def curvature(y, smooth: float = 0.05, smooth_curvature: float = 0.03) -> np.ndarray:
    """Curvature (1 / length unit) of a 2-D or 3-D curve at each of its samples.

    The curve must already be sampled evenly in arc length (see :func:`resample_arclength`).
    Derivatives come from a Savitzky–Golay fit (order 3) over ``smooth × T`` samples; κ is then
    smoothed over ``smooth_curvature × T`` samples.
    """
    y = as_trajectory(y, "y", min_points=3, allow_static=True)
    if y.shape[1] not in (2, 3):
        raise ValueError(f"y: curvature needs a 2-D or 3-D curve, got D = {y.shape[1]}")
    smooth = check_real(smooth, "smooth", positive=True, maximum=1.0)
    smooth_curvature = check_real(smooth_curvature, "smooth_curvature", positive=True, maximum=1.0)
    return _curvature(y, smooth, smooth_curvature)


def _curvature(y: np.ndarray, smooth: float, smooth_curvature: float) -> np.ndarray:
    """:func:`curvature` of a checked curve (segmentation's own resampled one)."""
    n_points = y.shape[0]
    if y.shape[1] == 2:
        y = np.column_stack([y, np.zeros(n_points)])
    window = _odd_window(smooth, n_points, 7)
    check_limit(
        float(n_points) * window,
        "max_work",
        "curvature's smoothing work (samples x window); resample to fewer points first",
    )
    # A curve that does not move (to rounding) has no curvature: its derivatives are rounding noise.
    extent = float(np.max(np.ptp(y, axis=0)))
    if window <= 3 or extent <= 1e-12 * float(np.max(np.abs(y))):
        return np.zeros(n_points)
    # Scaled by the power of two of its extent (exact: the same bits for every step below), a
    # curve of 1e-298 mm keeps the cube of its speed in range; κ scales back by that power.
    exponent = int(np.frexp(extent)[1])
    y = np.ldexp(y, -exponent)
    first = savgol_filter(y, window, 3, deriv=1, axis=0)
    second = savgol_filter(y, window, 3, deriv=2, axis=0)
    speed = np.linalg.norm(first, axis=1)
    # Guard ‖r′‖ → 0: where the curve does not advance, curvature is undefined; call it 0.
    floor = 1e-12 * max(float(np.max(speed)), np.finfo(float).tiny)
    kappa = np.linalg.norm(np.cross(first, second), axis=1) / np.maximum(speed, floor) ** 3
    kappa[speed <= floor] = 0.0
    window = _odd_window(smooth_curvature, n_points, 5)
    if window > 3:
        kappa = savgol_filter(kappa, window, 2)
    return np.maximum(np.ldexp(kappa, -exponent), 0.0)


def _alternating_extrema(kappa: np.ndarray, low: int, high: int) -> tuple[np.ndarray, np.ndarray]:
    """Local maxima (+1) and minima (-1) of ``kappa[low:high]``; they alternate.

    Returns (indices, types). A plateau counts once, at its middle (a straight stretch has
    κ ≈ 0 over its whole length: its minimum is its centre, not where it happens to start).
    """
    segment = kappa[low:high]
    if segment.shape[0] < 3:
        return np.empty(0, int), np.empty(0, int)
    slope = np.sign(np.diff(segment))
    # Carry the last non-zero slope across plateaus so that a flat top is still one extremum.
    nonzero = np.flatnonzero(slope)
    if nonzero.size == 0:
        return np.empty(0, int), np.empty(0, int)
    filled = slope[
        nonzero[np.maximum(np.searchsorted(nonzero, np.arange(slope.size), side="right") - 1, 0)]
    ]
    change = np.flatnonzero(np.diff(filled) != 0) + 1
    indices, types = [], []
    for index in change:
        kind = 1 if filled[index - 1] > 0 else -1
        start = index
        while start > 0 and slope[start - 1] == 0:
            start -= 1
        # Each change flips the sign of the filled slope, so maxima and minima alternate by themselves.
        indices.append(low + (start + index) // 2)
        types.append(kind)
    return np.asarray(indices, int), np.asarray(types, int)


def _prune_persistence(indices, types, kappa, epsilon):
    """Repeatedly cancel the adjacent (extremum, extremum) pair with the smallest curvature
    difference while it is below ``epsilon``; ties go to the leftmost pair.

    Cancelling the globally smallest adjacent pair keeps the sequence alternating (and, by the
    elder rule, keeps the deeper minimum / higher maximum of each basin). A heap of pair gaps
    over a doubly linked list makes this O(m log m) for m extrema; see
    :func:`_prune_persistence_plain` for the literal O(m²) loop it is tested against.
    """
    indices, types = np.asarray(indices, int), np.asarray(types, int)
    count = indices.shape[0]
    if count < 2:
        return indices, types
    values = kappa[indices]
    left = np.arange(-1, count - 1)
    right = np.arange(1, count + 1)  # right[-1] == count: no neighbour
    alive = np.ones(count, bool)
    heap = [(abs(values[i + 1] - values[i]), i, i + 1) for i in range(count - 1)]
    heapq.heapify(heap)
    while heap:
        gap, a, b = heap[0]
        if not (alive[a] and alive[b] and right[a] == b):
            heapq.heappop(heap)  # a pair that no longer exists
            continue
        if gap >= epsilon:
            break
        heapq.heappop(heap)
        alive[a] = alive[b] = False
        before, after = left[a], right[b]
        if before >= 0:
            right[before] = after
        if after < count:
            left[after] = before
        if before >= 0 and after < count:
            heapq.heappush(heap, (abs(values[after] - values[before]), before, after))
    return indices[alive], types[alive]


def _prune_persistence_plain(indices, types, kappa, epsilon):
    """The literal rule of :func:`_prune_persistence`, O(m²): the tests' reference."""
    indices, types = list(indices), list(types)
    while len(indices) >= 2:
        gaps = np.abs(np.diff(kappa[indices]))
        pair = int(np.argmin(gaps))
        if gaps[pair] >= epsilon:
            break
        del indices[pair : pair + 2], types[pair : pair + 2]
    return np.asarray(indices, int), np.asarray(types, int)


def _prune_paper(indices, types, kappa, epsilon):
    keep = np.ones(len(indices), bool)
    position = 0
    while position + 1 < len(indices):
        if types[position] == 1 and types[position + 1] == -1:  # a (Ma_i, Mi_i) pair
            if abs(kappa[indices[position]] - kappa[indices[position + 1]]) < epsilon:
                keep[position : position + 2] = False
            position += 2
        else:
            position += 1
    return np.asarray(indices, int)[keep], np.asarray(types, int)[keep]


@dataclass(frozen=True)
class Segmentation:
    """Result of :func:`segment`: the segmentation points of a demonstration.

    Attributes
    ----------
    points : int array (m,)
        Sorted sample indices into the demonstration. Empty for a straight demonstration.
    kinds : int array (m,)
        +1 where the point is a curvature maximum (a corner), -1 where it is a minimum (the
        straightest part between corners).
    """

    points: np.ndarray
    kinds: np.ndarray

    @property
    def corners(self) -> np.ndarray:
        """The points that are curvature maxima."""
        return self.points[self.kinds > 0]

    def __len__(self) -> int:
        return int(self.points.shape[0])


@numerically_guarded
def segment(y, eps_frac: float = 0.1, method: str = "persistence") -> Segmentation:
    """Segmentation points of a demonstration (1D-SEG).

    Parameters
    ----------
    y : array-like, shape (T, D), D = 2 or 3
        Demonstration; T ≥ 10. Curvature is analysed on ``min(T, 4096)`` samples equally spaced
        in arc length (``MAX_ANALYSIS_POINTS``), so the cost is linear in T.
    eps_frac : float in (0, 1), default 0.1
        Pruning threshold as a fraction of the curvature range.
    method : {"persistence", "paper"}
        Pruning rule (see the module docstring).

    Returns
    -------
    Segmentation
        ``points`` (sorted sample indices into ``y``; each extremum found on the arc-length
        resampled curve is mapped to the original sample nearest in arc length) and ``kinds``
        (+1 maximum, -1 minimum).
    """
    y = as_trajectory(y, "y", min_points=10)
    if y.shape[1] not in (2, 3):
        raise ValueError(f"y must be a 2-D or 3-D curve for segmentation, got D = {y.shape[1]}")
    eps_frac = check_real(eps_frac, "eps_frac")
    if not 0.0 < eps_frac < 1.0:
        raise ValueError(f"eps_frac must lie in (0, 1), got {eps_frac}")
    check_choice(method, "method", ("persistence", "paper"))
    return _segment(y, eps_frac, method)


def _segment(y: np.ndarray, eps_frac: float, method: str) -> Segmentation:
    """:func:`segment` of a checked demonstration (T >= 10, D = 2 or 3) and options."""
    n_samples = y.shape[0]
    n_points = min(n_samples, MAX_ANALYSIS_POINTS)
    s = arclength(y)
    total = s[-1]
    resampled = resample_arclength(y, n_points)
    kappa = _curvature(resampled, 0.05, 0.03)
    low, high = (
        int(np.ceil(_INTERIOR[0] * (n_points - 1))),
        int(np.floor(_INTERIOR[1] * (n_points - 1))) + 1,
    )
    interior = kappa[low:high]
    # Dimensionless curvature κ·L below 1e-6 everywhere: a straight line, nothing to cut.
    if np.max(interior) * total < 1e-6:  # (at least 10 samples: the interior has 8 or more)
        return Segmentation(np.empty(0, int), np.empty(0, int))
    indices, types = _alternating_extrema(kappa, low, high)
    epsilon = eps_frac * (np.max(interior) - np.min(interior))
    prune = _prune_persistence if method == "persistence" else _prune_paper
    kept, kinds = prune(indices, types, kappa, epsilon)
    # Map resampled indices (equal arc-length spacing) back to the nearest original samples.
    positions = kept / (n_points - 1) * total
    original = np.clip(np.searchsorted(s, positions), 1, n_samples - 1)
    nearer_left = (positions - s[original - 1]) < (s[original] - positions)
    original = np.where(nearer_left, original - 1, original)
    original, first = np.unique(original, return_index=True)
    return Segmentation(original, kinds[first])


@dataclass(frozen=True)
class Piece:
    """The piece of a demonstration to imitate towards a new target.

    ``start`` (= seg) and ``end`` are sample indices into the demonstration, inclusive.
    """

    index: int  # j*, the piece number
    start: int  # seg_index
    end: int
    breakpoints: np.ndarray  # 0, s_1 … s_m, T-1


def choose_piece(y, segmentation_points, new_target) -> Piece:
    """Pick the piece whose end point is nearest the new target (ties: the later piece).

    ``segmentation_points`` is a :class:`Segmentation` or an int array of sample indices.

    Breakpoints ``0 = b_0 < s_1 < … < s_m < b_end = T − 1`` split ``y`` into pieces; piece ``j``
    runs from ``b_j`` to ``b_{j+1}``.
    """
    y = as_trajectory(y, "y")
    target = as_point(new_target, y.shape[1], "new_target", like="y")
    if isinstance(segmentation_points, Segmentation):
        segmentation_points = segmentation_points.points
    points = as_indices(segmentation_points, "segmentation_points", y.shape[0] - 1, "y")
    return _choose_piece(y, points, target)


def _choose_piece(y: np.ndarray, points: np.ndarray, target: np.ndarray) -> Piece:
    """:func:`choose_piece` of a checked demonstration, sample indices and target."""
    last = y.shape[0] - 1
    breakpoints = np.unique(np.concatenate([[0], points, [last]]))
    ends = y[breakpoints[1:]]
    distances = np.linalg.norm(ends - target, axis=1)
    # Ties go to the later piece: search the reversed distances for the first minimum.
    index = len(distances) - 1 - int(np.argmin(distances[::-1]))
    return Piece(
        index=index,
        start=int(breakpoints[index]),
        end=int(breakpoints[index + 1]),
        breakpoints=breakpoints,
    )
