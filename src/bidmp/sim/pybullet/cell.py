"""The PyBullet Panda cell: the world's state and the backend protocol's methods."""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np

from ..._checks import as_labels, as_point, check_real
from ..backend import SIM_STEP, Execution, Hold, MotionPlan
from ..robots import GAIN, MAX_SAMPLE_SPACING, PANDA_MODEL, RobotModel, _unit_of
from . import execute as _execute
from . import ik as _ik
from . import render as _render
from .world import SOLVER_ITERATIONS, _add_solid, _kinematic_urdf, _pybullet_module, _tool_urdf

__all__ = ["RobotCell"]


class RobotCell:
    """A headless PyBullet world with a scene's parts and a serial arm of six or more joints (the
    Panda unless ``robot`` names another) carrying the scene's tool: the PyBullet
    implementation of :class:`bidmp.sim.backend.SimulatorBackend`. It holds the world's
    state; planning, execution and pictures are the functions of this subpackage's modules.

    Parameters
    ----------
    scene : bidmp.Scene
    units : str
        The scene's length unit ("mm", "cm" or "m").
    base : array (3,)
        Robot base position in the scene's unit.
    yaw : float
        Robot base rotation about z in degrees (90: the robot faces +y).
    robot : RobotModel, optional
        The arm (:data:`bidmp.sim.robots.ROBOT_MODELS`, or a scenario's own URDF).
    """

    def __init__(
        self,
        scene,
        units: str = "mm",
        base=(0.0, -450.0, 0.0),
        yaw: float = 90.0,
        robot: RobotModel = PANDA_MODEL,
    ):
        from ...scene import Scene

        if not isinstance(robot, RobotModel):
            raise TypeError(
                f"robot must be a bidmp.sim.robots.RobotModel, got {type(robot).__name__}"
            )
        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a bidmp.Scene, got {type(scene).__name__}")
        base, yaw = as_point(base, 3, "base"), check_real(yaw, "yaw")
        self.model = robot
        self.limits = robot.limits
        self.scene = scene
        self.unit = _unit_of(units)
        self.p = p = _pybullet_module()
        self.client = p.connect(p.DIRECT)
        try:
            p.setTimeStep(SIM_STEP, physicsClientId=self.client)
            # 20 solver iterations instead of 50: the same tracking here (< 0.3 mm), 20 % less time.
            p.setPhysicsEngineParameter(
                numSolverIterations=SOLVER_ITERATIONS, physicsClientId=self.client
            )
            p.setGravity(0.0, 0.0, -9.81, physicsClientId=self.client)
            self._bodies = {}  # body id -> solid label
            self._owners = {}  # body id -> part label
            for solid in scene.solids:
                body = _add_solid(p, self.client, self.unit, solid)
                self._bodies[body] = solid.label
                self._owners[body] = solid.part
            # A second world holds a copy of the arm alone for inverse and forward kinematics, so
            # that planning never resets the simulated robot's state.
            self.ik_client = p.connect(p.DIRECT)
            with tempfile.TemporaryDirectory() as folder:
                path = Path(folder) / "robot_tool.urdf"
                text = _tool_urdf(
                    robot, scene.tool.radius * self.unit, scene.tool.length * self.unit
                )
                path.write_text(text)
                kinematics = Path(folder) / "robot_kinematics.urdf"
                kinematics.write_text(_kinematic_urdf(text))
                base_m = np.asarray(base, dtype=float) * self.unit
                orientation = p.getQuaternionFromEuler([0, 0, math.radians(yaw)])
                self.robot = p.loadURDF(
                    str(path),
                    base_m.tolist(),
                    orientation,
                    useFixedBase=True,
                    physicsClientId=self.client,
                )
                self.ik_robot = p.loadURDF(
                    str(kinematics),
                    base_m.tolist(),
                    orientation,
                    useFixedBase=True,
                    physicsClientId=self.ik_client,
                )
            names = [
                p.getJointInfo(self.robot, j, physicsClientId=self.client)[12].decode()
                for j in range(p.getNumJoints(self.robot, physicsClientId=self.client))
            ]
            self.tcp = names.index("tcp")
            movable = [
                j
                for j in range(len(names))
                if p.getJointInfo(self.robot, j, physicsClientId=self.client)[2] != p.JOINT_FIXED
            ]
            if len(movable) < 6 or len(movable) != robot.n_joints:
                what = (
                    "serial arms of six or more joints"
                    if len(movable) < 6
                    else f"its {robot.n_joints} limits"
                )
                raise ValueError(
                    f"robot {robot.name!r} has {len(movable)} movable joints up to its flange "
                    f"{robot.flange!r}; the simulator drives {what}"
                )
            self.arm = movable
            self.gains = [GAIN] * len(movable)
            # A tool symmetric about its axis leaves the turn about that axis free; it is the last
            # joint's when that joint turns about the tool's axis (the Panda, the iiwa, the xArm6, the
            # UR5): the IK then parks it and solves the others for the position and the axis.
            self.wrist_turns_tool = self._last_joint_turns_tool()
            # False while the tool's turn matters (a gripper's part turns with it): set per world
            # by the simulator and the job (bidmp.sim.run._turn_is_free)
            self.free_turn = True
            self.base = np.asarray(base, dtype=float)
            self.yaw = float(yaw)
            self._set_joints(robot.rest)
        except BaseException:
            self.close()
            raise

    # the robot's joint limits (the backend protocol's; set per instance)
    limits = PANDA_MODEL.limits
    simulator = "PyBullet, 1 kHz position control"  # how reports name this backend

    @property
    def n_joints(self) -> int:
        return len(self.arm)

    @property
    def name(self) -> str:
        """The arm's name (its model's)."""
        return self.model.name

    @property
    def joint_names(self) -> tuple:
        """The driven joints' names, base to flange, as in the arm's URDF."""
        p = self.p
        return tuple(
            p.getJointInfo(self.robot, j, physicsClientId=self.client)[1].decode() for j in self.arm
        )

    @property
    def joint_units(self) -> tuple:
        """Each driven joint's unit: "m" for a prismatic joint, "rad" for a revolute one."""
        p = self.p
        return tuple(
            "m"
            if p.getJointInfo(self.robot, j, physicsClientId=self.client)[2] == p.JOINT_PRISMATIC
            else "rad"
            for j in self.arm
        )

    @property
    def rest(self) -> tuple:
        """The joints (rad) the arm starts from: the tool pointing down."""
        return self.model.rest

    def use_rest(self, q) -> None:
        """Make joints ``q`` (J,) rad, within the arm's limits, its rest pose: the model's rest from
        now on (where a run starts), the arm put there, and whether its last joint turns the tool
        judged again there. For an arm given without one (a URDF's), once a working pose is
        found."""
        import dataclasses

        q = self._joints(q)
        lower, upper = np.asarray(self.limits.lower), np.asarray(self.limits.upper)
        if np.any(q < lower) or np.any(q > upper):
            joint = int(np.flatnonzero((q < lower) | (q > upper))[0])
            raise ValueError(
                f"q: joint {joint + 1} at {q[joint]:.4g} rad is outside its limits "
                f"[{lower[joint]:.4g}, {upper[joint]:.4g}]"
            )
        self.model = dataclasses.replace(self.model, rest=tuple(q.tolist()), rest_given=True)
        self._set_joints(self.model.rest)
        self.wrist_turns_tool = self._last_joint_turns_tool()

    def _last_joint_turns_tool(self) -> bool:
        """Whether the last joint turns about the tool's axis through its mouth (at the rest pose)."""
        p, robot, client = self.p, self.ik_robot, self.ik_client
        self._set_joints(self.model.rest, kinematic=True)
        last = p.getJointInfo(robot, self.arm[-1], physicsClientId=client)
        frame = p.getLinkState(
            robot, self.arm[-1], computeForwardKinematics=1, physicsClientId=client
        )
        tcp = p.getLinkState(robot, self.tcp, computeForwardKinematics=1, physicsClientId=client)
        axis = np.array(p.getMatrixFromQuaternion(frame[5])).reshape(3, 3) @ np.asarray(last[13])
        tool = np.array(p.getMatrixFromQuaternion(tcp[5])).reshape(3, 3)[:, 2]
        offset = np.asarray(tcp[4]) - np.asarray(frame[4])
        across = offset - (offset @ tool) * tool
        return bool(abs(abs(axis @ tool) - 1.0) < 1e-6 and np.linalg.norm(across) < 1e-6)

    @classmethod
    def load_robot(
        cls,
        scene,
        units: str = "mm",
        base=(0.0, -450.0, 0.0),
        yaw: float = 90.0,
        robot: RobotModel = PANDA_MODEL,
    ) -> RobotCell:
        """The backend protocol's constructor (the same as ``RobotCell(...)``)."""
        return cls(scene, units, base, yaw, robot)

    def close(self) -> None:
        for name in ("client", "ik_client"):
            client = getattr(self, name, None)
            if client is not None:
                self.p.disconnect(client)
                setattr(self, name, None)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _joints(self, q) -> np.ndarray:
        """Joint positions (J,) rad, checked: one per joint of the arm, finite."""
        return as_point(q, len(self.arm), "q")

    def _set_joints(self, q, velocities=None, kinematic: bool = False) -> None:
        robot, client = (self.ik_robot, self.ik_client) if kinematic else (self.robot, self.client)
        reset = self.p.resetJointState
        rates = [0.0] * len(self.arm) if velocities is None else np.asarray(velocities).tolist()
        for joint, angle, rate in zip(self.arm, np.asarray(q).tolist(), rates):
            reset(robot, joint, angle, rate, physicsClientId=client)

    def tcp_position(self) -> np.ndarray:
        """The simulated robot's measured TCP position (m)."""
        return np.array(
            self.p.getLinkState(
                self.robot, self.tcp, computeForwardKinematics=1, physicsClientId=self.client
            )[4]
        )

    def tool_orientation(self) -> np.ndarray:
        """The simulated robot's measured tool frame (quaternion x, y, z, w)."""
        return np.array(
            self.p.getLinkState(
                self.robot, self.tcp, computeForwardKinematics=1, physicsClientId=self.client
            )[5]
        )

    # -- what the job does in the world ------------------------------------------------------
    def add_solids(self, solids) -> None:
        """Static bodies for more parts (the job's bin, its rack), their contacts reported by label."""
        from .parts import _add_job_solids

        _add_job_solids(self, solids)

    def arm_touch(self, plan, exclude=()) -> tuple[str, float] | None:
        """Whether the arm, run along ``plan``, would touch a part other than ``exclude``'s (the
        target's own, a part it carries): the planned joints set on the arm at its IK samples,
        PyBullet's closest points of every link (the tool's too)
        against every other part's body. Returns ``(part, depth in scene units)`` of the deepest
        touch, or None. The contract judges the tool's path; this catches a wrist or an elbow
        running into a duct the tool passes clear of, before any command is sent. The arm is
        put back where it was (an execution starts from the plan's first joints anyway)."""
        if not all(hasattr(plan, name) for name in ("fractions", "spline")):
            raise TypeError(
                f"plan must be a bidmp.sim.MotionPlan (RobotCell.plan), got {type(plan).__name__}"
            )
        p, client = self.p, self.client
        exclude = set(as_labels(exclude, "exclude"))
        bodies = [body for body, owner in self._owners.items() if owner not in exclude]
        if not bodies:
            return None
        now = [p.getJointState(self.robot, joint, physicsClientId=client)[:2] for joint in self.arm]
        # the IK samples: the tool moves at most 5 mm between them, the links comparably
        grid = np.asarray(plan.fractions, dtype=float)
        deepest = None
        try:
            for q in plan.spline(grid):
                self._set_joints(q)
                for body in bodies:
                    for point in p.getClosestPoints(self.robot, body, 0.0, physicsClientId=client):
                        depth = -float(point[8])
                        if depth > 1e-4 and (deepest is None or depth > deepest[1]):
                            deepest = (self._owners[body], depth)
        finally:
            self._set_joints([a for a, _ in now], [v for _, v in now])
        return None if deepest is None else (deepest[0], deepest[1] / self.unit)

    def movable_part(self, label: str, mass: float):
        """The scene's part ``label`` as one the job moves (a nut on its thread, a held part, a
        released one that falls): :class:`bidmp.sim.pybullet.parts._MovablePart`."""
        from .parts import _MovablePart

        return _MovablePart(self, label, mass)

    def settle(self, seconds: float) -> None:
        """Let the world run ``seconds`` with the arm holding where it is (a released part falls)."""
        from .parts import _settle

        _settle(self, check_real(seconds, "seconds", nonnegative=True, maximum=60.0))

    def forward(self, q) -> np.ndarray:
        """TCP position (m) for joint positions ``q`` (forward kinematics on the planning copy)."""
        return self._tcp_at(self._joints(q))

    def _tcp_at(self, q: np.ndarray) -> np.ndarray:
        """:meth:`forward` of checked joints ``q`` (J,): the planning copy is left at ``q``."""
        self._set_joints(q, kinematic=True)
        return np.array(
            self.p.getLinkState(
                self.ik_robot, self.tcp, computeForwardKinematics=1, physicsClientId=self.ik_client
            )[4]
        )

    def joint_origins(self, q) -> np.ndarray:
        """The arm's joint origins from its base to the tool's mouth (m), (9, 3), at joints ``q``
        (on the planning copy): what the 3-D viewer draws."""
        self._set_joints(self._joints(q), kinematic=True)
        states = self.p.getLinkStates(
            self.ik_robot,
            [*self.arm, self.tcp],
            computeForwardKinematics=1,
            physicsClientId=self.ik_client,
        )
        # The base's URDF frame, where it was placed (PyBullet's base position is its centre of mass).
        return np.array([self.base * self.unit] + [state[4] for state in states])

    def fk(self, q) -> np.ndarray:
        """The backend protocol's forward kinematics: :meth:`forward`."""
        return self.forward(q)

    def solve_ik(self, point_m: np.ndarray, seed, orientation=None) -> tuple[np.ndarray, float]:
        """Joint positions that put the TCP at ``point_m`` (m) with the tool's frame at
        ``orientation`` (quaternion x, y, z, w; default pointing down), started from ``seed``;
        and the position error left (m). See :func:`bidmp.sim.pybullet.ik.solve_ik`."""
        return _ik._solve_ik(self, point_m, seed, orientation)

    ik = solve_ik  # the backend protocol's name

    def plan(
        self,
        path,
        label: str = "",
        fractions=None,
        seed=None,
        orientations=None,
        spacing: float = MAX_SAMPLE_SPACING,
    ) -> MotionPlan:
        """Inverse kinematics along ``path`` (n, 3, scene units), IK samples at most ``spacing`` (m)
        apart where it moves fastest, and the fastest uniform timing within the limits
        (:func:`bidmp.sim.planning.plan_path`)."""
        from ..planning import plan_path

        return plan_path(self, path, label, fractions, seed, orientations, spacing)

    def execute(
        self,
        plan: MotionPlan,
        exclude=(),
        hold: Hold | None = None,
        frames: int = 0,
        on_record=None,
    ) -> Execution:
        """Run ``plan`` under position control at 1 kHz (:func:`bidmp.sim.pybullet.execute.execute`);
        ``on_record(t)`` after every recorded step."""
        return _execute._execute(self, plan, exclude, hold, frames, on_record)

    def execute_closed_loop(
        self,
        stepper,
        duration: float,
        exclude=(),
        hold: Hold | None = None,
        frames: int = 0,
        max_factor: float = 4.0,
        goal_update=None,
    ) -> Execution:
        """Run a DMP/Bi-DMP ``stepper`` on the measured TCP at 100 Hz, with an optional perception
        update (:func:`bidmp.sim.pybullet.execute.execute_closed_loop`)."""
        return _execute._execute_closed_loop(
            self, stepper, (duration, max_factor), exclude, hold, frames, goal_update
        )

    def contacts(self) -> dict:
        """Part label -> penetration depth (m) of the robot's contacts now."""
        found = {}
        _execute._contacts_into(self, found)
        return found

    def render(self, width: int = 320, height: int = 240, target=None) -> np.ndarray:
        """An RGB image (height, width, 3) of the cell (:func:`bidmp.sim.pybullet.render.render`)."""
        return _render._render(self, width, height, target)

    def keyframe(self, t: float, focus, width: int = 320, height: int = 240) -> np.ndarray:
        """A labelled keyframe (2 height, width, 3): the whole arm above, a close-up on the tool
        and ``focus`` (scene units) below, the time ``t`` (s) written in."""
        return _render._keyframe(self, t, focus, width, height)

    def scene_centre(self) -> np.ndarray:
        return _render._scene_centre(self)
