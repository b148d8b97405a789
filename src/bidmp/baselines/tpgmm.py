"""Task-parameterised GMM (Calinon 2016, "A tutorial on task-parameterized movement learning and
retrieval"). No maintained Python 3 library under a permissive licence exists, so it is
written here.

Two frames ``(A_j, b_j)``: the start and the target. Each (augmented) demonstration is expressed
in every frame, ``x⁽ʲ⁾ = A_j⁻¹ (x − b_j)``, and one GMM is fitted by EM on the stacked
``[t, x⁽¹⁾, x⁽²⁾]``. For new frames, each component's per-frame Gaussian is mapped back
(``μ̂ = A μ + b``, ``Σ̂ = A Σ Aᵀ``, t unchanged). The frames' Gaussians are multiplied, and GMR
on t gives the trajectory.
"""

from __future__ import annotations

import numpy as np

from .._checks import (
    _as_bounded_array,
    as_point,
    check_bool,
    check_fitted,
    check_int,
    check_real,
    numerically_guarded,
)
from .gmm import _AugmentedMixture, _check_gmr_size, _fit_mixture, _gmr, augment

__all__ = ["TPGMM"]


def _rotation(value, n_dims: int, name: str) -> np.ndarray:
    """A frame orientation: an orthonormal (D, D) matrix."""
    matrix = _as_bounded_array(value, name, 2)
    if matrix.shape != (n_dims, n_dims) or not np.all(np.isfinite(matrix)):
        raise ValueError(
            f"{name} must be a finite ({n_dims}, {n_dims}) rotation matrix, got shape {matrix.shape}"
        )
    if not np.allclose(matrix @ matrix.T, np.eye(n_dims), atol=1e-6):
        raise ValueError(f"{name} must be orthonormal (R Rᵀ = I)")
    return matrix


class TPGMM(_AugmentedMixture):
    """TP-GMM with a start frame and a target frame (identity orientation by default).

    Parameters
    ----------
    n_components : int, default 16
    reg_covar : float, default 1e-4
        Regularisation of every covariance (and of each frame's Gaussian before the product). The
        stacked frame coordinates are collinear for copies that share their frames; 1e-3 (mm²)
        already biases the end point by 3–4 mm, 1e-4 does not.
    n_copies, noise, seed : augmentation of a single demonstration.

    Attributes
    ----------
    weights_, means_, covariances_ : the mixture on ``[t, x⁽start⁾, x⁽target⁾]``.
    n_steps_, n_dims_ : int
    start_, goal_ : array (D,)
        The demonstration's start and goal (what :meth:`rollout` goes between by default).
    """

    def __init__(
        self,
        n_components: int = 16,
        reg_covar: float = 1e-4,
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
    def fit(self, y) -> TPGMM:
        """Fit on one demonstration (T, D); frames at each copy's own start and end."""
        self._check_params()
        demos = augment(y, self.n_copies, self.noise, self.seed)
        n_steps, n_dims = demos.shape[1], demos.shape[2]
        t = np.linspace(0.0, 1.0, n_steps)[:, None]
        # Identity orientations: local coordinates are translations (A_j⁻¹ = I).
        data = np.concatenate([np.hstack([t, demo - demo[0], demo - demo[-1]]) for demo in demos])
        self.weights_, self.means_, self.covariances_ = _fit_mixture(
            data, self.n_components, self.reg_covar, self.seed
        )
        self.n_steps_, self.n_dims_ = n_steps, n_dims
        demonstration = np.asarray(y, dtype=np.float64)
        self.start_, self.goal_ = demonstration[0].copy(), demonstration[-1].copy()
        return self

    def _frame_gaussian(self, frame: int, A: np.ndarray, b: np.ndarray):
        """Every component's [t, x] Gaussian of one frame, mapped to the global frame."""
        d = self.n_dims_
        index = np.r_[0, 1 + frame * d : 1 + (frame + 1) * d]
        mu = self.means_[:, index]
        sigma = self.covariances_[:, index][:, :, index]
        transform = np.eye(d + 1)
        transform[1:, 1:] = A
        offset = np.r_[0.0, b]
        mu_global = mu @ transform.T + offset
        # checked where it is used: set_params may have changed it since fit
        reg_covar = check_real(self.reg_covar, "reg_covar", positive=True, maximum=1e6)
        sigma_global = transform @ sigma @ transform.T + reg_covar * np.eye(d + 1)
        return mu_global, sigma_global

    @numerically_guarded
    def rollout(
        self,
        goal=None,
        *,
        start=None,
        n_steps: int | None = None,
        start_rotation=None,
        target_rotation=None,
        return_covariance: bool = False,
    ):
        """The mean motion (n, D) from ``start`` to ``goal`` (the target frame's origin), on the
        demonstration's sample grid in normalised time (t ∈ [0, 1]); default the demonstration's
        own start and goal. ``return_covariance``: also the covariances (n, D, D)."""
        check_fitted(self, "weights_")
        d = self.n_dims_
        start = self.start_ if start is None else as_point(start, d, "start")
        target = self.goal_ if goal is None else as_point(goal, d, "goal")
        rotations = [
            np.eye(d) if r is None else _rotation(r, d, name)
            for r, name in (
                (start_rotation, "start_rotation"),
                (target_rotation, "target_rotation"),
            )
        ]
        n_steps = (
            self.n_steps_
            if n_steps is None
            else check_int(n_steps, "n_steps", minimum=2, limit="max_steps")
        )
        _check_gmr_size(n_steps, self.means_.shape)
        precision_sum = 0.0
        weighted_mean = 0.0
        for frame, (A, b) in enumerate(zip(rotations, (start, target))):
            mu, sigma = self._frame_gaussian(frame, A, b)
            precision = np.linalg.inv(sigma)
            precision_sum = precision_sum + precision
            weighted_mean = weighted_mean + np.einsum("kij,kj->ki", precision, mu)
        covariance = np.linalg.inv(precision_sum)  # product of Gaussians
        mean = np.einsum("kij,kj->ki", covariance, weighted_mean)
        mean, covariances = _gmr(self.weights_, mean, covariance, np.linspace(0.0, 1.0, n_steps))
        return (mean, covariances) if check_bool(return_covariance, "return_covariance") else mean
