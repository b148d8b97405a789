"""Broad Learning System with incremental enhancement nodes (SPEC §6, paper Eq. 16–26).

Hidden layer for inputs X (N × d), with ``X̃ = [X, 0.1]``:

* **Mapped features**, windows i = 1…u of q nodes: ``F_i = X̃ W_e,i`` (random, seeded) is
  min–max scaled, a sparse autoencoder ``β_i = argmin ½‖F_i β − X̃‖² + λ₁‖β‖₁`` (ADMM) gives
  ``W_Z,i = β_iᵀ``, and ``Z_i = X̃ W_Z,i`` is min–max normalised with stored constants.
* **Enhancement nodes**: ``H = tanh(s_H · [Z, 0.1] W_H)``: ``W_H`` is orthonormal (seeded),
  ``s_H = shrink / max|[Z, 0.1] W_H|`` is stored, and ``tansig(x) = 2/(1 + e^{−2x}) − 1`` is
  exactly ``tanh(x)``.
* **Output**: ``A = [Z | H]``, ``W = A⁺ Y`` with the ridge pseudo-inverse
  ``A⁺ = (AᵀA + λI)⁻¹Aᵀ`` (``reg = λ``; ``reg = 0`` gives the Moore–Penrose pseudo-inverse).
  The paper prints ``(λI + AAᵀ)⁻¹Aᵀ``, which has the wrong dimensions.

**Adding enhancement nodes E** without retraining (Eq. 23–26): ``D = A⁺E``, ``C = E − AD``,
``[A | E]⁺ = [A⁺ − D Bᵀ ; Bᵀ]`` and ``W_new = [W − D BᵀY ; BᵀY]``, with ``Bᵀ = C⁺`` when C has
full column rank and ``Bᵀ = (I + DᵀD)⁻¹DᵀA⁺`` when ``C = 0``. In between, the general Cline
(1964) block formula is exact in every case (:func:`block_pinv_update`). The widely circulated
BLS code gets two of these wrong: its zero test (``C.all() == 0``) is wrong, and its C = 0
branch has ``I − DᵀD``.

That formula is exact for the exact pseudo-inverse; a numerical one is truncated at a rank cut
(``PINV_RCOND`` of the largest singular value), and Cline's C then keeps the directions A's
truncation dropped. So ``BLS(reg=0)`` updates the *thin SVD* of the hidden matrix instead
(the SVD of ``[U S | E]``, ``N × (r + m)``), truncated at the same relative cut as
``numpy.linalg.pinv``. That equals a from-scratch pinv whenever the pseudo-inverse is well posed:
when the cut falls in a gap of the spectrum (the smallest kept singular value at least ``1e4``
times the largest dropped one; on a Bi-DMP learned from a bundled recording it then equals
``numpy.linalg.pinv`` to 1e-7). Where it is not — the nut task's Bi-DMP hidden matrix has
singular values decaying continuously through the cut, kept and dropped ones meeting at about
1e-10 of the largest, so that a 1e-15 relative change of the matrix moves NumPy's own weights by
more than 1e-8 and no update reproduces them — the update is refused with that reason; ``reg > 0``
is exact there (``update="exact_ridge"``). ``tests/test_bls.py`` measures both.
With ``update="exact_ridge"`` the model keeps the Cholesky factor of ``AᵀA + λI`` and grows it
by a block Cholesky step, so that the result equals a ridge fit from scratch with the same nodes.
(An explicit block inverse via the Schur complement loses all accuracy here, because the hidden
matrix is rank-deficient by construction; see ``PINV_RCOND``.)
"""

from __future__ import annotations

import logging
from typing import NamedTuple

import numpy as np
from scipy.linalg import cho_factor, cho_solve, cholesky, solve_triangular
from sklearn.base import BaseEstimator

from .._checks import (
    _as_bounded_array,
    _check_finite,
    _check_magnitude,
    as_trajectory,
    check_bytes,
    check_choice,
    check_fitted,
    check_int,
    check_limit,
    check_real,
    numerically_guarded,
)
from .._threads import one_thread, single_threaded

from .bls_state import bls_from_state, bls_state

MAX_ADMM_ITERATIONS = 10_000  # sparse_autoencoder's iterations at most (the BLS uses 50)
_THREADED_ROWS = 64  # predict() runs single-threaded from this many rows on

__all__ = ["BLS", "sparse_autoencoder", "block_pinv_update", "truncated_svd", "svd_update"]

logger = logging.getLogger(__name__)

_BIAS = 0.1  # the constant appended to inputs and to Z (paper Eq. 17-18)
_RANK_TOLERANCE = 1e-10  # block_pinv_update: singular values of C below this times ‖E‖₂ count as zero
# The truncated pseudo-inverse is well posed when its cut falls in a spectral gap this wide.
PINV_GAP = 1e4
# Mapped features are linear in [X, 0.1], so the hidden matrix is rank-deficient by construction
# (rank(Z) <= d + 2): its Moore–Penrose inverse needs a clean cut. Singular values below this
# fraction of the largest count as zero.
PINV_RCOND = 1e-10
_MAX_ADMM_ITERATIONS = 10_000


def _check_work(n_samples: int, n_hidden: int, n_inputs: int = 0) -> None:
    """Refuse a fit whose dense algebra (N·h² for the output solve) would run for minutes."""
    check_bytes(n_samples * max(n_hidden, n_inputs + 1), "the BLS hidden matrix (samples x hidden nodes)")
    check_limit(float(n_samples) * n_hidden * n_hidden, "max_work", "the BLS solve's work (samples x hidden nodes^2)")


def _with_bias(X: np.ndarray) -> np.ndarray:
    return np.hstack([X, np.full((X.shape[0], 1), _BIAS)])


def _affine(X: np.ndarray, weights: np.ndarray) -> np.ndarray:
    """``[X, 0.1] @ weights`` without building ``[X, 0.1]`` (a full copy of X)."""
    return X @ weights[:-1] + _BIAS * weights[-1]


def _orthonormal(rng: np.random.Generator, n_rows: int, n_cols: int) -> np.ndarray:
    """A seeded matrix with orthonormal columns (or rows, when it is wide)."""
    if n_cols <= n_rows:
        q, r = np.linalg.qr(rng.standard_normal((n_rows, n_cols)))
        return q * np.sign(np.diag(r))  # fix QR's sign ambiguity: reproducible across LAPACKs
    q, r = np.linalg.qr(rng.standard_normal((n_cols, n_rows)))
    return (q * np.sign(np.diag(r))).T


def sparse_autoencoder(F: np.ndarray, target: np.ndarray, l1: float = 1e-3, n_iter: int = 50, rho: float = 1.0) -> np.ndarray:
    """Lasso ``argmin_β ½‖F β − target‖² + l1 ‖β‖₁`` by ADMM (Boyd et al. 2011, §6.4).

    Parameters
    ----------
    F : array (N, q)
    target : array (N, m)

    Returns
    -------
    beta : array (q, m), the sparse iterate ``z``.
    """
    F = as_trajectory(F, "F", min_points=1, allow_static=True)
    target = as_trajectory(target, "target", min_points=1, allow_static=True)
    if target.shape[0] != F.shape[0]:
        raise ValueError(f"target must have {F.shape[0]} rows (one per row of F), got {target.shape[0]}")
    check_limit(F.shape[1], "max_hidden_nodes", "the columns of F")
    l1 = check_real(l1, "l1", nonnegative=True, maximum=1e12)
    n_iter = check_int(n_iter, "n_iter", minimum=1, maximum=MAX_ADMM_ITERATIONS)
    rho = check_real(rho, "rho", positive=True, minimum=1e-12, maximum=1e12)
    q = F.shape[1]
    factor = cho_factor(F.T @ F + rho * np.eye(q))
    rhs = F.T @ target
    z = np.zeros((q, target.shape[1]))
    u = np.zeros_like(z)
    threshold = l1 / rho
    for _ in range(n_iter):
        x = cho_solve(factor, rhs + rho * (z - u))
        v = x + u
        z = np.sign(v) * np.maximum(np.abs(v) - threshold, 0.0)  # soft thresholding
        u = v - z
    return z


def truncated_svd(A: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Thin SVD of A cut as ``numpy.linalg.pinv(A, rcond=PINV_RCOND)`` cuts it:
    ``(U (N, r), s (r,), V (c, r), dropped singular values)``."""
    u, s, vt = np.linalg.svd(A, full_matrices=False)
    keep = s > PINV_RCOND * (s[0] if s.size else 0.0)
    return np.ascontiguousarray(u[:, keep]), s[keep], np.ascontiguousarray(vt[keep].T), s[~keep]


def _check_gap(kept: np.ndarray, dropped: np.ndarray) -> None:
    """Refuse a pseudo-inverse whose rank cut does not fall in a spectral gap (see the module
    docstring): its weights then depend on rounding, and no update can reproduce them."""
    if kept.size == 0 or dropped.size == 0 or dropped[0] * PINV_GAP <= kept[-1]:
        return
    raise ValueError(
        f"add_enhancement_nodes: with reg = 0 the output weights are the pseudo-inverse's, and for this hidden matrix "
        f"it is ill-posed: its singular values decay through the rank cut ({PINV_RCOND:g} of the largest) without a gap "
        f"(kept down to {kept[-1] / kept[0]:.3g}, dropped from {dropped[0] / kept[0]:.3g} of the largest), so rounding "
        f"alone moves the weights and no update can match a from-scratch pinv; use reg > 0 (for which the update is "
        f"exact, update='exact_ridge'; Bi-DMP's default is 1e-4)"
    )


def svd_update(U: np.ndarray, s: np.ndarray, V: np.ndarray, E: np.ndarray):
    """The truncated thin SVD of ``[A | E]`` from that of ``A = U diag(s) Vᵀ`` (r kept values):
    the SVD of ``K = [U diag(s) | E]`` (N × (r + m)), whose right factor maps back through
    ``blockdiag(V, I)``. Returns ``(U', s', V', dropped)`` like :func:`truncated_svd`."""
    K = np.hstack([U * s, E])
    u, values, vt = np.linalg.svd(K, full_matrices=False)
    keep = values > PINV_RCOND * values[0]
    c, r, m = V.shape[0], V.shape[1], E.shape[1]
    right = np.zeros((c + m, r + m))
    right[:c, :r] = V
    right[c:, r:] = np.eye(m)
    return np.ascontiguousarray(u[:, keep]), values[keep], right @ vt[keep].T, values[~keep]


def _pinv_absolute(C: np.ndarray, tolerance: float) -> tuple[np.ndarray, int]:
    """Pseudo-inverse of C, treating singular values <= ``tolerance`` as zero; also its rank."""
    u, s, vt = np.linalg.svd(C, full_matrices=False)
    keep = s > tolerance
    rank = int(np.count_nonzero(keep))
    return (vt[keep].T / s[keep]) @ u[:, keep].T, rank


def block_pinv_update(A: np.ndarray, A_pinv: np.ndarray, E: np.ndarray) -> tuple[np.ndarray, np.ndarray, str]:
    """Pseudo-inverse of ``[A | E]`` from that of A (Eq. 23–26, Cline 1964).

    Parameters
    ----------
    A : array (N, c)
    A_pinv : array (c, N), the pseudo-inverse of A
    E : array (N, m), the new columns

    Returns
    -------
    (D, Bt, case) with ``[A | E]⁺ = [A⁺ − D Bt ; Bt]`` and case ``"zero"`` (C = 0),
    ``"full-rank"`` or ``"general"``.
    """
    D = A_pinv @ E
    C = E - A @ D
    tolerance = _RANK_TOLERANCE * max(np.linalg.norm(E, 2), np.finfo(float).tiny)
    C_pinv, rank = _pinv_absolute(C, tolerance)
    m = E.shape[1]
    if rank == 0:
        # C = 0: the new columns lie in span(A). Note the plus sign.
        Bt = np.linalg.solve(np.eye(m) + D.T @ D, D.T @ A_pinv)
        return D, Bt, "zero"
    if rank == m:
        return D, C_pinv, "full-rank"
    # General case: L = C⁺ + (I − C⁺C) K Dᵀ A⁺ (I − E C⁺)... written with D = A⁺E:
    # K = (I + (I − C⁺C) DᵀD (I − C⁺C))⁻¹, L = C⁺ + (I − C⁺C) K Dᵀ A⁺ (I − E C⁺).
    projector = np.eye(m) - C_pinv @ C
    K = np.linalg.inv(np.eye(m) + projector @ D.T @ D @ projector)
    Bt = C_pinv + projector @ K @ D.T @ A_pinv @ (np.eye(E.shape[0]) - E @ C_pinv)
    return D, Bt, "general"


class _BLSParams(NamedTuple):
    n_windows: int
    n_mapped: int
    n_enhance: int
    shrink: float
    reg: float
    l1: float
    admm_iterations: int
    update: str  # "auto" resolved to "pinv" or "exact_ridge"
    seed: int


def _rng(seed: int, kind: int, index: int) -> np.random.Generator:
    return np.random.default_rng([seed, kind, index])


def _mapped_features(X: np.ndarray, mapping_weights: np.ndarray, low: np.ndarray, span: np.ndarray) -> np.ndarray:
    """Min–max normalised mapped features Z of inputs X; every window in one matrix product."""
    weights = np.ascontiguousarray(mapping_weights.transpose(1, 0, 2).reshape(mapping_weights.shape[1], -1))  # (d+1, u·q)
    return (_affine(X, weights) - low) / span


def _enhancement_block(Z: np.ndarray, seed: int, block: int, n_nodes: int, shrink: float) -> tuple[np.ndarray, float, np.ndarray]:
    """Draw enhancement block number ``block``: (weights (c+1, n), scale s, H = tanh(s·[Z, 0.1]W))."""
    weights = np.ascontiguousarray(_orthonormal(_rng(seed, 1, block), Z.shape[1] + 1, n_nodes))
    pre_activation = _affine(Z, weights)
    scale = shrink / max(float(np.max(np.abs(pre_activation))), np.finfo(float).tiny)
    return weights, scale, np.tanh(scale * pre_activation)


class BLS(BaseEstimator):
    """Broad Learning System regressor with incremental enhancement nodes (SPEC §6).

    A scikit-learn style estimator: the constructor only stores its parameters; ``fit``
    validates them and learns; a failed ``fit`` leaves the model as it was.

    Parameters
    ----------
    n_windows : int, default 10
        Mapped-feature windows u.
    n_mapped : int, default 10
        Nodes per window q.
    n_enhance : int, default 100
        Enhancement nodes of the first block.
    shrink : float, default 0.8
        Target maximum of the enhancement pre-activation (s_H = shrink / max|·|).
    reg : float, default 1e-8
        Ridge λ of the output weights; 0 means the Moore–Penrose pseudo-inverse (truncated at
        ``PINV_RCOND``; adding nodes is refused where it is ill-posed, see the module docstring).
    l1 : float, default 1e-3
        Sparsity weight λ₁ of the autoencoder.
    admm_iterations : int, default 50
    update : {"auto", "pinv", "exact_ridge"}, default "auto"
        How :meth:`add_enhancement_nodes` updates: ``"pinv"`` is the pseudo-inverse of the grown
        hidden matrix (Eq. 23–26's result, computed by a thin-SVD update), for ``reg = 0``; ``"exact_ridge"`` is a block Cholesky step of the ridge
        Gram matrix, equal to a ridge fit from scratch for any ``reg > 0``. ``"auto"`` picks
        ``"pinv"`` for ``reg = 0`` and ``"exact_ridge"`` otherwise. Eq. 23–26 applied to a *ridge*
        A⁺ (the paper's combination) is not exact: on these rank-deficient hidden matrices its
        training residual can even rise as nodes are added, so it is not offered.
    seed : int, default 0
        Every random matrix is drawn from ``numpy.random.default_rng([seed, kind, index])``, so a
        model is reproducible from its seed, whatever order blocks are added in.

    Attributes
    ----------
    n_features_ : int
        Input dimension d seen in ``fit``.
    mapping_weights_ : array (u, d+1, q)
        ``W_Z,i``.
    mapping_min_, mapping_range_ : array (u·q,)
        Min–max constants of Z.
    enhancement_weights_ : list of arrays (u·q+1, m_k)
        One array per block (the first, then each addition).
    enhancement_scales_ : list of float
        Shrink factors ``s`` per block.
    output_weights_ : array (u·q + Σ m_k, n_outputs)
    """

    def __init__(
        self,
        n_windows: int = 10,
        n_mapped: int = 10,
        n_enhance: int = 100,
        shrink: float = 0.8,
        reg: float = 1e-8,
        l1: float = 1e-3,
        admm_iterations: int = 50,
        update: str = "auto",
        seed: int = 0,
    ) -> None:
        self.n_windows = n_windows
        self.n_mapped = n_mapped
        self.n_enhance = n_enhance
        self.shrink = shrink
        self.reg = reg
        self.l1 = l1
        self.admm_iterations = admm_iterations
        self.update = update
        self.seed = seed

    def _params(self) -> _BLSParams:
        """Validate the hyperparameters; raise naming the first bad one."""
        reg = check_real(self.reg, "reg", nonnegative=True)
        update = check_choice(self.update, "update", ("auto", "pinv", "exact_ridge"))
        if update == "pinv" and reg > 0:
            raise ValueError("update='pinv' (Eq. 23-26) is exact only with reg=0; use update='exact_ridge' for reg > 0")
        if update == "exact_ridge" and reg <= 0:
            raise ValueError("update='exact_ridge' needs reg > 0 (the hidden matrix is rank-deficient)")
        if update == "auto":
            update = "pinv" if reg == 0.0 else "exact_ridge"
        params = _BLSParams(
            n_windows=check_int(self.n_windows, "n_windows", minimum=1, limit="max_hidden_nodes"),
            n_mapped=check_int(self.n_mapped, "n_mapped", minimum=1, limit="max_hidden_nodes"),
            n_enhance=check_int(self.n_enhance, "n_enhance", minimum=1, limit="max_hidden_nodes"),
            shrink=check_real(self.shrink, "shrink", positive=True, maximum=1e6),
            reg=check_real(reg, "reg", maximum=1e6),
            l1=check_real(self.l1, "l1", nonnegative=True, maximum=1e6),
            admm_iterations=check_int(self.admm_iterations, "admm_iterations", minimum=1, maximum=_MAX_ADMM_ITERATIONS),
            update=update,
            seed=check_int(self.seed, "seed", minimum=0, maximum=2**63 - 1),
        )
        check_limit(params.n_windows * params.n_mapped + params.n_enhance, "max_hidden_nodes",
                    "the hidden nodes n_windows * n_mapped + n_enhance")
        return params

    def __sklearn_is_fitted__(self) -> bool:
        return "output_weights_" in self.__dict__

    # -- hidden layer ----------------------------------------------------------------------------
    def _mapped(self, X: np.ndarray) -> np.ndarray:
        return _mapped_features(X, self.mapping_weights_, self.mapping_min_, self.mapping_range_)

    def _enhancement(self, Z: np.ndarray, block: int) -> np.ndarray:
        return np.tanh(self.enhancement_scales_[block] * _affine(Z, self.enhancement_weights_[block]))

    def hidden(self, X) -> np.ndarray:
        """The hidden-layer matrix ``[Z | H | E_1 | …]`` for inputs X, shape (N, n_hidden)."""
        check_fitted(self, "output_weights_")
        X = self._check_X(X, self.n_features_)
        Z = self._mapped(X)
        return np.hstack([Z] + [self._enhancement(Z, block) for block in range(len(self.enhancement_weights_))])

    @property
    def n_hidden_(self) -> int:
        check_fitted(self, "output_weights_")
        return self.output_weights_.shape[0]

    @staticmethod
    def _check_X(X, expected: int | None = None) -> np.ndarray:
        X = _as_bounded_array(X, "X", 3)
        if X.ndim != 2:
            raise ValueError(f"X must have shape (N, d), got shape {X.shape}")
        if expected is not None and X.shape[1] != expected:
            raise ValueError(f"X must have {expected} columns (as in fit), got {X.shape[1]}")
        if X.shape[0] == 0 or X.shape[1] == 0:
            raise ValueError(f"X is empty (shape {X.shape})")
        check_limit(X.shape[0], "max_samples", "X: the number of samples N")
        check_limit(X.shape[1], "max_hidden_nodes", "X: the number of features d")
        _check_finite(X, "X")
        _check_magnitude(X, "X")
        return X

    @staticmethod
    def _check_Y(Y, n_rows: int) -> tuple[np.ndarray, bool]:
        Y = _as_bounded_array(Y, "Y", 3)
        was_1d = Y.ndim == 1
        Y = Y.reshape(-1, 1) if was_1d else Y
        if Y.ndim != 2 or Y.shape[0] != n_rows or Y.shape[1] == 0:
            raise ValueError(f"Y must have shape ({n_rows}, n_outputs), got shape {Y.shape}")
        check_limit(Y.shape[1], "max_hidden_nodes", "Y: the number of outputs")
        _check_finite(Y, "Y")
        _check_magnitude(Y, "Y")
        return Y, was_1d

    # -- learning --------------------------------------------------------------------------------
    @numerically_guarded
    @single_threaded
    def fit(self, X, Y) -> "BLS":
        """Fit mapped features, the first enhancement block and the output weights.

        Parameters
        ----------
        X : array (N, d)
        Y : array (N, n_outputs) or (N,)

        Returns
        -------
        self

        Everything is computed first and stored at the end, so a failed ``fit`` (bad parameters,
        bad data, a numerical failure) leaves a fitted model exactly as it was.
        """
        params = self._params()
        X = self._check_X(X)
        Y, y_was_1d = self._check_Y(Y, X.shape[0])
        _check_work(X.shape[0], params.n_windows * params.n_mapped + params.n_enhance, X.shape[1])
        X_bias = _with_bias(X)
        windows, mins, ranges = [], [], []
        for window in range(params.n_windows):
            F = X_bias @ _rng(params.seed, 0, window).uniform(-1.0, 1.0, size=(X_bias.shape[1], params.n_mapped))
            F_low, F_span = F.min(axis=0), np.ptp(F, axis=0)
            F = (F - F_low) / np.where(F_span > 0, F_span, 1.0)
            W_Z = np.ascontiguousarray(sparse_autoencoder(F, X_bias, params.l1, params.admm_iterations).T)  # (d+1, q)
            Z = X_bias @ W_Z
            low, span = Z.min(axis=0), np.ptp(Z, axis=0)
            windows.append(W_Z)
            mins.append(low)
            ranges.append(np.where(span > 0, span, 1.0))  # a constant node stays finite
        mapping_weights = np.stack(windows)
        mapping_min, mapping_range = np.concatenate(mins), np.concatenate(ranges)
        Z = _mapped_features(X, mapping_weights, mapping_min, mapping_range)
        weights, scale, H = _enhancement_block(Z, params.seed, 0, params.n_enhance, params.shrink)
        A = np.hstack([Z, H])
        solution = _solve_output(A, Y, params)
        # Nothing above touched the model: commit the new state in one go.
        self.n_features_ = X.shape[1]
        self._y_was_1d = y_was_1d
        self.mapping_weights_, self.mapping_min_, self.mapping_range_ = mapping_weights, mapping_min, mapping_range
        self.enhancement_weights_, self.enhancement_scales_ = [weights], [scale]
        self._set_train_hidden(A)
        self.train_targets_ = Y
        self._set_solution(*solution)
        return self

    @property
    def update_rule_(self) -> str:
        """The update in use: ``"pinv"`` or ``"exact_ridge"`` (``update="auto"`` resolved)."""
        return self._params().update

    @property
    def train_hidden_(self) -> np.ndarray:
        """Hidden matrix of the training inputs, (N, n_hidden): a view into a buffer with spare
        columns, so that adding nodes does not copy the whole matrix each time."""
        return self._hidden_buffer[:, : self._n_hidden]

    def _set_train_hidden(self, A: np.ndarray) -> None:
        self._hidden_buffer = np.array(A, order="C")
        self._n_hidden = A.shape[1]
        self._svd = None  # of another matrix

    def _append_train_hidden(self, E: np.ndarray) -> None:
        used, added = self._n_hidden, E.shape[1]
        if self._hidden_buffer.shape[1] < used + added:
            grown = np.empty((E.shape[0], max(2 * self._hidden_buffer.shape[1], used + added)))
            grown[:, :used] = self.train_hidden_
            self._hidden_buffer = grown
        self._hidden_buffer[:, used : used + added] = E
        self._n_hidden = used + added

    def _hidden_svd(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The truncated thin SVD of the training hidden matrix (``reg = 0``), checked for a gap
        at its cut; computed once (after ``fit`` or loading) and then updated block by block."""
        svd = self.__dict__.get("_svd")
        if svd is None or svd[2].shape[0] != self._n_hidden:
            U, values, V, dropped = truncated_svd(self.train_hidden_)
            _check_gap(values, dropped)
            svd = self._svd = (U, values, V)
        return svd

    def _set_solution(self, output_weights, hidden_pinv, gram_factor, projected_targets) -> None:
        self.output_weights_ = output_weights
        self.hidden_pinv_ = hidden_pinv
        self.gram_factor_ = gram_factor
        self._projected_targets = projected_targets

    @numerically_guarded
    @single_threaded
    def add_enhancement_nodes(self, n: int) -> "BLS":
        """Add a block of ``n`` enhancement nodes and update the output weights without
        retraining (Eq. 23–26, or the exact ridge block inverse). Returns self.

        As with ``fit``, the model is only changed once the update has succeeded.
        """
        check_fitted(self, "output_weights_")
        n = check_int(n, "n", minimum=1, limit="max_hidden_nodes")
        params = self._params()
        A, Y = self.train_hidden_, self.train_targets_
        check_limit(A.shape[1] + n, "max_hidden_nodes", "the hidden nodes after adding n")
        _check_work(A.shape[0], A.shape[1] + n)
        Z = A[:, : self.mapping_min_.shape[0]]
        block = len(self.enhancement_weights_)
        weights, scale, E = _enhancement_block(Z, params.seed, block, n, params.shrink)
        if params.update == "exact_ridge":
            # Block Cholesky: R_new = [[R, R12], [0, R22]] with R12 = R⁻ᵀAᵀE and
            # R22 = chol(EᵀE + λI − R12ᵀR12); then block forward/back substitution reuses
            # z = R⁻ᵀAᵀY and the old weights: O(N·c·m + c²·(m + D)), no refactorisation.
            # (Inputs are our own finite arrays: skip SciPy's O(c²) finiteness scans.)
            R = self.gram_factor_
            c = R.shape[0]
            R12 = solve_triangular(R, A.T @ E, trans="T", check_finite=False)
            try:
                R22 = cholesky(E.T @ E + params.reg * np.eye(n) - R12.T @ R12, lower=False, check_finite=False)
            except np.linalg.LinAlgError:
                raise ValueError(f"add_enhancement_nodes: the ridge Gram matrix lost positive definiteness in "
                                 f"float64 (reg = {params.reg:g} is too small for these nodes); use a larger reg") from None
            z_new = solve_triangular(R22, E.T @ Y - R12.T @ self._projected_targets, trans="T", check_finite=False)
            W_new = solve_triangular(R22, z_new, check_finite=False)
            W_old = self.output_weights_ - solve_triangular(R, R12 @ W_new, check_finite=False)
            grown = np.zeros((c + n, c + n), order="F")
            grown[:c, :c], grown[:c, c:], grown[c:, c:] = R, R12, R22
            solution = (np.ascontiguousarray(np.vstack([W_old, W_new])), None, grown,
                        np.vstack([self._projected_targets, z_new]))
        else:
            U, values, V, dropped = svd_update(*self._hidden_svd(), E)
            _check_gap(values, dropped)
            pinv = np.ascontiguousarray((V / values) @ U.T)
            solution = (pinv @ Y, pinv, None, None)
            self._svd = (U, values, V)
        self.enhancement_weights_.append(weights)
        self.enhancement_scales_.append(scale)
        self._append_train_hidden(E)
        self._set_solution(*solution)
        return self

    @numerically_guarded
    def predict(self, X) -> np.ndarray:
        """Outputs for inputs X: ``hidden(X) @ output_weights_``, shape (N, n_outputs)."""
        check_fitted(self, "output_weights_")
        check_bytes(np.shape(X)[0] * self.n_hidden_ if np.ndim(X) == 2 else 0, "the hidden matrix of X (N x hidden nodes)")
        if np.shape(X)[0] >= _THREADED_ROWS:
            with one_thread():  # as fit: small products, and idle pools would contend (bidmp._threads)
                out = self.hidden(X) @ self.output_weights_
        else:  # a control loop's one row: limiting the pools would cost more than the product
            out = self.hidden(X) @ self.output_weights_
        return out[:, 0] if self._y_was_1d else out

    def _get_state(self) -> tuple[dict, dict]:
        return bls_state(self)

    @classmethod
    def _from_state(cls, meta: dict, arrays) -> "BLS":
        return bls_from_state(cls, meta, arrays)


def _solve_output(A: np.ndarray, Y: np.ndarray, params: _BLSParams) -> tuple:
    """Output weights for hidden matrix A and targets Y: (W, A⁺ or None, R or None, z or None)."""
    if params.update == "exact_ridge":
        # Upper Cholesky factor R of the ridge Gram matrix: AᵀA + λI = RᵀR, kept in Fortran
        # order (LAPACK's) so that triangular solves never copy it. z = R⁻ᵀAᵀY, W = R⁻¹z.
        try:
            R = np.asfortranarray(cholesky(A.T @ A + params.reg * np.eye(A.shape[1]), lower=False))
        except np.linalg.LinAlgError:
            raise ValueError(f"fit: the ridge Gram matrix is not positive definite in float64 (reg = {params.reg:g} is "
                             f"too small for this hidden layer); use a larger reg") from None
        projected = solve_triangular(R, A.T @ Y, trans="T")
        return np.ascontiguousarray(solve_triangular(R, projected)), None, R, projected
    U, values, V, _ = truncated_svd(A)
    pinv = np.ascontiguousarray((V / values) @ U.T)  # numpy.linalg.pinv(A, rcond=PINV_RCOND)
    return pinv @ Y, pinv, None, None
