"""The forcing term: Gaussian kernels on the phase, their weights, and the forcing target that
makes the transformation system reproduce a demonstration::

    f(phase) = phase · Σ_i w_i ψ_i(phase) / Σ_i ψ_i(phase),  ψ_i = exp(-h_i (phase - c_i)²)

Pure functions, vectorised over samples and dimensions; layer 1, imports only the canonical system.
"""

from __future__ import annotations

import numpy as np

from .._checks import (
    _as_bounded_array,
    as_points,
    as_vector,
    check_choice,
    check_int,
    check_real,
)
from .canonical import _checked_phase_args, _phase_decay, phase_grid

__all__ = ["kernel_centres", "kernel_widths", "basis_functions"]

_LOG_PSI_FLOOR = -40.0  # kernel terms below e^-40 of a row's largest cannot change a float64 sum


def kernel_centres(
    n_kernels: int,
    n_steps: int,
    dt: float,
    tau: float = 1.0,
    alpha_phase: float = 1.0,
    *,
    exact: bool = False,
) -> np.ndarray:
    """Kernel centres at the phase of ``n_kernels`` equally spaced times over the horizon.

    They span exactly the visited phase range ``[phase[n_steps - 1], 1]``: a centre outside it
    belongs to a kernel that never fires, and its LWR weight blows up. ``exact`` as in
    :func:`phase_grid`.
    """
    n_kernels = check_int(n_kernels, "n_kernels", minimum=1, limit="max_kernels")
    n_steps = check_int(n_steps, "n_steps", minimum=1, limit="max_steps")
    dt, tau, alpha_phase, exact = _checked_phase_args(dt, tau, alpha_phase, exact)
    steps = np.linspace(0.0, n_steps - 1, n_kernels)
    if exact:
        return np.exp(-alpha_phase * dt / tau * steps)
    return np.exp(np.log(_phase_decay(dt, tau, alpha_phase)) * steps)


def kernel_widths(
    centres: np.ndarray, alpha_phase: float = 1.0, method: str = "spacing"
) -> np.ndarray:
    """Kernel widths ``h_i`` of ``ψ_i = exp(-h_i (phase - c_i)²)``.

    ``"spacing"`` (default): ``h_i = 1 / (c_{i+1} - c_i)²``, so neighbouring kernels overlap at
    ``e⁻¹``; LWR then reproduces LASA shapes to < 1 % of their extent.
    ``"pydmps"``: ``h_i = N^1.5 / (c_i alpha_phase)`` (as the paper prints it, the pydmps convention);
    neighbours overlap at ≈ 0.9 and LWR smooths the forcing term noticeably (2–5 % on LASA).
    """
    centres = as_vector(centres, "centres", positive=True)
    alpha_phase = check_real(alpha_phase, "alpha_phase", positive=True)
    check_choice(method, "method", ("spacing", "pydmps"))
    n_kernels = len(centres)
    if n_kernels > 1 and np.any(np.diff(np.sort(centres)) == 0.0):
        raise ValueError(
            "centres must be distinct (two kernels at one phase have no spacing to size them by)"
        )
    if method == "pydmps":
        return n_kernels**1.5 / (centres * alpha_phase)
    if n_kernels == 1:
        return np.ones(1)  # a single normalised kernel is constant whatever its width
    spacing = np.abs(np.diff(centres))
    spacing = np.append(spacing, spacing[-1])
    return 1.0 / spacing**2


def basis_functions(phase: np.ndarray, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
    """The DMP basis rows ``phi(phase) = phase · ψ(phase) / Σ ψ(phase)``.

    Parameters
    ----------
    phase : array, shape (L,)
    centres, widths : array, shape (N,)

    Returns
    -------
    phi : array, shape (L, N)
        Each row sums to its phase. The normalisation is a softmax of ``-h (phase - c)²``,
        computed after subtracting the row maximum, so it never underflows to 0/0 however far
        the phase is from the centres.
    """
    phase = as_vector(phase, "phase")
    centres = as_vector(centres, "centres", positive=True)
    widths = as_vector(widths, "widths", positive=True)
    if widths.shape != centres.shape:
        raise ValueError(
            f"widths must have one entry per entry of centres ({centres.shape[0]}), got {widths.shape[0]}"
        )
    return _basis_rows(phase, centres, widths)


def _basis_rows(phase: np.ndarray, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
    """:func:`basis_functions` for a DMP's own (valid) centres and widths and validated phases."""
    phase = np.asarray(phase, dtype=np.float64).reshape(-1)
    n_kernels = centres.shape[0]
    # Reference exponent per row: the larger of the two kernels bracketing the phase. It is one
    # of the row's entries, so shifting by it cannot overflow and the largest term survives; it
    # replaces an exact row maximum, which costs more than the exp here.
    order = np.argsort(centres)
    position = np.searchsorted(centres[order], phase)
    shift = np.full(phase.shape[0], -np.inf)
    for offset in (-1, 0):
        column = order[np.clip(position + offset, 0, n_kernels - 1)]
        np.maximum(shift, -widths[column] * (phase - centres[column]) ** 2, out=shift)
    # -h (phase - c)² - shift = [phase², phase, 1, -shift] @ [-h; 2hc; -hc²; 1]: one BLAS product
    # writes the whole (L, N) exponent matrix. Cancellation costs ~h·phase²·1e-16 in the exponent
    # (< 1e-11 for any sensible number of kernels).
    features = np.column_stack([phase * phase, phase, np.ones_like(phase), -shift])
    coefficients = np.stack(
        [-widths, 2.0 * widths * centres, -widths * centres * centres, np.ones_like(centres)]
    )
    log_psi = features @ coefficients
    # Terms below e^-40 of the row maximum cannot change a float64 sum; clipping them keeps exp
    # out of the (slow) subnormal range.
    np.maximum(log_psi, _LOG_PSI_FLOOR, out=log_psi)
    psi = np.exp(log_psi, out=log_psi)
    psi *= (phase / (psi @ np.ones(n_kernels)))[:, None]
    return psi


def _basis_row(phase: float, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
    """``phi(phase)`` (1, N) for one phase: :func:`basis_functions` without its batching (a
    control loop asks for one row per step)."""
    log_psi = -widths * (phase - centres) ** 2
    log_psi -= log_psi.max()
    psi = np.exp(np.maximum(log_psi, _LOG_PSI_FLOOR))
    return (psi * (phase / psi.sum()))[None]


def _derivatives(y: np.ndarray, dt: float, method: str) -> tuple[np.ndarray, np.ndarray]:
    if method == "gradient":
        velocity = np.gradient(y, dt, axis=0)
        return velocity, np.gradient(velocity, dt, axis=0)
    # Forward differences: exactly the quantities the explicit Euler rollout integrates, padded
    # at the end by holding the last value (the rollout never reads the last two entries).
    velocity = np.empty_like(y)
    velocity[:-1] = np.diff(y, axis=0) / dt
    velocity[-1] = velocity[-2]
    acceleration = np.empty_like(y)
    acceleration[:-1] = np.diff(velocity, axis=0) / dt
    acceleration[-1] = acceleration[-2]
    return velocity, acceleration


def _forcing_target(
    y: np.ndarray,
    phase: np.ndarray,
    *,
    dt: float,
    tau: float,
    alpha: float,
    beta: float,
    K: float,
    derivatives: str = "gradient",
    gate: np.ndarray | None = None,
) -> np.ndarray:
    """The forcing term that makes Eq. 10 reproduce ``y``.

    ``f*[l] = (tau² ÿ[l] - alpha (beta (g - y[l]) - tau ẏ[l])) / K + gate[l] (g - y0)`` with
    ``g = y[-1]``, ``y0 = y[0]`` and the goal gate ``gate`` (default: the phase, Eq. 10; the
    delayed goal of the robot protocol otherwise).

    Parameters
    ----------
    y : array, shape (T, D)
        Demonstration (positions, any length unit).
    phase : array, shape (T,)
        Phase at each sample.
    dt : float
        Time step of ``y`` in seconds.
    derivatives : {"gradient", "forward"}
        ``np.gradient`` (central differences) or forward differences.

    Returns
    -------
    f_target : array, shape (T, D)
    """
    velocity, acceleration = _derivatives(y, dt, derivatives)
    start, goal = y[0], y[-1]
    spring = alpha * (beta * (goal - y) - tau * velocity)
    gate = phase if gate is None else gate
    return (tau**2 * acceleration - spring) / K + gate[:, None] * (goal - start)


def _regress(
    phi: np.ndarray, phase: np.ndarray, target: np.ndarray, *, regression: str, ridge: float
) -> np.ndarray:
    """Forcing-term weights (N, D) from basis rows ``phi`` (L, N) at ``phase`` (L,) and the forcing
    target (L, D): LWR per kernel (``regression="lwr"``) or ridge least squares (``"ridge"``, the
    regulariser ``ridge`` relative to the mean diagonal of ``ΦᵀΦ``)."""
    n_kernels = phi.shape[1]
    if regression == "lwr":
        # w_i = Σ_l phase_l ψ̄_il f_l / Σ_l phase_l² ψ̄_il, with phi = phase · ψ̄.
        denominator = phi.T @ phase
        weights = (phi.T @ target) / np.maximum(denominator, np.finfo(float).tiny)[:, None]
    else:
        gram = phi.T @ phi
        reg = ridge * max(np.trace(gram) / n_kernels, np.finfo(float).tiny)
        weights = np.linalg.solve(gram + reg * np.eye(n_kernels), phi.T @ target)
    if not np.all(np.isfinite(weights)):
        raise ValueError(
            "fit: the learned weights are not finite; the demonstration's scale or the gains are out of range"
        )
    return weights


def _learn_weights(
    train: np.ndarray, dt: float, gate: np.ndarray, params
) -> tuple[np.ndarray, ...]:
    """The forcing term of a demonstration as learned, ``train`` (n, D) on the normalised grid
    ``dt`` with the goal gate ``gate`` (n,), for a DMP's resolved ``params``.

    The weights belong to the demonstration's own time scale (``tau = 1``): ``tau`` only scales
    rollouts, so it is not used here.

    Returns
    -------
    (weights (N, D), centres (N,), widths (N,), phase (n,), basis rows (n, N))
    """
    n_train = train.shape[0]
    phase = phase_grid(n_train, dt, 1.0, params.alpha_phase, exact=params.exact)
    centres = kernel_centres(
        params.n_kernels, n_train, dt, 1.0, params.alpha_phase, exact=params.exact
    )
    widths = kernel_widths(centres, params.alpha_phase, params.widths)
    target = _forcing_target(
        train,
        phase,
        dt=dt,
        tau=1.0,
        alpha=params.alpha,
        beta=params.beta,
        K=params.K,
        derivatives=params.derivatives,
        gate=gate,
    )
    phi = _basis_rows(phase, centres, widths)
    weights = _regress(phi, phase, target, regression=params.regression, ridge=params.ridge)
    return np.ascontiguousarray(weights), centres, widths, phase, phi


def _as_phase(phase, name: str = "phase") -> np.ndarray:
    """Phases (L,) validated: finite and in [0, 1] (a DMP's phase decays from 1 towards 0)."""
    phase = _as_bounded_array(phase, name, max_ndim=2)
    phase = as_points(phase.reshape(-1, 1) if phase.ndim <= 1 else phase, 1, name)[:, 0]
    if phase.size and (phase.min() < 0.0 or phase.max() > 1.0):
        raise ValueError(
            f"{name} must lie in [0, 1] (a DMP's phase decays from 1 towards 0), got values in "
            f"[{phase.min():.3g}, {phase.max():.3g}]"
        )
    return phase


def _check_forcing_increment(forcing_increment, name: str = "forcing_increment") -> None:
    """Refuse a forcing increment that is not a callable ``f(phase (n,), basis (n, N)) -> (n, D)``."""
    if forcing_increment is not None and not callable(forcing_increment):
        raise TypeError(
            f"{name} must be callable as f(phase (n,), basis (n, N)) -> (n, D), got "
            f"{type(forcing_increment).__name__}"
        )
