"""Metrics of generated trajectories (SPEC §9), in the trajectories' own length unit.

RMSE and extent live in the private helper module ``bidmp._trajectory`` and are re-exported here
for users.
"""

from __future__ import annotations

import numpy as np

from ._checks import as_point, as_trajectory, check_real
from ._trajectory import path_extent, rmse

__all__ = ["rmse", "path_extent", "endpoint_error", "approach_error", "path_difference"]


def endpoint_error(trajectory, target) -> float:
    """Distance between the last point of ``trajectory`` (n, D) and ``target`` (D,)."""
    trajectory = as_trajectory(trajectory, "trajectory", min_points=1, allow_static=True)
    return float(np.linalg.norm(trajectory[-1] - as_point(target, trajectory.shape[1], "target")))


def approach_error(trajectory, target, height: float) -> float:
    """Largest horizontal distance from the target's vertical axis while the trajectory is less
    than ``height`` above the target (SPEC §9). 0 if it never comes that low.

    Parameters
    ----------
    trajectory : array (n, 3)
    target : array (3,)
    height : float
        Height of the band above the target (e.g. the socket's 28.5 mm groove).
    """
    trajectory = as_trajectory(trajectory, "trajectory", min_points=1, allow_static=True)
    if trajectory.shape[1] != 3:
        raise ValueError(f"approach_error needs a 3-D trajectory (z is the height), got D = {trajectory.shape[1]}")
    target = as_point(target, 3, "target")
    height = check_real(height, "height", positive=True)
    low = trajectory[:, 2] - target[2] < height
    if not np.any(low):
        return 0.0
    return float(np.max(np.linalg.norm(trajectory[low, :2] - target[:2], axis=1)))


def path_difference(trajectory, reference) -> float:
    """The paper's "difference": ``Σ_l ‖y_l − ref_l‖`` over the reference's samples.

    Only the first ``len(reference)`` samples of ``trajectory`` are compared (a run to
    convergence goes on afterwards; squeezing it into T samples would compare different times).
    """
    trajectory = as_trajectory(trajectory, "trajectory", min_points=1, allow_static=True)
    reference = as_trajectory(reference, "reference", min_points=1, allow_static=True)
    if trajectory.shape[0] < reference.shape[0] or trajectory.shape[1] != reference.shape[1]:
        raise ValueError(f"trajectory {trajectory.shape} must cover reference {reference.shape}: at least as many "
                         f"samples, the same D")
    return float(np.sum(np.linalg.norm(trajectory[: reference.shape[0]] - reference, axis=1)))
