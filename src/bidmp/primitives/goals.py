"""The robot protocol's goal system and rest start (issue 19).

A DMP's goal enters its input through the goal gate ``G``: ``u = αβ g + K f - K G (g - y0)``. The
motion's response to a change of goal is then ``R(t) (g' - g)``, a scalar *goal share* ``R``
that rises from 0 to 1; the robot protocol chooses ``G`` so that ``R`` is a profile of the
demonstration's own progress along its path:

* ``σ`` — the arc-length progress (0 → 1) of the demonstration as learned;
* ``R = σ · S(t / w)`` over the first ``w`` of the motion and ``1 - (1 - σ) S((T - t) / w)``
  over its last ``w``, ``R = σ`` in between, 1 after. ``S`` is the 7th-order smoothstep (zero
  first to third derivative at both ends), ``w = GOAL_BLEND`` (15 %) of the demonstration's
  duration. So ``R, R', R'', R'''`` all start at 0: the first ~50 ms of a motion do not depend on
  its goal (no acceleration or jerk step when the goal moves), and ``R`` reaches 1 with zero
  slope when the motion comes to rest;
* ``G`` is the *continuous* inverse of the spring for ``R``:
  ``G = (αβ (1 - R) - R'' - α R') / K`` (normalised time, ``tau = 1``). Integrated exactly
  (:mod:`bidmp._integrate`), the response is ``R`` at any control rate.

**The bound on a moved goal** (stated in the README): ``y_{g'}(t) = y_g(t) + R(t) (g' - g)``
exactly, and ``|R(t) - σ(t)| ≤ max(σ(w), 1 - σ(T - w))``: the progress made in the first and in
the last ``w``. Against the demonstration scaled to the new goal, ``y_g + σ (g' - g)``, the motion
differs by at most that share of ``‖g' - g‖``: for a straight demonstration and a nearer goal
this is the largest overshoot; a minimum-jerk start makes ``σ(w) ≈ 10 (0.15)³ = 3 %`` and the
overshoot itself is far smaller (``σ (1 - S)`` peaks near ``w/2``).

**Rest start.** A robot starts at rest; a prepared recording starts at the sensor's noise floor
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

__all__ = ["GOAL_BLEND", "smoothstep", "goal_share", "goal_gate", "rest_started"]

logger = logging.getLogger(__name__)

GOAL_BLEND = 0.15  # share of the demonstration's duration over which the goal's share starts and ends
REST_BLEND_SHARE = 0.1  # the rest blend adds at most this share of the demonstration's acceleration
REST_BLEND_MAX = 0.25  # the rest blend never spans more than this share of the demonstration
_REST_CANDIDATES = np.geomspace(0.01, REST_BLEND_MAX, 32)


def smoothstep(u: np.ndarray) -> np.ndarray:
    """The 7th-order smoothstep ``35u⁴ - 84u⁵ + 70u⁶ - 20u⁷`` on [0, 1] (clipped outside): 0 → 1 with
    zero first, second and third derivatives at both ends."""
    u = np.clip(u, 0.0, 1.0)
    return u**4 * (35.0 + u * (-84.0 + u * (70.0 - 20.0 * u)))


def _smoothstep_derivatives(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and second derivative of :func:`smoothstep` (0 outside [0, 1])."""
    inside = (u > 0.0) & (u < 1.0)
    first = np.where(inside, 140.0 * u**3 * (1.0 - u) ** 3, 0.0)
    second = np.where(inside, 420.0 * u**2 * (1.0 - u) ** 2 * (1.0 - 2.0 * u), 0.0)
    return first, second


def goal_share(progress: np.ndarray, n_motion: int, dt: float, blend: float = GOAL_BLEND) -> np.ndarray:
    """The goal share ``R`` on the training grid (module docstring).

    Parameters
    ----------
    progress : array (n,)
        Arc-length progress ``σ`` of the trajectory as learned (rest after ``n_motion`` samples).
    n_motion : int
        Samples of the demonstrated motion (``T``); after them ``R = 1``.
    dt : float
        Normalised step.
    """
    s = np.arange(progress.shape[0]) * dt
    end = (n_motion - 1) * dt
    width = max(blend * end, dt)
    share = progress * smoothstep(s / width)
    closing = s > end - width
    share[closing] = 1.0 - (1.0 - progress[closing]) * smoothstep((end - s[closing]) / width)
    share[s >= end] = 1.0
    return share


def goal_gate(share: np.ndarray, dt: float, *, alpha: float, beta: float, K: float) -> np.ndarray:
    """The gate ``G = (αβ (1 - R) - R'' - α R') / K`` whose continuous response is ``R``."""
    rate = np.gradient(share, dt)
    curvature = np.gradient(rate, dt)
    gate = (alpha * beta * (1.0 - share) - curvature - alpha * rate) / K
    # R, R' and R'' vanish at the start (the smoothstep is flat there): one-sided differences
    # would leave a trace of the next samples, and the initial acceleration must not depend on
    # the goal.
    gate[0] = alpha * beta / K
    return gate


# The rest blend's acceleration is -v₀ q''(t/w) / w with q(u) = u (1 - S(u)), q'' = -2S' - u S'':
# its shape on [0, 1] does not depend on the window, so it is tabulated once.
_BLEND_U = np.linspace(0.0, 1.0, 65)
_BLEND_SHAPE = np.abs(2.0 * _smoothstep_derivatives(_BLEND_U)[0] + _BLEND_U * _smoothstep_derivatives(_BLEND_U)[1])


def _blend_window(speed_vector: np.ndarray, acceleration: np.ndarray, dt: float, peak: float) -> float:
    """The shortest window (normalised time) over which blending ``speed_vector`` out adds at most
    ``REST_BLEND_SHARE`` of the demonstration's running peak acceleration."""
    speed = float(np.linalg.norm(speed_vector))
    if speed <= 1e-12 * max(peak, 1e-300):
        return 0.0
    running = np.maximum.accumulate(np.linalg.norm(acceleration, axis=1))
    # All candidate windows at once: (candidates, 65) added accelerations against the running peak.
    added = speed * _BLEND_SHAPE[None, :] / _REST_CANDIDATES[:, None]
    index = np.minimum((_BLEND_U[None, :] * _REST_CANDIDATES[:, None] / dt).astype(int), running.shape[0] - 1)
    within = np.all(added <= REST_BLEND_SHARE * np.maximum(running[index], 1e-300), axis=1)
    return float(_REST_CANDIDATES[np.argmax(within)]) if within.any() else float(REST_BLEND_MAX)


def rest_started(y: np.ndarray, dt: float, duration_s: float, what: str = "the demonstration",
                 unit: str = "units") -> np.ndarray:
    """``y`` (T, D) with its start and end velocity blended out (module docstring).

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
    for end, speed_vector, forward in ((False, velocity[0], acceleration), (True, velocity[-1], acceleration[::-1])):
        width = _blend_window(speed_vector, forward, dt, peak)
        if width == 0.0:
            continue
        elapsed = (s[-1] - s) if end else s
        blend = elapsed * (1.0 - smoothstep(elapsed / width))
        out += (1.0 if end else -1.0) * blend[:, None] * speed_vector[None, :]
        speed = float(np.linalg.norm(speed_vector))
        level = logging.WARNING if speed > 0.05 * peak else logging.DEBUG
        logger.log(level, "%s %s at %.3g %s/s (%.1f %% of its peak speed); the DMP %s at rest, blended over %.3g s",
                   what, "ends" if end else "starts", speed / duration_s, unit, 100 * speed / peak,
                   "ends" if end else "starts", width * duration_s)
    return out
