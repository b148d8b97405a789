"""The route planner against spaces whose free set is known in closed form: boxes in the plane and
in seven dimensions, tested here by dense sampling (an oracle that shares no code with the
planner's conservative advancement)."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from bidmp.planning import NoRouteError, plan_route, segment_free

pytest.importorskip("ompl")


class Boxes:
    """Axis-aligned boxes (obstacles) in a box of the plane or of d dimensions; the body is a
    point kept ``clearance`` from every obstacle. Slack in closed form (a box's distance)."""

    def __init__(self, lower, upper, obstacles, clearance=0.0, tolerance=1e-3):
        self.lower, self.upper = np.asarray(lower, float), np.asarray(upper, float)
        self.obstacles = [(np.asarray(lo, float), np.asarray(hi, float)) for lo, hi in obstacles]
        self.clearance, self.tolerance, self.calls = clearance, tolerance, 0

    def distance(self, q) -> float:
        best = np.inf
        for lo, hi in self.obstacles:
            gap = np.maximum(np.maximum(lo - q, q - hi), 0.0)
            inside = np.all((q >= lo) & (q <= hi))
            best = min(best, -np.min(np.minimum(q - lo, hi - q)) if inside else np.linalg.norm(gap))
        return best

    def slack(self, q) -> float:
        self.calls += 1
        return self.distance(np.asarray(q, float)) - self.clearance - self.tolerance

    def sweep(self, a, b) -> float:
        return float(np.linalg.norm(np.asarray(b) - np.asarray(a)))


def dense_clear(space: Boxes, path, step=2e-4) -> bool:
    """The oracle: every point of the polyline, every ``step``, keeps the clearance."""
    for a, b in zip(path[:-1], path[1:]):
        count = max(int(np.ceil(np.linalg.norm(b - a) / step)), 1) + 1
        for share in np.linspace(0.0, 1.0, count):
            if space.distance(a + share * (b - a)) < space.clearance - 1e-12:
                return False
    return True


def wall(d=2):
    """A wall across the middle of [-1, 1]^d, with a gap above y = 0.8."""
    lo, hi = -np.ones(d), np.ones(d)
    obstacle_lo, obstacle_hi = lo.copy(), hi.copy()
    obstacle_lo[0], obstacle_hi[0] = -0.1, 0.1
    obstacle_hi[1] = 0.8
    return Boxes(lo, hi, [(obstacle_lo, obstacle_hi)], clearance=0.02)


@pytest.mark.parametrize("d", [2, 7])
def test_a_route_round_a_wall_is_free_ends_where_asked_and_is_near_the_shortest(d):
    space = wall(d)
    start, goal = np.zeros(d), np.zeros(d)
    start[0], goal[0] = -0.5, 0.5
    route = plan_route(space, start, goal, seed=3)
    assert np.array_equal(route.waypoints[0], start)
    assert np.array_equal(route.waypoints[-1], goal)
    assert dense_clear(space, route.waypoints)
    # the shortest route: up to the gap's edge, kept 0.02 away, across, and down
    corner = np.hypot(0.4 - 0.02, 0.8 + 0.02)
    shortest = 2 * corner + 0.2 + 2 * 0.02
    assert shortest - 1e-9 <= route.length <= 1.15 * shortest, (route.length, shortest)


def test_the_partial_shortcuts_shorten_more_than_ompls_simplifier_in_seven_dimensions():
    space = wall(7)
    start, goal = np.zeros(7), np.zeros(7)
    start[0], goal[0] = -0.5, 0.5
    ours = [plan_route(space, start, goal, seed=s).length for s in range(3)]
    theirs = [plan_route(space, start, goal, seed=s, shorten="ompl").length for s in range(3)]
    raw = [plan_route(space, start, goal, seed=s, shorten="none").length for s in range(3)]
    assert np.mean(ours) < np.mean(theirs) <= np.mean(raw)


def test_the_same_seed_finds_the_same_route_and_budgets_count_tests_not_seconds():
    space = wall(7)
    start, goal = np.zeros(7), np.zeros(7)
    start[0], goal[0] = -0.5, 0.5
    first = plan_route(space, start, goal, seed=11)
    again = plan_route(space, start, goal, seed=11)
    assert np.array_equal(first.waypoints, again.waypoints) and first.checks == again.checks
    other = plan_route(space, start, goal, seed=12)
    assert not np.array_equal(first.waypoints, other.waypoints)


def test_a_goal_among_several_is_reached_and_a_walled_in_goal_is_not():
    # two goals: one inside a closed room, one free
    room = Boxes(
        [-1, -1],
        [1, 1],
        [
            ([0.3, -0.5], [0.35, 0.5]),
            ([0.65, -0.5], [0.7, 0.5]),
            ([0.3, 0.45], [0.7, 0.5]),
            ([0.3, -0.5], [0.7, -0.45]),
        ],
        clearance=0.01,
    )
    route = plan_route(room, [-0.5, 0.0], [[0.5, 0.0], [-0.5, 0.9]], seed=0, max_checks=5000)
    assert route.goal == 1 and np.allclose(route.waypoints[-1], [-0.5, 0.9])
    with pytest.raises(NoRouteError, match="no route found after"):
        plan_route(room, [-0.5, 0.0], [0.5, 0.0], seed=0, max_checks=3000)


def test_a_start_or_every_goal_inside_an_obstacle_is_refused_before_any_search():
    space = wall(2)
    with pytest.raises(NoRouteError, match="the start .* is not free"):
        plan_route(space, [0.0, 0.0], [0.5, 0.0])
    with pytest.raises(NoRouteError, match="none of the 2 goal"):
        plan_route(space, [-0.5, 0.0], [[0.0, 0.0], [0.05, 0.5]])


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"seed": -1}, ValueError, "seed must be >= 0"),
        ({"seed": 1.5}, TypeError, "seed must be an integer"),
        ({"planner": "prm"}, ValueError, "planner"),
        ({"shorten": "max"}, ValueError, "shorten"),
        ({"max_checks": 0}, ValueError, "max_checks must be >= 1"),
        ({"time_limit": -1.0}, ValueError, "time_limit must be > 0"),
    ],
)
def test_bad_options_are_refused_naming_them(kwargs, error, match):
    with pytest.raises(error, match=match):
        plan_route(wall(2), [-0.5, 0.0], [0.5, 0.0], **kwargs)


def test_a_start_outside_the_box_or_of_another_dimension_is_refused():
    with pytest.raises(ValueError, match="start must lie within"):
        plan_route(wall(2), [-1.5, 0.0], [0.5, 0.0])
    with pytest.raises(ValueError, match="start must have 2"):
        plan_route(wall(2), [-0.5, 0.0, 0.0], [0.5, 0.0])
    with pytest.raises(TypeError, match="space must be a bidmp.planning.FreeSpace"):
        plan_route(object(), [-0.5, 0.0], [0.5, 0.0])


@settings(max_examples=60, deadline=None)
@given(
    st.lists(st.floats(-0.9, 0.9), min_size=4, max_size=4),
    st.lists(st.floats(-0.9, 0.9), min_size=4, max_size=4),
    st.floats(0.05, 0.4),
)
def test_segment_free_never_passes_a_segment_that_dense_sampling_sees_touch(corner, ends, size):
    """Conservative advancement against sampling every 0.2 mm: a segment called free keeps the
    clearance everywhere; one that a sample shows inside it is never called free."""
    lo = np.array(corner[:2])
    space = Boxes([-1, -1], [1, 1], [(lo, lo + size)], clearance=0.03, tolerance=1e-3)
    a, b = np.array(ends[:2]), np.array(ends[2:])
    free = segment_free(space, a, b)
    touched = not dense_clear(space, np.array([a, b]))
    if free:
        assert not touched
    if touched:
        assert not free


class Counted(Boxes):
    """Boxes whose slack calls are counted by the test itself."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        self.asked = 0

    def slack(self, q) -> float:
        self.asked += 1
        return super().slack(q)


def test_a_routes_test_count_is_the_configurations_the_space_was_asked_about():
    """``Route.checks`` reports every slack the planner asked the space for: the search's, the
    segments' and the shortening's, counted here by the space."""
    for d, seed in ((2, 0), (7, 4)):
        base = wall(d)
        space = Counted(base.lower, base.upper, base.obstacles, base.clearance, base.tolerance)
        start, goal = np.zeros(d), np.zeros(d)
        start[0], goal[0] = -0.5, 0.5
        route = plan_route(space, start, goal, seed=seed)
        assert route.checks == space.asked > 0
        space.asked = 0
        straight = plan_route(space, [-0.5, 0.9] + [0.0] * (d - 2), [0.5, 0.9] + [0.0] * (d - 2))
        assert straight.checks == space.asked and straight.waypoints.shape[0] == 2


def test_a_segment_that_ends_at_the_clearance_with_the_part_beyond_it_is_free():
    """The advancement stops at the segment's end: a part just past it is not tested against
    (dense sampling of the segment itself says it keeps the clearance)."""
    space = Boxes([-1, -1], [1, 1], [([0.5, -0.5], [0.7, 0.5])], clearance=0.05, tolerance=1e-4)
    a, b = np.array([-0.5, 0.0]), np.array([0.5 - 0.05 - 1e-4 - 1e-6, 0.0])
    assert dense_clear(space, np.array([a, b]))
    assert segment_free(space, a, b)
    assert not segment_free(space, a, b + [0.01, 0.0])  # a centimetre on, inside the clearance


def test_a_segment_that_grazes_its_clearance_all_along_is_taken_as_touching():
    """Along a wall at the clearance plus half the least step, every test finds the body a
    hair's breadth outside it: the advancement moves by its least step only and gives up after
    its 10 000 steps, calling the segment touching (never freer than it is)."""
    tolerance = 1e-6
    space = Boxes(
        [-1, -1], [1, 1], [([-1.0, -1.0], [1.0, -0.2])], clearance=0.1, tolerance=tolerance
    )
    y = -0.2 + 0.1 + tolerance + tolerance / 2.0  # slack tolerance / 2 everywhere on the segment
    assert 0.0 < space.slack([0.0, y]) < tolerance
    assert not segment_free(space, [-0.5, y], [0.5, y])


def test_the_goal_reached_is_the_one_the_last_segment_was_tested_to():
    """Several goals, the first in sight of the start: the route goes straight to it, and every
    segment of it (dense sampling) keeps the clearance; with the first walled off, the route
    ends exactly at the other and says which."""
    space = wall(2)
    route = plan_route(space, [-0.5, 0.0], [[-0.5, 0.5], [0.5, 0.0]], seed=1)
    assert route.goal == 0 and np.array_equal(route.waypoints, [[-0.5, 0.0], [-0.5, 0.5]])
    route = plan_route(space, [-0.5, 0.0], [[0.0, 0.0], [0.5, 0.0]], seed=1)
    assert route.goal == 1 and np.array_equal(route.waypoints[-1], [0.5, 0.0])
    assert dense_clear(space, route.waypoints)
