"""The motion contract: whether a motion to a target is one a robot may run, judged by one function
wherever it is judged — the evaluation (the planned motion), the simulator and the job (the motion
the arm executed, and the joint commands it was sent).

A motion meets the contract when

* **end**: its last point is within the success threshold of the target;
* **engaged** (where the scenario has an approach height): its final approach is a monotone descent
  along the target's axis — the motion enters the band of that height above the target from above
  and, inside it, never rises (nor dips below where it has been and comes back up) by more than
  :data:`ENGAGE_RISE_MM`, and stays within the threshold of the axis;
* **clear**: the whole tool, swept between the samples, keeps the scene's margin from every part but
  the target's own (stand-offs declared in the scene, such as the plate under the nuts, are kept
  instead of the margin), and the simulator reports no contact of the arm with such a part;
* **aligned** (pose scenarios): the tool's axis within the alignment threshold of the target's over
  the final approach;
* **within the limits** (where joint commands exist): every 1 kHz joint command within the arm's
  velocity, acceleration and jerk limits, from rest to rest (:func:`command_peaks`), and, where
  the limits carry the arm's own judge (``limits.reflex(commands)``: a Franka arm's FCI tables),
  raising no reflex there.

Every default is defined in millimetres and converted to the scenario's unit (:func:`mm`), so the
same cell gives the same verdicts in m, cm and mm.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from .._checks import (
    as_labels,
    as_point,
    as_trajectory,
    as_vector,
    check_bool,
    check_real,
    short_token,
)
from .._units import length_text, mm
from ..primitives.so3 import as_quaternions
from .metrics import approach_error, axis_deviation, endpoint_error

__all__ = [
    "Contract",
    "Verdict",
    "CommandPeaks",
    "command_peaks",
    "mm",
    "ENGAGE_RISE_MM",
    "AT_REST",
    "PADDING",
]

# The most a final approach may rise inside its band, in mm: 1.5 times the repeatability the Panda, the
# xArm6 and the UR5 are specified to (+-0.1 mm), below which a rise cannot be told from the arm's own
# scatter. A learned skill's approach settles 0.04-0.11 mm below its target and back (the DMP's fit of
# a demonstration's abrupt stop), executed on the simulated arm 0.06-0.08 mm; the paper's DMP run on to
# convergence dips 0.19 mm below each nut and comes back up: no monotone descent.
ENGAGE_RISE_MM = 0.15
PADDING = 3  # samples of rest before and after the commands when they are checked
# A motion starts and stops at rest: the acceleration of its first and last command at most this
# fraction of the limit (a minimum-jerk start reaches 0.3 % of it in its first millisecond; a clamped
# cubic starts at its full 6A/T², up to 45 % of the limit on the simulated nut task).
AT_REST = 0.05
_SLACK = 1e-9  # a peak equal to its limit to rounding is within it
_CONTROLLER_PERIOD_S = 1e-3  # the rate a robot controller's own judge (limits.reflex) takes


# ---------------------------------------------------------------------------------------------
# Joint commands
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CommandPeaks:
    """Peaks of joint commands, each the largest over the joints as a fraction of its limit (jerk: 0
    when the limits state none), the joint where the largest of them is, and ``ends``: the
    acceleration of the first and the last command (from and to rest)."""

    velocity: float
    acceleration: float
    jerk: float
    ends: float = 0.0
    joint: int | None = None  # 0-based joint of the worst of the three peaks
    # the reflex the arm's own controller raises on the commands (a Franka arm's FCI), in words
    reflex: str = ""

    @property
    def within(self) -> bool:
        return (
            not self.reflex
            and self.velocity <= 1.0 + _SLACK
            and self.acceleration <= 1.0 + _SLACK
            and self.jerk <= 1.0 + _SLACK
            and self.ends <= AT_REST
        )

    def reason(self) -> str:
        """What breaks the limits, in words (empty when nothing does)."""
        if self.within:
            return ""
        if self.reflex:
            return f"the arm's controller would stop the motion: {self.reflex}"
        joint = "" if self.joint is None else f"joint {self.joint + 1}'s "
        over = [
            f"{name} {value:.2f}"
            for name, value in (
                ("velocity", self.velocity),
                ("acceleration", self.acceleration),
                ("jerk", self.jerk),
            )
            if value > 1.0 + _SLACK
        ]
        if over:
            return f"{joint}commands exceed the limits ({', '.join(over)} of the limit)"
        return f"the commands do not start and stop at rest (acceleration {self.ends:.2f} of the limit at an end)"


def _fractions(values: np.ndarray, limit) -> np.ndarray:
    """``max over samples of |values| / limit`` per joint (zeros without a limit); ``values`` are
    the padded commands' differences, never empty."""
    if limit is None:
        return np.zeros(values.shape[1])
    return np.max(np.abs(values), axis=0) / np.asarray(limit, dtype=float)


def command_peaks(commands, limits, dt: float = 1e-3) -> CommandPeaks:
    """The peaks of joint position commands (n, J) sent every ``dt`` seconds, from rest to rest.

    The velocity, acceleration and jerk are the first, second and third differences of the commands,
    as the arm's interface (libfranka) computes them, with the first and the last command held
    :data:`PADDING` samples before and after (a jump in velocity or acceleration at an end shows in
    the differences). ``limits`` has ``velocity``, ``acceleration`` and ``jerk`` per joint
    (``jerk`` may be None: not checked).
    """
    commands = as_trajectory(commands, "commands", min_points=1, allow_static=True)
    dt = check_real(dt, "dt", minimum=1e-6, maximum=1.0)  # a controller's period: 1 µs to 1 s
    rates = []
    for key in ("velocity", "acceleration", "jerk"):
        value = getattr(limits, key, None)
        if value is None and key == "jerk":
            rates.append(None)
            continue
        if value is None:
            raise TypeError(
                f"limits must have velocity, acceleration and jerk per joint, got {type(limits).__name__}"
            )
        rate = as_vector(value, f"limits.{key}", positive=True)
        if rate.shape[0] != commands.shape[1]:
            raise ValueError(
                f"limits.{key} has {rate.shape[0]} values but commands has {commands.shape[1]} joints (columns)"
            )
        rates.append(rate)
    padded = np.vstack(
        [
            np.repeat(commands[:1], PADDING, axis=0),
            commands,
            np.repeat(commands[-1:], PADDING, axis=0),
        ]
    )
    velocity = np.diff(padded, axis=0) / dt
    acceleration = np.diff(velocity, axis=0) / dt
    jerk = np.diff(acceleration, axis=0) / dt
    per_joint = np.vstack(
        [
            _fractions(velocity, rates[0]),
            _fractions(acceleration, rates[1]),
            _fractions(jerk, rates[2]),
        ]
    )
    ends = 0.0
    # from rest: the first command's acceleration is its first step over dt²
    if commands.shape[0] >= 2:
        steps = np.abs(np.vstack([commands[1] - commands[0], commands[-2] - commands[-1]])) / dt**2
        ends = float(np.max(steps / rates[1]))
    joint = int(np.argmax(np.max(per_joint, axis=0)))
    return CommandPeaks(
        float(per_joint[0].max()), float(per_joint[1].max()), float(per_joint[2].max()), ends, joint
    )


# ---------------------------------------------------------------------------------------------
# The verdict
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Verdict:
    """The contract's judgement of one motion (lengths in the scenario's unit).

    ``None`` for a check that does not apply (no approach height, no scene, no commands, a position
    scenario's alignment).
    """

    target: str
    end_error: float
    threshold: float
    units: str
    approach_error: float | None = None
    engaged: bool | None = None
    clearance: object = None  # bidmp.scene.Clearance, with the margin it was judged against
    # part label -> depth: the simulator's contacts with other parts
    contacts: dict = field(default_factory=dict)
    axis_deviation: float | None = None
    aligned: bool | None = None
    limits: CommandPeaks | None = None

    @property
    def reached(self) -> bool:
        return bool(self.end_error <= self.threshold)

    @property
    def clear(self) -> bool | None:
        if self.clearance is None and not self.contacts:
            return None
        return bool((self.clearance is None or self.clearance.clear) and not self.contacts)

    @property
    def within_limits(self) -> bool | None:
        return None if self.limits is None else self.limits.within

    @property
    def ok(self) -> bool:
        """End, engagement, clearance, alignment and limits, each where it applies."""
        return (
            self.reached
            and self.engaged is not False
            and self.clear is not False
            and self.aligned is not False
            and self.within_limits is not False
        )

    @property
    def failed(self) -> list[str]:
        """The checks that failed, in the order: end, engagement, clearance, alignment, limits."""
        checks = (
            ("end", self.reached),
            ("engagement", self.engaged),
            ("clearance", self.clear),
            ("alignment", self.aligned),
            ("limits", self.within_limits),
        )
        return [name for name, value in checks if value is False]

    def reason(self) -> str:
        """One sentence: why the motion breaks the contract (empty when it does not)."""
        parts = []
        unit = self.units or "units"
        for name in self.failed:
            if name == "end":
                parts.append(
                    f"ends {length_text(self.end_error, unit)} from the target (within "
                    f"{self.threshold:g} {unit} is success)"
                )
            elif name == "engagement":
                if self.approach_error is None or not math.isfinite(self.approach_error):
                    parts.append("has no monotone final descent along the target's axis")
                else:
                    parts.append(
                        f"comes down {length_text(self.approach_error, unit)} off the target's axis"
                    )
            elif name == "clearance":
                parts.append(self._clearance_words(unit))
            elif name == "alignment":
                if self.axis_deviation is None:
                    parts.append("tilts the tool off the target's axis")
                elif not np.isfinite(self.axis_deviation):  # no final approach to measure it on
                    parts.append(
                        "never comes down along the target's axis, so the tool's tilt over the "
                        "final approach cannot be measured"
                    )
                else:
                    parts.append(
                        f"tilts the tool {self.axis_deviation:.1f} deg from the target's axis"
                    )
            else:
                parts.append(self.limits.reason())
        if not parts:
            return ""
        return f"the motion to {self.target} " + (
            ", ".join(parts[:-1]) + " and " + parts[-1] if len(parts) > 1 else parts[0]
        )

    def _clearance_words(self, unit: str) -> str:
        words = []
        if self.clearance is not None and not self.clearance.clear:
            c = self.clearance
            if c.distance < 0.0:
                words.append(
                    f"cuts {length_text(-c.distance, unit)} into {c.part}"
                    if -c.distance >= 0.005
                    else f"touches {c.part}"
                )
            else:
                words.append(
                    f"passes {length_text(c.distance, unit)} from {c.part}, inside the {c.margin:g} {unit} it must keep"
                )
        if self.contacts:
            label, depth = max(self.contacts.items(), key=lambda item: item[1])
            words.append(f"the arm touches {label} ({length_text(depth, unit)} deep)")
        return " and ".join(words)

    def to_dict(self) -> dict:
        from ..io.strict_json import json_number

        c = self.clearance
        return {
            "ok": self.ok,
            "failed": self.failed,
            "reason": self.reason(),
            "end_error": float(self.end_error),
            "approach_error": json_number(self.approach_error),
            "engaged": self.engaged,
            "clearance": None if c is None else json_number(c.distance),
            "clearance_part": None if c is None else c.part,
            "margin": None if c is None else c.margin,
            "contacts": {k: float(v) for k, v in sorted(self.contacts.items())},
            "axis_deviation": json_number(self.axis_deviation),
            "aligned": self.aligned,
            "within_limits": self.within_limits,
        }


@dataclass(frozen=True)
class Contract:
    """The rules a motion to a target is judged by (lengths in the scenario's unit).

    Parameters
    ----------
    threshold : float
        End within this of the target; also the largest distance from the target's axis over the
        final approach.
    approach_height : float or None
        The band above the target the final approach descends through (None: not checked).
    scene : bidmp.Scene or None
        The parts, the tool, the margin and the stand-offs (None: clearance not checked).
    units : str
        The scenario's length unit (the reasons' words).
    alignment_threshold : float or None
        Pose scenarios: the largest angle (degrees) between the tool's axis and the target's.
    limits : object or None
        The arm's joint limits (``velocity``, ``acceleration``, ``jerk`` per joint) the commands are
        checked against, where there are commands.
    """

    threshold: float
    approach_height: float | None = None
    scene: object = None
    units: str = "mm"
    alignment_threshold: float | None = None
    limits: object = None

    def __post_init__(self) -> None:
        from ..scene import Scene

        object.__setattr__(
            self, "threshold", check_real(self.threshold, "threshold", positive=True)
        )
        if self.approach_height is not None:
            object.__setattr__(
                self,
                "approach_height",
                check_real(self.approach_height, "approach_height", positive=True),
            )
        if self.scene is not None and not isinstance(self.scene, Scene):
            raise TypeError(f"scene must be a bidmp.Scene or None, got {type(self.scene).__name__}")
        if not isinstance(self.units, str) or len(self.units) > 16:
            raise TypeError(
                f"units must be a unit name such as 'mm', got {short_token(self.units)}"
            )
        if self.alignment_threshold is not None:
            object.__setattr__(
                self,
                "alignment_threshold",
                check_real(
                    self.alignment_threshold, "alignment_threshold", positive=True, maximum=180.0
                ),
            )
        if self.limits is not None and not all(
            hasattr(self.limits, key) for key in ("velocity", "acceleration", "jerk")
        ):
            raise TypeError(
                f"limits must be joint limits (velocity, acceleration, jerk per joint), got "
                f"{type(self.limits).__name__}"
            )

    @classmethod
    def of(cls, scenario, limits=None, geometry: bool = True) -> Contract:
        """The contract of a :class:`bidmp.tasks.scenarios.Scenario` (``geometry`` False: without its scene)."""
        from .scenarios import Scenario

        if not isinstance(scenario, Scenario):
            raise TypeError(
                f"scenario must be a bidmp.tasks.Scenario, got {type(scenario).__name__}"
            )
        geometry = check_bool(geometry, "geometry")
        return cls(
            scenario.success_threshold,
            scenario.approach_height if scenario.demonstration.shape[1] >= 3 else None,
            scenario.scene if geometry else None,
            scenario.units,
            scenario.alignment_threshold if scenario.is_pose else None,
            limits,
        )

    def judge(  # noqa: PLR0913 - the public call spells its options out, as users pass them
        self,
        path,
        target,
        *,
        label: str = "",
        axis=None,
        exclude=(),
        orientations=None,
        commands=None,
        contacts=None,
        dt: float = 1e-3,
        clearance=None,
        applies: bool = True,
    ) -> Verdict:
        """The verdict on ``path`` (n, 3 or D) to ``target`` (D,).

        Parameters
        ----------
        path : array (n, D)
            The motion: planned (evaluation) or executed (the tool-centre point the arm measured).
        target : array (D,)
            Where it must end (a pose target's position is its first three values).
        label : str
            The target's name (the reason's words).
        axis : array (3,), optional
            The target's axis, pointing out of it (default +z).
        exclude : list of str
            The parts the tool takes in at the target (not checked for clearance).
        orientations : array (n, 4), optional
            The tool frame along ``path`` (quaternions x, y, z, w): the clearance of a tilted tool,
            and the alignment of a pose scenario.
        commands : array (m, J), optional
            The joint commands sent every ``dt`` seconds (checked against ``limits``).
        contacts : dict, optional
            The simulator's contacts of the arm with parts other than the target's: label -> depth.
        clearance : bidmp.scene.Clearance, optional
            The path's clearance when the caller has it already (not computed again).
        applies : bool
            Whether the scene applies to this target (its ``targets`` list); else no clearance.
        """
        path = as_trajectory(path, "path", min_points=1, allow_static=True)
        target = as_vector(target, "target")
        position = path[:, :3] if path.shape[1] >= 3 else path
        if target.shape[0] < position.shape[1]:
            raise ValueError(
                f"target has {target.shape[0]} coordinates; path's positions have {position.shape[1]}"
            )
        goal = target[: position.shape[1]]
        if not isinstance(label, str):
            raise TypeError(
                f"label must be the target's name (a string), got {type(label).__name__}"
            )
        if axis is not None:
            axis = as_point(axis, 3, "axis")
            if not np.linalg.norm(axis) > 0.0:
                raise ValueError("axis must be a direction (not zero)")
        exclude = as_labels(exclude, "exclude")
        if orientations is not None:
            orientations = as_quaternions(orientations, "orientations")
            if orientations.shape[0] != path.shape[0]:
                raise ValueError(
                    f"orientations has {orientations.shape[0]} rows but path has {path.shape[0]}"
                )
        dt = check_real(dt, "dt", positive=True)
        if contacts is not None and (
            not isinstance(contacts, dict)
            or not all(
                isinstance(key, str) and isinstance(value, (int, float)) and math.isfinite(value)
                for key, value in contacts.items()
            )
        ):
            raise TypeError(
                f"contacts must be a dict of part label -> depth, got {short_token(contacts, 30)}"
            )
        if clearance is not None and not all(
            hasattr(clearance, key) for key in ("distance", "part", "clear")
        ):
            raise TypeError(
                f"clearance must be a bidmp.Clearance or None, got {type(clearance).__name__}"
            )
        applies = check_bool(applies, "applies")
        if commands is not None:
            commands = as_trajectory(commands, "commands", min_points=1, allow_static=True)
        end = endpoint_error(position, goal)
        approach = engaged = deviation = aligned = None
        if self.approach_height is not None and position.shape[1] == 3:
            approach = approach_error(
                position, goal, self.approach_height, axis, rise=mm(ENGAGE_RISE_MM, self.units)
            )
            engaged = bool(approach <= self.threshold)
            if self.alignment_threshold is not None and orientations is not None:
                deviation = axis_deviation(
                    position,
                    orientations,
                    goal,
                    self.approach_height,
                    axis,
                    rise=mm(ENGAGE_RISE_MM, self.units),
                )
                aligned = bool(deviation <= self.alignment_threshold)
        if clearance is None and self.scene is not None and applies and position.shape[1] == 3:
            clearance = self.scene.clearance(position, exclude=exclude, orientations=orientations)
        peaks = None
        if commands is not None and self.limits is not None:
            peaks = command_peaks(commands, self.limits, dt)
            # the arm's own controller too, where the limits carry its judge (a Franka arm's
            # FCI) and the commands come at its 1 kHz
            reflex = getattr(self.limits, "reflex", None)
            if reflex is not None and dt == _CONTROLLER_PERIOD_S:
                peaks = replace(peaks, reflex=reflex(commands))
        return Verdict(
            label,
            end,
            self.threshold,
            self.units,
            approach,
            engaged,
            clearance if applies else None,
            dict(contacts or {}),
            deviation,
            aligned,
            peaks,
        )
