"""The canonical system: the phase ``ϑ`` that drives a DMP (paper Eq. 13), as a component.

A DMP asks its canonical system for the phase on a grid of samples, one control step at a time,
and at the fractional sample indices where its basis places kernels; what it asks is the
:class:`CanonicalSystem` protocol. The discrete DMP's is :class:`ExponentialPhase`:
``tau dϑ/dt = -alpha_phase ϑ``, ``ϑ(0) = 1``, solved exactly, ``ϑ = exp(-alpha_phase t / tau)``
(the robot protocol), or discretised by explicit Euler, ``ϑ[l] = (1 - alpha_phase dt / tau)^l``
(the paper's). A rhythmic DMP's phase (one that advances at a frequency and wraps) is another
class with the same methods, given as ``DMP(canonical_system=...)``.

Times are normalised (the demonstration lasts one unit); layer 1, imports only the checks.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar, Protocol, runtime_checkable

import numpy as np

from .._checks import _as_bounded_array, as_points, as_vector, check_bool, check_int, check_real

__all__ = ["phase_grid", "CanonicalSystem", "ExponentialPhase", "RhythmicPhase"]

# Kernels need distinct, representable phases over the training grid: e^-27.6 = 1e-12.
_MIN_TRAINING_PHASE_LOG = -27.6
# A DMP's gains, temporal scaling and one step of normalised time (a motion lasts 1) stay within
# these: beyond them float64 leaves its range in the forcing target or the integration.
_MAX_RATE = 1e6
_TAU_RANGE = (1e-6, 1e6)
_MAX_STEP = 1e3


def _phase_decay(dt: float, tau: float, alpha_phase: float) -> float:
    """Per-step factor of the Euler-discretised canonical system (Eq. 13); refused unless in (0, 1)."""
    decay = 1.0 - alpha_phase * dt / tau
    if not 0.0 < decay < 1.0:
        raise ValueError(
            f"alpha_phase * dt / tau must lie in (0, 1) for a decaying phase, got "
            f"{alpha_phase * dt / tau:g} (alpha_phase={alpha_phase:g}, dt={dt:g}, tau={tau:g})"
        )
    return decay


def phase_grid(
    n_steps: int, dt: float, tau: float = 1.0, alpha_phase: float = 1.0, *, exact: bool = False
) -> np.ndarray:
    """Phase at every step (shape ``(n_steps,)``): ``(1 - alpha_phase dt / tau) ** l``, the
    Euler-discretised canonical system (Eq. 13), or with ``exact`` its solution
    ``exp(-alpha_phase l dt / tau)``, which does not depend on the step."""
    n_steps = check_int(n_steps, "n_steps", minimum=1, limit="max_steps")
    dt, tau, alpha_phase, exact = _checked_phase_args(dt, tau, alpha_phase, exact)
    if exact:
        # (a rate of inf, from a 5e-324 s tau, times the first step's 0 would be NaN: capped
        # where e^-rate is 0 anyway, the same numbers otherwise)
        rate = min(alpha_phase * dt / tau, 1e300)
        return np.exp(-rate * np.arange(n_steps))
    return _phase_decay(dt, tau, alpha_phase) ** np.arange(n_steps)


def _checked_phase_args(dt, tau, alpha_phase, exact) -> tuple[float, float, float, bool]:
    """The canonical system's arguments as the public functions take them: positive finite
    ``dt``, ``tau`` and ``alpha_phase``, a bool ``exact``; an Euler step must not overshoot."""
    dt, tau = check_real(dt, "dt", positive=True), check_real(tau, "tau", positive=True)
    alpha_phase, exact = (
        check_real(alpha_phase, "alpha_phase", positive=True),
        check_bool(exact, "exact"),
    )
    if not exact and alpha_phase * dt / tau >= 1.0:
        raise ValueError(
            f"alpha_phase * dt / tau = {alpha_phase * dt / tau:.3g} must be < 1 (the Euler phase would not "
            f"decay); lower dt or use exact=True"
        )
    return dt, tau, alpha_phase, exact


def _check_phase_span(span: float, alpha_phase: float) -> None:
    """Refuse an ``alpha_phase`` that decays the phase below 1e-12 over the training grid (of
    ``span`` normalised time): its kernels' widths and weights would leave float64's range."""
    if -alpha_phase * span < _MIN_TRAINING_PHASE_LOG:
        raise ValueError(
            f"alpha_phase = {alpha_phase:g} decays the phase to e^{-alpha_phase * span:.4g} over "
            f"the demonstration; the kernels need at least e^{_MIN_TRAINING_PHASE_LOG:g}: lower alpha_phase"
        )


@runtime_checkable
class CanonicalSystem(Protocol):
    """What a :class:`~bidmp.DMP` asks of its phase (normalised time: the demonstration lasts 1).

    Attributes
    ----------
    initial : float
        The phase at the start of a motion.
    """

    initial: float

    def grid(self, n_steps: int, step: float, tau: float) -> np.ndarray:
        """The phase at ``n_steps`` samples ``step`` apart, shape ``(n_steps,)``."""
        ...

    def at(self, samples: np.ndarray, step: float, tau: float) -> np.ndarray:
        """The phase at fractional sample indices ``samples`` of that grid (where kernels go)."""
        ...

    def advance(self, phase: float, step: float, tau: float) -> float:
        """The phase ``step`` after ``phase`` (a control loop's step, as :meth:`grid` steps)."""
        ...

    def check_step(self, step: float, tau: float) -> None:
        """Refuse a step the discretisation cannot take (``ValueError``)."""
        ...

    def check_span(self, span: float) -> None:
        """Refuse a training grid of ``span`` normalised time whose phases a basis cannot tell
        apart (``ValueError``)."""
        ...

    def as_phase(self, phase, name: str = "phase") -> np.ndarray:
        """``phase`` validated as phases of this system, shape ``(L,)`` (``ValueError`` naming
        ``name`` otherwise)."""
        ...


@dataclass(frozen=True)
class ExponentialPhase:
    """The discrete DMP's canonical system: a phase that decays from 1 at ``rate`` (``alpha_phase``).

    Parameters
    ----------
    rate : float
        ``alpha_phase`` (per unit of normalised time).
    exact : bool
        The exact solution ``exp(-rate t / tau)`` (the same at any step) or the explicit-Euler
        recursion ``(1 - rate step / tau)^l`` (the paper's Eq. 13).
    """

    rate: float
    exact: bool = True
    initial: ClassVar[float] = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "rate", check_real(self.rate, "rate", positive=True, maximum=_MAX_RATE)
        )
        object.__setattr__(self, "exact", check_bool(self.exact, "exact"))

    def grid(self, n_steps: int, step: float, tau: float) -> np.ndarray:
        """The phase at ``n_steps`` samples ``step`` apart (:func:`phase_grid`)."""
        n_steps = check_int(n_steps, "n_steps", minimum=1, limit="max_steps")
        step, tau = self._step_args(step, tau)
        if self.exact:
            return np.exp(-self.rate * step / tau * np.arange(n_steps))
        return (1.0 - self.rate * step / tau) ** np.arange(n_steps)

    def at(self, samples: np.ndarray, step: float, tau: float) -> np.ndarray:
        """The phase at fractional sample indices (the Euler recursion continued between samples)."""
        samples = as_vector(samples, "samples")
        step, tau = self._step_args(step, tau)
        if self.exact:
            return np.exp(-self.rate * step / tau * samples)
        return np.exp(np.log(1.0 - self.rate * step / tau) * samples)

    def advance(self, phase: float, step: float, tau: float) -> float:
        """The phase ``step`` later, as :meth:`grid` steps (a control loop calls this every step,
        so arguments a stepper passes are checked by comparisons alone)."""
        if not (
            type(phase) is float
            and type(step) is float
            and type(tau) is float
            and 0.0 <= phase <= 1.0
            and 0.0 <= step <= _MAX_STEP
            and _TAU_RANGE[0] <= tau <= _TAU_RANGE[1]
        ):
            phase = check_real(phase, "phase", minimum=0.0, maximum=1.0)
            step = check_real(step, "step", nonnegative=True, maximum=_MAX_STEP)
            tau = check_real(tau, "tau", minimum=_TAU_RANGE[0], maximum=_TAU_RANGE[1])
        if self.exact:
            return phase * math.exp(-self.rate * step / tau)
        factor = 1.0 - self.rate * (step / tau)
        if factor <= 0.0:
            self.check_step(step, tau)
        return phase * factor

    def check_step(self, step: float, tau: float) -> None:
        """Refuse an Euler step that does not decay the phase (the exact solution takes any)."""
        self._step_args(step, tau)

    def check_span(self, span: float) -> None:
        """Refuse a training span (normalised time) over which the phase decays below 1e-12."""
        span = check_real(span, "span", positive=True, maximum=_MAX_STEP)
        if -self.rate * span < _MIN_TRAINING_PHASE_LOG:
            raise ValueError(
                f"span = {span:g}: alpha_phase = {self.rate:g} decays the phase to "
                f"e^{-self.rate * span:.4g} over it; the kernels need at least "
                f"e^{_MIN_TRAINING_PHASE_LOG:g}: lower alpha_phase"
            )

    def as_phase(self, phase, name: str = "phase") -> np.ndarray:
        """Phases in [0, 1], shape ``(L,)``."""
        return _as_phase(phase, name)

    def _step_args(self, step, tau) -> tuple[float, float]:
        """``step`` and ``tau`` checked; an Euler step must decay the phase."""
        step = check_real(step, "step", positive=True, minimum=1e-12, maximum=_MAX_STEP)
        tau = check_real(tau, "tau", minimum=_TAU_RANGE[0], maximum=_TAU_RANGE[1])
        if not self.exact and not self.rate * step / tau < 1.0:
            raise ValueError(
                f"alpha_phase * step / tau must lie in (0, 1) for a decaying Euler phase, got "
                f"{self.rate * step / tau:g} (alpha_phase={self.rate:g}, step={step:g}, "
                f"tau={tau:g}): take a smaller step"
            )
        return step, tau


def _as_phase(phase, name: str = "phase") -> np.ndarray:
    """Phases (L,) validated: finite and in [0, 1] (a DMP's phase decays from 1 towards 0)."""
    if not isinstance(name, str) or not name.isidentifier() or len(name) > 64:
        raise TypeError("name must be the argument's name (an identifier) to say in a refusal")
    phase = _as_bounded_array(phase, name, max_ndim=2)
    phase = as_points(phase.reshape(-1, 1) if phase.ndim <= 1 else phase, 1, name)[:, 0]
    if phase.size and (phase.min() < 0.0 or phase.max() > 1.0):
        raise ValueError(
            f"{name} must lie in [0, 1] (a DMP's phase decays from 1 towards 0), got values in "
            f"[{phase.min():.3g}, {phase.max():.3g}]"
        )
    return phase


@dataclass(frozen=True)
class RhythmicPhase:
    """The rhythmic DMP's canonical system: an angle that advances at ``1 / tau`` rad per unit of
    time (``tau φ̇ = 1``, so ``Ω = 1 / tau`` is the angular frequency) and wraps at 2π.

    A :class:`RhythmicDMP <bidmp.primitives.rhythmic.RhythmicDMP>` runs it in seconds
    (``tau = 1 / (2π f)``); the phase never decays, so nothing limits the span of a training grid.
    """

    initial: ClassVar[float] = 0.0

    def grid(self, n_steps: int, step: float, tau: float) -> np.ndarray:
        """The phase (rad, in [0, 2π)) at ``n_steps`` samples ``step`` apart."""
        n_steps = check_int(n_steps, "n_steps", minimum=1, limit="max_steps")
        return self.at(np.arange(n_steps, dtype=float), step, tau)

    def at(self, samples: np.ndarray, step: float, tau: float) -> np.ndarray:
        """The phase at fractional sample indices of that grid."""
        samples = as_vector(samples, "samples")
        step = check_real(step, "step", positive=True, maximum=_MAX_STEP)
        tau = check_real(tau, "tau", minimum=_TAU_RANGE[0], maximum=_TAU_RANGE[1])
        return np.mod(samples * (step / tau), 2.0 * math.pi)

    def advance(self, phase: float, step: float, tau: float) -> float:
        """The phase ``step`` later, wrapped to [0, 2π)."""
        phase = check_real(phase, "phase", minimum=-1e6, maximum=1e6)
        step = check_real(step, "step", nonnegative=True, maximum=_MAX_STEP)
        tau = check_real(tau, "tau", minimum=_TAU_RANGE[0], maximum=_TAU_RANGE[1])
        return math.fmod(phase + step / tau, 2.0 * math.pi) % (2.0 * math.pi)

    def check_step(self, step: float, tau: float) -> None:
        """Any positive step: the phase is integrated exactly."""
        check_real(step, "step", positive=True, maximum=_MAX_STEP)
        check_real(tau, "tau", minimum=_TAU_RANGE[0], maximum=_TAU_RANGE[1])

    def check_span(self, span: float) -> None:
        """Any positive span: the phase does not decay."""
        check_real(span, "span", positive=True)

    def as_phase(self, phase, name: str = "phase") -> np.ndarray:
        """Phases in radians, any finite values (wrapped by the basis), shape ``(L,)``."""
        if not isinstance(name, str) or not name.isidentifier() or len(name) > 64:
            raise TypeError("name must be the argument's name (an identifier) to say in a refusal")
        phase = _as_bounded_array(phase, name, max_ndim=2)
        return as_points(phase.reshape(-1, 1) if phase.ndim <= 1 else phase, 1, name)[:, 0]
