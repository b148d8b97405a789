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
    point_m = _reachable(as_point(point_m, 3, "point_m"), cell.base * cell.unit, "point_m")
    q = _joint_seed(seed, cell.limits)
    if orientation is not None:
        from ...primitives.so3 import as_quaternions

        orientation = as_quaternions(orientation, "orientation")
        if orientation.shape[0] != 1:
            raise ValueError(f"orientation must be one quaternion (4,), got {orientation.shape[0]}")
        orientation = orientation[0]
    from scipy.spatial.transform import Rotation

    target_orientation = _DOWN if orientation is None else [float(v) for v in orientation]
    # The tool is a socket (a spindle turns it), symmetric about its axis: only the axis is
    # prescribed, pointing down or as ``orientation`` has it (5 DOF). Each burst aims at the
    # orientation nearest the current one with that axis, so the arm keeps its own turn about
    # the axis: a full orientation made the wrist fight it, and near a 6-axis arm's wrist
    # singularity left 0.06 mm where this leaves 0.005 (an xArm6 2 mm from it).
    axis = Rotation.from_quat(target_orientation).apply([0.0, 0.0, 1.0])
    seed = q
    # The last joint, where it turns the flange about the tool's axis (moving neither the tool's
    # mouth nor its axis), is parked at its start pose's turn (chosen farthest inside the limits)
    # rather than left to drift to a limit; where the parked arm does not converge (a joint near
    # its own limit on the way), the turn is left to the arm too.
    # Last, the whole frame prescribed (its turn the one given, or the pose's): another branch
    # of the solutions, which a seed near a joint limit may reach when the free turn does not.
    # A gripper holding a part (``cell.free_turn`` False) turns it with the tool: the whole frame
    # is prescribed for a motion pointing down, the axis for a pose (its turn the arm's own).
    whole_frame = (False, list(target_orientation))
    if cell.free_turn:
        tries = [(True, None)] if cell.wrist_turns_tool else []
        tries += [(False, None), whole_frame]
    else:
        tries = [(cell.wrist_turns_tool, None)] if orientation is not None else [whole_frame]
    best = None
    for park, frame in tries:
        q, error = _bursts(cell, point_m, seed, axis, park, frame)
        if best is None or error < best[1]:
            best = (q, error)
        if error <= IK_ACCURACY:
            break
    return best


def _bursts(cell, point_m, seed, axis, park: bool, frame=None) -> tuple[np.ndarray, float]:
    """Short bursts of PyBullet's damped least squares from ``seed`` toward ``point_m`` (m) with
    the tool's axis along ``axis``, each aiming at the orientation nearest the current one with
    that axis (or at ``frame``, a quaternion, when given); ``park``: the last joint held at the
    start pose's turn. Checked by forward
    kinematics: a few dozen iterations reach 1 µm from a seed a few millimetres away (one long
    call costs 10x). Each check leaves the planning copy at its joints, where the next starts."""
    p, limits = cell.p, cell.limits
    ranges = [upper - lower for lower, upper in zip(limits.lower, limits.upper)]
    q, error = seed, math.inf
    cell._set_joints(q, kinematic=True)
    for _ in range(60):
        if frame is None:
            current = p.getLinkState(
                cell.ik_robot, cell.tcp, computeForwardKinematics=1, physicsClientId=cell.ik_client
            )[5]
        q = np.array(
            p.calculateInverseKinematics(
                cell.ik_robot,
                cell.tcp,
                point_m.tolist(),
                _aimed(current, axis) if frame is None else frame,
                lowerLimits=list(limits.lower),
                upperLimits=list(limits.upper),
                jointRanges=ranges,
                restPoses=q.tolist(),
                maxNumIterations=40,
                residualThreshold=1e-9,
                physicsClientId=cell.ik_client,
            )[: len(cell.arm)]
        )
        if park:
            q[-1] = cell.model.rest[-1]
        error = float(np.linalg.norm(cell._tcp_at(q) - point_m))
        if error <= IK_ACCURACY:
            break
    return q, error


def _aimed(current, axis) -> list:
    """The frame nearest ``current`` (quaternion x, y, z, w) whose z axis is ``axis`` (unit, (3,)):
    ``current`` turned by the shortest arc from its z axis onto ``axis``, as a list (x, y, z, w).
    In closed form (the half-way quaternion): SciPy's ``align_vectors`` gives the same rotation
    at 30x the cost, once per burst (tests/sim/test_free_axis.py compares the two)."""
    x, y, z, w = (float(v) for v in current)
    t0, t1, t2 = 2.0 * (x * z + w * y), 2.0 * (y * z - w * x), 1.0 - 2.0 * (x * x + y * y)
    tool_z = np.array([t0, t1, t2])
    dot = float(tool_z @ axis)
    if dot < -1.0 + 1e-12:  # opposite: half a turn about any axis across it
        across = np.cross(tool_z, [1.0, 0.0, 0.0] if abs(tool_z[0]) < 0.9 else [0.0, 1.0, 0.0])
        swing = np.append(across / np.linalg.norm(across), 0.0)
    else:
        # np.cross's products and differences, in floats (np.cross costs 40 µs a call, every burst)
        a0, a1, a2 = (float(v) for v in axis)
        swing = np.array([t1 * a2 - t2 * a1, t2 * a0 - t0 * a2, t0 * a1 - t1 * a0, 1.0 + dot])
        swing /= np.linalg.norm(swing)
    sx, sy, sz, sw = swing
    return [
        sw * x + sx * w + sy * z - sz * y,
        sw * y - sx * z + sy * w + sz * x,
        sw * z + sx * y - sy * x + sz * w,
        sw * w - sx * x - sy * y - sz * z,
    ]
