"""A route between configurations through free space: OMPL's RRT-Connect (Kuffner & LaValle
2000, bidirectional trees) over a box of real vectors, then shortened by partial shortcuts.

Why OMPL and not a planner written here: it is the field's maintained reference (MoveIt's
default), complete in probability, and its RRT-Connect solves a 7-joint problem round a wall in
about a millisecond; what costs is testing configurations, which is the caller's: a
:class:`FreeSpace` says how far a configuration is from touching (its *slack*) and how far any
point of the body can move along a straight segment (its *sweep*). A segment is then tested by
conservative advancement (the body may move by its slack without touching): few tests far from
the parts, as many as needed near them, and nothing narrower than a fixed resolution is missed,
because there is none.

Reproducible: OMPL's random numbers are seeded from ``seed`` before every plan, and the search
stops after a number of configurations tested (``max_checks``), not after a time, so the same call
finds the same route on a slow machine and a fast one; ``time_limit`` is a guard only.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from .._checks import (
    TaskRefusal,
    as_point,
    as_points,
    as_vector,
    check_choice,
    check_int,
    check_real,
    check_seed,
    require_extra,
)

__all__ = [
    "FreeSpace",
    "NoRouteError",
    "Route",
    "plan_route",
    "segment_free",
    "PLANNERS",
    "SHORTENINGS",
]

logger = logging.getLogger(__name__)

# The planners one may ask for: RRT-Connect (the default) and, for a second opinion that shares
# no tree-growing code with it (the tests' route oracle), plain RRT and asymptotically optimal RRT*.
PLANNERS = ("rrt-connect", "rrt", "rrt-star")
# How a found route is shortened: partial shortcuts (ours, the default), OMPL's own simplifier (the
# plain planner's, for comparisons), or not at all.
SHORTENINGS = ("partial", "ompl", "none")
_SEED_MAX = 2**32 - 2  # OMPL's seeds are 32-bit and 0 means "random": ours are shifted by one
_MAX_ADVANCES = 10_000  # conservative advancement steps along one segment before it is refused


class FreeSpace(Protocol):
    """What :func:`plan_route` asks of a configuration space.

    Attributes
    ----------
    lower, upper : array (d,)
        The box the configurations lie in (a joint space's limits).
    tolerance : float
        The slack below which a configuration counts as touching (the body's units), and the
        least step of an advancement along a segment.
    """

    lower: np.ndarray
    upper: np.ndarray
    tolerance: float

    def slack(self, q: np.ndarray) -> float:
        """How far the body at ``q`` (d,) is from coming within its clearance of any part (the
        body's units, a lower bound is enough); negative: it is within it."""

    def sweep(self, a: np.ndarray, b: np.ndarray) -> float:
        """An upper bound of how far any point of the body moves when the configuration goes
        straight from ``a`` to ``b`` (the body's units)."""


class NoRouteError(TaskRefusal):
    """No route was found within the search's budget (or its start or every goal is not free):
    the message says which, and how many configurations were tested."""


@dataclass(frozen=True)
class Route:
    """A route found by :func:`plan_route`.

    Attributes
    ----------
    waypoints : array (k, d)
        From the start to the goal reached; consecutive waypoints are joined by straight segments,
        each free (tested by conservative advancement).
    goal : int
        The index of the goal reached (among those given).
    planner : str
        Which planner found it.
    checks : int
        Configurations tested (the search's and the shortening's).
    seconds : float
        Wall time of the search and the shortening (s).
    """

    waypoints: np.ndarray
    goal: int
    planner: str
    checks: int
    seconds: float

    @property
    def length(self) -> float:
        """The route's length in its own space (the sum of its segments' Euclidean lengths)."""
        return float(np.sum(np.linalg.norm(np.diff(self.waypoints, axis=0), axis=1)))


class _Tester:
    """The space's tests, counted: a configuration's and a segment's (conservative advancement)."""

    def __init__(self, space: FreeSpace):
        self.space, self.count = space, 0
        self.tolerance = float(space.tolerance)

    def free(self, q: np.ndarray) -> bool:
        self.count += 1
        return bool(float(self.space.slack(np.array(q, dtype=float))) >= 0.0)

    def segment(self, a: np.ndarray, b: np.ndarray) -> bool:
        free, tests = _advance(self.space, np.array(a, dtype=float), np.array(b, dtype=float))
        self.count += tests
        return free

    def state(self, dimension: int):
        """The test of an OMPL state (a view into C++: copied)."""
        return lambda state: self.free(
            np.fromiter((state[i] for i in range(dimension)), float, dimension)
        )


def _advance(space, a: np.ndarray, b: np.ndarray) -> tuple[bool, int]:
    """Whether the straight segment from ``a`` to ``b`` is free, and the configurations tested:
    the body advances by its slack (it cannot touch a part within it), at least the space's
    tolerance, to ``b``."""
    sweep, travelled, tolerance = float(space.sweep(a, b)), 0.0, float(space.tolerance)
    for tests in range(1, _MAX_ADVANCES + 1):
        slack = float(space.slack(a + travelled * (b - a)))
        if slack < 0.0:
            return False, tests
        if travelled >= 1.0 or sweep <= 0.0:
            return True, tests
        travelled = min(travelled + max(slack, tolerance) / sweep, 1.0)
    return False, _MAX_ADVANCES  # grazing for too long: taken as touching (never freer than it is)


def segment_free(space: FreeSpace, a, b) -> bool:
    """Whether the straight segment from configuration ``a`` to ``b`` is free in ``space``
    (conservative advancement: the body moves by its slack, at least the space's tolerance)."""
    lower, _ = _box(space)
    a = as_point(a, lower.shape[0], "a", like="space.lower")
    b = as_point(b, lower.shape[0], "b", like="space.lower")
    return _advance(space, a, b)[0]


def _ompl():
    """OMPL's modules (base, geometric, util), their log silenced (the library never prints:
    outcomes are read from the results and said through :mod:`logging`)."""
    require_extra("ompl", "plan", "the route planner (bidmp.planning)")
    from ompl import base, geometric, util

    util.setLogLevel(util.LogLevel.LOG_NONE)
    return base, geometric, util


def plan_route(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    space: FreeSpace,
    start,
    goals,
    *,
    seed: int = 0,
    max_checks: int = 20_000,
    time_limit: float = 10.0,
    planner: str = "rrt-connect",
    shorten: str = "partial",
    rounds: int = 200,
) -> Route:
    """A free route from ``start`` to one of ``goals`` in ``space``.

    Parameters
    ----------
    space : FreeSpace
        The box of configurations and the test of each (its slack, a segment's sweep).
    start : array (d,)
    goals : array (g, d) or (d,)
        One or several goal configurations; the route ends exactly at one of them.
    seed : int
        The planner's and the shortening's random numbers (0 to 2**32 - 2).
    max_checks : int
        The search stops after this many configurations tested without a route.
    time_limit : float
        A guard (s): the search stops after this long whatever the count.
    planner : {"rrt-connect", "rrt", "rrt-star"}
    shorten : {"partial", "ompl", "none"}
        How the route found is shortened: ``rounds`` partial shortcuts, OMPL's simplifier run to
        its end, or not at all.
    rounds : int
        Partial shortcuts tried.

    Raises
    ------
    NoRouteError
        The start, or every goal, is not free; or no route was found within the budget.
    """
    lower, upper = _box(space)
    start = _within(as_point(start, lower.shape[0], "start")[None], lower, upper, "start")[0]
    goals = _within(as_points(goals, lower.shape[0], "goals"), lower, upper, "goals")
    if goals.shape[0] > 1000:
        raise ValueError(f"goals holds {goals.shape[0]} configurations; at most 1000")
    seed = check_int(seed, "seed", minimum=0, maximum=_SEED_MAX)
    max_checks = check_int(max_checks, "max_checks", minimum=1, maximum=10_000_000)
    time_limit = check_real(time_limit, "time_limit", positive=True, maximum=3600.0)
    planner = check_choice(planner, "planner", PLANNERS)
    shorten = check_choice(shorten, "shorten", SHORTENINGS)
    rounds = check_int(rounds, "rounds", minimum=0, maximum=100_000)
    tester = _Tester(space)
    began = time.perf_counter()
    if not tester.free(start):
        raise NoRouteError(f"the start {np.round(start, 4).tolist()} is not free")
    free_goals = [index for index, goal in enumerate(goals) if tester.free(goal)]
    if not free_goals:
        raise NoRouteError(f"none of the {len(goals)} goal configuration(s) is free")
    if tester.segment(start, goals[free_goals[0]]):
        waypoints = np.vstack([start, goals[free_goals[0]]])  # in sight: no search
    else:
        waypoints = _search(
            start,
            goals[free_goals],
            (lower, upper),
            tester,
            (seed, planner),
            (max_checks, time_limit),
            shorten == "ompl",
        )
    # OMPL's route holds the start and the goal state it reached as they were given: found exactly
    reached = [index for index in free_goals if np.array_equal(goals[index], waypoints[-1])]
    if not np.array_equal(waypoints[0], start) or not reached:
        raise RuntimeError("the planner's route does not run from the start to a goal given")
    if shorten == "partial" and waypoints.shape[0] > 2:
        waypoints = _shortened(waypoints, tester.segment, rounds, check_seed(seed))
    logger.debug(
        "%s: a route of %d waypoints after %d tests", planner, waypoints.shape[0], tester.count
    )
    return Route(waypoints, reached[0], planner, tester.count, time.perf_counter() - began)


def _box(space) -> tuple[np.ndarray, np.ndarray]:
    """The space's box, checked (and its tolerance): a ``TypeError`` for what is not a space."""
    members = ("lower", "upper", "slack", "sweep", "tolerance")
    if not all(hasattr(space, name) for name in members) or not all(
        callable(getattr(space, name)) for name in ("slack", "sweep")
    ):
        raise TypeError(
            "space must be a bidmp.planning.FreeSpace (lower, upper, tolerance, slack, sweep), "
            f"got {type(space).__name__}"
        )
    lower = as_vector(space.lower, "space.lower")
    if lower.shape[0] > 64:
        raise ValueError(
            f"space.lower has {lower.shape[0]} coordinates; a route plans in at most 64"
        )
    upper = as_point(space.upper, lower.shape[0], "space.upper", like="space.lower")
    if np.any(upper <= lower):
        raise ValueError("space.upper must be above space.lower in every coordinate")
    check_real(space.tolerance, "space.tolerance", positive=True)
    return lower, upper


def _within(points: np.ndarray, lower, upper, name: str) -> np.ndarray:
    if np.any(points < lower - 1e-9) or np.any(points > upper + 1e-9):
        raise ValueError(f"{name} must lie within the space's box [lower, upper]")
    return np.clip(points, lower, upper)


def _search(start, goals, box, tester: _Tester, how, budget, simplify: bool) -> np.ndarray:
    """OMPL's planner in ``box`` = (lower, upper) from ``start`` to any of ``goals``, segments
    tested by ``tester`` (``how`` = (seed, planner); ``budget`` = (max_checks, time_limit)): the
    waypoints (k, d) of its route (``simplify``: shortened by OMPL's simplifier)."""
    base, geometric, util = _ompl()
    lower, upper = box
    seed, planner = how
    max_checks, time_limit = budget
    d = start.shape[0]
    util.RNG.setSeed(seed + 1)
    space = base.RealVectorStateSpace(d)
    bounds = base.RealVectorBounds(d)
    for i in range(d):
        bounds.setLow(i, float(lower[i]))
        bounds.setHigh(i, float(upper[i]))
    space.setBounds(bounds)
    setup = geometric.SimpleSetup(space)
    setup.setStateValidityChecker(tester.state(d))
    information = setup.getSpaceInformation()
    validator = _motion_validator(base, information, tester, d)
    information.setMotionValidator(validator)
    first = space.allocState()
    for i in range(d):
        first[i] = float(start[i])
    goal = base.GoalStates(information)
    for point in goals:
        state = space.allocState()
        for i in range(d):
            state[i] = float(point[i])
        goal.addState(state)
    setup.setStartState(first)
    setup.setGoal(goal)
    setup.setPlanner(_planner(geometric, planner, information))
    stop = base.plannerOrTerminationCondition(
        base.PlannerTerminationCondition(lambda: tester.count >= max_checks),
        base.timedPlannerTerminationCondition(time_limit),
    )
    setup.solve(stop)
    if not setup.haveExactSolutionPath():
        raise NoRouteError(
            f"no route found after {tester.count} configurations tested (within time_limit = "
            f"{time_limit:g} s and max_checks = {max_checks:,})"
        )
    if simplify:
        geometric.PathSimplifier(information).simplifyMax(setup.getSolutionPath())
    path = setup.getSolutionPath()
    return np.array([[path.getState(k)[i] for i in range(d)] for k in range(path.getStateCount())])


def _motion_validator(base, information, tester: _Tester, dimension: int):
    """An OMPL motion validator that tests a segment by conservative advancement."""

    def configuration(state) -> np.ndarray:
        return np.fromiter((state[i] for i in range(dimension)), float, dimension)

    class _Advancing(base.MotionValidator):
        def checkMotion(self, first, second, *rest):  # noqa: N802 - OMPL's name
            return bool(tester.segment(configuration(first), configuration(second)))

    return _Advancing(information)


def _planner(geometric, name: str, information):
    if name == "rrt-connect":
        return geometric.RRTConnect(information)
    if name == "rrt":
        return geometric.RRT(information)
    return geometric.RRTstar(information)


def _shortened(path: np.ndarray, segment_free, rounds: int, rng) -> np.ndarray:
    """``path`` (k, d) shortened by partial shortcuts (Geraerts & Overmars 2007): each round picks
    two points of the path (subdivided into 20 pieces) and straightens the stretch between them
    in every coordinate or in one (a joint that need not move round the obstacle is straightened
    even where the others may not be), kept where every changed segment is free. Then every
    vertex whose neighbours see each other is dropped. The ends stay; the length never grows. A
    sampled path wanders in the coordinates the obstacles leave free: on a 7-D wall OMPL's own
    simplifier left 3.15 for a shortest route of 1.99, this 2.02 (300 rounds)."""
    path = _subdivided(path, 20)
    for _ in range(rounds):
        count = path.shape[0]
        if count < 3:
            break
        i, j = np.sort(rng.choice(count, 2, replace=False))
        if j - i < 2:
            continue
        coordinates = slice(None) if rng.uniform() < 0.5 else [int(rng.integers(path.shape[1]))]
        candidate = path.copy()
        share = np.linspace(0.0, 1.0, j - i + 1)[:, None]
        candidate[i : j + 1, coordinates] = (1.0 - share) * path[i, coordinates] + share * path[
            j, coordinates
        ]
        if all(segment_free(candidate[k], candidate[k + 1]) for k in range(i, j)):
            path = candidate
    index = 1
    while index < path.shape[0] - 1:
        if segment_free(path[index - 1], path[index + 1]):
            path = np.delete(path, index, axis=0)
        else:
            index += 1
    return path


def _subdivided(path: np.ndarray, pieces: int) -> np.ndarray:
    """``path`` with vertices added so that it has about ``pieces`` segments of equal length."""
    lengths = np.linalg.norm(np.diff(path, axis=0), axis=1)
    spacing = max(float(np.sum(lengths)) / pieces, 1e-12)
    parts = [path[:1]]
    for a, b, length in zip(path[:-1], path[1:], lengths):
        steps = max(int(np.ceil(length / spacing)), 1)
        parts.append(a + (b - a) * (np.arange(1, steps + 1)[:, None] / steps))
    return np.vstack(parts)
