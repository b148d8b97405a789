"""The rollout grid of a DMP: phase, basis rows, unit responses and goal gate on a grid of samples.

None of them depends on the weights, so the last grid a fitted system used is cached with it (a
Bi-DMP's skills and a batch of goals share one). The cache key holds every hyperparameter the grid depends
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


class _Caches:
    """What a fitted DMP keeps between rollouts, shared by its systems at every ``tau``: the last
    rollout grid (:class:`_GridEntry`; the key holds every setting it depends on and the learned
    kernels, so a changed one never rolls out with stale responses) and the learned progress gate
    (``(key, gate)``)."""

    __slots__ = ("grid", "goal_system")

    def __init__(self) -> None:
        self.grid = None
        self.goal_system = None

    def store(
        self,
        system,
        phase: np.ndarray,
        basis: np.ndarray,
        step: float,
        gate: np.ndarray | None = None,
        band: _Band | None = None,
    ) -> _GridEntry:
        """Cache the grid (phase, basis rows, unit responses, goal gate) of ``system`` (a
        :class:`~bidmp.primitives.system.DMPSystem`, at its settings); return the entry. ``gate``
        (n,): the goal gate on this grid when the caller has it (default: the system's goal system
        on it); ``band``: the rows as a band (:func:`~bidmp.primitives.band._band_of`), or None to
        multiply the dense rows."""
        params = system.settings
        if gate is None:
            gate = system.goal_system().on_grid(phase, step, params.tau, params.exact)
        self.grid = _GridEntry(
            _grid_key(params, step),
            system.centres,
            system.widths,
            phase,
            basis,
            band,
            _unit_responses(params, phase, None, step, gate),
            gate,
        )
        return self.grid

    def cached(self, system, n_steps: int, step: float) -> _GridEntry | None:
        """The cached entry for this grid, or None (another grid, or the kernels changed).

        A grid of fewer samples is the cached one's first ``n_steps`` (the phase, the basis rows,
        the gate and the responses of the causal integration all are), so the rollout a timed
        trajectory asks for (one sample past the horizon, for the state's derivatives) and the
        plain rollout share the grid ``fit`` computed."""
        cached = self.grid
        if (
            cached is None
            or cached.key != _grid_key(system.settings, step)
            or cached.centres is not system.centres
            or cached.widths is not system.widths
            or cached.phase.shape[0] < n_steps
        ):
            return None
        return cached if cached.phase.shape[0] == n_steps else cached.head(n_steps)

    def entry(self, system, n_steps: int, step: float | None = None) -> _GridEntry:
        """The grid of ``n_steps`` samples ``step`` apart in normalised time (default the system's
        ``dt``): the cached one, or computed and cached."""
        step = system.dt if step is None else step
        cached = self.cached(system, n_steps, step)
        if cached is None:
            params = system.settings
            phase = params.canonical_system.grid(n_steps, step, params.tau)
            basis = params.basis.rows(phase, system.centres, system.widths)
            # A band here too: a model loaded from a file rolls out as the fitted one did, to the bit.
            cached = self.store(system, phase, basis, step, band=_band_of(basis))
        return cached
