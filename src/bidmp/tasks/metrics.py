"""Metrics of generated trajectories (end error, approach error, axis deviation), in the trajectories' own length unit.

RMSE and extent live in the private helper module ``bidmp._trajectory`` and are re-exported here
for users.
"""

from __future__ import annotations

import math

import numpy as np

from .._checks import (
    _as_bounded_array,
    _check_finite,
    as_point,
    as_trajectory,
    check_real,
)
from .._norms import row_norms, tamed_rows
from .._trajectory import path_extent, rmse

__all__ = [
    "rmse",
    "path_extent",
    "endpoint_error",
    "approach_error",
    "axis_deviation",
    "path_difference",
    "swept_area",
    "final_approach_mask",
]


def endpoint_error(trajectory, target) -> float:
    """Distance between the last point of ``trajectory`` (n, D) and ``target`` (D,)."""
    trajectory = as_trajectory(trajectory, "trajectory", min_points=1, allow_static=True)
    return float(
        np.linalg.norm(
            trajectory[-1] - as_point(target, trajectory.shape[1], "target", like="trajectory")
        )
    )


# Of the band's height: the most a final approach may rise when no tolerance is given (0.15 mm of the
# socket's 28.5 mm band: the motion contract's own tolerance, bidmp.tasks.contract, is 0.15 mm in any unit).
LIFT_TOLERANCE = 0.15 / 28.5


def final_approach_mask(
    heights: np.ndarray, height: float, rise: float | None = None
) -> np.ndarray | None:
    """The samples of the final approach: from the last sample at or above ``height`` (the motion's
    final entry into the band, from above) to the end, inside the band, a monotone descent: no rise
    within it by more than ``rise`` (default :data:`LIFT_TOLERANCE` of ``height``) above the lowest
    point reached so far.
    None when there is none: the motion ends above the band, never comes from above it, or rises
    inside it (a pass through the band, a lift out of it, a wobble, or a dip below the target and
    back up is no engagement).

    Parameters
    ----------
    heights : array (n,)
        Height of each sample above the target, along the target's axis.
    height : float
        The band's height (the socket's 28.5 mm, in the trajectory's unit).
    rise : float, optional
        The largest rise allowed inside the band (the trajectory's unit).
    """
    heights = _as_bounded_array(heights, "heights", max_ndim=1).reshape(-1)
    _check_finite(heights, "heights")
    height = check_real(height, "height", positive=True)
    rise = LIFT_TOLERANCE * height if rise is None else check_real(rise, "rise", nonnegative=True)
    above = np.flatnonzero(heights >= height)
    if above.size == 0 or above[-1] == heights.shape[0] - 1:
        return None
    start = above[-1] + 1
    inside = heights[start:]
    if np.max(inside - np.minimum.accumulate(inside)) > rise:
        return None
    mask = np.zeros(heights.shape[0], dtype=bool)
    mask[start:] = True
    return mask


def approach_error(
    trajectory, target, height: float, axis=None, rise: float | None = None
) -> float:
    """Largest distance from the target's axis over the final approach: the
    motion's final descent along the axis from ``height`` above the target into it
    (:func:`final_approach_mask`). ``inf`` when the motion has no such descent: a pass through the
    band, a lift, or a motion that never comes down from above does not engage.

    Parameters
    ----------
    trajectory : array (n, 3)
    target : array (3,)
    height : float
        Height of the band above the target (e.g. the socket's 28.5 mm groove).
    axis : array (3,), optional
        The target's axis, pointing out of it (a tilted nut's); default +z. Height is measured
        along it and the distance across it.
    rise : float, optional
        The largest rise allowed inside the band (:func:`final_approach_mask`).
    """
    trajectory = as_trajectory(trajectory, "trajectory", min_points=1, allow_static=True)
    if trajectory.shape[1] != 3:
        raise ValueError(
            f"approach_error needs a 3-D trajectory (z is the height), got D = {trajectory.shape[1]}"
        )
    target = as_point(target, 3, "target")
    height = check_real(height, "height", positive=True)
    axis = np.array([0.0, 0.0, 1.0]) if axis is None else _unit_axis(axis)
    offsets = trajectory - target
    along = offsets @ axis
    final = final_approach_mask(along, height, rise)
    if final is None:
        return math.inf
    return float(np.max(np.linalg.norm(offsets[final] - np.outer(along[final], axis), axis=1)))


def _unit_axis(axis) -> np.ndarray:
    axis = as_point(axis, 3, "axis")
    norm = np.linalg.norm(axis)
    if norm < 1e-12:
        raise ValueError("axis must not be zero")
    return axis / norm


def axis_deviation(
    trajectory, orientations, target, height: float, axis=None, rise: float | None = None
) -> float:
    """Largest angle (degrees) between the tool's axis and the target's axis over the final
    approach (:func:`final_approach_mask`, ``height`` along ``axis``, default +z); ``inf`` when the
    motion has none. The tool's axis is the z axis of each orientation (quaternions x, y, z, w),
    pointing into the target, so a perfect approach has it opposite ``axis``."""
    from scipy.spatial.transform import Rotation

    trajectory = as_trajectory(trajectory, "trajectory", min_points=1, allow_static=True)
    q = _as_bounded_array(orientations, "orientations", max_ndim=2)
    if q.shape != (trajectory.shape[0], 4):
        raise ValueError(
            f"orientations must have shape ({trajectory.shape[0]}, 4), one per row of trajectory, got {q.shape}"
        )
    _check_finite(q, "orientations")
    if np.any(row_norms(q) < 1e-12):  # (scaled first: rows of 1e300 do not overflow)
        raise ValueError("orientations contains a zero quaternion, which is no rotation")
    q = tamed_rows(q)  # (SciPy normalises them: rows of 1e300 must not overflow its norm)
    target = as_point(target, 3, "target")
    height = check_real(height, "height", positive=True)
    axis = np.array([0.0, 0.0, 1.0]) if axis is None else _unit_axis(axis)
    low = final_approach_mask((trajectory - target) @ axis, height, rise)
    if low is None:
        return math.inf
    tool_axes = Rotation.from_quat(q[low]).apply([0.0, 0.0, 1.0])
    cosines = np.clip(tool_axes @ -axis, -1.0, 1.0)
    return float(np.degrees(np.max(np.arccos(cosines))))


def path_difference(trajectory, reference) -> float:
    """The paper's "difference": ``Σ_l ‖y_l − ref_l‖`` over the reference's samples.

    Only the first ``len(reference)`` samples of ``trajectory`` are compared (a run to
    convergence goes on afterwards; squeezing it into T samples would compare different times).
    """
    trajectory = as_trajectory(trajectory, "trajectory", min_points=1, allow_static=True)
    reference = as_trajectory(reference, "reference", min_points=1, allow_static=True)
    if trajectory.shape[0] < reference.shape[0] or trajectory.shape[1] != reference.shape[1]:
        raise ValueError(
            f"trajectory {trajectory.shape} must cover reference {reference.shape}: at least as many "
            f"samples, the same D"
        )
    return float(np.sum(np.linalg.norm(trajectory[: reference.shape[0]] - reference, axis=1)))


def swept_area(trajectory, reference) -> float:
    """Swept error area (Khansari-Zadeh & Billard's CLF-DM benchmark): the sum over
    time-aligned steps of the areas of the quadrilaterals ``r_l, r_{l+1}, y_{l+1}, y_l`` between a
    2-D trajectory and its reference (shoelace formula, absolute value per quadrilateral).
    Both (T, 2), same T; in the trajectories' unit squared."""
    trajectory = as_trajectory(trajectory, "trajectory", min_points=2, allow_static=True)
    reference = as_trajectory(reference, "reference", min_points=2, allow_static=True)
    if trajectory.shape != reference.shape or trajectory.shape[1] != 2:
        raise ValueError(
            f"trajectory and reference must be 2-D curves (T, 2) of the same length, got "
            f"{trajectory.shape} and {reference.shape}"
        )
    # (T-1, 4, 2)
    corners = np.stack([reference[:-1], reference[1:], trajectory[1:], trajectory[:-1]], axis=1)
    x, y = corners[..., 0], corners[..., 1]
    twice = np.sum(x * np.roll(y, -1, axis=1) - np.roll(x, -1, axis=1) * y, axis=1)
    return float(np.sum(np.abs(twice)) / 2.0)
