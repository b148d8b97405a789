"""The final approach of a demonstration, its straight tail into the goal; and its departure, the
straight head it starts with (a lift off a part).

A robot's last motion into a nut or a socket is a straight move along the target's axis; a DMP that
keeps it (``DMP(keep_approach=True)``, :class:`bidmp.primitives.goals.ApproachGate`) completes a
goal's offset before it, so the approach to a moved goal is a translated copy of the demonstrated
one. Segmentation (:func:`bidmp.extension.extend.final_approach`) uses the same test of straightness.
"""

from __future__ import annotations

import numpy as np

__all__ = ["STRAIGHTNESS", "straight_tail_start"]

STRAIGHTNESS = 0.02  # an approach deviates from its chord by at most this fraction of the chord
MAX_TAIL_CANDIDATES = 256  # start indices tried for the earliest straight tail


def _is_straight(points: np.ndarray, tolerance: float = STRAIGHTNESS) -> bool:
    """Whether ``points`` (n, D) stay within ``tolerance`` × their chord of the chord and never move
    back along it (by more than that)."""
    chord = points[-1] - points[0]
    length = float(np.linalg.norm(chord))
    if length == 0.0:
        return False
    offsets = points - points[0]
    along = offsets @ (chord / length)
    deviation = np.linalg.norm(offsets - along[:, None] * (chord / length), axis=1)
    return bool(
        deviation.max() <= tolerance * length and np.all(np.diff(along) >= -tolerance * length)
    )


def _straight_head_end(y: np.ndarray, straightness: float = STRAIGHTNESS) -> int:
    """The latest index up to which ``y`` (T, D) is straight from its start (on the same grid of
    candidates as :func:`_tail_start`); 0 when no head of 2 samples or more is."""
    return y.shape[0] - 1 - _tail_start(y[::-1], 0, straightness)


def straight_tail_start(y, start: int = 0, straightness: float = STRAIGHTNESS) -> int:
    """The earliest sample index from ``start`` on from which the rest of ``y`` (T, D) is
    straight — within ``straightness`` × its chord of the chord, never moving back along it —
    tried on a grid of at most 256 candidates; ``T - 1`` when no tail of two samples or more is
    (the motion has no straight approach)."""
    from .._checks import as_trajectory, check_int, check_real

    y = as_trajectory(y, "y", min_points=2, allow_static=True)
    start = check_int(start, "start", minimum=0, maximum=y.shape[0] - 1)
    straightness = check_real(straightness, "straightness", positive=True, maximum=1.0)
    return _tail_start(y, start, straightness)


def _tail_start(y: np.ndarray, start: int = 0, straightness: float = STRAIGHTNESS) -> int:
    """The earliest index from ``start`` on (on a grid of at most 256 candidates) from which the
    rest of ``y`` (T, D) is straight; ``T - 1`` when no tail of 2 samples or more is (the motion has
    no approach)."""
    last = y.shape[0] - 1
    if _is_straight(y[start:], straightness):
        return int(start)
    candidates = np.linspace(start, last - 1, min(MAX_TAIL_CANDIDATES, max(last - start, 1)))
    candidates = candidates.astype(int)  # non-decreasing: its distinct values without a sort
    candidates = candidates[np.concatenate(([True], candidates[1:] != candidates[:-1]))]
    # The candidates' tests at once (a fit asks twice: its approach and its departure; one
    # candidate at a time was 80 % of a robot-protocol fit), each stage a necessary condition of
    # the next, so only a few candidates take the whole test: three probes inside each tail, then
    # every 8th sample of it, then all of it. Each stage looks only at the samples from its
    # earliest candidate on (the tails are the motion's last part).
    candidates = candidates[_probes_straight(y, candidates, straightness)]
    block = max(1, _BLOCK_ELEMENTS // max(y.shape[0] * y.shape[1], 1))
    for first in range(0, candidates.shape[0], block):
        chunk = candidates[first : first + block]
        chunk = chunk[_tails_from(y, chunk, straightness, _COARSE)]
        for part in range(0, chunk.shape[0], _FULL_BATCH):  # in order: the first that holds wins
            batch = chunk[part : part + _FULL_BATCH]
            straight = np.flatnonzero(_tails_from(y, batch, straightness, 1))
            if straight.size:
                return int(batch[straight[0]])
    return last


_BLOCK_ELEMENTS = 1 << 20  # floats of one block of candidate tails tested together (8 MB)
_COARSE = 8  # every how many samples the cheap first test looks at
_FULL_BATCH = 4  # the candidates that pass it, taken the whole test this many at a time


def _tails_from(y: np.ndarray, starts: np.ndarray, tolerance: float, stride: int) -> np.ndarray:
    """:func:`_tails_straight` on the samples from the earliest start on (the same tails: each
    looks only at its own samples, and the end is the same)."""
    if starts.size == 0:
        return np.zeros(0, dtype=bool)
    lowest = int(starts.min())
    return _tails_straight(y[lowest:], starts - lowest, tolerance, stride=stride)


def _probes_straight(y: np.ndarray, starts: np.ndarray, tolerance: float) -> np.ndarray:
    """A necessary condition of :func:`_tails_straight` for every start (k,), from three samples
    of each tail only (a quarter, half and three quarters of the way to the end): each within
    ``tolerance`` × the chord of the chord. (k,) bool; a tail it refuses is not straight."""
    if starts.size == 0:
        return np.zeros(0, dtype=bool)
    last = y.shape[0] - 1
    ends = y - y[-1]
    origin = ends[starts]  # (k, D)
    length = np.linalg.norm(origin, axis=1)
    moving = length > 0.0
    unit = -origin / np.where(moving, length, 1.0)[:, None]
    # the three probes of every tail at once: (3, k) samples
    index = starts + np.floor(_PROBES[:, None] * (last - starts)).astype(int)
    offset = ends[index] - origin  # (3, k, D)
    along = np.sum(offset * unit, axis=2)
    across = np.sum(offset * offset, axis=2) - along * along
    bound = tolerance * length
    # a hair of slack: the full test sums the same squares in another order
    return moving & np.all(across <= bound * bound * (1.0 + 1e-9) + 1e-300, axis=0)


_PROBES = np.array([0.25, 0.5, 0.75])  # where inside each tail the probes look, as shares


def _tails_straight(
    y: np.ndarray, starts: np.ndarray, tolerance: float, stride: int = 1
) -> np.ndarray:
    """:func:`_is_straight` of ``y[s:]`` for every ``s`` in ``starts`` (k,), as matrix products:
    with the points taken from the end ``p = y - y[-1]`` and each tail's chord ``c`` from its first
    point ``o`` (unit ``u``), a sample's distance along the chord is ``(p - o)·u`` and its squared
    distance from it ``|p - o|² - ((p - o)·u)²``; the samples before a tail's start are masked
    out. With ``stride`` > 1 only every ``stride``-th sample's distance from the chord is looked
    at (no backward step): a necessary condition, so a tail it refuses is not straight. (k,) bool."""
    if starts.size == 0:
        return np.zeros(0, dtype=bool)
    ends = y - y[-1]  # from the end: small numbers, little cancellation in the squares
    origin = ends[starts]  # (k, D)
    index = np.arange(0, y.shape[0], stride)
    points = ends[index]
    length = np.linalg.norm(origin, axis=1)  # the chord runs from the origin to the end (0)
    moving = length > 0.0
    unit = -origin / np.where(moving, length, 1.0)[:, None]
    along = points @ unit.T - np.sum(origin * unit, axis=1)  # (n, k)
    squared = (
        np.sum(points * points, axis=1)[:, None]
        - 2.0 * points @ origin.T
        + np.sum(origin * origin, axis=1)[None, :]
    )
    across = squared - along * along
    inside = index[:, None] >= starts[None, :]
    widest = np.where(inside, across, -np.inf).max(axis=0)
    bound = tolerance * length
    if stride > 1:
        return moving & (widest <= bound * bound)
    steps = np.diff(along, axis=0)
    back = np.where(index[1:, None] > starts[None, :], steps, np.inf).min(axis=0)
    return moving & (widest <= bound * bound) & (back >= -bound)
