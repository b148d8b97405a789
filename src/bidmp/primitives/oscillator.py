"""Online learning of a periodic signal (Gams et al. 2009): an adaptive frequency oscillator
locks onto its fundamental, a Fourier series on its phase estimates it, and a rhythmic DMP's
weights are learned one sample at a time by recursive least squares with a forgetting factor.

Layer 1: the package's own math.
"""

from __future__ import annotations

import math

import numpy as np

from .._checks import SLOWEST_HZ, as_point, check_int, check_real
from .canonical import RhythmicPhase
from .forcing import VonMisesBasis
from .frequency import _series
from .rhythmic import RhythmicDMP, _rhythmic_target

__all__ = ["AdaptiveOscillator"]


class AdaptiveOscillator:
    """Online learning of a periodic signal of unknown or drifting frequency (Gams et al. 2009):
    an adaptive frequency oscillator locks onto the signal's fundamental, a Fourier series on its
    phase estimates the signal, and the rhythmic DMP's weights are learned one sample at a time
    by recursive least squares with a forgetting factor.

    Oscillator (per sample, ``e = y - ŷ`` summed over the dimensions' shares)::

        φ̇ = Ω - K e sin φ,   Ω̇ = -K e sin φ,
        ŷ = a_0 + Σ_k a_k cos kφ + b_k sin kφ,  ȧ_k = η e cos kφ, ḃ_k = η e sin kφ, ȧ_0 = η e

    Parameters
    ----------
    frequency : float
        Initial guess (Hz).
    n_harmonics : int
        Harmonics of the estimate ``ŷ``.
    coupling : float
        ``K`` (1/s), acting on the error over the signal's running RMS about its centre. The
        defaults (K = 5, η = 2) lock within 5 periods from a guess 20 % off on a signal whose
        frequency drifts 10 % (``tests/primitives/test_rhythmic.py``); a larger K chases the
        error the Fourier estimate has not learned yet and locks later.
    learning_rate : float
        ``η`` (1/s) of the Fourier coefficients.
    n_kernels, alpha : int, float
        The rhythmic DMP's basis size and spring gain.
    forgetting : float
        λ of the recursive least squares (per sample; 1 = no forgetting).
    """

    def __init__(  # noqa: PLR0913 - an estimator's constructor: each hyperparameter is one (scikit-learn)
        self,
        frequency: float,
        n_dims: int = 1,
        *,
        n_harmonics: int = 5,
        coupling: float = 5.0,
        learning_rate: float = 2.0,
        n_kernels: int = 30,
        alpha: float = 25.0,
        forgetting: float = 0.999,
    ) -> None:
        frequency = check_real(frequency, "frequency", minimum=SLOWEST_HZ, maximum=1e3)
        self.n_dims = check_int(n_dims, "n_dims", minimum=1, limit="max_dims")
        self.n_harmonics = check_int(n_harmonics, "n_harmonics", minimum=1, maximum=60)
        self.coupling = check_real(coupling, "coupling", positive=True, maximum=1e6)
        self.learning_rate = check_real(learning_rate, "learning_rate", positive=True, maximum=1e6)
        self.forgetting = check_real(forgetting, "forgetting", positive=True, maximum=1.0)
        self.alpha = check_real(alpha, "alpha", positive=True, maximum=1e4)
        self.omega = 2.0 * math.pi * frequency
        self.phase = 0.0
        self.a0 = np.zeros(self.n_dims)
        self.a = np.zeros((self.n_harmonics, self.n_dims))
        self.b = np.zeros((self.n_harmonics, self.n_dims))
        self._basis = VonMisesBasis(
            check_int(n_kernels, "n_kernels", minimum=2, limit="max_kernels")
        )
        self.centres, self.widths = self._basis.place(RhythmicPhase(), 1, 1.0)
        self.weights = np.zeros((self._basis.size, self.n_dims))
        self._precision = np.ones(self._basis.size)  # RLS's P per kernel
        self._scale = None  # running mean square of the signal about its centre
        self.period_guess = 1.0 / frequency

    @property
    def frequency(self) -> float:
        """The oscillator's frequency now (Hz)."""
        return self.omega / (2.0 * math.pi)

    def estimate(self, phase: float | None = None, order: int = 0) -> np.ndarray:
        """The Fourier estimate ``ŷ`` (D,) at ``phase`` (default the oscillator's), or its
        ``order``-th derivative in phase."""
        phase = (
            self.phase if phase is None else check_real(phase, "phase", maximum=1e6, minimum=-1e6)
        )
        order = check_int(order, "order", minimum=0, maximum=3)
        coefficients = np.vstack([self.a0[None], self.a, self.b])
        return _series(coefficients, np.array([phase]), self.n_harmonics, order)[0]

    def update(self, y, dt: float) -> None:
        """Take one sample ``y`` (D,) ``dt`` seconds after the last."""
        y = as_point(y, self.n_dims, "y")
        dt = check_real(dt, "dt", positive=True, maximum=1.0)
        if self._scale is None:  # the first sample: the centre starts there, not at 0
            self.a0 = y.copy()
            self._scale = 0.0
        error = y - self.estimate()
        # The coupling acts on the error relative to the signal's running RMS about its centre
        # (a signal in mm and one in m lock alike).
        centred = float(np.sum((y - self.a0) ** 2))
        self._scale += min(dt / self.period_guess, 1.0) * (centred - self._scale)
        feedback = float(np.sum(error)) / max(math.sqrt(self._scale), 1e-12)
        sin_phase = math.sin(self.phase)
        k = np.arange(1, self.n_harmonics + 1)[:, None]
        cos_k, sin_k = np.cos(k * self.phase), np.sin(k * self.phase)
        self.a0 = self.a0 + self.learning_rate * dt * error
        self.a = self.a + self.learning_rate * dt * cos_k * error
        self.b = self.b + self.learning_rate * dt * sin_k * error
        self.phase = math.fmod(
            self.phase + dt * (self.omega - self.coupling * feedback * sin_phase), 2.0 * math.pi
        )
        if self.phase < 0.0:
            self.phase += 2.0 * math.pi
        self.omega = max(self.omega - dt * self.coupling * feedback * sin_phase, 1e-6)
        self._learn_weights()

    def _learn_weights(self) -> None:
        """One recursive-least-squares step per kernel towards the forcing target of the
        estimate at the current phase (its derivatives analytic in the phase)."""
        coefficients = np.vstack([self.a0[None], self.a, self.b])
        phase = np.array([self.phase])
        position, slope, curvature = (
            _series(coefficients, phase, self.n_harmonics, order)[0] for order in (0, 1, 2)
        )
        target = _rhythmic_target(position, slope, curvature, self.a0, self.alpha)
        psi = np.exp(self.widths * (np.cos(self.phase - self.centres) - 1.0))
        lam = self.forgetting
        precision = self._precision
        precision = (precision - precision**2 / (lam / psi + precision)) / lam
        self._precision = precision
        self.weights += (psi * precision)[:, None] * (target[None, :] - self.weights)

    def to_dmp(self) -> RhythmicDMP:
        """The rhythmic DMP learned so far (frequency, anchor and weights as they are now)."""
        model = RhythmicDMP(n_kernels=self._basis.size, alpha=self.alpha)
        model.weights_ = self.weights.copy()
        model.centres_, model.widths_ = self.centres, self.widths
        model.anchor_ = self.a0.copy()
        model.frequency_ = self.frequency
        model.amplitude_ = np.sqrt(np.sum(self.a**2 + self.b**2, axis=0))
        model.units_, model.names_, model.n_dims_ = "", [], self.n_dims
        model.estimate_ = None
        return model
