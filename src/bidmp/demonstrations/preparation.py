"""Kinesthetic recordings made usable for learning: uniform time, a zero-phase low-pass, idle ends
trimmed (positions, :func:`prepare`; poses, :func:`prepare_poses`).

Layer 2 (data in): imports the math (``bidmp.primitives``) and the checks, never files,
scenarios or the CLI.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from .._checks import as_trajectory, check_real, numerically_guarded
from .._units import check_units
from ..primitives.cartesian import as_poses
from ..primitives.so3 import continuous_log, orientation_from_log
from ..primitives.timing import Trajectory, drop_repeated_stamps, uniform_time

__all__ = ["prepare", "PrepareInfo", "prepare_poses"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class PrepareInfo:
    """What :func:`prepare` did: the kept span of the recording (s, from its first stamp), the
    filter cutoff (Hz), the sample rate (Hz) and the peak speed (units/s)."""

    start_s: float
    end_s: float
    cutoff_hz: float
    rate_hz: float
    peak_speed: float


def _moving_span(speed: np.ndarray, rate: float, fraction: float) -> tuple[int, int]:
    """First and last sample of the motion: the speed exceeds ``fraction`` of its peak for at
    least 0.1 s (shorter excursions are noise), extended outwards down the acceleration ramps to
    where the speed stops falling (the rest the motion starts from and comes to)."""
    threshold = fraction * np.max(speed)
    moving = speed > threshold
    minimum_run = max(int(round(0.1 * rate)), 1)
    edges = np.flatnonzero(np.diff(np.concatenate([[0], moving.astype(np.int8), [0]])))
    runs = [
        (start, stop) for start, stop in zip(edges[::2], edges[1::2]) if stop - start >= minimum_run
    ]
    if not runs:
        raise ValueError(
            "the recording never moves: its speed stays below "
            f"{fraction:g} of its peak for 0.1 s or longer"
        )
    first, last = runs[0][0], runs[-1][1] - 1
    floor = np.median(speed[~moving]) if np.any(~moving) else 0.0
    while first > 0 and speed[first - 1] < speed[first] and speed[first - 1] > floor:
        first -= 1
    while last < speed.shape[0] - 1 and speed[last + 1] < speed[last] and speed[last + 1] > floor:
        last += 1
    return int(first), int(last)


@numerically_guarded
def prepare(
    y, t, *, cutoff_hz: float = 6.0, idle_fraction: float = 0.05, units: str = ""
) -> tuple[Trajectory, PrepareInfo]:
    """Make a kinesthetic recording usable for learning.

    1. Uniform time: the samples are resampled to their mean rate over the same span.
    2. Zero-phase low-pass filter: a 4th-order Butterworth run forwards and backwards
       (:func:`scipy.signal.sosfiltfilt`) at ``cutoff_hz`` (default 6 Hz: hand-guided motions
       have no content above ~3 Hz; sensor noise is white), at least one cycle over the
       recording's duration and below half its sample rate.
    3. Idle ends trimmed: the motion is where the filtered speed exceeds ``idle_fraction`` of its
       peak for at least 0.1 s, extended down the acceleration ramps to rest.

    Parameters
    ----------
    y : array (T, D)
        Positions in ``units`` (e.g. mm).
    t : array (T,)
        Timestamps in seconds (see :func:`check_timestamps`).

    Returns
    -------
    (Trajectory, PrepareInfo)
        The trimmed motion, time from 0 s, with filtered velocities and accelerations.
    """
    from scipy.signal import butter, sosfiltfilt

    units = check_units(units)
    y = as_trajectory(y, "y", min_points=10)
    y, t = drop_repeated_stamps(y, t)
    cutoff_hz = check_real(cutoff_hz, "cutoff_hz", positive=True)
    idle_fraction = check_real(idle_fraction, "idle_fraction", positive=True, maximum=0.5)
    uniform, grid = uniform_time(y, t)
    rate = (grid.shape[0] - 1) / grid[-1]
    if cutoff_hz < 1.0 / grid[-1]:
        # below one cycle over the recording the filter takes the motion itself away (and its
        # design is singular long before 1e-300 Hz)
        raise ValueError(
            f"cutoff_hz must be >= {1.0 / grid[-1]:.4g} Hz (one cycle over the recording's "
            f"{grid[-1]:.4g} s), got {cutoff_hz:g}"
        )
    if cutoff_hz >= 0.5 * rate:
        raise ValueError(
            f"cutoff_hz = {cutoff_hz:g} must be below half the sample rate of t ({0.5 * rate:.4g} Hz)"
        )
    sos = butter(4, cutoff_hz, fs=rate, output="sos")
    # Pad with the signal's even reflection (a resting end stays at rest) over ~3 filter periods.
    padlen = min(3 * int(np.ceil(rate / cutoff_hz)), uniform.shape[0] - 1)
    filtered = sosfiltfilt(sos, uniform, axis=0, padtype="even", padlen=padlen)
    # A recording that only shows sensor noise has nothing to trim to: its filtered extent stays
    # within a few noise standard deviations (estimated from what the filter removed).
    noise = float(np.sqrt(np.mean(np.sum((uniform - filtered) ** 2, axis=1))))
    extent = float(np.linalg.norm(np.ptp(filtered, axis=0)))
    if extent <= 20.0 * noise:
        raise ValueError(
            f"the recording never moves: its extent {extent:.3g} is within the sensor noise "
            f"({noise:.3g} RMS after the {cutoff_hz:g} Hz filter)"
        )
    dt = grid[1] - grid[0]
    velocity = np.gradient(filtered, dt, axis=0)
    speed = np.linalg.norm(velocity, axis=1)
    first, last = _moving_span(speed, rate, idle_fraction)
    if last - first + 1 < 10:
        raise ValueError(
            f"the recording moves for only {last - first + 1} samples ({(last - first) * dt:.3g} s)"
        )
    kept = filtered[first : last + 1]
    kept_velocity = velocity[first : last + 1]
    acceleration = np.gradient(kept_velocity, dt, axis=0)
    times = grid[first : last + 1] - grid[first]
    logger.info(
        "prepare: kept %.3f-%.3f s of %.3f s (%d samples at %.1f Hz)",
        grid[first],
        grid[last],
        grid[-1],
        last - first + 1,
        rate,
    )
    info = PrepareInfo(
        start_s=float(grid[first]),
        end_s=float(grid[last]),
        cutoff_hz=cutoff_hz,
        rate_hz=float(rate),
        peak_speed=float(np.max(speed)),
    )
    return Trajectory(times, kept, kept_velocity, acceleration, units), info


# rad -> "units" while prepare() filters: the idle ends are found from positions
_ORIENTATION_WEIGHT = 1e-6


def prepare_poses(
    poses, t, *, cutoff_hz: float = 6.0, idle_fraction: float = 0.05, units: str = ""
):
    """:func:`bidmp.prepare` for a pose recording: uniform time, the same zero-phase low-pass on
    positions and on the orientation (its continuous log at the last sample), idle ends trimmed
    by the positions' speed.

    Returns
    -------
    (poses (n, 7), t (n,), PrepareInfo)
        Uniform samples from 0 s; ``info.start_s`` is where they begin in the recording.
    """
    positions, quaternions = as_poses(poses, "poses", min_points=10)
    goal = quaternions[-1]
    # Scaled down, the orientation rides along through the same linear filter and resampling
    # without moving the speed threshold that finds the motion.
    stacked = np.hstack([positions, continuous_log(quaternions, goal) * _ORIENTATION_WEIGHT])
    trajectory, info = prepare(
        stacked, t, cutoff_hz=cutoff_hz, idle_fraction=idle_fraction, units=units
    )
    orientation = orientation_from_log(trajectory.y[:, 3:] / _ORIENTATION_WEIGHT, goal)
    return np.hstack([trajectory.y[:, :3], orientation]), trajectory.t, info
