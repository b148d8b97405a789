"""The final approach of a demonstration, its straight tail into the goal; and its departure, the
straight head it starts with (a lift off a part).

A robot's last motion into a nut or a socket is a straight move along the target's axis; a DMP that
keeps it (``DMP(keep_approach=True)``, :class:`bidmp.primitives.goals.ApproachGate`) completes a
goal's offset before it, so the approach to a moved goal is a translated copy of the demonstrated
one. Segmentation (:func:`bidmp.extension.extend.final_approach`) uses the same test of straightness.
"""

from __future__ import annotations

import functools

import numpy as np

from .._kernels import tail_start

__all__ = ["STRAIGHTNESS", "straight_tail_start"]

STRAIGHTNESS = 0.02  # an approach deviates from its chord by at most this fraction of the chord
MAX_TAIL_CANDIDATES = 256  # start indices tried for the earliest straight tail


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
    # One compiled loop over the candidates with early exits (a fit asks twice, its approach and
    # its departure; tested together as NumPy matrix products they were a sixth of a fit).
    return tail_start(y, _tail_candidates(start, y.shape[0] - 1), straightness)


@functools.lru_cache(maxsize=16)
def _tail_candidates(start: int, last: int) -> np.ndarray:
    """The start indices tried from ``start`` for a path whose last index is ``last``: at most
    :data:`MAX_TAIL_CANDIDATES`, evenly spread, increasing (read-only: shared by every fit of a
    demonstration of that length)."""
    candidates = np.linspace(start, last - 1, min(MAX_TAIL_CANDIDATES, max(last - start, 1)))
    candidates = candidates.astype(np.int64)  # non-decreasing: its distinct values without a sort
    candidates = candidates[np.concatenate(([True], candidates[1:] != candidates[:-1]))]
    candidates.flags.writeable = False
    return candidates
