"""Simulated task runs: every method's motion to every target executed on a simulator backend, in
worker processes (each with its own world), measured into a :class:`bidmp.sim.report.SimReport`."""

from __future__ import annotations

import atexit
import logging
import os
import time
from dataclasses import dataclass

import numpy as np

from .._checks import as_labels, check_bool, check_int, check_real, short_token
from .._trajectory import arclength
from .._units import length_digits, length_text, mm
from ..primitives.avoidance import SceneAvoidance
from ..primitives.coupling import PhaseStopping
from .backend import COUPLING, GoalUpdate, Hold, SimError
from .execution import TRACKING_ALLOWANCE_MM, _executable, _refusal
from .planning import _paced_duration, _slowed
from .pybullet.cell import RobotCell
from .report import SimMethod, SimReport, SimTarget, _measure, _SimTask
from .robots import (
    IK_TOLERANCE,
    MAX_SAMPLE_SPACING,
    PANDA_MODEL,
    RobotModel,
    _unit_of,
    robot_model,
    robot_placement,
)
from .routes import judged_route, needlessly_slow, reach, supports_routes

__all__ = ["simulate", "target_labels"]

logger = logging.getLogger(__name__)

CLOSED_LOOP_SPACING = 1e-3  # m: the IK samples a closed-loop motion is timed on


@dataclass
class _Job:
    """One motion to execute (what a worker process needs, picklable)."""

    method: str
    label: str
    rollout: np.ndarray  # (n, 3) scenario units
    exclude: list
    frames: int
    orientations: np.ndarray | None = None  # (n, 4) a pose skill's tool frames
    view: bool = False  # record the arm's joint origins along the motion (the 3-D viewer's)
    repair: str = ""  # how the evaluation repaired the motion (empty: the method's own)
    record: bool = False  # keep the measured path and the 1 kHz commands on the result


@dataclass(frozen=True)
class _SimSetup:
    """What every worker needs to build its world and judge a motion (plain data, picklable):
    the task, the scene (its dict form), the arm's base (scene units) and yaw (degrees), the
    backend and the scenario's arm, and how the motions run."""

    task: _SimTask
    scene: dict
    base: tuple
    yaw: float
    backend: type
    robot: RobotModel
    closed_loop: bool = False
    hold: Hold | None = None
    coupling: float = 0.0  # phase stopping's gain (1/unit²), closed loop
    models: dict | None = None  # method -> fitted model, closed loop
    avoid: bool = False
    goal_update: GoalUpdate | None = None
    pace: float | None = None  # the demonstration's peak tool speed (units/s), None: limits only
    # the demonstration's start (units): an arm given without a rest pose starts there
    start: tuple | None = None
    free_turn: bool = True  # the tool's turn about its axis left to the IK (a socket)


def _run_jobs(setup: _SimSetup, jobs: list, progress=None) -> list:
    """Execute ``jobs`` in one world; returns (method, label, SimTarget, frames, seconds)."""
    results = []
    cell = _world(setup)
    contract = setup.task.contract(getattr(cell, "scene", None), cell.limits)
    for job in jobs:
        if progress is not None:
            progress(job.method, job.label)
        try:
            results.append(_run_one(setup, cell, contract, job))
        except SimError as exc:  # a motion that cannot run (unreachable, past a joint limit)
            results.append(_not_run(job, str(exc)))
    return results


def _touch_reason(setup: _SimSetup, cell, plan, job: _Job) -> str:
    """Why ``plan`` may not run though its tool path keeps the contract ("" when it may): a
    link of the arm would touch a part (a backend that models its links: ``arm_touch``)."""
    touch = getattr(cell, "arm_touch", None)
    touched = None if touch is None else touch(plan, job.exclude)
    if touched is None:
        return ""
    return (
        f"not run: the arm would touch {touched[0]} ({length_text(touched[1], setup.task.units)} "
        f"deep) on its way to {job.label}, though the tool's path keeps the contract"
    )


def _arm_routed(setup: _SimSetup, cell, contract, job: _Job):
    """The arm's own route to ``job``'s target from where its motion starts, judged before it
    runs (:func:`bidmp.sim.routes.judged_route`), with the repairs' tracking allowance on the
    margin and no faster than the demonstration's pace; a ``SimError`` when there is none."""
    task, label = setup.task, job.label
    target = np.asarray(task.targets[label], dtype=float)
    axis = task.axes.get(label)
    plan = judged_route(
        cell,
        contract,
        job.rollout[0],
        target,
        axis=axis,
        approach_height=task.approach_height or 0.0,
        exclude=job.exclude,
        margin=cell.scene.margin + mm(TRACKING_ALLOWANCE_MM, task.units),
        pace=setup.pace,
        label=label,
    )
    touched = _touch_reason(setup, cell, plan, job)
    if touched:
        raise SimError(touched)
    return plan


def _not_run(job: _Job, reason: str, frames=()) -> tuple:
    """The outcome of a motion not sent to the arm: its row with ``reason``, no simulated time, no
    recorded arm (the tuple ``_run_one`` returns); ``frames``: a still of the arm where it stands,
    when pictures of the motion were asked for (the strip then shows the failure, not nothing)."""
    return job.method, job.label, SimTarget.not_run(job.label, reason), list(frames), 0.0, None


def _run_one(setup: _SimSetup, cell, contract, job):
    """One motion planned, executed and measured: (method, label, SimTarget, frames, seconds, motion)."""
    # The closed loop runs the learned motion itself, not a spline through IK samples 5 mm apart,
    # which smooths its final stop: it is timed on samples 1 mm apart (else a fast descent stops
    # harder than the joints' acceleration limits, and the limiter overshoots the nut).
    spacing = CLOSED_LOOP_SPACING if setup.closed_loop else MAX_SAMPLE_SPACING
    if setup.closed_loop and job.orientations is not None:
        raise ValueError("closed_loop runs position skills; this scenario's are poses")
    target = np.asarray(setup.task.targets[job.label], dtype=float)[:3]
    slow = False
    try:
        plan = cell.plan(job.rollout, job.label, orientations=job.orientations, spacing=spacing)
        slow = not setup.closed_loop and supports_routes(cell) and needlessly_slow(cell, plan)
        _slowed(plan, _paced_duration(job.rollout, None, setup.pace))  # the demonstration's pace
        trouble = _touch_reason(setup, cell, plan, job)
    except SimError as exc:  # a point out of the IK's reach from the joints before it, a limit
        plan, trouble = None, str(exc)
    repair = job.repair
    if slow and not trouble:  # near a singularity: the arm's own route, where it is faster
        try:
            routed = _arm_routed(setup, cell, contract, job)
        except SimError:
            routed = None
        if routed is not None and routed.duration < plan.duration:
            plan = routed
            repair = f"{repair} + arm route (faster)" if repair else "arm route (faster)"
    if trouble:
        # The arm's own route where the skill's motion cannot run on the arm (the closed loop
        # runs the skill itself, on the measured tool: it has no other motion to run).
        if setup.closed_loop or not supports_routes(cell):
            return _not_run(job, trouble)
        try:
            plan = _arm_routed(setup, cell, contract, job)
        except SimError as exc:
            return _not_run(job, f"{trouble}; the arm's own route: {exc}")
        repair = f"{repair} + arm route" if repair else "arm route"
    if setup.closed_loop:
        coupling = setup.coupling
        if setup.avoid:  # steered round every part but the target's, with phase stopping
            coupling = [PhaseStopping(coupling), SceneAvoidance(cell.scene, target=job.label)]
        stepper = _stepper(setup.models, job.method, target, plan.duration, coupling)
        update = setup.goal_update
        run = cell.execute_closed_loop(
            stepper, plan.duration, job.exclude, setup.hold, job.frames, goal_update=update
        )
        if update is not None:  # judged at where the part turned out to be
            target = target + np.asarray(update.offset)
    else:
        run = cell.execute(plan, job.exclude, setup.hold, job.frames)
    measured = _measure(
        setup.task,
        job.label,
        target,
        (plan, run),
        cell.unit,
        setup.closed_loop,
        (cell.limits, contract, job.exclude),
    )
    measured.repair = repair
    measured.commanded_penetration = _commanded_penetration(cell, run, job)
    if job.record:
        measured.path, measured.commands = run.tcp / cell.unit, np.asarray(run.commands)
        measured.joint_velocities = np.asarray(run.joint_velocities)
    motion = _arm_motion(cell, run) if job.view else None
    return job.method, job.label, measured, run.frames, float(run.times[-1]), motion


# The last world this process built, kept for the next call with the same scene, robot placement
# and backend: building one (two URDF loads, the parts' bodies) is a quarter of a one-target run.
# Every execution resets the joints it starts from, so a kept world runs a job as a new one would
# (the jobs of one call already share a world: results do not depend on the number of workers).
_WORLD: dict = {}


def _world(setup: _SimSetup):
    """The world of ``setup``: the kept one if it matches, else a new one (the old one closed)."""
    import json

    from ..scene.clearance import Scene

    key = (
        setup.backend,
        json.dumps(setup.scene, sort_keys=True),
        json.dumps(setup.task.targets, sort_keys=True),
        setup.task.units,
        tuple(setup.base),
        setup.yaw,
        setup.robot,
    )
    if _WORLD.get("key") != key:
        _close_world()
        scene = Scene.from_dict(setup.scene, setup.task.targets)
        # another backend need not know of arms
        arm = {} if setup.robot is PANDA_MODEL else {"robot": setup.robot}
        _WORLD["cell"] = setup.backend.load_robot(
            scene, setup.task.units, setup.base, setup.yaw, **arm
        )
        if setup.start is not None:
            _start_where_it_works(_WORLD["cell"], setup.robot, setup.start)
        _WORLD["key"] = key
    _WORLD["cell"].free_turn = setup.free_turn
    return _WORLD["cell"]


def _close_world() -> None:
    cell = _WORLD.pop("cell", None)
    _WORLD.pop("key", None)
    if cell is not None:
        cell.close()


atexit.register(_close_world)


def simulate(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    scenario,
    methods=("dmp", "bidmp"),
    *,
    closed_loop: bool = False,
    targets=None,
    hold: Hold | None = None,
    coupling: float | None = None,
    progress=None,
    frames: dict | None = None,
    report=None,
    workers: int | None = None,
    backend=None,
    avoid: bool = False,
    goal_update: GoalUpdate | None = None,
    views=(),
    record: bool = False,
) -> SimReport:
    """Execute ``methods`` on every target of ``scenario`` on the simulated arm (the Panda, or
    the one the scenario's ``"robot"`` names).

    Parameters
    ----------
    scenario : Scenario or str
        Needs a ``"scene"``; ``"robot": {"base": [x, y, z], "yaw": deg}`` places the arm, and
        ``"model": "iiwa"`` or ``"urdf"``/``"flange"``/``"limits"`` choose it.
    methods : sequence of str
        Evaluation methods (dmp, bidmp, ...): their rollouts are what is executed.
    closed_loop : bool
        Run the DMP/Bi-DMP stepper on the measured TCP with phase stopping, for dmp and bidmp, with
        the skills on the robot protocol (a paper-protocol scenario's are learned again on it: its
        fixed horizon stops a motion that is still moving).
    coupling : float, optional
        Phase stopping's ``alpha_e`` in 1/unit² (default :data:`COUPLING` per m², 0.5 /mm²).
    targets, hold : list of str, Hold, optional
        A subset of the targets (default all); a scripted disturbance in every motion.
    progress : callable, optional
        Called with ``(method, label)`` as each motion starts (in-process) or finishes (workers).
    frames : dict, optional
        ``{(method, label): n}``: render n frames of those motions (PyBullet's TinyRenderer).
    report : bidmp.tasks.evaluation.Report, optional
        The motions to execute, from :func:`execution_report` of the same scenario (evaluated
        once for several calls); default: evaluated here the same way. A report judged any
        other way is refused: what runs is what the contract judged and repaired.
    workers : int, optional
        Worker processes, each with its own PyBullet world (default: one per core, at most 2;
        1 runs in this process). Results do not depend on it.
    backend : class or str, optional
        A simulator backend (:class:`bidmp.sim.backend.SimulatorBackend`) or a registered name
        (:func:`bidmp.sim.get_backend`: "pybullet", "kinematic"); default the PyBullet arm,
        :class:`bidmp.sim.pybullet.RobotCell`.
    avoid, goal_update : bool, GoalUpdate, optional
        Closed loop: steer round the other parts (SceneAvoidance); a perception update in every
        motion (the target and the goal move; judged at the moved target).
    views : collection of (method, label), optional
        Record the arm's joint origins along these motions every 40 ms (``SimReport.motions``,
        scene units) for the 3-D viewer (:func:`bidmp.plotting.viewer.add_robot_motions`).
    record : bool
        Keep on every :class:`~bidmp.sim.report.SimTarget` what the arm did: its measured tool path
        (``path``, scene units) and the joint commands it was sent every 1 ms (``commands``, rad),
        for a check of one's own.
    """
    scenario, backend = _scenario_and_backend(scenario, backend)
    methods, labels = _checked(scenario, methods, targets, closed_loop)
    coupling = (
        COUPLING * _unit_of(scenario.units) ** 2
        if coupling is None
        else check_real(coupling, "coupling", nonnegative=True)
    )
    if closed_loop and scenario.protocol != "robot":
        # The closed loop steps the skills as a robot runs them: the paper's protocol stops at its
        # fixed horizon while still moving, and an arm stopped there overshoots the target.
        logger.info(
            "closed loop: the skills of %s on the robot protocol (the scenario's is %r)",
            scenario.name,
            scenario.protocol,
        )
        scenario = scenario.with_robot_protocol()
        if report is not None and report.scenario.protocol != "robot":
            report = None  # the skills it holds are the paper protocol's: learned again
    report = _executable(scenario, methods, report)
    base, yaw = robot_placement(scenario)
    arm = robot_model(scenario.robot, scenario.base_dir)
    jobs = _jobs(
        scenario, report, methods, labels, frames or {}, _views(views), check_bool(record, "record")
    )
    models = {name: report.fitted[name] for name in methods} if closed_loop else None
    setup = _setup(
        scenario,
        labels,
        base,
        yaw,
        closed_loop=closed_loop,
        hold=hold,
        coupling=coupling,
        models=models,
        backend=backend,
        robot=arm,
        **_loop_options(closed_loop, avoid, goal_update),
    )
    if hold is not None and not isinstance(hold, Hold):
        raise TypeError(f"hold must be a bidmp.sim.Hold (or None), got {type(hold).__name__}")
    if hold is not None and hold.joint >= _world(setup).limits.n_joints:
        raise ValueError(
            f"hold: joint {hold.joint + 1} of an arm with {_world(setup).limits.n_joints} joints"
        )
    unreachable = _unreachable(setup, scenario, labels)
    refusals = {
        (job.method, job.label): unreachable[job.label]
        if job.label in unreachable
        else _refusal(report, job.method, job.label)
        for job in jobs
    }
    skipped = [job for job in jobs if refusals[(job.method, job.label)]]
    jobs = [job for job in jobs if not refusals[(job.method, job.label)]]
    n_workers = _n_workers(workers, max(len(jobs), 1))
    start = time.perf_counter()
    outcomes = _execute_jobs(setup, jobs, n_workers, progress) if jobs else []
    stills = {}
    for (
        job
    ) in skipped:  # a still of the arm where it stands, for pictures asked of a refused motion
        if job.frames:
            focus = np.asarray(setup.task.targets[job.label], dtype=float)[:3]
            stills[(job.method, job.label)] = [_world(setup).render(target=focus)]
    outcomes += [
        _not_run(job, refusals[(job.method, job.label)], stills.get((job.method, job.label), ()))
        for job in skipped
    ]
    out = _sim_report(scenario, methods, labels, outcomes, (base, yaw), closed_loop, (backend, arm))
    out.evaluation = report
    out.wall_s = time.perf_counter() - start
    out.workers = n_workers
    return out


def _loop_options(closed_loop: bool, avoid, goal_update) -> dict:
    """``avoid`` and ``goal_update`` of :func:`simulate`, validated (closed loop only)."""
    if (avoid or goal_update is not None) and not closed_loop:
        raise ValueError(
            "avoid and goal_update act on the closed loop's stepper: give closed_loop=True"
        )
    if goal_update is not None and not isinstance(goal_update, GoalUpdate):
        raise TypeError(
            f"goal_update must be a bidmp.sim.GoalUpdate, got {type(goal_update).__name__}"
        )
    return {"avoid": check_bool(avoid, "avoid"), "goal_update": goal_update}


def _scenario_and_backend(scenario, backend):
    """The scenario (loaded if named), which must have a scene, and the backend class: given, or
    registered under a name (default "pybullet", whose extra must then be installed: checked
    here, before any work)."""
    from ..tasks import scenarios as scenario_module
    from .backend import get_backend

    scenario = scenario_module.resolve(scenario)
    if scenario.scene is None:
        raise ValueError(
            f'scenario {scenario.name!r} has no "scene": the simulator needs the parts and the tool'
        )
    if backend is None or isinstance(backend, str):
        backend = get_backend("pybullet" if backend is None else backend)
    elif not callable(getattr(backend, "load_robot", None)):
        raise TypeError(
            "backend must be a simulator backend (a class with load_robot, see "
            f"bidmp.sim.SimulatorBackend) or a registered name, got {type(backend).__name__}"
        )
    return scenario, backend


def _open_world(backend, scenario, base, yaw):
    """A new world of ``backend`` for ``scenario``: its scene, the arm the scenario names (a
    backend that has its own arm is not told of it) at ``base`` turned ``yaw``, starting where
    it can work."""
    arm = robot_model(scenario.robot, scenario.base_dir)
    robot = {} if arm is PANDA_MODEL else {"robot": arm}
    cell = backend.load_robot(scenario.scene, scenario.units, base, yaw, **robot)
    _start_where_it_works(cell, arm, np.asarray(scenario.demonstration, dtype=float)[0, :3])
    cell.free_turn = _turn_is_free(scenario)
    return cell


def _turn_is_free(scenario) -> bool:
    """Whether the tool's turn about its own axis is left to the arm's IK: a socket, symmetric
    about its axis and turned by a spindle (the nut task, or a scenario without a job), may turn
    as the arm likes; a gripper holding a cell turns the cell with it, so its frame is kept."""
    return scenario.job is None or scenario.job.kind == "unscrew"


def _start_where_it_works(cell, arm: RobotModel, start) -> None:
    """An arm given without a rest pose (a URDF's, no ``"robot": {"rest": ...}``) starts at the
    demonstration's ``start`` (scene units), tool pointing down: solved by IK within its limits,
    as far inside them as found (:func:`bidmp.sim.robots._working_rest`). Its ranges' middle,
    the fallback, is often a stretched pose from which nothing can be solved. Another backend's
    arm, or one whose rest was given, is left as it is; an arm that cannot reach the start then
    is reported so by the motions (naming ``robot.rest``)."""
    from .robots import _working_rest

    if arm.rest_given or getattr(cell, "model", None) is not arm:
        return
    q = _working_rest(cell, np.asarray(start, dtype=float)[:3] * cell.unit)
    if q is None:
        logger.info(
            "no joints of the %s reach the demonstration's start: it starts at the middle "
            "of its ranges",
            arm.name,
        )
        return
    cell.use_rest(q)


def _unreachable(setup: _SimSetup, scenario, labels) -> dict:
    """The targets out of the arm's reach from its base, each with its reason (every target, when
    the demonstration's start is out of reach: every motion starts there). The tool points down,
    or for a pose scenario as the pose says (a nut on a tilted bracket is reached tilted)."""
    from .backend import SimError

    cell = _world(setup)
    frame = "as the target's pose" if scenario.is_pose else "pointing down"
    arm_at = (
        f"{cell.name} at base {np.round(cell.base, length_digits(scenario.units)).tolist()} "
        f"{scenario.units} (tool {frame})"
    )
    where = (
        f'for the {arm_at}: out of its reach (move its base: scenario key "robot": '
        f'{{"base": ...}}), or not from its start pose (give one nearer: "robot": {{"rest": '
        f"[...]}}, rad)"
    )

    def why(pose) -> str:
        """Why ``pose`` is out of reach ("" when it is not): from the rest pose, or where the
        arm has a route model, from any of several seeds (with the reason)."""
        pose = np.asarray(pose, dtype=float)
        orientation = pose[3:7] if scenario.is_pose else None
        try:
            _, error = cell.solve_ik(pose[:3] * cell.unit, cell.rest, orientation)
        except SimError as exc:
            return str(exc)
        if error <= 10 * IK_TOLERANCE:
            return ""
        if supports_routes(cell):  # not from the rest pose: from any other joints?
            reason = reach(cell, pose[:3], orientation, seed=scenario.seed)
            return reason and f"for the {arm_at}: {reason}"
        return where

    start = why(np.asarray(scenario.demonstration, dtype=float)[0])
    if start:
        return {label: f"the demonstration's start is unreachable: {start}" for label in labels}
    reasons = {label: why(scenario.targets[label]) for label in labels}
    return {
        label: f"target {label} is unreachable: {reason}"
        for label, reason in reasons.items()
        if reason
    }


VIEW_STEP = 0.04  # s between the arm's poses the viewer animates (25 per second)


def _arm_motion(cell, run) -> dict:
    """The arm's joint origins (scene units) every :data:`VIEW_STEP` of the recorded motion."""
    every = max(1, int(round(VIEW_STEP / float(np.median(np.diff(run.times))))))
    picked = np.unique(np.r_[np.arange(0, len(run.times), every), len(run.times) - 1])
    return {
        "times": run.times[picked],
        "links": np.array([cell.joint_origins(q) for q in run.joints[picked]]) / cell.unit,
    }


def _commanded_penetration(cell, run, job) -> float | None:
    """How deep the *commanded* tool goes into a part other than the target's, from the scene's
    geometry (scene units; 0: clear) — beside the simulator's contact depth, which the physics
    keeps small by pushing the arm aside. None for pose skills (the tool's tilt is not replayed)."""
    scene = getattr(cell, "scene", None)
    if scene is None or job.orientations is not None:
        return None
    clearance = scene.clearance(run.commanded_tcp / cell.unit, exclude=job.exclude)
    return max(0.0, -float(clearance.distance))


def _jobs(scenario, report, methods, labels, frames: dict, views=(), record: bool = False) -> list:
    """One job per method and target: the rollout to execute, the parts it may touch, frames to
    render, whether the viewer records the arm's motion."""
    return [
        _Job(
            method,
            label,
            np.asarray(report.methods[method].rollouts[label]),
            scenario.scene.target_parts(label, scenario.targets[label]),
            int(frames.get((method, label), 0)),
            None
            if report.methods[method].orientations is None
            else report.methods[method].orientations[label],
            view=(method, label) in views,
            repair=report.methods[method].repaired_at(label),
            record=record,
        )
        for method in methods
        for label in labels
    ]


def _setup(scenario, labels, base, yaw, **run) -> _SimSetup:
    """The set-up every worker gets; ``run``: the fields of :class:`_SimSetup` past the world's."""
    return _SimSetup(
        _SimTask.of(scenario, labels),
        scenario.scene.to_dict(),
        tuple(base.tolist()),
        yaw,
        **run,
        pace=scenario.pace,
        start=tuple(np.asarray(scenario.demonstration, dtype=float)[0, :3].tolist()),
        free_turn=_turn_is_free(scenario),
    )


def _n_workers(workers, n_jobs: int) -> int:
    n_workers = (
        min(2, os.cpu_count() or 1)
        if workers is None
        else check_int(workers, "workers", minimum=1, maximum=64)
    )
    return max(1, min(n_workers, n_jobs))


def _views(views) -> set:
    """``views`` of :func:`simulate`: (method, label) pairs."""
    if isinstance(views, (str, bytes)) or not hasattr(views, "__iter__"):
        raise TypeError(
            f"views must be a collection of (method, label) pairs, got {type(views).__name__}"
        )
    pairs = set()
    for pair in views:
        if not (
            isinstance(pair, tuple) and len(pair) == 2 and all(isinstance(v, str) for v in pair)
        ):
            raise TypeError(f"views must hold (method, label) pairs of strings, got {pair!r:.60}")
        pairs.add(pair)
    return pairs


def _sim_report(
    scenario, methods, labels, outcomes, placement: tuple, closed_loop: bool, robot: tuple
) -> SimReport:
    """The workers' outcomes ``(method, label, measured, images, seconds, motion)`` as a report,
    in the order of the methods and targets (whatever order the workers finished in);
    ``placement`` = (the robot's base, its yaw), ``robot`` = (the backend, the arm)."""
    base, yaw = placement
    backend, arm = robot
    # the scenario's arm (PyBullet's, MuJoCo's: the same URDF); another backend brings its own
    ours = isinstance(backend, type) and issubclass(backend, RobotCell)
    limits = arm.limits if ours else getattr(backend, "limits", None)
    by_key = {
        (method, label): (measured, images, seconds)
        for method, label, measured, images, seconds, _ in outcomes
    }
    out = SimReport(
        scenario,
        {},
        base,
        yaw,
        closed_loop,
        limits=limits,
        robot=arm.name if ours else getattr(backend, "name", getattr(backend, "__name__", "robot")),
        simulator=getattr(backend, "simulator", backend.__name__),
    )
    out.motions = {
        (method, label): motion for method, label, _, _, _, motion in outcomes if motion is not None
    }
    for method in methods:
        out.methods[method] = SimMethod(
            method,
            {label: by_key[(method, label)][0] for label in labels},
            scenario.success_threshold,
        )
        out.pictures += [
            (method, label, by_key[(method, label)][1])
            for label in labels
            if by_key[(method, label)][1]
        ]
    out.simulated_s = sum(value[2] for value in by_key.values())
    return out


def target_labels(scenario, targets) -> list[str]:
    """The labels of ``targets`` (None: every target of the scenario), each one the scenario has."""
    from ..tasks.scenarios import Scenario

    if not isinstance(scenario, Scenario):
        raise TypeError(
            f"scenario must be a bidmp Scenario (bidmp.tasks.load), got {type(scenario).__name__}"
        )
    labels = scenario.labels if targets is None else as_labels(targets, "targets")
    if not labels:  # (the command line's --targets ' ' too)
        raise ValueError(
            f"targets names no target: give at least one of the scenario's ("
            f"{', '.join(scenario.labels[:20])}), or leave it out for all of them"
        )
    for label in labels:
        if label not in scenario.targets:
            raise ValueError(
                f"targets: unknown target {short_token(label, 20)}; the scenario's targets: "
                f"{', '.join(scenario.labels[:20])}"
            )
    return list(labels)


def _checked(scenario, methods, targets, closed_loop: bool) -> tuple[list, list]:
    """The methods (registered; with a stepper for the closed loop) and target labels to run."""
    methods = list(dict.fromkeys(methods))
    if not methods:
        raise ValueError("methods is empty: name at least one of dmp, bidmp, ...")
    labels = target_labels(scenario, targets)
    from ..tasks import methods as registry

    open_only = [name for name in methods if not registry.get(name).closed_loop]
    if closed_loop and open_only:
        raise ValueError(
            f"closed_loop runs the methods' steppers: {', '.join(open_only)} has none (methods with one: "
            f"{', '.join(registry.names(closed_loop=True))})"
        )
    return methods, labels


def _execute_jobs(setup: _SimSetup, jobs: list, n_workers: int, progress) -> list:
    """Every job's outcome, in this process or spread over ``n_workers`` worker processes."""
    if n_workers == 1:
        return _run_jobs(setup, jobs, progress)
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    # One job at a time to whichever worker is free, the costliest first (the ones that render
    # frames, then the longest paths): fixed chunks put a scenario's far target, pictures and
    # all, on one worker for every method while the other sat idle. "fork" (where there is one)
    # starts the workers in milliseconds, works from any __main__, and hands each worker a copy
    # of this process's world (PyBullet's DIRECT world lives in the process's memory): no world
    # is built again. "spawn" elsewhere: each worker builds one for its first job and keeps it.
    # A motion starts from its own reset state, so the measurements do not depend on which
    # world ran it (tested against one worker).
    outcomes = []
    method = "fork" if "fork" in multiprocessing.get_all_start_methods() else "spawn"
    with ProcessPoolExecutor(n_workers, mp_context=multiprocessing.get_context(method)) as pool:
        futures = [pool.submit(_run_jobs, setup, [job]) for job in sorted(jobs, key=_job_cost)]
        for future in as_completed(futures):
            for outcome in future.result():
                if progress is not None:
                    progress(outcome[0], outcome[1])
                outcomes.append(outcome)
    return outcomes


def _job_cost(job) -> tuple[int, float]:
    """A sort key, costliest job first: the frames it renders (tens of ms each), then its path's
    length (the motion's duration grows with it)."""
    return (-job.frames, -float(arclength(job.rollout[:, :3])[-1]))


def _stepper(models, method, goal, duration, coupling):
    """The registered method's stepper to ``goal`` on its fitted model."""
    from ..tasks import methods as registry

    return registry.get(method).stepper(models[method], goal, duration, coupling)
