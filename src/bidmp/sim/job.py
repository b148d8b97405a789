"""The whole job on the simulated arm: at every target, in the job's order, the learned approach,
then the job's steps (engage, unscrew, retract, drop; or grasp, (rock,) lift, place), each a motion
planned through the arm's IK, timed within its limits, executed at 1 kHz and judged by the motion
contract (:mod:`bidmp.tasks.contract`) on what the arm did.

Every motion between places comes from the learned skills: the approach is the Bi-DMP's (skill
"nearest") from wherever the tool is, repaired like any motion that would break the contract
(:mod:`bidmp.tasks.repair`: lifted over a part by via-points, steered round it, or a skill learned
for this target); the transfers to the bin or the rack are the plain DMP's start and goal
generalisation, lifted over the work by a via-point where the tool or the part it carries would
come within the margin of a part. Straight moves along a part's axis (unscrewing, retracting,
lifting out) are lines. Rocking a part loose is a periodic skill (a rhythmic DMP learned from a
recording) run from rest at the grasp and back to rest there, at its learned timing. The
unscrewing is a powered spindle on the tool coupled to the retraction:
it turns the socket by one turn per pitch the arm rises (measured, every 2 ms), which a wrist
cannot (its last joint turns less than one turn each way) and which keeps the nut on its thread
whatever the arm's timing. A tilted part (a pose scenario) is approached by the pose skill along
its own axis and unscrewed and lifted along it.

A target whose step fails is a row of the report with its reason; the job goes on with the next.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np

from .._checks import TaskRefusal
from .._units import length_digits, length_text, mm
from ..tasks.contract import Contract
from .backend import MovablePart
from .job_report import JobPhase, JobReport, JobTarget, in_bin, in_slot
from .job_world import (
    _body,
    _Move,
    _move,
    _plan_key,
    _StepFailed,
    _transfer,
    _transfer_contract,
    _World,
)

__all__ = ["JobInternalError", "run_job", "job_targets"]


class JobInternalError(RuntimeError):
    """A job stopped by an exception that is not one of the task's refusals (a bug): the
    command's internal error, exit status 1, naming the target and the phase it happened in."""


RELEASE_S = 0.6  # s the world runs after a part is let go, for it to come to rest


# ---------------------------------------------------------------------------------------------
# Steps
# ---------------------------------------------------------------------------------------------
def _approach(world: _World, label: str, target, axis) -> JobPhase:
    """The learned approach from the tool's place now, repaired if it would break the contract."""
    exclude = world.scenario.scene.target_parts(label, target[:3]) + world.gone
    # from the tool's pose now (a pose skill starts from the measured tool frame too)
    start = np.concatenate([world.tcp, world.orientation().as_quat()]) if world.pose else world.tcp
    repaired = world.repairer.repair(
        world.model,
        target,
        label,
        start=start,
        axis=axis,
        exclude=exclude,
        arm=_links_check(world, exclude),
    )
    # A motion only the arm's links cannot run goes on to the arm's own route (_move plans it).
    if not repaired.ok and not (repaired.verdict.ok and repaired.arm):
        raise _StepFailed(f"approach: {repaired.reason()}")
    if repaired.how == "route" and repaired.model is not None:
        world.model = (
            repaired.model
        )  # the route, learned as a skill: the next targets start from it
    path, turns = repaired.motion[:, :3], (repaired.motion[:, 3:] if world.pose else None)
    fractions = np.linspace(0.0, 1.0, path.shape[0])
    note = f"repaired: {repaired.how}" if repaired.how else ""
    phase = _move(
        world,
        _Move(path, fractions, exclude, "approach", orientations=turns, target=target, axis=axis),
    )
    _note(phase, note)
    return phase


def _links_check(world: _World, exclude):
    """``check(motion) -> str``: why the arm's links cannot run a motion of the tool from its
    joints now ("" when they can, or when the arm has no model of its links): its plan's joints,
    the links on the arm's own model (pinocchio and coal, touching within 0.1 mm) against every
    part but ``exclude``. The simulated world is not touched (a check that set the simulated
    arm's joints would change the physics that follows). A motion the inverse kinematics does not
    follow is not the links' business: the arm's own route takes it (:func:`bidmp.sim.job_world._move`)."""
    from ..planning import segment_free
    from .backend import SimError
    from .routes import _arm, supports_routes

    if not supports_routes(world.cell):
        return None
    cell = world.cell
    space = _arm(cell).space(world.scene, cell.unit, exclude=exclude, margin=0.0)

    def check(motion) -> str:
        motion = np.asarray(motion, dtype=float)
        path, turns = motion[:, :3], (motion[:, 3:] if world.pose else None)
        try:
            plan = world.cell.plan(
                path,
                f"{world.label} (approach)" if world.label else "approach",
                fractions=np.linspace(0.0, 1.0, path.shape[0]),
                seed=world.q,
                orientations=turns,
            )
        except SimError:
            return ""
        # the approach that runs is planned the same way: kept for it (IK is most of a plan)
        world.planned = (_plan_key(path, turns, world.q), plan)
        joints = np.asarray(plan.joints, dtype=float)
        for a, b in zip(joints[:-1], joints[1:]):
            if not segment_free(space, a, b):
                part, depth = space.nearest(b)
                deep = length_text(max(-depth, 0.0) / cell.unit, world.scenario.units)
                return f"a link would touch {part} ({deep} deep)"
        return ""

    return check


def _note(phase: JobPhase, note: str) -> None:
    """Add how a move was made (``note``: a repair, a lift) to its phase, keeping a refusal's
    reason (a motion not run says why) ahead of it."""
    phase.note = f"{phase.note}; {note}" if phase.note and note else phase.note or note


def _engaged(world: _World, part: MovablePart, target) -> tuple[bool, str]:
    """Whether the tool's mouth is on the part's own axis (where the part is, not where the
    target says) within the tolerance, at the target's height along the axis."""
    tcp = world.tcp
    offset = tcp - part.centre0
    across = float(np.linalg.norm(offset - np.dot(offset, part.axis) * part.axis))
    along = abs(float(np.dot(tcp - np.asarray(target, dtype=float)[:3], part.axis)))
    tolerance, unit = world.spec.engage_tolerance, world.scenario.units
    if across > tolerance or along > world.scenario.success_threshold:
        return False, (
            f"the tool is {length_text(across, unit)} off the part's axis and "
            f"{length_text(along, unit)} off its height "
            f"(it engages within {tolerance:g} {unit} and {world.scenario.success_threshold:g} {unit})"
        )
    return True, f"{length_text(across, unit)} off the axis"


def _supports(world: _World, part: MovablePart) -> list:
    """The parts ``part`` stands on: those whose top is where its bottom is, under its centre."""
    bottom = part.centre0 - part.axis * part.height / 2.0
    found = []
    for other in world.scene.labels:
        if other == part.label:
            continue
        lower, upper = world.scene.bounds(other)
        under = np.all(lower[:2] <= bottom[:2]) and np.all(bottom[:2] <= upper[:2])
        if under and abs(float(upper[2] - bottom[2])) <= world.spec.play:
            found.append(other)
    return found


def _straight(
    world: _World, direction, length: float, exclude, name: str, part=None, **options
) -> JobPhase:
    """A straight move ``length`` along ``direction``, the tool's frame kept as it is."""
    start = world.tcp
    end = start + np.asarray(direction, dtype=float) * length
    turns = np.repeat(world.orientation().as_quat()[None], 2, axis=0) if world.pose else None
    on_record = options.pop("on_record", None)
    move = _Move(np.vstack([start, end]), None, exclude, name, turns, carried=part, **options)
    return _move(world, move, on_record)


def _unscrew(world: _World, part: MovablePart, exclude) -> JobPhase:
    """Turn the nut off its stud: the spindle turns the socket one turn per pitch the arm rises."""
    spec = world.spec
    stud = [s for s in world.scenario.scene.solids if s.label == f"{part.label}/stud"]
    bottom = float(np.dot(part.centre0, part.axis)) - 0.5 * part.height
    top = float(np.max([np.max(_corners(s) @ part.axis) for s in stud])) if stud else bottom
    rise = top - bottom + spec.play  # off the thread, a little clear of the stud's end
    start = float(np.dot(world.tcp, part.axis))
    phase = _straight(
        world,
        part.axis,
        rise,
        exclude,
        "unscrew",
        on_record=lambda t: part.thread(float(np.dot(world.tcp, part.axis)) - start, spec.pitch, t),
        least_duration=rise / spec.pitch / spec.spindle_speed,
    )
    if part.rise < rise - 0.1 * spec.play:
        raise _StepFailed(
            f"unscrew: the nut rose {length_text(part.rise, world.scenario.units)} of "
            f"{length_text(rise, world.scenario.units)}: still on its stud"
        )
    part.hold()
    world.held = part
    phase.note = (
        f"{rise / spec.pitch:.1f} turns, {length_text(rise, world.scenario.units)} up the thread"
    )
    return phase


def _corners(solid) -> np.ndarray:
    """The eight corners of a solid's box in its own frame, in the scene (a stud's top, a tilted one's too)."""
    if solid.kind == "cylinder":
        half = np.array([solid.params[0], solid.params[0], solid.params[1] / 2.0])
    elif solid.kind == "box":
        half = np.asarray(solid.params, dtype=float) / 2.0
    else:
        half = np.ptp(np.asarray(solid.params[0]), axis=0) / 2.0
    signs = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)])
    return (signs * half) @ np.asarray(solid.rotation).T + np.asarray(solid.centre)


def _drop_point(world: _World) -> np.ndarray:
    """Where the next part is let go: over the bin, on a grid over its floor (parts dropped all at
    its centre stack into a tower once at rest, and the tower rises out of the bin)."""
    floor, inner = world.spec.bin_floor, np.asarray(world.spec.bin[1], dtype=float)
    span = max(float(world.scene.tool.radius) * 2.0, 1e-9)
    counts = np.maximum(np.floor(inner[:2] / span).astype(int), 1)
    index = world.dropped % int(np.prod(counts))
    cell = np.array([index % counts[0], index // counts[0]])
    offset = (cell + 0.5) / counts * inner[:2] - inner[:2] / 2.0
    return floor + np.array([offset[0], offset[1], inner[2] + world.spec.clearance])


def _drop(world: _World, part: MovablePart, exclude) -> JobPhase:
    """Carry the nut over the bin (the plain DMP from here to there), let go, let it fall."""
    point = _drop_point(world)
    path, fractions, turns, note = _transfer(world, point, exclude, carried=_body(world, part))
    phase = _move(
        world,
        _Move(path, fractions, exclude, "drop", orientations=turns, carried=part, target=point),
    )
    centre = _release(world)
    world.dropped += 1
    phase.seconds += RELEASE_S
    _note(phase, note or "")
    if not in_bin(centre, world.spec.bin_floor, world.spec.bin[1]):
        phase.ok = False
        lies = np.round(centre, length_digits(world.scenario.units)).tolist()
        # (a drop refused before it ran lets go where the tool is: its refusal is the reason)
        _note(phase, f"released outside the bin: the nut lies at {lies} {world.scenario.units}")
    return phase


def _reach(
    world: _World, label: str, target, axis, record: JobTarget, step: str
) -> tuple[MovablePart, list]:
    """The approach to ``target`` and the check that the tool took the part in (``step``:
    engage, grasp); the part and the parts its moves may touch."""
    part = world.cell.movable_part(label, world.spec.part_mass)
    exclude = world.scenario.scene.target_parts(label, target[:3]) + world.gone
    approach = _approach(world, label, target, axis)
    _add(world, record, approach, target[:3])
    if not approach.ok:
        verdict = approach.verdict
        raise _StepFailed(
            f"approach: {verdict.reason() if verdict is not None and not verdict.ok else approach.note}"
        )
    engaged, note = _engaged(world, part, target)
    record.phases.append(JobPhase(step, engaged, 0.0, note))
    if not engaged:
        raise _StepFailed(f"{step}: {note}")
    return part, exclude


def _finish(record: JobTarget, part: MovablePart) -> None:
    """The part is removed when every step kept the contract and it ended where it belongs."""
    record.removed = all(phase.ok for phase in record.phases)
    record.final_position = part.pose()[0]
    record.reason = _why(record)


def _nut_cycle(world: _World, label: str, target, axis, record: JobTarget) -> None:
    """approach → engage → unscrew → retract → drop for one nut, each phase into ``record``."""
    part, exclude = _reach(world, label, target, axis, record, "engage")
    _checked(world, record, _unscrew(world, part, exclude), target[:3])
    _checked(
        world,
        record,
        _straight(world, part.axis, world.spec.clearance, exclude, "retract", part),
        target[:3],
    )
    record.thread = np.array(part.trace)
    _add(world, record, _drop(world, part, exclude), _drop_point(world))
    _finish(record, part)


def _place(world: _World, part: MovablePart, slot, exclude) -> JobPhase:
    """Carry the part to its rack slot (the plain DMP's start and goal generalisation, its kept
    approach coming straight down), set it down, let go."""
    bottom = part.pose()[0] - part.axis * part.height / 2.0
    goal = np.asarray(slot, dtype=float) + (world.tcp - bottom) + [0.0, 0.0, world.spec.play]
    path, fractions, turns, note = _transfer(
        world, goal, exclude + ["rack"], carried=_body(world, part)
    )
    phase = _move(
        world,
        _Move(
            path,
            fractions,
            exclude + ["rack"],
            "place",
            orientations=turns,
            carried=part,
            target=goal,
        ),
    )
    centre = _release(world)
    phase.seconds += RELEASE_S
    off = float(np.linalg.norm(centre[:2] - np.asarray(slot)[:2]))
    _note(phase, note)
    if not in_slot(
        centre, slot, part.height, world.spec.engage_tolerance * 5, world.spec.slot_tolerance
    ):
        phase.ok = False
        phase.note = (
            f"not in its slot: the part lies {length_text(off, world.scenario.units)} off it, at "
            f"{np.round(centre, length_digits(world.scenario.units)).tolist()}"
        )
    return phase


def _rhythm(world: _World):
    """The rock step's periodic skill, learned once per job from its recording (in mm, converted
    to the scenario's unit)."""
    if world.rhythm is None:
        from .._units import conversion
        from ..demonstrations.datasets import recording
        from ..primitives.rhythmic import RhythmicDMP

        y, t = recording(world.spec.rock.recording)
        units = world.scenario.units
        world.rhythm = RhythmicDMP().fit(y * conversion("mm", units), t, units=units)
    return world.rhythm


def _rock(world: _World, part: MovablePart, exclude) -> JobPhase:
    """Rock the held part loose: the periodic skill from rest at the grasp, its cycles, and back
    to rest there, timed as learned (slower only if the arm's limits ask), judged like any move."""
    spec, rhythm = world.spec.rock, _rhythm(world)
    motion = rhythm.run(spec.cycles, dt=0.002, amplitude=spec.amplitude, frequency=spec.frequency)
    path = world.tcp + (motion.y - rhythm.anchor_)
    swing = float(np.max(np.abs(motion.y - rhythm.anchor_)))
    phase = _move(
        world,
        _Move(
            path,
            motion.t / motion.t[-1],
            exclude,
            "rock",
            least_duration=float(motion.t[-1]),
            # IK samples fine enough for the swing: 16 or more a cycle
            spacing=max(swing / 4.0, 1e-6) * world.cell.unit,
            carried=part,
            support=_supports(world, part),
        ),
    )
    frequency = rhythm.frequency_ if spec.frequency is None else spec.frequency
    phase.note = (
        f"{spec.cycles:g} cycles at {frequency:.3g} Hz, swing up to {swing:.2g} "
        f"{world.scenario.units}, from rest and back to rest"
    )
    return phase


def _lift_cycle(world: _World, label: str, target, axis, record: JobTarget) -> None:
    """approach → grasp (→ rock) → lift straight out → place in the next rack slot, for one part."""
    part, exclude = _reach(world, label, target, axis, record, "grasp")
    part.hold()
    world.held = part
    if "rock" in world.spec.steps:
        _checked(world, record, _rock(world, part, exclude), target[:3])
    if "lift" in world.spec.steps:
        _checked(
            world,
            record,
            _straight(
                world,
                part.axis,
                part.height + world.spec.lift,
                exclude,
                "lift",
                part,
                support=_supports(world, part),
            ),
            target[:3],
        )
    slot = world.spec.slot(world.placed)
    _add(world, record, _place(world, part, slot, exclude), slot)
    _finish(record, part)
    world.placed += record.removed
    world.gone.append(label)  # out of the module, wherever it ended


def _why(record: JobTarget) -> str:
    """The first phase that failed and why, in one sentence: the contract's reason, or its note."""
    failed = next((phase for phase in record.phases if not phase.ok), None)
    if failed is None:
        return ""
    verdict = getattr(failed, "verdict", None)
    if verdict is not None and not verdict.ok:
        return f"{failed.name}: {verdict.reason()}"
    return f"{failed.name}: {failed.note}"


def _checked(world: _World, record: JobTarget, phase: JobPhase, focus) -> None:
    """Record ``phase``; a motion that broke the contract ends the target's cycle."""
    _add(world, record, phase, focus)
    if not phase.ok:
        raise _StepFailed(_why(record))


def _add(world: _World, record: JobTarget, phase: JobPhase, focus) -> None:
    """Record ``phase``; on the first cycle with pictures, a keyframe of where it ended; a keyframe
    of every phase that broke the contract, looking at the part it came too close to."""
    record.phases.append(phase)
    first = world.pictures is not None and (
        not world.pictures or world.pictures[0][0] == record.label
    )
    if first:
        image = world.cell.keyframe(record.seconds, focus)
        world.pictures.append((record.label, phase.name, record.seconds, image))
    verdict = getattr(phase, "verdict", None)
    if world.pictures is not None and verdict is not None and not verdict.ok:
        clearance = verdict.clearance
        near = focus if clearance is None or clearance.point is None else clearance.point
        world.failures.append(
            (record.label, phase.name, world.cell.keyframe(record.seconds, near), verdict.reason())
        )


def _release(world: _World) -> np.ndarray:
    """Let go of the part in the tool, let it fall and come to rest; where it lies (scene units)."""
    part, world.held = world.held, None
    part.release()
    world.cell.settle(RELEASE_S)
    centre, _ = part.pose()
    part.rest()
    return centre


def _leave(world: _World, label: str, target, axis, record: JobTarget) -> str:
    """After a failed step with the tool at the part (within the approach height above it, the
    socket on or near it): the tool first leaves along the part's own axis to the approach
    height, a move judged like any other, so that the next approach does not start from inside
    the part and drag the tool through it. Returns "" when the tool is free, else why it is not
    (then nothing else moves: the remaining targets are not attempted)."""
    height = world.scenario.approach_height
    if height is None:
        return ""
    axis = np.array([0.0, 0.0, 1.0]) if axis is None else np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    offset = world.tcp - np.asarray(target, dtype=float)[:3]
    above = float(np.dot(offset, axis))
    across = float(np.linalg.norm(offset - above * axis))
    near = across <= 2.0 * float(world.scene.tool.radius) + world.scene.margin
    if not near or above >= height:
        return ""
    exclude = world.scenario.scene.target_parts(label, np.asarray(target)[:3]) + world.gone
    held = world.held if world.held is not None and world.held.state == "held" else None
    try:
        phase = _straight(world, axis, height - above, exclude, "leave", held)
    except TaskRefusal as exc:
        phase = JobPhase("leave", False, 0.0, f"not run: {exc}")
    record.phases.append(phase)
    if phase.ok:
        return ""
    why = phase.verdict.reason() if phase.verdict is not None else phase.note
    return f"after target {label} failed, the tool could not leave it along its axis: {why}"


def _let_go(world: _World) -> None:
    """After a failed step: a part still in the tool is let go where it is (reported with its
    target), so that the next target starts with an empty tool."""
    if world.held is not None and world.held.state == "held":
        _release(world)
    world.held = None


# ---------------------------------------------------------------------------------------------
# The job's world
# ---------------------------------------------------------------------------------------------
def _job_parts(scenario, labels) -> list:
    """The job's own parts as scene parts: the bin (floor and four walls), or a shelf under the
    rack's slots (its top at their height, a part's size round them)."""
    spec = scenario.job
    if spec.kind == "unscrew":
        return _bin_parts(spec.bin[0], spec.bin[1], spec.bin_wall)
    first = spec.rack[0]
    corners = np.array([spec.slot(k) for k in range(len(labels))])
    parts = [s for s in scenario.scene.solids if s.label in labels]
    room = np.max([s.upper - s.lower for s in parts], axis=0) if parts else np.zeros(3)
    lower, upper = corners.min(axis=0) - room, corners.max(axis=0) + room
    centre = 0.5 * (lower + upper)
    thickness = mm(5.0, spec.units)
    return [
        {
            "type": "box",
            "label": "rack",
            "at": [float(centre[0]), float(centre[1]), float(first[2]) - thickness],
            "size": [float(upper[0] - lower[0]), float(upper[1] - lower[1]), thickness],
        }
    ]


def _bin_parts(bottom, inner, wall: float) -> list:
    """An open box (the bin) standing at ``bottom`` (its bottom's centre) as five thin box parts: a
    floor slab ``wall`` thick under its whole footprint, four walls ``wall`` thick and ``inner[2]``
    high on it; ``at`` is each part's bottom centre, as the scene's parts have it (scene units)."""
    bottom, inner = np.asarray(bottom, float), np.asarray(inner, float)
    half = inner / 2.0
    pieces = [(bottom, [inner[0] + 2 * wall, inner[1] + 2 * wall, wall])]
    for sign in (-1.0, 1.0):  # on the floor slab, round the inner floor
        pieces.append(
            (bottom + [sign * (half[0] + wall / 2), 0, wall], [wall, inner[1] + 2 * wall, inner[2]])
        )
        pieces.append((bottom + [0, sign * (half[1] + wall / 2), wall], [inner[0], wall, inner[2]]))
    return [
        {
            "type": "box",
            "label": "bin" if k == 0 else f"bin-wall-{k}",
            "at": np.asarray(at, float).tolist(),
            "size": [float(v) for v in size],
        }
        for k, (at, size) in enumerate(pieces)
    ]


def _job_scene(scenario, parts):
    """The scene with the job's own ``parts``: what the motions are checked against and the world holds."""
    return scenario.scene.with_parts(parts, scenario.targets)


def _order(scenario, labels) -> list:
    from ..tasks.jobs import tour

    if scenario.job.order == "listed":
        return list(labels)
    points = np.array([scenario.targets[label][:3] for label in labels])
    return [labels[i] for i in tour(points, scenario.targets[scenario.demonstrated][:3])]


def job_targets(scenario, targets=None) -> list:
    """The targets a job visits: ``targets`` (checked against the scenario's), or every target
    with a part of its own to take away (not a cell task's nut)."""
    from ..tasks.scenarios import Scenario
    from .run import _checked as _checked_names

    if not isinstance(scenario, Scenario):
        raise TypeError(
            f"scenario must be a bidmp Scenario (bidmp.tasks.load), got {type(scenario).__name__}"
        )
    if scenario.job is None:
        raise ValueError(
            f'scenario {scenario.name!r} has no "job": the steps to run at each target'
        )
    _, labels = _checked_names(scenario, ["bidmp"], targets, False)
    return (
        labels
        if targets is not None
        else [label for label in labels if label in scenario.scene.labels]
    )


def _job_world(scenario, report, cell, scene, pictures: bool, view: bool) -> _World:
    """The job's state: the learned skills, the contract on the job's scene and the arm's limits,
    the repairs of the approaches (planned with room for the arm's tracking)."""
    from ..tasks.repair import Repairer
    from .execution import TRACKING_ALLOWANCE_MM

    # the scenario's contract, on the job's scene (its parts, the bin, the rack)
    contract = dataclasses.replace(Contract.of(scenario, cell.limits), scene=scene)
    allowance = mm(TRACKING_ALLOWANCE_MM, scenario.units)
    repairer = Repairer(
        contract,
        scenario.demonstration,
        extension=scenario.extension,
        seed=scenario.seed,
        allowance=allowance,
        bidmp=scenario.bidmp,
    )
    transfers = Repairer(
        _transfer_contract(contract),
        scenario.demonstration,
        order=("lift", "avoid"),
        allowance=allowance,
    )
    return _World(
        cell,
        scenario,
        scenario.job,
        report.fitted["bidmp"],
        np.array(cell.rest, dtype=float),
        contract,
        repairer,
        transfers,
        [] if pictures else None,
        [] if view else None,
    )


def _joints_of(cell) -> tuple[tuple, tuple]:
    """(names, units) of the arm that ran: its backend's; a backend that does not name its
    joints gets ``joint1`` … in radians."""
    count = len(cell.limits.lower)
    names = tuple(getattr(cell, "joint_names", ()) or (f"joint{k + 1}" for k in range(count)))
    units = tuple(getattr(cell, "joint_units", ()) or ("rad",) * len(names))
    return names, units


def run_job(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    scenario,
    *,
    targets=None,
    report=None,
    progress=None,
    pictures: bool = False,
    view: bool = False,
    record: bool = False,
    backend=None,
) -> JobReport:
    """Run the scenario's ``"job"`` on the simulated arm at every target (or ``targets``);
    ``pictures``: keyframes of the first cycle's phases and of every phase that broke the
    contract (``JobReport.pictures``, ``JobReport.failures``); ``view``: the arm's motion over the
    first cycle (``JobReport.motions``, for the 3-D viewer); ``record``: keep each motion's measured
    tool path and 1 kHz joint commands on its phase (``JobPhase.path``, ``JobPhase.commands``);
    ``backend``: the simulator (a class or a registered name, :func:`bidmp.sim.get_backend`;
    default the PyBullet arm).

    Returns a :class:`~bidmp.sim.job_report.JobReport`: per target and phase, the contract's
    verdict, contacts with other parts and their depth, peak joint velocity, acceleration and jerk
    as fractions of the limits (commanded and measured), simulated seconds; the parts removed, the
    reason each other one was not, and the cycle times. A target that fails is a row; the job goes on.
    """
    from .._checks import check_bool
    from ..tasks.evaluation import evaluate
    from .robots import robot_placement
    from .run import _open_world, _scenario_and_backend

    pictures, view, record = (
        check_bool(pictures, "pictures"),
        check_bool(view, "view"),
        check_bool(record, "record"),
    )
    scenario, backend = _scenario_and_backend(scenario, backend)
    labels = job_targets(scenario, targets)
    if report is None:
        report = evaluate(scenario.with_robot_protocol(), ["bidmp"], geometry=False)
    base, yaw = robot_placement(scenario)
    start = time.perf_counter()
    parts = _job_parts(scenario, labels)
    scene = _job_scene(scenario, parts)
    cell = _open_world(backend, scenario, base, yaw)
    try:
        joints = _joints_of(cell)  # (asked while the world is open)
        added = {part["label"] for part in parts}
        cell.add_solids([solid for solid in scene.solids if solid.part in added])
        world = _job_world(scenario, report, cell, scene, pictures, view)
        world.record = record
        done, motions, stuck = [], {}, ""
        for label in _order(scenario, labels):
            if progress is not None:
                progress(label)
            record = JobTarget(label)
            world.label = label
            if stuck:  # the tool could not leave a failed target: nothing else may move
                record.reason = f"not attempted: {stuck}"
                done.append(record)
                continue
            target, axis = scenario.targets[label], scenario.target_axis(label)
            try:
                cycle = _nut_cycle if scenario.job.kind == "unscrew" else _lift_cycle
                cycle(world, label, target, axis, record)
            except (_StepFailed, TaskRefusal) as exc:  # the task's reasons: the target's row
                record.reason = str(exc)
                stuck = _leave(world, label, target, axis, record)
                _let_go(world)
            except Exception as exc:
                # Anything else is a bug: a row would hide it as a failed target (and the next
                # targets would start from a state nobody judged).
                phase = record.phases[-1].name if record.phases else "approach"
                raise JobInternalError(
                    f"internal error at target {label} ({phase}): {type(exc).__name__}: {exc}"
                ) from exc
            done.append(record)
            if world.motion:  # the first cycle only
                motions = {
                    ("job", label): {
                        "times": np.concatenate([t for t, _ in world.motion]),
                        "links": np.concatenate([links for _, links in world.motion]),
                    }
                }
                world.motion = None
    finally:
        cell.close()
    out = JobReport(
        scenario,
        scenario.job.kind,
        cell.name,
        done,
        wall_s=time.perf_counter() - start,
        pictures=world.pictures or [],
        motions=motions,
    )
    out.failures = world.failures
    out.evaluation, out.scene = report, scene
    out.joint_names, out.joint_units = joints
    return out
