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

from .._kernels import rest_blend_arguments, rest_blended, rest_windows
from .goals import _smoothstep_derivatives

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
    # The two windows are decisions (a width from a fixed table): one compiled search for both,
    # on NumPy's gradient of the demonstration (its acceleration's running peak from either end).
    start_width, end_width, peak, start_speed, end_speed = rest_windows(
        y, dt, _BLEND_U, _BLEND_SHAPE, _REST_CANDIDATES, _REST_BLEND_SHARE, _REST_BLEND_MAX
    )
    # y - v₀ s (1 - S(s / w₀)) + v₁ (s_T - s) (1 - S((s_T - s) / w₁)): two compiled loops around
    # NumPy's u⁴ (the smoothstep's powers, as _smoothstep takes them); the end velocities are
    # np.gradient's one-sided ones, to the bit.
    start_velocity, end_velocity = (y[1] - y[0]) / dt, (y[-1] - y[-2]) / dt
    arguments = rest_blend_arguments(y.shape[0], dt, start_width, end_width)
    out = rest_blended(
        y, arguments, arguments**4, dt, start_velocity, end_velocity, start_width, end_width
    )
    for end, speed, width in ((False, start_speed, start_width), (True, end_speed, end_width)):
        if width == 0.0:
            continue
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
