"""A DMP learned from several demonstrations, keeping their spread as a weight distribution.

Alignment in time: by phase — each demonstration is taken on its own normalised time (its first
sample at 0, its last at 1) and resampled to the demonstrations' median length, the motion lasting
their mean duration. (No dynamic time warping: demonstrations whose features come at different
shares of their duration are averaged where they are; DTW is left for a later release.)

One forcing term from all: the DMP's grid, kernels and goal system come from the mean aligned
demonstration; every demonstration's forcing target is taken on that grid and regressed on its
basis, and the weights are their mean (the same numbers as one regression on all the targets
stacked: the rows are shared). Their covariance, regularised, is the weight distribution: a
rollout's positions are affine in the weights, ``y = y₀ + A W`` with ``A`` the response of each
basis function's forcing, so a motion to any goal has a mean, an exact variance and samples.

Layer 1: the package's own math.
"""

from __future__ import annotations

import numpy as np

from .._api import Estimator, clone, real
from .._checks import NotFittedError, as_point, check_int, check_seed
from .._state import state_reader
from .._threads import single_threaded
from .._trajectory import resample_time
from .dmp import DMP
from .forcing import _regression_factor, _solve_weights
from .integrate import _unit_responses
from .promp import _demonstrations, _stamps, _weight_covariance

__all__ = ["MultiDMP"]


class MultiDMP(Estimator):
    """A DMP from several demonstrations, with their spread.

    Parameters
    ----------
    dmp : DMP, optional
        The DMP to learn (its parameters; cloned, never fitted itself); default ``DMP()``.
    cov_reg : float
        Added to the weight covariance's diagonal, times its mean variance.

    Attributes
    ----------
    dmp_ : DMP
        The fitted DMP whose weights are the mean weights.
    weights_ : (n_demos, N, D)
        Each demonstration's weights on the shared grid.
    weight_cov_ : (D, N, N)
        The weights' covariance per dimension (regularised).
    """

    _parameter_constraints = {"cov_reg": real(positive=True, maximum=1e3)}

    def __init__(self, dmp: DMP | None = None, cov_reg: float = 1e-6) -> None:
        self.dmp = dmp
        self.cov_reg = cov_reg

    @single_threaded  # small dense algebra: idle BLAS threads only steal the core
    def fit(self, demonstrations, times=None, units: str | None = None) -> MultiDMP:
        """Learn from ``demonstrations`` (a list of (T_i, D) arrays) with their stamps ``times``
        (a list of (T_i,) arrays, s; None: each over 1 s)."""
        self._check_constraints()
        cov_reg = float(self.cov_reg)
        template = DMP() if self.dmp is None else self.dmp
        if not isinstance(template, DMP):
            raise TypeError(
                f"dmp must be a bidmp.DMP (its parameters), got {type(template).__name__}"
            )
        demos = _demonstrations(demonstrations)
        stamps = _stamps(times, demos)
        n_samples = int(np.median([y.shape[0] for y in demos]))
        aligned = np.stack([resample_time(y, n_samples) for y in demos])
        duration = float(np.mean([t[-1] - t[0] for t in stamps]))
        t = np.linspace(0.0, duration, n_samples)
        model = clone(template).fit(
            aligned.mean(axis=0), t if times is not None else None, units=units
        )
        # Every demonstration's forcing target on the mean one's grid, regressed as the DMP
        # regresses its own (one factor for all); each is started and ended at rest as the mean
        # one was, which said so once when the model was fitted.
        params = model.settings()
        phase, basis = model.training_grid()
        factor = _regression_factor(basis, phase, params.regression, params.ridge)
        weights = np.stack(
            [
                _solve_weights(
                    factor, basis, model.forcing_target(model.training_trajectory(y, quiet=True))
                )
                for y in aligned
            ]
        )
        model.weights_ = np.ascontiguousarray(weights.mean(axis=0))
        n_kernels, n_dims = model.weights_.shape
        covariance = np.stack(
            [_weight_covariance(weights[:, :, d], cov_reg) for d in range(n_dims)]
        )
        self.dmp_ = model
        self.weights_ = weights
        self.weight_cov_ = covariance
        self.aligned_ = aligned
        return self

    def check_fitted(self) -> None:
        """Raise :class:`bidmp.NotFittedError`, saying what to do, unless the model is fitted."""
        if "dmp_" not in self.__dict__:
            raise NotFittedError("this MultiDMP is not fitted yet: call fit(demonstrations) first")

    @property
    def system_(self):
        """The mean motion as a :class:`~bidmp.primitives.system.DMPSystem` (the mean weights'
        DMP's, at its ``tau``)."""
        self.check_fitted()
        return self.dmp_.system_

    def trajectory(self, goal=None, **options):
        """The mean motion (:meth:`bidmp.DMP.trajectory` of the mean weights)."""
        self.check_fitted()
        return self.dmp_.trajectory(goal, **options)

    def rollout(self, goal=None, **options) -> np.ndarray:
        """The mean motion's positions (:meth:`bidmp.DMP.rollout`)."""
        self.check_fitted()
        return self.dmp_.rollout(goal, **options)

    def response(self, goal=None, n_steps: int | None = None) -> np.ndarray:
        """``A`` (n, N): how each weight moves the rollout's positions (the same for every
        dimension and any goal: the forcing enters each alike), exactly — the rollout grid's
        basis functions integrated as forcing terms, all at once."""
        self.check_fitted()
        dmp = self.dmp_
        if goal is not None:  # checked as a rollout would, though the response is the same
            as_point(goal, dmp.n_dims_, "goal")
        system = dmp.system_
        phase, basis, *_ = system.grid(n_steps)  # the grid checks the step
        return _unit_responses(system.settings, phase, basis, system.dt).T

    def std(self, goal=None, n_steps: int | None = None) -> np.ndarray:
        """The positions' standard deviation (n, D) along the rollout to ``goal`` (exact)."""
        A = self.response(goal, n_steps)
        variance = np.stack(
            [np.einsum("ti,ij,tj->t", A, block, A) for block in self.weight_cov_], axis=1
        )
        return np.sqrt(np.maximum(variance, 0.0))

    def sample(self, n_samples: int, seed=0, goal=None, n_steps: int | None = None) -> np.ndarray:
        """``n_samples`` rollouts (n_samples, n, D) to ``goal`` with weights drawn from the
        distribution (seeded)."""
        self.check_fitted()
        n_samples = check_int(n_samples, "n_samples", minimum=1, maximum=10_000)
        rng = np.random.default_rng(check_seed(seed, "seed"))
        n_kernels, n_dims = self.dmp_.weights_.shape
        # (n_samples, N, D)
        changes = np.stack(
            [
                np.column_stack(
                    [
                        rng.multivariate_normal(np.zeros(n_kernels), self.weight_cov_[d])
                        for d in range(n_dims)
                    ]
                )
                for _ in range(n_samples)
            ]
        )
        # the rollout is affine in the weights: the mean motion plus each change's response
        base = self.dmp_.rollout(goal, n_steps=n_steps)
        return base[None] + np.einsum("tn,snd->std", self.response(goal, n_steps), changes)

    # -- persistence (used by bidmp.io) -----------------------------------------------------
    def to_state(self) -> tuple[dict, dict]:
        """The model-file form of the fitted model, ``(meta, arrays)``: its parameters and scalars
        as a JSON-able dict, its learned arrays by name (:func:`bidmp.io.save_model` writes the two
        into one ``.npz``; no pickle). Raises :class:`bidmp.NotFittedError` before ``fit``."""
        self.check_fitted()
        inner_state, inner_arrays = self.dmp_.to_state()
        arrays = {f"dmp/{name}": value for name, value in inner_arrays.items()}
        arrays["weights_"] = self.weights_
        arrays["weight_cov_"] = self.weight_cov_
        state = {"cov_reg": float(self.cov_reg), "dmp": inner_state}
        return state, arrays

    @classmethod
    @state_reader
    def from_state(cls, meta: dict, arrays) -> MultiDMP:
        """The fitted model :meth:`to_state` described: ``meta`` as written, ``arrays`` a mapping of
        name to array, each read when needed and checked for dtype, shape and finiteness
        (:func:`bidmp.io.load_model` calls it; a bad file raises, naming the member)."""
        from .._checks import check_loaded
        from .._state import Prefixed

        inner = DMP.from_state(meta["dmp"], Prefixed(arrays, "dmp/"))
        model = cls(dmp=DMP(**inner.get_params()), cov_reg=meta["cov_reg"])
        n_kernels, n_dims = inner.weights_.shape
        model.dmp_ = inner
        model.weights_ = check_loaded(arrays["weights_"], "weights_", (None, n_kernels, n_dims))
        model.weight_cov_ = check_loaded(
            arrays["weight_cov_"], "weight_cov_", (n_dims, n_kernels, n_kernels)
        )
        return model
