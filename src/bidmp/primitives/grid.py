"""The rollout grid of a DMP: phase, basis rows, unit responses and goal gate on a grid of samples.

None of them depends on the weights, so the last grid a model used is cached on it (a Bi-DMP's
skills and a batch of goals share one). The cache key holds every hyperparameter the grid depends
on and the learned kernels, so changing any of them after ``fit`` can never roll out with stale
responses.
"""

from __future__ import annotations

import numpy as np

from .integrate import _unit_responses

__all__ = []


def _grid_key(params, n_steps: int, step: float) -> tuple:
    """Everything a rollout grid depends on besides the learned kernels."""
    return (
        n_steps,
        params.tau,
        params.alpha,
        params.beta,
        params.K,
        params.alpha_phase,
        params.canonical_system,
        params.basis,
        params.goal_rate,
        params.integrator,
        step,
    )


def _store_grid(model, params, phase: np.ndarray, basis: np.ndarray, step: float) -> tuple:
    """Cache the grid (phase, basis rows, unit responses, goal gate) on ``model``; return the entry."""
    gate = model.goal_system(params).on_grid(phase, step, params.tau, params.exact)
    cached = (
        _grid_key(params, phase.shape[0], step),
        model.centres_,
        model.widths_,
        phase,
        basis,
        _unit_responses(params, phase, None, step, gate),
        gate,
    )
    model._grid_cache = cached
    return cached


def _cached_grid(model, params, n_steps: int, step: float) -> tuple | None:
    """The cached entry for this grid, or None (another grid, or the kernels changed)."""
    cached = model.__dict__.get("_grid_cache")
    if (
        cached is None
        or cached[0] != _grid_key(params, n_steps, step)
        or cached[1] is not model.centres_
        or cached[2] is not model.widths_
    ):
        return None
    return cached


def _rollout_grid(model, params, n_steps: int, step: float | None = None) -> tuple[np.ndarray, ...]:
    """Phase (n,), basis rows (n, N), unit responses ``[B, C, V]`` (3, n) and goal gate (n,) on the grid of
    ``n_steps`` samples ``step`` apart in normalised time (default ``dt_``) for the validated
    ``params``.

    None of them depends on the weights, so the last grid used is cached. The cache key holds
    every hyperparameter the grid depends on and the learned kernels, so changing any of them
    after ``fit`` can never roll out with stale responses.
    """
    step = model.dt_ if step is None else step
    cached = _cached_grid(model, params, n_steps, step)
    if cached is None:
        phase = params.canonical_system.grid(n_steps, step, params.tau)
        basis = params.basis.rows(phase, model.centres_, model.widths_)
        cached = _store_grid(model, params, phase, basis, step)
    return cached[3:]
