"""The rollout grid of a DMP: phase, basis rows, unit responses and goal gate on a grid of samples.

None of them depends on the weights, so the last grid a model used is cached on it (a Bi-DMP's
skills and a batch of goals share one). The cache key holds every hyperparameter the grid depends
on and the learned kernels, so changing any of them after ``fit`` can never roll out with stale
responses.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .band import _Band, _band_of
from .integrate import _unit_responses

__all__ = []


@dataclass(frozen=True)
class _GridEntry:
    """A model's cached rollout grid: what it was computed for (``key``, the learned ``centres``
    and ``widths``, compared by identity), and on it the phase (n,), the basis rows (n, N) and
    the same rows as a band (None where they are not one), the unit responses ``[B, C, V]``
    (3, n) and the goal gate (n,)."""

    key: tuple
    centres: np.ndarray
    widths: np.ndarray
    phase: np.ndarray
    basis: np.ndarray
    band: _Band | None
    responses: np.ndarray
    gate: np.ndarray
    # shorter grids served from this one: n -> their entry (the same objects every time)
    prefixes: dict = field(default_factory=dict, compare=False)

    def head(self, n_steps: int) -> _GridEntry:
        """The entry of the grid's first ``n_steps`` samples (a causal rollout's prefix)."""
        if n_steps not in self.prefixes:
            self.prefixes[n_steps] = _GridEntry(
                self.key,
                self.centres,
                self.widths,
                self.phase[:n_steps],
                self.basis[:n_steps],
                None if self.band is None else self.band.head(n_steps),
                self.responses[:, :n_steps],
                self.gate[:n_steps],
            )
        return self.prefixes[n_steps]

    def forcing(self, weights: np.ndarray) -> np.ndarray:
        """The basis rows times ``weights`` (N, D): (n, D), from the band where there is one."""
        return self.basis @ weights if self.band is None else self.band.product(weights)


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
    model,
    params,
    phase: np.ndarray,
    basis: np.ndarray,
    step: float,
    gate: np.ndarray | None = None,
    band: _Band | None = None,
) -> _GridEntry:
    """Cache the grid (phase, basis rows, unit responses, goal gate) on ``model``; return the entry.
    ``gate`` (n,): the goal gate on this grid when the caller has it (default: the model's goal
    system on it); ``band``: the rows as a band (:func:`~bidmp.primitives.band._band_of`), or None
    to multiply the dense rows."""
    if gate is None:
        gate = model.goal_system(params).on_grid(phase, step, params.tau, params.exact)
    entry = _GridEntry(
        _grid_key(params, step),
        model.centres_,
        model.widths_,
        phase,
        basis,
        band,
        _unit_responses(params, phase, None, step, gate),
        gate,
    )
    model._grid_cache = entry
    return entry


def _cached_grid(model, params, n_steps: int, step: float) -> _GridEntry | None:
    """The cached entry for this grid, or None (another grid, or the kernels changed).

    A grid of fewer samples is the cached one's first ``n_steps`` (the phase, the basis rows, the
    gate and the responses of the causal integration all are), so the rollout a timed trajectory
    asks for (one sample past the horizon, for the state's derivatives) and the plain rollout
    share the grid ``fit`` computed."""
    cached = model.__dict__.get("_grid_cache")
    if (
        cached is None
        or cached.key != _grid_key(params, step)
        or cached.centres is not model.centres_
        or cached.widths is not model.widths_
        or cached.phase.shape[0] < n_steps
    ):
        return None
    return cached if cached.phase.shape[0] == n_steps else cached.head(n_steps)


def _grid_entry(model, params, n_steps: int, step: float | None = None) -> _GridEntry:
    """The grid of ``n_steps`` samples ``step`` apart in normalised time (default ``dt_``) for
    the validated ``params``: the cached one, or computed and cached (the last grid used is kept:
    none of it depends on the weights, and the key holds every hyperparameter it depends on and
    the learned kernels, so changing any of them after ``fit`` never rolls out with stale
    responses)."""
    step = model.dt_ if step is None else step
    cached = _cached_grid(model, params, n_steps, step)
    if cached is None:
        phase = params.canonical_system.grid(n_steps, step, params.tau)
        basis = params.basis.rows(phase, model.centres_, model.widths_)
        # A band here too: a model loaded from a file rolls out as the fitted one did, to the bit.
        cached = _store_grid(model, params, phase, basis, step, band=_band_of(basis))
    return cached


def _rollout_grid(model, params, n_steps: int, step: float | None = None) -> tuple[np.ndarray, ...]:
    """Phase (n,), basis rows (n, N), unit responses ``[B, C, V]`` (3, n) and goal gate (n,) on
    the grid of ``n_steps`` samples ``step`` apart (:func:`_grid_entry`)."""
    entry = _grid_entry(model, params, n_steps, step)
    return entry.phase, entry.basis, entry.responses, entry.gate
