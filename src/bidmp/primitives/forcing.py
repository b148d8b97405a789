"""The forcing term: a basis on the phase, its weights, and the forcing target that makes the
transformation system reproduce a demonstration.

The basis is a component (the :class:`Basis` protocol: where its functions go on a canonical
system's phase, and their rows at any phase); the discrete DMP's is :class:`GaussianBasis`::

    f(phase) = phase · Σ_i w_i ψ_i(phase) / Σ_i ψ_i(phase),  ψ_i = exp(-h_i (phase - c_i)²)

A periodic basis (von Mises functions on a wrapping phase) or any other function approximator
linear in its weights is another class with the same methods, given as ``DMP(forcing_basis=...)``. The
weights are learned by least squares on the basis rows whatever the basis.

Vectorised over samples and dimensions; layer 1, imports only the canonical system.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field
from typing import Protocol, runtime_checkable

import numpy as np

from .._checks import (
    as_vector,
    check_choice,
    check_int,
    check_real,
)
from .._kernels import all_finite, forcing_target
from .._threads import one_thread, single_threaded
from .band import _Band, _band_of
from .canonical import _checked_phase_args, _phase_decay
from .gains import _Gains

__all__ = [
    "kernel_centres",
    "kernel_widths",
    "basis_functions",
    "Basis",
    "GaussianBasis",
    "VonMisesBasis",
]

_MAX_PHASE = 1e6  # |phase| a basis row is computed for (a DMP's phase lies in [0, 1])
_LOG_PSI_FLOOR = -40.0  # kernel terms below e^-40 of a row's largest cannot change a float64 sum
_LOG_OVERFLOW_MARGIN = 600.0  # exp overflows past ~709: a row's excess beyond this is shifted


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
    if n_kernels == 1 and method == "spacing":
        return np.ones(1)  # a single normalised kernel is constant whatever its width
    with np.errstate(over="ignore", under="ignore", divide="ignore"):  # judged below, by name
        if method == "pydmps":
            widths = n_kernels**1.5 / (centres * alpha_phase)
        else:
            spacing = np.abs(np.diff(centres))
            widths = 1.0 / np.append(spacing, spacing[-1]) ** 2
    if not np.all(np.isfinite(widths)):
        # (1e-300 apart, or at 1e-300: the width's square or quotient overflows)
        raise ValueError(
            "centres: kernels so close together or so near 0 that their widths overflow float64 "
            f"(with alpha_phase = {alpha_phase:g}); spread them over the phase"
        )
    return widths


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
    # Outside the centres' range a narrower kernel further away can exceed the bracketing one;
    # where it does by enough to overflow exp, shift such rows by their exact maximum (rows that
    # did not overflow keep their numbers: a shift cancels in the normalisation).
    outside = (phase < centres.min()) | (phase > centres.max())
    if outside.any():
        rows = np.flatnonzero(outside)
        excess = log_psi[rows].max(axis=1)
        high = excess > _LOG_OVERFLOW_MARGIN
        if high.any():
            log_psi[rows[high]] -= excess[high, None]
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


def _forward_differences(y: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Velocity and acceleration (T, D) as forward differences: exactly the quantities the
    explicit Euler rollout integrates, padded at the end by holding the last value (the rollout
    never reads the last two entries)."""
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
    gains: _Gains,
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
    gains : _Gains
        ``alpha``, ``beta`` and ``K`` of Eq. 10.
    derivatives : {"gradient", "forward"}
        ``np.gradient`` (central differences) or forward differences.

    Returns
    -------
    f_target : array, shape (T, D)
    """
    gate = phase if gate is None else gate
    alpha, beta, K = gains
    if derivatives == "gradient":  # central differences, the formula in one compiled loop
        return forcing_target(y, gate, dt, tau, tau**2, alpha, beta, K)
    velocity, acceleration = _forward_differences(y, dt)
    start, goal = y[0], y[-1]
    spring = alpha * (beta * (goal - y) - tau * velocity)
    return (tau**2 * acceleration - spring) / K + gate[:, None] * (goal - start)


def _regress(
    phi: np.ndarray, phase: np.ndarray, target: np.ndarray, *, regression: str, ridge: float
) -> np.ndarray:
    """Forcing-term weights (N, D) from basis rows ``phi`` (L, N) at ``phase`` (L,) and the forcing
    target (L, D): LWR per kernel (``regression="lwr"``) or ridge least squares (``"ridge"``, the
    regulariser ``ridge`` relative to the mean diagonal of ``ΦᵀΦ``)."""
    return _solve_weights(_regression_factor(phi, phase, regression, ridge), phi, target)


def _regression_factor(
    phi: np.ndarray, phase: np.ndarray, regression: str, ridge: float
) -> tuple[str, np.ndarray, _Band | None]:
    """What the regression needs of the basis alone (no target): ``(kind, values, band)``,
    LWR's per-kernel denominators ``Σ_l phase_l² ψ̄_il`` (N,), or ridge's regularised
    ``ΦᵀΦ + λ I`` (N, N); ``band`` None (a cached design keeps the rows as a band and ridge's
    matrix inverted: kind "inverse")."""
    if regression == "lwr":
        # w_i = Σ_l phase_l ψ̄_il f_l / Σ_l phase_l² ψ̄_il, with phi = phase · ψ̄.
        return "lwr", np.maximum(phi.T @ phase, np.finfo(float).tiny), None
    n_kernels = phi.shape[1]
    gram = phi.T @ phi
    reg = ridge * max(np.trace(gram) / n_kernels, np.finfo(float).tiny)
    return "ridge", gram + reg * np.eye(n_kernels), None


def _solve_weights(factor: tuple, phi: np.ndarray, target: np.ndarray) -> np.ndarray:
    """The weights (N, D) for a forcing target (L, D) from :func:`_regression_factor`: ``Φᵀ f``
    (from the band where the factor has one: it reads only the kernels that matter), then
    divided by LWR's denominators, or solved with ridge's matrix (one product with its inverse
    for a cached design: it rounds differently from a solve, the weights agreeing to ~1e-11 of
    their size, the Gram matrix's condition ~1e5 times the rounding)."""
    kind, values, band = factor
    if band is not None and kind != "ridge" and values.size * target.shape[1] < _ONE_THREAD_BELOW:
        # No product here that OpenBLAS would spread over threads (the band's is compiled, and
        # LWR's a division): no limit to set and restore — the robot protocol's common case,
        # where the limit cost 0.06-0.08 ms of a 0.8 ms fit + trajectory beside other work.
        return _weights_of(kind, values, band.transposed_product(target))
    with one_thread():  # small dense algebra: idle BLAS threads only steal the core
        projected = phi.T @ target if band is None else band.transposed_product(target)
        return _weights_of(kind, values, projected)


def _weights_of(kind: str, values: np.ndarray, projected: np.ndarray) -> np.ndarray:
    """The weights (N, D) from the projected target ``Φᵀ f`` (N, D) and the regression's factor."""
    if kind == "lwr":
        weights = projected / values[:, None]
    elif kind == "inverse":
        weights = values @ projected
    else:
        weights = np.linalg.solve(values, projected)
    if not all_finite(weights):
        raise ValueError(
            "fit: the learned weights are not finite; the demonstration's scale or the gains are out of range"
        )
    return weights


def _readonly(*arrays: np.ndarray) -> None:
    for array in arrays:
        array.flags.writeable = False


# OpenBLAS runs a matrix product of m·n·k below 65 536 · GEMM_MULTITHREAD_THRESHOLD (4 in the
# wheels) on the calling thread: below the smallest such bound, no limit is needed around it.
_ONE_THREAD_BELOW = 65_536


@functools.lru_cache(maxsize=8)
def _cached_design(canonical, basis, n_train: int, dt: float, regression: str, ridge: float):
    design = _training_design(canonical, basis, n_train, dt, regression, ridge)
    # Shared by every fit on this grid: nobody may write into them.
    _readonly(*design[:4], design[4][1])
    return design


@single_threaded  # its Gram product and inverse are BLAS calls OpenBLAS would thread
def _training_design(canonical, basis, n_train: int, dt: float, regression: str, ridge: float):
    """Everything a fit needs that does not depend on the demonstration's values: the phase and
    basis rows one sample past the training grid (n + 1,), (n + 1, N), the kernels' centres and
    widths (N,), the regression's factor, and the rows as a band (or None)."""
    grid_phase = canonical.grid(n_train + 1, dt, 1.0)
    centres, widths = basis.place(canonical, n_train, dt)
    grid_phi = basis.rows(grid_phase, centres, widths)
    factor = _regression_factor(grid_phi[:n_train], grid_phase[:n_train], regression, ridge)
    band = _band_of(grid_phi)
    if band is not None:
        # Every fit on this grid regresses on the same rows: they are kept as a band, and ridge's
        # matrix inverted once (NumPy's; SciPy's OpenBLAS is a second thread pool, whose idle
        # threads spun against NumPy's here: 0.9 ms fits took 1-5 ms on two cores).
        kind, values, _ = factor
        if kind == "ridge":
            kind, values = "inverse", np.linalg.inv(values)
        factor = (kind, values, band.head(n_train))
    return grid_phase, grid_phi, centres, widths, factor, band


def _learn_weights(
    train: np.ndarray, dt: float, gate: np.ndarray, params
) -> tuple[np.ndarray, ...]:
    """The forcing term of a demonstration as learned, ``train`` (n, D) on the normalised grid
    ``dt`` with the goal gate ``gate`` (n,), for a DMP's resolved ``params`` (its canonical
    system and basis among them).

    The weights belong to the demonstration's own time scale (``tau = 1``): ``tau`` only scales
    rollouts, so it is not used here. The phase, the basis rows and the regression's factor
    depend only on the grid and the components, not on the demonstration, so the last few
    grids' are kept (read-only) and a fit of another recording of the same length reuses them.

    Returns
    -------
    (weights (N, D), centres (N,), widths (N,), phase (n + 1,), basis rows (n + 1, N), the
    rows as a :class:`~bidmp.primitives.band._Band` or None): the grid one sample past the
    training grid
    """
    n_train = train.shape[0]
    canonical, basis = params.canonical_system, params.basis
    key = (canonical, basis, n_train, dt, params.regression, params.ridge)
    try:
        hash(key)
    except TypeError:  # a component of one's own that cannot be a cache key
        design = _training_design(*key)
    else:
        design = _cached_design(*key)
    # One sample past the training grid: a timed trajectory's rollout asks for it (the state's
    # derivatives at the last sample), and then shares the grid cached from here.
    grid_phase, grid_phi, centres, widths, factor, band = design
    phase, phi = grid_phase[:n_train], grid_phi[:n_train]
    target = _forcing_target(
        train,
        phase,
        dt=dt,
        tau=1.0,
        gains=params.gains,
        derivatives=params.derivatives,
        gate=gate,
    )
    weights = _solve_weights(factor, phi, target)
    return np.ascontiguousarray(weights), centres, widths, grid_phase, grid_phi, band


def _check_forcing_increment(forcing_increment, name: str = "forcing_increment") -> None:
    """Refuse a forcing increment that is not a callable ``f(phase (n,), basis (n, N)) -> (n, D)``."""
    if forcing_increment is not None and not callable(forcing_increment):
        raise TypeError(
            f"{name} must be callable as f(phase (n,), basis (n, N)) -> (n, D), got "
            f"{type(forcing_increment).__name__}"
        )


@runtime_checkable
class Basis(Protocol):
    """What a :class:`~bidmp.DMP` asks of its basis (the forcing term's function approximator).

    The learned parameters of the functions (a DMP's ``centres_`` and ``widths_``, shape (N,)
    each) are placed by :meth:`place` at ``fit`` and passed back to every other method, so a
    basis object holds only its settings.

    Attributes
    ----------
    size : int
        Number of functions N (the rows' columns, the weights' rows).
    """

    size: int

    def place(self, canonical, n_steps: int, step: float) -> tuple[np.ndarray, np.ndarray]:
        """Centres and widths (N,) for the training grid of ``n_steps`` samples ``step`` apart
        on the canonical system ``canonical``."""
        ...

    def rows(self, phase: np.ndarray, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
        """Basis rows at the phases ``phase`` (L,), shape ``(L, N)``."""
        ...

    def row(self, phase: float, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
        """One row ``(1, N)`` at one phase (a control loop asks for one per step)."""
        ...


@dataclass(frozen=True)
class GaussianBasis:
    """The discrete DMP's basis: ``size`` normalised Gaussian kernels scaled by the phase
    (:func:`basis_functions`), centred at the phase of equally spaced times over the training
    grid (:func:`kernel_centres`), sized by the ``widths`` rule (:func:`kernel_widths`).

    Parameters
    ----------
    size : int
        Number of kernels N.
    widths : {"spacing", "pydmps"}, default "spacing"
        Kernel-width rule (``"pydmps"`` needs the canonical system's decay ``rate``).
    """

    size: int
    widths: str = "spacing"
    # the last kernels row() checked (a control loop passes the same arrays every step)
    _checked: tuple | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "size", check_int(self.size, "size", minimum=1, limit="max_kernels")
        )
        check_choice(self.widths, "widths", ("spacing", "pydmps"))

    def place(self, canonical, n_steps: int, step: float) -> tuple[np.ndarray, np.ndarray]:
        """Centres at the phase of ``size`` equally spaced samples of the training grid, sized
        by the width rule."""
        n_steps = check_int(n_steps, "n_steps", minimum=1, limit="max_steps")
        if not callable(getattr(canonical, "at", None)):
            raise TypeError(
                "canonical must be a canonical system (bidmp.primitives.CanonicalSystem, with "
                f"at(samples, step, tau)), got {type(canonical).__name__}"
            )
        # The kernels span exactly the visited phase range: one outside it never fires, and
        # its LWR weight blows up.
        centres = canonical.at(np.linspace(0.0, n_steps - 1, self.size), step, 1.0)
        rate = getattr(canonical, "rate", None) if self.widths == "pydmps" else 1.0
        if rate is None:
            raise ValueError(
                'GaussianBasis(widths="pydmps") sizes kernels by the phase\'s decay rate; '
                f'{type(canonical).__name__} has none: use widths="spacing"'
            )
        return centres, kernel_widths(centres, rate, self.widths)

    def rows(self, phase: np.ndarray, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
        """:func:`basis_functions` (its checks included)."""
        return basis_functions(phase, centres, widths)

    def row(self, phase: float, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
        """One row at a phase: the control loop's call, so the kernels are checked once per pair
        of arrays (a DMP's own, the same every step)."""
        if not (type(phase) is float and -_MAX_PHASE <= phase <= _MAX_PHASE):
            phase = check_real(phase, "phase", minimum=-_MAX_PHASE, maximum=_MAX_PHASE)
        checked = self._checked
        if checked is None or checked[0] is not centres or checked[1] is not widths:
            basis_functions(np.zeros(1), centres, widths)  # checks the kernels, names them
            object.__setattr__(self, "_checked", (centres, widths))
        return _basis_row(phase, centres, widths)


@dataclass(frozen=True)
class VonMisesBasis:
    """A periodic basis: ``size`` von Mises functions ``ψ_i(φ) = exp(h (cos(φ - c_i) - 1))`` with
    centres ``c_i`` evenly spaced over one cycle [0, 2π) and one concentration ``h`` (default
    ``2.5 · size``: neighbours overlap at about half height), normalised to sum to 1 at every
    phase (the rhythmic forcing term carries no phase factor: it never fades).

    Parameters
    ----------
    size : int
        Number of functions N.
    concentration : float, optional
        ``h`` (dimensionless); default ``2.5 · size``.
    """

    size: int
    concentration: float | None = None
    # the last kernels row() checked (a control loop passes the same arrays every step)
    _checked: tuple | None = field(default=None, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "size", check_int(self.size, "size", minimum=2, limit="max_kernels")
        )
        if self.concentration is not None:
            object.__setattr__(
                self,
                "concentration",
                check_real(self.concentration, "concentration", positive=True, maximum=1e6),
            )

    def place(self, canonical, n_steps: int, step: float) -> tuple[np.ndarray, np.ndarray]:
        """Centres (rad) evenly over a cycle and the concentration of each, (N,) each; the
        grid's length and step do not matter (the phase covers every cycle alike)."""
        centres = 2.0 * np.pi * np.arange(self.size) / self.size
        concentration = 2.5 * self.size if self.concentration is None else self.concentration
        return centres, np.full(self.size, float(concentration))

    def rows(self, phase: np.ndarray, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
        """Normalised rows (L, N) at phases (L,) in radians (any value: the functions are
        periodic). Shifted by each row's largest exponent, so no concentration underflows."""
        phase = as_vector(phase, "phase")
        centres, widths = _von_mises_kernels(centres, widths)
        if np.abs(phase).max(initial=0.0) > _MAX_PHASE:
            raise ValueError(f"phase must lie within ±{_MAX_PHASE:g} rad")
        log_psi = widths[None, :] * (np.cos(phase[:, None] - centres[None, :]) - 1.0)
        log_psi -= log_psi.max(axis=1, keepdims=True)
        psi = np.exp(np.maximum(log_psi, _LOG_PSI_FLOOR))
        psi /= psi.sum(axis=1, keepdims=True)
        return psi

    def row(self, phase: float, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
        """One row (1, N): the control loop's call, so the kernels are checked once per pair of
        arrays (a model's own, the same every step)."""
        if type(phase) is not float or not -_MAX_PHASE <= phase <= _MAX_PHASE:
            phase = check_real(phase, "phase", minimum=-_MAX_PHASE, maximum=_MAX_PHASE)
        checked = self._checked
        if checked is None or checked[0] is not centres or checked[1] is not widths:
            _von_mises_kernels(centres, widths)  # checks them, names them
            object.__setattr__(self, "_checked", (centres, widths))
        log_psi = widths * (np.cos(phase - centres) - 1.0)
        psi = np.exp(np.maximum(log_psi - log_psi.max(), _LOG_PSI_FLOOR))
        return (psi / psi.sum())[None]


def _von_mises_kernels(centres, widths) -> tuple[np.ndarray, np.ndarray]:
    """Finite centres (rad) and positive concentrations of equal length, (N,) each."""
    centres = as_vector(centres, "centres")
    widths = as_vector(widths, "widths", positive=True)
    if widths.shape != centres.shape:
        raise ValueError(
            f"widths must have one entry per entry of centres ({centres.shape[0]}), got {widths.shape[0]}"
        )
    if np.abs(centres).max() > _MAX_PHASE or widths.max() > 1e6:
        raise ValueError(f"centres must lie within ±{_MAX_PHASE:g} rad and widths at most 1e6")
    return centres, widths
