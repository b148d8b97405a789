"""The tool's own route through a scene: from where a motion starts to the top of the target's final
approach, by RRT-Connect over the tool's position (and, for a pose, how far it has turned from its
start frame to the target's), then straight down the target's axis onto it.

The arm is not here: this is the route of the tool, the thing the motion contract judges in a task
without an arm (``bidmp demo``). The arm's own route, its links against the cell, is
:mod:`bidmp.sim.routes`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .._checks import as_labels, as_point, as_vector, check_int, check_real
from .rrt import NoRouteError, plan_route

__all__ = ["ToolRoute", "tool_route"]

# The least step of the tool along a segment tested, as a share of the margin (0.3 mm for 3 mm):
# routes keep the margin plus this at every test, so the swept tool keeps the margin between.
_TOLERANCE = 0.1
_ABOVE = 0.5  # the descent starts this share of the approach height above it
# Partial shortcuts of a tool's route (3 or 4 coordinates): on the busbar cell's post, 20 to 200
# rounds gave routes within 1 % of one another's length, 40 at a fifth of 200's tests.
_ROUNDS = 40


@dataclass(frozen=True)
class ToolRoute:
    """A route of the tool (:func:`tool_route`).

    Attributes
    ----------
    waypoints : array (k, 3) or (k, 7)
        The tool's mouth (and, for a pose, its frame: quaternions x, y, z, w) from the start to the
        target: the planned route to the top of the final approach, then straight down the axis.
        The tool moves straight (and turns by the shortest arc) between consecutive waypoints.
    path : array (m, 3) or (m, 7)
        The same route subdivided, its corners rounded where the rounding stays free.
    approach : int
        The index of ``path``'s point where the final approach begins.
    checks : int
        Placements of the tool tested.
    seconds : float
        Wall time (s).
    """

    waypoints: np.ndarray
    path: np.ndarray
    approach: int
    checks: int
    seconds: float

    @property
    def length(self) -> float:
        """The mouth's path length along ``path`` (scene units)."""
        return float(np.sum(np.linalg.norm(np.diff(self.path[:, :3], axis=0), axis=1)))

    def motion(self, count: int) -> np.ndarray:
        """``count`` samples of the tool along ``path``, evenly spaced in time from rest to rest
        (a minimum-jerk law along its length, s = 10τ³ − 15τ⁴ + 6τ⁵), (count, 3) or (count, 7):
        the motion a skill learns and an arm runs."""
        count = check_int(count, "count", minimum=2, maximum=1_000_000)
        path = self.path
        lengths = np.concatenate(
            [[0.0], np.cumsum(np.linalg.norm(np.diff(path[:, :3], axis=0), axis=1))]
        )
        tau = np.linspace(0.0, 1.0, count)
        along = (10 * tau**3 - 15 * tau**4 + 6 * tau**5) * lengths[-1]
        positions = np.column_stack([np.interp(along, lengths, path[:, i]) for i in range(3)])
        if path.shape[1] == 3:
            return positions
        from scipy.spatial.transform import Slerp

        keep = np.concatenate([[True], np.diff(lengths) > 0.0])
        frames = Slerp(lengths[keep], Rotation.from_quat(path[keep, 3:]))(along).as_quat()
        return np.hstack([positions, frames])


def tool_route(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    scene,
    start,
    goal,
    *,
    axis=None,
    approach_height: float = 0.0,
    exclude=(),
    margin: float | None = None,
    seed: int = 0,
    max_checks: int = 20_000,
) -> ToolRoute:
    """A route of the tool from ``start`` to ``goal`` that keeps every part's clearance.

    Parameters
    ----------
    scene : bidmp.Scene
    start, goal : array (3,) or (7,)
        Positions, or poses (position and quaternion x, y, z, w: the tool's frame, its z axis
        the approach direction); both of one kind. Positions keep the tool pointing down.
    axis : array (3,), optional
        The target's axis, pointing out of it (default +z).
    approach_height : float
        The final approach's length along ``axis`` (scene units): the route comes straight down
        onto ``goal`` from one and a half times this above it, the tool in the goal's frame.
    exclude : sequence of str
        Parts not checked (the target's own: it enters the socket).
    margin : float, optional
        The clearance kept (scene units; default the scene's), a part's stand-off from it.
    seed : int
    max_checks : int
        The search's budget in tool placements tested.

    Raises
    ------
    NoRouteError
        The start or the final approach is not free, or no route was found.
    """
    if not callable(getattr(scene, "pose_checker", None)) or not hasattr(scene, "tool"):
        raise TypeError(f"scene must be a bidmp.Scene, got {type(scene).__name__}")
    start, goal, pose = _poses(start, goal)
    axis = np.array([0.0, 0.0, 1.0]) if axis is None else as_vector(axis, "axis", length=3)
    if not np.linalg.norm(axis) > 0.0:
        raise ValueError("axis must be a direction (not zero)")
    axis = axis / np.linalg.norm(axis)
    height = check_real(approach_height, "approach_height", nonnegative=True)
    exclude = as_labels(exclude, "exclude")
    margin = (
        scene.margin
        if margin is None
        else check_real(margin, "margin", nonnegative=True, maximum=scene.tool.radius)
    )
    seed = check_int(seed, "seed", minimum=0, maximum=2**32 - 2)
    max_checks = check_int(max_checks, "max_checks", minimum=1, maximum=10_000_000)
    # A segment is tested by advancing the tool by its slack, at least this much: asked to keep
    # the margin plus this, the swept tool keeps the margin between two tests.
    tolerance = _TOLERANCE * max(margin, 1e-2 * scene.tool.length)
    checker = scene.pose_checker(exclude, margin=margin + tolerance)
    # The straight descent starts above the approach height: the route's last bend, rounded, stays
    # out of the band the contract judges the engagement in.
    top = as_point(goal[:3] + axis * height * (1.0 + _ABOVE), 3, "approach_height (its top)")
    space = _ToolSpace(scene, checker, start, goal, top, pose, tolerance)
    descent = _descent(space, goal, top)
    if descent:
        raise NoRouteError(f"the final approach onto the goal is not free: {descent}")
    route = plan_route(
        space,
        space.state(start[:3], 0.0),
        space.state(top, 1.0),
        seed=seed,
        max_checks=max_checks,
        time_limit=60.0,
        rounds=_ROUNDS,
    )
    states = np.vstack([route.waypoints, space.state(goal[:3], 1.0)[None]])
    rounded = _rounded(space, states)
    return ToolRoute(
        space.poses(states),
        space.poses(rounded),
        rounded.shape[0] - 2,
        route.checks + space.tests,
        route.seconds,
    )


def _rounded(space, states: np.ndarray, spacing_share: float = 0.04, sweeps: int = 8) -> np.ndarray:
    """The route ``states`` (k, d; its last segment the final approach) subdivided and its corners
    rounded: every inner point moved half-way to its neighbours' middle, ``sweeps`` times, where
    the two segments it joins stay free; the start, the approach's top and the target stay, and
    the final approach stays straight. A polygon's corners ask the arm to stop in them, or to
    accelerate without bound."""
    approach = states[-2:]
    lengths = np.linalg.norm(np.diff(states[:-1], axis=0), axis=1)
    total = float(np.sum(lengths))
    if states.shape[0] < 3 or total <= 0.0:
        return states
    spacing = spacing_share * total
    pieces = [states[:1]]
    for a, b, length in zip(states[:-2], states[1:-1], lengths):
        steps = max(int(np.ceil(length / spacing)), 1)
        pieces.append(a + (b - a) * (np.arange(1, steps + 1)[:, None] / steps))
    dense = np.vstack(pieces)
    for _ in range(sweeps):
        moved = False
        for index in range(1, dense.shape[0] - 1):
            middle = 0.5 * (dense[index - 1] + dense[index + 1])
            candidate = dense[index] + 0.5 * (middle - dense[index])
            if (
                np.linalg.norm(candidate - dense[index]) > 1e-6 * total
                and space.segment(dense[index - 1], candidate)
                and space.segment(candidate, dense[index + 1])
            ):
                dense[index] = candidate
                moved = True
        if not moved:
            break
    return np.vstack([dense, approach[1:]])


class _Turn:
    """The shortest turn from one frame to another (quaternions x, y, z, w): the frame a share of
    the way, as a matrix, in closed form (Rodrigues' formula about the turn's fixed axis: SciPy's
    Slerp costs 0.5 ms a call, and a planner asks for it at every configuration it tests)."""

    def __init__(self, first, last):
        self.first = Rotation.from_quat(first).as_matrix()
        relative = Rotation.from_matrix(self.first.T @ Rotation.from_quat(last).as_matrix())
        rotvec = relative.as_rotvec()
        self.angle = float(np.linalg.norm(rotvec))
        k = rotvec / self.angle if self.angle > 0.0 else np.zeros(3)
        cross = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
        self._cross, self._square = cross, cross @ cross

    def matrix(self, share: float) -> np.ndarray:
        """The frame ``share`` (clipped to [0, 1]) of the way, (3, 3)."""
        angle = min(max(float(share), 0.0), 1.0) * self.angle
        return self.first @ (
            np.eye(3) + math.sin(angle) * self._cross + (1.0 - math.cos(angle)) * self._square
        )


def _poses(start, goal) -> tuple[np.ndarray, np.ndarray, bool]:
    start, goal = as_vector(start, "start").copy(), as_vector(goal, "goal").copy()
    if start.shape[0] not in (3, 7) or goal.shape[0] != start.shape[0]:
        raise ValueError(
            f"start and goal must both be positions (3,) or both poses (7,), got {start.shape[0]} "
            f"and {goal.shape[0]} values"
        )
    pose = start.shape[0] == 7
    if pose:
        for name, value in (("start", start), ("goal", goal)):
            norm = float(np.linalg.norm(value[3:]))
            if not norm > 1e-9:
                raise ValueError(f"{name}'s quaternion must not be zero")
            value[3:] /= norm
    return start, goal, pose


def _descent(space, goal, top) -> str:
    """Why the straight descent from ``top`` onto ``goal`` in the goal's frame is not free ("" when
    it is)."""
    for point in np.linspace(top, goal[:3], 50):
        slack = space.slack(space.state(point, 1.0))
        if slack < 0.0:
            rotation = space.turn.matrix(1.0) if space.pose else None
            part = space.checker.nearest(point, rotation)
            return (
                f"the tool at {np.round(point, 6).tolist()} comes {-slack:.3g} inside the "
                f"clearance of {part} (a part not in exclude)"
            )
    return ""


class _ToolSpace:
    """The tool's configurations as a :class:`~bidmp.planning.FreeSpace`: its mouth's position
    (x, y, z) and, for a pose, how far it has turned from the start frame to the goal's, scaled so
    that a unit of it moves the tool's far end a unit (the mouth's travel plus the far end's turn
    bounds every point's: the sweep)."""

    def __init__(self, scene, checker, start, goal, top, pose: bool, tolerance: float):
        self.checker, self.pose, self.tests = checker, pose, 0
        self.lower, self.upper = _box(scene, start[:3], top)
        self.tolerance = tolerance
        if pose:
            self.turn = _Turn(start[3:], goal[3:])
            reach = math.hypot(scene.tool.length, scene.tool.radius)
            self.span = max(reach * self.turn.angle, self.tolerance)
            self.lower = np.append(self.lower, 0.0)
            self.upper = np.append(self.upper, self.span)

    def poses(self, states: np.ndarray) -> np.ndarray:
        """Configurations (k, d) as the tool's mouth (k, 3), or its poses (k, 7)."""
        if not self.pose:
            return states[:, :3].copy()
        turns = [self.turn.matrix(share) for share in states[:, 3] / self.span]
        return np.hstack([states[:, :3], Rotation.from_matrix(turns).as_quat()])

    def free(self, q: np.ndarray) -> bool:
        self.tests += 1
        return self.slack(q) >= 0.0

    def segment(self, a: np.ndarray, b: np.ndarray) -> bool:
        """Whether the straight segment from ``a`` to ``b`` is free (conservative advancement)."""
        sweep, travelled = self.sweep(a, b), 0.0
        for _ in range(10_000):
            slack = self.slack(a + travelled * (b - a))
            self.tests += 1
            if slack < 0.0:
                return False
            if travelled >= 1.0 or sweep <= 0.0:
                return True
            travelled = min(travelled + max(slack, self.tolerance) / sweep, 1.0)
        return False

    def state(self, point, share: float) -> np.ndarray:
        """The configuration of the mouth at ``point`` turned ``share`` of the way."""
        return np.append(point, share * self.span) if self.pose else np.asarray(point, float)

    def slack(self, q: np.ndarray) -> float:
        if not self.pose:
            return self.checker.slack(q, check_input=False)
        return self.checker.slack(q[:3], self.turn.matrix(q[3] / self.span), check_input=False)

    def sweep(self, a: np.ndarray, b: np.ndarray) -> float:
        travel = float(np.linalg.norm(b[:3] - a[:3]))
        return travel + (abs(float(b[3] - a[3])) if self.pose else 0.0)


def _box(scene, start: np.ndarray, top: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The region the route may use: the box round the start, the approach's top and the parts,
    grown by the tool's length (to pass over the tallest part) and its diameter (to pass round
    the outermost)."""
    points = [start, top]
    for label in scene.labels:
        points += list(scene.bounds(label))
    points = np.array(points)
    grow = np.array([2.0, 2.0, 1.0]) * scene.tool.radius + [0.0, 0.0, scene.tool.length]
    return points.min(axis=0) - grow * [1.0, 1.0, 0.0], points.max(axis=0) + grow
