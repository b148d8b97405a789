"""Coupling terms: what the step integrator adds to a DMP's acceleration as it runs.

A coupling term is any callable ``coupling(t, y, yd, phase) -> acceleration`` (the
movement_primitives convention): ``t`` the motion's own time (s), ``y`` (D,) the commanded
position (units), ``yd`` (D,) its velocity (units/s), ``phase`` the canonical state; it returns
(D,) units/s² added to the motion's acceleration over the next control step (held constant over
the step). Pass a list of them as ``coupling=`` to :meth:`bidmp.DMP.trajectory`,
:meth:`bidmp.DMP.stepper` and the Bi-DMP and pose versions; each runs the step integrator
(:class:`bidmp.primitives.integrate.StepIntegrator`) instead of the fast path.

A *temporal* coupling term (Ijspeert et al. 2013, §3.3) changes how fast the system's time runs
instead: it has a ``slowdown(y, y_measured) -> float ≥ 1`` method. :class:`PhaseStopping` is one:
a robot held back makes the motion pause. Obstacle avoidance, via-points and the like are spatial
coupling terms and belong here, one small class each.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from .._checks import as_point, as_vector, check_real

__all__ = ["CouplingTerm", "PhaseStopping", "ConstantAcceleration"]


class CouplingTerm:
    """Base of the coupling terms (optional: any callable with the signature works).

    Subclasses implement ``__call__(t, y, yd, phase) -> acceleration (D,)`` in units/s².
    """

    def __call__(
        self, t: float, y: np.ndarray, yd: np.ndarray, phase: float
    ) -> np.ndarray:  # pragma: no cover
        raise NotImplementedError


class PhaseStopping(CouplingTerm):
    """Phase stopping (Ijspeert et al. 2013): the system's time runs ``1 + gain ‖y_measured - y‖²``
    times slower while the robot lags its command, so a held robot makes the motion pause rather
    than run away, and it resumes once the robot catches up.

    Parameters
    ----------
    gain : float
        ``alpha_e`` in 1/units² (0 turns it off).
    """

    def __init__(self, gain: float) -> None:
        self.gain = check_real(gain, "gain", nonnegative=True, maximum=1e6)

    def __call__(self, t: float, y: np.ndarray, yd: np.ndarray, phase: float) -> np.ndarray:
        return np.zeros_like(y)

    def slowdown(self, y: np.ndarray, y_measured) -> float:
        """How many times slower the system's time runs for a measurement ``y_measured`` (D,)."""
        # a stepper's own state passes as is
        if not (type(y) is np.ndarray and y.dtype == np.float64 and y.ndim == 1):
            y = as_vector(y, "y")
        if y_measured is None:
            return 1.0
        # checked even at gain 0 (no slowdown): a measurement that is no point is refused
        error = as_point(y_measured, y.shape[0], "y_measured", like="y") - y
        if self.gain == 0.0:
            return 1.0
        slowdown = 1.0 + self.gain * float(error @ error)
        if not math.isfinite(slowdown):
            raise ValueError("y must be finite numbers (the command), and so must y_measured")
        return slowdown


class ConstantAcceleration(CouplingTerm):
    """A constant push ``acceleration`` (D,) units/s² — a wind, a known bias, or a test of the
    integrator: on a critically damped DMP it moves the motion by the closed form
    ``a tau² / (αβ) (1 - (1 + ω t) e^{-ω t})`` (real time, ``ω = α / (2 tau)``)."""

    def __init__(self, acceleration) -> None:
        self.acceleration = as_vector(acceleration, "acceleration").copy()

    def __call__(self, t: float, y: np.ndarray, yd: np.ndarray, phase: float) -> np.ndarray:
        return np.broadcast_to(self.acceleration, y.shape)


def _as_couplings(coupling) -> tuple[list, list]:
    """Split ``coupling`` into (spatial terms, temporal terms).

    ``coupling`` is a number (the gain of a :class:`PhaseStopping` term: ``stepper(coupling=20.0)``),
    one coupling term, or a sequence of them; ``None`` is none.
    """
    if coupling is None:
        return [], []
    if isinstance(coupling, (int, float, np.integer, np.floating)) and not isinstance(
        coupling, bool
    ):
        return [], [PhaseStopping(check_real(coupling, "coupling", nonnegative=True, maximum=1e6))]
    terms = [coupling] if callable(coupling) else coupling
    if not isinstance(terms, Sequence) or isinstance(terms, (str, bytes)):
        raise TypeError(
            f"coupling must be a number (the phase-stopping gain), a coupling term or a list of them, "
            f"got {type(coupling).__name__}"
        )
    spatial, temporal = [], []
    for term in terms:
        if not callable(term):
            raise TypeError(
                f"coupling terms must be callable as coupling(t, y, yd, phase), got {type(term).__name__}"
            )
        (temporal if hasattr(term, "slowdown") else spatial).append(term)
    return spatial, temporal
