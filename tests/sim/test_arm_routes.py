"""The arm's own routes, checked from outside the code that plans them: the pinocchio model of each
arm against PyBullet's and against an arm's published DH table written here; its distances to the
parts against PyBullet's closest points; its inverse kinematics against the DH product; a planned
route executed and judged by PyBullet's contacts, the contract's clearance and command differences
taken here. The user's arm of the acceptance (an ABB IRB 1200 written from its published table,
tests/data/irb1200) is one of them: its wrist is singular wherever the tool points straight down
with the forearm level."""

import json
import math
import shutil
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

pytest.importorskip("pybullet")
pytest.importorskip("pinocchio")
pytest.importorskip("ompl")

from bidmp import sim  # noqa: E402
from bidmp.sim.arm_geometry import ArmGeometry  # noqa: E402
from bidmp.sim.robots import ROBOT_MODELS, JointLimits, RobotModel  # noqa: E402

DATA = Path(__file__).resolve().parents[1] / "data"
IRB = DATA / "irb1200" / "irb1200.urdf"
DEG = math.pi / 180.0
# The IRB 1200-7/0.7 as ABB publishes it: classic DH (d, a, alpha), theta offsets, axis ranges and speeds
IRB_DH = (
    (0.399, 0.0, -90),
    (0.0, 0.35, 0.0),
    (0.0, 0.042, -90),
    (0.351, 0.0, 90),
    (0.0, 0.0, -90),
    (0.082, 0.0, 0.0),
)
IRB_OFFSETS = (0.0, -90.0, 0.0, 0.0, 0.0, 180.0)
IRB_LOWER = (-170, -100, -200, -270, -130, -400)
IRB_UPPER = (170, 135, 70, 270, 130, 400)
IRB_SPEED = (288, 240, 297, 400, 405, 600)


def irb_model() -> RobotModel:
    speeds = [v * DEG for v in IRB_SPEED]
    limits = JointLimits(
        [v * DEG for v in IRB_LOWER],
        [v * DEG for v in IRB_UPPER],
        speeds,
        [5 * v for v in speeds],
        [500 * v for v in speeds],
    )
    return RobotModel(
        "irb1200", str(IRB), "flange", limits, (0.0,) * 6, (100.0,) * 6, rest_given=False
    )


def irb_flange(q) -> np.ndarray:
    """The flange's pose (4, 4) from ABB's table: Rz(theta + offset) Tz(d) Tx(a) Rx(alpha)."""
    pose = np.eye(4)
    for (d, a, alpha), offset, theta in zip(IRB_DH, IRB_OFFSETS, q):
        t, al = theta + offset * DEG, alpha * DEG
        ct, st, ca, sa = np.cos(t), np.sin(t), np.cos(al), np.sin(al)
        pose = pose @ np.array(
            [
                [ct, -st * ca, st * sa, a * ct],
                [st, ct * ca, -ct * sa, a * st],
                [0, sa, ca, d],
                [0, 0, 0, 1],
            ]
        )
    return pose


ARMS = {**ROBOT_MODELS, "irb1200": irb_model()}


@pytest.mark.parametrize("name", sorted(ARMS))
def test_the_route_model_of_every_arm_is_pybullets_to_a_micrometre(name):
    """pinocchio's model of the arm (what routes are planned on) against the simulated arm's own
    forward kinematics at 30 random joint vectors within its limits: the tool's mouth to 1 µm and
    its frame to 1e-6."""
    robot = ARMS[name]
    base, yaw = np.array([0.1, -0.4, 0.02]), 70.0
    from bidmp.scene import Scene, Tool

    with sim.RobotCell(Scene([], Tool(0.0125, 0.1)), "m", base, yaw, robot) as cell:
        arm = ArmGeometry(robot, 0.0125, 0.1, base, yaw)
        rng = np.random.default_rng(1)
        lower, upper = np.array(robot.limits.lower), np.array(robot.limits.upper)
        for _ in range(30):
            q = rng.uniform(np.maximum(lower, -3.0), np.minimum(upper, 3.0))
            mouth, frame = arm.tool_pose(q)
            assert np.linalg.norm(mouth - cell.fk(q)) < 1e-6
            cell.fk(q)
            measured = cell.p.getLinkState(cell.ik_robot, cell.tcp, physicsClientId=cell.ik_client)[
                5
            ]
            np.testing.assert_allclose(frame, Rotation.from_quat(measured).as_matrix(), atol=1e-6)


def test_the_irb1200_urdf_is_its_published_table():
    """The user's arm written by tools/ur5_urdf.py against ABB's table multiplied out here."""
    arm = ArmGeometry(irb_model(), 0.0125, 0.0, np.zeros(3), 0.0)
    rng = np.random.default_rng(2)
    for _ in range(30):
        q = rng.uniform(-2.0, 2.0, 6)
        flange = irb_flange(q)
        mouth, frame = arm.tool_pose(q)
        np.testing.assert_allclose(mouth, flange[:3, 3], atol=1e-9)
        np.testing.assert_allclose(frame[:, 2], flange[:3, 2], atol=1e-9)


def busbar(directory: Path) -> Path:
    """The acceptance's kind of cell, committed beside its arm (tools/busbar_cell.py writes it),
    copied with the arm into ``directory``."""
    shutil.copy(IRB.parent / "busbar.json", directory / "busbar.json")
    shutil.copy(IRB, directory / "irb1200.urdf")
    return directory / "busbar.json"


def test_the_route_models_distances_agree_with_pybullets_closest_points(tmp_path):
    """At 300 random joint vectors of the IRB 1200 in the busbar cell: free by the route model's
    slack exactly where PyBullet finds no point of the arm within the margin of a part."""
    from bidmp.sim.routes import _arm
    from bidmp.tasks import scenarios

    scenario = scenarios.load(str(busbar(tmp_path)))
    base, yaw = sim.robot_placement(scenario)
    with sim.RobotCell(
        scenario.scene, "m", base, yaw, sim.robot_model(scenario.robot, tmp_path)
    ) as cell:
        exclude = scenario.scene.target_parts("B3", scenario.targets["B3"][:3])
        space = _arm(cell).space(scenario.scene, 1.0, exclude=exclude, margin=0.003)
        p, client = cell.p, cell.client
        bodies = [body for body, owner in cell._owners.items() if owner not in exclude]
        rng = np.random.default_rng(0)
        disagree = []
        for q in rng.uniform(space.lower, space.upper, (300, 6)):
            cell._set_joints(q)
            near = min(
                (
                    point[8]
                    for body in bodies
                    for point in p.getClosestPoints(cell.robot, body, 0.01, physicsClientId=client)
                ),
                default=np.inf,
            )
            slack = space.slack(q)
            # the model asks for the margin plus its tolerance: agree outside that band
            if slack >= 0 and near < 0.003 or slack < -1e-9 and near > 0.003 + space.tolerance:
                disagree.append((q, slack, near))
        assert not disagree, disagree[:3]


def test_the_inverse_kinematics_reaches_poses_at_the_irb1200s_wrist_singularity():
    """Poses the arm takes (forward kinematics of random joints, joint 5 within 1 degree of zero:
    the wrist singular), solved from the rest pose and checked by ABB's table: the mouth within
    0.05 mm, the tool's axis within 1e-6 of the asked one, every joint within its limits."""
    robot = irb_model()
    arm = ArmGeometry(robot, 0.0125, 0.1, np.zeros(3), 0.0)
    rng = np.random.default_rng(4)
    lower, upper = np.array(robot.limits.lower), np.array(robot.limits.upper)
    solved = 0
    for _ in range(20):
        q = rng.uniform(-1.2, 1.2, 6)
        q[4] = rng.uniform(-1.0, 1.0) * DEG
        mouth, frame = arm.tool_pose(q)
        found, error = None, np.inf
        for seed in (np.zeros(6), rng.uniform(-1, 1, 6), rng.uniform(-2, 2, 6)):
            candidate, error = arm.solve_ik(mouth, Rotation.from_matrix(frame).as_quat(), seed)
            if error <= 5e-5:
                found = candidate
                break
        assert found is not None, (q, error)
        flange = irb_flange(found)
        np.testing.assert_allclose(flange[:3, 3] + flange[:3, 2] * 0.1, mouth, atol=5e-5)
        assert np.linalg.norm(flange[:3, 2] - frame[:, 2]) < 1e-6
        assert np.all(found >= lower - 1e-9) and np.all(found <= upper + 1e-9)
        solved += 1
    assert solved == 20


def test_a_route_of_the_arm_round_the_post_runs_clear_and_within_the_limits(tmp_path):
    """The arm's own route from the rest pose to the nut behind the busbar post, executed on the
    simulated arm: no contact in PyBullet, no link within the margin of a part (PyBullet's
    closest points along the plan), the tool's path clear by the scene's clearance, its last 28.5
    mm straight down the nut's axis, the 1 kHz commands within the limits by differences taken
    here, from rest to rest."""
    from bidmp.tasks import scenarios

    scenario = scenarios.load(str(busbar(tmp_path)))
    base, yaw = sim.robot_placement(scenario)
    robot = sim.robot_model(scenario.robot, tmp_path)
    target = np.asarray(scenario.targets["B3"], dtype=float)
    axis = scenario.target_axis("B3")
    exclude = scenario.scene.target_parts("B3", target[:3])
    with sim.RobotCell(scenario.scene, "m", base, yaw, robot) as cell:
        routed = sim.arm_route(
            cell,
            np.asarray(cell.rest),
            target[:3],
            axis=axis,
            approach_height=scenario.approach_height,
            orientation=target[3:],
            exclude=exclude,
            label="B3",
        )
        plan = routed.plan
        assert cell.arm_touch(plan, exclude) is None
        run = cell.execute(plan, exclude)
        assert not run.contacts
    path = plan.points
    assert np.linalg.norm(path[-1] - target[:3]) < 1e-5
    assert scenario.scene.clearance(path, exclude=exclude, orientations=plan.orientations).clear
    along = (path - target[:3]) @ axis
    inside = path[along <= scenario.approach_height]
    offsets = inside - target[:3]
    across = np.linalg.norm(offsets - np.outer(offsets @ axis, axis), axis=1)
    assert across.max() < 1e-4
    commands = np.vstack([[run.commands[0]] * 3, run.commands, [run.commands[-1]] * 3])
    limits = robot.limits
    for order, limit in ((1, limits.velocity), (2, limits.acceleration), (3, limits.jerk)):
        rate = np.diff(commands, n=order, axis=0) / 1e-3**order
        assert np.all(np.max(np.abs(rate), axis=0) <= np.asarray(limit) * 1.001), order


def test_the_committed_busbar_cell_is_the_one_its_builder_writes():
    """Structure guard: tests/data/irb1200/busbar.json is tools/busbar_cell.py's output."""
    import busbar_cell

    written = json.loads(json.dumps(busbar_cell.cell()))
    assert written == json.loads((IRB.parent / "busbar.json").read_text())


def test_a_carried_part_keeps_the_margin_where_the_tool_keeps_a_stand_off():
    """The route's model of a part the tool carries keeps the scene's margin from every part, as
    the contract's clearance of a carried part asks; the tool itself may come to a declared
    stand-off (the plate it works on). The IRB 1200's tool pointing down over a plate (margin 3
    mm, stand-off 1 mm), a nut in its socket reaching 2 mm below the mouth: with the mouth 4 mm
    up (the nut 2 mm over the plate) the arm is within its clearance, with the mouth 6 mm up it is
    not; without the nut, 4 mm is clear."""
    from bidmp.scene import Scene

    scene = Scene.from_dict(
        {
            "tool": {"radius": 0.0125, "length": 0.1},
            "margin": 0.003,
            "standoff": {"plate": 0.001},
            "parts": [
                {
                    "type": "plate",
                    "label": "plate",
                    "at": [0.45, 0.0, 0.0],
                    "size": [0.3, 0.3, 0.01],
                },
                {
                    "type": "nut",
                    "label": "N",
                    "at": [0.45, 0.0, 0.002],
                    "across_flats": 0.013,
                    "height": 0.0065,
                },
            ],
        }
    )
    arm = ArmGeometry(irb_model(), 0.0125, 0.1, np.zeros(3), 0.0)
    nut = next(solid for solid in scene.solids if solid.part == "N")
    down = np.array([1.0, 0.0, 0.0, 0.0])
    clear = {}
    for height in (0.004, 0.006):
        q, error = arm.solve_ik(
            np.array([0.45, 0.0, height]), down, np.array([0, 0.5, 0.3, 0, 0.8, 0])
        )
        assert error < 1e-6
        # the nut where the socket holds it: its bottom 2 mm below the mouth
        held = nut.moved(np.asarray(nut.centre) + [0.0, 0.0, height - 0.004], np.eye(3))
        carried = arm.space(scene, 1.0, exclude=["N"], margin=0.003, carried=(held, q))
        bare = arm.space(scene, 1.0, exclude=["N"], margin=0.003)
        clear[height] = (carried.slack(q) >= 0.0, bare.slack(q) >= 0.0)
    assert clear == {0.004: (False, True), 0.006: (True, True)}, clear


def test_a_simulated_motions_route_starts_from_joints_clear_of_the_parts():
    """A simulated motion starts with the arm placed at its first point: where the joints the
    inverse kinematics gives there from the rest pose put a link within the margin of a part,
    the arm's own route starts from other joints that put the tool at the same place clear of
    it (it said its start was not free, and the target failed). The Panda, a post beside its
    forearm at the motion's start: the route's first joints put the tool's mouth at the start
    (within 1 µm), keep every link clear (the route model's slack, which agrees with PyBullet's
    closest points above) and differ from the rest pose's solution."""
    import pinocchio

    from bidmp.scene import Scene
    from bidmp.sim.robots import PANDA_MODEL
    from bidmp.tasks.contract import Contract

    start, target = np.array([0.0, 0.4, 0.25]), np.array([0.15, 0.5, 0.05])
    arm = ArmGeometry(PANDA_MODEL, 0.0125, 0.1, np.zeros(3), 90.0)
    tool = {"radius": 0.0125, "length": 0.1}
    with sim.RobotCell(
        Scene.from_dict(
            {
                "tool": tool,
                "parts": [
                    {
                        "type": "box",
                        "label": "far",
                        "at": [1.5, 1.5, 0.0],
                        "size": [0.01, 0.01, 0.01],
                    }
                ],
            }
        ),
        "m",
        np.zeros(3),
        90.0,
        PANDA_MODEL,
    ) as bare:
        placed, error = bare.solve_ik(start, np.asarray(bare.rest))
    assert error < 1e-6
    # beside its forearm (halfway from the elbow to the wrist), 40 mm off it
    pinocchio.forwardKinematics(arm.model, arm.data, placed)
    elbow, wrist = (arm.rotation @ arm.data.oMi[j].translation for j in (4, 6))
    forearm = 0.5 * (elbow + wrist)
    post = {
        "type": "cylinder",
        "label": "post",
        "at": [forearm[0] + 0.04, forearm[1], -0.1],
        "radius": 0.015,
        "height": float(forearm[2] + 0.1),
    }
    scene = Scene.from_dict({"tool": tool, "margin": 0.003, "parts": [post]})
    space = arm.space(scene, 1.0, margin=0.003)
    assert space.slack(placed) < 0.0  # the rest pose's solution: its elbow in the post
    contract = Contract(0.00175, 0.025, scene, "m")
    with sim.RobotCell(scene, "m", np.zeros(3), 90.0, PANDA_MODEL) as cell:
        plan = sim.judged_route(cell, contract, start, target, approach_height=0.025, label="T")
    first = plan.joints[0]
    assert np.linalg.norm(arm.tool_pose(first)[0] - start) < 1e-6
    assert space.slack(first) >= 0.0 and np.max(np.abs(first - placed)) > 0.05
    assert np.linalg.norm(plan.points[-1] - target) < 1e-5


def test_a_route_on_the_fr3_is_slowed_to_its_position_based_velocity_limits():
    """The FR3's controller lets a joint move towards its range's end only as fast as it can
    still brake (libfranka's position-based velocity limits): a route timed to the constant
    limits alone, swinging joint 1 from -1.0 to -2.66 rad (0.09 rad from its end), is refused by
    the FCI's judge at 1 kHz; stretched as the route's timing stretches it, it is accepted. The
    Panda has no such limits: its route is not stretched."""
    from bidmp.planning import time_path
    from bidmp.sim import FR3, PANDA
    from bidmp.sim.backend import LIMIT_MARGIN
    from bidmp.sim.fci import judge_commands
    from bidmp.sim.robots import FR3_MODEL
    from bidmp.sim.routes import _fci_stretch

    start, end = np.array(FR3_MODEL.rest), np.array(FR3_MODEL.rest)
    start[0], end[0] = -1.0, -2.66
    timed = time_path(
        np.array([start, end]), FR3.velocity, FR3.acceleration, FR3.jerk, margin=LIMIT_MARGIN
    )

    def commands(duration):
        return timed(np.arange(0.0, duration + 1e-3, 1e-3) / duration)

    assert not judge_commands(commands(timed.duration), "fr3").ok
    stretch = _fci_stretch(FR3, timed)
    assert 1.0 < stretch < 3.0
    assert judge_commands(commands(timed.duration * stretch), "fr3").ok
    assert _fci_stretch(PANDA, timed) == 1.0


def test_the_inverse_kinematics_keeps_inside_the_ranges_when_asked():
    """``inside``: the solutions keep that far inside each joint's range (a route's goal, so that
    the spline timed through it does not overshoot a range held at its end: the Panda's joint 6
    went past 3.7525 rad). A pose the IRB 1200 takes with joint 5 at its end (130 degrees):
    solved there with nothing asked, kept 5 mrad inside (and so missing the pose) when asked."""
    robot = irb_model()
    arm = ArmGeometry(robot, 0.0125, 0.1, np.zeros(3), 0.0)
    q = np.array([0.3, 0.4, -0.2, 0.5, robot.limits.upper[4], 0.2])
    mouth, frame = arm.tool_pose(q)
    turn = Rotation.from_matrix(frame).as_quat()
    seed = q + np.array([0.05, -0.05, 0.05, -0.05, -0.1, 0.05])
    solved, error = arm.solve_ik(mouth, turn, seed)
    assert error < 1e-6 and solved[4] == pytest.approx(robot.limits.upper[4], abs=1e-6)
    inside, missed = arm.solve_ik(mouth, turn, seed, inside=0.005)
    assert np.all(inside <= np.asarray(robot.limits.upper) - 0.005 + 1e-12)
    assert np.all(inside >= np.asarray(robot.limits.lower) + 0.005 - 1e-12)
    assert missed > 1e-5
    with pytest.raises(ValueError, match="inside"):
        arm.solve_ik(mouth, turn, seed, inside=[0.1, -0.1, 0, 0, 0, 0])


def test_a_jobs_route_to_a_nut_ends_where_the_arm_can_go_back_up_the_axis(tmp_path):
    """After the approach a job unscrews the nut and retracts it straight up its axis: the arm's
    route to the nut starts its final approach at least that high (``retract``), so the
    configuration it ends in follows the way back up (the xArm6's route ended in a branch from
    which the unscrew's first millimetres were out of its inverse kinematics' reach). The busbar
    nut behind its post, 60 mm of retract: the route's last 60 mm are straight down the nut's
    axis, and the inverse kinematics follows them back up from the route's last joints (2 mm
    steps from the joints before, within 0.05 mm)."""
    from bidmp.tasks import scenarios

    scenario = scenarios.load(str(busbar(tmp_path)))
    base, yaw = sim.robot_placement(scenario)
    robot = sim.robot_model(scenario.robot, tmp_path)
    target = np.asarray(scenario.targets["B3"], dtype=float)
    axis = scenario.target_axis("B3")
    exclude = scenario.scene.target_parts("B3", target[:3])
    with sim.RobotCell(scenario.scene, "m", base, yaw, robot) as cell:
        routed = sim.arm_route(
            cell,
            np.asarray(cell.rest),
            target[:3],
            axis=axis,
            approach_height=scenario.approach_height,
            orientation=target[3:],
            exclude=exclude,
            label="B3",
            retract=0.06,
        )
    path = routed.plan.points
    along = (path - target[:3]) @ axis
    last = np.flatnonzero(along > 0.06 - 1e-6)[-1]
    offsets = path[last:] - target[:3]
    assert np.linalg.norm(offsets - np.outer(offsets @ axis, axis), axis=1).max() < 1e-4
    arm = ArmGeometry(robot, 0.0125, 0.1, np.asarray(base) * 1.0, yaw)
    q = routed.plan.joints[-1]
    for height in np.arange(0.002, 0.0601, 0.002):
        q, error = arm.solve_ik(target[:3] + axis * height, target[3:], q, iterations=30)
        assert error < 5e-5, height


def test_a_configuration_free_for_the_route_is_free_in_pybullet():
    """The route's model of the links (pinocchio, the meshes' convex hulls) against PyBullet's own
    closest points, the contacts the contract counts: Bullet grows a mesh's hull by its collision
    margin (1 mm), so a link the route kept 0.6 mm clear touched a post (the route oracle's cell 1
    dropped two nuts so, cell 0 had five routes refused by the PyBullet check). The Panda at its
    rest pose turned by its first joint into a tall post, across the first contact in 0.1 mrad
    steps: wherever the route's space calls the arm free (links asked to keep nothing), PyBullet
    finds no contact."""
    from bidmp.scene import Scene
    from bidmp.sim.routes import _arm

    robot = ROBOT_MODELS["panda"]
    scene = Scene.from_dict(
        {
            "tool": {"radius": 0.0125, "length": 0.1},
            "parts": [
                {
                    "type": "cylinder",
                    "label": "post",
                    "at": [0.3 * math.cos(0.6), 0.3 * math.sin(0.6), 0.0],
                    "radius": 0.02,
                    "height": 1.2,
                }
            ],
        }
    )
    rest = np.asarray(robot.rest, dtype=float)
    with sim.RobotCell(scene, "m", [0.0, 0.0, 0.0], 0.0, robot) as cell:
        space = _arm(cell).space(scene, 1.0, exclude=[], margin=0.0, links=0.0)
        (post,) = [body for body, owner in cell._owners.items() if owner == "post"]

        def pybullet(turn: float) -> float:
            q = rest.copy()
            q[0] = turn
            cell._set_joints(q)
            points = cell.p.getClosestPoints(cell.robot, post, 0.05, physicsClientId=cell.client)
            return min((float(point[8]) for point in points), default=0.05)

        clear, touching = 0.0, 0.6
        assert pybullet(clear) > 0.0 and pybullet(touching) < 0.0
        for _ in range(40):  # the first contact, from PyBullet alone
            middle = 0.5 * (clear + touching)
            clear, touching = (middle, touching) if pybullet(middle) > 0.0 else (clear, middle)
        free = 0
        for turn in clear + np.linspace(-0.01, 0.005, 151):
            q = rest.copy()
            q[0] = turn
            if space.slack(q) >= 0.0:
                free += 1
                assert pybullet(turn) >= 0.0, (turn, pybullet(turn), space.nearest(q))
        assert free > 50  # (the sweep reaches well into the free side)
