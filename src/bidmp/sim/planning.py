"""Planning, for any backend: a Cartesian path subdivided into IK samples, solved joint by joint
through the backend's ``solve_ik``, splined (quintic, at rest at both ends) and timed to the
arm's velocity, acceleration and jerk limits (:data:`bidmp.sim.backend.LIMIT_MARGIN` of them).
Any number of joints: the backend's ``n_joints``, ``rest`` and ``limits`` say how many."""

from __future__ import annotations

import numpy as np
from scipy.interpolate import make_interp_spline

from .._checks import as_trajectory, as_vector, check_real
from .._trajectory import interp_columns
from .._units import length_digits
from ..primitives.so3 import as_quaternions
from ..primitives.timing import Trajectory, time_scale
from .backend import LIMIT_MARGIN, MotionPlan, SimError
from .pacing import _paced_duration, _slowed  # noqa: F401 - run and the job read them here
from .robots import IK_TOLERANCE, MAX_SAMPLE_SPACING, _joint_seed, _reachable, _unit_name

__all__ = ["plan_path"]


def plan_path(
    cell,
    path,
    label: str = "",
    fractions=None,
    seed=None,
    orientations=None,
    spacing: float = MAX_SAMPLE_SPACING,
) -> MotionPlan:
    """Inverse kinematics along ``path`` (n, 3, scene units) and the fastest uniform timing
    within :data:`LIMIT_MARGIN` of the joint limits, for the backend ``cell`` (its ``unit``,
    ``base``, ``rest``, ``name``, ``limits`` and ``solve_ik``). ``fractions``: normalised time of each
    sample (default: uniform, as a DMP rollout is). ``orientations`` (n, 4): the tool frame
    along the path (a pose skill's); default pointing down."""
    missing = [
        member
        for member in ("solve_ik", "limits", "unit", "base", "rest", "name")
        if not hasattr(cell, member)
    ]
    if missing:
        raise TypeError(
            f"cell must be a simulator backend (bidmp.sim.SimulatorBackend); "
            f"{type(cell).__name__} lacks {', '.join(missing)}"
        )
    path = as_trajectory(path, "path", min_points=2, allow_static=True)
    if path.shape[1] != 3:
        raise ValueError(f"path must have 3 columns, got {path.shape[1]}")
    if not isinstance(label, str) or len(label) > 256:
        raise TypeError(f"label must be the target's name (a string), got {type(label).__name__}")
    # (IK samples a micrometre apart or closer: a unit mistake, and a path of millions of samples)
    spacing = check_real(spacing, "spacing", minimum=1e-6, maximum=1.0)
    for point in (path.min(axis=0), path.max(axis=0)):  # before subdividing it into 5 mm steps
        _reachable(point * cell.unit, cell.base * cell.unit, "path")
    given = (
        np.linspace(0.0, 1.0, path.shape[0])
        if fractions is None
        else as_vector(fractions, "fractions")
    )
    if (
        given.shape != (path.shape[0],)
        or np.any(np.diff(given) < 0)
        or given[0] < 0
        or given[-1] > 1
    ):
        raise ValueError(f"fractions must be {path.shape[0]} non-decreasing times in [0, 1]")
    points, u = _subdivide(path * cell.unit, given, spacing)
    turns = None
    if orientations is not None:
        from scipy.spatial.transform import Rotation, Slerp

        q = as_quaternions(orientations, "orientations")
        if q.shape != (path.shape[0], 4):
            raise ValueError(f"orientations must have shape ({path.shape[0]}, 4), got {q.shape}")
        keep = np.concatenate([[True], np.diff(given) > 1e-12])
        turns = Slerp(given[keep], Rotation.from_quat(q[keep]))(u).as_quat()
    limits = cell.limits
    n_joints = limits.n_joints
    q = np.array(cell.rest, dtype=float) if seed is None else _joint_seed(seed, limits)
    joints = np.empty((points.shape[0], n_joints))
    for index, point in enumerate(points):
        turn = None if turns is None else turns[index]
        q, error = cell.solve_ik(point, q, turn)
        if error > IK_TOLERANCE:
            raise SimError(_not_followed(cell, label, point, turn, error))
        below, above = q < np.array(limits.lower) - 1e-9, q > np.array(limits.upper) + 1e-9
        if below.any() or above.any():
            joint = int(np.flatnonzero(below | above)[0])
            raise SimError(
                f"target {label!r}: joint {joint + 1} would leave its limits "
                f"[{limits.lower[joint]}, {limits.upper[joint]}] rad ({q[joint]:.3f})"
            )
        joints[index] = q
    # A quintic spline at rest at both ends, acceleration included: the arm's interface asks for
    # zero velocity and acceleration where a motion starts and stops (a clamped cubic ends with
    # an acceleration, up to 0.45 of the limit), and its jerk is then bounded too.
    rest = [(1, np.zeros(n_joints)), (2, np.zeros(n_joints))]
    spline = make_interp_spline(u, joints, k=5, bc_type=(rest, rest))
    grid = np.linspace(0.0, 1.0, max(4001, 20 * len(u)))
    # The joints' rates in normalised time, evaluated once for the timing and the peaks.
    rates = [spline(grid, 1), spline(grid, 2)]
    unit_time = Trajectory(grid, spline(grid), rates[0], rates[1])
    caps = {
        "max_velocity": LIMIT_MARGIN * np.asarray(limits.velocity),
        "max_acceleration": LIMIT_MARGIN * np.asarray(limits.acceleration),
        "max_jerk": None if limits.jerk is None else LIMIT_MARGIN * np.asarray(limits.jerk),
    }
    duration = float(time_scale(unit_time, norm="axis", **caps).t[-1])
    if limits.jerk is not None:
        rates.append(spline(grid, 3))
    peaks = [
        0.0
        if limit is None
        else float(np.max(np.abs(rates[order - 1]) / duration**order / np.asarray(limit)))
        for order, limit in ((1, limits.velocity), (2, limits.acceleration), (3, limits.jerk))
    ]
    return MotionPlan(
        label, points, u, joints, duration, spline, peaks[0], peaks[1], turns, peak_jerk=peaks[2]
    )


_REACH_SEEDS = 8  # seeded draws (beside the rest pose and the ranges' middle) a point is tried from


def _not_followed(cell, label: str, point: np.ndarray, turn, error: float) -> str:
    """Why the inverse kinematics did not follow a motion to ``point`` (m), leaving ``error``:
    where joints from elsewhere (the rest pose, the ranges' middle, seeded draws within the
    limits) put the tool there, the motion's way is the trouble (a singularity or a joint's range
    on it), and the point is not called unreachable; where none does, it is, and the reason
    says to move the arm's base."""
    digits = length_digits(_unit_name(cell.unit))  # 0.01 mm detail in the scene's unit
    where = np.round(point / cell.unit, digits).tolist()
    leaves = f"{error / cell.unit:.3g} {_unit_name(cell.unit)}"
    lower, upper = np.asarray(cell.limits.lower), np.asarray(cell.limits.upper)
    middle, half = 0.5 * (lower + upper), np.minimum(0.5 * (upper - lower), np.pi)
    draws = np.random.default_rng(0).uniform(-1.0, 1.0, (_REACH_SEEDS, lower.size))
    elsewhere = (
        f"target {label!r}: the inverse kinematics does not follow its motion to the point "
        f"{where} from the joints before it (it leaves {leaves} there), though other joints "
        "of the arm reach that point: a singularity or a joint's range on the way"
    )
    for start in np.vstack([np.asarray(cell.rest, dtype=float), middle, middle + draws * half]):
        _, reached = cell.solve_ik(point, start, turn)
        if reached <= IK_TOLERANCE:
            return elsewhere
    from .routes import reach, supports_routes

    # An arm known from its URDF is asked once more by the routes' own inverse kinematics (damped
    # least squares on the arm's model from 24 starts, the tool's turn free): near a wrist's
    # singularity it reaches points the simulator's IK misses from all of the starts above (an
    # xArm6's unscrew 14.4 mm up a nut's tilted axis, in a random cell of the route oracle).
    if supports_routes(cell) and not reach(cell, point / cell.unit, turn):
        return elsewhere
    return (
        f"target {label!r}: the point {where} of its motion is unreachable for the {cell.name} at "
        f"base {np.round(cell.base, digits).tolist()} (inverse kinematics from the joints before "
        f"it, the rest pose, the ranges' middle and {_REACH_SEEDS} other starts leaves {leaves}): "
        'out of its reach (move its base: scenario key "robot": {"base": ...})'
    )


def _subdivide(
    points: np.ndarray, fractions: np.ndarray, spacing: float
) -> tuple[np.ndarray, np.ndarray]:
    """The IK samples of a path: evenly spaced in time (``fractions``), as few as keep consecutive
    samples at most ``spacing`` apart where the path moves fastest, linearly interpolated between
    the given samples (at rest: the ends only).

    Even spacing in time matters: the joints are splined in time, and a cubic spline through knots
    whose time steps change abruptly (dropping close samples, inserting on long steps) overshoots
    between them — on a transfer slower than the approach after it, by 0.7 mm off a straight
    Cartesian line."""
    steps = np.linalg.norm(np.diff(points, axis=0), axis=1)
    durations = np.diff(fractions)
    moving = durations > 1e-12
    if not np.any(moving) or not np.any(steps[moving] > 0.0):
        return points[[0, -1]], fractions[[0, -1]]
    fastest = float(np.max(steps[moving] / durations[moving]))  # distance per unit of time
    count = max(int(np.ceil(fastest * (fractions[-1] - fractions[0]) / spacing)), 1) + 1
    u = np.linspace(fractions[0], fractions[-1], count)
    keep = np.concatenate([[True], moving])
    return interp_columns(u, fractions[keep], points[keep]), u
