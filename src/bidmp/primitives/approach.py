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
    candidates = np.unique(
        np.linspace(start, last - 1, min(MAX_TAIL_CANDIDATES, max(last - start, 1))).astype(int)
    )
    for candidate in candidates:
        if _is_straight(y[candidate:], straightness):
            return int(candidate)
    return last
