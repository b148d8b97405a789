"""Time-driven GMM/GMR: a Gaussian mixture on ``[t, y]`` fitted by EM (scikit-learn's
``GaussianMixture``), and Gaussian mixture regression of ``y`` given ``t``.

It reproduces the demonstrations it was given and has no notion of a new target: it cannot adapt,
which is the point of the comparison in the paper's Table 4.
"""

from __future__ import annotations

import logging
import warnings

import numpy as np

from .._api import Estimator, integer, real
from .._checks import (
    as_trajectory,
    check_bool,
    check_fitted,
    check_int,
    check_limit,
    check_real,
    numerically_guarded,
)
from .._noise import perturb

__all__ = ["augment", "GMMRegressor"]

logger = logging.getLogger(__name__)
_EM_ITERATIONS = 100  # scikit-learn's max_iter default, used for the work bound


def _gmr(
    weights: np.ndarray, means: np.ndarray, covariances: np.ndarray, t: np.ndarray, n_in: int = 1
):
    """Gaussian mixture regression of the outputs given the first ``n_in`` input dimensions.

    Parameters
    ----------
    weights : (K,)
    means : (K, n)
    covariances : (K, n, n)
    t : (L,) or (L, n_in)

    Returns
    -------
    mean : (L, n − n_in)
    covariance : (L, n − n_in, n − n_in)
    """
    t = np.asarray(t, dtype=np.float64).reshape(len(t), -1)
    mu_in, mu_out = means[:, :n_in], means[:, n_in:]
    s_ii = covariances[:, :n_in, :n_in]
    s_oi = covariances[:, n_in:, :n_in]
    s_oo = covariances[:, n_in:, n_in:]
    s_ii_inv = np.linalg.inv(s_ii)
    # Responsibilities h_k(t) ∝ π_k N(t; μ_in,k, Σ_ii,k), computed in log space.
    diff = t[:, None, :] - mu_in[None]  # (L, K, n_in)
    mahalanobis = np.einsum("lki,kij,lkj->lk", diff, s_ii_inv, diff)
    _, logdet = np.linalg.slogdet(s_ii)
    log_h = np.log(weights)[None] - 0.5 * (mahalanobis + logdet[None] + n_in * np.log(2 * np.pi))
    log_h -= log_h.max(axis=1, keepdims=True)
    h = np.exp(log_h)
    h /= h.sum(axis=1, keepdims=True)
    gain = np.einsum("koi,kij->koj", s_oi, s_ii_inv)  # Σ_oi Σ_ii⁻¹
    conditional = mu_out[None] + np.einsum("koj,lkj->lko", gain, diff)  # (L, K, n_out)
    mean = np.einsum("lk,lko->lo", h, conditional)
    cond_cov = s_oo - np.einsum("koj,kpj->kop", gain, s_oi)  # Σ_oo − Σ_oi Σ_ii⁻¹ Σ_io
    spread = conditional - mean[:, None, :]
    covariance = np.einsum("lk,kop->lop", h, cond_cov) + np.einsum(
        "lk,lko,lkp->lop", h, spread, spread
    )
    return mean, covariance


def _check_gmr_size(n_steps: int, means_shape: tuple) -> None:
    from .._checks import check_bytes

    n_components, n_dims = means_shape
    check_bytes(
        n_steps * n_components * n_dims * n_dims,
        "GMR's intermediate arrays (steps x components x dims²)",
    )


def augment(y: np.ndarray, n_copies: int = 5, noise: float = 1.5, seed: int = 0) -> np.ndarray:
    """The single-demonstration augmentation: ``y`` plus smooth noisy copies.

    Returns (n_copies + 1, T, D); the copies keep the start and the end exact.
    """
    y = as_trajectory(y, "y")
    check_int(n_copies, "n_copies", minimum=0, maximum=_MAX_COPIES)
    check_real(noise, "noise", nonnegative=True, maximum=1e-3 * _max_abs())
    check_limit(
        y.size * (n_copies + 1),
        "max_samples",
        "the augmented data's values, T * D * (n_copies + 1)",
    )
    rng = np.random.default_rng(check_int(seed, "seed", minimum=0, maximum=2**63 - 1))
    return np.stack([y] + [perturb(y, noise, rng) for _ in range(n_copies)])


def _fit_mixture(data: np.ndarray, n_components: int, reg_covar: float, seed: int):
    """EM for a full-covariance Gaussian mixture (scikit-learn): (weights, means, covariances).

    Runs with one BLAS/OpenMP thread, as the BLS does: EM on a few thousand 4–7-D points gains
    nothing from threads, and on 2 cores contention between the thread pools made
    ``GaussianMixture`` up to 15× slower in a review (3–7.5 s instead of 0.35–0.5 s), so the
    baselines' run times measured contention rather than the method.
    """
    from sklearn.exceptions import ConvergenceWarning
    from sklearn.mixture import GaussianMixture
    from threadpoolctl import threadpool_limits

    n_samples, n_dims = data.shape
    if n_samples < n_components:
        raise ValueError(
            f"n_components = {n_components} needs at least as many samples, got {n_samples}"
        )
    check_limit(
        float(n_samples) * n_components * n_dims * n_dims * _EM_ITERATIONS,
        "max_work",
        "EM's work (samples x components x dims² x iterations)",
    )
    # A fresh limiter (not the BLS's cached one): it must see the OpenMP runtime that
    # scikit-learn's k-means initialisation loads, which may not have been loaded before.
    with threadpool_limits(limits=1), warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", ConvergenceWarning)
        mixture = GaussianMixture(
            n_components, covariance_type="full", reg_covar=reg_covar, random_state=seed
        ).fit(data)
    for warning in caught:  # library code never prints: report EM's convergence through logging
        logger.warning("GaussianMixture: %s", warning.message)
    return mixture.weights_, mixture.means_, mixture.covariances_


_MAX_COMPONENTS = 1_000
_MAX_COPIES = 1_000


def _max_abs() -> float:
    from .._checks import get_limits

    return get_limits().max_abs_value


class _AugmentedMixture(Estimator):
    """Parameters shared by the baselines: mixture size, regularisation, augmentation, seed.

    scikit-learn conventions: the constructor stores, ``fit`` validates (:meth:`_check_params`).
    """

    _parameter_constraints = {
        "n_components": integer(minimum=1, maximum=_MAX_COMPONENTS),
        "reg_covar": real(positive=True, maximum=1e6),
        "n_copies": integer(minimum=0, maximum=_MAX_COPIES),
        # (a thousandth of the value limit in force when it is checked)
        "noise": lambda value, name: check_real(
            value, name, nonnegative=True, maximum=1e-3 * _max_abs()
        ),
        # scikit-learn's random_state range
        "seed": integer(minimum=0, maximum=2**32 - 1),
    }

    def _check_params(self) -> None:
        self._check_constraints()

    def __sklearn_is_fitted__(self) -> bool:
        return "weights_" in self.__dict__


class GMMRegressor(_AugmentedMixture):
    """Time-driven GMM/GMR on one (augmented) demonstration.

    Parameters
    ----------
    n_components : int, default 16
        With fewer, GMR's per-component linear regression averages the decelerating end of a
        movement: 8 components end 6 mm short on the battery approach, 16 end within 0.8 mm.
    reg_covar : float, default 1e-6
        Added to the covariance diagonals (at least 1e-6).
    n_copies, noise : augmentation of a single demonstration (see :func:`augment`).
    seed : int

    Attributes
    ----------
    weights_, means_, covariances_ : the mixture on ``[t, y]``.
    n_steps_ : int
    """

    def __init__(
        self,
        n_components: int = 16,
        reg_covar: float = 1e-6,
        n_copies: int = 5,
        noise: float = 1.5,
        seed: int = 0,
    ):
        self.n_components = n_components
        self.reg_covar = reg_covar
        self.n_copies = n_copies
        self.noise = noise
        self.seed = seed

    @numerically_guarded
    def fit(self, y) -> GMMRegressor:
        """Fit on one demonstration (T, D), time scaled to [0, 1]."""
        self._check_params()
        demos = augment(y, self.n_copies, self.noise, self.seed)
        n_steps = demos.shape[1]
        t = np.linspace(0.0, 1.0, n_steps)
        data = np.concatenate([np.column_stack([t, demo]) for demo in demos])
        self.weights_, self.means_, self.covariances_ = _fit_mixture(
            data, self.n_components, self.reg_covar, self.seed
        )
        self.n_steps_ = n_steps
        return self

    @numerically_guarded
    def rollout(self, goal=None, *, n_steps: int | None = None, return_covariance: bool = False):
        """The mean motion (n, D) by GMR, on the demonstration's sample grid in normalised time
        (t ∈ [0, 1]); ``return_covariance``: also the covariances (n, D, D). A GMM on time has no
        notion of a goal: ``goal`` must be None (:class:`TPGMM` takes one)."""
        check_fitted(self, "weights_")
        if goal is not None:
            raise ValueError(
                "goal: GMMRegressor reproduces its demonstration and takes no goal (TPGMM does)"
            )
        n_steps = (
            self.n_steps_
            if n_steps is None
            else check_int(n_steps, "n_steps", minimum=2, limit="max_steps")
        )
        _check_gmr_size(n_steps, self.means_.shape)
        mean, covariances = _gmr(
            self.weights_, self.means_, self.covariances_, np.linspace(0.0, 1.0, n_steps)
        )
        return (mean, covariances) if check_bool(return_covariance, "return_covariance") else mean
