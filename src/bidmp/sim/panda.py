"""Execute a scenario's motions on a simulated Franka Panda (PyBullet, headless).

``simulate(scenario)`` builds the scenario's scene (plate, nuts and studs, cells, ...) and a
Panda from ``pybullet_data`` whose hand is replaced by the scenario's tool, a cylinder on the
flange with the tool-centre point (TCP) at its mouth. Then, for each method and target:

1. the method's Cartesian trajectory (the evaluation's rollout, in the scenario's unit);
2. inverse kinematics per sample, seeded by the previous solution, tool pointing down; a sample
   the arm cannot reach, or a joint outside the Panda's limits, is an error naming the target;
3. real time: the joint path is a clamped cubic spline, uniformly time-scaled to 90 % of the
   Panda's published joint velocity and acceleration limits (:func:`bidmp.time_scale`);
4. position control at 1 kHz (PyBullet's joint motors with velocity feed-forward), the measured
   TCP path, and every contact of the arm or the tool with a part other than the target
   (``getContactPoints``).

Results per target: commanded and measured end-point error, engagement (lateral error over the
last approach height, measured), contacts, peak joint velocity and acceleration as fractions of
the limits, motion time. Task success in simulation = measured end point within the threshold ∧
engaged ∧ no contact ∧ within the limits.

``closed_loop=True`` runs the DMP/Bi-DMP :meth:`~bidmp.DMP.stepper` at 100 Hz on the measured TCP
position with phase stopping, and ``hold`` scripts a disturbance (a joint held still for a while).

What is modelled: the Panda's kinematics, link masses and joint limits, its joint motors under
position control, rigid contacts between the arm, the tool and the parts. What is not: the real
controller's filters and its torque and jerk limits, friction of the thread, the nut turning.

Needs the ``sim`` extra: ``pip install 'bidmp[sim]'`` (pybullet).
"""

from __future__ import annotations

import json
import logging
import math
import os
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.interpolate import CubicSpline

from .._checks import as_point, as_trajectory, check_int, check_real, require_extra
from ..tasks._tables import markdown_table, text_table
from ..tasks.metrics import approach_error, axis_deviation
from ..primitives.timing import Trajectory, time_scale

__all__ = ["PANDA", "JointLimits", "Hold", "PandaCell", "MotionPlan", "Execution", "SimTarget", "SimMethod",
           "SimReport", "SimError", "simulate", "robot_placement", "write_sim_report"]

logger = logging.getLogger(__name__)

SIM_STEP = 1e-3  # s: 1 kHz physics and position control
CONTROL_STEP = 1e-2  # s: the closed-loop stepper and its inverse kinematics run at 100 Hz
LIMIT_MARGIN = 0.9  # motions are timed to this fraction of the joint velocity and acceleration limits
SOLVER_ITERATIONS = 20
COUPLING = 5e5  # 1/m²: phase stopping's default gain in closed loop (0.5 /mm²)
RECORD_EVERY = 2  # physics steps per recorded sample (500 Hz); contacts are checked every step
SETTLE = 0.3  # s held at the end before the end point is measured
MAX_SAMPLE_SPACING = 5e-3  # m: the Cartesian path is subdivided so that IK points are at most this far apart
IK_TOLERANCE = 5e-5  # m: a sample whose IK leaves more than this (0.05 mm) is unreachable
IK_ACCURACY = 5e-6  # m: IK stops refining below this (tracking errors are ~100x larger)
_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
_DOWN = (1.0, 0.0, 0.0, 0.0)  # quaternion (x, y, z, w): the flange's z axis pointing down
_REST = (0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.785)


class SimError(ValueError):
    """A motion cannot be executed (unreachable, outside the joint limits); names the target."""


@dataclass(frozen=True)
class JointLimits:
    """Joint limits of a 7-axis arm: position (rad), velocity (rad/s), acceleration (rad/s²)."""

    lower: tuple
    upper: tuple
    velocity: tuple
    acceleration: tuple


# Franka Emika Panda, from Franka's published robot and interface specifications.
PANDA = JointLimits(
    lower=(-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973),
    upper=(2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973),
    velocity=(2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100),
    acceleration=(15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0),
)
_EFFORT = [87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0]  # N m
_GAINS = [1.0] * 7  # PyBullet's position and velocity gains: the stiffest its motors allow


@dataclass(frozen=True)
class Hold:
    """A scripted disturbance: joint ``joint`` (0-6) held where it is from ``start`` for
    ``duration`` seconds of the motion."""

    joint: int
    start: float
    duration: float = 0.5


def _pybullet():
    """Import pybullet without its banner (it writes one line from C to the process's stderr on
    import; a library must not)."""
    import sys

    module = sys.modules.get("pybullet")
    if module is not None:
        return module
    sys.stdout.flush()
    sys.stderr.flush()
    saved = [os.dup(1), os.dup(2)]
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            os.dup2(null.fileno(), 2)
            try:
                return require_extra("pybullet", "sim", "the simulator (bidmp sim)")
            finally:
                os.dup2(saved[0], 1)
                os.dup2(saved[1], 2)
    finally:
        for fd in saved:
            os.close(fd)


def _unit(units: str) -> float:
    if units not in _UNITS:
        raise ValueError(f"the simulator needs lengths in m, cm or mm; the scenario's units are {units!r}")
    return _UNITS[units]


def robot_placement(scenario) -> tuple[np.ndarray, float]:
    """The robot's base (scenario units) and yaw (degrees): the scenario's ``"robot"`` key, or in
    front of the work: 330 mm short of the nearest point in y, centred in x, at the lowest
    target's height, facing +y."""
    robot = scenario.robot or {}
    if "base" in robot:
        return np.asarray(robot["base"], dtype=float), float(robot.get("yaw", 90.0))
    points = np.vstack([scenario.target_array, scenario.demonstration])
    unit = _unit(scenario.units)
    base = np.array([0.5 * (points[:, 0].min() + points[:, 0].max()), points[:, 1].min() - 0.33 / unit,
                     scenario.target_array[:, 2].min()])
    return base, float(robot.get("yaw", 90.0))


def _panda_urdf(tool_radius: float, tool_length: float) -> str:
    """The Panda of pybullet_data with its hand replaced by a cylindrical tool (metres): link
    ``tool`` on the flange, link ``tcp`` at the tool's mouth."""
    import pybullet_data

    folder = Path(pybullet_data.getDataPath()) / "franka_panda"
    text = (folder / "panda.urdf").read_text()
    cut = text.index('<joint name="panda_hand_joint"')
    inertia = 'ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"'
    tool = (
        f'  <joint name="tool_joint" type="fixed"><parent link="panda_link8"/><child link="tool"/>'
        f'<origin rpy="0 0 0" xyz="0 0 {tool_length / 2}"/></joint>\n'
        f'  <link name="tool"><inertial><origin xyz="0 0 0"/><mass value="0.3"/><inertia {inertia}/></inertial>'
        f'<visual><geometry><cylinder radius="{tool_radius}" length="{tool_length}"/></geometry>'
        f'<material name="socket"><color rgba="0.25 0.25 0.28 1"/></material></visual>'
        f'<collision><geometry><cylinder radius="{tool_radius}" length="{tool_length}"/></geometry></collision></link>\n'
        f'  <joint name="tcp_joint" type="fixed"><parent link="tool"/><child link="tcp"/>'
        f'<origin rpy="0 0 0" xyz="0 0 {tool_length / 2}"/></joint>\n'
        f'  <link name="tcp"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>'
        f'</inertial></link>\n</robot>\n'
    )
    return (text[:cut] + tool).replace("package://meshes/", f"{folder / 'meshes'}/")


@dataclass
class MotionPlan:
    """A Cartesian path turned into a timed joint path (arrays in SI units: s, rad)."""

    label: str
    points: np.ndarray  # (n, 3) m, the IK samples (the path subdivided)
    fractions: np.ndarray  # (n,) normalised time of each sample in [0, 1]
    joints: np.ndarray  # (n, 7) rad
    duration: float  # s
    spline: CubicSpline  # q(u), u in [0, 1]
    peak_velocity: float  # fraction of the limit, the largest over joints
    peak_acceleration: float
    orientations: np.ndarray | None = None  # (n, 4) the tool frame at the IK samples (pose skills)

    def command(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Joint positions and velocities commanded at time(s) ``t`` (s): (7,) or (n, 7)."""
        u = np.clip(np.asarray(t, dtype=float) / self.duration, 0.0, 1.0)
        moving = (u > 0.0) & (u < 1.0)  # at rest before the start and after the end
        return self.spline(u), self.spline(u, 1) / self.duration * moving[..., None]


@dataclass
class Execution:
    """What the simulated robot did: times (s), measured TCP (m), joints (rad, rad/s)."""

    times: np.ndarray
    tcp: np.ndarray
    joints: np.ndarray
    joint_velocities: np.ndarray
    commanded_tcp: np.ndarray  # the command's TCP at the same times (FK of the commanded joints)
    contacts: dict  # part label -> deepest penetration (m, > 0)
    frames: list = field(default_factory=list)  # rendered RGB images, when asked for
    command_times: np.ndarray | None = None  # closed loop: the control steps (s) ...
    command_joints: np.ndarray | None = None  # ... the joints commanded there (rad) ...
    motion_clock: np.ndarray | None = None  # ... and the stepper's own time (s; stands still while paused)
    tcp_orientation: np.ndarray | None = None  # measured TCP frame (x, y, z, w)

    @property
    def paused(self) -> float:
        """Seconds of the run during which the motion's own time ran at under a fifth of the
        clock's pace (closed loop; 0 otherwise)."""
        if self.motion_clock is None or len(self.motion_clock) < 2:
            return 0.0
        running = self.motion_clock[1:] < self.motion_clock[-1]  # not the settling at the end
        slow = np.diff(self.motion_clock) < 0.2 * np.diff(self.command_times)
        return float(np.sum(slow & running) * CONTROL_STEP)


_REACH_M = 2.0  # m from the base: far beyond the Panda's 0.855 m, so a path past it is a mistake


def _reachable(point_m: np.ndarray, base_m: np.ndarray, name: str) -> np.ndarray:
    """Refuse a point (m) further than any Panda reaches from its base (a unit mistake, or a
    path that IK would chase for ever)."""
    distance = float(np.linalg.norm(point_m - base_m))
    if not distance <= _REACH_M:
        raise SimError(f"{name}: a point {distance:.3g} m from the robot's base, beyond the Panda's reach "
                       f"(0.855 m); check the units and the base")
    return point_m


def _joint_seed(seed) -> np.ndarray:
    """Seven finite joint angles (rad) within the Panda's limits, to start IK from."""
    q = as_point(seed, 7, "seed")
    outside = (q < np.array(PANDA.lower) - 1e-6) | (q > np.array(PANDA.upper) + 1e-6)
    if outside.any():
        joint = int(np.argmax(outside))
        raise ValueError(f"seed: joint {joint + 1} at {q[joint]:.4g} rad is outside its limits "
                         f"[{PANDA.lower[joint]}, {PANDA.upper[joint]}]")
    return q


class PandaCell:
    """A headless PyBullet world with a scene's parts and a Panda carrying the scene's tool.

    Parameters
    ----------
    scene : bidmp.Scene
    units : str
        The scene's length unit ("mm", "cm" or "m").
    base : array (3,)
        Robot base position in the scene's unit.
    yaw : float
        Robot base rotation about z in degrees (90: the robot faces +y).
    """

    def __init__(self, scene, units: str = "mm", base=(0.0, -450.0, 0.0), yaw: float = 90.0):
        self.p = p = _pybullet()
        self.scene = scene
        self.unit = _unit(units)
        self.client = p.connect(p.DIRECT)
        try:
            p.setTimeStep(SIM_STEP, physicsClientId=self.client)
            # 20 solver iterations instead of 50: the same tracking here (< 0.3 mm), 20 % less time.
            p.setPhysicsEngineParameter(numSolverIterations=SOLVER_ITERATIONS, physicsClientId=self.client)
            p.setGravity(0.0, 0.0, -9.81, physicsClientId=self.client)
            self._bodies = {}  # body id -> solid label
            self._owners = {}  # body id -> part label
            for solid in scene.solids:
                body = self._add_solid(solid)
                self._bodies[body] = solid.label
                self._owners[body] = solid.part
            # A second world holds a copy of the arm alone for inverse and forward kinematics, so
            # that planning never resets the simulated robot's state.
            self.ik_client = p.connect(p.DIRECT)
            with tempfile.TemporaryDirectory() as folder:
                path = Path(folder) / "panda_tool.urdf"
                path.write_text(_panda_urdf(scene.tool.radius * self.unit, scene.tool.length * self.unit))
                base_m = np.asarray(base, dtype=float) * self.unit
                orientation = p.getQuaternionFromEuler([0, 0, math.radians(yaw)])
                self.robot = p.loadURDF(str(path), base_m.tolist(), orientation, useFixedBase=True,
                                        physicsClientId=self.client)
                self.ik_robot = p.loadURDF(str(path), base_m.tolist(), orientation, useFixedBase=True,
                                           physicsClientId=self.ik_client)
            names = [p.getJointInfo(self.robot, j, physicsClientId=self.client)[12].decode()
                     for j in range(p.getNumJoints(self.robot, physicsClientId=self.client))]
            self.tcp = names.index("tcp")
            self.arm = list(range(7))
            self.base = np.asarray(base, dtype=float)
            self.yaw = float(yaw)
            self._set_joints(_REST)
        except BaseException:
            self.close()
            raise

    # -- world -----------------------------------------------------------------------------
    def _add_solid(self, solid) -> int:
        p, unit = self.p, self.unit
        if solid.kind == "box":
            half = [0.5 * v * unit for v in solid.params]
            shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=self.client)
            visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=self._colour(solid), physicsClientId=self.client)
        elif solid.kind == "cylinder":
            radius, height = solid.params[0] * unit, solid.params[1] * unit
            shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=radius, height=height, physicsClientId=self.client)
            visual = p.createVisualShape(p.GEOM_CYLINDER, radius=radius, length=height, rgbaColor=self._colour(solid),
                                         physicsClientId=self.client)
        else:  # the hex nut: its convex hull
            vertices = (np.asarray(solid.params[0]) * unit).tolist()
            shape = p.createCollisionShape(p.GEOM_MESH, vertices=vertices, physicsClientId=self.client)
            extent = np.ptp(np.asarray(solid.params[0]), axis=0) * unit
            visual = p.createVisualShape(p.GEOM_CYLINDER, radius=0.5 * extent[0], length=extent[2],
                                         rgbaColor=self._colour(solid), physicsClientId=self.client)
        from scipy.spatial.transform import Rotation

        orientation = Rotation.from_matrix(solid.rotation).as_quat().tolist()
        return p.createMultiBody(0.0, shape, visual, (np.asarray(solid.centre) * unit).tolist(), orientation,
                                 physicsClientId=self.client)

    @staticmethod
    def _colour(solid) -> list:
        if solid.label.endswith("/stud"):
            return [0.35, 0.35, 0.38, 1.0]
        if solid.kind == "convex":
            return [0.75, 0.75, 0.7, 1.0]
        return [0.55, 0.62, 0.72, 1.0] if solid.params[2] < 20 else [0.35, 0.5, 0.8, 1.0]

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

    def _set_joints(self, q, velocities=None, kinematic: bool = False) -> None:
        robot, client = (self.ik_robot, self.ik_client) if kinematic else (self.robot, self.client)
        for joint in range(7):
            self.p.resetJointState(robot, joint, float(q[joint]), 0.0 if velocities is None else float(velocities[joint]),
                                   physicsClientId=client)

    def tcp_position(self) -> np.ndarray:
        """The simulated robot's measured TCP position (m)."""
        return np.array(self.p.getLinkState(self.robot, self.tcp, computeForwardKinematics=1,
                                            physicsClientId=self.client)[4])

    def forward(self, q) -> np.ndarray:
        """TCP position (m) for joint positions ``q`` (forward kinematics on the planning copy)."""
        self._set_joints(q, kinematic=True)
        return np.array(self.p.getLinkState(self.ik_robot, self.tcp, computeForwardKinematics=1,
                                            physicsClientId=self.ik_client)[4])

    # -- planning --------------------------------------------------------------------------
    def solve_ik(self, point_m: np.ndarray, seed, orientation=None) -> tuple[np.ndarray, float]:
        """Joint positions that put the TCP at ``point_m`` (m) with the tool's frame at
        ``orientation`` (quaternion x, y, z, w; default pointing down), started from ``seed``;
        and the position error left (m)."""
        p = self.p
        point_m = _reachable(as_point(point_m, 3, "point_m"), self.base * self.unit, "point_m")
        q = _joint_seed(seed)
        if orientation is not None:
            from ..primitives.so3 import as_quaternions

            orientation = as_quaternions(orientation, "orientation")[0]
        target_orientation = _DOWN if orientation is None else [float(v) for v in orientation]
        axis = None
        if orientation is not None:
            # The tool is a socket, symmetric about its axis: only the axis is prescribed. Each
            # burst aims at the orientation nearest the current one with that axis, so the arm
            # keeps its own turn about the axis (a full orientation made the wrist fight it).
            from scipy.spatial.transform import Rotation

            axis = Rotation.from_quat(target_orientation).apply([0.0, 0.0, 1.0])
        limits = PANDA
        ranges = [u - l for l, u in zip(limits.lower, limits.upper)]
        error = math.inf
        # Short bursts from the previous solution, checked by forward kinematics: a few dozen
        # iterations reach 1 µm from a seed a few millimetres away (one long call costs 10x).
        for _ in range(20):
            self._set_joints(q, kinematic=True)
            if axis is not None:
                current = Rotation.from_quat(p.getLinkState(self.ik_robot, self.tcp, computeForwardKinematics=1,
                                                            physicsClientId=self.ik_client)[5])
                swing, _ = Rotation.align_vectors([axis], [current.apply([0.0, 0.0, 1.0])])
                target_orientation = (swing * current).as_quat().tolist()
            q = np.array(p.calculateInverseKinematics(
                self.ik_robot, self.tcp, point_m.tolist(), target_orientation, lowerLimits=list(limits.lower),
                upperLimits=list(limits.upper), jointRanges=ranges, restPoses=q.tolist(), maxNumIterations=40,
                residualThreshold=1e-9, physicsClientId=self.ik_client)[:7])
            if axis is not None:
                # Joint 7 turns the flange about the tool's axis, which moves neither the tool's
                # mouth nor its axis: park it mid-range instead of letting it drift to a limit.
                q[6] = _REST[6]
            error = float(np.linalg.norm(self.forward(q) - point_m))
            if error <= IK_ACCURACY:
                break
        return q, error

    def plan(self, path, label: str = "", fractions=None, seed=None, orientations=None) -> MotionPlan:
        """Inverse kinematics along ``path`` (n, 3, scene units) and the fastest uniform timing
        within :data:`LIMIT_MARGIN` of the joint limits. ``fractions``: normalised time of each
        sample (default: uniform, as a DMP rollout is). ``orientations`` (n, 4): the tool frame
        along the path (a pose skill's); default pointing down."""
        path = as_trajectory(path, "path", min_points=2, allow_static=True)
        if path.shape[1] != 3:
            raise ValueError(f"path must have 3 columns, got {path.shape[1]}")
        for point in (path.min(axis=0), path.max(axis=0)):  # before subdividing it into 5 mm steps
            _reachable(point * self.unit, self.base * self.unit, "path")
        given = np.linspace(0.0, 1.0, path.shape[0]) if fractions is None else np.asarray(fractions, dtype=float)
        if given.shape != (path.shape[0],) or not np.all(np.isfinite(given)) or np.any(np.diff(given) < 0) \
                or given[0] < 0 or given[-1] > 1:
            raise ValueError(f"fractions must be {path.shape[0]} non-decreasing times in [0, 1]")
        points, u = _subdivide(path * self.unit, given, MAX_SAMPLE_SPACING)
        turns = None
        if orientations is not None:
            from scipy.spatial.transform import Rotation, Slerp

            q = np.asarray(orientations, dtype=float)
            if q.shape != (path.shape[0], 4):
                raise ValueError(f"orientations must have shape ({path.shape[0]}, 4), got {q.shape}")
            keep = np.concatenate([[True], np.diff(given) > 1e-12])
            turns = Slerp(given[keep], Rotation.from_quat(q[keep]))(u).as_quat()
        q = np.array(_REST, dtype=float) if seed is None else _joint_seed(seed)
        joints = np.empty((points.shape[0], 7))
        for index, point in enumerate(points):
            q, error = self.solve_ik(point, q, None if turns is None else turns[index])
            if error > IK_TOLERANCE:
                raise SimError(f"target {label!r}: the point {np.round(point / self.unit, 2).tolist()} of its motion is "
                               f"unreachable for the Panda at base {np.round(self.base, 1).tolist()} "
                               f"(inverse kinematics leaves {error / self.unit:.3g} {_unit_name(self.unit)}); move the "
                               f"robot (scenario key \"robot\": {{\"base\": ...}})")
            below, above = q < np.array(PANDA.lower) - 1e-9, q > np.array(PANDA.upper) + 1e-9
            if below.any() or above.any():
                joint = int(np.flatnonzero(below | above)[0])
                raise SimError(f"target {label!r}: joint {joint + 1} would leave its limits "
                               f"[{PANDA.lower[joint]}, {PANDA.upper[joint]}] rad ({q[joint]:.3f})")
            joints[index] = q
        spline = CubicSpline(u, joints, bc_type="clamped")
        grid = np.linspace(0.0, 1.0, max(2001, 10 * len(u)))
        unit_time = Trajectory(grid, spline(grid), spline(grid, 1), spline(grid, 2))
        vmax = LIMIT_MARGIN * np.asarray(PANDA.velocity)
        amax = LIMIT_MARGIN * np.asarray(PANDA.acceleration)
        timed = time_scale(unit_time, max_velocity=vmax, max_acceleration=amax, norm="axis")
        duration = float(timed.t[-1])
        return MotionPlan(label, points, u, joints, duration, spline,
                          float(np.max(np.abs(timed.yd) / np.asarray(PANDA.velocity))),
                          float(np.max(np.abs(timed.ydd) / np.asarray(PANDA.acceleration))), turns)

    # -- execution -------------------------------------------------------------------------
    def _ignore(self, exclude, enable: bool) -> None:
        """Switch contacts between the robot and the parts in ``exclude`` off (the target enters
        the tool) or back on."""
        p = self.p
        links = list(range(-1, p.getNumJoints(self.robot, physicsClientId=self.client)))
        for body, owner in self._owners.items():
            if owner in exclude:
                for link in links:
                    p.setCollisionFilterPair(self.robot, body, link, -1, int(enable), physicsClientId=self.client)

    def _contacts(self, found: dict) -> None:
        for contact in self.p.getContactPoints(bodyA=self.robot, physicsClientId=self.client):
            depth = -contact[8]
            if depth > 0.0 and contact[2] in self._bodies:
                label = self._bodies[contact[2]]
                found[label] = max(found.get(label, 0.0), depth)

    def _drive(self, q, qd) -> None:
        self.p.setJointMotorControlArray(self.robot, self.arm, self.p.POSITION_CONTROL, targetPositions=q,
                                         targetVelocities=qd, forces=_EFFORT, positionGains=_GAINS,
                                         velocityGains=_GAINS, physicsClientId=self.client)

    def execute(self, plan: MotionPlan, exclude=(), hold: Hold | None = None, frames: int = 0) -> Execution:
        """Run ``plan`` under position control at 1 kHz, the parts in ``exclude`` ignored; a
        ``hold`` keeps one joint still for a while (its command runs on: open loop)."""
        p = self.p
        n_steps = int(math.ceil((plan.duration + SETTLE) / SIM_STEP))
        positions, velocities = plan.command(np.arange(n_steps) * SIM_STEP)
        self._set_joints(positions[0])
        position_list, velocity_list = positions.tolist(), velocities.tolist()
        record = _Recorder(self, n_steps, frames)
        self._ignore(exclude, False)
        held = None
        # The 1 kHz loop is most of a simulation's cost: PyBullet's calls bound once, the
        # recorder visited only on the steps it records.
        robot, client, arm, mode, step_simulation = self.robot, self.client, self.arm, p.POSITION_CONTROL, p.stepSimulation
        motors, contact_points, contacts = p.setJointMotorControlArray, p.getContactPoints, record.contacts
        bodies = self._bodies
        visit = np.zeros(n_steps, dtype=bool)
        visit[::RECORD_EVERY] = True
        visit[-1] = True
        visit[list(record.frame_steps)] = True
        try:
            for step in range(n_steps):
                t = step * SIM_STEP
                q, qd = position_list[step], velocity_list[step]
                if hold is not None and hold.start <= t < hold.start + hold.duration:
                    if held is None:
                        held = p.getJointState(robot, hold.joint, physicsClientId=client)[0]
                    q, qd = list(q), list(qd)
                    q[hold.joint], qd[hold.joint] = held, 0.0
                motors(robot, arm, mode, targetPositions=q, targetVelocities=qd, forces=_EFFORT, positionGains=_GAINS,
                       velocityGains=_GAINS, physicsClientId=client)
                step_simulation(physicsClientId=client)
                for contact in contact_points(bodyA=robot, physicsClientId=client):
                    if contact[8] < 0.0 and contact[2] in bodies:
                        label = bodies[contact[2]]
                        contacts[label] = max(contacts.get(label, 0.0), -contact[8])
                if visit[step]:
                    record.sample(step, t + SIM_STEP, positions[step])
        finally:
            self._ignore(exclude, True)
        return record.finish()

    def execute_closed_loop(self, stepper, duration: float, exclude=(), hold: Hold | None = None,
                            frames: int = 0, max_factor: float = 4.0) -> Execution:
        """Run a DMP/Bi-DMP ``stepper`` (scene units) on the measured TCP at 100 Hz.

        Each control step asks the stepper for the command given where the TCP is, solves IK
        and hands the joints to the 1 kHz position control, which moves linearly from the last
        control step's joints to these over the next 10 ms. With phase stopping the motion's
        own time stands still while the robot is held. The run ends when the stepper's time has
        reached ``duration`` (at most ``max_factor`` times that in wall time) plus the settling.
        """
        p = self.p
        q, error = self.solve_ik(np.asarray(stepper.y) * self.unit, _REST)
        if error > IK_TOLERANCE:
            raise SimError(f"the start {np.round(stepper.y, 2).tolist()} is unreachable")
        self._set_joints(q)
        every = int(round(CONTROL_STEP / SIM_STEP))
        longest = max_factor * duration + (0.0 if hold is None else hold.duration)
        n_steps = int(math.ceil((longest + SETTLE) / SIM_STEP))
        record = _Recorder(self, n_steps, frames)
        self._ignore(exclude, False)
        command, previous, held, settle_from = q, q, None, None
        times, commands, clock = [], [], []
        # A rate limiter on the joint command, as the Panda's own interface has: the stepper's
        # command changes pace abruptly when phase stopping engages or lets go, and the joints
        # must not follow that jump faster than their limits allow.
        speed, max_speed = np.zeros(7), LIMIT_MARGIN * np.asarray(PANDA.velocity)
        max_change = LIMIT_MARGIN * np.asarray(PANDA.acceleration) * CONTROL_STEP

        def limited(wanted, command, speed):
            """The next command towards ``wanted`` and its joint speed, within the limits."""
            speed = np.clip(np.clip((wanted - command) / CONTROL_STEP, speed - max_change, speed + max_change),
                            -max_speed, max_speed)
            return command + speed * CONTROL_STEP, speed

        step = 0
        try:
            for step in range(n_steps):
                t = step * SIM_STEP
                if step % every == 0:
                    previous = command
                    if settle_from is not None and step - settle_from >= SETTLE / SIM_STEP:
                        break
                    if settle_from is None:  # (settling: the limiter brings the joints to rest at the last IK target)
                        measured = self.tcp_position() / self.unit
                        y, _, _ = stepper.step(CONTROL_STEP, measured)
                        wanted, _ = self.solve_ik(np.asarray(y) * self.unit, command)
                    command, speed = limited(wanted, command, speed)
                    times.append(t)
                    commands.append(command)
                    clock.append(stepper.time)
                    if settle_from is None and stepper.time >= duration:
                        settle_from = step
                share = (step % every + 1) / every
                between = previous + share * (command - previous)  # linear over the 10 ms
                q = between.tolist()
                qd = ((command - previous) / CONTROL_STEP).tolist()
                if hold is not None and hold.start <= t < hold.start + hold.duration:
                    if held is None:
                        held = p.getJointState(self.robot, hold.joint, physicsClientId=self.client)[0]
                    q[hold.joint], qd[hold.joint] = held, 0.0
                self._drive(q, qd)
                p.stepSimulation(physicsClientId=self.client)
                record.sample(step, t + SIM_STEP, between, contacts=True, every_step=True)
        finally:
            self._ignore(exclude, True)
        run = record.finish()
        run.command_times, run.command_joints, run.motion_clock = np.array(times), np.array(commands), np.array(clock)
        return run

    # -- pictures --------------------------------------------------------------------------
    def render(self, width: int = 320, height: int = 240, target=None) -> np.ndarray:
        """An RGB image (height, width, 3) of the cell by PyBullet's TinyRenderer (headless)."""
        p = self.p
        if target is None:  # between the robot and its work, a little above: the whole arm in view
            look = 0.5 * (self.base + self.scene_centre()) * self.unit + [0.0, 0.0, 0.2]
        else:
            look = np.asarray(target, dtype=float) * self.unit
        view = p.computeViewMatrixFromYawPitchRoll(look.tolist(), 1.2, self.yaw - 50.0, -25.0, 0.0, 2,
                                                   physicsClientId=self.client)
        projection = p.computeProjectionMatrixFOV(45.0, width / height, 0.02, 5.0, physicsClientId=self.client)
        _, _, rgba, _, _ = p.getCameraImage(width, height, view, projection, renderer=p.ER_TINY_RENDERER,
                                            physicsClientId=self.client)
        return np.asarray(rgba, dtype=np.uint8).reshape(height, width, 4)[:, :, :3]

    def scene_centre(self) -> np.ndarray:
        lower, upper = np.min([s.lower for s in self.scene.solids], axis=0), np.max([s.upper for s in self.scene.solids], axis=0)
        return 0.5 * (lower + upper)


class _Recorder:
    """Measured samples of one execution (every step) and optional frames."""

    def __init__(self, cell: PandaCell, n_steps: int, frames: int):
        self.cell = cell
        self.n_steps = n_steps
        n_records = (n_steps - 1) // RECORD_EVERY + 1
        self.times = np.empty(n_records)
        self.tcp = np.empty((n_records, 3))
        self.tcp_orientation = np.empty((n_records, 4))
        self.joints = np.empty((n_records, 7))
        self.velocities = np.empty((n_records, 7))
        self.commanded = []
        self.contacts = {}
        self.frame_steps = set(np.linspace(0, n_steps - 1, frames).astype(int).tolist()) if frames else set()
        self.frames = []
        self.filled = 0

    def sample(self, step: int, t: float, commanded_joints, contacts: bool = False, every_step: bool = False) -> None:
        """Record step ``step`` (the loop calls it on recorded steps only, or ``every_step``)."""
        cell = self.cell
        p = cell.p
        if contacts:
            cell._contacts(self.contacts)
        if step in self.frame_steps:
            self.frames.append(cell.render())
        if every_step and step % RECORD_EVERY and step != self.n_steps - 1:
            return
        row = min(step // RECORD_EVERY + (step % RECORD_EVERY > 0), len(self.times) - 1)
        self.filled = row + 1
        self.times[row] = t
        state = p.getLinkState(cell.robot, cell.tcp, computeForwardKinematics=1, physicsClientId=cell.client)
        self.tcp[row], self.tcp_orientation[row] = state[4], state[5]
        states = p.getJointStates(cell.robot, cell.arm, physicsClientId=cell.client)
        self.joints[row] = [s[0] for s in states]
        self.velocities[row] = [s[1] for s in states]
        if row % 10 == 0 or step == self.n_steps - 1:  # the command's TCP, 50 Hz (forward kinematics)
            self.commanded.append((row, np.asarray(commanded_joints, dtype=float).copy()))

    def finish(self) -> Execution:
        """The execution (cut to the rows recorded when the run ended early)."""
        cell = self.cell
        n_rows = self.filled
        rows = [r for r, _ in self.commanded if r < n_rows]
        commanded = np.array([cell.forward(q) for r, q in self.commanded if r < n_rows])
        full = np.column_stack([np.interp(np.arange(n_rows), rows, commanded[:, k]) for k in range(3)])
        run = Execution(self.times[:n_rows], self.tcp[:n_rows], self.joints[:n_rows], self.velocities[:n_rows], full,
                        self.contacts, self.frames)
        run.tcp_orientation = self.tcp_orientation[:n_rows]
        return run


def _unit_name(unit: float) -> str:
    return {1.0: "m", 1e-2: "cm", 1e-3: "mm"}[unit]


def _subdivide(points: np.ndarray, fractions: np.ndarray, spacing: float) -> tuple[np.ndarray, np.ndarray]:
    """The IK samples of a path: samples closer than ``spacing / 2`` to the last one kept are
    dropped (the joint spline interpolates them to micrometres), and points (with their times)
    are inserted on segments longer than ``spacing``."""
    keep, last = [0], points[0]
    for index in range(1, len(points) - 1):
        if np.linalg.norm(points[index] - last) >= 0.5 * spacing:
            keep.append(index)
            last = points[index]
    keep.append(len(points) - 1)
    points, fractions = points[keep], fractions[keep]
    lengths = np.linalg.norm(np.diff(points, axis=0), axis=1)
    pieces = np.maximum(np.ceil(lengths / spacing).astype(int), 1)
    out_points, out_u = [points[:1]], [fractions[:1]]
    for index, count in enumerate(pieces):
        share = np.arange(1, count + 1)[:, None] / count
        out_points.append(points[index] + share * (points[index + 1] - points[index]))
        out_u.append(fractions[index] + share[:, 0] * (fractions[index + 1] - fractions[index]))
    points, u = np.vstack(out_points), np.concatenate(out_u)
    keep = np.concatenate([[True], np.diff(u) > 1e-12])
    return points[keep], u[keep]


# ---------------------------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------------------------
@dataclass
class SimTarget:
    """One executed motion (lengths in the scenario's unit, times in s)."""

    label: str
    commanded_error: float  # end of the commanded path vs the target
    measured_error: float  # measured TCP after settling vs the target
    approach_error: float | None
    engaged: bool | None
    contacts: dict  # part label -> penetration depth (scenario unit)
    peak_velocity: float  # commanded, fractions of the joint limits (largest joint)
    peak_acceleration: float
    measured_peak_velocity: float  # what the simulated joints did
    measured_peak_acceleration: float  # (over 10 ms windows)
    motion_time: float
    tracking_error: float  # largest distance between the commanded and the measured TCP
    within_limits: bool  # the commanded joint motion within the velocity and acceleration limits
    paused: float = 0.0  # closed loop: seconds the motion's own time stood (nearly) still
    axis_deviation: float | None = None  # pose scenarios: degrees between tool and target axes over the approach
    aligned: bool | None = None

    def task_success(self, threshold: float) -> bool:
        return bool(self.measured_error <= threshold and self.engaged is not False and not self.contacts
                    and self.within_limits and self.aligned is not False)

    def to_dict(self, threshold: float) -> dict:
        return {
            "commanded_error": round(self.commanded_error, 4), "measured_error": round(self.measured_error, 4),
            "approach_error": None if self.approach_error is None else round(self.approach_error, 4),
            "engaged": self.engaged, "contacts": sorted(self.contacts),
            "contact_depths": {k: round(v, 4) for k, v in sorted(self.contacts.items())},
            "peak_joint_velocity": round(self.peak_velocity, 4), "peak_joint_acceleration": round(self.peak_acceleration, 4),
            "measured_peak_joint_velocity": round(self.measured_peak_velocity, 4),
            "measured_peak_joint_acceleration": round(self.measured_peak_acceleration, 4), "paused_s": round(self.paused, 3),
            "motion_time_s": round(self.motion_time, 3), "tracking_error": round(self.tracking_error, 4),
            "within_limits": self.within_limits, "task_success": self.task_success(threshold),
            "axis_deviation_deg": None if self.axis_deviation is None else round(self.axis_deviation, 4),
            "aligned": self.aligned,
        }


@dataclass
class SimMethod:
    name: str
    targets: dict  # label -> SimTarget
    threshold: float

    @property
    def task_successes(self) -> int:
        return sum(t.task_success(self.threshold) for t in self.targets.values())

    @property
    def end_successes(self) -> int:
        return sum(t.measured_error <= self.threshold for t in self.targets.values())

    @property
    def engaged(self) -> int | None:
        values = [t.engaged for t in self.targets.values()]
        return None if any(v is None for v in values) else sum(values)

    @property
    def contacts(self) -> int:
        """Motions with at least one contact."""
        return sum(bool(t.contacts) for t in self.targets.values())

    @property
    def within_limits(self) -> int:
        return sum(t.within_limits for t in self.targets.values())

    @property
    def aligned(self) -> int | None:
        values = [t.aligned for t in self.targets.values()]
        return None if any(v is None for v in values) else sum(values)

    def to_dict(self) -> dict:
        return {"task_successes": self.task_successes, "end_successes": self.end_successes, "engaged": self.engaged,
                "aligned": self.aligned,
                "contacts": self.contacts, "within_limits": self.within_limits, "n_targets": len(self.targets),
                "targets": {label: t.to_dict(self.threshold) for label, t in self.targets.items()}}


@dataclass
class SimReport:
    scenario: object
    methods: dict  # name -> SimMethod
    base: np.ndarray
    yaw: float
    closed_loop: bool
    simulated_s: float = 0.0
    wall_s: float = 0.0
    pictures: list = field(default_factory=list)
    workers: int = 1

    def to_dict(self) -> dict:
        return {"scenario": self.scenario.name, "units": self.scenario.units, "closed_loop": self.closed_loop,
                "robot": {"base": np.round(self.base, 3).tolist(), "yaw_deg": self.yaw},
                "success_threshold": self.scenario.success_threshold,
                "limits": {"velocity_rad_s": list(PANDA.velocity), "acceleration_rad_s2": list(PANDA.acceleration),
                           "timed_to": LIMIT_MARGIN},
                "methods": {name: method.to_dict() for name, method in self.methods.items()}}

    def rows(self) -> tuple[list[str], list[list[str]]]:
        poses = any(method.aligned is not None for method in self.methods.values())
        header = ["method", "end point", "engaged"] + (["aligned"] if poses else []) + \
            ["contacts", "within limits", "task success", "motion time s"]
        rows = []
        for name, method in self.methods.items():
            n = len(method.targets)
            times = [t.motion_time for t in method.targets.values()]
            row = [name, f"{method.end_successes}/{n}", "-" if method.engaged is None else f"{method.engaged}/{n}"]
            if poses:
                row.append("-" if method.aligned is None else f"{method.aligned}/{n}")
            rows.append(row + [f"{method.contacts}/{n}", f"{method.within_limits}/{n}", f"{method.task_successes}/{n}",
                               f"{min(times):.1f}-{max(times):.1f}"])
        return header, rows

    def summary(self) -> str:
        scenario = self.scenario
        aligned = (f", tool axis within {scenario.alignment_threshold:g} deg of the nut's" if scenario.is_pose else "")
        lines = [f"{scenario.name} on a simulated Franka Panda (PyBullet, 1 kHz position control), robot base "
                 f"{np.round(self.base, 1).tolist()} {scenario.units}, {'closed' if self.closed_loop else 'open'} loop",
                 f"task success = measured end point <= {scenario.success_threshold:g} {scenario.units}, engaged{aligned}, "
                 f"no contact with another part, joints within the Panda's velocity and acceleration limits", "",
                 text_table(*self.rows())]
        if self.wall_s > 0:
            lines.append(f"\nsimulated {self.simulated_s:.1f} s in {self.wall_s:.1f} s wall time "
                         f"({self.simulated_s / self.wall_s:.1f}x real time, {self.workers} worker process"
                         f"{'es' if self.workers > 1 else ''})")
        return "\n".join(lines)

    def markdown(self) -> str:
        return markdown_table(*self.rows())


def _measure(scenario: dict, label: str, target: np.ndarray, plan: MotionPlan, run: Execution, unit: float,
             closed_loop: bool) -> SimTarget:
    """The per-target results of one execution (``scenario``: its targets, units, threshold)."""
    tcp = run.tcp / unit
    measured_error = float(np.linalg.norm(tcp[-1] - target))
    commanded_error = float(np.linalg.norm(plan.points[-1] / unit - target))
    approach = deviation = None
    axis = scenario.get("axes", {}).get(label)
    if scenario["approach_height"] is not None:
        approach = approach_error(tcp, target, scenario["approach_height"], axis)
        if scenario.get("alignment_threshold") is not None:
            deviation = axis_deviation(tcp, run.tcp_orientation, target, scenario["approach_height"], axis)
    velocity = float(np.max(np.abs(run.joint_velocities) / np.asarray(PANDA.velocity)))
    if closed_loop:  # no plan timed it: the commands the stepper produced, 100 Hz
        command_velocity = np.diff(run.command_joints, axis=0) / CONTROL_STEP
        command_acceleration = np.diff(command_velocity, axis=0) / CONTROL_STEP
        peak_velocity = float(np.max(np.abs(command_velocity) / np.asarray(PANDA.velocity)))
        peak_acceleration = float(np.max(np.abs(command_acceleration) / np.asarray(PANDA.acceleration)))
        motion_time = float(run.times[-1]) - SETTLE
    else:
        peak_velocity, peak_acceleration, motion_time = plan.peak_velocity, plan.peak_acceleration, plan.duration
    return SimTarget(
        label=label, commanded_error=commanded_error, measured_error=measured_error, approach_error=approach,
        engaged=None if approach is None else bool(approach <= scenario["success_threshold"]),
        contacts={k: v / unit for k, v in run.contacts.items()}, peak_velocity=peak_velocity,
        peak_acceleration=peak_acceleration, measured_peak_velocity=velocity,
        measured_peak_acceleration=_measured_acceleration(run), motion_time=motion_time,
        tracking_error=float(np.max(np.linalg.norm(run.tcp - run.commanded_tcp, axis=1)) / unit),
        within_limits=bool(peak_velocity <= 1.0 + 1e-9 and peak_acceleration <= 1.0 + 1e-9), paused=run.paused,
        axis_deviation=deviation,
        aligned=None if deviation is None else bool(deviation <= scenario["alignment_threshold"]))


def _measured_acceleration(run: Execution) -> float:
    """Peak joint acceleration (fraction of the limits) of a measured run, over 10 ms windows."""
    window = int(round(0.01 / (SIM_STEP * RECORD_EVERY)))
    velocity = run.joint_velocities[::window]
    acceleration = np.diff(velocity, axis=0) / (window * SIM_STEP * RECORD_EVERY)
    return float(np.max(np.abs(acceleration) / np.asarray(PANDA.acceleration))) if len(acceleration) else 0.0


@dataclass
class _Job:
    """One motion to execute (what a worker process needs, picklable)."""

    method: str
    label: str
    rollout: np.ndarray  # (n, 3) scenario units
    exclude: list
    frames: int
    orientations: np.ndarray | None = None  # (n, 4) a pose skill's tool frames


def _run_jobs(setup: dict, jobs: list, progress=None) -> list:
    """Execute ``jobs`` in one PyBullet world; returns (method, label, SimTarget, frames, seconds)."""
    from ..scene.geometry import Scene

    scenario = setup["scenario"]
    scene = Scene.from_dict(setup["scene"], scenario["targets"])
    results = []
    with PandaCell(scene, scenario["units"], setup["base"], setup["yaw"]) as cell:
        for job in jobs:
            if progress is not None:
                progress(job.method, job.label)
            plan = cell.plan(job.rollout, job.label, orientations=job.orientations)
            if setup["closed_loop"] and job.orientations is not None:
                raise ValueError("closed_loop runs position skills; this scenario's are poses")
            target = np.asarray(scenario["targets"][job.label], dtype=float)[:3]
            if setup["closed_loop"]:
                stepper = _stepper(setup["models"], job.method, target, plan.duration, setup["coupling"])
                run = cell.execute_closed_loop(stepper, plan.duration, job.exclude, setup["hold"], job.frames)
            else:
                run = cell.execute(plan, job.exclude, setup["hold"], job.frames)
            measured = _measure(scenario, job.label, target, plan, run, cell.unit, setup["closed_loop"])
            results.append((job.method, job.label, measured, run.frames, float(run.times[-1])))
    return results


def _run_chunk(setup: dict, jobs: list) -> list:
    return _run_jobs(setup, jobs)


def simulate(scenario, methods=("dmp", "bidmp"), *, closed_loop: bool = False, targets=None, hold: Hold | None = None,
             coupling: float | None = None, progress=None, frames: dict | None = None, report=None,
             workers: int | None = None) -> SimReport:
    """Execute ``methods`` on every target of ``scenario`` on the simulated Panda.

    Parameters
    ----------
    scenario : Scenario or str
        Needs a ``"scene"``; ``"robot": {"base": [x, y, z], "yaw": deg}`` places the arm
        (default :func:`robot_placement`).
    methods : sequence of str
        Evaluation methods (dmp, bidmp, ...): their rollouts are what is executed.
    closed_loop : bool
        Run the DMP/Bi-DMP stepper on the measured TCP with phase stopping, for dmp and bidmp.
    coupling : float, optional
        Phase stopping's ``alpha_e`` in 1/unit² (default :data:`COUPLING` per m², 0.5 /mm²: a
        0.3 mm lag slows the motion by 5 %, a 3 mm one 5.5 times).
    targets : list of str, optional
        A subset of the targets (default all).
    hold : Hold, optional
        A scripted disturbance in every motion.
    progress : callable, optional
        Called with ``(method, label)`` as each motion starts (in-process) or finishes (workers).
    frames : dict, optional
        ``{(method, label): n}``: render n frames of those motions (PyBullet's TinyRenderer).
    report : bidmp.evaluation.Report, optional
        A finished evaluation of the same scenario to take the rollouts from.
    workers : int, optional
        Worker processes, each with its own PyBullet world (default: one per core, at most 2;
        1 runs in this process). Results do not depend on it.

    Returns
    -------
    SimReport
    """
    from ..tasks import scenarios as scenario_module
    from ..tasks.evaluation import evaluate

    if not isinstance(scenario, scenario_module.Scenario):
        scenario = scenario_module.load(scenario)
    if scenario.scene is None:
        raise ValueError(f"scenario {scenario.name!r} has no \"scene\": the simulator needs the parts and the tool")
    _pybullet()  # fail early, with the install command, when the extra is missing
    methods = list(dict.fromkeys(methods))
    if not methods:
        raise ValueError("methods is empty: name at least one of dmp, bidmp, ...")
    labels = scenario.labels if targets is None else list(targets)
    for label in labels:
        if label not in scenario.targets:
            raise ValueError(f"unknown target {label!r}; the scenario's targets: {', '.join(scenario.labels[:20])}")
    from ..tasks import methods as registry

    open_only = [name for name in methods if not registry.get(name).closed_loop]
    if closed_loop and open_only:
        raise ValueError(f"closed_loop runs the methods' steppers: {', '.join(open_only)} has none (methods with one: "
                         f"{', '.join(registry.names(closed_loop=True))})")
    coupling = COUPLING * _unit(scenario.units) ** 2 if coupling is None else check_real(coupling, "coupling", nonnegative=True)
    if report is None:
        report = evaluate(scenario, methods, geometry=False)
    base, yaw = robot_placement(scenario)
    scene = scenario.scene
    frames = frames or {}
    jobs = [_Job(method, label, np.asarray(report.methods[method].rollouts[label]),
                 scene.target_parts(label, scenario.targets[label]),
                 int(frames.get((method, label), 0)),
                 None if report.methods[method].orientations is None else report.methods[method].orientations[label])
            for method in methods for label in labels]
    models = {name: report.fitted[name] for name in methods} if closed_loop else None
    setup = {"scenario": {"targets": {k: v.tolist() for k, v in scenario.targets.items()}, "units": scenario.units,
                          "approach_height": scenario.approach_height, "success_threshold": scenario.success_threshold,
                          "axes": {label: None if scenario.target_axis(label) is None else scenario.target_axis(label).tolist()
                                   for label in labels},
                          "alignment_threshold": scenario.alignment_threshold if scenario.is_pose else None},
             "scene": scene.to_dict(), "base": base.tolist(), "yaw": yaw, "closed_loop": closed_loop, "hold": hold,
             "coupling": coupling, "models": models}
    n_workers = min(2, os.cpu_count() or 1) if workers is None else check_int(workers, "workers", minimum=1, maximum=64)
    n_workers = max(1, min(n_workers, len(jobs)))
    start = time.perf_counter()
    if n_workers == 1:
        outcomes = _run_jobs(setup, jobs, progress)
    else:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor, as_completed

        # Interleaved chunks balance long and short motions. "fork" (where there is one) starts
        # the workers in milliseconds and works from any __main__; "spawn" elsewhere.
        chunks = [jobs[k::n_workers] for k in range(n_workers)]
        outcomes = []
        method = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"
        with ProcessPoolExecutor(n_workers, mp_context=multiprocessing.get_context(method)) as pool:
            futures = [pool.submit(_run_chunk, setup, chunk) for chunk in chunks]
            for future in as_completed(futures):
                for outcome in future.result():
                    if progress is not None:
                        progress(outcome[0], outcome[1])
                    outcomes.append(outcome)
    by_key = {(method, label): (measured, images, seconds) for method, label, measured, images, seconds in outcomes}
    out = SimReport(scenario, {}, base, yaw, closed_loop)
    for method in methods:
        out.methods[method] = SimMethod(method, {label: by_key[(method, label)][0] for label in labels},
                                        scenario.success_threshold)
        for label in labels:
            if by_key[(method, label)][1]:
                out.pictures.append((method, label, by_key[(method, label)][1]))
    out.simulated_s = sum(value[2] for value in by_key.values())
    out.wall_s = time.perf_counter() - start
    out.workers = n_workers
    return out


def _stepper(models, method, goal, duration, coupling):
    """The registered method's stepper to ``goal`` on its fitted model."""
    from ..tasks import methods as registry

    return registry.get(method).stepper(models[method], goal, duration, coupling)


# ---------------------------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------------------------
def write_sim_report(report: SimReport, out) -> list[Path]:
    """``sim_results.json``, ``sim.md`` (the table), a keyframe strip per method and, when both dmp and bidmp have
    frames of the same target, an animated GIF of the two side by side."""
    from ..io.files import atomic_write

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = [out / "sim_results.json", out / "sim.md"]
    with atomic_write(written[0], "w") as handle:
        json.dump(report.to_dict(), handle, indent=2)
    with atomic_write(written[1], "w") as handle:
        handle.write(report.markdown() + "\n")
    by_method = {}
    for method, label, frames in report.pictures:
        by_method.setdefault(method, (label, frames))
    for method, (_, frames) in by_method.items():
        written.append(_write_strip(out / f"sim_keyframes_{method}.png", frames[:: max(1, len(frames) // 6)][:6]))
    if {"dmp", "bidmp"} <= set(by_method) and by_method["dmp"][0] == by_method["bidmp"][0]:
        written.append(_write_gif(out / f"sim_{by_method['dmp'][0]}_dmp_vs_bidmp.gif", by_method["dmp"][1], by_method["bidmp"][1]))
    return written


def _write_strip(path: Path, frames) -> Path:
    from PIL import Image

    from ..io.files import atomic_write

    strip = np.concatenate(frames, axis=1)
    with atomic_write(path, "wb") as handle:
        Image.fromarray(strip).save(handle, format="PNG")
    return path


def _write_gif(path: Path, left, right) -> Path:
    from PIL import Image

    from ..io.files import atomic_write

    n = min(len(left), len(right))
    images = [Image.fromarray(np.concatenate([left[i], np.full((left[i].shape[0], 6, 3), 255, np.uint8), right[i]], axis=1))
              for i in range(n)]
    with atomic_write(path, "wb") as handle:
        images[0].save(handle, format="GIF", save_all=True, append_images=images[1:], duration=120, loop=0)
    return path

