"""The job's world on the simulated arm and how the arm moves in it: the state a job carries
from step to step (the cell, the learned skills, the contract, what the tool holds), and the
motions between places, each planned through the arm's IK, timed within its limits, executed
at 1 kHz and judged by the motion contract on what the arm did; a motion that would break it
is repaired (lifted over a part, steered round it) or the step fails, saying why."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, NamedTuple

import numpy as np
from scipy.spatial.transform import Rotation

from .._units import length_text
from ..tasks.contract import Contract
from .backend import SimError
from .job_report import JobPhase, _phase
from .planning import _paced_duration, _slowed
from .routes import needlessly_slow, supports_routes

if TYPE_CHECKING:
    from ..incremental.bidmp import BiDMP
    from ..incremental.cartesian import CartesianBiDMP
    from ..primitives.rhythmic import RhythmicDMP
    from ..tasks.jobs import JobSpec
    from ..tasks.repair import Repairer
    from ..tasks.scenarios import Scenario
    from .backend import MovablePart, SimulatorBackend

__all__ = []

_DOWN = Rotation.from_quat([1.0, 0.0, 0.0, 0.0])  # the tool pointing down (its z axis along -z)


@dataclass
class _World:
    """The state a job carries from step to step."""

    cell: SimulatorBackend  # the simulated arm and its world (a backend's cell)
    scenario: Scenario
    spec: JobSpec  # the steps at each target, the bin, the rack
    model: BiDMP | CartesianBiDMP  # the fitted Bi-DMP (a pose one for a tilted scenario)
    q: np.ndarray  # the arm's joints now (rad)
    # the job's scene (the scenario's parts, the bin, the rack), the arm's limits
    contract: Contract
    repairer: Repairer  # of the approaches
    # ... and of the transfers to the bin or the rack (lift, steer; a carried part kept clear too)
    transfers: Repairer
    # keyframes at the end of each phase of the first cycle, when asked for
    pictures: list | None = None
    # (times, joint origins) of the first cycle's motions, for the viewer
    motion: list | None = None
    clock: float = 0.0  # simulated seconds since the job began
    placed: int = 0  # parts in the rack so far
    dropped: int = 0  # parts let go over the bin so far
    # the part in the tool, if any (let go where it is when a step fails)
    held: MovablePart | None = None
    gone: list = field(default_factory=list)  # whole parts taken away (cells): no longer in the way
    # (target, phase, image) where a motion broke the contract
    failures: list = field(default_factory=list)
    record: bool = False  # keep each phase's measured path and commands
    rhythm: RhythmicDMP | None = None  # the rock step's periodic skill, learned once per job
    label: str = ""  # the target being worked on (its phases' refusals name it)
    # (what it was planned from, the plan) of the approach the links' check planned: reused
    planned: tuple | None = None

    @property
    def scene(self):
        return self.contract.scene

    @property
    def tcp(self) -> np.ndarray:
        return self.cell.tcp_position() / self.cell.unit

    @property
    def pose(self) -> bool:
        return self.scenario.is_pose

    def orientation(self) -> Rotation:
        """The tool frame now (measured)."""
        return Rotation.from_quat(self.cell.tool_orientation())


class _StepFailed(Exception):
    """A step that cannot be done; the message says which and why."""


# ---------------------------------------------------------------------------------------------
# Motions
# ---------------------------------------------------------------------------------------------
class _Move(NamedTuple):
    """A job's move: its tool ``path`` (n, 3) and the time ``fractions`` at its points (None: by
    arc length), its ``name`` (the phase) and the parts it may touch (``exclude``), and what the
    contract judges it by: its end within the threshold of ``target`` (default the path's end),
    the final descent along ``axis`` when it is the approach, the tool's ``orientations`` (n, 4)
    or None, a ``carried`` part and the parts it stands on (``support``, not counted while it is
    lifted off them); ``least_duration`` (s): no faster than that; ``spacing``: the IK samples'
    largest spacing (m; default the planner's 5 mm), finer for a small oscillation."""

    path: np.ndarray
    fractions: object
    exclude: list
    name: str
    orientations: object = None
    least_duration: float = 0.0
    spacing: float | None = None
    carried: object = None
    target: object = None
    axis: object = None
    support: tuple = ()


def _move(world: _World, move: _Move, on_record=None) -> JobPhase:
    """Plan ``move``'s path from the arm's joints now, execute it and judge what the arm did by the
    contract: its end, the approach's descent, clearance by the margin of the executed tool and of
    a carried part (its own contacts count as the arm's), the 1 kHz commands within the limits."""
    path, fractions, exclude, name = move.path, move.fractions, move.exclude, move.name
    carried, target, axis = move.carried, move.target, move.axis
    least_duration, support = move.least_duration, move.support
    cell = world.cell
    note = ""
    try:
        plan = _planned(world, move)
        # (a carried part is not rushed: its weight on a faster route is the physics' to judge)
        slow = (
            name in _ROUTED
            and carried is None
            and supports_routes(cell)
            and needlessly_slow(cell, plan)
        )
        # No faster than the demonstration's pace, nor than the step asks (the spindle's turns, a
        # rhythm's timing): the limits only ever slow a motion down.
        _slowed(plan, max(least_duration, _paced_duration(path, fractions, world.scenario.pace)))
        contract, goal = _judged_by(world, move)
        refused = _refused_plan(world, plan, contract, move, goal)
        if refused is None and slow:  # near a singularity: the arm's own route, if faster
            routed, _ = _routed(world, move, contract, goal)
            if routed is not None and routed.duration < plan.duration:
                plan, note = (
                    routed,
                    "the arm's own route (the skill's motion ran near a singularity)",
                )
    except SimError as exc:  # a point the IK does not reach from the joints now, a limit
        if name not in _ROUTED or not supports_routes(cell):
            raise
        (contract, goal), plan, refused = _judged_by(world, move), None, exc
    if refused is not None and name in _ROUTED and supports_routes(cell):
        # The motion between places cannot run from the arm's joints now: the arm's own route
        # from here, judged like any motion, before the step is given up.
        routed, why = _routed(world, move, contract, goal)
        if routed is not None:
            plan, refused, note = routed, None, "the arm's own route"
        elif isinstance(refused, SimError):
            raise SimError(f"{refused}; the arm's own route: {why}") from None
        else:
            refused.note = f"{refused.note}; the arm's own route: {why}"
    if refused is not None:
        return refused
    touched = {}
    if carried is not None:

        def on_record(t, inner=on_record):
            carried.contacts(touched, ignore=exclude)
            if inner is not None:
                inner(t)

    run = cell.execute(plan, exclude, on_record=on_record)
    world.q = run.joints[-1]
    if world.motion is not None:
        from .run import _arm_motion

        arm = _arm_motion(cell, run)
        world.motion.append((world.clock + arm["times"], arm["links"]))
    phase = _phase(name, run, plan, cell, touched)
    executed = run.tcp / cell.unit
    # the tool as it was turned: a pose's, or where the arm's own route turned it (a route turns
    # the tool as its joints go, in a position scenario too)
    tool_frames = run.tcp_orientation if world.pose or plan.orientations is not None else None
    clearance = _clearance(world, executed, exclude, carried, tool_frames, support)
    phase.verdict = contract.judge(
        executed,
        executed[-1] if target is None else np.asarray(target)[:3],
        label=name,
        axis=axis,
        exclude=exclude,
        orientations=tool_frames,
        commands=run.commands,
        contacts=phase.contacts,
        clearance=clearance,
    )
    phase.ok = phase.verdict.ok
    if note:
        phase.note = f"{phase.note}; {note}" if phase.note else note
    if world.record:
        phase.path, phase.commands = executed, np.asarray(run.commands)
    world.clock += phase.seconds
    return phase


def _plan_key(path, turns, q) -> tuple:
    """What a plan is planned from: the tool's path, its frames and the joints it starts at."""
    return (
        np.asarray(path, dtype=float).tobytes(),
        None if turns is None else np.asarray(turns, dtype=float).tobytes(),
        np.asarray(q, dtype=float).tobytes(),
    )


def _planned(world: _World, move: _Move):
    """``move``'s plan from the arm's joints now: the one the links' check of the approach made
    from the same path, frames and joints (the same call: the same plan), else a new one."""
    import copy

    kept, world.planned = getattr(world, "planned", None), None
    if kept is not None and move.spacing is None and move.fractions is not None:
        if kept[0] == _plan_key(move.path, move.orientations, world.q):
            return copy.copy(kept[1])  # (the plan's timing is stretched in place later)
    name = move.name
    return world.cell.plan(
        np.asarray(move.path, dtype=float),
        f"{world.label} ({name})" if world.label else name,  # "target 'B4 (approach)': ..."
        fractions=move.fractions,
        seed=world.q,
        orientations=move.orientations,
        **({} if move.spacing is None else {"spacing": move.spacing}),
    )


def _judged_by(world: _World, move: _Move) -> tuple:
    """The contract ``move`` is judged by (an approach's, or a transfer's without a final
    descent) and the point its end is judged at (its target, else its path's end)."""
    contract = world.contract if move.name == "approach" else _transfer_contract(world.contract)
    goal = np.asarray(move.path, dtype=float)[-1] if move.target is None else move.target
    return contract, np.asarray(goal, dtype=float)[:3]


# The moves between places: where one cannot run from the arm's joints now, the arm's own route
# is planned (the straight moves along a part's axis are the task itself: no other route).
_ROUTED = ("approach", "drop", "place")


def _routed(world: _World, move: _Move, contract, goal) -> tuple:
    """``(plan, "")`` of the arm's own route for ``move`` from its joints now
    (:func:`bidmp.sim.routes.arm_route`), judged before it runs as every motion is; ``(None,
    why)`` when there is none or the contract refuses it. An approach ends in the final approach
    down the target's axis; a drop may tilt the tool within :data:`~bidmp.sim.routes.DROP_CONE_DEG`
    of pointing down (the part falls the same); a placed part is kept upright. A carried part is
    carried along the route and kept clear."""
    from .._units import mm
    from .execution import TRACKING_ALLOWANCE_MM
    from .routes import DROP_CONE_DEG, arm_route

    cell, scenario = world.cell, world.scenario
    approach = move.name == "approach"
    target = np.asarray(move.target if move.target is not None else goal, dtype=float)
    carried = None
    if move.carried is not None:  # the part as it is now, riding on the tool from the joints now
        centre, rotation = move.carried.pose()
        carried = (move.carried.solid.moved(centre, rotation.as_matrix()), world.q)
    try:
        routed = arm_route(
            cell,
            world.q,
            target[:3],
            scene=world.scene,
            axis=(move.axis if move.axis is not None else [0.0, 0.0, 1.0]) if approach else None,
            approach_height=(scenario.approach_height or 0.0) if approach else 0.0,
            orientation=target[3:7] if approach and target.shape[0] >= 7 else None,
            exclude=list(move.exclude) + ([move.carried.label] if move.carried is not None else []),
            margin=world.scene.margin + mm(TRACKING_ALLOWANCE_MM, scenario.units),
            seed=scenario.seed,
            label=f"{world.label} ({move.name})" if world.label else move.name,
            carried=carried,
            cone=DROP_CONE_DEG if move.name == "drop" else 0.0,
            retract=_retract_length(world, target, move.axis) if approach else 0.0,
        )
    except SimError as exc:
        return None, str(exc)
    plan = routed.plan
    path = plan.points / cell.unit
    _slowed(plan, max(move.least_duration, _paced_duration(path, plan.fractions, scenario.pace)))
    planned = move._replace(
        path=path,
        fractions=plan.fractions,
        orientations=plan.orientations,  # the tool as the route turns it, judged so
    )
    refused = _refused_plan(world, plan, contract, planned, goal)
    if refused is not None:
        return None, refused.note
    return plan, ""


def _retract_length(world: _World, target, axis) -> float:
    """How far up its axis an unscrew job takes the tool from the target once the nut is in the
    socket (scene units): off the top of the part's own solids along the axis (its stud's end),
    the play, then the job's clearance; 0 for other jobs."""
    if world.spec.kind != "unscrew":
        return 0.0
    axis = np.array([0.0, 0.0, 1.0]) if axis is None else np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    solids = [solid for solid in world.scenario.scene.solids if solid.part == world.label]
    corners = [
        np.array([[x, y, z] for x in (a[0], b[0]) for y in (a[1], b[1]) for z in (a[2], b[2])])
        for a, b in ((solid.lower, solid.upper) for solid in solids)
    ]
    top = max((float(np.max(c @ axis)) for c in corners), default=float(np.dot(target[:3], axis)))
    above = max(top - float(np.dot(np.asarray(target, dtype=float)[:3], axis)), 0.0)
    return above + world.spec.play + world.spec.clearance


def _refused_plan(world: _World, plan, contract, move: _Move, goal) -> JobPhase | None:
    """The phase of a motion the contract refuses before it runs (None: it may run): the planned
    tool path of ``move`` judged as the executed one will be (its end at ``goal``, the final
    descent of an approach, the clearance of the tool and of a carried part), and the plan's joint
    peaks against the limits. A refused motion is never sent to the arm: it costs no simulated
    time."""
    path, name, axis, exclude = move.path, move.name, move.axis, move.exclude
    orientations, carried, support = move.orientations, move.carried, move.support
    planned = np.asarray(path, dtype=float)[:, :3]
    clearance = _clearance(world, planned, exclude, carried, orientations, support)
    verdict = contract.judge(
        planned,
        goal,
        label=name,
        axis=axis,
        exclude=exclude,
        orientations=orientations if world.pose else None,
        clearance=clearance,
    )
    peaks = (plan.peak_velocity, plan.peak_acceleration, plan.peak_jerk)
    over = [kind for kind, peak in zip(("velocity", "acceleration", "jerk"), peaks) if peak > 1.0]
    touch = _arm_touch(world, plan, exclude, carried) if verdict.ok and not over else None
    if verdict.ok and not over and touch is None:
        return None
    if not verdict.ok:
        why = verdict.reason()
    elif over:
        why = f"its planned joint {over[0]} exceeds the limit"
    else:
        why = f"the arm would touch {touch[0]} ({length_text(touch[1], world.scenario.units)} deep)"
    phase = JobPhase(name, False, 0.0, f"not run: the contract refuses its plan: {why}")
    phase.verdict = verdict if not verdict.ok else None
    phase.peaks = peaks
    phase.within_limits = not over
    return phase


def _arm_touch(world: _World, plan, exclude, carried) -> tuple[str, float] | None:
    """The part the arm's links would touch along ``plan`` (a backend that models its links:
    ``arm_touch``), the target's own parts, those gone and a carried part left out."""
    touch = getattr(getattr(world, "cell", None), "arm_touch", None)
    if touch is None:
        return None
    label = getattr(carried, "label", None)
    return touch(plan, list(exclude) + ([label] if label else []))


def _transfer_contract(contract: Contract) -> Contract:
    """The contract of a move that is not an approach: no final descent to judge."""
    return dataclasses.replace(contract, approach_height=None, alignment_threshold=None)


def _clearance(world: _World, path, exclude, carried, orientations=None, support=()):
    """The tool's clearance along ``path``, and of a ``carried`` part (the backend's movable part,
    or ``(solid, offset from the mouth)``) but from the parts it is lifted off (``support``): the nearer
    of the two to its margin."""
    from ..tasks.repair import carried_clearance

    if carried is not None and not isinstance(carried, tuple):  # where it is now, the tool too
        carried = _body(world, carried)
    return carried_clearance(world.scene, path, exclude, carried, support, orientations)


def _body(world: _World, part) -> tuple:
    """A carried part as the clearance checks see it: its solid where it is now and its centre's
    offset from the tool's mouth now."""
    centre, rotation = part.pose()
    return part.solid.moved(centre, rotation.as_matrix()), centre - world.tcp


def _clear_transfer(world: _World, goal, exclude, carried=None):
    """The plain skill's motion to ``goal`` (a transfer), repaired where the tool, or the part it
    carries (``carried``: its solid and offset from the mouth), would come within the margin of a
    part: lifted over it by via-points, or steered round it (:mod:`bidmp.tasks.repair`);
    ``(positions, fractions, orientations, note)``. A pose transfer ends with the tool upright
    (over the bin or a slot)."""
    start = world.tcp
    goal = np.asarray(goal, dtype=float)
    if world.pose:
        start = np.concatenate([world.tcp, world.orientation().as_quat()])
        goal = np.concatenate([goal[:3], _DOWN.as_quat()])
    repaired = world.transfers.repair(
        world.model,
        goal,
        "the transfer",
        start=start,
        exclude=exclude,
        skill=0,
        carried=carried,
    )
    if not repaired.ok:
        raise _StepFailed(repaired.reason())
    note = f"repaired: {repaired.how}" if repaired.how else ""
    motion = repaired.motion
    turns = motion[:, 3:] if world.pose else None
    return motion[:, :3], np.linspace(0.0, 1.0, motion.shape[0]), turns, note


def _closeness(clearance, unit: str) -> str:
    """How a clearance breaks the margin, in words ("cut 2.1 mm into", "pass 1.2 mm from")."""
    if clearance.distance < 0.0:
        return f"cut {length_text(-clearance.distance, unit)} into"
    return f"pass {length_text(clearance.distance, unit)} from"


def _transfer(world: _World, goal, exclude, carried=None):
    """A move to the bin or the rack from the learned skill: the DMP's start and goal
    generalisation (lifted over the work if it would come too close), or with ``transfer:
    "similarity"`` the plain DMP's own reproduction turned (the smallest rotation taking its
    start-to-goal onto this one), scaled and moved to run from the tool's place to ``goal``."""
    if world.spec.transfer == "dmp" or world.pose:
        return _clear_transfer(world, goal, exclude, carried)
    reproduction = world.model.trajectory(skill=0)
    shape, start, goal = reproduction.y, world.tcp, np.asarray(goal, dtype=float)
    demonstrated, wanted = shape[-1] - shape[0], goal - start
    turn, _ = Rotation.align_vectors([wanted], [demonstrated])
    path = start + np.linalg.norm(wanted) / np.linalg.norm(demonstrated) * turn.apply(
        shape - shape[0]
    )
    clearance = _clearance(world, path, exclude, carried)
    if not clearance.clear:
        raise _StepFailed(
            f"the learned shape, turned and scaled, would {_closeness(clearance, world.scenario.units)} "
            f"{clearance.part}"
        )
    return path, reproduction.t / reproduction.t[-1], None, "the skill's shape turned and scaled"
