"""The simulator backend protocol: what the simulated task runs need of a simulator and its robot,
and the backend-independent types they exchange (plans, executions, disturbances).

A backend is a class with a ``load_robot(scene, units, base, yaw)`` constructor and the members
of :class:`SimulatorBackend`; ``simulate(..., backend=...)`` and ``run_job(..., backend=...)`` run
on it, by class or by registered name (``bidmp sim --backend NAME``). The PyBullet arm
(:class:`bidmp.sim.pybullet.RobotCell`: the Panda, the iiwa, the xArm6, a UR5-class arm or a URDF)
is the default; :class:`bidmp.sim.kinematic.KinematicCell` is an ideal arm in memory (no physics,
no extra), what the tests run the whole seam on; another simulator or robot is one more module
registered with :func:`register_backend`.

Lengths inside a backend are metres, angles radians, times seconds; the scene is given in its own
unit (``units``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from .._checks import TaskRefusal, as_point, as_vector, check_int, check_real, short_token

__all__ = [
    "require_simulator",
    "SimulatorBackend",
    "MovablePart",
    "backend_names",
    "get_backend",
    "register_backend",
    "SimError",
    "JointLimits",
    "Hold",
    "GoalUpdate",
    "MotionPlan",
    "Execution",
    "SIM_STEP",
    "CONTROL_STEP",
    "LIMIT_MARGIN",
    "COUPLING",
    "RECORD_EVERY",
    "SETTLE",
]

SIM_STEP = 1e-3  # s: 1 kHz physics and position control
CONTROL_STEP = 1e-2  # s: the closed-loop stepper and its inverse kinematics run at 100 Hz
# motions are timed to this fraction of the joint velocity, acceleration and jerk limits
LIMIT_MARGIN = 0.9
COUPLING = 5e5  # 1/m²: phase stopping's default gain in closed loop (0.5 /mm²)
RECORD_EVERY = 2  # physics steps per recorded sample (500 Hz); contacts are checked every step
SETTLE = 0.3  # s held at the end before the end point is measured


class SimError(TaskRefusal):
    """A motion cannot be executed (unreachable, outside the joint limits); names the target."""


@dataclass(frozen=True)
class JointLimits:
    """Joint limits of an arm, one value per joint, base to flange: position (rad), velocity
    (rad/s), acceleration (rad/s²) and jerk (rad/s³; None: not checked); ``fci``: the Franka
    Control Interface table that judges the arm's 1 kHz commands as the robot does
    (:data:`bidmp.sim.fci.FCI_LIMITS`: ``"panda"``, ``"fr3"``; None: not a Franka arm)."""

    lower: tuple
    upper: tuple
    velocity: tuple
    acceleration: tuple
    jerk: tuple | None = None
    fci: str | None = None

    def __post_init__(self) -> None:
        counts = {}
        for name in ("lower", "upper", "velocity", "acceleration", "jerk"):
            value = getattr(self, name)
            if value is None and name == "jerk":
                continue
            values = as_vector(
                value, f"JointLimits.{name}", positive=name not in ("lower", "upper")
            )
            counts[name] = len(values)
            object.__setattr__(self, name, tuple(float(v) for v in values))
        if len(set(counts.values())) > 1:
            raise ValueError(
                "JointLimits: one value per joint in each of "
                + ", ".join(f"{name} ({count})" for name, count in counts.items())
            )
        if any(low >= high for low, high in zip(self.lower, self.upper)):
            raise ValueError("JointLimits.lower must be below JointLimits.upper for every joint")
        if self.fci is not None and (
            not isinstance(self.fci, str)
            or self.fci not in ("panda", "fr3")
            or len(self.lower) != 7
        ):
            raise ValueError(
                f"JointLimits.fci must be 'panda' or 'fr3' on a 7-joint arm, got "
                f"{short_token(self.fci, 40)}"
            )

    @property
    def n_joints(self) -> int:
        return len(self.lower)

    def reflex(self, commands) -> str:
        """The reflex the arm's FCI raises on joint-position ``commands`` (T, J) rad sent every
        1 ms, in words (:func:`bidmp.sim.fci.judge_commands`), or ``""``: accepted, or not a
        Franka arm. The motion contract asks it beside its own limits (it holds what the
        published ones leave out: the FR3's velocity limits fall towards its ranges' ends)."""
        if self.fci is None:
            return ""
        from .fci import judge_commands

        return judge_commands(commands, self.fci).reason()


@dataclass(frozen=True)
class Hold:
    """A scripted disturbance: joint ``joint`` (0-based, base first) held where it is from
    ``start`` for ``duration`` seconds of the motion."""

    joint: int
    start: float
    duration: float = 0.5

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "joint", check_int(self.joint, "Hold.joint", minimum=0, maximum=63)
        )
        object.__setattr__(self, "start", check_real(self.start, "Hold.start", nonnegative=True))
        object.__setattr__(
            self, "duration", check_real(self.duration, "Hold.duration", positive=True)
        )


@dataclass(frozen=True)
class GoalUpdate:
    """A scripted perception update (closed loop): at ``time`` seconds of the motion the target
    part turns out to be ``offset`` (3,) (scene units) away from where it was seen; the part moves
    there in the world and the stepper's goal with it (:meth:`DMPStepper.set_goal`)."""

    time: float
    offset: tuple

    def __post_init__(self) -> None:
        object.__setattr__(self, "time", check_real(self.time, "GoalUpdate.time", nonnegative=True))
        object.__setattr__(
            self, "offset", tuple(as_point(self.offset, 3, "GoalUpdate.offset").tolist())
        )


@dataclass
class MotionPlan:
    """A Cartesian path turned into a timed joint path (arrays in SI units: s, rad)."""

    label: str
    points: np.ndarray  # (n, 3) m, the IK samples (the path subdivided)
    fractions: np.ndarray  # (n,) normalised time of each sample in [0, 1]
    joints: np.ndarray  # (n, J) rad, J the arm's joints
    duration: float  # s
    spline: object  # q(u), u in [0, 1]: a scipy spline, q(u, order) its derivatives
    peak_velocity: float  # fraction of the limit, the largest over joints
    peak_acceleration: float
    orientations: np.ndarray | None = None  # (n, 4) the tool frame at the IK samples (pose skills)
    peak_jerk: float = 0.0  # fraction of the jerk limit (0 when the limits state none)

    def command(self, t) -> tuple[np.ndarray, np.ndarray]:
        """Joint positions and velocities commanded at time(s) ``t`` (s): (J,) or (n, J)."""
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
    # ... and the stepper's own time (s; stands still while paused)
    motion_clock: np.ndarray | None = None
    tcp_orientation: np.ndarray | None = None  # measured TCP frame (x, y, z, w)
    commands: np.ndarray | None = None  # (n, J) rad: the joint positions commanded every SIM_STEP
    # (start, end) s of a disturbance (a held joint): the world moved the arm then, not its commands
    disturbed: tuple | None = None

    @property
    def paused(self) -> float:
        """Seconds of the run during which the motion's own time ran at under a fifth of the
        clock's pace (closed loop; 0 otherwise)."""
        if self.motion_clock is None or len(self.motion_clock) < 2:
            return 0.0
        running = self.motion_clock[1:] < self.motion_clock[-1]  # not the settling at the end
        slow = np.diff(self.motion_clock) < 0.2 * np.diff(self.command_times)
        return float(np.sum(slow & running) * CONTROL_STEP)


class MovablePart(Protocol):
    """A part the job moves, as the backend's world holds it (``movable_part``): seated →
    threading (a nut) → held by the tool → released (it falls) → at rest. Poses in scene units.

    Attributes
    ----------
    label : str
    solid : bidmp.scene.Solid
        Its solid where it was seated.
    centre0 : array (3,)
        Its centre where it was seated.
    axis : array (3,)
        Its own z axis (the stud's, the lift's direction).
    height : float
        Its height along the axis.
    state : str
        "seated", "threading", "held", "released" or "at rest".
    rise : float
        How far it has risen on its thread.
    trace : list of (rise, angle, time)
        Its threading, as it went.
    """

    label: str
    solid: object
    centre0: np.ndarray
    axis: np.ndarray
    height: float
    state: str
    rise: float
    trace: list

    def pose(self) -> tuple[np.ndarray, object]:
        """Its centre (3,) and rotation (a scipy ``Rotation``) now."""

    def thread(self, rise: float, pitch: float, t: float) -> None:
        """Risen ``rise`` on its thread, turned ``rise / pitch`` turns (at ``t`` seconds)."""

    def hold(self) -> None:
        """Held by the tool from now on, where it is."""

    def contacts(self, found: dict, ignore=()) -> None:
        """Add its contacts with the scene's parts (not those in ``ignore``) to ``found``
        (label -> depth, scene units)."""

    def release(self) -> None:
        """Let go: it falls."""

    def rest(self) -> None:
        """It has come to rest where it lies."""


class SimulatorBackend(Protocol):
    """A simulated robot in a scene's world: what ``bidmp.sim`` (:func:`~bidmp.sim.simulate`, the
    job) asks of it. Lengths in metres, angles in radians, times in seconds unless said otherwise;
    any number of joints (``limits.n_joints``)."""

    unit: float  # metres per scene unit
    scene: object  # the bidmp.scene.Scene it was built from (the closed loop steers round it)
    limits: JointLimits  # the arm's, one value per joint
    base: np.ndarray  # the arm's base (scene units)
    name: str  # the arm's name, in reports
    simulator: str  # how reports name the simulator ("PyBullet, 1 kHz position control")
    rest: tuple  # the joints (rad) it starts from and IK is seeded with
    joint_names: tuple  # its driven joints' names, base to flange (a command file's header)
    joint_units: tuple  # each joint's unit: "rad" (revolute) or "m" (prismatic)

    @classmethod
    def load_robot(cls, scene, units: str, base, yaw: float, **robot) -> SimulatorBackend:
        """Build the world of ``scene`` (parts, tool) with the robot at ``base`` (scene units),
        turned ``yaw`` degrees about z (``robot``: the scenario's arm, for backends that take one)."""

    def solve_ik(self, point_m: np.ndarray, seed, orientation=None) -> tuple[np.ndarray, float]:
        """Joint positions that put the tool-centre point at ``point_m`` (m), from ``seed``; and the
        position error left (m)."""

    def fk(self, q) -> np.ndarray:
        """The tool-centre point (m) at joint positions ``q``."""

    def joint_origins(self, q) -> np.ndarray:
        """The arm's joint origins (m), base to tool, at ``q`` (what the 3-D viewer draws)."""

    def plan(
        self, path, label: str = "", fractions=None, seed=None, orientations=None, spacing=...
    ) -> MotionPlan:
        """A Cartesian path (n, 3, scene units) turned into a timed joint path within the limits
        (:func:`bidmp.sim.planning.plan_path` does it for any backend with the members above)."""

    def execute(
        self,
        plan: MotionPlan,
        exclude=(),
        hold: Hold | None = None,
        frames: int = 0,
        on_record=None,
    ) -> Execution:
        """Run ``plan`` open loop, the parts in ``exclude`` ignored for contacts; ``on_record(t)``
        after every recorded step."""

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
        """Run a DMP stepper on the measured tool-centre point (the parts in ``exclude`` moved by
        ``goal_update`` at its time, and the stepper's goal with them)."""

    def tcp_position(self) -> np.ndarray:
        """The measured tool-centre point now (m)."""

    def tool_orientation(self) -> np.ndarray:
        """The measured tool frame now (quaternion x, y, z, w)."""

    def contacts(self) -> dict:
        """Part label -> penetration depth (m) of the robot's contacts now."""

    def add_solids(self, solids) -> None:
        """More static parts in the world (the job's bin, its rack)."""

    def movable_part(self, label: str, mass: float) -> MovablePart:
        """The scene's part ``label`` (of ``mass`` kg) as one the job moves."""

    def settle(self, seconds: float) -> None:
        """Let the world run ``seconds`` with the arm holding still."""

    def render(self, width: int = 320, height: int = 240, target=None) -> np.ndarray:
        """An RGB image (height, width, 3) of the world."""

    def keyframe(self, t: float, focus, width: int = 320, height: int = 240) -> np.ndarray:
        """A labelled picture of the world at ``t`` seconds looking at ``focus`` (scene units)."""

    def close(self) -> None:
        """Release the simulator."""


# The backends by name (``bidmp sim --backend NAME``): the module and class, imported on first use.
_BACKENDS: dict[str, object] = {
    "pybullet": ("bidmp.sim.pybullet.cell", "RobotCell"),
    "kinematic": ("bidmp.sim.kinematic", "KinematicCell"),
    "mujoco": ("bidmp.sim.mujoco.cell", "MujocoCell"),
}


def backend_names() -> list[str]:
    """The registered backends' names."""
    return list(_BACKENDS)


def get_backend(name: str):
    """The backend class registered as ``name`` (``"pybullet"``: the PyBullet arm, the default;
    ``"kinematic"``: an ideal arm in memory, no physics, no extra)."""
    if not isinstance(name, str):
        raise TypeError(f"backend must be a backend's name (a string), got {type(name).__name__}")
    if name not in _BACKENDS:
        raise ValueError(
            f"name: unknown simulator backend {name[:40]!r} (known: {', '.join(_BACKENDS)})"
        )
    entry = _BACKENDS[name]
    if isinstance(entry, tuple):
        import importlib

        module, attribute = entry
        if name in ("pybullet", "mujoco"):
            require_simulator()
        if name == "mujoco":
            from .mujoco.world import _mujoco_module

            _mujoco_module()
        entry = getattr(importlib.import_module(module), attribute)
    return entry


def register_backend(name: str, backend) -> None:
    """Register ``backend`` (a class with :class:`SimulatorBackend`'s members) as ``name``, for
    ``simulate(backend=name)``, ``run_job(backend=name)`` and ``--backend``."""
    if not isinstance(name, str) or not name.isidentifier():
        raise ValueError(f"name must be an identifier, got {str(name)[:40]!r}")
    missing = [
        member
        for member in ("load_robot", "plan", "execute", "tcp_position", "close")
        if not callable(getattr(backend, member, None))
    ]
    if missing:
        raise TypeError(
            f"backend must provide SimulatorBackend's members; {getattr(backend, '__name__', type(backend).__name__)} "
            f"lacks {', '.join(missing)}"
        )
    _BACKENDS[name] = backend


def _part_args(scene, label, mass) -> tuple[object, float]:
    """A movable part's solid (the first of the scene's with ``label``) and mass (kg, > 0), checked."""
    if not isinstance(label, str):
        raise TypeError(f"label must be a part's label (a string), got {type(label).__name__}")
    mass = check_real(mass, "mass", positive=True, maximum=1e4)
    for solid in scene.solids:
        if solid.label == label:
            return solid, mass
    raise ValueError(f"label {short_token(label, 30)}: no part of the scene to take away has it")


def _check_solids(solids) -> list:
    """Solids to add to a world: a list of the scene's solids (bidmp.scene.Solid)."""
    from ..scene import Solid

    if not isinstance(solids, (list, tuple)) or not all(isinstance(s, Solid) for s in solids):
        raise TypeError("solids must be a list of bidmp.scene.Solid (a scene's solids)")
    return list(solids)


def _picture_args(width, height) -> tuple[int, int]:
    return (
        check_int(width, "width", minimum=8, maximum=4096),
        check_int(height, "height", minimum=8, maximum=4096),
    )


def _solid_height(solid) -> float:
    """A solid's height along its own z axis (scene units): what a part the job lifts rises by
    before it is clear of where it stood."""
    if solid.kind == "box":
        return float(solid.params[2])
    if solid.kind == "cylinder":
        return float(solid.params[1])
    return float(np.ptp(np.asarray(solid.params[0])[:, 2]))


def require_simulator() -> None:
    """Check that the simulator (the ``sim`` extra: PyBullet) is installed, before any work;
    without it :class:`bidmp.MissingExtraError` says how to install it."""
    from .pybullet.world import _pybullet_module

    _pybullet_module()
