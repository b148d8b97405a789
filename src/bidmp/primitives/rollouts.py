"""Rollouts to many goals at once: the rollout is affine in the goal, ``y = free + B g``, so G goals
cost one integration and one outer product (:meth:`bidmp.DMP.rollout_many`,
:meth:`bidmp.DMP.iter_rollouts`)."""

from __future__ import annotations

import numpy as np

from .._checks import as_points, check_bytes, check_limit, get_limits
from .integrate import _affine_rollouts

__all__ = []


def _rollouts_to(
    goals, free: np.ndarray, goal_response: np.ndarray, out: np.ndarray | None = None
) -> np.ndarray:
    """The rollouts ``free + B goals[i]`` (G, n, D) of a model's free response ``free`` (n, D) and
    goal response ``goal_response`` (n,), into ``out`` if given (else refused over the limit
    ``max_array_bytes``)."""
    goals = _goals(goals, free)
    shape = (goals.shape[0], *free.shape)
    if out is None:
        n_bytes = 8 * goals.shape[0] * free.size
        budget = get_limits().max_array_bytes
        if n_bytes > budget:
            chunk = max(budget // (8 * free.size), 1)
            raise ValueError(
                f"goals: {goals.shape[0]:,} goals x {free.shape[0]:,} steps x {free.shape[1]} dims would take "
                f"{n_bytes / 2**30:.3g} GiB, over max_array_bytes = {budget / 2**30:.3g} GiB; give out= (a "
                f"numpy.lib.format.open_memmap of shape {shape}), use iter_rollouts(goals, chunk_size={chunk:,}) "
                f"or raise the limit"
            )
        return _affine_rollouts(goal_response, goals, free)
    if (
        not isinstance(out, np.ndarray)
        or out.shape != shape
        or out.dtype != np.float64
        or not out.flags.writeable
    ):
        described = (
            f"{type(out).__name__} {getattr(out, 'shape', '')} {getattr(out, 'dtype', '')}".strip()
        )
        raise ValueError(f"out must be a writable float64 array of shape {shape}, got {described}")
    for first, chunk in _chunks(goals, free):
        _affine_rollouts(goal_response, chunk, free, out[first : first + chunk.shape[0]])
    return out


def _chunks(goals: np.ndarray, free: np.ndarray, chunk_size: int | None = None):
    """``(first, goals[first : first + chunk_size])``; by default about 64 MiB of rollouts a chunk."""
    if chunk_size is None:
        chunk_size = max((64 << 20) // (8 * free.size), 1)  # about 64 MiB per chunk
    for first in range(0, goals.shape[0], chunk_size):
        yield first, goals[first : first + chunk_size]


def _goals(goals, free: np.ndarray) -> np.ndarray:
    """Goals (G, D) of a batch: at most ``max_samples`` of them, and no more rollout samples in all
    than ``max_work`` (each goal is a whole motion: the total work is bounded, not only one array)."""
    goals = as_points(goals, free.shape[1], "goals")
    check_limit(goals.shape[0], "max_samples", "goals: the number of goals")
    check_limit(
        goals.shape[0] * free.size,
        "max_work",
        "goals: the rollouts' samples in all (goals x n_steps x D)",
    )
    return goals


def _iter_rollouts_to(goals, free: np.ndarray, goal_response: np.ndarray, chunk_size: int):
    """:func:`_rollouts_to`, ``chunk_size`` goals at a time: yields ``(first, y (g, n, D))``."""
    goals = _goals(goals, free)
    check_bytes(
        min(chunk_size, goals.shape[0]) * free.size,
        "one chunk of iter_rollouts (chunk_size x n_steps x D)",
    )
    for first, chunk in _chunks(goals, free, chunk_size):
        yield first, _affine_rollouts(goal_response, chunk, free)
