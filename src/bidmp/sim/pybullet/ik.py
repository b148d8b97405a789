"""Inverse kinematics of the arm on the planning copy of the arm: short bursts of PyBullet's
damped least squares from the previous solution, checked by forward kinematics."""

from __future__ import annotations

import math

import numpy as np

from ..._checks import as_point
from ..robots import _DOWN, IK_ACCURACY, _joint_seed, _reachable

__all__ = []


# -- planning --------------------------------------------------------------------------
def _solve_ik(cell, point_m: np.ndarray, seed, orientation=None) -> tuple[np.ndarray, float]:
    """Joint positions that put the TCP at ``point_m`` (m) with the tool's frame at
    ``orientation`` (quaternion x, y, z, w; default pointing down), started from ``seed``;
    and the position error left (m)."""
    p = cell.p
    point_m = _reachable(as_point(point_m, 3, "point_m"), cell.base * cell.unit, "point_m")
    q = _joint_seed(seed, cell.limits)
    if orientation is not None:
        from ...primitives.so3 import as_quaternions

        orientation = as_quaternions(orientation, "orientation")
        if orientation.shape[0] != 1:
            raise ValueError(f"orientation must be one quaternion (4,), got {orientation.shape[0]}")
        orientation = orientation[0]
    target_orientation = _DOWN if orientation is None else [float(v) for v in orientation]
    axis = None
    if orientation is not None:
        # The tool is a socket, symmetric about its axis: only the axis is prescribed. Each
        # burst aims at the orientation nearest the current one with that axis, so the arm
        # keeps its own turn about the axis (a full orientation made the wrist fight it).
        from scipy.spatial.transform import Rotation

        axis = Rotation.from_quat(target_orientation).apply([0.0, 0.0, 1.0])
    limits = cell.limits
    ranges = [upper - lower for lower, upper in zip(limits.lower, limits.upper)]
    error = math.inf
    # Short bursts from the previous solution, checked by forward kinematics: a few dozen
    # iterations reach 1 µm from a seed a few millimetres away (one long call costs 10x). Each
    # check leaves the planning copy at its joints, where the next burst starts.
    cell._set_joints(q, kinematic=True)
    for _ in range(20):
        if axis is not None:
            current = Rotation.from_quat(
                p.getLinkState(
                    cell.ik_robot,
                    cell.tcp,
                    computeForwardKinematics=1,
                    physicsClientId=cell.ik_client,
                )[5]
            )
            swing, _ = Rotation.align_vectors([axis], [current.apply([0.0, 0.0, 1.0])])
            target_orientation = (swing * current).as_quat().tolist()
        q = np.array(
            p.calculateInverseKinematics(
                cell.ik_robot,
                cell.tcp,
                point_m.tolist(),
                target_orientation,
                lowerLimits=list(limits.lower),
                upperLimits=list(limits.upper),
                jointRanges=ranges,
                restPoses=q.tolist(),
                maxNumIterations=40,
                residualThreshold=1e-9,
                physicsClientId=cell.ik_client,
            )[: len(cell.arm)]
        )
        if axis is not None and cell.wrist_turns_tool:
            # The last joint turns the flange about the tool's axis, which moves neither the tool's
            # mouth nor its axis: park it where it rests instead of letting it drift to a limit.
            q[-1] = cell.model.rest[-1]
        error = float(np.linalg.norm(cell._tcp_at(q) - point_m))
        if error <= IK_ACCURACY:
            break
    return q, error
