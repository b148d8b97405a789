"""Rhythmic DMPs (Ijspeert et al. 2013): periodic motions learned from a recording of several
periods and changed while they run (learned online: :mod:`bidmp.primitives.oscillator`).

Per dimension, in seconds, with the phase ``φ`` in radians and ``Ω = 1 / τ`` the angular frequency::

    τ ż = α (β (g - y) - z) + r f(φ),   τ ẏ = z,   τ φ̇ = 1
    f(φ) = Σ_i ψ_i(φ) w_i / Σ_i ψ_i(φ),  ψ_i = exp(h (cos(φ - c_i) - 1))   (von Mises)

``g`` is the anchor (the centre of the oscillation) and ``r`` the amplitude (1 as learned: the
oscillation about ``g`` scales with it, the system being linear). The phase and the basis are the
components :class:`~bidmp.primitives.RhythmicPhase` and :class:`~bidmp.primitives.VonMisesBasis`.

Learning from a recording (:meth:`RhythmicDMP.fit`): the frequency is estimated
(:func:`~bidmp.primitives.estimate_frequency`, in :mod:`bidmp.primitives.frequency`: a spectral
peak refined by least squares of a harmonic series over all kept samples, with its standard
error), the transients at both ends are cut (where the
one-period RMS envelope is below 9/10 of the steady part's), and the forcing target is computed
from that harmonic series — the mean period of every kept period at once, differentiated
analytically (no numerical derivative of noisy, jittered samples) — and regressed on the basis.

Changing frequency, amplitude and anchor while running (:class:`RhythmicStepper`): each passes
through a critically damped second-order filter of time constant ``transition`` (s), so it and its
rate are continuous and no step in acceleration reaches the robot.

Layer 1: imports only the package's own math.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from .._api import Estimator, integer, real
from .._checks import (
    SLOWEST_HZ,
    _limit,
    as_point,
    as_trajectory,
    as_vector,
    check_bytes,
    check_choice,
    check_int,
    check_names,
    check_real,
)
from .._state import state_reader
from .._threads import single_threaded
from .._units import check_units
from .canonical import RhythmicPhase
from .forcing import VonMisesBasis
from .frequency import _MAX_HARMONICS, _series, _with_frequency, estimate_frequency
from .integrate import _exact_responses, _exact_state, _foh_step
from .timing import Trajectory, check_timestamps

__all__ = ["RhythmicDMP", "RhythmicStepper"]

logger = logging.getLogger(__name__)


class RhythmicDMP(Estimator):
    """A rhythmic DMP (Ijspeert et al. 2013) learned from a recording of several periods.

    Parameters
    ----------
    n_kernels : int
        Von Mises functions per cycle (the forcing term's resolution).
    alpha : float
        Spring gain α (1/s in units of the period's τ); ``beta = alpha / 4`` (critically damped).
    concentration : float, optional
        The von Mises concentration ``h``; default ``2.5 · n_kernels``.
    n_harmonics : int, optional
        Harmonics of the series the forcing target is taken from; default chosen by BIC.
    ridge : float
        Ridge regulariser, relative to the mean diagonal of ``ΦᵀΦ``.

    Attributes
    ----------
    frequency_ : float
        The learned frequency (Hz).
    estimate_ : FrequencyEstimate
        How it was estimated (uncertainty, steady part, period-to-period spread).
    anchor_ : array (D,)
        The centre of the oscillation (units).
    amplitude_ : array (D,)
        Half the learned cycle's peak-to-peak per dimension (units).
    weights_ : array (N, D)
    """

    # What each parameter may be (checked by set_params and fit). A spring weaker than 1e-3
    # never pulls onto the cycle (a denormal one made the period's transition singular).
    _parameter_constraints = {
        "n_kernels": integer(minimum=2, limit="max_kernels"),
        "alpha": real(minimum=1e-3, maximum=1e4),
        "concentration": real(optional=True, positive=True, maximum=1e6),
        "n_harmonics": integer(optional=True, minimum=1, maximum=4 * _MAX_HARMONICS),
        "ridge": real(nonnegative=True, maximum=1.0),
    }

    def __init__(
        self,
        n_kernels: int = 50,
        alpha: float = 25.0,
        concentration: float | None = None,
        n_harmonics: int | None = None,
        ridge: float = 1e-8,
    ) -> None:
        self.n_kernels = n_kernels
        self.alpha = alpha
        self.concentration = concentration
        self.n_harmonics = n_harmonics
        self.ridge = ridge

    # -- learning ---------------------------------------------------------------------------
    @single_threaded  # small dense algebra: idle BLAS threads only steal the core
    def fit(self, y, t, units: str | None = None, names=None, frequency: float | None = None):
        """Learn from a recording ``y`` (T, D) at stamps ``t`` (s) of at least 2 periods
        (transients at both ends are cut); ``frequency`` (Hz) skips the estimate of it (the
        steady part is still found). Returns self."""
        self._check_constraints()
        n_kernels, alpha, ridge = int(self.n_kernels), float(self.alpha), float(self.ridge)
        basis = VonMisesBasis(n_kernels, self.concentration)
        y = as_trajectory(y, "y", min_points=8)
        t = check_timestamps(t, y.shape[0])
        units = "" if units is None else check_units(units)
        names = check_names(names, y.shape[1])
        estimate = estimate_frequency(y, t, n_harmonics=self.n_harmonics)
        if frequency is not None:
            frequency = check_real(frequency, "frequency", minimum=SLOWEST_HZ, maximum=1e3)
            estimate = _with_frequency(estimate, y, t, frequency)
        # the mean period's series over every kept period, as the estimate fitted it
        coefficients = estimate.series
        harmonics = estimate.n_harmonics
        # The target on a fine grid of one cycle: every kept period at once, through the series.
        n_grid = max(20 * n_kernels, 1000)
        phase = 2.0 * math.pi * np.arange(n_grid) / n_grid
        position, slope, curvature = (
            _series(coefficients, phase, harmonics, order) for order in (0, 1, 2)
        )
        anchor = coefficients[0]
        target = _rhythmic_target(position, slope, curvature, anchor, alpha)
        centres, widths = basis.place(RhythmicPhase(), n_grid, 1.0)
        rows = basis.rows(phase, centres, widths)
        gram = rows.T @ rows
        reg = ridge * np.trace(gram) / n_kernels
        weights = np.linalg.solve(gram + reg * np.eye(n_kernels), rows.T @ target)
        if not np.all(np.isfinite(weights)):
            raise ValueError(
                "fit: the learned weights are not finite; the recording's scale is out of range"
            )
        self.weights_ = weights
        self.centres_, self.widths_ = centres, widths
        self.anchor_ = anchor.copy()
        self.frequency_ = estimate.frequency
        self.estimate_ = estimate
        self.amplitude_ = estimate.amplitude
        self.units_ = units
        self.names_ = names
        self.n_dims_ = y.shape[1]
        logger.debug(
            "fitted a rhythmic DMP: %.5g Hz ± %.2g over %d periods, spread %.3g",
            estimate.frequency,
            estimate.uncertainty,
            estimate.periods,
            estimate.spread,
        )
        return self

    def check_fitted(self) -> None:
        """Raise :class:`bidmp.NotFittedError`, saying what to do, unless the model is fitted."""
        if "weights_" not in self.__dict__:
            from .._checks import NotFittedError

            raise NotFittedError("this RhythmicDMP is not fitted yet: call fit(y, t) first")

    @property
    def _basis(self) -> VonMisesBasis:
        """The von Mises basis of the learned kernels (made once per model)."""
        basis = self.__dict__.get("_basis_cache")
        if basis is None or basis.size != len(self.centres_):
            basis = VonMisesBasis(len(self.centres_), float(self.widths_[0]))
            self._basis_cache = basis
        return basis

    def forcing(self, phase) -> np.ndarray:
        """The learned forcing term ``f(φ)`` (L, D) at phases (rad), amplitude 1."""
        self.check_fitted()
        phase = as_vector(phase, "phase")
        check_bytes(phase.size * len(self.centres_), "the basis rows at phase (phases x kernels)")
        return self._basis.rows(phase, self.centres_, self.widths_) @ self.weights_

    def cycle_start(
        self,
        frequency: float | None = None,
        amplitude: float = 1.0,
        anchor=None,
        dt: float | None = None,
    ):
        """The state ``(y, ẏ)`` (units, units/s) at phase 0 on the limit cycle for these settings:
        the periodic solution of the sampled system (the fixed point of one period's transition
        ``x* = Φ_T x* + x_forced``): exact on the grid of a rollout whose period is a whole number
        of its steps ``dt`` (s), otherwise on a grid of ``max(2000, ⌈period / dt⌉)`` steps per
        period, within the input's first-order hold (about 1e-5 of the amplitude)."""
        frequency, amplitude, anchor = self._settings(frequency, amplitude, anchor)
        omega = 2.0 * math.pi * frequency
        n = 2000
        if dt is not None:
            per_period = 1.0 / (frequency * check_real(dt, "dt", positive=True, maximum=1.0))
            _check_samples(per_period, "a period's steps (1 / (frequency * dt))")
            whole = round(per_period)
            # A whole number of the rollout's own steps: solve on exactly its grid.
            n = (
                whole
                if abs(per_period - whole) <= 1e-9 * per_period
                else max(n, math.ceil(per_period))
            )
        step = 1.0 / (frequency * n)
        tau = 1.0 / omega
        # One period from rest at 0 (the forced response), one sample past it for its state.
        phase = omega * step * np.arange(n + 2)
        inputs = self._inputs(phase, amplitude, anchor)
        zeros = np.zeros(self.n_dims_)
        forced = _exact_responses(
            inputs.T, zeros, zeros, step=step, alpha=self._alpha, beta=self._beta, tau=tau
        )
        transition = _period_transition(step, n, self._alpha, self._beta, tau)
        z_forced = _exact_state(
            forced.T[n:], inputs[n:], step=step, alpha=self._alpha, beta=self._beta, tau=tau
        )[0][0]
        end = np.stack([forced[:, n], z_forced])  # the state [y, z] after one period, (2, D)
        fixed = np.linalg.solve(np.eye(2) - transition, end)
        return fixed[0], fixed[1] / tau

    def _shape_peaks(self) -> tuple[float, float, float, float]:
        """The learned cycle at amplitude 1 as a function of the phase: the largest norms of
        ``y - g`` and its first three derivatives in φ (the same at any frequency)."""
        cached = self.__dict__.get("_shape_cache")
        if cached is not None and cached[0] is self.weights_:
            return cached[1]
        n = 4000
        dt = 1.0 / (self.frequency_ * n)
        motion = self.trajectory(1.0, dt=dt)
        omega = 2.0 * math.pi * self.frequency_
        jerk = np.gradient(motion.ydd, dt, axis=0)
        peaks = (
            float(np.linalg.norm(motion.y - self.anchor_, axis=1).max()),
            float(np.linalg.norm(motion.yd, axis=1).max()) / omega,
            float(np.linalg.norm(motion.ydd, axis=1).max()) / omega**2,
            float(np.linalg.norm(jerk, axis=1).max()) / omega**3,
        )
        self._shape_cache = (self.weights_, peaks)
        return peaks

    @property
    def _alpha(self) -> float:
        # checked where it is used: set_params may have changed it since fit
        return check_real(self.alpha, "alpha", minimum=1e-3, maximum=1e4)

    @property
    def _beta(self) -> float:
        return self._alpha / 4.0

    def _settings(self, frequency, amplitude, anchor):
        self.check_fitted()
        frequency = (
            self.frequency_
            if frequency is None
            else check_real(frequency, "frequency", minimum=SLOWEST_HZ, maximum=1e3)
        )
        amplitude = check_real(amplitude, "amplitude", nonnegative=True, maximum=1e6)
        anchor = self.anchor_ if anchor is None else as_point(anchor, self.n_dims_, "anchor")
        return frequency, amplitude, anchor

    def _inputs(self, phase: np.ndarray, amplitude: float, anchor: np.ndarray) -> np.ndarray:
        """``u = α β g + r f(φ)`` (L, D) at phases (L,)."""
        return self._alpha * self._beta * anchor + amplitude * self.forcing(phase)

    # -- motions ----------------------------------------------------------------------------
    def trajectory(
        self,
        cycles: float = 1.0,
        *,
        dt: float = 0.001,
        frequency: float | None = None,
        amplitude: float = 1.0,
        anchor=None,
    ) -> Trajectory:
        """``cycles`` periods on the limit cycle (started on it at phase 0), sampled every ``dt``
        seconds, exact (first-order hold): positions, velocities and accelerations."""
        frequency, amplitude, anchor = self._settings(frequency, amplitude, anchor)
        cycles = check_real(cycles, "cycles", positive=True, maximum=1e5)
        dt = check_real(dt, "dt", positive=True, maximum=1.0)
        steps = _check_samples(cycles / (frequency * dt), "cycles / (frequency * dt)")
        if steps < 1.0 - 1e-9:
            raise ValueError(
                f"cycles: {cycles:g} cycles at {frequency:.4g} Hz last less than one step dt = {dt:g} s"
            )
        n = int(math.floor(steps + 1e-9)) + 1
        omega = 2.0 * math.pi * frequency
        tau = 1.0 / omega
        phase = omega * dt * np.arange(n + 1)
        inputs = self._inputs(phase, amplitude, anchor)
        y0, v0 = self.cycle_start(frequency, amplitude, anchor, dt)
        positions = _exact_responses(
            inputs.T, y0, tau * v0, step=dt, alpha=self._alpha, beta=self._beta, tau=tau
        ).T
        z, acceleration = _exact_state(
            positions, inputs, step=dt, alpha=self._alpha, beta=self._beta, tau=tau
        )
        z[0] = tau * v0
        acceleration[0] = (
            inputs[0] - self._alpha * self._beta * positions[0] - self._alpha * z[0]
        ) / tau**2
        return Trajectory(
            np.arange(n) * dt,
            positions[:n],
            z[:n] / tau,
            acceleration[:n],
            self.units_,
            tuple(self.names_ or ()),
        )

    def rollout(self, cycles: float = 1.0, **settings) -> np.ndarray:
        """Positions (n, D) of :meth:`trajectory`."""
        return self.trajectory(cycles, **settings).y

    def stepper(
        self,
        *,
        frequency: float | None = None,
        amplitude: float = 1.0,
        anchor=None,
        start: str = "cycle",
        transition: float | None = None,
        limits: dict | None = None,
    ) -> RhythmicStepper:
        """A control-loop stepper (:class:`RhythmicStepper`) started on the limit cycle
        (``start="cycle"``) or at rest at the anchor with the amplitude rising from 0
        (``"rest"``); ``limits`` as :class:`RhythmicStepper` takes them."""
        return RhythmicStepper(self, frequency, amplitude, anchor, start, transition, limits)

    def run(  # noqa: PLR0913 - the public call spells its options out, as users pass them
        self,
        cycles: float,
        *,
        dt: float = 0.001,
        frequency: float | None = None,
        amplitude: float = 1.0,
        anchor=None,
        transition: float | None = None,
        settle: float = 1e-3,
        limits: dict | None = None,
    ) -> Trajectory:
        """From rest at the anchor into the rhythm and back to rest: the amplitude rises from 0
        (a critically damped filter of time constant ``transition``), ``cycles`` periods run,
        then it falls to 0 and the motion settles at the anchor (until within ``settle`` × the
        amplitude, at rest; ``settle`` in [1e-9, 0.5]: below 1e-9 of the amplitude the rest is
        rounding, not motion). Smooth at both ends: acceleration 0 at the first and last sample.
        The settling runs at most as long as the filter and the spring take to decay by
        ``settle`` (a bound computed before it starts); a motion that cannot come that near in
        floating point (an anchor far larger than the amplitude) is refused naming ``settle``."""
        cycles = check_real(cycles, "cycles", positive=True, maximum=1e5)
        settle = check_real(settle, "settle", positive=True, maximum=0.5)
        if settle < _SETTLE_FLOOR:
            raise ValueError(
                f"settle must be >= {_SETTLE_FLOOR:g} (the smallest meaningful share of the "
                f"amplitude: below it the rest is rounding), got {settle:g}"
            )
        stepper = self.stepper(
            frequency=frequency,
            amplitude=amplitude,
            anchor=anchor,
            start="rest",
            transition=transition,
            limits=limits,
        )
        dt = check_real(dt, "dt", positive=True, maximum=1.0)
        # The rise, the cycles and the settling (a few transition times) must fit the limit.
        _check_samples(
            (cycles + 8.0) / (stepper.frequency * dt) + 12.0 * stepper.time_constant / dt,
            "the run's samples ((cycles + settling) / (frequency * dt))",
        )
        samples = [stepper.step(dt)]
        scale = max(float(np.max(self.amplitude_)) * max(amplitude, 1e-12), 1e-12)
        limit = int(_limit("max_steps"))
        while stepper.cycles < cycles and len(samples) < limit:
            samples.append(stepper.step(dt))
        stepper.stop()
        # The settling's own bound: what it needs to decay by ``settle``, not the step limit
        # (two million stepped samples are minutes).
        limit = min(limit, len(samples) + _settling_steps(stepper, self._alpha, settle, dt))
        rest_for, off = 0, np.inf
        while len(samples) < limit:
            y, v, a = stepper.step(dt)
            samples.append((y, v, a))
            off = max(np.max(np.abs(y - stepper.anchor)), np.max(np.abs(v)) * stepper.period)
            rest_for = rest_for + 1 if off <= settle * scale else 0
            if rest_for * dt >= stepper.period:
                break
        else:
            raise ValueError(
                f"settle: the motion comes no nearer its anchor at rest than {off / scale:.3g} x "
                f"the amplitude (the rounding of its numbers); give settle >= {2 * off / scale:.2g}"
            )
        y, v, a = (np.array(part) for part in zip(*samples))
        return Trajectory(np.arange(len(y)) * dt, y, v, a, self.units_, tuple(self.names_ or ()))

    # -- persistence (used by bidmp.io) -----------------------------------------------------
    def to_state(self) -> tuple[dict, dict]:
        """The model-file form of the fitted model, ``(meta, arrays)``: its parameters and scalars
        as a JSON-able dict, its learned arrays by name (:func:`bidmp.io.save_model` writes the two
        into one ``.npz``; no pickle). Raises :class:`bidmp.NotFittedError` before ``fit``."""
        self.check_fitted()
        estimate = self.estimate_
        state = {
            "params": self.get_params(),
            "frequency": float(self.frequency_),
            "units": self.units_,
            "names": list(self.names_ or []),
            "estimate": None
            if estimate is None
            else {
                "uncertainty": float(estimate.uncertainty),
                "n_harmonics": int(estimate.n_harmonics),
                "start": float(estimate.start),
                "end": float(estimate.end),
                "periods": int(estimate.periods),
                "spread": float(estimate.spread),
            },
        }
        arrays = {
            "weights_": self.weights_,
            "centres_": self.centres_,
            "widths_": self.widths_,
            "anchor_": self.anchor_,
            "amplitude_": self.amplitude_,
        }
        return state, arrays

    @classmethod
    @state_reader
    def from_state(cls, meta: dict, arrays) -> RhythmicDMP:
        """The fitted model :meth:`to_state` described: ``meta`` as written, ``arrays`` a mapping of
        name to array, each read when needed and checked for dtype, shape and finiteness
        (:func:`bidmp.io.load_model` calls it; a bad file raises, naming the member)."""
        from .._checks import check_loaded
        from .frequency import FrequencyEstimate

        model = cls(**meta["params"])
        n_kernels = check_int(model.n_kernels, "n_kernels", minimum=2, limit="max_kernels")
        model.weights_ = check_loaded(arrays["weights_"], "weights_", (n_kernels, None))
        n_dims = model.weights_.shape[1]
        model.centres_ = check_loaded(arrays["centres_"], "centres_", (n_kernels,))
        model.widths_ = check_loaded(arrays["widths_"], "widths_", (n_kernels,), positive=True)
        model.anchor_ = check_loaded(arrays["anchor_"], "anchor_", (n_dims,))
        model.amplitude_ = check_loaded(arrays["amplitude_"], "amplitude_", (n_dims,))
        model.frequency_ = check_real(
            meta["frequency"], "frequency", minimum=SLOWEST_HZ, maximum=1e3
        )
        model.units_ = "" if not meta["units"] else check_units(meta["units"])
        model.names_ = check_names(meta["names"] or None, n_dims)
        model.n_dims_ = n_dims
        found = meta["estimate"]
        model.estimate_ = (
            None
            if found is None
            else FrequencyEstimate(
                frequency=model.frequency_,
                uncertainty=check_real(found["uncertainty"], "uncertainty", nonnegative=True),
                n_harmonics=check_int(found["n_harmonics"], "n_harmonics", minimum=1),
                start=check_real(found["start"], "start", nonnegative=True),
                end=check_real(found["end"], "end", nonnegative=True),
                periods=check_int(found["periods"], "periods", minimum=1),
                spread=check_real(found["spread"], "spread", nonnegative=True),
                amplitude=model.amplitude_,
            )
        )
        return model


def _rhythmic_target(position, slope, curvature, anchor, alpha: float) -> np.ndarray:
    """The forcing term that makes ``τż = α(β(g − y) − z) + f`` follow a cycle given as a
    function of the phase: ``f = y'' − α(β(g − y) − y')`` with ``y' = dy/dφ``, ``y'' = d²y/dφ²``
    (``τ²ÿ = y''`` and ``τẏ = y'`` for ``τφ̇ = 1``: the same at any frequency), β = α/4."""
    return curvature - alpha * (alpha / 4.0 * (anchor - position) - slope)


def _period_transition(step: float, n: int, alpha: float, beta: float, tau: float) -> np.ndarray:
    """The free system's transition over ``n`` steps (2, 2) for the state ``[y, z]``."""
    transition = _foh_step(step, alpha, beta, tau)[0]
    return np.linalg.matrix_power(transition, n)


# The smallest ``settle`` of :meth:`RhythmicDMP.run`: a share of the amplitude below which the
# rest is rounding (float64 resolves 2e-16 of the anchor's magnitude).
_SETTLE_FLOOR = 1e-9


def _settling_steps(stepper: RhythmicStepper, alpha: float, settle: float, dt: float) -> int:
    """An upper bound of the steps (of ``dt`` s) a stopped ``stepper`` takes to settle within
    ``settle`` of its amplitude, at rest, for a period.

    Two critically damped systems in series: the amplitude's filter (time constant T) and the
    spring (rate λ = α / (2τ), τ = period / 2π). Each decays as ``(1 + x) e^{-x}`` in its own
    time ``x``; the velocity test scales it by the period over the time constant. With ``L =
    ln(1 / settle) + ln(1 + P / T + λ P)``, ``x = L + 2 ln(1 + L) + 2`` makes ``(1 + x) e^{-x}``
    at most ``e^{-L}``; the two times add (the spring follows the filter), then a period at
    rest and one more of margin."""
    period = stepper.period
    constant = stepper.time_constant
    rate = alpha * math.pi / period
    share = math.log(1.0 / settle) + math.log1p(period / constant + rate * period)
    span = share + 2.0 * math.log1p(share) + 2.0
    seconds = 1.5 * span * (constant + 1.0 / rate) + 2.0 * period
    return int(min(seconds / dt, float(_limit("max_steps")))) + 2


def _check_samples(count: float, what: str) -> float:
    """Refuse a motion of more samples than the configured limit (``bidmp.set_limits``)."""
    limit = _limit("max_steps")
    if not count <= limit:
        raise ValueError(
            f"dt: {what} = {count:.4g} samples, more than the limit {limit} (bidmp.set_limits); "
            "raise dt"
        )
    return count


def _check_rhythm_limits(limits) -> dict:
    """``limits`` as a dict of positive caps among max_velocity, max_acceleration, max_jerk."""
    if limits is None:
        return {}
    if not isinstance(limits, dict):
        raise TypeError(
            f"limits must be a dict of max_velocity / max_acceleration / max_jerk, got "
            f"{type(limits).__name__}"
        )
    known = ("max_velocity", "max_acceleration", "max_jerk")
    unknown = sorted(str(key) for key in limits if key not in known)
    if unknown:
        raise ValueError(
            f"limits has an unknown key {unknown[0][:40]!r}; known: {', '.join(known)}"
        )
    return {
        key: check_real(value, f"limits[{key!r}]", positive=True)
        for key, value in limits.items()
        if value is not None
    }


class _CriticalFilter:
    """A critically damped second-order filter ``p̈ = ω² (p* - p) - 2 ω ṗ`` of time constant
    ``1 / ω``, stepped exactly: the output and its rate are continuous whatever the command."""

    def __init__(self, value, time_constant: float) -> None:
        self.value = np.array(value, dtype=float)
        self.rate = np.zeros_like(self.value)
        self.target = self.value.copy()
        self.time_constant = time_constant

    def step(self, dt: float) -> None:
        # ``p = p* + (e (1 + x) + ṗ dt) e^{-x}``, ``ṗ = ṗ (1 - x) e^{-x} - e x² e^{-x} / dt`` with
        # ``x = dt / T``, written with ``x e^{-x}`` (at most 1/e) so that a time constant far
        # below the step (1e-300 s: the setting jumps) gives 0, not inf times 0; past x = 746
        # e^{-x} is 0 in float64, so capping x changes nothing but keeps it finite.
        x = min(dt / self.time_constant, 1e6)
        decay = math.exp(-x)
        share = x * decay
        error = self.value - self.target
        self.value = self.target + error * (decay + share) + self.rate * (dt * decay)
        self.rate = self.rate * (decay - share) - error * (share * x / dt)


class RhythmicStepper:
    """A rhythmic DMP one control step at a time, its frequency, amplitude and anchor changed
    while it runs.

    ``step(dt)`` returns ``(y, ẏ, ÿ)`` (units, units/s, units/s²) at the current sample and
    advances by ``dt`` seconds. :meth:`set_frequency`, :meth:`set_amplitude`,
    :meth:`set_anchor` and :meth:`stop` set targets that each setting follows through a
    critically damped filter of time constant ``transition`` (s; default a quarter of the
    longer of the two periods, lengthened where ``limits`` ask): the settings and their rates are
    continuous, so no step in acceleration reaches the robot; a change is 95 % done after about
    4.7 time constants. ``limits`` (``max_velocity``, ``max_acceleration``, ``max_jerk``: the
    norms' caps, units/s^k, as for a discrete trajectory) refuse a setting whose steady rhythm
    exceeds them and set the time constant so that the change stays within them.

    Each step is exact for the settings held over it (the spring's transition for that τ, the
    input linear over the step).
    """

    def __init__(self, model, frequency, amplitude, anchor, start, transition, limits=None) -> None:
        frequency, amplitude, anchor = model._settings(frequency, amplitude, anchor)
        start = check_choice(start, "start", ("cycle", "rest"))
        self._model = model
        self._transition = (
            None
            if transition is None
            else check_real(transition, "transition", positive=True, maximum=1e4)
        )
        self._limits = _check_rhythm_limits(limits)
        self._check_setting(frequency, amplitude, "the start's settings")
        self._frequency = _CriticalFilter(frequency, 1.0)
        self._amplitude = _CriticalFilter(amplitude if start == "cycle" else 0.0, 1.0)
        self._anchor = _CriticalFilter(anchor, 1.0)
        if start == "rest":
            self._amplitude.target = np.array(float(amplitude))
            self.y, self.v = anchor.copy(), np.zeros(model.n_dims_)
        else:
            self.y, self.v = model.cycle_start(frequency, amplitude, anchor)
        self._retime()
        self.phase = 0.0
        self.cycles = 0.0
        self.time = 0.0
        self._u = self._input()  # the input now; a step's end is the next one's start

    def _check_setting(self, frequency: float, amplitude: float, what: str) -> None:
        """Refuse a setting whose steady rhythm exceeds the limits (peak velocity, acceleration,
        jerk: ``r Ω^k max|d^k y / dφ^k|`` of the learned cycle)."""
        if not self._limits:
            return
        shape = self._model._shape_peaks()
        omega = 2.0 * math.pi * frequency
        for order, (key, unit) in enumerate(
            (("max_velocity", "/s"), ("max_acceleration", "/s^2"), ("max_jerk", "/s^3")), start=1
        ):
            limit = self._limits.get(key)
            peak = amplitude * omega**order * shape[order]
            if limit is not None and peak > limit:
                raise ValueError(
                    f"{what}: at {frequency:.4g} Hz and amplitude {amplitude:.4g} the rhythm's peak "
                    f"{key[4:]} is {peak:.4g} units{unit}, over {key} = {limit:g}"
                )

    def _retime(self) -> None:
        """One time constant for the three settings' filters: ``transition`` when given, else a
        quarter of the longer period, lengthened until the change's first-order bound on the
        peaks stays within the limits (when given)."""
        if self._transition is not None:
            constant = self._transition
        else:
            frequencies = (float(self._frequency.value), float(self._frequency.target))
            constant = 0.25 / min(frequencies)
            if self._limits:
                constant = self._limited_constant(constant)
        for part in (self._frequency, self._amplitude, self._anchor):
            part.time_constant = constant

    def _limited_constant(self, constant: float) -> float:
        """The shortest time constant from ``constant`` up (by 20 % steps) whose bound holds.

        The rhythm is ``y = g + r c(φ)`` with ``φ̇ = Ω`` and a cycle ``c`` learned at amplitude 1
        (the same path in φ at any Ω), so ``ẏ = r Ω c' + ṙ c + ġ``, ``ÿ = r Ω² c'' + r Ω̇ c' + 2 ṙ Ω c'
        + r̈ c + g̈`` and the jerk likewise; a critically damped filter moving a setting by Δ has
        ``|ṗ| ≤ Δ / (e T)``, ``|p̈| ≤ Δ / T²``, ``|p⃛| ≤ 2 Δ / T³``. The bound sums the terms'
        maxima at the larger of the old and new settings."""
        d0, d1, d2, d3 = self._model._shape_peaks()
        omegas = 2.0 * math.pi * np.array([self._frequency.value, self._frequency.target])
        amplitudes = np.array([self._amplitude.value, self._amplitude.target], dtype=float)
        omega, r = float(omegas.max()), float(amplitudes.max())
        d_omega = float(abs(omegas[1] - omegas[0]))
        d_r = float(abs(amplitudes[1] - amplitudes[0]))
        d_g = float(np.linalg.norm(self._anchor.target - self._anchor.value))

        def peaks(t: float) -> tuple[float, float, float]:
            rate, second, third = 1.0 / (math.e * t), 1.0 / t**2, 2.0 / t**3
            velocity = r * omega * d1 + d_r * d0 * rate + d_g * rate
            acceleration = (
                r * omega**2 * d2
                + r * d_omega * d1 * rate
                + 2.0 * d_r * omega * d1 * rate
                + d_r * d0 * second
                + d_g * second
            )
            jerk = (
                r * omega**3 * d3
                + 3.0 * r * omega * d_omega * d2 * rate
                + r * d_omega * d1 * second
                + 3.0 * d_r * omega**2 * d2 * rate
                + 3.0 * d_r * omega * d1 * second
                + 2.0 * d_r * d0 * third
                + 2.0 * d_g * third
            )
            return velocity, acceleration, jerk

        keys = ("max_velocity", "max_acceleration", "max_jerk")
        while constant < 1e4:
            if all(
                self._limits.get(key) is None or value <= self._limits[key]
                for key, value in zip(keys, peaks(constant))
            ):
                return constant
            constant *= 1.2
        raise ValueError("limits: no transition of up to 1e4 s keeps this change within them")

    @property
    def time_constant(self) -> float:
        """The settings' filter time constant now (s)."""
        return float(self._frequency.time_constant)

    @property
    def frequency(self) -> float:
        """The frequency in use now (Hz), on its way to the last one set."""
        return float(self._frequency.value)

    @property
    def anchor(self) -> np.ndarray:
        return self._anchor.value.copy()

    @property
    def period(self) -> float:
        return 1.0 / self.frequency

    def set_frequency(self, frequency: float) -> None:
        """Move to ``frequency`` (Hz); refused if its steady rhythm exceeds the limits."""
        frequency = check_real(frequency, "frequency", minimum=SLOWEST_HZ, maximum=1e3)
        self._check_setting(frequency, float(self._amplitude.target), "frequency")
        self._frequency.target = np.array(frequency)
        self._retime()

    def set_amplitude(self, amplitude: float) -> None:
        """Move to ``amplitude`` (× the learned swing); refused if it exceeds the limits."""
        amplitude = check_real(amplitude, "amplitude", nonnegative=True, maximum=1e6)
        self._check_setting(float(self._frequency.target), amplitude, "amplitude")
        self._amplitude.target = np.array(amplitude)
        self._retime()

    def set_anchor(self, anchor) -> None:
        """Move the oscillation's centre to ``anchor`` (D,) (units)."""
        self._anchor.target = as_point(anchor, self._model.n_dims_, "anchor")
        self._retime()

    def stop(self) -> None:
        """Let the amplitude fall to 0: the motion settles at the anchor, at rest."""
        self._amplitude.target = np.array(0.0)
        self._retime()

    def _input(self) -> np.ndarray:
        """``u = α β g + r f(φ)`` (D,) at the settings and phase now."""
        model = self._model
        forcing = model._basis.row(self.phase, model.centres_, model.widths_)[0] @ model.weights_
        return (
            model._alpha * model._beta * self._anchor.value + float(self._amplitude.value) * forcing
        )

    def _acceleration(self, u: np.ndarray) -> np.ndarray:
        model = self._model
        omega = 2.0 * math.pi * self.frequency
        tau = 1.0 / omega
        z = tau * self.v
        return (u - model._alpha * model._beta * self.y - model._alpha * z) / tau**2

    def step(self, dt: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        dt = check_real(dt, "dt", positive=True, maximum=1.0)
        model = self._model
        u_now = self._u
        out = (self.y.copy(), self.v.copy(), self._acceleration(u_now))
        omega = 2.0 * math.pi * self.frequency
        tau = 1.0 / omega
        transition, now, after = _foh_step(dt, model._alpha, model._beta, tau)
        # The settings move over the step; the phase advances by the mean frequency.
        for part in (self._frequency, self._amplitude, self._anchor):
            part.step(dt)
        omega_next = 2.0 * math.pi * self.frequency
        advance = 0.5 * (omega + omega_next) * dt
        self.phase = math.fmod(self.phase + advance, 2.0 * math.pi)
        self.cycles += advance / (2.0 * math.pi)
        self.time += dt
        u_next = self._u = self._input()
        z = tau * self.v
        y_next = (
            transition[0, 0] * self.y + transition[0, 1] * z + now[0] * u_now + after[0] * u_next
        )
        z_next = (
            transition[1, 0] * self.y + transition[1, 1] * z + now[1] * u_now + after[1] * u_next
        )
        self.y = y_next
        # z = τ ẏ with the τ of the step; the velocity is what carries over a change of τ.
        self.v = z_next / tau
        return out
