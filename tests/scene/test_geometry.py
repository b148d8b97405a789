"""Scene geometry: clearance against closed forms, collisions named by part, the scene-aware and
approach-preserving extension, the battery tasks' task success, and bad scene data."""

import json
import sys

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bidmp
from bidmp.cli import main
from bidmp.extension import NoFreeRouteError, RoadmapOptions, extend_demonstration, final_approach
from bidmp.scene import Scene, SceneError, Tool
from bidmp.tasks import evaluate, scenarios

TOOL = {"radius": 12.5, "length": 100.0}
NUT = {"across_flats": 13, "height": 6.5, "stud": {"radius": 4, "above": 10}}


def scene_of(*parts, tool=TOOL, targets=None, **options):
    return Scene.from_dict({"tool": dict(tool), "parts": list(parts), **options}, targets)


def vertical(x, y, z_from, z_to, n=201):
    return np.column_stack([np.full(n, x), np.full(n, y), np.linspace(z_from, z_to, n)])


# ---------------------------------------------------------------------------------------------
# Closed forms
# ---------------------------------------------------------------------------------------------
def cylinder_closed_form(point, tool_radius, tool_length, base, radius, height):
    """Signed distance between two vertical cylinders (a product of a disc and an interval)."""
    lateral = np.hypot(*(point[:2] - base[:2])) - tool_radius - radius
    below, above = base[2] - (point[2] + tool_length), point[2] - (base[2] + height)
    vertical_gap = max(below, above)
    if lateral > 0 or vertical_gap > 0:
        return float(np.hypot(max(lateral, 0.0), max(vertical_gap, 0.0)))
    return -min(-lateral, -vertical_gap)  # penetration: the shorter way out, sideways or up/down


def box_closed_form(point, tool_radius, tool_length, lower, upper):
    """Distance (> 0 cases) from a vertical cylinder to an axis-aligned box."""
    to_rectangle = np.linalg.norm(
        np.maximum(np.maximum(lower[:2] - point[:2], point[:2] - upper[:2]), 0.0)
    )
    vertical_gap = max(lower[2] - (point[2] + tool_length), point[2] - upper[2], 0.0)
    return float(np.hypot(max(to_rectangle - tool_radius, 0.0), vertical_gap))


def test_clearance_to_a_cylinder_matches_the_closed_form_for_parallel_axes():
    rng = np.random.default_rng(0)
    base = np.array([10.0, -5.0, 0.0])
    scene = scene_of(
        {"type": "cylinder", "label": "post", "at": base.tolist(), "radius": 4.0, "height": 16.5}
    )
    checked = 0
    for point in rng.uniform([-60, -60, -140], [60, 60, 60], size=(400, 3)):
        expected = cylinder_closed_form(point, 12.5, 100.0, base, 4.0, 16.5)
        got = scene.clearance(point[None], step=1.0)
        if expected > 0:
            assert got.distance == pytest.approx(expected, abs=1e-6)
            assert got.part == "post" and got.collision_free
            checked += 1
        else:
            assert got.distance == pytest.approx(expected, abs=1e-4)  # EPA's penetration depth
            assert got.collision_part == "post"
    assert checked > 200


def test_gjk_answers_off_the_shapes_are_not_taken_for_distances(monkeypatch):
    """Two vertical cylinders with parallel axes: coal's GJK at the tight tolerance (and its
    Nesterov variant) sometimes returned the distance between "nearest points" that lie off the
    shapes — found by the avoidance coupling term mid-rollout: 1.96 for 16.90, 3.93 for
    12.50, near the two placements below. It depends on the solver's state from the queries before,
    so it is not replayed here in isolation; the guard is tested by making coal's first answer
    a distance its nearest points do not bear out, and every answer is checked against
    the closed form on those placements, sweeps past them and 1000 random placements each."""
    cases = [
        (
            (169.80415092295226, -22.281346540941826),
            18.06691042669175,
            280.9494237754709,
            (194.93626516, 17.98545751, 59.99999999),
            12.5,
        ),
        (
            (-192.68901374467922, -18.703061415319553),
            27.063229384665757,
            436.3844539761248,
            (-149.88034053, -42.22793144, 126.1722646),
            9.279404857491983,
        ),
    ]
    rng = np.random.default_rng(23)
    checked = 0
    for (x, y), radius, height, point, tool_radius in cases:
        base = np.array([x, y, -100.0])
        scene = Scene.from_dict(
            {
                "tool": {"radius": tool_radius, "length": 100.0},
                "parts": [
                    {
                        "type": "cylinder",
                        "label": "post",
                        "at": base.tolist(),
                        "radius": radius,
                        "height": height,
                    }
                ],
            }
        )
        # GJK keeps a guess from one query to the next: placements in a row, as a motion queries them.
        sweep = np.linspace(
            np.asarray(point) - [60, -40, 0], np.asarray(point) + [60, -40, 0], 1000
        )
        scattered = base + np.column_stack(
            [rng.uniform(-80, 80, (1000, 2)), rng.uniform(0, 200, 1000)]
        )
        for sample in np.vstack([sweep, point, scattered]):
            expected = cylinder_closed_form(sample, tool_radius, 100.0, base, radius, height)
            if expected > 0:
                assert scene.clearance(sample[None]).distance == pytest.approx(
                    expected, abs=1e-6
                ), sample.tolist()
                checked += 1
    assert checked > 1000
    # The guard: coal's first answer is a separation its nearest points do not bear out; the engine
    # asks again and returns the closed form.
    scene = Scene.from_dict(
        {
            "tool": {"radius": 12.5, "length": 100.0},
            "parts": [
                {
                    "type": "cylinder",
                    "label": "post",
                    "at": [0, 0, -100],
                    "radius": 18,
                    "height": 300,
                }
            ],
        }
    )
    engine = scene._engine()
    real, calls = engine.coal.distance, []

    def first_answer_wrong(a, pose_a, b, pose_b, request, result):
        distance = real(a, pose_a, b, pose_b, request, result)
        calls.append(distance)
        return (
            2.0 if len(calls) == 1 else distance
        )  # the first: a separation its points do not bear out

    monkeypatch.setattr(engine.coal, "distance", first_answer_wrong)
    point = np.array([50.0, 10.0, 20.0])
    expected = cylinder_closed_form(point, 12.5, 100.0, np.array([0.0, 0.0, -100.0]), 18.0, 300.0)
    assert engine.tool_to(point, 0) == pytest.approx(expected, abs=1e-6) and len(calls) == 2


def test_clearance_to_a_box_matches_the_closed_form():
    rng = np.random.default_rng(1)
    scene = scene_of({"type": "box", "label": "cell", "at": [0, 0, -10], "size": [20, 40, 30]})
    lower, upper = np.array([-10.0, -20.0, -10.0]), np.array([10.0, 20.0, 20.0])
    errors = []
    for point in rng.uniform([-70, -80, -150], [70, 80, 80], size=(400, 3)):
        expected = box_closed_form(point, 12.5, 100.0, lower, upper)
        if expected > 0:
            errors.append(scene.clearance(point[None]).distance - expected)
    assert len(errors) > 200 and np.max(np.abs(errors)) <= 1e-6


def test_hex_nut_clearance_at_its_corners_and_flats():
    scene = scene_of({"type": "nut", "label": "4", "at": [30, 0, -2], **NUT})
    corner = 13 / np.sqrt(3)  # yaw 0: a corner on +x and -x, flats facing +y and -y
    assert scene.clearance([[0.0, 0.0, 0.0]]).distance == pytest.approx(
        30 - corner - 12.5, abs=1e-6
    )
    assert scene.clearance([[30.0, 50.0, 0.0]]).distance == pytest.approx(50 - 6.5 - 12.5, abs=1e-6)
    # Above the nut, the stud (4 mm radius up to 14.5 mm) is what the tool meets.
    over = scene.clearance([[30.0, 18.0, 10.0]])  # 5.5 mm above the nut, beside the stud
    assert over.part == "4/stud" and over.distance == pytest.approx(18 - 4 - 12.5, abs=1e-6)


def test_clearance_along_a_trajectory_is_the_minimum_over_a_brute_force_check():
    data = json.loads(scenarios.builtin_text("nut-unscrewing"))
    scene = scenarios.load("nut-unscrewing").scene
    rng = np.random.default_rng(3)
    engine = scene._engine()
    for _ in range(3):
        path = np.cumsum(rng.normal(0.0, 6.0, size=(30, 3)), axis=0) + [60.0, 20.0, 25.0]
        got = scene.clearance(path, exclude="3", step=0.5)
        # The plain way: every part at every sample of the same densified path.
        from bidmp.scene.clearance import _densify

        dense = _densify(path, 0.5)
        chosen = [i for i, solid in enumerate(scene.solids) if solid.part != "3"]
        distances = np.array([[engine.tool_to(p, i) for i in chosen] for p in dense])
        row, col = np.unravel_index(np.argmin(distances), distances.shape)
        assert got.distance == pytest.approx(distances[row, col], abs=1e-9)
        assert got.part == scene.solids[chosen[col]].label
    assert data["scene"]["tool"] == TOOL | {"length": 100}


def test_a_trajectory_through_a_stud_is_reported_with_the_studs_label():
    targets = {"3": [0, 0, 0], "4": [30, 0, 0]}
    scene = scene_of(
        {"type": "nut", "at_targets": "all", "offset": [0, 0, -2], **NUT}, targets=targets
    )
    sweep = np.column_stack(
        [np.linspace(0, 30, 50), np.zeros(50), np.full(50, 8.0)]
    )  # above the nut, into the stud
    hit = scene.clearance(sweep, exclude="3")
    assert not hit.collision_free and hit.collision_part == "4/stud"
    assert hit.distance == pytest.approx(-(14.5 - 8.0), abs=1e-4)  # pushed up out of the stud
    descent = scene.clearance(vertical(0, 0, 40, 0), exclude="3")
    assert descent.collision_free and descent.part == "4"
    assert descent.distance == pytest.approx(30 - 13 / np.sqrt(3) - 12.5, abs=1e-6)


def test_the_checker_and_straight_moves_agree_with_dense_placements():
    scene = scenarios.load("nut-unscrewing").scene
    checker = scene.checker()
    rng = np.random.default_rng(5)
    a = rng.uniform([-30, -30, 0], [210, 80, 40], size=(60, 3))
    b = a + rng.normal(0.0, 15.0, size=a.shape)
    moves = checker.segments_free(a, b)
    dense = np.array([np.all(checker(np.linspace(p, q, 2000))) for p, q in zip(a, b)])
    assert moves.any() and not moves.all()
    assert np.array_equal(moves, dense)


# ---------------------------------------------------------------------------------------------
# The extension
# ---------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def nut():
    return scenarios.load("nut-unscrewing")


def test_the_kept_approach_is_the_demonstrated_one_translated(nut):
    demo = nut.demonstration
    target = np.array([150.0, 25.0, 0.0])
    extension = extend_demonstration(demo, target, seed=0, scene=nut.scene)
    start = extension.approach_index
    assert start == final_approach(demo, extension.segmentation_points)
    n = demo.shape[0] - start
    np.testing.assert_allclose(
        extension.complete[-n:], demo[start:] + (target - demo[-1]), rtol=0, atol=1e-9
    )
    # At least T samples: the transfer takes as long as it needs.
    assert extension.complete.shape[0] >= demo.shape[0] and np.array_equal(
        extension.complete[0], demo[0]
    )
    # The kept approach is the straight vertical descent from 40 mm onto the nut.
    np.testing.assert_allclose(demo[start], [0.0, 0.0, 40.0], atol=0.5)
    assert nut.scene.clearance(
        extension.complete, exclude=nut.scene.parts_at(target)
    ).collision_free
    paper = extend_demonstration(demo, target, seed=0, approach="paper")
    assert paper.approach == "paper" and paper.approach_index is None


def test_gprm_routes_the_transfer_around_a_part_in_its_way(nut):
    demo = nut.demonstration
    target = np.array([150.0, 25.0, 0.0])
    blind = extend_demonstration(demo, target, seed=0)
    # A block on the blind transfer's way, half-way along it, with room around it (the transfer
    # ends where the kept approach, the demonstration's last samples from approach_index, begins).
    hover = len(blind.complete) - (len(demo) - blind.approach_index)
    middle = blind.complete[(blind.seg_index + hover) // 2]
    block = {
        "type": "cylinder",
        "label": "block",
        "at": (middle - [0, 0, 10]).tolist(),
        "radius": 3,
        "height": 20,
    }
    scene = scene_of(block)
    assert not scene.clearance(blind.complete).collision_free
    routed = extend_demonstration(
        demo, target, seed=0, scene=scene, roadmap=RoadmapOptions(sigma_rel=0.1)
    )
    assert scene.clearance(routed.complete).collision_free


def test_a_wall_that_blocks_every_route_is_a_clear_error(nut):
    wall = {"type": "box", "label": "wall", "at": [40, 0, -500], "size": [10, 4000, 4000]}
    with pytest.raises(NoFreeRouteError, match="no collision-free route"):
        extend_demonstration(nut.demonstration, [150.0, 25.0, 0.0], seed=0, scene=scene_of(wall))


def test_a_part_in_the_translated_approach_is_a_clear_error(nut):
    shelf = {
        "type": "box",
        "label": "shelf",
        "at": [170, 25, 20],
        "size": [24, 40, 5],
    }  # overhangs the descent
    with pytest.raises(NoFreeRouteError, match="approach.*hits part 'shelf'"):
        extend_demonstration(nut.demonstration, [150.0, 25.0, 0.0], seed=0, scene=scene_of(shelf))


# ---------------------------------------------------------------------------------------------
# The battery tasks
# ---------------------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def nut_report(nut):
    return evaluate(nut, ["dmp", "bidmp"])


def test_nut_task_bidmp_defaults_succeed_on_every_nut(nut_report):
    bidmp_result = nut_report.methods["bidmp"]
    assert (
        bidmp_result.task_successes == 14
        and bidmp_result.collision_free == 14
        and bidmp_result.engaged == 14
    )
    assert bidmp_result.worst_clearance.distance >= 0.0
    assert nut_report.methods["dmp"].task_successes == 8
    data = nut_report.to_dict()["methods"]["bidmp"]
    for key in (
        "task_successes",
        "collision_free",
        "engaged",
        "min_clearance",
        "min_clearance_part",
    ):
        assert key in data
    assert set(data["targets"]["12"]) >= {"clearance", "engaged", "collision_part"}
    assert data["targets"]["12"]["collision_part"] is None


def test_nut_task_with_the_paper_approach_keeps_todays_numbers(nut):
    spec = nut.to_dict()
    spec["extension"] = {"approach": "paper"}
    report = evaluate(scenarios.from_dict(spec), ["bidmp"])
    result = report.methods["bidmp"]
    assert result.successes == 14 and result.engaged == 6  # ends on every nut, engages 6
    data = result.to_dict()
    hits = {
        label: t["collision_part"] for label, t in data["targets"].items() if t["collision_part"]
    }
    assert hits and all(
        part.endswith("/stud") for part in hits.values()
    )  # through the neighbours' studs
    assert data["min_clearance"] < 0


def test_cell_removal_reaches_every_cell_without_touching_a_neighbour():
    report = evaluate("cell-removal", ["bidmp"])
    result = report.methods["bidmp"]
    cells = [label for label in report.scenario.labels if label.startswith("B")]
    assert result.checked == cells
    assert all(result.task_success_at(label) for label in cells)
    assert result.clearance_at("N3") is None  # the nut under the cells is the earlier task


def test_a_layout_read_from_a_file_behaves_the_same(tmp_path, nut):
    spec = nut.to_dict()
    spec["targets"] = {
        f"r{row}c{col}": [35.0 * col, 45.0 * row, 0.0] for row in range(3) for col in range(5)
    }
    spec["demonstrated"] = "r0c0"
    spec["scene"]["parts"][0] = {
        "type": "plate",
        "label": "plate",
        "at": [70, 45, -2],
        "size": [240, 160, 5],
    }
    spec["scene"]["parts"][1]["stud"]["above"] = 14
    spec["methods"] = ["dmp", "bidmp"]
    path = tmp_path / "grid.json"
    path.write_text(json.dumps(spec))
    report = evaluate(scenarios.load(path))
    assert report.failed_targets  # the plain DMP misses some: Bi-DMP is extended for them
    result = report.methods["bidmp"]
    assert all(result.task_success_at(label) for label in report.scenario.labels)


# ---------------------------------------------------------------------------------------------
# Bad input
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "data, targets, match",
    [
        (
            {
                "tool": TOOL,
                "parts": [
                    {"type": "box", "label": "a", "at": [0, 0, 0], "size": [10, 10, 10]},
                    {"type": "box", "label": "b", "at": [5, 0, 0], "size": [10, 10, 10]},
                ],
            },
            None,
            "overlap by 5",
        ),
        (
            {"tool": TOOL, "parts": [{"type": "nut", "label": "3", "at": [0, 0, -2], **NUT}]},
            {"3": [0, 0, 0], "9": [90, 0, 0]},
            "target '9' has no part",
        ),
        (
            {"tool": TOOL, "parts": [{"type": "nut", "label": "3", "at": [0, 0, -2], **NUT}]},
            {"3": [60, 0, 0]},
            "target '3' .* is not on part '3'",
        ),
        (
            {
                "tool": {"radius": 0, "length": 100},
                "parts": [{"type": "box", "label": "a", "at": [0, 0, 0], "size": [1, 1, 1]}],
            },
            None,
            "tool.radius: must be > 0",
        ),
        (
            {"tool": TOOL, "parts": [{"type": "sphere", "label": "a", "at": [0, 0, 0]}]},
            None,
            "unknown part type 'sphere' .known: box, cell, cylinder, nut, plate",
        ),
        (
            {
                "tool": TOOL,
                "parts": [
                    {
                        "type": "box",
                        "label": "a",
                        "at": [0, 0, 0],
                        "size": [1, 1, 1],
                        "colour": "red",
                    }
                ],
            },
            None,
            "unknown key for a box",
        ),
        (
            {"tool": TOOL, "parts": [{"type": "box", "label": "a", "at": [0, 0, 0]}]},
            None,
            "size: expected a list of 3",
        ),
        (
            {
                "tool": TOOL,
                "parts": [
                    {
                        "type": "nut",
                        "label": "a",
                        "at": [0, 0, 0],
                        "across_flats": 13,
                        "height": 6.5,
                        "stud": {"radius": 7, "above": 10},
                    }
                ],
            },
            None,
            "does not fit inside the nut",
        ),
        (
            {
                "tool": TOOL,
                "parts": [
                    {"type": "box", "label": "a", "at": [0, 0, 0], "size": [1, 1, 1]},
                    {"type": "box", "label": "a", "at": [9, 0, 0], "size": [1, 1, 1]},
                ],
            },
            None,
            "two parts are labelled 'a'",
        ),
        ({"tool": TOOL, "parts": []}, None, "non-empty list of parts"),
        (
            {"tool": TOOL, "parts": [{"type": "box", "at_targets": ["x"], "size": [1, 1, 1]}]},
            {"3": [0, 0, 0]},
            "'x' is not a target",
        ),
    ],
)
def test_bad_scene_data_is_a_clear_error(data, targets, match):
    with pytest.raises(SceneError, match=match):
        Scene.from_dict(data, targets)


def test_a_tool_of_zero_size_is_refused_directly():
    with pytest.raises(ValueError, match="tool.length must be a positive number"):
        Tool(12.5, 0.0)


def test_bad_scene_in_a_scenario_file_is_one_line_from_the_cli(tmp_path, capsys, nut):
    spec = nut.to_dict()
    spec["scene"]["parts"].append(
        {"type": "box", "label": "intruder", "at": [0, 0, -2], "size": [5, 5, 5]}
    )
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(spec))
    assert main(["scenario", "check", str(path)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "scene.parts: parts '3' and 'intruder' overlap" in err


def test_without_coal_the_geometry_says_how_to_install_it(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "coal", None)  # import coal now raises ImportError
    with pytest.raises(bidmp.MissingExtraError, match=r"pip install 'bidmp\[collision\]'"):
        scenarios.load("nut-unscrewing")
    assert main(["demo", "--out", "unused"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "pip install 'bidmp[collision]'" in err


def test_final_approach_is_the_straight_tail_of_the_last_piece():
    angles = np.linspace(0.0, np.pi / 2, 50)
    arc = np.column_stack(
        [40 * np.cos(angles), 40 * np.sin(angles), np.zeros(50)]
    )  # ends at (0, 40, 0) heading -x
    line = np.column_stack([np.linspace(0, -60, 31)[1:], np.full(30, 40.0), np.zeros(30)])
    y = np.vstack([arc, line])
    start = final_approach(y, np.array([], dtype=int))
    assert 36 <= start <= 49  # the join, give or take arc samples within 2 % of the chord
    chord = (y[-1] - y[start]) / np.linalg.norm(y[-1] - y[start])
    offsets = y[start:] - y[start]
    deviation = np.linalg.norm(offsets - np.outer(offsets @ chord, chord), axis=1)
    assert deviation.max() <= 0.02 * np.linalg.norm(y[-1] - y[start])
    assert (
        final_approach(y, np.array([], dtype=int), straightness=0.001) >= 47
    )  # stricter: closer to the join
    assert final_approach(line, np.array([], dtype=int)) == 0  # all straight: all of it
    wiggle = np.column_stack(
        [np.linspace(0, 10, 40), np.sin(np.linspace(0, 12 * np.pi, 40)), np.zeros(40)]
    )
    assert final_approach(wiggle, np.array([], dtype=int)) >= 37  # no straight approach to speak of


# --- collision queries never abort -----------------------------------------------------
def test_gjk_degenerate_queries_get_the_closed_form_distance_not_an_abort():
    """A vertical tool beside a vertical post (parallel flat sides): coal's GJK at the tight
    tolerance ends on a degenerate simplex for some placements and its EPA reports -DBL_MAX for
    shapes 7.4 mm apart. The engine must give the closed-form gap (axis distance - radii) there and
    at random placements around the post, and never raise."""
    from bidmp.scene.distances import _Distances

    coal = pytest.importorskip("coal")
    scene = Scene.from_dict(
        {
            "tool": {"radius": 12.5, "length": 100},
            "targets_on_parts": False,
            "parts": [
                {"type": "cylinder", "label": "post", "at": [0, 0, 0], "radius": 15, "height": 120}
            ],
        }
    )
    engine = _Distances(scene.solids, scene.tool)
    known_bad = np.array([-28.08238384203306, 20.653673896376088, 51.0573405982136])
    shape, pose = engine.shapes[0]
    raw = coal.distance(
        engine.tool,
        coal.Transform3s(np.eye(3), known_bad + [0.0, 0.0, 50.0]),
        shape,
        pose,
        engine.request,
        coal.DistanceResult(),
    )
    gap = float(np.hypot(*known_bad[:2]) - 27.5)
    assert (
        raw < -1e100 or abs(raw - gap) <= 1e-6
    )  # the reproduction (if this coal still fails there)
    assert engine.tool_to(known_bad, 0) == pytest.approx(gap, abs=1e-6)
    assert engine.tool_to(known_bad, 0) == pytest.approx(
        gap, abs=1e-6
    )  # and again on the same engine
    # Random placements beside the post, the tool's span overlapping the post's: the gap is the
    # distance between the axes less both radii (an independent closed form).
    rng = np.random.default_rng(21)
    angles = rng.uniform(0.0, 2.0 * np.pi, 400)
    radii = rng.uniform(27.6, 60.0, 400)
    heights = rng.uniform(-80.0, 100.0, 400)
    points = np.column_stack([radii * np.cos(angles), radii * np.sin(angles), heights])
    measured = np.array([engine.tool_to(point, 0) for point in points])
    np.testing.assert_allclose(measured, radii - 27.5, atol=1e-6)


# --- 4 (opt-in): a clearance margin ---------------------------------------------------------
def _post_scene(margin, at=(22.5, -27.6)):
    base = scenarios.load("nut-unscrewing")
    data = base.to_dict()["scene"]
    data["parts"] = [
        *data["parts"],
        {"type": "cylinder", "label": "post", "at": [at[0], at[1], -2], "radius": 8, "height": 200},
    ]
    if margin:
        data["margin"] = margin
    return base, Scene.from_dict(data, base.targets)


def _post_clearance(path, at=(22.5, -27.6)):
    """Closed form: the tool (radius 12.5, above the path) beside the vertical post (radius 8) whose
    height spans the tool's here: horizontal distance between the axes less both radii."""
    fine = np.vstack(
        [
            path[i] + np.linspace(0.0, 1.0, 25)[:, None] * (path[i + 1] - path[i])
            for i in range(len(path) - 1)
        ]
    )
    return float(np.min(np.hypot(fine[:, 0] - at[0], fine[:, 1] - at[1])) - 20.5)


@pytest.mark.parametrize("seed", [1, 2])
def test_an_extension_keeps_the_scenes_margin_from_every_part(seed):
    """A post 2 mm beside the straight transfer (placed from the blind extension's own transfer):
    without a margin the extension grazes it, with a 5 mm margin the planned transfer and the
    sampled extension keep 5 mm, by the closed form."""
    base = scenarios.load("nut-unscrewing")
    target = [150.0, 25.0, 0.0]
    blind = extend_demonstration(base.demonstration, target, seed=seed)
    chord = blind.tra_gen[-1, :2] - blind.tra_gen[0, :2]
    across = np.array([chord[1], -chord[0]]) / np.linalg.norm(chord)
    at = tuple((blind.tra_gen[0, :2] + chord / 2 + (20.5 + 2.0) * across).tolist())
    _, bare = _post_scene(0.0, at)
    _, kept = _post_scene(5.0, at)
    close = extend_demonstration(base.demonstration, target, seed=seed, scene=bare)
    far = extend_demonstration(base.demonstration, target, seed=seed, scene=kept)
    assert _post_clearance(close.complete, at) < 5.0  # the check can fail
    assert (
        _post_clearance(far.tra_gen, at) >= 5.0 - 1e-9
        and _post_clearance(far.complete, at) >= 5.0 - 1e-6
    )
    assert kept.clearance(far.complete, exclude=kept.parts_at(target)).clear


def test_a_margin_is_validated_and_counts_in_task_success():
    _, kept = _post_scene(5.0)
    assert kept.to_dict()["margin"] == 5.0
    near = np.array(
        [[22.5 + 20.5 + 2.0, -27.6, 150.0], [22.5 + 20.5 + 2.0, -27.6, 120.0]]
    )  # 2 mm from the post
    clearance = kept.clearance(near)
    assert clearance.collision_free and not clearance.clear and clearance.part == "post"
    with pytest.raises(SceneError, match="scene.margin"):
        _post_scene(-1.0)
    with pytest.raises(SceneError, match="scene.margin"):
        _post_scene(50.0)  # beyond the tool's radius


# ---------------------------------------------------------------------------------------------
# a default margin, and stand-offs stated per part
# ---------------------------------------------------------------------------------------------
def test_a_scenario_keeps_3_mm_by_default_in_its_units():
    spec = scenarios.load("pick-and-place").to_dict()
    assert "margin" not in spec["scene"]
    assert scenarios.from_dict(spec).scene.margin == 3.0
    metres = json.loads(json.dumps(spec))
    metres["units"] = "m"
    scale = 1e-3
    metres["targets"] = {k: (np.asarray(v) * scale).tolist() for k, v in spec["targets"].items()}
    metres["demonstrations"] = {}
    metres["demonstration"] = {"points": (minimum_jerk_points() * scale).tolist()}
    metres["success_threshold"] = 1.75 * scale
    metres["scene"]["tool"] = {"radius": 0.01, "length": 0.1}
    metres["scene"]["parts"] = [
        {"type": "box", "label": "pad", "at": [0.3, 0.06, -0.04], "size": [0.03, 0.03, 0.04]}
    ]
    metres["scene"]["targets"] = ["op1"]
    metres["scene"]["targets_on_parts"] = False
    metres["robot"] = {"base": [0.17, -0.33, 0.03], "yaw": 90}
    assert scenarios.from_dict(metres).scene.margin == pytest.approx(0.003)
    box = [{"type": "box", "label": "b", "at": [0, 0, 0], "size": [1, 1, 1]}]
    assert (
        Scene.from_dict({"tool": {"radius": 2.0, "length": 50}, "parts": box}, units="mm").margin
        == 2.0
    )  # <= the radius
    assert Scene.from_dict({"tool": TOOL, "parts": box}).margin == 0.0  # no units: no default


def minimum_jerk_points():
    from bidmp.demonstrations import minimum_jerk

    return minimum_jerk([[0, 0, 0], [150, 20, 190], [300, 60, 30]], 200)


def test_a_part_at_its_stand_off_does_not_hide_another_inside_the_margin():
    """Margin 3, the plate's stand-off 1 (closed forms: a vertical tool of radius 12.5 over the
    plate's top at height h is h away; beside a post of radius 4, the axes d apart, d − 16.5)."""
    plate = {"type": "plate", "label": "plate", "at": [0, 0, 0], "size": [400, 400, 5]}
    post = {"type": "cylinder", "label": "post", "at": [0, 0, 0], "radius": 4, "height": 60}
    scene = scene_of(plate, post, margin=3.0, standoff={"plate": 1.0})

    def passing(height, gap):  # along x at ``height`` over the plate, ``gap`` beside the post
        return np.column_stack(
            [np.linspace(-100, 100, 401), np.full(401, 16.5 + gap), np.full(401, height)]
        )

    hidden = scene.clearance(passing(1.5, 2.5))  # plate 1.5 (>= 1), post 2.5 (< 3)
    assert (
        not hidden.clear
        and hidden.part == "post"
        and hidden.distance == pytest.approx(2.5, abs=1e-6)
    )
    fine = scene.clearance(passing(1.5, 5.0))
    assert (
        fine.clear
        and fine.part == "plate"
        and fine.margin == 1.0
        and fine.distance == pytest.approx(1.5, abs=1e-6)
    )
    low = scene.clearance(passing(0.5, 5.0))
    assert not low.clear and low.part == "plate"
    assert (
        not scene_of(plate, post, margin=3.0).clearance(passing(1.5, 5.0)).clear
    )  # without the stand-off
    with pytest.raises(SceneError, match="standoff.ring: is not the label of a part"):
        scene_of(plate, margin=3.0, standoff={"ring": 1.0})
    with pytest.raises(
        SceneError, match=r"standoff.plate: expected a clearance in \[0, the margin 3\]"
    ):
        scene_of(plate, margin=3.0, standoff={"plate": 4.0})


def test_a_tool_turning_in_place_is_checked_along_its_sweep():
    """The tool's tip stays put while it turns 90 degrees about x (its body from up to along +y,
    two samples): the body sweeps a quarter disc of radius 100 through a block at 45 degrees, 70
    from the tip, which neither end pose comes near. Placements spaced by the tip's travel alone
    (zero here) saw only the two end poses and reported it clear; spaced by the sweep, the block
    is hit."""
    scene = Scene.from_dict(
        {
            "tool": {"radius": 5.0, "length": 100.0},
            "parts": [
                {
                    "type": "box",
                    "label": "block",
                    "at": [0.0, 49.5, 44.5],
                    "size": [10.0, 10.0, 10.0],
                }
            ],
        }
    )
    poses = (
        Rotation.from_euler("x", [[0.0], [-90.0]], degrees=True)
        * Rotation.from_euler("x", 180.0, degrees=True)
    ).as_quat()
    tip = np.zeros((2, 3))
    for pose in poses:
        assert scene.clearance(tip[:1], orientations=pose[None]).distance > 30.0
    swept = scene.clearance(tip, orientations=poses)
    assert not swept.collision_free and swept.part == "block"


def test_a_scene_with_more_parts_is_the_scene_its_file_would_give():
    """Structure guard (the job adds its bin and rack this way, no longer through a dict):
    with_parts gives the scene from_dict gives for the same parts, keeps the tool, margin and
    stand-offs, and refuses an overlap or a label already taken."""
    nut = scenarios.load("nut-unscrewing")
    targets = nut.targets
    box = {"type": "box", "label": "bin", "at": [90.0, 250.0, -20.0], "size": [60.0, 60.0, 40.0]}
    grown = nut.scene.with_parts([box], targets)
    data = nut.scene.to_dict()
    data["parts"] = data["parts"] + [box]
    expected = Scene.from_dict(data, {k: v.tolist() for k, v in targets.items()})
    assert grown.to_dict() == expected.to_dict() and len(grown.solids) == len(nut.scene.solids) + 1
    assert (grown.margin, grown.tool, grown.standoff) == (
        nut.scene.margin,
        nut.scene.tool,
        nut.scene.standoff,
    )
    path = np.array([[90.0, 250.0, 100.0], [90.0, 250.0, 10.0]])
    assert nut.scene.clearance(path).clear and not grown.clearance(path).collision_free
    with pytest.raises(ValueError, match="overlap"):
        nut.scene.with_parts([{**box, "label": "slab", "at": [90.0, 25.0, -2.0]}], targets)
    with pytest.raises(ValueError, match="'plate' is already a part"):
        nut.scene.with_parts([{**box, "label": "plate"}], targets)


@pytest.mark.parametrize("seed", range(4))
def test_a_turning_tool_among_tilted_parts_matches_every_pair_through_coal(seed):
    """Correctness of the culling (the bounds taken in each solid's own frame): random tilted
    boxes, cylinders and a convex part, a tool turning along a random path; the clearance must be
    the minimum over every (placement, solid) pair asked of coal, the slow plain way: a bound that
    is not a lower bound would skip the nearest pair and report more room than there is."""
    rng = np.random.default_rng(300 + seed)
    scene = None
    while scene is None:  # draw again where the random parts overlap
        parts = []
        for index in range(5):
            tilt = rng.uniform(-35.0, 35.0, 3).tolist()
            at = [*rng.uniform(-80.0, 80.0, 2), rng.uniform(-20.0, 20.0)]
            if index % 2:
                part = {
                    "type": "cylinder",
                    "radius": float(rng.uniform(4, 15)),
                    "height": float(rng.uniform(10, 40)),
                }
            else:
                part = {"type": "box", "size": rng.uniform(5.0, 60.0, 3).tolist()}
            parts.append(
                {**part, "label": f"p{index}", "at": [float(v) for v in at], "rotation": tilt}
            )
        try:
            scene = Scene.from_dict({"tool": {"radius": 6.0, "length": 60.0}, "parts": parts})
        except SceneError:
            continue
    path = np.cumsum(rng.normal(0.0, 6.0, (40, 3)), axis=0) + [0.0, 0.0, 30.0]
    turns = Rotation.from_rotvec(
        np.cumsum(rng.normal(0.0, 0.08, (40, 3)), axis=0)
    ) * Rotation.from_euler("x", 180.0, degrees=True)
    found = scene.clearance(path, orientations=turns.as_quat(), step=2.0)
    # the placements the clearance makes: densified by each point's travel, nlerp between frames
    from bidmp.scene.clearance import _sweep
    from bidmp.scene.distances import _densify

    q = turns.as_quat()
    sweep = _sweep(path, q, float(np.hypot(60.0, 6.0)))
    dense, segment, fraction = _densify(path, 2.0, weights=True, lengths=sweep)
    dense_q = q[segment] + fraction[:, None] * (q[segment + 1] - q[segment])
    rotations = Rotation.from_quat(
        dense_q / np.linalg.norm(dense_q, axis=1, keepdims=True)
    ).as_matrix()
    engine = scene._engine()
    every = min(
        engine.tool_to(dense[row], solid, rotations[row])
        for row in range(dense.shape[0])
        for solid in range(len(scene.solids))
    )
    assert found.distance == pytest.approx(every, abs=1e-9)


def _tilted_solids() -> Scene:
    """A tilted box, cylinder and nut, 150 apart (a 6-radius, 60-long tool)."""
    parts = [
        {"type": "box", "label": "b", "at": [0, 0, 0], "size": [60, 40, 8], "rotation": [20, -15, 30]},
        {"type": "cylinder", "label": "c", "at": [150, 0, 0], "radius": 9, "height": 50, "rotation": [35, 10, 0]},
        {"type": "nut", "label": "n", "at": [-150, 0, 0], "across_flats": 20, "height": 12, "rotation": [25, 5, 0]},
    ]  # fmt: skip
    return Scene.from_dict({"tool": {"radius": 6.0, "length": 60.0}, "parts": parts})


def test_a_carried_body_s_clearance_is_the_least_exact_distance_along_its_way():
    """A box carried past three tilted parts (:meth:`Scene.body_clearance`, culled by box bounds
    per placement and part): the distance found is coal's least over a finer sampling of the same
    way (each solid asked at every sample: no culling), within the sampling's half step."""
    from bidmp.scene import Scene

    scene = _tilted_solids()
    held = Scene.from_dict(
        {
            "tool": {"radius": 6.0, "length": 60.0},
            "parts": [{"type": "box", "label": "held", "at": [0, 0, 0], "size": [30, 20, 10]}],
        }
    ).solids[0]
    offset = np.array([0.0, 0.0, -25.0])
    way = np.array(
        [[-220.0, 30.0, 40.0], [-60.0, 45.0, 35.0], [80.0, 35.0, 45.0], [220.0, 30.0, 50.0]]
    )
    found = scene.body_clearance(held, way, offset)
    engine = scene._engine()
    shape = engine.shape_of(held)
    fine = np.vstack(
        [a + np.linspace(0.0, 1.0, 1600)[:, None] * (b - a) for a, b in zip(way[:-1], way[1:])]
    )
    every = min(
        engine.body_to(shape, held.rotation, point + offset, index)
        for point in fine
        for index in range(len(scene.solids))
    )
    assert np.isfinite(found.distance) and found.distance < 30.0  # it passes near a part
    # both samplings at most 0.12 apart (the default step, 0.2 % of the tool): half of each
    assert found.distance == pytest.approx(every, abs=0.06 + 0.06)


def test_the_oriented_bound_does_not_depend_on_where_a_solid_keeps_its_own_box():
    """A solid's box in its own frame need not be centred on its origin (a convex part's hull need
    not be): the same box described from another origin, its centre moved by ``R d`` and its
    corners by ``-d``, bounds every placement the same (a property of the geometry, not the code
    against itself; the built-in solids are all centred, so nothing else tries it)."""
    rng = np.random.default_rng(12)
    scene = _tilted_solids()
    chosen = np.arange(len(scene.solids))
    turns = Rotation.random(300, random_state=4).as_matrix()
    points = rng.normal([0.0, 0.0, 0.0], 120.0, (300, 3))
    axes = turns[:, :, 2]
    before = scene._oriented_bounds(points - axes * 30.0, axes, chosen)
    centre, rotation, lower, upper = scene._frames
    shift = rng.normal(size=centre.shape) * 25.0
    scene._frames = (
        centre + np.einsum("kij,kj->ki", rotation, shift),
        rotation,
        lower - shift,
        upper - shift,
    )
    after = scene._oriented_bounds(points - axes * 30.0, axes, chosen)
    assert np.any(before > 0.0) and np.allclose(after, before, rtol=0.0, atol=1e-9)


def test_the_oriented_bound_is_a_lower_bound_and_tight_where_the_tool_is_square_to_a_box():
    """The culling bound of a turning tool, on its own: never above coal's exact distance (random
    tilted boxes and cylinders, random tool frames and places; a bound above it would skip the
    nearest pair), and equal to it for a tool square to a tilted box's face (a looser bound would
    send every pair near a tilted plate to coal again, as the world-frame box did)."""
    rng = np.random.default_rng(11)
    scene = _tilted_solids()
    engine = scene._engine()
    chosen = np.arange(len(scene.solids))
    turns = Rotation.random(600, random_state=3)
    points = np.vstack(
        [rng.normal(centre, 45, (200, 3)) for centre in ([0, 0, 0], [150, 0, 0], [-150, 0, 0])]
    )
    axes = turns.as_matrix()[:, :, 2]
    bounds = scene._oriented_bounds(points - axes * 30.0, axes, chosen)
    exact = np.array(
        [[engine.tool_to(p, k, r) for k in chosen] for p, r in zip(points, turns.as_matrix())]
    )
    # (coal's exact distance is within 1e-8 of the closed form: a face-on bound may sit 1e-9 above)
    over = np.argwhere(bounds > np.maximum(exact, 0.0) + 1e-7)
    assert not over.size, [(int(i), int(k), bounds[i, k], exact[i, k]) for i, k in over[:5]]
    assert np.mean(bounds > 0.5 * np.maximum(exact, 0.0)) > 0.5  # and not a trivial one
    # square to the box: the tool's axis along the box's own -z, above its top face by 7
    solid = scene.solids[0]  # (its centre where the part's "at" puts it)
    box = Rotation.from_matrix(solid.rotation)
    into = box * Rotation.from_euler("x", 180.0, degrees=True)  # the tool's z into the face
    for offset in ([0, 0], [12, -5], [-20, 9]):
        mouth = solid.centre + box.apply([*offset, 4.0 + 7.0])
        axis = into.apply([0.0, 0.0, 1.0])
        (bound,) = scene._oriented_bounds(mouth[None] - axis * 30.0, axis[None], chosen[:1])[:, 0]
        assert bound == pytest.approx(7.0, abs=1e-9)
        assert engine.tool_to(mouth, 0, into.as_matrix()) == pytest.approx(7.0, abs=1e-6)
    # a cylinder's end: the tool along its axis, 5 beyond its top
    solid = scene.solids[1]
    cylinder = Rotation.from_matrix(solid.rotation)
    down = cylinder * Rotation.from_euler("x", 180.0, degrees=True)
    axis = down.apply([0.0, 0.0, 1.0])
    mouth = solid.centre + cylinder.apply([0.0, 0.0, 25.0 + 5.0])
    (bound,) = scene._oriented_bounds(mouth[None] - axis * 30.0, axis[None], chosen[1:])[:, 0]
    assert bound == pytest.approx(5.0, abs=1e-9)
