"""Repairs: a motion to a target that breaks the motion contract (:mod:`bidmp.tasks.contract`) made
into one that keeps it, from the same learned skills — or the target failed with the reason.

Whatever failed — the end, the engagement or the clearance — the repairs are tried in this order
(:data:`REPAIRS`), each judged by the contract, the first motion that keeps it taken:

* ``"lift"``: exact via-points (:mod:`bidmp.primitives.via`) raise the motion over the part it
  comes too close to, before its final approach, one point at a time where it comes closest (a
  few milliseconds each: the skill's shape is kept everywhere else);
* ``"avoid"``: the :class:`~bidmp.primitives.avoidance.SceneAvoidance` coupling steers it round
  the parts as it runs (one coupled rollout);
* ``"extend"``: an extended demonstration grown to this target through the scene (1D-SEG and a
  scene-aware G-PRM, the final approach kept) and learned by the Bi-DMP as a new skill, on a copy
  of the model (the learned skills are not changed by a repair);
* ``"margin"``: the extension planned again with the margin widened by what the last attempt
  lacked (the learned skill does not follow its extension exactly);
* ``"route"``: the complete fallback, where the demonstration's shape runs out: the tool's own
  route to the top of the final approach, found by a sampling-based planner through the scene
  (:func:`bidmp.planning.tool_route`: RRT-Connect, shortened, its corners rounded), then straight
  down the target's axis. The route is learned as a skill (the next target near it starts from
  that skill, without the planner), and the motion is that skill's where it keeps the contract,
  else the route itself. Any route that exists within the search's budget is found.

The order is the cost: a lift is about a hundredth of an extension, and on the random cells of
``tools/repair_order.py`` it repairs most motions that only a part in the way spoils; the route
comes last because it keeps the least of the demonstration's shape. A motion that misses its end
or its engagement cannot be lifted or steered into its target: it goes straight to the extension.

Before any of them, the final approach itself is checked: when the tool coming straight down the
target's axis onto it already comes too close to a part (a post beside the nut, a duct over it),
no motion can keep the contract and the target is refused at once, naming the part.

Motions are planned for a margin widened by ``allowance`` (what the arm's tracking may take off
it when the motion runs) and judged by the contract as it is.
"""

from __future__ import annotations

import copy
import logging
import time
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from .._checks import (
    as_labels,
    as_point,
    as_trajectory,
    as_vector,
    check_callable,
    check_options,
    check_real,
    check_seed,
    short_token,
)
from .._units import length_text
from .contract import Contract, Verdict
from .options import BiDMPOptions

if TYPE_CHECKING:
    from ..extension import ExtensionOptions

__all__ = ["REPAIRS", "Repairer", "Repaired", "Attempt", "carried_clearance", "carried_depth"]

logger = logging.getLogger(__name__)

REPAIRS = ("lift", "avoid", "extend", "margin", "route")
_MAX_ROUNDS = 4  # rounds of lifting (each lifts the stretch past the part the motion comes nearest)
_STRETCH = 5  # via-points spread along each stretch lifted
_WIDENINGS = 2  # plannings with a wider margin


def _target_args(goal, axis, exclude) -> tuple[np.ndarray, np.ndarray, list]:
    """A goal (position, or a pose's first three values), its axis (default +z, unit) and the parts excluded."""
    goal = as_vector(goal, "goal")
    if goal.shape[0] < 3:
        raise ValueError(f"goal must have at least 3 coordinates (x, y, z), got {goal.shape[0]}")
    if axis is None:
        axis = np.array([0.0, 0.0, 1.0])
    else:
        axis = as_point(axis, 3, "axis")
        norm = float(np.linalg.norm(axis))
        if not norm > 0.0:
            raise ValueError("axis must be a direction (not zero)")
        axis = axis / norm
    return goal, axis, as_labels(exclude, "exclude")


@dataclass(frozen=True)
class Attempt:
    """One repair tried: which, whether its motion kept the contract, how long it took (s), and why not."""

    how: str
    ok: bool
    seconds: float
    note: str = ""

    def to_dict(self) -> dict:
        return {
            "how": self.how,
            "ok": self.ok,
            "seconds": round(self.seconds, 4),
            "note": self.note,
        }


@dataclass
class Repaired:
    """What a repair made of a motion: the motion that keeps the contract (or, when none does, the
    method's own), its verdict, which repair made it (``how``; empty: none), every attempt, and for
    ``extend``/``margin`` the Bi-DMP with the new skill (``model``, ``skill``)."""

    motion: np.ndarray
    verdict: Verdict
    how: str = ""
    attempts: list = field(default_factory=list)
    model: object = None
    skill: object = None
    refused: str = ""  # why no repair was tried (the final approach itself is blocked)
    # why the arm cannot run the motion though it keeps the contract (a link would touch a part)
    arm: str = ""

    @property
    def ok(self) -> bool:
        return self.verdict.ok and not self.arm

    def reason(self) -> str:
        """Why the target fails, in one sentence (empty when it does not)."""
        if self.ok:
            return ""
        if self.refused:
            return self.refused
        tried = ", ".join(attempt.how for attempt in self.attempts)
        why = self.verdict.reason() if not self.verdict.ok else f"the arm cannot run it: {self.arm}"
        return why + (f"; repairs tried: {tried}" if tried else "")

    def to_dict(self) -> dict:
        return {
            "how": self.how,
            "refused": self.refused,
            "attempts": [a.to_dict() for a in self.attempts],
        }


def _is_bidmp(model) -> bool:
    """A Bi-DMP of positions or of poses (it learns new skills)."""
    return hasattr(model, "learn") and (
        hasattr(model, "skill_goals_") or hasattr(model, "skill_goal_orientations_")
    )


def _is_pose(model) -> bool:
    """A model of poses (a CartesianDMP or CartesianBiDMP): its motions are (n, 7)."""
    return hasattr(model, "orientation_")


def _trajectory(model, goal, start, skill, **options):
    """The model's timed motion to ``goal`` from ``start`` (a Bi-DMP's ``skill``)."""
    if _is_bidmp(model):
        options["skill"] = skill
    return model.trajectory(goal, start=start, **options)


def _path(trajectory) -> np.ndarray:
    """A timed motion's samples: positions (n, 3), or for a pose motion poses (n, 7)."""
    orientations = getattr(trajectory, "q", None)
    return trajectory.y if orientations is None else np.hstack([trajectory.y, orientations])


def _turns(motion) -> np.ndarray | None:
    """The tool frame along a motion (n, 4) when it is a pose motion (n, 7); else None (the tool
    upright)."""
    motion = np.asarray(motion)
    return motion[:, 3:7] if motion.shape[1] == 7 else None


class _Query(NamedTuple):
    """What :meth:`Repairer.repair` is asked: the model (a DMP or Bi-DMP, a pose one or not), the
    target (``goal``, ``label``, its ``axis`` and the parts ``exclude``d there), where the motion
    starts, which ``skill`` runs, and a ``carried`` part or None; passed whole to each repair and
    to each judgement."""

    model: object
    goal: np.ndarray
    label: str
    start: object
    axis: np.ndarray
    exclude: list
    skill: object
    carried: object


class Repairer:
    """The repairs of one task (module docstring).

    Parameters
    ----------
    contract : Contract
        What a motion must keep; its scene is where the parts are.
    demonstration : array (T, 3)
        The demonstration an extension grows from.
    extension : bidmp.extension.ExtensionOptions or dict
        How extensions are grown (a scenario's ``extension``), or the flat form of its file's
        ``"extension"`` object; the approach is kept whatever it says.
    seed : int
        The extension's seed.
    order : sequence of str
        The repairs to try, in order (a subset of :data:`REPAIRS`).
    allowance : float
        Scene units added to the margin the repairs plan for (what execution may take off it).
    bidmp : bidmp.tasks.BiDMPOptions or dict
        Parameters of a Bi-DMP built when the model is a plain DMP (``extend`` needs one): a
        scenario's ``bidmp``, or its keyword arguments.
    """

    def __init__(
        self,
        contract: Contract,
        demonstration,
        *,
        extension: ExtensionOptions | dict | None = None,
        seed: int = 0,
        order=REPAIRS,
        allowance: float = 0.0,
        bidmp: BiDMPOptions | dict | None = None,
    ) -> None:
        if not isinstance(contract, Contract):
            raise TypeError(
                f"contract must be a bidmp.tasks.Contract, got {type(contract).__name__}"
            )
        order = as_labels(order, "order")
        unknown = [how for how in order if how not in REPAIRS]
        if unknown:
            raise ValueError(
                f"order names {short_token(unknown[0], 20)}, which is no repair (known: {', '.join(REPAIRS)})"
            )
        if contract.scene is None:
            raise ValueError(
                "contract: repairs need the contract's scene, the parts a motion is kept away from"
            )
        self.contract = contract
        self.demonstration = as_trajectory(demonstration, "demonstration")
        from ..extension import ExtensionOptions

        # the extension's keyword arguments (a repair keeps the approach, whatever the file says)
        if not isinstance(extension, ExtensionOptions):
            extension = ExtensionOptions.from_flat(check_options(extension, "extension"))
        self.extension = extension.replace(approach="keep").arguments
        check_seed(seed, "seed")
        if not isinstance(bidmp, BiDMPOptions):
            try:
                bidmp = BiDMPOptions.from_flat(check_options(bidmp, "bidmp"))
            except (TypeError, ValueError) as error:  # the options' own words, said of bidmp
                message = str(error)
                raise type(error)(
                    message if message.startswith("bidmp") else f"bidmp: {message}"
                ) from None
        # the Bi-DMP's keyword arguments
        self.seed, self.order, self.bidmp = seed, tuple(order), bidmp.arguments
        self.allowance = check_real(allowance, "allowance", nonnegative=True)
        self.planning = self._widened(self.allowance)

    def _widened(self, extra: float) -> Contract:
        """The contract with the scene's margin widened by ``extra`` (at most the tool's radius)."""
        scene = copy.copy(self.contract.scene)
        scene.margin = min(scene.margin + max(extra, 0.0), scene.tool.radius)
        return Contract(
            self.contract.threshold,
            self.contract.approach_height,
            scene,
            self.contract.units,
            self.contract.alignment_threshold,
            self.contract.limits,
        )

    # -- the judgement -----------------------------------------------------------------------------
    def _judge(self, contract: Contract, motion, query: _Query, clearance=None) -> Verdict:
        """``contract``'s verdict on ``motion`` (positions, or poses: judged with the tool's
        frame) to ``query``'s target, its ``carried`` part's clearance counted with the tool's;
        ``clearance``: the motion's, when the caller has it already (a lift's)."""
        goal, label, axis, exclude, carried = (
            query.goal,
            query.label,
            query.axis,
            query.exclude,
            query.carried,
        )
        turns = _turns(motion)
        if clearance is None and contract.scene is not None and carried:
            clearance = self._clearance(
                contract.scene, np.asarray(motion)[:, :3], exclude, carried, turns
            )
        return contract.judge(
            motion,
            goal,
            label=label,
            axis=axis,
            exclude=exclude,
            clearance=clearance,
            orientations=turns,
        )

    def blocked(self, goal, axis, exclude) -> str:
        """Why no motion can keep the contract at ``goal`` (empty when one may): the tool coming
        straight down the target's axis over the approach height already comes too close to a part."""
        contract = self.contract
        height = contract.approach_height or 0.0
        goal, axis, exclude = _target_args(goal, axis, exclude)
        corridor = np.vstack([goal[:3] + axis * height, goal[:3]])
        orientations = None
        if axis[2] < 1.0 - 1e-12:  # a tilted target: the tool along its axis
            from scipy.spatial.transform import Rotation

            turn, _ = Rotation.align_vectors([-axis], [[0.0, 0.0, -1.0]])
            orientations = np.repeat(
                (turn * Rotation.from_quat([1.0, 0.0, 0.0, 0.0])).as_quat()[None], 2, axis=0
            )
        clearance = contract.scene.clearance(
            corridor, exclude=list(exclude), orientations=orientations
        )
        if clearance.clear:
            return ""
        unit = contract.units or "units"
        depth = (
            f"cuts {length_text(-clearance.distance, unit)} into"
            if clearance.distance < 0
            else f"passes {length_text(clearance.distance, unit)} from"
        )
        return (
            f"no motion can engage it: the tool coming straight down onto it {depth} {clearance.part} "
            f"(the margin is {clearance.margin:g} {unit})"
        )

    # -- repairing -----------------------------------------------------------------------------------
    def repair(  # noqa: PLR0913 - the public call spells its options out, as users pass them
        self,
        model,
        goal,
        label: str,
        *,
        start=None,
        axis=None,
        exclude=(),
        motion=None,
        verdict=None,
        skill="nearest",
        carried=None,
        arm=None,
    ) -> Repaired:
        """The motion of ``model`` (a DMP or Bi-DMP) to ``goal`` kept within the contract, or why not.

        ``motion`` and ``verdict``: the method's own motion and its verdict when the caller has
        them (else computed). The repairs are tried only when that verdict fails. ``carried``: a
        part the tool carries (a transfer), ``(solid, offset from the mouth)``, kept clear too.
        ``arm``: ``arm(motion) -> str``, why the arm cannot run a motion that keeps the contract
        ("" when it can: a simulator's check of its links along it); a link's contact starts the
        same repairs as the tool's, and a repair is kept only where the arm can run it too. Where
        none is, but one keeps the contract on the tool where the method's own motion did not,
        that one is kept with ``Repaired.arm`` saying why the arm cannot run it (the simulator
        gives it the arm's own route).
        """
        goal, axis, exclude = _target_args(goal, axis, exclude)
        if not isinstance(label, str):
            raise TypeError(
                f"label must be the target's name (a string), got {type(label).__name__}"
            )
        if not hasattr(model, "trajectory"):
            raise TypeError(f"model must be a fitted DMP or Bi-DMP, got {type(model).__name__}")
        query = _Query(model, goal, label, start, axis, exclude, skill, carried)
        if motion is None:
            motion = _path(_trajectory(model, goal, start, skill))
        if verdict is None:
            verdict = self._judge(self.contract, motion, query)
        out = Repaired(np.asarray(motion), verdict)
        if arm is not None:
            check_callable(arm, "arm")
            out.arm = str(arm(out.motion)) if verdict.ok else ""
        if out.ok:
            return out
        refused = (
            self.blocked(goal, axis, exclude) if self.contract.approach_height is not None else ""
        )
        if refused:
            out.refused = f"the motion to {label} cannot be repaired: {refused}"
            logger.info("%s", out.refused)
            return out
        only_clearance = set(verdict.failed) <= {"clearance"}
        shortfall, kept = 0.0, None
        for how in self.order:
            if not self._applies(how, query, only_clearance):
                continue
            started = time.perf_counter()
            try:
                found = self._try(
                    how,
                    query,
                    shortfall,
                    verdict.clearance if motion is out.motion and how == "lift" else None,
                )
            except ValueError as exc:  # a via-point refused, an avoidance miss, no free route ...
                out.attempts.append(
                    Attempt(how, False, time.perf_counter() - started, _first_line(exc))
                )
                continue
            candidate, trial, trial_skill, planned = found
            final = self._final(planned, candidate, query)
            problem = self._arm_problem(arm, candidate, final, planned)
            ok = final.ok and planned.ok and not problem
            note = (
                f"the arm cannot run it: {problem}" if problem else "" if ok else planned.reason()
            )
            out.attempts.append(Attempt(how, ok, time.perf_counter() - started, note))
            if problem and kept is None:  # the first that keeps the contract on the tool, kept
                kept = (candidate, final, how, trial, trial_skill, problem)
            if ok:
                out.motion, out.verdict, out.how, out.model, out.skill, out.arm = (
                    candidate,
                    final,
                    how,
                    trial,
                    trial_skill,
                    "",
                )
                logger.info("the motion to %s kept the contract after %s", label, how)
                return out
            if planned.clearance is not None:
                shortfall = max(shortfall, planned.clearance.margin - planned.clearance.distance)
        if kept is not None and not out.verdict.ok:
            # No repair clears the links too, but one keeps the contract on the tool: that motion,
            # its links left to the arm's own route (bidmp.sim), rather than one that misses.
            out.motion, out.verdict, out.how, out.model, out.skill, out.arm = kept
        return out

    @staticmethod
    def _arm_problem(arm, candidate, final: Verdict, planned: Verdict) -> str:
        """Why the arm cannot run a repair's motion that keeps the contract ("" when it can, when
        the contract refuses it anyway, or with no check of the arm)."""
        if arm is None or not (final.ok and planned.ok):
            return ""
        return str(arm(candidate))

    def _applies(self, how: str, query: _Query, only_clearance: bool) -> bool:
        """Whether repair ``how`` can help ``query``'s motion: a lift or a steer does not bring a
        motion that misses its target onto it; an extension needs a model that learns skills; a
        carried part is not the tool (the arm's route carries it: :mod:`bidmp.sim.routes`)."""
        if how in ("lift", "avoid"):
            return only_clearance
        if how in ("extend", "margin"):
            return _is_bidmp(query.model) or self.bidmp_possible(query.model)
        return not (how == "route" and query.carried)

    def _final(self, planned, motion, query: _Query) -> Verdict:
        """The contract's own verdict on a repair's ``motion`` (the one the report shows), judged
        after its verdict on the planning contract (``planned``): not judged again where that
        already failed (the repair is not kept), nor where no allowance widens the planning
        contract (the two are then one contract, on the same motion and arguments)."""
        if not planned.ok or self.planning.scene.margin == self.contract.scene.margin:
            return planned
        return self._judge(self.contract, motion, query)

    @staticmethod
    def bidmp_possible(model) -> bool:
        """Whether ``extend`` can grow a Bi-DMP on ``model`` (a fitted plain DMP or pose DMP)."""
        if _is_pose(model):
            return hasattr(model, "cartesian_") or hasattr(model, "start_log_")
        return hasattr(model, "weights_") and hasattr(model, "n_steps_")

    def _try(self, how, query: _Query, shortfall: float, known=None):
        """``(motion, model, skill, verdict on the planning contract)`` of one repair of ``query``
        (``known``: the method's own motion's clearance, where it has one: the lift's first
        round)."""
        model, goal, label, start, skill = (
            query.model,
            query.goal,
            query.label,
            query.start,
            query.skill,
        )
        if how == "lift":
            motion, clearance = self._lift(query, known)
            verdict = self._judge(self.planning, motion, query, clearance)
            return motion, None, None, verdict
        if how == "route":
            return self._route(query)
        if how == "avoid":
            from ..primitives.avoidance import SceneAvoidance

            scene = self.planning.scene
            term = SceneAvoidance(
                scene, margin=scene.margin, target=label if label in scene.labels else None
            )
            motion = _path(_trajectory(model, goal, start, skill, coupling=[term]))
            return motion, None, None, self._judge(self.planning, motion, query)
        widen = self.allowance + (shortfall if how == "margin" else 0.0)
        attempts = _WIDENINGS if how == "margin" else 1
        for _ in range(attempts):
            trial, index = self._learned(model, goal, self._widened(widen), start, skill)
            motion = _path(_trajectory(trial, goal, start, index))
            # Planned with a wider margin, judged by what it must keep: the margin and the
            # allowance (the shortfall only steers the planning).
            verdict = self._judge(self.planning, motion, query)
            if verdict.ok or verdict.clearance is None or how != "margin":
                return motion, trial, index, verdict
            widen += max(verdict.clearance.margin - verdict.clearance.distance, 0.0)
        return motion, trial, index, verdict

    def _route(self, query: _Query):
        """``(motion, model, skill, verdict on the planning contract)`` of the complete fallback:
        the tool's route through the planning scene (module docstring), learned as a new skill on
        a copy of the model; the motion is that skill's where the planning contract keeps it,
        else the route's own (a ``ValueError`` when there is no route)."""
        from ..planning import tool_route

        model, goal, start = query.model, query.goal, query.start
        pose = _is_pose(model)
        width = 7 if pose else 3
        begin = np.asarray(self.demonstration[0] if start is None else start, dtype=float)
        if begin.shape[0] < width:  # a pose motion from a position: the demonstration's frame
            begin = np.concatenate([begin[:3], np.asarray(self.demonstration[0], float)[3:7]])
        route = tool_route(
            self.planning.scene,
            begin[:width],
            np.asarray(goal, dtype=float)[:width],
            axis=query.axis,
            approach_height=self.contract.approach_height or 0.0,
            exclude=query.exclude,
            seed=self.seed,
        )
        count = self.demonstration.shape[0]
        motion = route.motion(max(count, 2))
        trial, index = self._taught(model, motion, route.length)
        if trial is not None:
            learned = _path(_trajectory(trial, goal, start, index))
            verdict = self._judge(self.planning, learned, query)
            if verdict.ok:
                return learned, trial, index, verdict
        return motion, trial, index, self._judge(self.planning, motion, query)

    def _taught(self, model, motion: np.ndarray, length: float):
        """A copy of the Bi-DMP (one is built on a plain DMP) with ``motion`` learned as a new
        skill, timed at the demonstration's pace (its duration scaled by the route's length over
        the demonstration's), and the skill's index; ``(None, None)`` where the model cannot learn
        skills."""
        from ..incremental.bidmp import BiDMP
        from ..incremental.cartesian import CartesianBiDMP

        pose = _is_pose(model)
        if _is_bidmp(model):
            trial = copy.deepcopy(model)
            dmp = model.cartesian_.position_ if pose else model.dmp_
        elif self.bidmp_possible(model):
            trial = (CartesianBiDMP if pose else BiDMP)(copy.deepcopy(model), **self.bidmp)
            dmp = model.position_ if pose else model
        else:
            return None, None
        shown = float(np.sum(np.linalg.norm(np.diff(self.demonstration[:, :3], axis=0), axis=1)))
        duration = dmp.duration_ * max(length / shown, 0.25) if shown > 0.0 else None
        trial.learn(motion, duration=duration)
        return trial, trial.n_skills - 1

    def _learned(self, model, goal, planning: Contract, start=None, skill="nearest"):
        """A copy of the Bi-DMP (one is built on a plain DMP) with a skill learned from an extended
        demonstration grown to ``goal`` through the planning scene, and that skill's index. It grows
        from the demonstration, or for a motion from another ``start`` from the skill's own motion
        from there (a skill learned from the demonstration, run from elsewhere, is another motion).
        A pose model grows a pose extension: its kept approach turned onto the target's axis."""
        from ..extension.extend import extend_demonstration, extend_pose_demonstration
        from ..incremental.bidmp import BiDMP
        from ..incremental.cartesian import CartesianBiDMP

        pose = _is_pose(model)
        if _is_bidmp(model):
            trial = copy.deepcopy(model)
            dmp = model.cartesian_.position_ if pose else model.dmp_  # fitted on the demonstration
        else:
            trial = (CartesianBiDMP if pose else BiDMP)(copy.deepcopy(model), **self.bidmp)
            dmp = model.position_ if pose else model
        source, duration = self.demonstration, None
        if start is not None:
            # A pose grows from the demonstrated motion run from there (its approach is the one
            # the extension turns onto the target's axis; the skill's own motion to a tilted
            # target comes down as the demonstration did, already turned, and would be kept so).
            own = (
                _trajectory(model, self.demonstration[-1], start, 0)
                if pose
                else _trajectory(model, goal, start, skill)
            )
            source, duration = _path(own), float(own.t[-1])
        if pose:
            options = {key: value for key, value in self.extension.items() if key != "approach"}
            extension = extend_pose_demonstration(
                source, goal, seed=self.seed, scene=planning.scene, **options
            )
            learned = extension.poses
        else:
            extension = extend_demonstration(
                source, goal[:3], seed=self.seed, scene=planning.scene, **self.extension
            )
            learned = extension.complete
        scale = (
            1.0
            if duration is None
            else duration / dmp.duration_ * (dmp.n_steps_ - 1) / (source.shape[0] - 1)
        )
        trial.learn(learned, duration=extension.duration_for(dmp) * scale)
        return trial, trial.n_skills - 1

    def _lift(self, query: _Query, known=None):
        """The motion of ``query`` raised over the parts it comes too close to by exact via-points:
        each round, the stretch of the motion that passes the nearest part (by its bounding box)
        before the final approach is lifted to over the part's top, by up to :data:`_STRETCH`
        points spread along it; a ``ValueError`` when it cannot be."""
        model, goal, start, axis, exclude, skill, carried = (
            query.model,
            query.goal,
            query.start,
            query.axis,
            query.exclude,
            query.skill,
            query.carried,
        )
        scene = self.planning.scene
        pose = _is_pose(model)
        trajectory = _trajectory(model, goal, start, skill)
        final = _final_approach_time(trajectory, goal, self.contract.approach_height, axis)
        # The weight change acts only through the kernels active before the final approach, so the
        # motion returns to its own course there (the contract judges how it ends); the points lie
        # after the motion's first tenth (the kernels cannot move its start) and before the last fifth
        # of the time they may act in.
        earliest = 0.1 * float(trajectory.t[-1])
        until = max(min(final, _motion_duration(model, goal, skill)), 2.0 * earliest)
        latest = until - 0.2 * (until - earliest)
        via: dict = {}
        # the tool's mouth this close to a part's box is near it
        band = scene.margin + scene.tool.radius
        for round_ in range(_MAX_ROUNDS):
            # the same motion: its distances are known
            if round_ == 0 and known is not None and not carried:
                clearance = type(known)(known.distance, known.part, known.point, scene.margin)
            else:
                clearance = self._clearance(
                    scene, trajectory.y, exclude, carried, getattr(trajectory, "q", None)
                )
            if clearance.clear:
                return _path(trajectory), clearance
            owner = _owner(scene, clearance.part)
            path = trajectory.y[:, :3]
            height = carried_depth(carried)
            near = scene.near(path, owner, band) | scene.near(
                path - [0.0, 0.0, height], owner, band
            )
            before = (trajectory.t <= latest) & (trajectory.t >= earliest)
            if not np.any(near & before):
                raise ValueError(
                    f"it comes too close to {clearance.part} within its final approach: no lift helps"
                )
            top = float(scene.bounds(owner)[1][2]) + scene.margin + 0.5 * scene.tool.radius + height
            stretch = np.flatnonzero(near & before)
            for index in np.unique(
                np.linspace(stretch[0], stretch[-1], min(_STRETCH, stretch.size))
                .round()
                .astype(int)
            ):
                point = trajectory.y[index].copy()
                point[2] = max(point[2], top)
                if pose:  # the tool's frame as the motion has it there
                    point = np.concatenate([point, trajectory.q[index]])
                via[round(float(trajectory.t[index]), 12)] = point
            trajectory = _trajectory(
                model, goal, start, skill, via=sorted(via.items()), via_until=until
            )
        clearance = self._clearance(
            scene, trajectory.y, exclude, carried, getattr(trajectory, "q", None)
        )
        if clearance.clear:
            return _path(trajectory), clearance
        raise ValueError(f"{_MAX_ROUNDS} rounds of via-points did not lift it clear of the parts")

    @staticmethod
    def _clearance(scene, path, exclude, carried=None, orientations=None):
        """The tool's clearance along ``path`` (its frame ``orientations``, default upright), and
        of a part it carries (:func:`carried_clearance`)."""
        return carried_clearance(scene, path, exclude, carried, orientations=orientations)


def carried_clearance(scene, path, exclude, carried=None, support=(), orientations=None):
    """The clearance along ``path`` (n, 3) of the tool and of a part it carries: ``carried`` is
    ``(solid, offset)``, the part's solid where it is and its centre's offset (3,) from the tool's
    mouth (:meth:`bidmp.Scene.body_clearance`). ``support``: parts left out of the part's check
    (those it is lifted off). The nearer of the two to its margin."""
    from ..scene import Scene

    if not isinstance(scene, Scene):
        raise TypeError(f"scene must be a bidmp.Scene, got {type(scene).__name__}")
    exclude, support = as_labels(exclude, "exclude"), as_labels(support, "support")
    path = as_trajectory(path, "path", min_points=1, allow_static=True)
    if path.shape[1] != 3:
        raise ValueError(f"path must have 3 columns (x, y, z), got {path.shape[1]}")
    clearance = scene.clearance(path, exclude=exclude, orientations=orientations)
    if carried is None:
        return clearance
    solid, offset = _carried_args(carried)
    body = scene.body_clearance(solid, path[:, :3], offset, exclude=exclude + support)
    body = type(body)(body.distance, body.part, body.point, scene.margin)
    return min(clearance, body, key=lambda c: c.distance - c.margin)


def _carried_args(carried) -> tuple:
    """``carried`` checked: (a scene Solid, its offset (3,) from the tool's mouth)."""
    from ..scene import Solid

    if (
        not isinstance(carried, (tuple, list))
        or len(carried) != 2
        or not isinstance(carried[0], Solid)
    ):
        raise TypeError(
            f"carried must be (a scene Solid, its offset (3,)) or None, got {short_token(carried, 30)}"
        )
    return carried[0], as_point(carried[1], 3, "carried's offset")


def carried_depth(carried) -> float:
    """How far a carried part reaches below the tool's mouth (scene units; 0 without one).

    Parameters
    ----------
    carried : (bidmp.scene.Solid, array (3,)) or None
        The part's solid where it is and its centre's offset from the tool's mouth (scene units).
    """
    if carried is None or (isinstance(carried, tuple) and not carried):
        return 0.0
    solid, offset = _carried_args(carried)
    return max(
        float(np.asarray(solid.centre)[2] - np.asarray(solid.lower)[2] - np.asarray(offset)[2]), 0.0
    )


def _motion_duration(model, goal, skill) -> float:
    """How long the skill's motion lasts (s) before it rests at its goal: via-points lie within it."""
    if _is_pose(model):  # the position part times the motion; a pose Bi-DMP picks on the position
        if _is_bidmp(model):
            skill = model.select_skill(np.asarray(goal, dtype=float), skill)
        model, goal = model.position_, np.asarray(goal, dtype=float)[:3]
    if _is_bidmp(model):
        index = model.select_skill(np.asarray(goal, dtype=float), skill)
        return float(model.dmp_.tau * model.dmp_.duration_ * model.skill_time_scales_[index])
    return float(model.tau * model.duration_)


def _owner(scene, solid_label: str) -> str:
    """The part a solid belongs to ("4/stud" belongs to "4")."""
    for solid in scene.solids:
        if solid.label == solid_label:
            return solid.part
    return solid_label


def _final_approach_time(trajectory, goal, height, axis) -> float:
    """The time (s) the motion enters the final approach band for the last time (its whole length
    when it has no band)."""
    if height is None:
        return float(trajectory.t[-1])
    axis = np.array([0.0, 0.0, 1.0]) if axis is None else np.asarray(axis, dtype=float)
    along = (trajectory.y[:, :3] - np.asarray(goal)[:3]) @ axis
    above = np.flatnonzero(along >= height)
    return float(trajectory.t[above[-1]]) if above.size else 0.0


def _first_line(exc: Exception) -> str:
    return str(exc).splitlines()[0][:300] if str(exc) else type(exc).__name__
