"""The whole job on the simulated arm: at every target, in the job's order, the learned approach,
then the job's steps (engage, unscrew, retract, drop; or grasp, lift, place), each a motion
planned through the arm's IK, timed within its limits and executed at 1 kHz, measured.

Every motion between places comes from the learned skills: the approach is the Bi-DMP's (skill
"nearest") from wherever the tool is, the transfers to the bin or the rack the plain DMP's start
and goal generalisation; each is clearance-checked on the scene before it runs, and one that would
touch a part is lifted by a via-point over the work (the DMP's exact via-points) — nothing is
written per target. Straight moves along a part's axis (unscrewing, retracting, lifting out) are
lines. The unscrewing is a powered spindle on the tool coupled to the retraction: it turns the
socket by one turn per pitch the arm rises (measured, every 2 ms), which a wrist cannot (its
last joint turns less than one turn each way) and which keeps the nut on its thread whatever the
arm's timing.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .job_report import JobPhase, JobReport, JobTarget, _phase
from .pybullet.parts import _add_job_solids, _MovablePart, _rest, _settle

__all__ = ["run_job", "job_targets"]

RELEASE_S = 0.6  # s the world runs after a part is let go, for it to come to rest


@dataclass
class _World:
    cell: object
    scenario: object
    spec: object
    model: object  # the fitted Bi-DMP
    q: np.ndarray  # the arm's joints now (rad)
    pictures: list | None = None  # keyframes at the end of each phase of the first cycle, when asked for
    motion: list | None = None  # (times, joint origins) of the first cycle's motions, for the viewer
    clock: float = 0.0  # simulated seconds since the job began
    placed: int = 0  # parts in the rack so far
    held: object = None  # the part in the tool, if any (let go where it is when a step fails)
    gone: list = field(default_factory=list)  # whole parts taken away (cells): no longer in the way
    scene: object = None  # the scenario's scene with the job's own parts (bin, rack): motions are checked on it

    @property
    def tcp(self) -> np.ndarray:
        return self.cell.tcp_position() / self.cell.unit


def _move(world: _World, path, fractions, exclude, name: str, on_record=None, least_duration: float = 0.0,
          carried=None):
    """Plan ``path`` (n, 3) from the arm's joints now, execute it, measure the phase; with a
    ``carried`` part, its own contacts with other parts count as the arm's."""
    cell = world.cell
    plan = cell.plan(np.asarray(path, dtype=float), name, fractions=fractions, seed=world.q)
    if plan.duration < least_duration:  # slower than the limits allow: every peak scales down
        scale = plan.duration / least_duration
        plan.duration = least_duration
        plan.peak_velocity *= scale
        plan.peak_acceleration *= scale**2
        plan.peak_jerk *= scale**3
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
    world.clock += phase.seconds
    return phase


def _skill_path(world: _World, goal, skill, via=None) -> tuple[np.ndarray, np.ndarray]:
    """The learned skill's motion from the tool's place now to ``goal`` (positions, fractions)."""
    options = {"goal": np.asarray(goal, dtype=float), "start": world.tcp, "skill": skill}
    if via is not None:
        options["via"] = via
    trajectory = world.model.trajectory(**options)
    return trajectory.y, trajectory.t / trajectory.t[-1]


def _clearance(world: _World, path, exclude, carried: float):
    """The tool's clearance along ``path``; with a part of height ``carried`` under its mouth, the
    smaller of the tool's and that of the part's bottom (the path lowered by its height)."""
    scene = world.scene
    clearance = scene.clearance(path, exclude=exclude)
    if carried > 0.0:
        below = scene.clearance(np.asarray(path) - [0.0, 0.0, carried], exclude=exclude)
        clearance = min(clearance, below, key=lambda c: c.distance)
    return clearance


def _clear_path(world: _World, goal, skill, exclude, carried: float = 0.0) -> tuple[np.ndarray, np.ndarray, str]:
    """The skill's motion to ``goal``, lifted by a via-point over the work if it (or the part it
    carries, ``carried`` high) would touch a part; and a note of what was done."""
    scene = world.scene
    path, fractions = _skill_path(world, goal, skill)
    clearance = _clearance(world, path, exclude, carried)
    if clearance.distance >= 0.0:
        return path, fractions, ""
    top = max(float(np.max([s.upper[2] for s in scene.solids])) + carried, float(world.tcp[2]), float(goal[2]))
    over = 0.5 * (world.tcp + np.asarray(goal, dtype=float))
    over[2] = top + world.spec.clearance
    lifted, fractions = _skill_path(world, goal, skill, via=[(0.5, over)])
    again = _clearance(world, lifted, exclude, carried)
    if again.distance < 0.0:
        raise _StepFailed(f"the learned motion would touch {clearance.part} ({-clearance.distance:.2f} "
                          f"{world.scenario.units} deep), and lifted over the work still {again.part}")
    return lifted, fractions, f"lifted over the work (it would have touched {clearance.part})"


def _transfer(world: _World, goal, exclude, carried: float = 0.0) -> tuple[np.ndarray, np.ndarray, str]:
    """A move to the bin or the rack from the learned skill: the DMP's start and goal
    generalisation (lifted over the work if it would touch), or with ``transfer: "similarity"``
    the plain DMP's own reproduction turned (the smallest rotation taking its start-to-goal onto
    this one), scaled and moved to run from the tool's place to ``goal``."""
    if world.spec.transfer == "dmp":
        return _clear_path(world, goal, 0, exclude, carried)
    from scipy.spatial.transform import Rotation

    reproduction = world.model.trajectory(skill=0)
    shape, start, goal = reproduction.y, world.tcp, np.asarray(goal, dtype=float)
    demonstrated, wanted = shape[-1] - shape[0], goal - start
    turn, _ = Rotation.align_vectors([wanted], [demonstrated])
    path = start + np.linalg.norm(wanted) / np.linalg.norm(demonstrated) * turn.apply(shape - shape[0])
    clearance = _clearance(world, path, exclude, carried)
    if clearance.distance < 0.0:
        raise _StepFailed(f"the learned shape, turned and scaled, would touch {clearance.part} "
                          f"({-clearance.distance:.2f} {world.scenario.units} deep)")
    return path, reproduction.t / reproduction.t[-1], "the skill's shape turned and scaled"


class _StepFailed(Exception):
    """A step that cannot be done; the message says which and why."""


def _approach(world: _World, label: str, target) -> JobPhase:
    exclude = world.scenario.scene.target_parts(label, target) + world.gone
    path, fractions, note = _clear_path(world, target, "nearest", exclude)
    phase = _move(world, path, fractions, exclude, "approach")
    phase.note = note
    return phase


def _engaged(world: _World, part: _MovablePart, target) -> tuple[bool, str]:
    """Whether the tool's mouth is on the part's own axis (where the part is, not where the
    target says) within the tolerance, at the target's height."""
    tcp = world.tcp
    offset = tcp - part.centre0
    across = float(np.linalg.norm(offset - np.dot(offset, part.axis) * part.axis))
    along = abs(float(np.dot(tcp - np.asarray(target, dtype=float), part.axis)))
    tolerance = world.spec.engage_tolerance
    if across > tolerance or along > world.scenario.success_threshold:
        return False, (f"the tool is {across:.2f} {world.scenario.units} off the part's axis and {along:.2f} off its "
                       f"height (engages within {tolerance:g} and {world.scenario.success_threshold:g})")
    return True, f"{across:.3f} {world.scenario.units} off the axis"


def _straight(world: _World, direction, length: float, exclude, name: str, part=None, **options) -> JobPhase:
    start = world.tcp
    end = start + np.asarray(direction, dtype=float) * length
    return _move(world, np.vstack([start, end]), None, exclude, name, carried=part, **options)


def _unscrew(world: _World, part: _MovablePart, exclude) -> JobPhase:
    """Turn the nut off its stud: the spindle turns the socket one turn per pitch the arm rises."""
    spec = world.spec
    stud = [s for s in world.scenario.scene.solids if s.label == f"{part.label}/stud"]
    bottom = float(np.dot(part.centre0, part.axis)) - 0.5 * part.height
    top = float(np.max([np.dot(s.upper, part.axis) for s in stud])) if stud else bottom
    rise = top - bottom + 0.5  # off the thread, half a unit clear of the stud's end
    start = float(np.dot(world.tcp, part.axis))
    phase = _straight(world, part.axis, rise, exclude, "unscrew",
                      on_record=lambda t: part.thread(float(np.dot(world.tcp, part.axis)) - start, spec.pitch, t),
                      least_duration=rise / spec.pitch / spec.spindle_speed)
    if part.rise < rise - 0.05:
        raise _StepFailed(f"the nut rose {part.rise:.2f} of {rise:.2f} {world.scenario.units}: still on its stud")
    part.hold()
    world.held = part
    phase.note = f"{rise / spec.pitch:.1f} turns, {rise:.2f} {world.scenario.units} up the thread"
    return phase


def _drop_point(world: _World) -> np.ndarray:
    floor, inner = world.spec.bin
    return floor + [0.0, 0.0, inner[2] + world.spec.clearance]


def _drop(world: _World, part: _MovablePart, exclude) -> JobPhase:
    """Carry the nut over the bin (the plain DMP from here to there), let go, let it fall."""
    path, fractions, note = _transfer(world, _drop_point(world), exclude)
    phase = _move(world, path, fractions, exclude, "drop", carried=part)
    centre = _release(world)
    phase.seconds += RELEASE_S
    floor, inner = world.spec.bin
    inside = bool(np.all(np.abs(centre[:2] - floor[:2]) <= inner[:2] / 2.0) and floor[2] <= centre[2] <= floor[2] + inner[2])
    phase.note = note or ""
    if not inside:
        phase.ok = False
        phase.note = f"released outside the bin: the nut lies at {np.round(centre, 1).tolist()} {world.scenario.units}"
    return phase


def _reach(world: _World, label: str, target, record: JobTarget, step: str) -> tuple[_MovablePart, list]:
    """The approach to ``target`` and the check that the tool took the part in (``step``:
    engage, grasp); the part and the parts its moves may touch."""
    part = _MovablePart(world.cell, label, world.spec.part_mass)
    exclude = world.scenario.scene.target_parts(label, target) + world.gone
    _add(world, record, _approach(world, label, target), target)
    engaged, note = _engaged(world, part, target)
    record.phases.append(JobPhase(step, engaged, 0.0, note))
    if not engaged:
        raise _StepFailed(f"{step}: {note}")
    return part, exclude


def _finish(record: JobTarget, part: _MovablePart) -> None:
    record.removed = record.phases[-1].ok
    record.final_position = part.pose()[0]
    record.reason = _why(record)


def _nut_cycle(world: _World, label: str, target, record: JobTarget) -> None:
    """approach → engage → unscrew → retract → drop for one nut, each phase into ``record``."""
    part, exclude = _reach(world, label, target, record, "engage")
    _add(world, record, _unscrew(world, part, exclude), target)
    _add(world, record, _straight(world, part.axis, world.spec.clearance, exclude, "retract", part), target)
    record.thread = np.array(part.trace)
    _add(world, record, _drop(world, part, exclude), _drop_point(world))
    _finish(record, part)


def _place(world: _World, part: _MovablePart, slot, exclude) -> JobPhase:
    """Carry the part to its rack slot (the plain DMP's start and goal generalisation, its kept
    approach coming straight down), set it down, let go."""
    bottom = part.pose()[0] - part.axis * part.height / 2.0
    goal = np.asarray(slot, dtype=float) + (world.tcp - bottom) + [0.0, 0.0, 0.5]  # let go half a unit above
    path, fractions, note = _transfer(world, goal, exclude, carried=part.height)
    phase = _move(world, path, fractions, exclude, "place", carried=part)
    centre = _release(world)
    phase.seconds += RELEASE_S
    off = float(np.linalg.norm(centre[:2] - np.asarray(slot)[:2]))
    phase.note = note
    if off > world.spec.engage_tolerance * 5 or abs(centre[2] - part.height / 2.0 - slot[2]) > 1.0:
        phase.ok = False
        phase.note = f"not in its slot: the part lies {off:.1f} {world.scenario.units} off it, at {np.round(centre, 1).tolist()}"
    return phase


def _lift_cycle(world: _World, label: str, target, record: JobTarget) -> None:
    """approach → grasp → lift straight out → place in the next rack slot, for one part."""
    part, exclude = _reach(world, label, target, record, "grasp")
    part.hold()
    world.held = part
    if "lift" in world.spec.steps:
        _add(world, record, _straight(world, part.axis, part.height + world.spec.lift, exclude, "lift", part), target)
    slot = world.spec.slot(world.placed)
    _add(world, record, _place(world, part, slot, exclude), slot)
    _finish(record, part)
    world.placed += record.removed
    world.gone.append(label)  # out of the module, wherever it ended


def _why(record: JobTarget) -> str:
    """The first phase that failed and why: what it touched (and how deep), or its note."""
    failed = next((phase for phase in record.phases if not phase.ok), None)
    if failed is None:
        return ""
    if failed.contacts:
        touched = ", ".join(f"{label} ({depth:.2f} deep)" for label, depth in sorted(failed.contacts.items()))
        return f"{failed.name}: touched {touched}"
    return f"{failed.name}: {failed.note}"


def _add(world: _World, record: JobTarget, phase: JobPhase, focus) -> None:
    """Record ``phase``; on the first cycle with pictures, a keyframe of where it ended."""
    record.phases.append(phase)
    if world.pictures is not None and (not world.pictures or world.pictures[0][0] == record.label):
        image = world.cell.keyframe(record.seconds, focus)
        world.pictures.append((record.label, phase.name, record.seconds, image))


def _release(world: _World) -> np.ndarray:
    """Let go of the part in the tool, let it fall and come to rest; where it lies (scene units)."""
    part, world.held = world.held, None
    part.release()
    _settle(world.cell, RELEASE_S)
    centre, _ = part.pose()
    _rest(part)
    return centre


def _let_go(world: _World) -> None:
    """After a failed step: a part still in the tool is let go where it is (reported with its
    target), so that the next target starts with an empty tool."""
    if world.held is not None and world.held.state == "held":
        _release(world)
    world.held = None


def _job_parts(scenario, labels) -> list:
    """The job's own parts as scene parts: the bin (floor and four walls), or a shelf under the
    rack's slots (its top at their height, a part's size round them)."""
    spec = scenario.job
    if spec.kind == "unscrew":
        return _bin_parts(*spec.bin)
    first = spec.rack[0]
    corners = np.array([spec.slot(k) for k in range(len(labels))])
    parts = [s for s in scenario.scene.solids if s.label in labels]
    room = np.max([s.upper - s.lower for s in parts], axis=0) if parts else np.zeros(3)
    lower, upper = corners.min(axis=0) - room, corners.max(axis=0) + room
    centre = 0.5 * (lower + upper)
    return [{"type": "box", "label": "rack", "at": [float(centre[0]), float(centre[1]), float(first[2]) - 5.0],
             "size": [float(upper[0] - lower[0]), float(upper[1] - lower[1]), 5.0]}]


def _bin_parts(floor, inner) -> list:
    """An open box (the bin) as five thin box parts, floor and walls 2 % of its width thick; ``at``
    is each part's bottom centre, as the scene's parts have it (scene units)."""
    floor, inner = np.asarray(floor, float), np.asarray(inner, float)
    wall = max(0.02 * float(inner[:2].min()), 1e-3 * float(inner.max()))
    half = inner / 2.0
    pieces = [(floor - [0, 0, wall], [inner[0] + 2 * wall, inner[1] + 2 * wall, wall])]
    for sign in (-1.0, 1.0):
        pieces.append((floor + [sign * (half[0] + wall / 2), 0, 0], [wall, inner[1] + 2 * wall, inner[2]]))
        pieces.append((floor + [0, sign * (half[1] + wall / 2), 0], [inner[0], wall, inner[2]]))
    return [{"type": "box", "label": "bin" if k == 0 else f"bin-wall-{k}", "at": np.asarray(at, float).tolist(),
             "size": [float(v) for v in size]} for k, (at, size) in enumerate(pieces)]


def _job_scene(scenario, parts):
    """The scene with the job's own ``parts``: what the motions are checked against and the world holds."""
    from ..scene.clearance import Scene

    data = scenario.scene.to_dict()
    data["parts"] = data["parts"] + parts
    return Scene.from_dict(data, {k: v.tolist() for k, v in scenario.targets.items()})


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
    from .run import _checked

    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario must be a bidmp Scenario (bidmp.scenarios.load), got {type(scenario).__name__}")
    if scenario.job is None:
        raise ValueError(f"scenario {scenario.name!r} has no \"job\": the steps to run at each target")
    _, labels = _checked(scenario, ["bidmp"], targets, False)
    return labels if targets is not None else [label for label in labels if label in scenario.scene.labels]


def run_job(scenario, *, targets=None, report=None, progress=None, pictures: bool = False, view: bool = False) -> JobReport:
    """Run the scenario's ``"job"`` on the simulated arm at every target (or ``targets``);
    ``pictures``: keyframes of the first cycle's phases (``JobReport.pictures``); ``view``: the
    arm's motion over the first cycle (``JobReport.motions``, for the 3-D viewer).

    Returns a :class:`~bidmp.sim.job_report.JobReport`: per target and phase, success, contacts
    with other parts and their depth, peak joint velocity, acceleration and jerk as fractions of
    the limits (commanded and measured), simulated seconds; the parts removed and the cycle times.
    """
    from .._checks import check_bool
    from ..tasks.evaluation import evaluate
    from .pybullet.cell import RobotCell
    from .pybullet.robot import robot_model, robot_placement
    from .run import _scenario_and_backend

    pictures, view = check_bool(pictures, "pictures"), check_bool(view, "view")
    scenario, _ = _scenario_and_backend(scenario, None)
    labels = job_targets(scenario, targets)
    report = evaluate(scenario.with_robot_protocol(), ["bidmp"], geometry=False) if report is None else report
    base, yaw = robot_placement(scenario)
    arm = robot_model(scenario.robot, scenario.base_dir)
    start = time.perf_counter()
    parts = _job_parts(scenario, labels)
    scene = _job_scene(scenario, parts)
    with RobotCell(scenario.scene, scenario.units, base, yaw, arm) as cell:
        added = {part["label"] for part in parts}
        _add_job_solids(cell, [solid for solid in scene.solids if solid.part in added])
        world = _World(cell, scenario, scenario.job, report.fitted["bidmp"], np.array(arm.rest, dtype=float),
                       [] if pictures else None, [] if view else None, scene=scene)
        done, motions = [], {}
        for label in _order(scenario, labels):
            if progress is not None:
                progress(label)
            record = JobTarget(label)
            try:
                cycle = _nut_cycle if scenario.job.kind == "unscrew" else _lift_cycle
                cycle(world, label, scenario.targets[label][:3], record)
            except (_StepFailed, ValueError) as exc:  # a SimError (unreachable) is a ValueError
                record.reason = str(exc)
                _let_go(world)
            done.append(record)
            if world.motion:  # the first cycle only
                motions = {("job", label): {"times": np.concatenate([t for t, _ in world.motion]),
                                            "links": np.concatenate([links for _, links in world.motion])}}
                world.motion = None
    out = JobReport(scenario, scenario.job.kind, arm.name, done, wall_s=time.perf_counter() - start, pictures=world.pictures or [],
                    motions=motions)
    out.evaluation, out.scene = report, scene
    return out
