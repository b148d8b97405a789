"""The MuJoCo cell: the world's state and the backend protocol's methods."""

from __future__ import annotations

import math
import tempfile
from pathlib import Path

import numpy as np

from ..._checks import as_labels, as_point, check_real
from ..backend import SIM_STEP, Execution, Hold, MotionPlan
from ..pybullet.cell import RobotCell
from ..pybullet.world import _kinematic_urdf, _pybullet_module, _tool_urdf
from ..robots import GAIN, PANDA_MODEL, RobotModel, _unit_of
from . import execute as _execute
from .world import ARM_GROUP, FALL_SUBSTEPS, _add_part_body, _arm_spec, _mujoco_module

__all__ = ["MujocoCell"]


class MujocoCell(RobotCell):
    """A MuJoCo world with a scene's parts and a serial arm of six or more joints (the Panda
    unless ``robot`` names another) carrying the scene's tool: the MuJoCo implementation of
    :class:`bidmp.sim.backend.SimulatorBackend`, built from the same URDF as the PyBullet arm
    (:func:`bidmp.sim.pybullet.world._tool_urdf`).

    The physics — the arm's dynamics under its 1 kHz joint position and velocity control, its
    contacts, the parts the job moves — is MuJoCo's. Planning (inverse and forward kinematics of
    the plans, :meth:`plan`) is the PyBullet arm's, on its kinematic copy of the same URDF: both
    engines are sent the same commands. The control is the PyBullet motors' law, every joint, every
    1 ms: the joint torque that brings the joint's velocity to the commanded velocity plus
    ``GAIN`` times the position error per step (by the arm's mass matrix and bias forces),
    clamped to the joint's effort — what Bullet's position motors solve as a constraint.

    Parameters are :class:`~bidmp.sim.pybullet.RobotCell`'s.
    """

    simulator = "MuJoCo, 1 kHz position control"  # how reports name this backend

    def __init__(
        self,
        scene,
        units: str = "mm",
        base=(0.0, -450.0, 0.0),
        yaw: float = 90.0,
        robot: RobotModel = PANDA_MODEL,
    ):
        from ...scene import Scene

        mujoco = _mujoco_module()
        if not isinstance(robot, RobotModel):
            raise TypeError(
                f"robot must be a bidmp.sim.robots.RobotModel, got {type(robot).__name__}"
            )
        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a bidmp.Scene, got {type(scene).__name__}")
        base, yaw = as_point(base, 3, "base"), check_real(yaw, "yaw")
        self.mj = mujoco
        self.model = robot
        self.limits = robot.limits
        self.scene = scene
        self.unit = _unit_of(units)
        self.p = p = _pybullet_module()
        self.client = None  # no PyBullet world: the physics is MuJoCo's
        self.ik_client = None
        try:
            self.ik_client = p.connect(p.DIRECT)
            text = _tool_urdf(robot, scene.tool.radius * self.unit, scene.tool.length * self.unit)
            if isinstance(text, tuple):  # (the text, notes on stand-in inertials)
                text = text[0]
            base_m = np.asarray(base, dtype=float) * self.unit
            orientation = p.getQuaternionFromEuler([0, 0, math.radians(yaw)])
            with tempfile.TemporaryDirectory() as folder:
                kinematics = Path(folder) / "robot_kinematics.urdf"
                kinematics.write_text(_kinematic_urdf(text))
                self.ik_robot = p.loadURDF(
                    str(kinematics),
                    base_m.tolist(),
                    orientation,
                    useFixedBase=True,
                    physicsClientId=self.ik_client,
                )
            names = [
                p.getJointInfo(self.ik_robot, j, physicsClientId=self.ik_client)[12].decode()
                for j in range(p.getNumJoints(self.ik_robot, physicsClientId=self.ik_client))
            ]
            self.tcp = names.index("tcp")
            movable = [
                j
                for j in range(len(names))
                if p.getJointInfo(self.ik_robot, j, physicsClientId=self.ik_client)[2]
                != p.JOINT_FIXED
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
            self.base = np.asarray(base, dtype=float)
            self.yaw = float(yaw)
            self._build(text, base_m, orientation)
            self.wrist_turns_tool = self._last_joint_turns_tool()
            self.free_turn = True
            self._set_joints(robot.rest)
        except BaseException:
            self.close()
            raise

    def _build(self, text: str, base_m: np.ndarray, orientation) -> None:
        """The MuJoCo model: the arm at its base, the scene's parts, 1 kHz, gravity."""
        mujoco = self.mj
        spec = _arm_spec(mujoco, text)
        spec.option.timestep = SIM_STEP
        spec.option.gravity = [0.0, 0.0, -9.81]
        root = spec.worldbody.first_body()
        root.pos = base_m.tolist()
        x, y, z, w = orientation
        root.quat = [w, x, y, z]
        for geom in spec.geoms:
            geom.contype, geom.conaffinity = ARM_GROUP
        self.spec = spec
        self._arm_bodies = {body.name for body in spec.bodies if body.name != "world"}
        self._part_bodies = {}  # body name -> (solid, part label)
        self._count = 0
        for solid in self.scene.solids:
            self._add_static(solid)
        self._compile()
        joints = [self.m.joint(j) for j in range(self.m.njnt)]
        arm_joints = [j for j in joints if self.m.body(j.bodyid[0]).name in self._arm_bodies]
        if len(arm_joints) != len(self.arm):
            raise ValueError(
                f"robot {self.model.name!r}: MuJoCo reads {len(arm_joints)} joints where PyBullet "
                f"reads {len(self.arm)}"
            )
        self._names = tuple(j.name for j in arm_joints)
        self._prismatic = tuple(int(j.type[0]) == mujoco.mjtJoint.mjJNT_SLIDE for j in arm_joints)

    def _add_static(self, solid) -> str:
        """A static body for ``solid`` (its contacts reported by its label); its body's name."""
        name = f"part{self._count}"
        self._count += 1
        _add_part_body(self.mj, self.spec, self.unit, solid, name)
        self._part_bodies[name] = (solid.label, solid.part)
        return name

    def _compile(self, keep: bool = False) -> None:
        """(Re)compile the model; ``keep``: the state carried over (the arm where it is)."""
        mujoco = self.mj
        renderer = getattr(self, "_renderer", None)
        if renderer is not None:  # drawn the model it was made with: made anew when asked
            renderer.close()
            self._renderer = None
        if keep:
            self.m, self.d = self.spec.recompile(self.m, self.d)
        else:
            self.m = self.spec.compile()
            self.d = mujoco.MjData(self.m)
        m = self.m
        self._tcp_body = m.body("tcp").id
        self._geom_label = {}  # geom id -> solid label (a part in place)
        self._geom_owner = {}  # geom id -> part label
        for name, (label, owner) in self._part_bodies.items():
            body = m.body(name)
            for g in range(body.geomadr[0], body.geomadr[0] + body.geomnum[0]):
                self._geom_label[g], self._geom_owner[g] = label, owner
        self._arm_geoms = {
            g for g in range(m.ngeom) if m.body(m.geom_bodyid[g]).name in self._arm_bodies
        }
        n = len(self.arm)
        self._qadr = np.array([m.jnt_qposadr[j] for j in range(n)])
        self._vadr = np.array([m.jnt_dofadr[j] for j in range(n)])
        if not (
            np.array_equal(self._qadr, np.arange(n)) and np.array_equal(self._vadr, np.arange(n))
        ):
            raise ValueError("the arm's joints must come first in the MuJoCo model")
        # the control's arrays (bidmp.sim.mujoco.execute._step): views of this model's state
        d = self.d
        self._views = (
            d.qpos[:n],
            d.qvel[:n],
            d.qfrc_bias[:n],
            d.qfrc_passive[:n],
            d.qfrc_applied[:n],
            np.zeros(m.nv),  # the wanted acceleration, every dof (the parts' 0)
            np.zeros(m.nv),  # the mass matrix times it
            np.asarray(self.model.effort, dtype=float),
            np.zeros(n),
        )
        mujoco.mj_forward(m, self.d)

    @classmethod
    def load_robot(
        cls,
        scene,
        units: str = "mm",
        base=(0.0, -450.0, 0.0),
        yaw: float = 90.0,
        robot: RobotModel = PANDA_MODEL,
    ) -> MujocoCell:
        """The backend protocol's constructor (the same as ``MujocoCell(...)``)."""
        return cls(scene, units, base, yaw, robot)

    def close(self) -> None:
        client = getattr(self, "ik_client", None)
        if client is not None:
            self.p.disconnect(client)
            self.ik_client = None
        self.d = None
        renderer = getattr(self, "_renderer", None)
        if renderer is not None:
            renderer.close()
            self._renderer = None

    @property
    def joint_names(self) -> tuple:
        """The driven joints' names, base to flange, as in the arm's URDF."""
        return self._names

    @property
    def joint_units(self) -> tuple:
        """Each driven joint's unit: "m" for a prismatic joint, "rad" for a revolute one."""
        return tuple("m" if slide else "rad" for slide in self._prismatic)

    def _set_joints(self, q, velocities=None, kinematic: bool = False) -> None:
        if kinematic:
            RobotCell._set_joints(self, q, velocities, kinematic=True)
            return
        n = len(self.arm)
        self.d.qpos[:n] = np.asarray(q, dtype=float)
        self.d.qvel[:n] = 0.0 if velocities is None else np.asarray(velocities, dtype=float)
        self.mj.mj_forward(self.m, self.d)

    def _joint_state(self) -> tuple[np.ndarray, np.ndarray]:
        n = len(self.arm)
        return self.d.qpos[:n].copy(), self.d.qvel[:n].copy()

    def tcp_position(self) -> np.ndarray:
        """The simulated robot's measured TCP position (m)."""
        return self.d.xpos[self._tcp_body].copy()

    def tool_orientation(self) -> np.ndarray:
        """The simulated robot's measured tool frame (quaternion x, y, z, w)."""
        w, x, y, z = self.d.xquat[self._tcp_body]
        return np.array([x, y, z, w])

    def model_fk(self, q) -> np.ndarray:
        """The TCP (m) at joints ``q`` by MuJoCo's own kinematics of its model (the engines'
        check compares it with PyBullet's); the arm is put back where it was."""
        q = self._joints(q)
        now = self._joint_state()
        try:
            self._set_joints(q)
            return self.tcp_position()
        finally:
            self._set_joints(*now)

    # -- the protocol's motions ------------------------------------------------------------------
    def execute(
        self,
        plan: MotionPlan,
        exclude=(),
        hold: Hold | None = None,
        frames: int = 0,
        on_record=None,
    ) -> Execution:
        """Run ``plan`` under position control at 1 kHz (:func:`bidmp.sim.mujoco.execute._execute`);
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
        """Run a DMP/Bi-DMP ``stepper`` on the measured TCP at 100 Hz
        (:func:`bidmp.sim.mujoco.execute._execute_closed_loop`)."""
        return _execute._execute_closed_loop(
            self, stepper, (duration, max_factor), exclude, hold, frames, goal_update
        )

    def contacts(self) -> dict:
        """Part label -> penetration depth (m) of the robot's contacts now."""
        found = {}
        _execute._contacts_into(self, found)
        return found

    # -- what the job does in the world ------------------------------------------------------
    def add_solids(self, solids) -> None:
        """Static bodies for more parts (the job's bin, its rack), their contacts reported by label."""
        from ..backend import _check_solids

        solids = _check_solids(solids)
        for solid in solids:
            self._add_static(solid)
        self._compile(keep=True)

    def arm_touch(self, plan, exclude=()) -> tuple[str, float] | None:
        """Whether the arm, run along ``plan``, would touch a part other than ``exclude``'s: the
        planned joints set on the arm at its IK samples, MuJoCo's contacts of every link (the
        tool's too) with every other part in place; ``(part, depth in scene units)`` of the
        deepest touch, or None (:meth:`bidmp.sim.pybullet.RobotCell.arm_touch`)."""
        if not all(hasattr(plan, name) for name in ("fractions", "spline")):
            raise TypeError(
                f"plan must be a bidmp.sim.MotionPlan (RobotCell.plan), got {type(plan).__name__}"
            )
        exclude = set(as_labels(exclude, "exclude"))
        mujoco, m, d = self.mj, self.m, self.d
        now = self._joint_state()
        deepest = None
        try:
            for q in plan.spline(np.asarray(plan.fractions, dtype=float)):
                d.qpos[: len(self.arm)] = q
                mujoco.mj_kinematics(m, d)
                mujoco.mj_collision(m, d)
                for k in range(d.ncon):
                    contact = d.contact[k]
                    g1, g2 = int(contact.geom[0]), int(contact.geom[1])
                    part = g2 if g1 in self._arm_geoms else g1 if g2 in self._arm_geoms else None
                    owner = self._geom_owner.get(part)
                    depth = -float(contact.dist)
                    if owner is None or owner in exclude or depth <= 1e-4:
                        continue
                    if deepest is None or depth > deepest[1]:
                        deepest = (owner, depth)
        finally:
            self._set_joints(*now)
        return None if deepest is None else (deepest[0], deepest[1] / self.unit)

    def movable_part(self, label: str, mass: float):
        """The scene's part ``label`` as one the job moves (a nut on its thread, a held part, a
        released one that falls): :class:`bidmp.sim.mujoco.parts._MovablePart`."""
        from .parts import _MovablePart

        return _MovablePart(self, label, mass)

    def settle(self, seconds: float) -> None:
        """Let the world run ``seconds`` with the arm holding where it is (a released part falls)."""
        seconds = check_real(seconds, "seconds", nonnegative=True, maximum=60.0)
        q, _ = self._joint_state()
        zero = np.zeros_like(q)
        # finer steps while a released part falls: at 1 ms a nut dropped 80 mm moves 1.25 mm a
        # step, and passed the middle of the bin's 1.4 mm floor before its first contact. Once
        # nothing free moves faster than 0.1 m/s (0.1 mm a step), 1 ms steps again.
        n = len(self.arm)
        try:
            for _ in range(int(round(seconds / SIM_STEP))):
                falling = self.m.nv > n and float(np.max(np.abs(self.d.qvel[n:]))) > 0.1
                substeps = FALL_SUBSTEPS if falling else 1
                self.m.opt.timestep = SIM_STEP / substeps
                for _ in range(substeps):
                    _execute._step(self, q, zero)
        finally:
            self.m.opt.timestep = SIM_STEP

    def render(self, width: int = 320, height: int = 240, target=None) -> np.ndarray:
        """An RGB image (height, width, 3) of the cell (MuJoCo's renderer, off-screen)."""
        from . import render as _render

        return _render._render(self, width, height, target)

    def keyframe(self, t: float, focus, width: int = 320, height: int = 240) -> np.ndarray:
        """A labelled keyframe (2 height, width, 3): the whole arm above, a close-up on the tool
        and ``focus`` (scene units) below, the time ``t`` (s) written in."""
        from . import render as _render

        return _render._keyframe(self, t, focus, width, height)
