"""The arm's complete fallback: where a motion from the learned skills cannot run on the arm — a
point of it the inverse kinematics does not reach from the joints before it (a wrist singularity
on the way), a joint limit, a link that would touch a part the tool passes clear of — the arm's
own route, planned in joint space over its links and tool against the cell (RRT-Connect,
:func:`bidmp.planning.plan_route`, tested by :class:`bidmp.sim.arm_geometry.ArmSpace`), ending in
the demonstrated final approach: straight down the part's own axis, from a little above the
approach height. The whole is timed as fast as the arm's limits allow
(:func:`bidmp.planning.time_path`) and handed back as a :class:`~bidmp.sim.backend.MotionPlan`,
which the motion contract judges like any other before it runs.

Free axes stay free: the goal configurations are the inverse kinematics of the approach's top with
the tool's turn about its own axis left to the arm (a socket), from several seeds, so a wrist at
its singularity has its other branch; a drop over a bin (no final approach) may tilt the tool
within a cone below the vertical (the part falls the same).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .._checks import as_point, as_vector, check_bool, check_int, check_real
from .._units import length_text
from ..planning import NoRouteError, plan_route, segment_free, time_path
from .backend import LIMIT_MARGIN, JointLimits, MotionPlan, SimError
from .robots import IK_TOLERANCE

__all__ = [
    "judged_route",
    "reach",
    "ArmRoute",
    "arm_route",
    "supports_routes",
    "needlessly_slow",
    "DROP_CONE_DEG",
    "SLOW",
]

logger = logging.getLogger(__name__)

DROP_CONE_DEG = 30.0  # a dropped part falls the same from a tool tilted this much from vertical
# A plan the arm's limits stretch to more than this many times the direct joint move between its
# ends passes near a singularity, its joints racing while the tool barely moves (a 22.9 s approach
# of 0.3 m on the busbar cell, 1.0 s direct); the built-in tasks' curved approaches and lifted
# transfers take 3.2 to 9.0 times it (the cell task's approaches to B5 and B6: 9.0 and 8.9).
SLOW = 15.0
_ABOVE = 0.5  # the route ends this share of the approach height above the approach's top
_GOALS = 4  # goal configurations the route may end at (distinct branches of the IK)
_SEEDS = 24  # inverse kinematics tried for them (the joints now, the rest pose, seeded draws)
# rad a route keeps inside each joint's range: the spline timed through it overshoots a joint
# held at its end (the Panda's joint 6 past 3.7525 rad by 1e-5); an FR3 keeps further in (below)
_INSIDE = 0.005
# rad: the route is subdivided this finely before it is splined (finer where the spline through
# the coarser points leaves the free space or a joint's range)
_SPACINGS = (0.05, 0.02, 0.008)
_CACHE: dict = {}


@dataclass
class ArmRoute:
    """What the arm's fallback made: the plan (a :class:`MotionPlan`), how many configurations it
    tested, how long it took (s), the route's length in joint space (rad) and in the tool's travel
    (scene units)."""

    plan: MotionPlan
    checks: int
    seconds: float
    joint_length: float
    tool_length: float
    timing: str


def supports_routes(cell) -> bool:
    """Whether ``cell``'s arm can have a route of its own: a backend whose arm is a URDF model
    (the PyBullet arms, a user's URDF), with the planner's extra installed."""
    from .robots import RobotModel

    if not isinstance(getattr(cell, "model", None), RobotModel) or not hasattr(cell, "solve_ik"):
        return False
    import importlib.util

    missing = [
        name for name in ("ompl", "pinocchio", "toppra") if importlib.util.find_spec(name) is None
    ]
    if missing:
        logger.info("the arm's routes need %s: pip install 'bidmp[plan]'", ", ".join(missing))
    return not missing


def needlessly_slow(cell, plan) -> bool:
    """Whether ``plan`` (timed to the arm's limits) lasts more than :data:`SLOW` times the direct
    joint move between its first and last joints, timed the same way."""
    if not isinstance(plan, MotionPlan):
        raise TypeError(f"plan must be a bidmp.sim.MotionPlan, got {type(plan).__name__}")
    limits = getattr(cell, "limits", None)
    if not isinstance(limits, JointLimits):
        raise TypeError(
            f"cell must be a simulator backend with its limits, got {type(cell).__name__}"
        )
    joints = np.asarray(plan.joints, dtype=float)
    if joints.ndim != 2 or joints.shape[1] != limits.n_joints:
        raise ValueError(f"plan's joints must be (n, {limits.n_joints}), got {joints.shape}")
    if joints.shape[0] < 2 or np.max(np.abs(joints[-1] - joints[0])) < 1e-6:
        return False
    direct = time_path(
        joints[[0, -1]], limits.velocity, limits.acceleration, limits.jerk, margin=LIMIT_MARGIN
    )
    return plan.duration > SLOW * direct.duration


def _arm(cell):
    """The cell's arm as an :class:`~bidmp.sim.arm_geometry.ArmGeometry` (kept per arm, tool and
    placement: building it loads the URDF and its meshes)."""
    from .arm_geometry import ArmGeometry

    model = getattr(cell, "model", None)
    scene = cell.scene
    key = (model, scene.tool.radius, scene.tool.length, cell.unit, tuple(cell.base), cell.yaw)
    if _CACHE.get("key") != key:
        _CACHE["arm"] = ArmGeometry(
            model,
            scene.tool.radius * cell.unit,
            scene.tool.length * cell.unit,
            np.asarray(cell.base, dtype=float) * cell.unit,
            cell.yaw,
        )
        _CACHE["key"] = key
    return _CACHE["arm"]


def arm_route(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    cell,
    start,
    goal,
    *,
    scene=None,
    axis=None,
    approach_height: float = 0.0,
    orientation=None,
    exclude=(),
    margin: float | None = None,
    seed: int = 0,
    label: str = "",
    carried=None,
    cone: float = 0.0,
    free_start: bool = False,
    retract: float = 0.0,
    links: float | None = None,
) -> ArmRoute:
    """The arm's route from joints ``start`` to ``goal`` (module docstring).

    Parameters
    ----------
    cell : bidmp.sim.pybullet.RobotCell
        A backend whose arm is a URDF model (``model``, ``scene``, ``unit``, ``base``, ``yaw``,
        ``limits``, ``solve_ik``, ``plan``).
    start : array (J,)
        The joints now (rad).
    goal : array (3,)
        The target (scene units).
    scene : bidmp.Scene, optional
        The parts the arm keeps clear of (default the cell's; a job's has its bin and rack).
    axis : array (3,), optional
        The target's axis, out of it: the motion ends with the final approach down it. None: no
        final approach (a drop: the tool may tilt within ``cone`` degrees of pointing down).
    approach_height : float
        The final approach's length (scene units).
    orientation : array (4,), optional
        The tool's frame at the target (a tilted part's); default along -``axis``.
    exclude : sequence of str
        Parts the arm may touch (the target's own).
    margin : float, optional
        Scene units kept from every other part (default the scene's), a part's stand-off from it.
    seed : int
    label : str
        The target's name, in messages.
    carried : (bidmp.scene.Solid, array (J,)), optional
        A part the tool holds (its solid where it is now) and the joints now: it moves with the
        tool and is kept clear too.
    cone : float
        Degrees the tool may tilt from pointing down where there is no final approach.
    retract : float
        How far up the axis the task takes the tool after the approach (a job's unscrew and
        retract; scene units): the final approach starts at least that high, so that the arm's
        configuration at the target follows that way back up too.
    free_start : bool
        The route may start from any joints that put the tool where ``start`` puts it (a
        simulated motion, which the arm is placed at the start of): where ``start`` would have a
        link within the margin of a part, the first of several inverse kinematics solutions
        that keeps it is taken instead. False: the arm is at ``start`` (a job's joints now).
    links : float, optional
        Scene units every link keeps from the parts (default the tracking allowance, 0.5 mm: the
        contract asks the links only not to touch; the tool keeps the margin).

    Raises
    ------
    SimError
        No route: the message says why (no goal configuration within the limits, none free, no
        route found in the budget).
    """
    if not supports_routes(cell):
        raise TypeError(
            "cell must be a simulator backend whose arm is a URDF model (bidmp.sim.RobotCell), with "
            f"the planner's extra installed (pip install 'bidmp[plan]'), got {type(cell).__name__}"
        )
    scene = cell.scene if scene is None else scene
    unit = cell.unit
    arm = _arm(cell)
    start = as_point(start, cell.limits.n_joints, "start", like="the arm's joints")
    goal = as_vector(goal, "goal")
    if goal.shape[0] < 3:
        raise ValueError(f"goal must be a point (x, y, z), got {goal.shape[0]} values")
    approach_height = check_real(approach_height, "approach_height", nonnegative=True)
    retract = check_real(retract, "retract", nonnegative=True)
    cone = check_real(cone, "cone", nonnegative=True, maximum=90.0)
    seed = check_int(seed, "seed", minimum=0, maximum=2**32 - 2)
    if axis is not None:
        axis = as_point(axis, 3, "axis")
        if not np.linalg.norm(axis) > 0.0:
            raise ValueError("axis must be a direction (not zero)")
    from .execution import TRACKING_ALLOWANCE_MM

    margin_m = (scene.margin if margin is None else margin) * unit
    links_m = (
        TRACKING_ALLOWANCE_MM * 1e-3
        if links is None
        else check_real(links, "links", nonnegative=True) * unit
    )
    space = arm.space(scene, unit, exclude=exclude, margin=margin_m, carried=carried, links=links_m)
    start = np.clip(np.asarray(start, dtype=float), space.lower, space.upper)
    inside = _inside(cell.limits)
    # the route keeps inside the ranges (where the arm is now may be nearer an end)
    space.lower = np.minimum(space.lower + inside, start)
    space.upper = np.maximum(space.upper - inside, start)
    if check_bool(free_start, "free_start") and space.slack(start) < 0.0:
        start = _free_start(cell, space, start, seed)
    goal = np.asarray(goal, dtype=float)[:3]
    name = f"target {label!r}: " if label else ""
    descent = None
    if axis is not None and approach_height > 0.0:
        axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
        top = goal + axis * max(approach_height * (1.0 + _ABOVE), retract)
        frame = _approach_frame(axis) if orientation is None else np.asarray(orientation, float)
        descent = np.linspace(top, goal, 2)
        goals, tails, why = _approach_goals(cell, space, start, descent, frame, seed)
    else:
        frames = _cone(cone)
        goals, tails, why = _drop_goals(cell, space, start, goal, frames, seed)
    if not goals:
        raise SimError(f"{name}no route of the arm: {why}")
    try:
        route = plan_route(space, start, np.array(goals), seed=seed, max_checks=40_000)
    except NoRouteError as exc:
        raise SimError(f"{name}no route of the arm round the parts: {exc}") from None
    tail = tails[route.goal]
    limits = cell.limits
    for spacing in _SPACINGS:
        # the timing's spline passes through the route's points: the finer they lie, the closer
        # it keeps to the route's free segments and inside the joints' ranges at its bends
        joints = np.vstack([_subdivided(route.waypoints, spacing), tail[1:]])
        timed = time_path(
            joints,
            limits.velocity,
            limits.acceleration,
            limits.jerk,
            margin=LIMIT_MARGIN,
        )
        fractions = np.linspace(0.0, 1.0, max(200, 4 * joints.shape[0]))
        sampled = timed(fractions)
        unsafe = _first_unsafe(space, sampled)
        beyond = _beyond_range(limits, timed)
        if unsafe is None and beyond is None:
            break
    else:
        if beyond is not None:
            raise SimError(
                f"{name}the arm's route, smoothed and timed, would take joint {beyond + 1} past "
                "its range"
            )
        part, depth = space.nearest(sampled[unsafe])
        raise SimError(
            f"{name}the arm's route, smoothed and timed, would come within "
            f"{length_text(max(-depth, 0.0) / unit, _unit_name(unit))} of the clearance of {part}"
        )
    poses = [arm.tool_pose(q) for q in sampled]
    points = np.array([p for p, _ in poses])
    turns = Rotation.from_matrix([r for _, r in poses]).as_quat()
    plan = MotionPlan(
        label,
        points,
        fractions,
        sampled,
        timed.duration,
        timed,
        timed.peaks[0],
        timed.peaks[1],
        turns,
        peak_jerk=timed.peaks[2],
    )
    from .pacing import _slowed

    stretch = _fci_stretch(limits, timed)
    if stretch > SLOW:  # it passes where the FCI lets a joint barely move towards its stop
        raise SimError(
            f"{name}the arm's route passes so near a joint's range end that its controller's "
            f"velocity limits there would make it {stretch:.0f} times slower"
        )
    _slowed(plan, timed.duration * stretch)
    tool_length = float(np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1))) / unit
    return ArmRoute(
        plan,
        route.checks,
        route.seconds,
        float(np.sum(np.linalg.norm(np.diff(joints, axis=0), axis=1))),
        tool_length,
        timed.timing,
    )


def reach(cell, point, frame=None, seed: int = 0) -> str:
    """Why the arm cannot put the tool's mouth at ``point`` (scene units) with its axis as
    ``frame`` (a quaternion; default pointing down), its turn free: "" when joints within the
    limits do, from any of several seeds (the rest pose, the ranges' middle, seeded draws). A
    point is called out of reach only when none does, and the reason says how far it is, which
    joint stops at its limit on the way, and what would help."""
    if not supports_routes(cell):
        raise TypeError(
            "cell must be a simulator backend whose arm is a URDF model (bidmp.sim.RobotCell), with "
            f"the planner's extra installed (pip install 'bidmp[plan]'), got {type(cell).__name__}"
        )
    unit = cell.unit
    arm = _arm(cell)
    point_m = as_point(point, 3, "point") * unit
    seed = check_int(seed, "seed", minimum=0, maximum=2**32 - 2)
    frame = np.array([1.0, 0.0, 0.0, 0.0]) if frame is None else as_vector(frame, "frame")
    lower, upper = np.asarray(cell.limits.lower), np.asarray(cell.limits.upper)
    best, best_q = math.inf, None
    for start in _seeds(cell, np.asarray(cell.rest, dtype=float), seed):
        q, error = arm.solve_ik(
            point_m, frame, start, free_turn=bool(getattr(cell, "free_turn", True))
        )
        if error <= IK_TOLERANCE:
            return ""
        if error < best:
            best, best_q = error, q
    distance = float(np.linalg.norm(point_m - arm.first_joint))
    if distance > arm.tool_reach:
        return (
            f"{distance:.3g} m from the arm's first joint, beyond its reach ({arm.tool_reach:.3g} m): "
            'move its base nearer (scenario key "robot": {"base": ...})'
        )
    stopped = np.flatnonzero((best_q <= lower + 1e-6) | (best_q >= upper - 1e-6))
    held = f"; joint {int(stopped[0]) + 1} stops at its limit on the way" if stopped.size else ""
    return (
        f"no joints within the limits put the tool there (the nearest leaves "
        f"{best / unit:.3g} {_unit_name(unit)}{held}): move the arm's base nearer (scenario key "
        '"robot": {"base": ...}), or turn the part toward it'
    )


def judged_route(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    cell,
    contract,
    start,
    target,
    *,
    axis=None,
    approach_height: float = 0.0,
    exclude=(),
    margin: float | None = None,
    pace: float | None = None,
    label: str = "",
) -> MotionPlan:
    """The arm's route (:func:`arm_route`) from the joints that put the tool at ``start`` (a point
    or pose, scene units; else the rest pose) to ``target`` (a point, or a pose whose frame the
    tool takes), no faster than ``pace`` (the demonstration's peak tool speed, scene units per
    second), and judged by ``contract`` on its planned tool path before it may run: a
    ``SimError`` says why not."""
    from .pacing import _paced_duration, _slowed

    start = as_vector(start, "start")
    target = as_vector(target, "target")
    pose = target.shape[0] >= 7
    rest = np.asarray(cell.rest, dtype=float)
    first, error = cell.solve_ik(
        start[:3] * cell.unit, rest, start[3:7] if start.shape[0] >= 7 else None
    )
    begin = np.asarray(first, dtype=float) if error <= IK_TOLERANCE else rest
    routed = arm_route(
        cell,
        begin,
        target[:3],
        free_start=True,  # the simulated motion starts where the route does
        axis=[0.0, 0.0, 1.0] if axis is None else axis,
        approach_height=approach_height,
        orientation=target[3:7] if pose else None,
        exclude=exclude,
        margin=margin,
        label=label,
    )
    plan = routed.plan
    path = plan.points / cell.unit
    _slowed(plan, _paced_duration(path, plan.fractions, pace))
    verdict = contract.judge(
        path,
        target[:3],
        label=label,
        axis=axis,
        exclude=exclude,
        # the route turns the tool as the joints go (a position scenario's too): judged as it is
        orientations=plan.orientations,
    )
    if not verdict.ok:
        raise SimError(f"the contract refuses its planned motion: {verdict.reason()}")
    return plan


def _inside(limits: JointLimits) -> np.ndarray:
    """Radians a route keeps inside each joint's range: :data:`_INSIDE`, and on an arm whose
    controller's velocity limits fall towards each range's end (the FR3's position-based limits)
    as far in as where they still leave a quarter of the joint's top speed (0.08 to 0.18 rad):
    a route that came to rest nearer an end would have to creep (the FCI's limit there falls to
    nothing within 8 mrad of it)."""
    inside = np.full(limits.n_joints, _INSIDE)
    fci = getattr(limits, "fci", None)
    if fci is None:
        return inside
    from .fci import FCI_LIMITS

    table = FCI_LIMITS[fci]
    if table.velocity_offset is None:
        return inside
    speed = 0.25 * np.asarray(table.velocity) + np.asarray(table.velocity_offset)
    return np.maximum(inside, speed**2 / (2.0 * np.asarray(table.deceleration)))


def _fci_stretch(limits: JointLimits, timed) -> float:
    """How many times longer the timed route must last for a Franka arm's FCI to take it: the
    FR3's velocity limits fall towards each joint's range ends (its position-based limits), and a
    route, unlike the skills' motions, may pass near them; its velocities are kept within
    :data:`LIMIT_MARGIN` of those limits where it is, sampled every millisecond. 1 for an arm
    without such limits (the constant ones are the timing's own)."""
    if getattr(limits, "fci", None) is None:
        return 1.0
    from .fci import FCI_LIMITS

    table = FCI_LIMITS[limits.fci]
    if table.velocity_offset is None:  # the same velocity limit everywhere: the timing's own
        return 1.0
    u = np.linspace(0.0, 1.0, max(2001, int(np.ceil(timed.duration * 1e3)) + 1))
    positions, velocities = timed(u), timed(u, 1) / timed.duration
    lowest, highest = table.velocity_bounds(positions)
    tiny = 1e-9
    share = np.where(
        velocities > 0.0,
        velocities / np.maximum(highest, tiny),
        velocities / np.minimum(lowest, -tiny),
    )
    return max(1.0, float(np.max(share)) / LIMIT_MARGIN)


def _unit_name(unit: float) -> str:
    return {1.0: "m", 1e-2: "cm", 1e-3: "mm"}.get(unit, "m")


def _approach_frame(axis: np.ndarray) -> np.ndarray:
    """The tool's frame coming down ``axis`` (its z axis along -axis), as a quaternion."""
    down = Rotation.from_quat([1.0, 0.0, 0.0, 0.0])
    turn, _ = Rotation.align_vectors([-axis], [[0.0, 0.0, -1.0]])
    return (turn * down).as_quat()


def _seeds(cell, start: np.ndarray, seed: int) -> np.ndarray:
    """Where the inverse kinematics starts: the joints now, the rest pose, seeded draws within
    the limits (each joint within half a turn of its range's middle)."""
    lower, upper = np.asarray(cell.limits.lower), np.asarray(cell.limits.upper)
    middle, half = 0.5 * (lower + upper), np.minimum(0.5 * (upper - lower), np.pi)
    draws = np.random.default_rng(seed).uniform(-1.0, 1.0, (_SEEDS, lower.size))
    return np.vstack([start, np.asarray(cell.rest, dtype=float), middle + draws * half])


def _solutions(cell, space, point_m, frame, seeds, enough: int = _GOALS) -> list:
    """Distinct joint solutions (within the limits, free) putting the mouth at ``point_m`` (m)
    with the tool's axis as ``frame`` has it (its turn about the axis free where the cell's tool
    turns freely), up to ``enough`` of them."""
    arm = _arm(cell)
    free_turn = bool(getattr(cell, "free_turn", True))
    found = []
    for seed in seeds:
        q, error = arm.solve_ik(
            point_m, frame, seed, free_turn=free_turn, inside=_inside(cell.limits)
        )
        if error > IK_TOLERANCE:
            continue
        if any(np.max(np.abs(q - other)) < 1e-2 for other in found):
            continue
        if space.slack(q) >= 0.0:
            found.append(q)
            if len(found) >= enough:
                break
    return found


def _free_start(cell, space, start: np.ndarray, seed: int) -> np.ndarray:
    """Joints that put the tool where ``start`` does (its mouth and axis, its turn free where the
    cell's tool turns freely) with every link clear of the parts: the first such solution from
    several seeds, else ``start`` itself (the planner then says it is not free)."""
    mouth, frame = _arm(cell).tool_pose(start)
    found = _solutions(
        cell, space, mouth, Rotation.from_matrix(frame).as_quat(), _seeds(cell, start, seed), 1
    )
    return found[0] if found else start


def _approach_goals(cell, space, start, descent, frame, seed) -> tuple[list, list, str]:
    """Goal configurations at the approach's top, each with the joints down the approach from
    it (IK samples along the straight descent, free): up to :data:`_GOALS` of them."""
    unit = cell.unit
    tops = _solutions(cell, space, descent[0] * unit, frame, _seeds(cell, start, seed), 2 * _GOALS)
    if not tops:
        return (
            [],
            [],
            "no joints within the limits put the tool at the approach's top free of the parts",
        )
    goals, tails = [], []
    arm = _arm(cell)
    free_turn = bool(getattr(cell, "free_turn", True))
    line = _line(descent[0], descent[1], cell.unit)
    problem, touched = "", ""
    for q in tops:
        joints = [q]
        for point in line[1:]:
            step, error = arm.solve_ik(
                point,
                frame,
                joints[-1],
                free_turn=free_turn,
                iterations=30,
                inside=_inside(cell.limits),
            )
            if error > IK_TOLERANCE:
                problem = "the arm cannot follow the final approach down the part's axis"
                break
            joints.append(step)
        else:
            joints = np.array(joints)
            blocked = next(
                (b for a, b in zip(joints[:-1], joints[1:]) if not segment_free(space, a, b)),
                None,
            )
            if blocked is None:
                goals.append(joints[0])
                tails.append(joints)
            else:
                touched = space.nearest(blocked)[0]
        if len(goals) >= _GOALS:
            break
    why = problem or (
        f"on the final approach down the part's axis the arm would come within its clearance "
        f"of {touched}, whichever way its joints turn ({len(tops)} tried)"
    )
    return goals, tails, why


def _line(top: np.ndarray, goal: np.ndarray, unit: float) -> np.ndarray:
    """Points (m) every 2 mm or closer from ``top`` to ``goal`` (scene units), both included."""
    length = float(np.linalg.norm(goal - top)) * unit
    count = max(int(math.ceil(length / 2e-3)), 1) + 1
    return np.linspace(top, goal, count) * unit


def _cone(cone: float) -> list:
    """Tool frames pointing down and tilted up to ``cone`` degrees from it (12 ways round)."""
    down = Rotation.from_quat([1.0, 0.0, 0.0, 0.0])
    frames = [down.as_quat()]
    for tilt in (cone / 3.0, 2.0 * cone / 3.0, cone) if cone > 0.0 else ():
        for turn in np.arange(0.0, 360.0, 30.0):
            axis = [math.cos(math.radians(turn)), math.sin(math.radians(turn)), 0.0]
            frames.append(
                (Rotation.from_rotvec(np.radians(tilt) * np.array(axis)) * down).as_quat()
            )
    return frames


def _drop_goals(cell, space, start, goal, frames, seed) -> tuple[list, list, str]:
    """Goal configurations with the mouth at ``goal``, the tool in any of ``frames``."""
    goals = []
    seeds = _seeds(cell, start, seed)[:8]
    for frame in frames:
        goals += _solutions(cell, space, goal * cell.unit, frame, seeds)
        if len(goals) >= _GOALS:
            break
    tails = [q[None] for q in goals]
    return goals, tails, "no joints within the limits put the tool there free of the parts"


def _subdivided(path: np.ndarray, spacing: float) -> np.ndarray:
    pieces = [path[:1]]
    for a, b in zip(path[:-1], path[1:]):
        steps = max(int(np.ceil(np.max(np.abs(b - a)) / spacing)), 1)
        pieces.append(a + (b - a) * (np.arange(1, steps + 1)[:, None] / steps))
    return np.vstack(pieces)


def _beyond_range(limits: JointLimits, timed):
    """The first joint the timed route takes outside its range, sampled every millisecond (the
    commands' rate), or None."""
    u = np.linspace(0.0, 1.0, max(2001, int(np.ceil(timed.duration * 1e3)) + 1))
    q = timed(u)
    outside = np.any((q < np.asarray(limits.lower)) | (q > np.asarray(limits.upper)), axis=0)
    return int(np.flatnonzero(outside)[0]) if outside.any() else None


def _first_unsafe(space, joints: np.ndarray):
    """The index of the first sample whose segment to the next is not free, or None."""
    for index in range(joints.shape[0] - 1):
        if not segment_free(space, joints[index], joints[index + 1]):
            return index
    return None
