"""The linear algebra of the Broad Learning System (:mod:`bidmp.incremental.bls`): the sparse
autoencoder of the mapped features, and the output weights solved and grown exactly.

Cline's block formula (Eq. 23–26, :func:`block_pinv_update`) is exact for the exact
pseudo-inverse; a numerical one is truncated at a rank cut
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
is exact there (``update="exact_ridge"``). ``tests/incremental/test_bls.py`` measures both.
With ``update="exact_ridge"`` the model keeps the Cholesky factor of ``AᵀA + λI`` and grows it
by a block Cholesky step, so that the result equals a ridge fit from scratch with the same nodes.
(An explicit block inverse via the Schur complement loses all accuracy here, because the hidden
matrix is rank-deficient by construction; see ``PINV_RCOND``.)

Eq. 23–26 applied to a *ridge* A⁺ (the paper's combination) is not exact: on these
rank-deficient hidden matrices its training residual can even rise as nodes are added, so the BLS
does not offer it.
"""

from __future__ import annotations

import numpy as np
from scipy.linalg import cho_factor, cholesky, get_lapack_funcs, solve_triangular

from .._checks import as_trajectory, as_vector, check_int, check_limit, check_real

__all__ = [
    "sparse_autoencoder",
    "block_pinv_update",
    "truncated_svd",
    "svd_update",
    "PINV_RCOND",
    "PINV_GAP",
    "MAX_ADMM_ITERATIONS",
]

MAX_ADMM_ITERATIONS = 10_000  # sparse_autoencoder's iterations at most (the BLS uses 50)
# block_pinv_update: singular values of C below this times ‖E‖₂ count as zero
_RANK_TOLERANCE = 1e-10
# The truncated pseudo-inverse is well posed when its cut falls in a spectral gap this wide.
PINV_GAP = 1e4
# Mapped features are linear in [X, 0.1], so the hidden matrix is rank-deficient by construction
# (rank(Z) <= d + 2): its Moore–Penrose inverse needs a clean cut. Singular values below this
# fraction of the largest count as zero.
PINV_RCOND = 1e-10


def sparse_autoencoder(
    F: np.ndarray, target: np.ndarray, l1: float = 1e-3, n_iter: int = 50, rho: float = 1.0
) -> np.ndarray:
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
        raise ValueError(
            f"target must have {F.shape[0]} rows (one per row of F), got {target.shape[0]}"
        )
    check_limit(F.shape[1], "max_hidden_nodes", "the columns of F")
    l1 = check_real(l1, "l1", nonnegative=True, maximum=1e12)
    n_iter = check_int(n_iter, "n_iter", minimum=1, maximum=MAX_ADMM_ITERATIONS)
    rho = check_real(rho, "rho", positive=True, minimum=1e-12, maximum=1e12)
    q = F.shape[1]
    factor, lower = cho_factor(F.T @ F + rho * np.eye(q))
    # LAPACK's potrs, which cho_solve calls: the same solve without its per-call checks and
    # wrappers, which were most of the loop's time on the BLS's small systems.
    (potrs,) = get_lapack_funcs(("potrs",), (factor,))
    rhs = F.T @ target
    z = np.zeros((q, target.shape[1]))
    u = np.zeros_like(z)
    threshold = l1 / rho
    for _ in range(n_iter):
        x, info = potrs(factor, rhs + rho * (z - u), lower=lower)
        if info != 0:  # pragma: no cover - a factor cho_factor accepted solves
            raise np.linalg.LinAlgError(f"sparse_autoencoder: LAPACK potrs failed (info {info})")
        v = x + u
        z = np.sign(v) * np.maximum(np.abs(v) - threshold, 0.0)  # soft thresholding
        u = v - z
    return z


def _matrix(value, name: str, rows: int | None = None, like: str = "") -> np.ndarray:
    """A finite 2-D array (with ``rows`` rows when given, as ``like`` says): the public algebra's arguments."""
    matrix = as_trajectory(value, name, min_points=1, allow_static=True)
    if rows is not None and matrix.shape[0] != rows:
        raise ValueError(f"{name} must have {rows} rows ({like}), got {matrix.shape[0]}")
    return matrix


def truncated_svd(A: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Thin SVD of A cut as ``numpy.linalg.pinv(A, rcond=PINV_RCOND)`` cuts it:
    ``(U (N, r), s (r,), V (c, r), dropped singular values)``."""
    return _truncated_svd(_matrix(A, "A"))


def _truncated_svd(A: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
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
        f"it is ill-posed: its singular values decay through the rank cut ({PINV_RCOND:g} of "
        f"the largest) without a gap "
        f"(kept down to {kept[-1] / kept[0]:.3g}, dropped from {dropped[0] / kept[0]:.3g} of the largest), so rounding "
        f"alone moves the weights and no update can match a from-scratch pinv; use reg > 0 (for which the update is "
        f"exact, update='exact_ridge'; Bi-DMP's default is 1e-4)"
    )


def svd_update(U: np.ndarray, s: np.ndarray, V: np.ndarray, E: np.ndarray):
    """The truncated thin SVD of ``[A | E]`` from that of ``A = U diag(s) Vᵀ`` (r kept values):
    the SVD of ``K = [U diag(s) | E]`` (N × (r + m)), whose right factor maps back through
    ``blockdiag(V, I)``. Returns ``(U', s', V', dropped)`` like :func:`truncated_svd`."""
    U = _matrix(U, "U")
    s = as_vector(s, "s")
    V, E = _matrix(V, "V"), _matrix(E, "E", rows=U.shape[0], like="as U has")
    if s.shape[0] != U.shape[1] or V.shape[1] != U.shape[1]:
        raise ValueError(f"s and V must have one entry / column per column of U ({U.shape[1]})")
    return _svd_update(U, s, V, E)


def _svd_update(U: np.ndarray, s: np.ndarray, V: np.ndarray, E: np.ndarray):
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


def block_pinv_update(
    A: np.ndarray, A_pinv: np.ndarray, E: np.ndarray
) -> tuple[np.ndarray, np.ndarray, str]:
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
    A = _matrix(A, "A")
    A_pinv = _matrix(A_pinv, "A_pinv", rows=A.shape[1], like="A's columns")
    E = _matrix(E, "E", rows=A.shape[0], like="as A has")
    if A_pinv.shape[1] != A.shape[0]:
        raise ValueError(
            f"A_pinv must be the pseudo-inverse of A: shape ({A.shape[1]}, {A.shape[0]}), got {A_pinv.shape}"
        )
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


def _solve_output(A: np.ndarray, Y: np.ndarray, update: str, reg: float) -> tuple:
    """Output weights for hidden matrix A and targets Y: (W, A⁺ or None, R or None, z or None)."""
    if update == "exact_ridge":
        # Upper Cholesky factor R of the ridge Gram matrix: AᵀA + λI = RᵀR, kept in Fortran
        # order (LAPACK's) so that triangular solves never copy it. z = R⁻ᵀAᵀY, W = R⁻¹z.
        try:
            R = np.asfortranarray(cholesky(A.T @ A + reg * np.eye(A.shape[1]), lower=False))
        except np.linalg.LinAlgError:
            raise ValueError(
                f"fit: the ridge Gram matrix is not positive definite in float64 (reg = {reg:g} is "
                f"too small for this hidden layer); use a larger reg"
            ) from None
        projected = solve_triangular(R, A.T @ Y, trans="T")
        return np.ascontiguousarray(solve_triangular(R, projected)), None, R, projected
    U, values, V, _ = _truncated_svd(A)
    pinv = np.ascontiguousarray((V / values) @ U.T)  # numpy.linalg.pinv(A, rcond=PINV_RCOND)
    return pinv @ Y, pinv, None, None


def _grow_ridge(
    R: np.ndarray,
    A: np.ndarray,
    E: np.ndarray,
    Y: np.ndarray,
    W: np.ndarray,
    projected: np.ndarray,
    reg: float,
) -> tuple:
    """The ridge solution for ``[A | E]`` from that for A (c columns, m new), in the layout of
    :func:`_solve_output`: ``(W', None, R', z')``.

    Block Cholesky: ``R' = [[R, R12], [0, R22]]`` with ``R12 = R⁻ᵀAᵀE`` and
    ``R22 = chol(EᵀE + λI − R12ᵀR12)``; block forward and back substitution reuse
    ``z = R⁻ᵀAᵀY`` (``projected``) and the old weights W: O(N·c·m + c²·(m + D)), no
    refactorisation. Equal to :func:`_solve_output` on ``[A | E]`` from scratch.
    """
    # Inputs are the model's own finite arrays: skip SciPy's O(c²) finiteness scans.
    c, m = R.shape[0], E.shape[1]
    R12 = solve_triangular(R, A.T @ E, trans="T", check_finite=False)
    try:
        R22 = cholesky(E.T @ E + reg * np.eye(m) - R12.T @ R12, lower=False, check_finite=False)
    except np.linalg.LinAlgError:
        raise ValueError(
            f"add_enhancement_nodes: the ridge Gram matrix lost positive definiteness in "
            f"float64 (reg = {reg:g} is too small for these nodes); use a larger reg"
        ) from None
    z_new = solve_triangular(R22, E.T @ Y - R12.T @ projected, trans="T", check_finite=False)
    W_new = solve_triangular(R22, z_new, check_finite=False)
    W_old = W - solve_triangular(R, R12 @ W_new, check_finite=False)
    grown = np.zeros((c + m, c + m), order="F")
    grown[:c, :c], grown[:c, c:], grown[c:, c:] = R, R12, R22
    return (
        np.ascontiguousarray(np.vstack([W_old, W_new])),
        None,
        grown,
        np.vstack([projected, z_new]),
    )


def _grow_pinv(
    svd: tuple[np.ndarray, np.ndarray, np.ndarray], E: np.ndarray, Y: np.ndarray
) -> tuple[tuple, tuple]:
    """The pseudo-inverse solution for ``[A | E]`` from the truncated SVD ``(U, s, V)`` of A:
    (the solution in the layout of :func:`_solve_output`, the grown SVD). Refused where the
    grown pseudo-inverse is ill-posed (:func:`_check_gap`)."""
    U, values, V, dropped = _svd_update(*svd, E)
    _check_gap(values, dropped)
    pinv = np.ascontiguousarray((V / values) @ U.T)
    return (pinv @ Y, pinv, None, None), (U, values, V)
