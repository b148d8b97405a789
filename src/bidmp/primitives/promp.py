"""Probabilistic movement primitives (Paraschos et al. 2013): a Gaussian over the weights of a
basis on the phase, learned from several demonstrations, and exact Gaussian conditioning.

``y(s) = Φ(s)ᵀ w``, ``w ~ N(μ_w, Σ_w)``, the phase ``s = t / T`` in [0, 1] for each demonstration
(its own duration: demonstrations of any length and rate), Φ the normalised Gaussian basis of the
field (centres evenly over [0, 1], width ``h = -1 / (8 N² ln overlap)``, as movement_primitives'
ProMP). The weights are stacked dimension after dimension: ``w = [w_dim0 (N), w_dim1 (N), …]``.

Fit: each demonstration's weights by ridge regression on its own phase; ``μ_w`` their mean,
``Σ_w`` their covariance plus ``cov_reg`` times the mean variance on the diagonal (so it stays
positive definite with few demonstrations — one demonstration gives an isotropic prior of that
size).

Conditioning on ``y*`` at phases ``s*`` with covariance ``Σ*`` (all via-points at once, stacked):
``K = Σ_w H (Σ* + Hᵀ Σ_w H)⁻¹``, ``μ_w ← μ_w + K (y* - Hᵀ μ_w)``, ``Σ_w ← Σ_w - K Hᵀ Σ_w`` —
:func:`condition_gaussian`, exact for ``Σ* = 0`` too (the point is then passed exactly, with zero
posterior variance there).

Layer 1: NumPy only.
"""

from __future__ import annotations

import math

import numpy as np

from .._api import Estimator, integer, real
from .._checks import (
    NotFittedError,
    _as_bounded_array,
    _check_magnitude,
    as_points,
    as_trajectory,
    as_vector,
    check_bytes,
    check_int,
    check_real,
    check_seed,
)
from .._state import state_reader
from .._threads import single_threaded
from .._units import check_units
from .timing import Trajectory, check_timestamps

__all__ = ["ProMP", "promp_basis", "condition_gaussian"]


def promp_basis(phase, n_basis: int, overlap: float = 0.7, derivative: int = 0) -> np.ndarray:
    """Normalised Gaussian basis rows (L, N) at phases (L,) in [0, 1], or their ``derivative``-th
    derivative in the phase (1 or 2), analytic.

    ``ψ_i = exp(-(s - c_i)² / (2h))``, ``c_i`` evenly over [0, 1], ``h = -1 / (8 N² ln overlap)``,
    ``φ_i = ψ_i / Σ_j ψ_j``."""
    phase = as_vector(phase, "phase")
    n_basis = check_int(n_basis, "n_basis", minimum=2, limit="max_kernels")
    overlap = check_real(overlap, "overlap", positive=True, maximum=0.99)
    derivative = check_int(derivative, "derivative", minimum=0, maximum=2)
    centres = np.linspace(0.0, 1.0, n_basis)
    width = -1.0 / (8.0 * n_basis**2 * math.log(overlap))
    offset = phase[:, None] - centres[None, :]
    log_psi = offset * offset
    log_psi *= -0.5 / width
    psi = np.exp(log_psi)
    total = psi.sum(axis=1, keepdims=True)
    if not np.all(total > 1e-250):  # a phase far outside [0, 1]: shift by each row's largest
        psi = np.exp(log_psi - log_psi.max(axis=1, keepdims=True))
        total = psi.sum(axis=1, keepdims=True)
    rows = psi / total
    if derivative == 0:
        return rows
    # ψ' = -(s - c)/h ψ; with a = -(s - c)/h:  φ' = φ (a - Σ φ a)
    slope = -offset / width
    mean_slope = np.sum(rows * slope, axis=1, keepdims=True)
    first = rows * (slope - mean_slope)
    if derivative == 1:
        return first
    # φ'' = φ' (a - ā) + φ (a' - ā'), a' = -1/h, ā' = Σ φ' a + Σ φ a' = Σ φ' a - 1/h
    mean_slope_rate = np.sum(first * slope, axis=1, keepdims=True) - 1.0 / width
    return first * (slope - mean_slope) + rows * (-1.0 / width - mean_slope_rate)


def condition_gaussian(mean, cov, H, y, noise) -> tuple[np.ndarray, np.ndarray]:
    """Exact Gaussian conditioning of ``w ~ N(mean, cov)`` on ``y = Hᵀ w + ε``, ``ε ~ N(0, noise)``.

    Parameters
    ----------
    mean : (M,); cov : (M, M) symmetric positive definite
    H : (M, K) the observation's columns
    y : (K,) the observed values
    noise : (K, K) positive semidefinite (zeros: the observation is exact)

    Returns
    -------
    (mean (M,), cov (M, M)) of the posterior, its covariance symmetrised.
    """
    mean = as_vector(mean, "mean")
    size = mean.shape[0]
    cov = _matrix(cov, "cov", (size, size), f"mean has {size} entries")
    H = _matrix(H, "H", (size, None), f"mean has {size} entries")
    # (an observation's columns of 1e300 overflow its products with the covariance)
    _check_magnitude(H, "H")
    y = as_vector(y, "y")
    if y.shape[0] != H.shape[1]:
        raise ValueError(f"y must have one value per column of H ({H.shape[1]}), got {y.shape[0]}")
    noise = _matrix(noise, "noise", (H.shape[1], H.shape[1]), f"y has {y.shape[0]} values")
    try:
        return _conditioned(mean, cov, H, y, noise)
    except _Conflict as conflict:
        first, second = conflict.rows
        if first == second:
            raise ValueError(
                f"y: observation {first} reads none of the weights (its column of H is 0 to the "
                "floats' range) yet differs from the mean's; give it noise > 0 or another H"
            ) from None
        raise ValueError(
            f"y: observations {first} and {second} conflict: they read the same combination of "
            "the weights (one point twice, or more points than the weights carry) with different "
            "values and no noise to reconcile them; merge them or give noise > 0"
        ) from None


class _Conflict(ValueError):
    """Exact observations that read one combination of the weights (the same point twice, or
    more points than the weights can carry) with different values: no weights pass them all.
    ``rows`` are the two observations (columns of H) that weigh most in the conflict."""

    def __init__(self, rows: tuple[int, int]) -> None:
        super().__init__(f"observations {rows[0]} and {rows[1]} conflict")
        self.rows = rows


# Below this share of the innovation's largest eigenvalue a direction is no observation of its
# own: the same point observed twice (or 1e-12 of the phase apart), or more points than weights.
_REDUNDANT = 1e-12


def _conditioned(mean, cov, H, y, noise) -> tuple[np.ndarray, np.ndarray]:
    """The posterior of :func:`condition_gaussian` on checked arrays. Observations that are one
    observation twice over (their innovation ``S = Hᵀ Σ H + N`` singular along a direction) are
    merged when their values agree along it — the posterior of the observation once — and
    raise :class:`_Conflict` when they do not."""
    cov_h = cov @ H  # (M, K)
    innovation = H.T @ cov_h + noise  # (K, K), positive definite when cov is
    residual = y - H.T @ mean
    values, vectors = np.linalg.eigh(0.5 * (innovation + innovation.T))
    largest = float(values[-1]) if values.size else 0.0
    if values.size and largest > 0.0 and values[0] > _REDUNDANT * largest:
        gain = np.linalg.solve(innovation, cov_h.T).T  # K = Σ H S⁻¹ (S symmetric)
    else:
        kept = values > _REDUNDANT * largest if largest > 0.0 else np.zeros(values.size, bool)
        null = vectors[:, ~kept]
        # The residual along the redundant directions must vanish: the points agree there
        # (to the rounding of the values and of the mean's reading of them).
        along = null.T @ residual
        scale = max(float(np.abs(y).max(initial=0.0)), float(np.abs(H.T @ mean).max(initial=0.0)))
        if np.abs(along).max(initial=0.0) > 1e-8 * max(scale, 1e-300):
            if not kept.any():  # the observations read no weight at all (H is 0 to rounding)
                worst = int(np.argmax(np.abs(residual)))
                raise _Conflict((worst, worst))
            # the two observations that weigh most in the direction they disagree along
            worst = np.abs(null[:, int(np.argmax(np.abs(along)))])
            first, second = (int(i) for i in np.argsort(-worst)[:2])
            if worst[second] <= 1e-6 * worst[first]:  # one observation alone: it reads nothing
                raise _Conflict((first, first))
            raise _Conflict((min(first, second), max(first, second)))
        inverse = (vectors[:, kept] / values[kept]) @ vectors[:, kept].T  # S⁺
        gain = cov_h @ inverse
    posterior_mean = mean + gain @ residual
    posterior_cov = cov - gain @ cov_h.T
    return posterior_mean, 0.5 * (posterior_cov + posterior_cov.T)


def _matrix(value, name: str, shape: tuple, why: str) -> np.ndarray:
    """A finite 2-D float array of ``shape`` (None: any length), refused naming ``name`` and
    ``why`` it must have that shape."""
    array = _as_bounded_array(value, name, 2)
    if array.ndim != 2 or any(
        want is not None and got != want for got, want in zip(array.shape, shape)
    ):
        expected = ", ".join("any" if want is None else str(want) for want in shape)
        raise ValueError(f"{name} must have shape ({expected}) ({why}), got {array.shape}")
    array = array.astype(float, copy=False)
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be finite")
    return array


def _phase_of(t: np.ndarray) -> np.ndarray:
    return (t - t[0]) / (t[-1] - t[0])


class ProMP(Estimator):
    """A probabilistic movement primitive learned from several demonstrations.

    Parameters
    ----------
    n_basis : int
        Basis functions per dimension N.
    ridge : float
        Ridge regulariser of each demonstration's weights (relative to the mean diagonal of
        ``ΦᵀΦ``).
    cov_reg : float
        Added to the weight covariance's diagonal, times its mean variance (or times the mean
        squared weight for a single demonstration). It decides how a ProMP conditioned outside
        its demonstrations' spread bends: on LASA's Angle (7 demonstrations, 20 functions), a goal
        moved by 60 % of the extent gives an RMSE of 1 124 mm from the shifted demonstration at
        1e-6 (the few demonstrations' covariance is nearly singular: the posterior swings along
        directions they barely vary in), 37 mm at the default 1e-2 and 15 mm at 0.1.
    overlap : float
        The basis' overlap (movement_primitives' 0.7).

    Attributes
    ----------
    weight_mean_ : (D·N,); weight_cov_ : (D·N, D·N)
    weights_ : (n_demos, D·N) each demonstration's weights
    duration_ : float
        The demonstrations' mean duration (s; 1 without stamps).
    n_dims_ : int
    """

    _parameter_constraints = {
        "n_basis": integer(minimum=2, limit="max_kernels"),
        "ridge": real(nonnegative=True, maximum=1.0),
        "cov_reg": real(positive=True, maximum=1e3),
        "overlap": real(positive=True, maximum=0.99),
    }

    def __init__(
        self, n_basis: int = 20, ridge: float = 1e-10, cov_reg: float = 1e-2, overlap: float = 0.7
    ) -> None:
        self.n_basis = n_basis
        self.ridge = ridge
        self.cov_reg = cov_reg
        self.overlap = overlap

    # -- learning ---------------------------------------------------------------------------
    @single_threaded  # small dense algebra: idle BLAS threads only steal the core
    def fit(self, demonstrations, times=None, units: str | None = None) -> ProMP:
        """Learn from ``demonstrations`` (a list of (T_i, D) arrays, any lengths) with their
        stamps ``times`` (a list of (T_i,) arrays, s; None: each over 1 s)."""
        self._check_constraints()
        n_basis, ridge, cov_reg = int(self.n_basis), float(self.ridge), float(self.cov_reg)
        demos = _demonstrations(demonstrations)
        stamps = _stamps(times, demos)
        units = "" if units is None else check_units(units)
        n_dims = demos[0].shape[1]
        weights = np.empty((len(demos), n_dims * n_basis))
        for index, (y, t) in enumerate(zip(demos, stamps)):
            rows = promp_basis(_phase_of(t), n_basis, self.overlap)
            gram = rows.T @ rows
            gram[np.diag_indices(n_basis)] += ridge * np.trace(gram) / n_basis
            weights[index] = np.linalg.solve(gram, rows.T @ y).T.reshape(-1)
        mean = weights.mean(axis=0)
        cov = _weight_covariance(weights, cov_reg)
        self.weights_ = weights
        self.weight_mean_ = mean
        self.weight_cov_ = cov
        self.duration_ = float(np.mean([t[-1] - t[0] for t in stamps]))
        self.n_dims_ = n_dims
        self.units_ = units
        return self

    def check_fitted(self) -> None:
        """Raise :class:`bidmp.NotFittedError`, saying what to do, unless the model is fitted."""
        if "weight_mean_" not in self.__dict__:
            raise NotFittedError("this ProMP is not fitted yet: call fit(demonstrations) first")

    # -- the distribution -------------------------------------------------------------------
    def _H(self, phase: np.ndarray, derivative: int = 0) -> np.ndarray:
        """The observation matrix (D·N, L·D) of all dimensions at ``phase``: column ``l·D + d``
        reads dimension d at phase l."""
        rows = promp_basis(phase, self._fitted_basis, self.overlap, derivative)  # (L, N)
        n_dims, n_basis = self.n_dims_, rows.shape[1]
        H = np.zeros((n_dims * n_basis, rows.shape[0] * n_dims))
        for d in range(n_dims):
            H[d * n_basis : (d + 1) * n_basis, d::n_dims] = rows.T
        return H

    def _phase(self, phase, n_steps: int) -> np.ndarray:
        if phase is None:
            n_steps = check_int(n_steps, "n_steps", minimum=2, limit="max_steps")
            return np.linspace(0.0, 1.0, n_steps)
        phase = as_vector(phase, "phase")
        if phase.min() < 0.0 or phase.max() > 1.0:
            raise ValueError("phase must lie in [0, 1] (the demonstrations' normalised time)")
        # the basis rows (L, N) and a dimension's block products are what a phase costs
        check_bytes(
            phase.size * self._fitted_basis * max(self.n_dims_, 1), "the ProMP's rows at phase"
        )
        return phase

    def _rows(self, phase, n_steps: int, derivative: int = 0) -> np.ndarray:
        """The basis rows (L, N) (or their phase derivative) at ``phase`` (default ``n_steps``)."""
        self.check_fitted()
        return promp_basis(
            self._phase(phase, n_steps), self._fitted_basis, self.overlap, derivative
        )

    @property
    def _fitted_basis(self) -> int:
        """The basis functions per dimension the weights were fitted with: what the rows must have
        (``n_basis`` may have been set since, by ``set_params``: it acts at the next ``fit``)."""
        return self.weight_mean_.size // self.n_dims_

    def _mean_of(self, rows: np.ndarray) -> np.ndarray:
        """``B w_d`` per dimension: (L, D)."""
        return rows @ self.weight_mean_.reshape(self.n_dims_, rows.shape[1]).T

    def _variance_of(self, rows: np.ndarray) -> np.ndarray:
        """``diag(B Σ_dd Bᵀ)`` per dimension: (L, D)."""
        n_basis = rows.shape[1]
        variance = np.empty((rows.shape[0], self.n_dims_))
        for d in range(self.n_dims_):
            block = slice(d * n_basis, (d + 1) * n_basis)
            variance[:, d] = np.einsum("ln,nm,lm->l", rows, self.weight_cov_[block, block], rows)
        return np.maximum(variance, 0.0)

    def mean(self, phase=None, n_steps: int = 100) -> np.ndarray:
        """The mean positions (L, D) at ``phase`` (default ``n_steps`` over [0, 1])."""
        return self._mean_of(self._rows(phase, n_steps))

    def var(self, phase=None, n_steps: int = 100) -> np.ndarray:
        """The positions' variance (L, D) at ``phase``."""
        return self._variance_of(self._rows(phase, n_steps))

    def mean_velocity(self, phase=None, n_steps: int = 100) -> np.ndarray:
        """The mean velocities (L, D), units/s over the mean duration."""
        return self._mean_of(self._rows(phase, n_steps, 1)) / self.duration_

    def var_velocity(self, phase=None, n_steps: int = 100) -> np.ndarray:
        """The velocities' variance (L, D), (units/s)²."""
        return self._variance_of(self._rows(phase, n_steps, 1)) / self.duration_**2

    def sample(self, n_samples: int, seed=0, phase=None, n_steps: int = 100) -> np.ndarray:
        """``n_samples`` trajectories (n, L, D) drawn from the weight distribution (seeded)."""
        self.check_fitted()
        n_samples = check_int(n_samples, "n_samples", minimum=1, maximum=100_000)
        rng = np.random.default_rng(check_seed(seed, "seed"))
        rows = self._rows(phase, n_steps)
        weights = rng.multivariate_normal(self.weight_mean_, self.weight_cov_, n_samples)
        # (n, D, N) weights times the rows: (n, L, D)
        return np.einsum("ln,sdn->sld", rows, weights.reshape(n_samples, self.n_dims_, -1))

    def condition(self, phase, y, cov=0.0, *, rest=None) -> ProMP:
        """A new ProMP conditioned on passing ``y`` (K, D) at ``phase`` (K,) with covariance
        ``cov``: 0 (exactly), a variance σ² (isotropic), (D, D) for every point, or (K, D, D);
        and at rest (velocity and acceleration 0, exactly) at the phases ``rest`` (R,) if given (a motion that
        starts or ends at rest: ``rest=[0.0, 1.0]``). All at once (one stacked observation).
        Two exact points at one phase with equal values are one point; with different values
        they conflict (a ``ValueError`` naming them), as do more exact points than the weights
        can carry."""
        self.check_fitted()
        phase = _as_bounded_array(phase, "phase", 1)
        rest = np.zeros(0) if rest is None else _as_bounded_array(rest, "rest", 1).reshape(-1)
        # one stacked observation: its ((K + R)·D)² covariance must fit before it is built
        count = phase.size + 2 * rest.size  # (a rest: its velocity and its acceleration)
        check_bytes((count * self.n_dims_) ** 2, f"conditioning on {count:,} points")
        phase = self._phase(phase.reshape(-1), 2)
        y = as_points(y, self.n_dims_, "y")
        if y.shape[0] != phase.size:
            raise ValueError(f"y must have one point per phase ({phase.size}), got {y.shape[0]}")
        if rest.size:
            rest = as_vector(rest, "rest")
            if rest.min() < 0.0 or rest.max() > 1.0:
                raise ValueError("rest must lie in [0, 1] (phases: the normalised time)")
        noise = _noise(cov, phase.size, self.n_dims_)
        H, values = self._H(phase), y.reshape(-1)
        if rest.size:  # the velocity's and acceleration's rows at the rest phases, 0 exactly
            H = np.hstack([H, self._H(rest, 1), self._H(rest, 2)])
            values = np.concatenate([values, np.zeros(2 * rest.size * self.n_dims_)])
            size = noise.shape[0] + 2 * rest.size * self.n_dims_
            noise = np.pad(noise, (0, size - noise.shape[0]))
        try:
            mean, covariance = _conditioned(self.weight_mean_, self.weight_cov_, H, values, noise)
        except _Conflict as conflict:
            raise ValueError(_conflict_text(conflict.rows, phase, rest, self.n_dims_)) from None
        out = ProMP(**self.get_params())
        out.__dict__.update({k: v for k, v in self.__dict__.items() if k.endswith("_")})
        out.weight_mean_, out.weight_cov_ = mean, covariance
        return out

    # -- persistence (used by bidmp.io) -----------------------------------------------------
    def to_state(self) -> tuple[dict, dict]:
        """The model-file form of the fitted model, ``(meta, arrays)``: its parameters and scalars
        as a JSON-able dict, its learned arrays by name (:func:`bidmp.io.save_model` writes the two
        into one ``.npz``; no pickle). Raises :class:`bidmp.NotFittedError` before ``fit``."""
        return _promp_state(self)

    @classmethod
    @state_reader
    def from_state(cls, meta: dict, arrays) -> ProMP:
        """The fitted model :meth:`to_state` described: ``meta`` as written, ``arrays`` a mapping of
        name to array, each read when needed and checked for dtype, shape and finiteness
        (:func:`bidmp.io.load_model` calls it; a bad file raises, naming the member)."""
        return _promp_from_state(cls, meta, arrays)

    def trajectory(self, dt: float = 0.01) -> Trajectory:
        """The mean motion over the mean duration, every ``dt`` s: positions, velocities and
        accelerations (analytic in the phase)."""
        self.check_fitted()
        dt = check_real(dt, "dt", positive=True, maximum=self.duration_)
        n = check_int(
            int(min(self.duration_ / dt, 1e15) + 1e-9) + 1,
            "the samples (duration / dt)",
            limit="max_steps",
        )
        t = np.arange(n) * dt
        phase = np.minimum(t / self.duration_, 1.0)
        y, yd, ydd = (
            self._mean_of(self._rows(phase, 0, order)) / self.duration_**order
            for order in (0, 1, 2)
        )
        return Trajectory(t, y, yd, ydd, self.units_)


def _conflict_text(rows: tuple[int, int], phase: np.ndarray, rest: np.ndarray, dims: int) -> str:
    """What :meth:`ProMP.condition` says of two observations that conflict: the points of ``y``
    (or the rests) and where they are."""
    kinds, numbers, where = [], [], []
    for row in sorted(rows):
        index = row // dims
        point = index < phase.size
        kinds.append("y" if point else "rest")
        # (a rest is its velocity's rows, then its acceleration's)
        numbers.append(index if point else (index - phase.size) % rest.size)
        where.append(phase[index] if point else rest[(index - phase.size) % rest.size])
    if rows[0] == rows[1]:
        return (
            f"{kinds[0]}: {'point' if kinds[0] == 'y' else 'rest'} {numbers[0]} (at phase "
            f"{where[0]:.6g}) reads none of the weights to the floats' range; move it or give "
            "cov > 0"
        )
    if kinds[0] == kinds[1]:
        named = (
            f"{kinds[0]}: {'points' if kinds[0] == 'y' else 'rests'} {numbers[0]} and {numbers[1]}"
        )
    else:
        named = f"y and rest: point {numbers[0]} and rest {numbers[1]}"
    at = (
        f"both at phase {where[0]:.6g}"
        if abs(where[0] - where[1]) <= 1e-6
        else f"at phases {where[0]:.6g} and {where[1]:.6g}"
    )
    return (
        f"{named} ({at}) conflict: different values the weights cannot both pass exactly (one "
        "time, or more points than weights); merge them, give each its own phase or cov > 0"
    )


def _weight_covariance(weights: np.ndarray, cov_reg: float) -> np.ndarray:
    """The covariance (M, M) of weights (n, M) of n demonstrations plus ``cov_reg`` times their
    mean variance on the diagonal (times the mean squared weight when they do not vary: one
    demonstration, or identical ones), so that it is positive definite."""
    size = weights.shape[1]
    cov = (
        np.cov(weights, rowvar=False).reshape(size, size)
        if weights.shape[0] > 1
        else np.zeros((size, size))
    )
    scale = float(np.mean(np.diag(cov)))
    if not scale > 0.0:
        scale = max(float(np.mean(weights.mean(axis=0) ** 2)), 1e-300)
    cov[np.diag_indices(size)] += cov_reg * scale
    return cov


def _demonstrations(demonstrations) -> list[np.ndarray]:
    if isinstance(demonstrations, np.ndarray) and demonstrations.ndim == 3:
        demonstrations = list(demonstrations)
    if not isinstance(demonstrations, (list, tuple)) or not demonstrations:
        raise TypeError(
            "demonstrations must be a list of (T_i, D) arrays (one or more demonstrations)"
        )
    demos = [
        as_trajectory(y, f"demonstrations[{index}]", min_points=3, allow_static=True)
        for index, y in enumerate(demonstrations)
    ]
    n_dims = demos[0].shape[1]
    for index, y in enumerate(demos):
        if y.shape[1] != n_dims:
            raise ValueError(
                f"demonstrations[{index}] has D = {y.shape[1]}, demonstrations[0] has {n_dims}"
            )
    return demos


def _stamps(times, demos: list[np.ndarray]) -> list[np.ndarray]:
    if times is None:
        return [np.linspace(0.0, 1.0, y.shape[0]) for y in demos]
    if not isinstance(times, (list, tuple)) or len(times) != len(demos):
        raise TypeError(
            f"times must be a list of {len(demos)} stamp arrays (one per demonstration)"
        )
    return [
        check_timestamps(t, y.shape[0], f"times[{i}]") for i, (t, y) in enumerate(zip(times, demos))
    ]


def _noise(cov, n_points: int, n_dims: int) -> np.ndarray:
    """The observation covariance (K·D, K·D) from 0, σ², (D, D) or (K, D, D)."""
    cov = _as_bounded_array(cov, "cov", 3)
    if cov.ndim == 1 or not np.all(np.isfinite(cov)):
        raise ValueError(
            f"cov must be 0, a variance, ({n_dims}, {n_dims}) or ({n_points}, {n_dims}, {n_dims}) "
            f"finite numbers, got shape {cov.shape}"
        )
    if cov.ndim == 0:
        if not (np.isfinite(cov) and cov >= 0.0):
            raise ValueError(f"cov must be a variance >= 0, got {float(cov)}")
        return float(cov) * np.eye(n_points * n_dims)
    square = cov.ndim == 2 and cov.shape == (n_dims, n_dims)
    blocks = np.broadcast_to(cov, (n_points, n_dims, n_dims)) if square else cov
    if blocks.shape != (n_points, n_dims, n_dims):
        raise ValueError(
            f"cov must be 0, a variance, ({n_dims}, {n_dims}) or ({n_points}, {n_dims}, {n_dims}), "
            f"got shape {cov.shape}"
        )
    out = np.zeros((n_points * n_dims, n_points * n_dims))
    for k in range(n_points):
        block = 0.5 * (blocks[k] + blocks[k].T)
        if np.linalg.eigvalsh(block).min() < -1e-12 * max(np.abs(block).max(), 1e-300):
            raise ValueError(f"cov[{k}] is not positive semidefinite")
        out[k * n_dims : (k + 1) * n_dims, k * n_dims : (k + 1) * n_dims] = block
    return out


def _promp_state(model: ProMP) -> tuple[dict, dict]:
    model.check_fitted()
    state = {
        "params": model.get_params(),
        "duration": float(model.duration_),
        "n_dims": int(model.n_dims_),
        "units": model.units_,
    }
    arrays = {
        "weight_mean_": model.weight_mean_,
        "weight_cov_": model.weight_cov_,
        "weights_": model.weights_,
    }
    return state, arrays


def _promp_from_state(cls, meta: dict, arrays) -> ProMP:
    from .._checks import check_loaded

    model = cls(**meta["params"])
    n_basis = check_int(model.n_basis, "n_basis", minimum=2, limit="max_kernels")
    n_dims = check_int(meta["n_dims"], "n_dims", minimum=1, limit="max_dims")
    size = n_basis * n_dims
    model.weight_mean_ = check_loaded(arrays["weight_mean_"], "weight_mean_", (size,))
    cov = check_loaded(arrays["weight_cov_"], "weight_cov_", (size, size))
    if not np.allclose(cov, cov.T, atol=1e-12 * max(np.abs(cov).max(), 1e-300)):
        raise ValueError("member weight_cov_ is not symmetric")
    model.weight_cov_ = cov
    model.weights_ = check_loaded(arrays["weights_"], "weights_", (None, size))
    model.duration_ = check_real(meta["duration"], "duration", positive=True)
    model.n_dims_ = n_dims
    model.units_ = "" if not meta["units"] else check_units(meta["units"])
    return model
