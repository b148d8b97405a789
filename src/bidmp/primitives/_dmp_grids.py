"""The grid queries of a :class:`~bidmp.primitives.dmp.DMP`: the phase and basis of its rollout and
training grids, its goal system, its forcing term and its end-point gain (a mixin: these read the
learned state and the validated parameters, and learn nothing)."""

from __future__ import annotations

import numpy as np

from .._checks import as_trajectory, check_bytes, check_int, numerically_guarded
from .._trajectory import resample_time
from .canonical import phase_grid
from .forcing import _as_phase, _basis_rows
from .goals import DelayedGoal, PhaseGate, ProgressGate, _learned_progress_gate
from .grid import _cached_grid, _rollout_grid
from .integrate import _unit_responses
from .protocols import _Params, _with_rest
from .rest import _rest_started

__all__ = ["GridQueries"]


class GridQueries:
    """What a fitted DMP computes on its grids (mixed into :class:`~bidmp.primitives.dmp.DMP`)."""

    # -- evaluation ----------------------------------------------------------------------------
    def default_n_steps(self) -> int:
        """The default rollout length on the normalised grid: ``round(settle · tau · T)`` samples
        (paper: T for ``tau = 1``; robot: 1.1 T, time for any goal to be reached)."""
        self._check_fitted()
        return self._n_steps(None, self._params())

    def _n_steps(self, n_steps, params: _Params) -> int:
        if n_steps is None:
            n_steps = max(int(round(params.settle * params.tau * self.n_steps_)), 1)
            check_int(n_steps, "the default rollout length round(tau * T)", limit="max_steps")
        else:
            n_steps = check_int(n_steps, "n_steps", minimum=1, limit="max_steps")
        check_bytes(n_steps * self.centres_.shape[0], "the rollout basis (n_steps x n_kernels)")
        return n_steps

    def phase(self, n_steps: int | None = None) -> np.ndarray:
        """Phase at each rollout step, shape ``(n_steps,)`` (default :meth:`default_n_steps`)."""
        self._check_fitted()
        params = self._params()
        return phase_grid(
            self._n_steps(n_steps, params),
            self.dt_,
            params.tau,
            params.alpha_phase,
            exact=params.exact,
        )

    def grid_basis(self, n_steps: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Phase (n,) and basis rows (n, N) on the rollout grid (default length
        :meth:`default_n_steps`), cached."""
        self._check_fitted()
        params = self._params()
        phase, basis, *_ = _rollout_grid(self, params, self._n_steps(n_steps, params))
        return phase, basis

    @property
    def n_train_(self) -> int:
        """Samples of the training grid: T (paper), or T followed by rest up to 1.1 T (robot)."""
        self._check_fitted()
        return max(int(round(self._params().settle * self.n_steps_)), self.n_steps_)

    def training_grid(self) -> tuple[np.ndarray, np.ndarray]:
        """Phase and basis rows (N columns) of the grid the weights were learned on
        (:attr:`n_train_` samples at ``tau = 1``); what :class:`bidmp.BiDMP` learns on."""
        self._check_fitted()
        phase, basis, *_ = _rollout_grid(self, self._params()._replace(tau=1.0), self.n_train_)
        return phase, basis

    def training_gate(self) -> np.ndarray:
        """The goal gate on the training grid: the phase (paper) or the delayed goal's remaining
        fraction (robot); the forcing target of :func:`_forcing_target` uses it."""
        self._check_fitted()
        params = self._params()
        return self.goal_system(params).training_gate(self.n_train_, self.dt_, params.exact)

    def goal_system(self, params: _Params | None = None) -> PhaseGate | DelayedGoal | ProgressGate:
        """The goal system (:mod:`bidmp.primitives.goals`) of this model for ``params`` (default its
        own): the phase gate, a delayed goal, or the learned progress gate (cached: a control loop
        asks for it once per stepper)."""
        if params is not None and not isinstance(params, _Params):
            raise TypeError(
                f"goal_system: params must be a DMP's resolved parameters (or None), got {type(params).__name__}"
            )
        params = self._params() if params is None else params
        if params.goal_rate is not None:
            return (PhaseGate if params.goal_rate == params.alpha_phase else DelayedGoal)(
                params.goal_rate
            )
        return _learned_progress_gate(self, params)

    def training_trajectory(self, y) -> np.ndarray:
        """A demonstration (T', D) as the weights are learned from it: resampled to T samples and,
        for the robot protocol, started and ended at rest (:func:`bidmp.primitives.rest.rest_started`) and
        followed by rest at its last point up to :attr:`n_train_`."""
        self._check_fitted()
        params = self._params()
        y = resample_time(as_trajectory(y, "y", min_points=2, allow_static=True), self.n_steps_)
        if params.rest_start:
            y = _rest_started(y, self.dt_, self.time_unit_)
        return _with_rest(y, params)

    def basis(self, phase) -> np.ndarray:
        """Basis rows ``phi(phase)`` of shape ``(L, n_kernels)`` (the Bi-DMP's BLS input)."""
        self._check_fitted()
        return _basis_rows(_as_phase(phase), self.centres_, self.widths_)

    def forcing_term(self, phase) -> np.ndarray:
        """Learned forcing term ``f(phase) = phi(phase) @ weights_``, shape ``(L, D)``."""
        return self.basis(phase) @ self.weights_

    @numerically_guarded
    def endpoint_gain(self, n_steps: int | None = None) -> float:
        """End-point gain ``c``: the final error for a shifted goal is ``c · ‖g' - g‖``.

        ``c = |1 - B[n_steps - 1]|`` where ``B`` is the goal's share of the affine rollout; it
        depends only on ``(alpha, K, alpha_phase, tau, T, n_steps)``, not on the weights. With the
        paper's fixed horizon it is far from 0 (T = 200, alpha = 100, K = alpha: c ≈ 0.0154); run to
        convergence and it tends to 0.
        """
        params = self._rollout_params()
        n_steps = self._n_steps(n_steps, params)
        cached = _cached_grid(self, params, n_steps, self.dt_)
        if cached is not None:
            goal_response = cached[5][0]
        else:  # B needs no basis matrix, and other horizons should not evict the cached grid
            phase = phase_grid(
                n_steps, self.dt_, params.tau, params.alpha_phase, exact=params.exact
            )
            gate = self.goal_system(params).on_grid(phase, self.dt_, params.tau, params.exact)
            goal_response = _unit_responses(params, phase, None, self.dt_, gate)[0]
        return float(abs(1.0 - goal_response[-1]))
