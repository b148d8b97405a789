"""The simulator backend protocol: what the simulated task runs need of a simulator and its robot,
and the backend-independent types they exchange (plans, executions, disturbances).

A backend is a class with a ``load_robot(scene, units, base, yaw)`` constructor and the methods
of :class:`SimulatorBackend`; ``bidmp.sim.simulate(..., backend=...)`` runs the task on it. The
PyBullet arm (:class:`bidmp.sim.pybullet.RobotCell`: the Panda, the iiwa or a URDF) is the first; another simulator or
robot is one more subpackage beside it.

Lengths inside a backend are metres, angles radians, times seconds; the scene is given in its own
unit (``units``).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np

from .._checks import as_point, as_vector, check_int, check_real

__all__ = [
    "require_simulator",
    "SimulatorBackend",
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


class SimError(ValueError):
    """A motion cannot be executed (unreachable, outside the joint limits); names the target."""


@dataclass(frozen=True)
class JointLimits:
    """Joint limits of an arm, one value per joint, base to flange: position (rad), velocity
    (rad/s), acceleration (rad/s²) and jerk (rad/s³; None: not checked)."""

    lower: tuple
    upper: tuple
    velocity: tuple
    acceleration: tuple
    jerk: tuple | None = None

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

    @property
    def n_joints(self) -> int:
        return len(self.lower)


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

    @property
    def paused(self) -> float:
        """Seconds of the run during which the motion's own time ran at under a fifth of the
        clock's pace (closed loop; 0 otherwise)."""
        if self.motion_clock is None or len(self.motion_clock) < 2:
            return 0.0
        running = self.motion_clock[1:] < self.motion_clock[-1]  # not the settling at the end
        slow = np.diff(self.motion_clock) < 0.2 * np.diff(self.command_times)
        return float(np.sum(slow & running) * CONTROL_STEP)


class SimulatorBackend(Protocol):
    """A simulated robot in a scene's world (the methods ``bidmp.sim`` calls)."""

    unit: float  # metres per scene unit
    scene: object  # the bidmp.scene.Scene it was built from (the closed loop steers round it)

    @classmethod
    def load_robot(cls, scene, units: str, base, yaw: float) -> SimulatorBackend:
        """Build the world of ``scene`` (parts, tool) with the robot at ``base`` (scene units),
        turned ``yaw`` degrees about z."""

    def ik(self, point_m: np.ndarray, seed, orientation=None) -> tuple[np.ndarray, float]:
        """Joint positions that put the tool-centre point at ``point_m`` (m), from ``seed``; and the
        position error left (m)."""

    def fk(self, q) -> np.ndarray:
        """The tool-centre point (m) at joint positions ``q``."""

    def plan(
        self, path, label: str = "", fractions=None, seed=None, orientations=None
    ) -> MotionPlan:
        """A Cartesian path (n, 3, scene units) turned into a timed joint path within the limits."""

    def execute(
        self, plan: MotionPlan, exclude=(), hold: Hold | None = None, frames: int = 0
    ) -> Execution:
        """Run ``plan`` open loop, the parts in ``exclude`` ignored for contacts."""

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

    def contacts(self) -> dict:
        """Part label -> penetration depth (m) of the robot's contacts now."""

    def render(self, width: int = 320, height: int = 240, target=None) -> np.ndarray:
        """An RGB image (height, width, 3) of the world."""

    def close(self) -> None:
        """Release the simulator."""


def require_simulator() -> None:
    """Check that the simulator (the ``sim`` extra: PyBullet) is installed, before any work;
    without it :class:`bidmp.MissingExtraError` says how to install it."""
    from .pybullet.world import _pybullet_module

    _pybullet_module()
