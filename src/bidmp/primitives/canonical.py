"""The canonical system: the phase ``ϑ`` that drives a DMP and its grid (paper Eq. 13).

``tau dϑ/dt = -alpha_phase ϑ``, ``ϑ(0) = 1``: solved exactly, ``ϑ = exp(-alpha_phase t / tau)``
(the robot protocol), or discretised by explicit Euler, ``ϑ[l] = (1 - alpha_phase dt / tau)^l``
(the paper's). Pure functions on normalised time; layer 1, imports only the checks.
"""

from __future__ import annotations

import numpy as np

from .._checks import check_bool, check_int, check_real

__all__ = ["phase_grid"]

# Kernels need distinct, representable phases over the training grid: e^-27.6 = 1e-12.
_MIN_TRAINING_PHASE_LOG = -27.6


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
        return np.exp(-alpha_phase * dt / tau * np.arange(n_steps))
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
