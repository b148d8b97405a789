"""Planning: a Cartesian path subdivided into IK samples, solved joint by joint, splined and timed to
the Panda's limits (:data:`bidmp.sim.backend.LIMIT_MARGIN` of them)."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import CubicSpline

from ..._checks import as_trajectory
from ...primitives.timing import Trajectory, time_scale
from ..backend import LIMIT_MARGIN, MotionPlan, SimError
from .robot import _REST, IK_TOLERANCE, MAX_SAMPLE_SPACING, PANDA, joint_seed, reachable, unit_name

__all__ = ["plan", "subdivide"]


def plan(cell, path, label: str = "", fractions=None, seed=None, orientations=None) -> MotionPlan:
    """Inverse kinematics along ``path`` (n, 3, scene units) and the fastest uniform timing
    within :data:`LIMIT_MARGIN` of the joint limits. ``fractions``: normalised time of each
    sample (default: uniform, as a DMP rollout is). ``orientations`` (n, 4): the tool frame
    along the path (a pose skill's); default pointing down."""
    path = as_trajectory(path, "path", min_points=2, allow_static=True)
    if path.shape[1] != 3:
        raise ValueError(f"path must have 3 columns, got {path.shape[1]}")
    for point in (path.min(axis=0), path.max(axis=0)):  # before subdividing it into 5 mm steps
        reachable(point * cell.unit, cell.base * cell.unit, "path")
    given = np.linspace(0.0, 1.0, path.shape[0]) if fractions is None else np.asarray(fractions, dtype=float)
    if given.shape != (path.shape[0],) or not np.all(np.isfinite(given)) or np.any(np.diff(given) < 0) \
            or given[0] < 0 or given[-1] > 1:
        raise ValueError(f"fractions must be {path.shape[0]} non-decreasing times in [0, 1]")
    points, u = subdivide(path * cell.unit, given, MAX_SAMPLE_SPACING)
    turns = None
    if orientations is not None:
        from scipy.spatial.transform import Rotation, Slerp

        q = np.asarray(orientations, dtype=float)
        if q.shape != (path.shape[0], 4):
            raise ValueError(f"orientations must have shape ({path.shape[0]}, 4), got {q.shape}")
        keep = np.concatenate([[True], np.diff(given) > 1e-12])
        turns = Slerp(given[keep], Rotation.from_quat(q[keep]))(u).as_quat()
    q = np.array(_REST, dtype=float) if seed is None else joint_seed(seed)
    joints = np.empty((points.shape[0], 7))
    for index, point in enumerate(points):
        q, error = cell.solve_ik(point, q, None if turns is None else turns[index])
        if error > IK_TOLERANCE:
            raise SimError(f"target {label!r}: the point {np.round(point / cell.unit, 2).tolist()} of its motion is "
                           f"unreachable for the Panda at base {np.round(cell.base, 1).tolist()} "
                           f"(inverse kinematics leaves {error / cell.unit:.3g} {unit_name(cell.unit)}); move the "
                           f"robot (scenario key \"robot\": {{\"base\": ...}})")
        below, above = q < np.array(PANDA.lower) - 1e-9, q > np.array(PANDA.upper) + 1e-9
        if below.any() or above.any():
            joint = int(np.flatnonzero(below | above)[0])
            raise SimError(f"target {label!r}: joint {joint + 1} would leave its limits "
                           f"[{PANDA.lower[joint]}, {PANDA.upper[joint]}] rad ({q[joint]:.3f})")
        joints[index] = q
    spline = CubicSpline(u, joints, bc_type="clamped")
    grid = np.linspace(0.0, 1.0, max(2001, 10 * len(u)))
    unit_time = Trajectory(grid, spline(grid), spline(grid, 1), spline(grid, 2))
    vmax = LIMIT_MARGIN * np.asarray(PANDA.velocity)
    amax = LIMIT_MARGIN * np.asarray(PANDA.acceleration)
    timed = time_scale(unit_time, max_velocity=vmax, max_acceleration=amax, norm="axis")
    duration = float(timed.t[-1])
    return MotionPlan(label, points, u, joints, duration, spline,
                      float(np.max(np.abs(timed.yd) / np.asarray(PANDA.velocity))),
                      float(np.max(np.abs(timed.ydd) / np.asarray(PANDA.acceleration))), turns)


def subdivide(points: np.ndarray, fractions: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """The IK samples of a path: samples closer than ``spacing / 2`` to the last one kept are
    dropped (the joint spline interpolates them to micrometres), and points (with their times)
    are inserted on segments longer than ``spacing``."""
    keep, last = [0], points[0]
    for index in range(1, len(points) - 1):
        if np.linalg.norm(points[index] - last) >= 0.5 * spacing:
            keep.append(index)
            last = points[index]
    keep.append(len(points) - 1)
    points, fractions = points[keep], fractions[keep]
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    pieces = np.maximum(np.ceil(lengths / spacing).astype(int), 1)
    out_points, out_u = [points[:1]], [fractions[:1]]
    for index, count in enumerate(pieces):
        share = np.arange(1, count + 1)[:, None] / count
        out_points.append(points[index] + share * (points[index + 1] - points[index]))
        out_u.append(fractions[index] + share[:, 0] * (fractions[index + 1] - fractions[index]))
    points, u = np.vstack(out_points), np.concatenate(out_u)
    keep = np.concatenate([[True], np.diff(u) > 1e-12])
    return points[keep], u[keep]
