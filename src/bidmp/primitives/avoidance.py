"""Steering around the parts of a scene as the motion runs: :class:`SceneAvoidance`, a coupling
term on the scene's exact geometry (coal), not on points.

For every part within the *influence* distance ``ρ`` of the margin shell (signed distance ``d``,
``p = d - margin``, unit direction ``n`` from the part's nearest point to the tool's, velocity
``v``, approach speed ``vₙ = max(0, -v·n)``, ``w = 1 - p/ρ``) it adds

* a **braking** acceleration ``w vₙ² / (2p)`` along ``n``: the deceleration that stops an approach
  at the shell (Park et al. 2008's dynamic potential acts only while the tool moves toward the
  obstacle and grows with the approach speed; this is that idea with the stopping distance
  written out, so its size is what the approach needs, not a tuned gain);
* a **barrier** ``strength w (ρ/p - 1)`` along ``n``: zero at the influence distance, unbounded at the
  shell, against the DMP's own pull into a part when the tool is slow;
* a **steering** acceleration ``steer w vₙ² / (2p)`` along the velocity's component tangent to the
  part (Hoffmann et al. 2009 rotate the velocity about the obstacle; here the approach speed the
  braking removes is turned along the surface instead, so the motion slides round rather than
  stopping). When the tangent speed is nil (head-on), the tangent component of the way to the
  goal is used, else a fixed perpendicular: a potential field's symmetric stall is broken.

Measured on random fields of boxes and cylinders (tests/primitives/test_avoidance.py; the README's
"Avoidance" section, ``benchmarks/bench_avoidance.py``): braking and barrier alone (Park's form
with volumes) stall in front of a part the straight motion meets head-on and miss the goal;
with the steering the motion goes round. The sum is capped at ``max_acceleration`` (the
motion's limit). Parts the target stands in or on are left out (the tool is meant to reach
them), a part with a designed stand-off (a plate under the nuts) is owed that instead of the
margin, and within the final approach's length of the goal the parts beside the goal fade out:
the approach is never pushed off its target (its clearance is still checked).

After a coupled rollout :meth:`check` measures the motion's clearance exactly
(:meth:`bidmp.scene.Scene.clearance`); :meth:`bidmp.DMP.trajectory` raises
:class:`AvoidanceError` (with the motion and its clearance) when it comes closer than the margin
or ends short of its goal (held in a dead end), or logs it with ``on_miss="warn"``. A motion is
never returned as clear when it is not.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from .._checks import TaskRefusal, as_labels, check_choice, check_real
from .coupling import CouplingTerm

__all__ = ["SceneAvoidance", "AvoidanceError"]

logger = logging.getLogger(__name__)

_NEAREST = 1e-3  # of the influence distance: p below it counts as this (the terms stay finite)
_BARRIER_CAP = 1e3  # the barrier's factor ρ/p - 1 at most this (without a limit)


class AvoidanceError(TaskRefusal):
    """A coupled motion that comes closer to a part than the margin, or that the parts hold short
    of its goal. ``trajectory`` is the motion, ``clearance`` its :class:`bidmp.scene.Clearance`."""

    def __init__(self, message: str, trajectory=None, clearance=None) -> None:
        super().__init__(message)
        self.trajectory, self.clearance = trajectory, clearance


class SceneAvoidance(CouplingTerm):
    """Coupling term that steers the tool around a scene's parts (module docstring).

    Parameters
    ----------
    scene : bidmp.scene.Scene
        Parts and tool; positions in the scene's unit (the DMP's must be the same).
    margin : float, optional
        Clearance to keep (scene units); default the scene's margin.
    influence : float, optional
        Distance beyond the margin where the term starts to act (scene units); default two tool
        radii.
    strength : float, optional
        The barrier's scale (units/s²); default what the DMP's spring pulls back a motion pushed
        the influence distance off its course with (``αβ ρ / (τT)²``), resolved into ``strength_``
        when a stepper binds the term: the barrier holds the spring off at half the influence distance.
    steer : float
        Share of the braking turned along the surface (0: Park-style braking only).
    max_acceleration : float, optional
        Cap on the term's acceleration (units/s²).
    exclude : iterable of str
        Parts left out besides the target's.
    target : str, optional
        The target's label: its parts (:meth:`Scene.target_parts`) are left out (default: the
        parts the tool takes into its mouth at the goal).
    approach : float, optional
        Length of the final approach (units): within it of the goal the parts beside the goal (those
        within the influence of the tool placed at the goal) are not pushed against (faded in over
        the next half length), so the approach stays a translated copy of the demonstrated one;
        default the plain motion's straight tail into its goal (0 when it has none).
    on_miss : {"raise", "warn"}
        What a trajectory whose clearance is below the margin does.
    """

    def __init__(  # noqa: PLR0913 - a coupling term's constructor: each setting is one, as users pass them
        self,
        scene,
        margin: float | None = None,
        influence: float | None = None,
        strength: float | None = None,
        steer: float = 1.0,
        max_acceleration: float | None = None,
        exclude=(),
        target: str | None = None,
        approach: float | None = None,
        on_miss: str = "raise",
    ) -> None:
        # imported here: the primitives do not need the scene otherwise
        from ..scene.clearance import Scene

        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a bidmp.scene.Scene, got {type(scene).__name__}")
        self.scene = scene
        self.margin = (
            float(scene.margin)
            if margin is None
            else check_real(margin, "margin", nonnegative=True)
        )
        radius = float(scene.tool.radius)
        self.influence = (
            2.0 * radius if influence is None else check_real(influence, "influence", positive=True)
        )
        self.strength = (
            None if strength is None else check_real(strength, "strength", nonnegative=True)
        )
        self.steer = check_real(steer, "steer", nonnegative=True, maximum=10.0)
        self.max_acceleration = (
            None
            if max_acceleration is None
            else check_real(max_acceleration, "max_acceleration", positive=True)
        )
        self.approach = (
            None if approach is None else check_real(approach, "approach", nonnegative=True)
        )
        self.on_miss = check_choice(on_miss, "on_miss", ("raise", "warn"))
        if target is not None and not isinstance(target, str):
            raise TypeError(
                f"target must be the target's label (a string) or None, got {type(target).__name__}"
            )
        self.target = target
        self.exclude = tuple(
            [exclude] if isinstance(exclude, str) else as_labels(exclude, "exclude")
        )
        self._proximity = None
        self._goal = None

    def bind(self, stepper) -> None:
        """Called by the stepper that runs the term: the goal (for head-on steering), the default
        strength, the target's parts left out, and the final approach's length."""
        from ..scene.proximity import Proximity
        from .approach import _tail_start
        from .stepper import DMPStepper

        if not isinstance(stepper, DMPStepper):
            raise TypeError(
                f"stepper must be the DMPStepper that runs the term, got {type(stepper).__name__}"
            )
        self._goal = stepper.target
        if self.approach is None:  # the motion's own straight tail, the skill's increment included
            plain = stepper.model.rollout(
                stepper.goal, start=stepper.start, forcing_increment=stepper.forcing_increment
            )
            self.approach_ = float(np.linalg.norm(plain[-1] - plain[_tail_start(plain)]))
        else:
            self.approach_ = self.approach
        system = stepper.system
        params, scale = system.settings, system.settings.tau * system.time_unit
        self.strength_ = (
            params.alpha * params.beta * self.influence / scale**2
            if self.strength is None
            else self.strength
        )
        excluded = set(self.exclude)
        if self.target is not None:
            excluded.update(self.scene.target_parts(self.target, self._goal))
        else:
            excluded.update(self.scene.parts_at(self._goal))
        self._proximity = Proximity(self.scene, sorted(excluded))
        self.excluded_ = tuple(sorted(excluded))
        # The parts the term would push against with the tool at the goal itself (a neighbouring
        # nut beside the socket): only these fade out along the final approach.
        beside = self._proximity.near(
            np.asarray(self._goal, dtype=float), self.margin + self.influence, check_input=False
        )[3]
        self._at_goal = np.zeros(self._proximity.standoffs.shape[0], dtype=bool)
        self._at_goal[beside] = True
        self._fades = bool(beside.size)

    def __call__(self, t: float, y: np.ndarray, yd: np.ndarray, phase: float) -> np.ndarray:
        if self._proximity is None:
            raise ValueError(
                "SceneAvoidance is run by a DMP's trajectory or stepper (which binds it to the motion)"
            )
        fade = self._fade(y) if self._fades else 1.0
        distances, away, owed, solids = self._proximity.near(
            y,
            self.margin + self.influence,
            self._at_goal if fade == 0.0 else None,
            check_input=False,
        )
        if distances.size == 0:
            return np.zeros(3)
        rho = self.influence
        owed = np.minimum(owed, self.margin)  # the margin, or a part's stand-off
        gap = np.maximum(distances - owed, _NEAREST * rho)
        weight = np.clip(1.0 - (distances - owed) / rho, 0.0, 1.0)
        if fade < 1.0:  # the parts beside the goal fade out along the final approach
            weight = np.where(self._at_goal[solids], weight * fade, weight)
        approach = np.maximum(-(away @ yd), 0.0)
        braking = weight * approach**2 / (2.0 * gap)
        # + the barrier
        total = braking + self.strength_ * weight * np.minimum(rho / gap - 1.0, _BARRIER_CAP)
        push = total @ away
        if self.steer > 0.0:
            push = push + self.steer * sum(
                b * self._tangent(n, yd, y) for b, n in zip(total, away) if b > 0.0
            )
        if self.max_acceleration is not None:
            size = float(np.linalg.norm(push))
            if size > self.max_acceleration:
                push = push * (self.max_acceleration / size)
        return push

    def _fade(self, y: np.ndarray) -> float:
        """1 away from the goal, 0 within the final approach's length of it (smoothstep between 1
        and 1.5 approach lengths)."""
        if self.approach_ <= 0.0:
            return 1.0
        gx, gy, gz = self._goal.tolist()
        x, y_, z = y.tolist()
        u = (math.sqrt((x - gx) ** 2 + (y_ - gy) ** 2 + (z - gz) ** 2) / self.approach_ - 1.0) / 0.5
        return 1.0 if u >= 1.0 else 0.0 if u <= 0.0 else u * u * (3.0 - 2.0 * u)

    def _tangent(
        self, normal: np.ndarray, velocity: np.ndarray, position: np.ndarray
    ) -> np.ndarray:
        """Unit direction along the surface: the velocity's tangent part, else the goal's, else a
        fixed perpendicular."""
        for direction in (velocity, self._goal - position):
            along = direction - (direction @ normal) * normal
            size = float(np.linalg.norm(along))
            if size > 1e-6 * max(float(np.linalg.norm(direction)), 1e-300):
                return along / size
        fixed = np.cross(normal, [0.0, 0.0, 1.0])
        if np.linalg.norm(fixed) < 1e-6:
            fixed = np.cross(normal, [1.0, 0.0, 0.0])
        return fixed / np.linalg.norm(fixed)

    def check(self, trajectory):
        """The exact clearance of a motion ``trajectory`` (n, 3) with the parts this term avoids
        (:class:`bidmp.scene.Clearance`, with this term's margin)."""
        from ..scene.clearance import Clearance

        found = self.scene.clearance(trajectory, exclude=getattr(self, "excluded_", self.exclude))
        # A part with a designed stand-off is owed that (the scene reports it as the margin);
        # every other part this term's margin.
        owed = min(found.margin, self.margin) if found.margin != self.scene.margin else self.margin
        return Clearance(found.distance, found.part, found.point, owed)


def _check_avoidance(terms, trajectory, target: np.ndarray, reach: float) -> None:
    """After a coupled rollout: raise (or log) when a :class:`SceneAvoidance` term's (``terms``) motion comes
    closer than its margin, or when it ends short of ``target`` (by more than
    :data:`_STALLED` of ``reach``, the start-goal distance): steered into a dead end."""
    for term in terms:
        clearance = term.check(trajectory.y)
        term.clearance_ = clearance
        short = float(np.linalg.norm(trajectory.y[-1] - target))
        if not clearance.clear:
            message = (
                f"the coupled motion comes {clearance.distance:.3g} from part {clearance.part!r} "
                f"(margin {clearance.margin:g}) at {np.round(clearance.point, 3).tolist()}"
            )
        elif short > _STALLED * reach:
            message = (
                f"the coupled motion ends {short:.3g} from its goal after {trajectory.t[-1]:.3g} s: the parts "
                f"hold it in a dead end (give a via-point round them, or plan with extend_demonstration)"
            )
        else:
            continue
        if term.on_miss == "raise":
            raise AvoidanceError(message, trajectory, clearance)
        logger.warning(message)


# of the start-goal distance: a coupled motion that ends further from its goal is reported
_STALLED = 1e-3
