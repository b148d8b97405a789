"""The arm's own geometry against the cell: every link and the tool as collision shapes at any
joint configuration, and how far they are from the parts — what a route of the arm is planned
against (:mod:`bidmp.sim.routes`).

Built from the same URDF the simulator loads (the scenario's arm with the scenario's tool on its
flange), by pinocchio (the arm's kinematics, its links placed in microseconds) and coal (the same
distance library the motion contract's clearance uses). A link's mesh is taken as its convex hull,
as PyBullet takes it for contacts, and kept the further 1 mm Bullet grows a hull by (its collision
margin), so a configuration free here is free there too. The parts are
the scene's solids, in metres, in the arm's base frame.

Why not PyBullet's own closest points: setting the arm's joints and asking each part costs half
a millisecond a configuration there, and a planner tests thousands; here a configuration costs
tens of microseconds.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import (
    as_labels,
    as_point,
    check_bool,
    check_int,
    check_real,
    checks_input,
    require_extra,
)

__all__ = ["ArmGeometry", "ArmSpace"]


def _pinocchio():
    return require_extra("pinocchio", "plan", "the arm's routes (bidmp.sim.routes)")


class ArmGeometry:
    """An arm (a :class:`~bidmp.sim.robots.RobotModel`) with a cylindrical tool, standing at
    ``base`` (m) turned ``yaw`` degrees about z: its links' and tool's collision shapes.

    Parameters
    ----------
    robot : bidmp.sim.RobotModel
    tool_radius, tool_length : float
        The tool's cylinder (m), hanging from the flange along its z axis.
    base : array (3,)
        The arm's base in the world (m).
    yaw : float
        Degrees about z.
    """

    def __init__(self, robot, tool_radius: float, tool_length: float, base, yaw: float):
        from .robots import RobotModel

        if not isinstance(robot, RobotModel):
            raise TypeError(f"robot must be a bidmp.sim.RobotModel, got {type(robot).__name__}")
        # (coal's shapes of a few femtometres crash it: a tool is at least a micrometre, or none)
        tool_radius = check_real(tool_radius, "tool_radius", minimum=1e-6, maximum=10.0)
        tool_length = check_real(tool_length, "tool_length", nonnegative=True, maximum=10.0)
        if 0.0 < tool_length < 1e-6:
            raise ValueError(f"tool_length must be 0 or at least 1e-06 m, got {tool_length:g}")
        base = as_point(base, 3, "base")
        yaw = check_real(yaw, "yaw")
        pin = _pinocchio()
        import coal

        from .pybullet.world import _tool_urdf

        text = _tool_urdf(robot, tool_radius, tool_length)
        self.model = pin.buildModelFromXML(text)
        if self.model.nq != robot.n_joints or self.model.nv != robot.n_joints:
            raise ValueError(
                f"robot {robot.name!r}: its URDF's joints ({self.model.nq} coordinates) are not "
                f"{robot.n_joints} revolute or prismatic joints: no route of its own"
            )
        self.geometry = pin.buildGeomFromUrdfString(self.model, text, pin.GeometryType.COLLISION)
        self.hulls = set()  # the links' meshes, taken as their hulls (grown by Bullet's margin)
        for item in self.geometry.geometryObjects:
            if isinstance(item.geometry, coal.BVHModelBase):  # PyBullet contacts a mesh's hull
                item.geometry.buildConvexHull(True, "Qt")
                item.geometry = item.geometry.convex
                self.hulls.add(item.name)
        self.data = self.model.createData()
        self.tcp = self.model.getFrameId("tcp")
        turn = math.radians(float(yaw))
        self.rotation = np.array(
            [
                [math.cos(turn), -math.sin(turn), 0.0],
                [math.sin(turn), math.cos(turn), 0.0],
                [0, 0, 1],
            ]
        )
        self.base = np.asarray(base, dtype=float)
        self.limits = robot.limits
        self.reach = self._reach()
        self.tool_reach = self._tool_reach()

    def _reach(self) -> np.ndarray:
        """For each joint, the farthest any point of the bodies it moves lies from its origin
        (m): bounded by the chain of joint origins out to each shape plus the shape's own extent.
        A joint turned by dq moves no point more than that times dq (the sweep's bound)."""
        pin = _pinocchio()
        model, data = self.model, self.data
        pin.forwardKinematics(model, data, pin.neutral(model))
        origins = [data.oMi[j].translation.copy() for j in range(model.njoints)]
        parents = list(model.parents)
        # each shape: its joint, the farthest its points lie from that joint's origin
        extents = []
        for item in self.geometry.geometryObjects:
            shape = item.geometry
            shape.computeLocalAABB()
            box = shape.aabb_local
            corner = np.maximum(np.abs(box.min_), np.abs(box.max_))
            extents.append(
                (
                    item.parentJoint,
                    float(np.linalg.norm(item.placement.translation))
                    + float(np.linalg.norm(corner)),
                )
            )
        reach = np.zeros(model.njoints - 1)
        for joint in range(1, model.njoints):
            farthest = 0.0
            for owner, extent in extents:
                chain, at = 0.0, owner
                while at > joint:  # the lengths of the chain from this joint out to the shape's
                    chain += float(np.linalg.norm(origins[at] - origins[parents[at]]))
                    at = parents[at]
                if at == joint:
                    farthest = max(farthest, chain + extent)
            reach[joint - 1] = farthest
        return reach

    def _tool_reach(self) -> float:
        """The farthest the tool's mouth can be from the first joint's origin (m): the lengths of
        the chain of joint origins out to it, end to end."""
        pin = _pinocchio()
        model, data = self.model, self.data
        pin.framesForwardKinematics(model, data, pin.neutral(model))
        frame = model.frames[self.tcp]
        # where the first joint turns, in the world (it does not move with its own turn)
        self.first_joint = self.rotation @ data.oMi[1].translation + self.base
        points = [data.oMf[self.tcp].translation]
        joint = frame.parentJoint
        while joint > 0:
            points.append(data.oMi[joint].translation)
            joint = model.parents[joint]
        return float(np.sum(np.linalg.norm(np.diff(np.array(points), axis=0), axis=1)))

    def tool_pose(self, q) -> tuple[np.ndarray, np.ndarray]:
        """The tool's mouth (m) and frame (3, 3) in the world at joints ``q`` (J,) rad."""
        pin = _pinocchio()
        q = as_point(q, self.model.nq, "q", like="the arm's joints")
        pin.framesForwardKinematics(self.model, self.data, q)
        frame = self.data.oMf[self.tcp]
        return (
            self.rotation @ frame.translation + self.base,
            self.rotation @ frame.rotation,
        )

    def solve_ik(
        self,
        point,
        frame,
        seed,
        *,
        free_turn: bool = True,
        iterations: int = 200,
        inside: float = 0.0,
    ) -> tuple[np.ndarray, float]:
        """Joints within the limits that put the tool's mouth at ``point`` (m, world) with its
        frame ``frame`` (a quaternion x, y, z, w; its z axis the approach direction), from joints
        ``seed``, and the position error left (m).

        Damped least squares on the position and the tool's axis, the turn about the axis left
        free where ``free_turn`` (a socket: the task's free axis stays free), the joints clamped
        to their limits at every step and drawn toward their ranges' middle in the task's null
        space. The damping grows near a singularity (a wrist with joints 4 and 6 aligned) instead
        of stepping across it: from another seed the other branch is found. Stops where the
        mouth is within 0.1 µm and the axis within 0.1 µrad, or after ``iterations``.
        ``inside``: radians kept inside each joint's range (one for all, or one per joint; at most
        a tenth of the range): a spline timed through such solutions does not overshoot the range
        where a joint is at its end.
        """
        from ..primitives.so3 import as_quaternions

        pin = _pinocchio()
        model, data = self.model, self.data
        point = as_point(point, 3, "point")
        frame = as_quaternions(frame, "frame")
        if frame.shape[0] != 1:
            raise ValueError(f"frame must be one quaternion (4,), got {frame.shape[0]}")
        q = as_point(seed, model.nq, "seed", like="the arm's joints")
        free_turn = check_bool(free_turn, "free_turn")
        iterations = check_int(iterations, "iterations", minimum=1, maximum=10_000)
        lower, upper = np.asarray(self.limits.lower), np.asarray(self.limits.upper)
        if np.ndim(inside) == 0:
            inside = np.full(q.size, check_real(inside, "inside", nonnegative=True))
        else:
            inside = as_point(inside, model.nq, "inside", like="the arm's joints")
            if np.any(inside < 0.0):
                raise ValueError("inside must be 0 or more radians for every joint")
        inside = np.minimum(inside, 0.1 * (upper - lower))
        lower, upper = lower + inside, upper - inside
        middle, span = 0.5 * (lower + upper), upper - lower
        inverse = self.rotation.T
        target = inverse @ (point - self.base)
        from scipy.spatial.transform import Rotation

        wanted = inverse @ Rotation.from_quat(frame[0]).as_matrix()
        q = np.clip(q, lower, upper)
        error = math.inf
        for _ in range(iterations):
            pin.framesForwardKinematics(model, data, q)
            placed = data.oMf[self.tcp]
            position, rotation = placed.translation, placed.rotation
            e_position = target - position
            if free_turn:  # the turn about the tool's axis is not asked for: two rows across it
                across = rotation[:, :2].T
                e_turn = across @ np.cross(rotation[:, 2], wanted[:, 2])
            else:
                across = np.eye(3)
                e_turn = pin.log3(wanted @ rotation.T)
            error = float(np.linalg.norm(e_position))
            if error < 1e-7 and np.linalg.norm(e_turn) < 1e-7:
                break
            jacobian = pin.computeFrameJacobian(
                model, data, q, self.tcp, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED
            )
            task = np.vstack([jacobian[:3], across @ jacobian[3:]])
            residual = np.concatenate([e_position, e_turn])
            rows = residual.size
            # Levenberg-Marquardt's damping by the squared error (Sugihara 2011): steady far from
            # the solution and near a singularity, undamped (quadratic) as the error vanishes
            damping = float(residual @ residual) + 1e-10
            inverse_task = task.T @ np.linalg.inv(task @ task.T + damping * np.eye(rows))
            step = inverse_task @ residual
            # the joints drawn toward their middles where the task does not mind, while far off
            # (the pull, not quite in the damped task's null space, would hold the last 0.01 mm)
            pull = min(1.0, error / 1e-3) * 0.05 * (middle - q) / span**2
            step += (np.eye(q.size) - inverse_task @ task) @ pull
            largest = float(np.max(np.abs(step)))
            if largest > 0.3:  # a long step overshoots: at most 0.3 rad a joint
                step *= 0.3 / largest
            q = np.clip(q + step, lower, upper)
        pin.framesForwardKinematics(model, data, q)
        error = float(np.linalg.norm(target - data.oMf[self.tcp].translation))
        return q, error

    def space(
        self,
        scene,
        unit: float,
        *,
        exclude=(),
        margin: float,
        carried=None,
        links: float | None = None,
    ) -> ArmSpace:
        """The arm's configurations in ``scene`` (its parts in scene units, ``unit`` metres each)
        as a :class:`~bidmp.planning.FreeSpace`: the tool kept ``margin`` (m) from every part but
        those in ``exclude``, a part's stand-off from it (the scene's, in metres), and the links
        ``links`` (m; default the margin: the contract asks the tool for its margin and the links
        only not to touch); ``carried``: a part the tool holds, ``(its solid where it is now, the
        joints now)``, kept clear as the tool is (it moves with the tool)."""
        from ..scene import Scene

        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a bidmp.Scene, got {type(scene).__name__}")
        unit = check_real(unit, "unit", positive=True)
        if unit not in (1.0, 1e-2, 1e-3):
            raise ValueError(
                f"unit must be metres per scene unit: 1 (m), 0.01 (cm) or 0.001 (mm), got {unit:g}"
            )
        exclude = as_labels(exclude, "exclude")
        unknown = [label for label in exclude if label not in scene.labels]
        if unknown:
            raise ValueError(f"exclude names {unknown[0][:30]!r}, which is not a part of the scene")
        if carried is not None:
            from ..scene import Solid

            if not (
                isinstance(carried, (tuple, list))
                and len(carried) == 2
                and isinstance(carried[0], Solid)
            ):
                raise TypeError(
                    "carried must be (a scene Solid where it is now, the joints now) or None"
                )
            carried = (carried[0], as_point(carried[1], self.model.nq, "carried's joints"))
        margin = check_real(margin, "margin", nonnegative=True)
        links = margin if links is None else check_real(links, "links", nonnegative=True)
        return ArmSpace(self, scene, unit, exclude, (margin, links), carried)


@dataclass
class _Pair:
    arm: int  # index of the arm's shape
    part: int  # index of the part's shape
    required: float  # m: the clearance this pair keeps


class ArmSpace:
    """The arm's joint configurations as a :class:`~bidmp.planning.FreeSpace` (built by
    :meth:`ArmGeometry.space`): the slack is the nearest approach of any link or the tool to any
    part beyond its clearance (m), the sweep bounds how far any point of the arm moves."""

    def __init__(self, arm: ArmGeometry, scene, unit: float, exclude: list, margins, carried=None):
        from .pybullet.world import HULL_MARGIN

        pin = _pinocchio()
        self.arm = arm
        margin, links = margins
        # The least step along a segment; asked to keep the margin plus this, the arm keeps the
        # margin between two tests (as the tool's route).
        self.tolerance = max(0.1 * min(margin, links), 1e-4)
        self.lower = np.asarray(arm.limits.lower, dtype=float)
        self.upper = np.asarray(arm.limits.upper, dtype=float)
        geometry = pin.GeometryModel()
        arm_shapes, tools, grown = [], set(), set()
        for item in arm.geometry.geometryObjects:
            if item.parentJoint == 0:
                continue  # the base link never moves: it is not tested against the parts
            index = geometry.addGeometryObject(item.copy())
            arm_shapes.append(index)
            if arm.model.frames[item.parentFrame].name == "tool":  # (the tool's link: _tool_urdf)
                tools.add(index)
            if item.name in arm.hulls:
                grown.add(index)
        held = None
        if carried is not None:
            held = geometry.addGeometryObject(_carried_object(pin, arm, carried, unit))
            arm_shapes.append(held)
            tools.add(held)
        inverse = arm.rotation.T
        pairs = []
        for solid in scene.solids:
            if solid.part in exclude:
                continue
            shape = _shape(solid, unit)
            placement = pin.SE3(
                inverse @ np.asarray(solid.rotation, dtype=float),
                inverse @ (np.asarray(solid.centre, dtype=float) * unit - arm.base),
            )
            part = geometry.addGeometryObject(
                pin.GeometryObject(f"part:{solid.label}", 0, placement, shape)
            )
            stand = scene.standoff.get(solid.part)
            required = margin if stand is None else min(stand * unit, margin)
            for shape_index in arm_shapes:
                # a stand-off lets the tool near the part it works on; a part the tool carries
                # keeps the margin from every part, as the motion contract's clearance asks; the
                # links only the links' allowance (the contract asks them not to touch)
                if shape_index == held:
                    keep = margin
                elif shape_index in tools:
                    keep = required
                else:
                    keep = min(links, required)
                # Bullet grows a mesh's hull by its collision margin (1 mm) where it contacts the
                # parts: a link 0.6 mm clear here touched a post there (the route oracle's cells)
                grow = HULL_MARGIN if shape_index in grown else 0.0
                pairs.append(_Pair(shape_index, part, keep + self.tolerance + grow))
        for pair in pairs:
            geometry.addCollisionPair(pin.CollisionPair(pair.arm, pair.part))
        self.geometry, self.data = geometry, pin.GeometryData(geometry)
        self.required = np.array([pair.required for pair in pairs])
        self.names = [geometry.geometryObjects[pair.part].name[5:] for pair in pairs]
        self.model, self.model_data = arm.model, arm.model.createData()
        self._pin = pin
        # Bounding spheres (centre in the shape's frame, radius): a pair whose spheres lie far
        # apart is bounded from below without coal.
        spheres = [_sphere(item.geometry) for item in geometry.geometryObjects]
        self._centres = np.array([centre for centre, _ in spheres]).reshape(-1, 3)
        self._radii = np.array([radius for _, radius in spheres])
        self._arm_index = np.array([pair.arm for pair in pairs], dtype=int)
        self._part_index = np.array([pair.part for pair in pairs], dtype=int)
        self._moving = np.array(sorted(set(arm_shapes)), dtype=int)
        # the parts' spheres stay where they are: their centres once (in the base frame)
        self._placed = np.zeros_like(self._centres)
        for index, item in enumerate(geometry.geometryObjects):
            if index not in set(arm_shapes):
                self._placed[index] = item.placement.rotation @ self._centres[index] + (
                    item.placement.translation
                )

    def _bounds(self, q: np.ndarray) -> np.ndarray:
        """Every pair's distance bounded from below by its bounding spheres (m), the shapes
        placed at ``q``."""
        pin = self._pin
        pin.updateGeometryPlacements(self.model, self.model_data, self.geometry, self.data, q)
        placements, centres = self.data.oMg, self._placed
        for i in self._moving:
            placement = placements[int(i)]
            centres[i] = placement.rotation @ self._centres[i] + placement.translation
        gap = np.linalg.norm(centres[self._arm_index] - centres[self._part_index], axis=1)
        return gap - self._radii[self._arm_index] - self._radii[self._part_index]

    def _distances(self, q: np.ndarray, far: float) -> np.ndarray:
        """Every pair's distance (m): coal's where the spheres' bound is within ``far`` of the
        pair's clearance, the bound elsewhere (a lower bound is all the slack needs)."""
        distances = self._bounds(q)
        near = np.flatnonzero(distances - self.required < far)
        compute = self._pin.computeDistance
        for index in near:
            distances[index] = compute(self.geometry, self.data, int(index)).min_distance
        return distances

    def slack(self, q: np.ndarray, check_input: bool = True) -> float:
        """How far the arm at joints ``q`` (J,) rad is from any part's clearance (m; a lower
        bound; negative: inside it). ``check_input=False``: ``q`` taken as given (a planner's)."""
        if checks_input(check_input):
            q = as_point(q, self.model.nq, "q", like="the arm's joints")
        if self.required.size == 0:
            return math.inf
        return float(np.min(self._distances(np.asarray(q, dtype=float), 0.02) - self.required))

    def nearest(self, q: np.ndarray) -> tuple[str, float]:
        """The part the arm at ``q`` comes nearest its clearance of, and by how much it keeps it
        (m; negative: inside it)."""
        q = as_point(q, self.model.nq, "q", like="the arm's joints")
        if self.required.size == 0:
            return "", math.inf
        distances = self._distances(q, math.inf)
        index = int(np.argmin(distances - self.required))
        return self.names[index], float(distances[index] - self.required[index] + self.tolerance)

    def sweep(self, a: np.ndarray, b: np.ndarray, check_input: bool = True) -> float:
        """How far any point of the arm may move when its joints go straight from ``a`` to ``b``
        (m): each joint's turn times the farthest any point it moves lies from it."""
        if checks_input(check_input):
            a = as_point(a, self.model.nq, "a", like="the arm's joints")
            b = as_point(b, self.model.nq, "b", like="the arm's joints")
        return float(np.sum(np.abs(np.asarray(b) - np.asarray(a)) * self.arm.reach))


def _sphere(shape) -> tuple[np.ndarray, float]:
    """A sphere round a coal shape in its own frame: its box's centre and half-diagonal."""
    shape.computeLocalAABB()
    box = shape.aabb_local
    low, high = np.asarray(box.min_, dtype=float), np.asarray(box.max_, dtype=float)
    return 0.5 * (low + high), float(np.linalg.norm(0.5 * (high - low)))


def _shape(solid, unit: float):
    """A scene solid as a coal shape in metres."""
    import coal

    if solid.kind == "box":
        return coal.Box(*(np.asarray(solid.params, dtype=float) * unit))
    if solid.kind == "cylinder":
        radius, height = solid.params
        return coal.Cylinder(float(radius) * unit, float(height) * unit)
    vertices = np.asarray(solid.params[0], dtype=float) * unit
    points = coal.StdVec_Vec3s()
    for vertex in vertices:
        points.append(vertex)
    return coal.ConvexBase.convexHull(points, False, "")


def _carried_object(pin, arm: ArmGeometry, carried, unit: float):
    """A carried part as a shape fixed to the tool's frame (it moves with the tool): ``carried`` =
    (its solid where it is now, scene units; the joints now)."""
    solid, q = carried
    pin.framesForwardKinematics(arm.model, arm.data, np.asarray(q, dtype=float))
    inverse = arm.rotation.T
    where = pin.SE3(
        inverse @ np.asarray(solid.rotation, dtype=float),
        inverse @ (np.asarray(solid.centre, dtype=float) * unit - arm.base),
    )
    frame = arm.model.frames[arm.tcp]
    relative = arm.data.oMf[arm.tcp].inverse() * where
    return pin.GeometryObject(
        "carried", frame.parentJoint, frame.placement * relative, _shape(solid, unit)
    )
