"""A plan's pace: the duration that keeps a path at the demonstration's tool speed, and a plan
stretched to a longer duration (its peaks scaled with it). The arm's plans, its routes and the
job's moves all slow their plans here.

Layer 3: the simulator's.
"""

from __future__ import annotations

import numpy as np

from .backend import MotionPlan


def _paced_duration(path, fractions=None, speed: float | None = None) -> float:
    """The shortest duration (s) in which ``path`` (n, 3, scene units; its samples at normalised
    times ``fractions``, default uniform) keeps its tool speed at or below ``speed`` (scene units
    per second: the demonstration's pace); 0 without a pace. Speeds between samples are their
    chords' over their time steps."""
    if speed is None:
        return 0.0
    path = np.asarray(path, dtype=float)[:, :3]
    u = (
        np.linspace(0.0, 1.0, path.shape[0])
        if fractions is None
        else np.asarray(fractions, dtype=float)
    )
    steps, durations = np.linalg.norm(np.diff(path, axis=0), axis=1), np.diff(u)
    moving = durations > 1e-12
    if not np.any(moving):
        return 0.0
    return float(np.max(steps[moving] / durations[moving])) / float(speed)


def _slowed(plan: MotionPlan, duration: float) -> MotionPlan:
    """``plan`` stretched to last ``duration`` seconds when that is longer (every joint peak
    scaled down with it: velocity by the ratio, acceleration by its square, jerk by its cube);
    a plan is never made faster here. Returns ``plan`` (changed in place)."""
    if duration > plan.duration:
        scale = plan.duration / duration
        plan.duration = float(duration)
        plan.peak_velocity *= scale
        plan.peak_acceleration *= scale**2
        plan.peak_jerk *= scale**3
    return plan
