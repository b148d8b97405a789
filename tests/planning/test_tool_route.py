"""The tool's own route through a scene, judged by the scene's clearance along the whole motion
(the contract's function: densified, branch and bound over every part) and by an engagement
check written here; the pose checker's answers against that clearance at random poses."""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bidmp.planning import NoRouteError, tool_route
from bidmp.scene import Scene

pytest.importorskip("ompl")
pytest.importorskip("coal")

DOWN = Rotation.from_euler("x", 180.0, degrees=True)


def walled(units: float = 1.0) -> Scene:
    """A plate, a nut at the origin, and a tall wall between it and where the motion starts (mm,
    or scaled to another unit by ``units``)."""
    f = units
    return Scene.from_dict(
        {
            "tool": {"radius": 12.5 * f, "length": 100 * f},
            "margin": 3 * f,
            "standoff": {"plate": 1 * f},
            "parts": [
                {
                    "type": "plate",
                    "label": "plate",
                    "at": [0, 0, -2 * f],
                    "size": [400 * f, 400 * f, 5 * f],
                },
                {
                    "type": "nut",
                    "label": "nut",
                    "at": [0, 0, -2 * f],
                    "across_flats": 13 * f,
                    "height": 6.5 * f,
                },
                {
                    "type": "box",
                    "label": "wall",
                    "at": [-60 * f, -80 * f, -2 * f],
                    "size": [20 * f, 200 * f, 150 * f],
                },
            ],
        },
        {"nut": [0.0, 0.0, 0.0]},
    )


def engaged(path, goal, axis, height, threshold) -> bool:
    """Over the last ``height`` along ``axis`` the path stays within ``threshold`` of the axis and
    goes down it."""
    along = (path[:, :3] - goal[:3]) @ axis
    outside = np.flatnonzero(along > height)
    band = path[outside[-1] + 1 :, :3] if outside.size else path[:, :3]
    offsets = band - goal[:3]
    across = np.linalg.norm(offsets - np.outer(offsets @ axis, axis), axis=1)
    return bool(across.max() <= threshold and np.all(np.diff(band @ axis) <= 1e-9))


@pytest.mark.parametrize("units", [1.0, 0.001])
def test_a_route_over_a_wall_keeps_the_margin_and_ends_down_the_axis(units):
    scene = walled(units)
    start = np.array([-150.0, -40.0, 60.0]) * units
    goal = np.zeros(3)
    route = tool_route(scene, start, goal, approach_height=28.5 * units, exclude=["nut"], seed=1)
    motion = route.motion(300)
    assert np.allclose(motion[0], start) and np.allclose(motion[-1], goal)
    clearance = scene.clearance(motion, exclude=["nut"])
    assert clearance.clear, clearance
    assert engaged(motion, goal, np.array([0.0, 0.0, 1.0]), 28.5 * units, 1e-9)
    # the route is not the straight line: that one cuts the wall
    assert not scene.clearance(np.vstack([start, goal]), exclude=["nut"]).clear


def test_a_tilted_target_is_reached_turning_the_tool_onto_its_axis():
    scene = walled()
    tilt = Rotation.from_euler("y", 20.0, degrees=True)
    start = np.concatenate([[-150.0, -40.0, 60.0], DOWN.as_quat()])
    goal = np.concatenate([[0.0, 0.0, 10.0], (tilt * DOWN).as_quat()])  # clear of the plate, tilted
    axis = tilt.apply([0.0, 0.0, 1.0])
    route = tool_route(scene, start, goal, axis=axis, approach_height=28.5, exclude=["nut"], seed=0)
    motion = route.motion(300)
    assert scene.clearance(motion[:, :3], exclude=["nut"], orientations=motion[:, 3:]).clear
    assert engaged(motion, goal, axis, 28.5, 1e-9)
    last = Rotation.from_quat(motion[-1, 3:]).apply([0.0, 0.0, 1.0])
    assert np.dot(last, -axis) > 1 - 1e-9


def test_a_blocked_final_approach_or_a_closed_room_has_no_route():
    scene = walled()
    with pytest.raises(NoRouteError, match="final approach onto the goal is not free"):
        # a goal right beside the wall: coming straight down it, the tool cuts the wall
        tool_route(
            scene, [-150.0, 0.0, 60.0], [-45.0, 0.0, 0.0], approach_height=28.5, exclude=["nut"]
        )
    boxed = Scene.from_dict(
        {
            "tool": {"radius": 5, "length": 50},
            "margin": 1,
            "parts": [
                {"type": "box", "label": "floor", "at": [0, 0, -10], "size": [100, 100, 10]},
                {"type": "box", "label": "lid", "at": [0, 0, 60], "size": [100, 100, 10]},
                {"type": "box", "label": "w1", "at": [-45, 0, 0], "size": [10, 100, 60]},
                {"type": "box", "label": "w2", "at": [45, 0, 0], "size": [10, 100, 60]},
                {"type": "box", "label": "w3", "at": [0, -45, 0], "size": [80, 10, 60]},
                {"type": "box", "label": "w4", "at": [0, 45, 0], "size": [80, 10, 60]},
            ],
        }
    )
    with pytest.raises(NoRouteError):
        tool_route(boxed, [-150.0, 0.0, 30.0], [0.0, 0.0, 2.0], max_checks=3000)


def test_the_pose_checker_agrees_with_the_clearance_at_random_poses():
    scene = walled()
    checker = scene.pose_checker(["nut"])
    rng = np.random.default_rng(0)
    for _ in range(300):
        point = rng.uniform([-150, -150, 0], [150, 150, 200])
        turn = Rotation.from_rotvec(rng.normal(0, 0.4, 3)) * DOWN
        clear = scene.clearance(
            point[None], exclude=["nut"], orientations=turn.as_quat()[None]
        ).clear
        assert checker.free(point, turn.as_matrix()) == clear
        slack = checker.slack(point, turn.as_matrix())
        assert (slack >= 0.0) == clear


def test_the_pose_checker_sees_a_part_by_the_tools_top_and_a_scene_of_one_part():
    """A beam beside the top of the tool (the mouth far from it, the body's last tenth within
    the margin), tilted or not, and the same with every other part excluded (one part left):
    the pose checker says what the clearance says, and its slack is never above it."""
    scene = Scene.from_dict(
        {
            "tool": {"radius": 10.0, "length": 100.0},
            "margin": 3.0,
            "parts": [
                {"type": "box", "label": "beam", "at": [21.5, -50.0, 85.0], "size": [20, 100, 10]},
                {"type": "box", "label": "floor", "at": [0, 0, -20], "size": [300, 300, 5]},
            ],
        }
    )
    point = np.array([0.0, 0.0, 0.0])
    for exclude in ([], ["floor"]):
        checker = scene.pose_checker(exclude)
        for tilt in (0.0, 3.0):
            turn = Rotation.from_euler("y", tilt, degrees=True) * DOWN
            clearance = scene.clearance(
                point[None], exclude=exclude, orientations=turn.as_quat()[None]
            )
            assert clearance.part == "beam" and not clearance.clear, clearance
            assert not checker.free(point, turn.as_matrix())
            assert checker.slack(point, turn.as_matrix()) <= clearance.distance - 3.0 + 1e-9
