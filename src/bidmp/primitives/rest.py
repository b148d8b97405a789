"""Learning a demonstration from rest: its start and end velocity blended out.

A robot starts at rest; a prepared recording starts at the sensor's noise floor
(1.6 mm/s for the bundled ones) and a user's demonstration may start at speed. The learned
trajectory is the demonstration with its start (and end) velocity blended out,
``y - v₀ t (1 - S(t / w₀))``, over the shortest window ``w₀`` in which the blend's acceleration
stays within 10 % of the demonstration's own peak acceleration so far (at most a quarter of the
motion). Its acceleration and jerk at the start are the demonstration's (``S`` is flat to third
order), so the rollout starts at rest with the demonstrated acceleration and without ringing.
"""

from __future__ import annotations

import logging

import numpy as np

from .goals import _smoothstep, _smoothstep_derivatives

__all__ = []

logger = logging.getLogger(__name__)

# the rest blend adds at most this share of the demonstration's acceleration
_REST_BLEND_SHARE = 0.1
_REST_BLEND_MAX = 0.25  # the rest blend never spans more than this share of the demonstration
_REST_CANDIDATES = np.geomspace(0.01, _REST_BLEND_MAX, 32)


# The rest blend's acceleration is -v₀ q''(t/w) / w with q(u) = u (1 - S(u)), q'' = -2S' - u S'':
# its shape on [0, 1] does not depend on the window, so it is tabulated once.
_BLEND_U = np.linspace(0.0, 1.0, 65)
_BLEND_SHAPE = np.abs(
    2.0 * _smoothstep_derivatives(_BLEND_U)[0] + _BLEND_U * _smoothstep_derivatives(_BLEND_U)[1]
)


def _blend_window(
    speed_vector: np.ndarray, acceleration: np.ndarray, dt: float, peak: float
) -> float:
    """The shortest window (normalised time) over which blending ``speed_vector`` out adds at most
    ``_REST_BLEND_SHARE`` of the demonstration's running peak acceleration."""
    speed = float(np.linalg.norm(speed_vector))
    if speed <= 1e-12 * max(peak, 1e-300):
        return 0.0
    running = np.maximum.accumulate(np.linalg.norm(acceleration, axis=1))
    # All candidate windows at once: (candidates, 65) added accelerations against the running peak.
    added = speed * _BLEND_SHAPE[None, :] / _REST_CANDIDATES[:, None]
    index = np.minimum(
        (_BLEND_U[None, :] * _REST_CANDIDATES[:, None] / dt).astype(int), running.shape[0] - 1
    )
    within = np.all(added <= _REST_BLEND_SHARE * np.maximum(running[index], 1e-300), axis=1)
    return float(_REST_CANDIDATES[np.argmax(within)]) if within.any() else float(_REST_BLEND_MAX)


def _rest_started(
    y: np.ndarray,
    dt: float,
    duration_s: float,
    what: str = "the demonstration",
    unit: str = "units",
    quiet: bool = False,
) -> np.ndarray:
    """``y`` (T, D) with its start and end velocity blended out (module docstring); ``quiet``
    logs the blend at debug level only (one of several demonstrations blended like the first).

    Parameters
    ----------
    y : array (T, D)
        The demonstration on its uniform grid.
    dt : float
        Normalised step (``1 / T``).
    duration_s : float
        Seconds per unit of normalised time (for the log message).
    what, unit : str
        What the trajectory is and its length unit, for the log message.
    """
    velocity = np.gradient(y, dt, axis=0)
    acceleration = np.gradient(velocity, dt, axis=0)
    peak = float(np.max(np.linalg.norm(velocity, axis=1)))
    s = np.arange(y.shape[0]) * dt
    out = y.copy()
    for end, speed_vector, forward in (
        (False, velocity[0], acceleration),
        (True, velocity[-1], acceleration[::-1]),
    ):
        width = _blend_window(speed_vector, forward, dt, peak)
        if width == 0.0:
            continue
        elapsed = (s[-1] - s) if end else s
        blend = elapsed * (1.0 - _smoothstep(elapsed / width))
        out += (1.0 if end else -1.0) * blend[:, None] * speed_vector[None, :]
        speed = float(np.linalg.norm(speed_vector))
        level = logging.WARNING if speed > 0.05 * peak and not quiet else logging.DEBUG
        logger.log(
            level,
            "%s %s at %.3g %s/s (%.1f %% of its peak speed); the DMP %s at rest, blended over %.3g s",
            what,
            "ends" if end else "starts",
            speed / duration_s,
            unit,
            100 * speed / peak,
            "ends" if end else "starts",
            width * duration_s,
        )
    return out
