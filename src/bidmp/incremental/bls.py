"""Broad Learning System with incremental enhancement nodes (paper Eq. 16–26).

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

How the output weights are solved and grown, exactly: :mod:`bidmp.incremental.linalg`.
"""

from __future__ import annotations

import collections
import hashlib
import logging
import threading
from typing import NamedTuple

import numpy as np
from scipy.linalg import solve_triangular

from .._api import Estimator
from .._checks import (
    _as_bounded_array,
    _check_finite,
    _check_magnitude,
    check_bytes,
    check_choice,
    check_fitted,
    check_int,
    check_limit,
    check_real,
    numerically_guarded,
)
from .._state import state_reader
from .._threads import one_thread, single_threaded
from .bls_state import _bls_members, _bls_params, _bls_state
from .linalg import (
    MAX_ADMM_ITERATIONS,
    _check_gap,
    _grow_pinv,
    _grow_ridge,
    _solve_output,
    _truncated_svd,
    sparse_autoencoder,
)

_THREADED_ROWS = 64  # predict() runs single-threaded from this many rows on

__all__ = ["BLS"]

logger = logging.getLogger(__name__)

_BIAS = 0.1  # the constant appended to inputs and to Z (paper Eq. 17-18)


def _check_work(n_samples: int, n_hidden: int, n_inputs: int = 0) -> None:
    """Refuse a fit whose dense algebra (N·h² for the output solve) would run for minutes."""
    check_bytes(
        n_samples * max(n_hidden, n_inputs + 1), "the BLS hidden matrix (samples x hidden nodes)"
    )
    check_limit(
        float(n_samples) * n_hidden * n_hidden,
        "max_work",
        "the BLS solve's work (samples x hidden nodes^2)",
    )


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


def _mapped_features(
    X: np.ndarray, mapping_weights: np.ndarray, low: np.ndarray, span: np.ndarray
) -> np.ndarray:
    """Min–max normalised mapped features Z of inputs X; every window in one matrix product."""
    # (d+1, u·q)
    weights = np.ascontiguousarray(
        mapping_weights.transpose(1, 0, 2).reshape(mapping_weights.shape[1], -1)
    )
    return (_affine(X, weights) - low) / span


def _draw_mapping(X: np.ndarray, params: _BLSParams):
    """The mapped features' weights (u, d+1, q), minima and ranges (u·q,) for inputs X: per
    window, seeded random features of ``[X, 0.1]``, min-max scaled, and the sparse
    autoencoder's weights that map ``[X, 0.1]`` onto them."""
    X_bias = _with_bias(X)
    windows, mins, ranges = [], [], []
    for window in range(params.n_windows):
        F = X_bias @ _rng(params.seed, 0, window).uniform(
            -1.0, 1.0, size=(X_bias.shape[1], params.n_mapped)
        )
        F_low, F_span = F.min(axis=0), np.ptp(F, axis=0)
        F = (F - F_low) / np.where(F_span > 0, F_span, 1.0)
        # (d+1, q)
        W_Z = np.ascontiguousarray(
            sparse_autoencoder(F, X_bias, params.l1, params.admm_iterations).T
        )
        Z = X_bias @ W_Z
        low, span = Z.min(axis=0), np.ptp(Z, axis=0)
        windows.append(W_Z)
        mins.append(low)
        ranges.append(np.where(span > 0, span, 1.0))  # a constant node stays finite
    return np.stack(windows), np.concatenate(mins), np.concatenate(ranges)


# The last few mappings drawn, by inputs and parameters. The mapping depends on nothing else, and
# a Bi-DMP's blocks all take the same inputs (its training grid): the repairs that each learn one
# skill on a copy of the same model draw the same block again and again, and the sparse
# autoencoder's iterations were most of each learn. A hit is the stored result itself, bit for
# bit (the inputs are compared in full, not only by their hash).
_MAPPINGS: collections.OrderedDict = collections.OrderedDict()
_MAPPINGS_KEPT = 8
_MAPPINGS_LOCK = threading.Lock()


def _mapping(X: np.ndarray, params: _BLSParams):
    """:func:`_draw_mapping`, remembered for the last :data:`_MAPPINGS_KEPT` inputs and parameters
    (copies returned: a model owns its arrays)."""
    key = (
        X.shape,
        hashlib.blake2b(np.ascontiguousarray(X).view(np.uint8), digest_size=16).digest(),
        params.seed,
        params.n_windows,
        params.n_mapped,
        params.l1,
        params.admm_iterations,
    )
    with _MAPPINGS_LOCK:
        kept = _MAPPINGS.get(key)
        if kept is not None and np.array_equal(kept[0], X):
            _MAPPINGS.move_to_end(key)
            return tuple(part.copy() for part in kept[1])
    mapping = _draw_mapping(X, params)
    with _MAPPINGS_LOCK:
        _MAPPINGS[key] = (X.copy(), tuple(part.copy() for part in mapping))
        while len(_MAPPINGS) > _MAPPINGS_KEPT:
            _MAPPINGS.popitem(last=False)
    return mapping


def _enhancement_block(
    Z: np.ndarray, seed: int, block: int, n_nodes: int, shrink: float
) -> tuple[np.ndarray, float, np.ndarray]:
    """Draw enhancement block number ``block``: (weights (c+1, n), scale s, H = tanh(s·[Z, 0.1]W))."""
    weights = np.ascontiguousarray(_orthonormal(_rng(seed, 1, block), Z.shape[1] + 1, n_nodes))
    pre_activation = _affine(Z, weights)
    scale = shrink / max(float(np.max(np.abs(pre_activation))), np.finfo(float).tiny)
    return weights, scale, np.tanh(scale * pre_activation)


def _check_inputs(X, expected: int | None = None) -> np.ndarray:
    """Inputs X (N, d) as float64, finite and bounded (``expected`` columns if given)."""
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


def _check_targets(Y, n_rows: int) -> tuple[np.ndarray, bool]:
    """Targets Y (n_rows, n_outputs) or (n_rows,) as float64 2-D, and whether they were 1-D."""
    Y = _as_bounded_array(Y, "Y", 3)
    was_1d = Y.ndim == 1
    Y = Y.reshape(-1, 1) if was_1d else Y
    if Y.ndim != 2 or Y.shape[0] != n_rows or Y.shape[1] == 0:
        raise ValueError(f"Y must have shape ({n_rows}, n_outputs), got shape {Y.shape}")
    check_limit(Y.shape[1], "max_hidden_nodes", "Y: the number of outputs")
    _check_finite(Y, "Y")
    _check_magnitude(Y, "Y")
    return Y, was_1d


class BLS(Estimator):
    """Broad Learning System regressor with incremental enhancement nodes.

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
        How :meth:`add_enhancement_nodes` updates (:mod:`bidmp.incremental.linalg`): ``"pinv"``, the
        grown pseudo-inverse by a thin-SVD update (``reg = 0``); ``"exact_ridge"``, a block Cholesky
        step equal to a ridge fit from scratch (``reg > 0``); ``"auto"`` picks by ``reg``.
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

    def __init__(  # noqa: PLR0913 - an estimator's constructor: each hyperparameter is one (scikit-learn)
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
            raise ValueError(
                "update='pinv' (Eq. 23-26) is exact only with reg=0; use update='exact_ridge' for reg > 0"
            )
        if update == "exact_ridge" and reg <= 0:
            raise ValueError(
                "update='exact_ridge' needs reg > 0 (the hidden matrix is rank-deficient)"
            )
        if update == "auto":
            update = "pinv" if reg == 0.0 else "exact_ridge"
        params = _BLSParams(
            n_windows=check_int(self.n_windows, "n_windows", minimum=1, limit="max_hidden_nodes"),
            n_mapped=check_int(self.n_mapped, "n_mapped", minimum=1, limit="max_hidden_nodes"),
            n_enhance=check_int(self.n_enhance, "n_enhance", minimum=1, limit="max_hidden_nodes"),
            shrink=check_real(self.shrink, "shrink", positive=True, maximum=1e6),
            reg=check_real(reg, "reg", maximum=1e6),
            l1=check_real(self.l1, "l1", nonnegative=True, maximum=1e6),
            admm_iterations=check_int(
                self.admm_iterations, "admm_iterations", minimum=1, maximum=MAX_ADMM_ITERATIONS
            ),
            update=update,
            seed=check_int(self.seed, "seed", minimum=0, maximum=2**63 - 1),
        )
        check_limit(
            params.n_windows * params.n_mapped + params.n_enhance,
            "max_hidden_nodes",
            "the hidden nodes n_windows * n_mapped + n_enhance",
        )
        return params

    def __sklearn_is_fitted__(self) -> bool:
        return "output_weights_" in self.__dict__

    # -- hidden layer ----------------------------------------------------------------------------
    def _mapped(self, X: np.ndarray) -> np.ndarray:
        return _mapped_features(X, self.mapping_weights_, self.mapping_min_, self.mapping_range_)

    def _enhancement(self, Z: np.ndarray, block: int) -> np.ndarray:
        return np.tanh(
            self.enhancement_scales_[block] * _affine(Z, self.enhancement_weights_[block])
        )

    def hidden(self, X) -> np.ndarray:
        """The hidden-layer matrix ``[Z | H | E_1 | …]`` for inputs X, shape (N, n_hidden)."""
        check_fitted(self, "output_weights_")
        X = _check_inputs(X, self.n_features_)
        Z = self._mapped(X)
        return np.hstack(
            [Z] + [self._enhancement(Z, block) for block in range(len(self.enhancement_weights_))]
        )

    @property
    def n_hidden_(self) -> int:
        check_fitted(self, "output_weights_")
        return self.output_weights_.shape[0]

    # -- learning --------------------------------------------------------------------------------
    @numerically_guarded
    @single_threaded
    def fit(self, X, Y) -> BLS:
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
        X = _check_inputs(X)
        Y, y_was_1d = _check_targets(Y, X.shape[0])
        _check_work(X.shape[0], params.n_windows * params.n_mapped + params.n_enhance, X.shape[1])
        mapping_weights, mapping_min, mapping_range = _mapping(X, params)
        Z = _mapped_features(X, mapping_weights, mapping_min, mapping_range)
        weights, scale, H = _enhancement_block(Z, params.seed, 0, params.n_enhance, params.shrink)
        A = np.hstack([Z, H])
        solution = _solve_output(A, Y, params.update, params.reg)
        # Nothing above touched the model: commit the new state in one go.
        self.n_features_ = X.shape[1]
        self._y_was_1d = y_was_1d
        self.mapping_weights_, self.mapping_min_, self.mapping_range_ = (
            mapping_weights,
            mapping_min,
            mapping_range,
        )
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
            U, values, V, dropped = _truncated_svd(self.train_hidden_)
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
    def add_enhancement_nodes(self, n: int) -> BLS:
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
            solution = _grow_ridge(
                self.gram_factor_,
                A,
                E,
                Y,
                self.output_weights_,
                self._projected_targets,
                params.reg,
            )
        else:
            solution, self._svd = _grow_pinv(self._hidden_svd(), E, Y)
        self.enhancement_weights_.append(weights)
        self.enhancement_scales_.append(scale)
        self._append_train_hidden(E)
        self._set_solution(*solution)
        return self

    @numerically_guarded
    def predict(self, X) -> np.ndarray:
        """Outputs for inputs X: ``hidden(X) @ output_weights_``, shape (N, n_outputs)."""
        check_fitted(self, "output_weights_")
        X = _check_inputs(X, self.n_features_)
        check_bytes(X.shape[0] * self.n_hidden_, "the hidden matrix of X (N x hidden nodes)")
        if np.shape(X)[0] >= _THREADED_ROWS:
            # as fit: small products, and idle pools would contend (bidmp._threads)
            with one_thread():
                out = self.hidden(X) @ self.output_weights_
        else:  # a control loop's one row: limiting the pools would cost more than the product
            out = self.hidden(X) @ self.output_weights_
        return out[:, 0] if self._y_was_1d else out

    def check_fitted(self) -> None:
        """Raise :class:`bidmp.NotFittedError`, saying what to do, unless the model is fitted."""
        check_fitted(self, "output_weights_")

    def to_state(self) -> tuple[dict, dict]:
        """The model-file form of the fitted model, ``(meta, arrays)``: its parameters and scalars
        as a JSON-able dict, its learned arrays by name (:func:`bidmp.io.save_model` writes the two
        into one ``.npz``; no pickle). Raises :class:`bidmp.NotFittedError` before ``fit``."""
        return _bls_state(self, self._y_was_1d)

    @classmethod
    @state_reader
    def from_state(cls, meta: dict, arrays) -> BLS:
        """The fitted model :meth:`to_state` described: ``meta`` as written, ``arrays`` a mapping of
        name to array, each read when needed and checked for dtype, shape and finiteness
        (:func:`bidmp.io.load_model` calls it; a bad file raises, naming the member)."""
        model = cls(**_bls_params(meta))
        members = _bls_members(meta, arrays, model._params())
        model._y_was_1d = members.pop("y_was_1d")
        model._set_train_hidden(members.pop("train_hidden"))
        for name, value in members.items():
            setattr(model, name, value)
        # the ridge update's projected targets, as fit leaves them (pinv: none)
        model._projected_targets = (
            None
            if model.gram_factor_ is None
            else solve_triangular(
                model.gram_factor_, model.train_hidden_.T @ model.train_targets_, trans="T"
            )
        )
        return model
