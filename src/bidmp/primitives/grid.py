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


def _grid_key(params, step: float) -> tuple:
    """Everything a rollout grid depends on besides its length and the learned kernels."""
    return (
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


def _store_grid(
    model, params, phase: np.ndarray, basis: np.ndarray, step: float, gate: np.ndarray | None = None
) -> tuple:
    """Cache the grid (phase, basis rows, unit responses, goal gate) on ``model``; return the entry.
    ``gate`` (n,): the goal gate on this grid when the caller has it (default: the model's goal
    system on it)."""
    if gate is None:
        gate = model.goal_system(params).on_grid(phase, step, params.tau, params.exact)
    cached = (
        _grid_key(params, step),
        model.centres_,
        model.widths_,
        phase,
        basis,
        _unit_responses(params, phase, None, step, gate),
        gate,
        {},  # shorter grids served from this one: n -> their entry (the same objects every time)
    )
    model._grid_cache = cached
    return cached


def _cached_grid(model, params, n_steps: int, step: float) -> tuple | None:
    """The cached entry for this grid, or None (another grid, or the kernels changed).

    A grid of fewer samples is the cached one's first ``n_steps`` (the phase, the basis rows, the
    gate and the responses of the causal integration all are), so the rollout a timed trajectory
    asks for (one sample past the horizon, for the state's derivatives) and the plain rollout
    share the grid ``fit`` computed."""
    cached = model.__dict__.get("_grid_cache")
    if (
        cached is None
        or cached[0] != _grid_key(params, step)
        or cached[1] is not model.centres_
        or cached[2] is not model.widths_
        or cached[3].shape[0] < n_steps
    ):
        return None
    if cached[3].shape[0] == n_steps:
        return cached
    prefixes = cached[7]
    if n_steps not in prefixes:
        key, centres, widths, phase, basis, responses, gate, _ = cached
        prefixes[n_steps] = (
            key,
            centres,
            widths,
            phase[:n_steps],
            basis[:n_steps],
            responses[:, :n_steps],
            gate[:n_steps],
            {},
        )
    return prefixes[n_steps]


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
    return cached[3:7]
