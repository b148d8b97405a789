"""An ideal arm in memory: the simulator backend with no physics and no extra.

:class:`KinematicCell` is a six-joint arm whose inverse kinematics is exact: three prismatic
joints carry the tool's mouth (metres from the base, in the base's frame turned by ``yaw``) and
three wrist joints turn the tool (a rotation vector, radians, from the tool pointing down). It
follows every command exactly: the measured motion *is* the command, sampled as the PyBullet arm's
is (1 kHz commands, 500 Hz records, the settling at the end). Contacts are the scene's geometry
(the swept tool's deepest penetration of a part, from :meth:`bidmp.Scene.clearance`); a released
part drops straight down onto whatever is under it; nothing is drawn (pictures are a plain grey).

What it is for: running ``simulate``, the job and every command that takes ``--backend`` anywhere
(a CI machine, a laptop without PyBullet) and testing the backend seam itself — the contract, the
repairs and the job's steps judged on an arm that does exactly what it is told. What it is not: a
test of tracking, dynamics or contact physics (use the PyBullet backend); a scripted joint hold
needs dynamics and is refused.
"""

from __future__ import annotations

import logging
import math

import numpy as np
from scipy.spatial.transform import Rotation

from .._checks import as_labels, as_point, check_int, check_real
from .backend import (
    CONTROL_STEP,
    LIMIT_MARGIN,
    RECORD_EVERY,
    SETTLE,
    SIM_STEP,
    Execution,
    GoalUpdate,
    Hold,
    JointLimits,
    MotionPlan,
    SimError,
    _check_solids,
    _part_args,
    _picture_args,
    _solid_height,
)
from .limits import _hermite, _joint_velocity, _RateLimiter
from .robots import MAX_SAMPLE_SPACING, _unit_of

__all__ = ["KinematicCell", "KINEMATIC_LIMITS"]

logger = logging.getLogger(__name__)

_DOWN = Rotation.from_quat([1.0, 0.0, 0.0, 0.0])  # the tool pointing down (its z along -z)
# Joint limits: the carriage (m, m/s, m/s², m/s³) and the wrist (rad, ...); a cobot's pace.
KINEMATIC_LIMITS = JointLimits(
    lower=(-1.5, -1.5, -1.5, -math.pi, -math.pi, -math.pi),
    upper=(1.5, 1.5, 1.5, math.pi, math.pi, math.pi),
    velocity=(1.0, 1.0, 1.0, 2.5, 2.5, 2.5),
    acceleration=(5.0, 5.0, 5.0, 10.0, 10.0, 10.0),
    jerk=(200.0, 200.0, 200.0, 500.0, 500.0, 500.0),
)
_REST = (0.3, 0.0, 0.45, 0.0, 0.0, 0.0)  # the tool 0.3 m ahead of the base, 0.45 m up, down
_GREY = 200


class KinematicCell:
    """An ideal six-joint arm in a scene's world, in memory (module docstring).

    Parameters
    ----------
    scene : bidmp.Scene
    units : str
        The scene's length unit ("mm", "cm" or "m").
    base : array (3,)
        The arm's base in the scene's unit.
    yaw : float
        The base's turn about z in degrees (the carriage's x axis points along ``yaw``).
    """

    name = "kinematic arm"
    simulator = "in memory: ideal tracking, contacts from the geometry, no physics"
    limits = KINEMATIC_LIMITS
    rest = _REST
    n_joints = 6
    # the carriage's three prismatic joints (m), then the wrist's rotation vector (rad)
    joint_names = ("carriage_x", "carriage_y", "carriage_z", "wrist_x", "wrist_y", "wrist_z")
    joint_units = ("m", "m", "m", "rad", "rad", "rad")

    def __init__(self, scene, units: str = "mm", base=(0.0, -450.0, 0.0), yaw: float = 90.0):
        from ..scene import Scene

        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a bidmp.Scene, got {type(scene).__name__}")
        self.scene = scene
        self.unit = _unit_of(units)
        self.base = as_point(base, 3, "base")
        self.yaw = check_real(yaw, "yaw")
        self._frame = Rotation.from_euler("z", self.yaw, degrees=True)
        self._q = np.array(_REST)
        self._solids = list(scene.solids)  # the scene's and any added (the job's bin, its rack)
        self._parts: dict[str, _KinematicPart] = {}

    @classmethod
    def load_robot(cls, scene, units: str = "mm", base=(0.0, -450.0, 0.0), yaw=90.0, **robot):
        """The backend protocol's constructor; a scenario's ``robot`` model is not this arm's (it
        is logged and left aside)."""
        if robot:
            logger.info("the kinematic cell is its own arm: the scenario's robot model is not used")
        return cls(scene, units, base, yaw)

    def close(self) -> None:
        """Nothing to release (the protocol's)."""

    # -- kinematics ---------------------------------------------------------------------------
    def fk(self, q) -> np.ndarray:
        """The tool's mouth (m) at joints ``q`` (6,)."""
        q = as_point(q, 6, "q")
        return self.base * self.unit + self._frame.apply(q[:3])

    forward = fk

    def _orientation(self, q: np.ndarray) -> Rotation:
        return _DOWN * Rotation.from_rotvec(q[3:])

    def solve_ik(self, point_m, seed, orientation=None) -> tuple[np.ndarray, float]:
        """Joints that put the tool's mouth at ``point_m`` (m) with the tool's frame at
        ``orientation`` (x, y, z, w; default pointing down): exact, so the error left is 0 inside
        the limits (``seed`` only keeps the wrist's turn on the seed's side)."""
        point = as_point(point_m, 3, "point_m")
        seed = as_point(seed, 6, "seed")
        carriage = self._frame.inv().apply(point - self.base * self.unit)
        turn = (
            np.zeros(3)
            if orientation is None
            else (
                _DOWN.inv() * Rotation.from_quat(as_point(orientation, 4, "orientation"))
            ).as_rotvec()
        )
        if np.linalg.norm(turn - seed[3:]) > math.pi:  # the same turn, nearer the seed
            angle = np.linalg.norm(turn)
            if angle > 0.0:
                turn = turn - 2.0 * math.pi * turn / angle
        q = np.concatenate([carriage, turn])
        inside = np.clip(q, self.limits.lower, self.limits.upper)
        error = float(np.linalg.norm(self.fk(inside) - point))
        return inside, error

    def joint_origins(self, q) -> np.ndarray:
        """The carriage's corners from the base to the tool's mouth (m), (4, 3)."""
        q = as_point(q, 6, "q")
        base = self.base * self.unit
        steps = np.cumsum(np.diag(q[:3]), axis=0)
        return np.vstack([base, base + self._frame.apply(steps)])

    def tcp_position(self) -> np.ndarray:
        """The tool's mouth now (m)."""
        return self.fk(self._q)

    def tool_orientation(self) -> np.ndarray:
        """The tool's frame now (x, y, z, w)."""
        return self._orientation(self._q).as_quat()

    # -- motions ------------------------------------------------------------------------------
    def plan(
        self,
        path,
        label: str = "",
        fractions=None,
        seed=None,
        orientations=None,
        spacing: float = MAX_SAMPLE_SPACING,
    ) -> MotionPlan:
        """The path's IK samples splined and timed within the limits
        (:func:`bidmp.sim.planning.plan_path`)."""
        from .planning import plan_path

        return plan_path(self, path, label, fractions, seed, orientations, spacing)

    def execute(
        self,
        plan: MotionPlan,
        exclude=(),
        hold: Hold | None = None,
        frames: int = 0,
        on_record=None,
    ) -> Execution:
        """Follow ``plan`` exactly at 1 kHz, then hold still for the settling; ``on_record(t)``
        after every recorded step (500 Hz)."""
        if not isinstance(plan, MotionPlan):
            raise TypeError(f"plan must be a MotionPlan (from plan()), got {type(plan).__name__}")
        frames = check_int(frames, "frames", minimum=0, maximum=1000)
        exclude = as_labels(exclude, "exclude")
        if on_record is not None and not callable(on_record):
            raise TypeError(
                f"on_record must be callable as on_record(t), got {type(on_record).__name__}"
            )
        _refuse_hold(hold)
        n_steps = int(math.ceil((plan.duration + SETTLE) / SIM_STEP))
        positions, velocities = plan.command(np.arange(n_steps) * SIM_STEP)
        rows = np.unique(np.r_[np.arange(0, n_steps, RECORD_EVERY), n_steps - 1])
        times = (rows + 1) * SIM_STEP
        for row, step in enumerate(rows):
            self._q = positions[step]
            if on_record is not None:
                on_record(float(times[row]))
        run = self._execution(times, positions[rows], velocities[rows], exclude, frames)
        run.commands = positions
        return run

    def execute_closed_loop(
        self,
        stepper,
        duration: float,
        exclude=(),
        hold: Hold | None = None,
        frames: int = 0,
        max_factor: float = 4.0,
        goal_update: GoalUpdate | None = None,
    ) -> Execution:
        """Run ``stepper`` (scene units) at 100 Hz on the tool's mouth, which is where the last
        command put it. The commands are the PyBullet arm's: every 1 ms the cubic between the
        last two 100 Hz targets through the jerk-limited rate limiter
        (:class:`bidmp.sim.limits._RateLimiter`), so they are within the limits; the arm follows
        them exactly. The run ends when the stepper's time reaches its horizon (at most
        ``max_factor`` times ``duration``), then the settling."""
        frames = check_int(frames, "frames", minimum=0, maximum=1000)
        exclude = as_labels(exclude, "exclude")
        _refuse_hold(hold)
        q, error = self.solve_ik(np.asarray(stepper.y) * self.unit, self.rest)
        if error > 1e-9:
            raise SimError(f"the start {np.round(stepper.y, 2).tolist()} is out of the arm's reach")
        every = int(round(CONTROL_STEP / SIM_STEP))
        complete = float(getattr(stepper, "horizon", duration))
        n_steps = int(math.ceil((max_factor * max(duration, complete) + SETTLE) / SIM_STEP))
        limited = _RateLimiter(q, self.limits, LIMIT_MARGIN)
        target = previous = q
        target_rate = previous_rate = np.zeros_like(q)
        sent, rates, times, targets, clock = [], [], [], [], []
        settle_from, updated = None, False
        for step in range(n_steps):
            if step % every == 0:
                previous, previous_rate = target, target_rate
                if settle_from is not None and step - settle_from >= SETTLE / SIM_STEP:
                    break
                if settle_from is None:
                    if goal_update is not None and not updated and stepper.time >= goal_update.time:
                        stepper.set_goal(stepper.target + np.asarray(goal_update.offset))
                        updated = True
                    # the arm is where it was sent: the stepper's own position is what it measures
                    y, yd, _ = stepper.step(CONTROL_STEP, stepper.position)
                    point = np.asarray(y) * self.unit
                    target, _ = self.solve_ik(point, target)
                    target_rate = _joint_velocity(self, target, point, np.asarray(yd) * self.unit)
                else:
                    target_rate = np.zeros_like(target)
                times.append(step * SIM_STEP)
                targets.append(target)
                clock.append(stepper.time)
                if settle_from is None and stepper.time >= complete:
                    settle_from = step
            share = (step % every + 1) / every
            sent.append(
                limited(
                    *_hermite(previous, previous_rate, target, target_rate, share, CONTROL_STEP)
                )
            )
            rates.append(limited.velocity.copy())
        commands, velocities = np.array(sent), np.array(rates)
        rows = np.unique(np.r_[np.arange(0, len(sent), RECORD_EVERY), len(sent) - 1])
        self._q = commands[-1]
        run = self._execution(
            (rows + 1) * SIM_STEP, commands[rows], velocities[rows], exclude, frames
        )
        run.command_times, run.command_joints, run.motion_clock = (
            np.array(times),
            np.array(targets),
            np.array(clock),
        )
        run.commands = commands
        return run

    def _execution(self, times, joints, velocities, exclude, frames: int) -> Execution:
        """What the arm did: exactly the commands at the recorded samples, and its contacts."""
        tcp = self.base * self.unit + self._frame.apply(joints[:, :3])
        orientations = (_DOWN * Rotation.from_rotvec(joints[:, 3:])).as_quat()
        run = Execution(
            np.asarray(times, dtype=float),
            tcp,
            joints,
            velocities,
            tcp.copy(),
            self._contacts(tcp, orientations, exclude),
            [self.render() for _ in range(int(frames))],
        )
        run.tcp_orientation = orientations
        return run

    def _contacts(self, tcp: np.ndarray, orientations: np.ndarray, exclude=()) -> dict:
        """Part label -> how deep (m) the swept tool went into it: the scene's geometry."""
        clearance = self.scene.clearance(
            tcp / self.unit, exclude=exclude, orientations=orientations
        )
        if clearance.part is None or clearance.distance >= 0.0:
            return {}
        return {clearance.part: -float(clearance.distance) * self.unit}

    def contacts(self) -> dict:
        """Part label -> penetration depth (m) of the tool now."""
        point = self.tcp_position()[None]
        return self._contacts(point, self.tool_orientation()[None])

    # -- the job's world ----------------------------------------------------------------------
    def add_solids(self, solids) -> None:
        """More static parts (the job's bin, its rack): what released parts land on, and what the
        tool's contacts are measured against (as the scene's own parts are)."""
        from ..scene import Scene
        from ..scene.parts import Part

        solids = _check_solids(solids)
        self._solids.extend(solids)
        known = set(self.scene.labels)
        grouped: dict = {}
        for solid in solids:
            if solid.part not in known:
                grouped.setdefault(solid.part, []).append(solid)
        if grouped:
            scene = self.scene
            added = [Part(label, "box", {}, tuple(group)) for label, group in grouped.items()]
            self.scene = Scene(
                (*scene.parts, *added),
                scene.tool,
                scene.targets,
                scene.targets_on_parts,
                scene.margin,
                scene.standoff,
            )

    def movable_part(self, label: str, mass: float) -> _KinematicPart:
        """The scene's part ``label`` as one the job moves."""
        part = _KinematicPart(self, label, mass)
        self._parts[label] = part
        return part

    def settle(self, seconds: float) -> None:
        """The world holds still (a released part has already landed)."""
        check_real(seconds, "seconds", nonnegative=True, maximum=60.0)

    def render(self, width: int = 320, height: int = 240, target=None) -> np.ndarray:
        """A plain grey picture (this backend draws nothing; ``target`` is checked as the PyBullet
        arm's is: a point in scene units, or None)."""
        width, height = _picture_args(width, height)
        if target is not None:
            as_point(target, 3, "target")
        return np.full((height, width, 3), _GREY, dtype=np.uint8)

    def keyframe(self, t: float, focus, width: int = 320, height: int = 240) -> np.ndarray:
        """A plain grey keyframe of the PyBullet arm's size (this backend draws nothing)."""
        check_real(t, "t", nonnegative=True)
        as_point(focus, 3, "focus")
        width, height = _picture_args(width, height)
        return np.full((2 * height, width, 3), _GREY, dtype=np.uint8)

    def _landing(self, part: _KinematicPart, centre: np.ndarray) -> float:
        """The height (scene units) of the highest top under ``centre`` and below the part's
        bottom: a solid still in place, or a part at rest (with nothing under it, the ground: the
        lowest point of the world)."""
        bottom = centre[2] - part.height / 2.0
        moved = {label for label, other in self._parts.items() if other.state != "seated"}
        tops = [min(float(solid.lower[2]) for solid in self._solids)]
        for solid in self._solids:
            if solid.label == part.label or solid.part in moved:
                continue
            lower, upper = np.asarray(solid.lower), np.asarray(solid.upper)
            over = np.all(lower[:2] <= centre[:2]) and np.all(centre[:2] <= upper[:2])
            if over and upper[2] <= bottom + 1e-9:
                tops.append(float(upper[2]))
        for other in self._parts.values():
            if other is part or other.state != "at rest":
                continue
            other_centre, _ = other.pose()
            top = other_centre[2] + other.height / 2.0
            near = np.linalg.norm(other_centre[:2] - centre[:2]) <= other.radius
            if near and top <= bottom + 1e-9:
                tops.append(float(top))
        return max(tops)


class _KinematicPart:
    """A part the job moves in the kinematic cell: seated → (threading) → held → released →
    at rest. Poses in scene units."""

    def __init__(self, cell: KinematicCell, label: str, mass: float):
        self.solid, mass = _part_args(cell.scene, label, mass)
        self.cell, self.label, self.mass = cell, label, mass
        self.centre0 = np.asarray(self.solid.centre, dtype=float)
        self.rotation0 = Rotation.from_matrix(self.solid.rotation)
        self.axis = np.asarray(self.solid.rotation)[:, 2]
        self.height = _solid_height(self.solid)
        self.radius = 0.5 * float(np.max(np.ptp([self.solid.lower, self.solid.upper], axis=0)[:2]))
        self.state, self.rise = "seated", 0.0
        self.trace: list[tuple[float, float, float]] = []
        self._centre, self._rotation = self.centre0.copy(), self.rotation0
        self._grip = None  # (offset, rotation) in the tool's frame while held

    def pose(self) -> tuple[np.ndarray, Rotation]:
        """Its centre (3,) and rotation now; held, where the tool carries it."""
        if self._grip is not None:
            tool = Rotation.from_quat(self.cell.tool_orientation())
            mouth = self.cell.tcp_position() / self.cell.unit
            offset, rotation = self._grip
            return mouth + tool.apply(offset), tool * rotation
        return self._centre.copy(), self._rotation

    def thread(self, rise: float, pitch: float, t: float) -> None:
        """Risen ``rise`` on its thread, turned ``rise / pitch`` turns (loosening only)."""
        self.state, self.rise = "threading", max(self.rise, float(rise))
        angle = 2.0 * math.pi * self.rise / pitch
        self._centre = self.centre0 + self.axis * self.rise
        self._rotation = Rotation.from_rotvec(self.axis * angle) * self.rotation0
        self.trace.append((self.rise, angle, t))

    def hold(self) -> None:
        """Held by the tool from now on, where it is."""
        tool = Rotation.from_quat(self.cell.tool_orientation())
        mouth = self.cell.tcp_position() / self.cell.unit
        self._grip = (tool.inv().apply(self._centre - mouth), tool.inv() * self._rotation)
        self.state = "held"

    def contacts(self, found: dict, ignore=()) -> None:
        """A carried part's contacts are not modelled here (the contract's geometry judges its
        clearance)."""

    def release(self) -> None:
        """Let go: it drops straight down onto what is under it."""
        centre, rotation = self.pose()
        self._grip = None
        self.state = "released"
        centre[2] = self.cell._landing(self, centre) + self.height / 2.0
        self._centre, self._rotation = centre, rotation

    def rest(self) -> None:
        """It has come to rest where it landed."""
        self.state = "at rest"


def _refuse_hold(hold) -> None:
    if hold is not None and not isinstance(hold, Hold):
        raise TypeError(f"hold must be a bidmp.sim.Hold (or None), got {type(hold).__name__}")
    if hold is not None:
        raise ValueError(
            "hold: the kinematic cell follows its commands exactly, so a held joint would jump "
            "back when let go; a scripted hold needs dynamics: use backend='pybullet'"
        )
