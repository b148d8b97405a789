"""Scenario evaluation: every method on every target of a scenario, judged by the motion contract.

``evaluate(scenario, methods)`` returns a :class:`Report`; ``report.to_dict()`` is the JSON the
CLI writes, ``report.summary()`` the tables it prints, and :func:`write_report` writes the
results and figures. The paper's experiments built on it live in :mod:`bidmp.experiments.reproduce`.
"""

from __future__ import annotations

import copy
import logging
import time

import numpy as np

from .._checks import check_bool, check_callable, check_real
from .._progress import report
from .._trajectory import resample_time
from ..extension.extend import extend_demonstration
from ..extension.roadmap import NoFreeRouteError
from ..incremental.bidmp import BiDMP, forgetting_runs
from .methods.dmp_converged import CONVERGED_GAIN
from .metrics import path_difference
from .report import MethodResult, Report, write_report

logger = logging.getLogger(__name__)

__all__ = ["CONVERGED_GAIN", "MethodResult", "Report", "evaluate", "write_report"]


class _Timer:
    def __enter__(self):
        self._start = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self._start
        return False


def _resolve_target(target, scenario, failed: list[str]) -> np.ndarray | None:
    """An extension target: a label, a point (or pose), or the centre of the failed targets (for
    poses: their mean position and mean orientation)."""
    if isinstance(target, str) and target == "centre_of_failed":
        if not failed:
            return None
        points = np.array([scenario.targets[label] for label in failed])
        if scenario.is_pose:
            from scipy.spatial.transform import Rotation

            return np.concatenate(
                [points[:, :3].mean(axis=0), Rotation.from_quat(points[:, 3:]).mean().as_quat()]
            )
        return points.mean(axis=0)
    if isinstance(target, str):
        return scenario.targets[target]
    return np.asarray(target, dtype=float)


def _route_failure(target, exc) -> dict:
    """What the report says of an extension stage the roadmap found no free route for."""
    logger.warning(
        "no collision-free route to %s: %s", np.round(np.asarray(target)[:3], 3).tolist(), exc
    )
    return {"target": np.asarray(target, dtype=float).tolist(), "reason": str(exc)}


def _bidmp_model(scenario, dmp, failed, route_failures: list):
    """Build the scenario's Bi-DMP: chained extensions, then further demonstrations. A stage the
    roadmap finds no free route for is skipped and recorded in ``route_failures`` (the targets it
    was for then fail on their own; the rest of the evaluation goes on)."""
    model = BiDMP(dmp, **scenario.bidmp.arguments)
    extensions, targets = [], []
    previous = None
    # The paper's protocol knows no battery geometry: approach "paper" grows the extension blind.
    keep = scenario.extension.approach == "keep"
    for stage in scenario.extensions:
        target = _resolve_target(stage.target, scenario, failed)
        if target is None:
            continue  # nothing failed: no extension needed
        source = (
            scenario.demonstration
            if not stage.from_previous or previous is None
            else previous.complete
        )
        scene = scenario.scene if keep and stage.in_scene else None
        try:
            model, previous = _learned_clear(model, dmp, source, target, scenario, scene)
        except NoFreeRouteError as exc:  # that target's failure, not the whole evaluation's
            route_failures.append(_route_failure(target, exc))
            continue
        extensions.append(previous)
        targets.append(target)
    forgetting = {}
    if scenario.demonstrations:
        # learn the operators' demonstrations and measure forgetting in one pass
        if model.n_skills == 1:
            forgetting = forgetting_runs(
                model, list(scenario.demonstrations.values()), ("nearest", "latest")
            )
        else:
            for demonstration in scenario.demonstrations.values():
                model.learn(demonstration)
    return model, extensions, targets, forgetting


_REPAIRS = 3  # plannings with a wider margin when the learned skill's own rollout comes too close


def _learned_clear(model, dmp, source, target, scenario, scene):
    """``(the Bi-DMP with the stage's skill, its extension)``. With a scene that keeps a margin, the
    *learned* rollout to the stage's target is checked too — the skill does not follow its
    extension exactly — and where it comes closer than the margin, the extension is planned again
    with the margin widened by the shortfall and learned afresh, up to :data:`_REPAIRS` times; then
    the skill is kept and its motions are reported inside the margin (not clear), naming the part."""
    planning = scene
    checked = scene is not None and scene.margin > 0.0
    for attempt in range(_REPAIRS + 1):
        extension = extend_demonstration(
            source, target, seed=scenario.seed, scene=planning, **scenario.extension_arguments
        )
        # A skill that may be planned again is learned on a copy: the Bi-DMP cannot forget a block.
        trial = copy.deepcopy(model) if checked and attempt < _REPAIRS else model
        # a longer extension takes longer
        trial.learn(extension.complete, duration=extension.duration_for(dmp))
        if not checked or attempt == _REPAIRS:
            return trial, extension
        clearance = scene.clearance(trial.rollout(target), exclude=scene.parts_at(target))
        if clearance.clear:
            return trial, extension
        planning = copy.copy(planning)
        planning.margin = min(
            planning.margin + (clearance.margin - clearance.distance), scene.tool.radius
        )
        logger.info(
            "the skill learned for %s passes %.3g from %s, inside %g: planned again with a margin of %.3g",
            np.round(target, 3).tolist(),
            clearance.distance,
            clearance.part,
            clearance.margin,
            planning.margin,
        )
    return trial, extension


def _pose_bidmp_model(scenario, cartesian, failed, report):
    """The pose scenario's Bi-DMP: extensions on poses, then further demonstrations."""
    from ..extension.extend import extend_pose_demonstration
    from ..incremental.cartesian import CartesianBiDMP

    model = CartesianBiDMP(cartesian, BiDMP(**scenario.bidmp.arguments))
    previous = None
    options = scenario.extension_arguments
    del options["approach"]  # a pose extension keeps the approach
    for stage in scenario.extensions:
        target = _resolve_target(stage.target, scenario, failed)
        if target is None:
            continue
        source = scenario.demonstration if not stage.from_previous or previous is None else previous
        stage_scene = scenario.scene if stage.in_scene else None
        try:
            extension = extend_pose_demonstration(
                source, target, seed=scenario.seed, scene=stage_scene, **options
            )
        except NoFreeRouteError as exc:
            report.route_failures.append(_route_failure(target, exc))
            continue
        previous = extension.poses
        model.learn(previous, duration=extension.duration_for(cartesian.position_))
        report.extensions.append(extension)
        report.extension_targets.append(target[:3])
    for demonstration in scenario.demonstrations.values():
        model.learn(demonstration)
    return model


def _skills_builder(scenario, failed, report):
    """``build_skills(dmp)`` of the scenario's task: its Bi-DMP, recorded in the report."""

    def build(dmp):
        if scenario.is_pose:
            report.model = _pose_bidmp_model(scenario, dmp, failed, report)
        else:
            report.model, report.extensions, report.extension_targets, report.forgetting = (
                _bidmp_model(scenario, dmp, failed, report.route_failures)
            )
        return report.model

    return build


def _method_names(scenario, methods) -> list[str]:
    """The methods to run, each checked against the registry (and for poses, that it learns them)."""
    from . import methods as registry

    names = list(scenario.methods if methods is None else methods)
    if not names:
        raise ValueError("methods is empty: name at least one of " + ", ".join(registry.names()))
    for name in names:
        method = registry.get(name)
        if scenario.is_pose and not method.poses:
            raise ValueError(
                f"method {name!r} does not learn poses; a pose scenario runs "
                f"{', '.join(registry.names(poses=True))}"
            )
    return names


def evaluate(
    scenario,
    methods=None,
    progress=None,
    geometry: bool = True,
    repair: bool | None = None,
    allowance: float = 0.0,
    arm=None,
) -> Report:
    """Run ``methods`` (default: the scenario's) on every target of ``scenario``, each motion judged
    by the motion contract (:mod:`bidmp.tasks.contract`); the pipeline's method's motions that
    break it repaired (:mod:`bidmp.tasks.repair`).

    Parameters
    ----------
    scenario : Scenario or str
        A scenario, a scenario file, or a built-in name.
    methods : list of str, optional
        Names from the methods registry (:mod:`bidmp.tasks.methods`): dmp, dmp-converged, bidmp,
        bidmp-latest, gmm, tpgmm, mp-dmp, or any registered one.
    progress : callable, optional
        Called with each method name before it runs, and with ``"<method>: repair <target>"``
        before each repair (the CLI hooks a progress bar here).
    geometry : bool, default True
        Check every rollout against the scenario's scene (clearance, collisions, task success).
        False skips the checks (the extensions are still grown around the parts); the report
        then has no geometry columns.
    repair : bool, optional
        Repair the motions of the methods that repair theirs (``bidmp``) that break the contract:
        a lift over a part by via-points, the scene avoidance coupling, an extended demonstration
        to the target learned as a skill, one planned with a wider margin; a target no repair
        brings within the contract fails with its reason (``report.methods[m].reason_at``). False:
        every method as it is (the paper's protocol, ``bidmp reproduce``). Default: repair, except a
        scenario whose extension takes the paper's approach (``"approach": "paper"``: its skills
        are the paper's, the final approach not kept). Needs a scene.
    allowance : float, default 0
        Scene units the repairs add to the margin they plan for (what running the motion on an
        arm may take off it: the simulator passes its tracking allowance).
    arm : callable, optional
        ``arm(motion, label) -> str``: why an arm cannot run a motion that keeps the contract
        ("" when it can: the simulator's check of the arm's links along it). A motion it refuses
        is repaired like one the contract refuses, and a repair is kept only where the arm can
        run it (:meth:`bidmp.tasks.Repairer.repair`). Needs ``repair``.

    Returns
    -------
    Report
        ``report.to_dict()`` is its JSON (``results.json``); ``report.fitted`` holds each method's model.
    """
    from . import methods as registry
    from . import scenarios as scenario_module

    scenario = scenario_module.resolve(scenario)
    names = _method_names(scenario, methods)
    labels = scenario.labels
    goals = np.stack([scenario.targets[label] for label in labels])
    task = registry.Task(
        scenario.demonstration,
        goals,
        seed=scenario.seed,
        dmp=scenario.dmp.arguments,
        bidmp=scenario.bidmp.arguments,
        poses=scenario.is_pose,
    )
    if repair is None:
        repair = scenario.extension.approach == "keep"
    geometry = check_bool(geometry, "geometry") and scenario.scene is not None
    repair = check_bool(repair, "repair") and geometry
    allowance = check_real(allowance, "allowance", nonnegative=True)
    if arm is not None:
        check_callable(arm, "arm", "a check of an arm (motion, label) -> str")
        if not repair:
            raise ValueError("arm checks the motions repairs are kept by: give repair=True")
    settings = {"geometry": geometry, "repair": repair, "allowance": allowance}
    if arm is not None:
        settings["arm"] = True
    report = Report(scenario=scenario, methods={}, settings=settings)
    report.failed_targets = failed = _failed_targets(scenario, task, labels, goals)
    task.build_skills = _skills_builder(scenario, failed, report)
    result = _results_builder(scenario, labels, geometry)
    repairer = _repairer(scenario, allowance) if repair else None
    for name in names:
        if progress is not None:
            progress(name)
        method = registry.get(name)
        model, fit_seconds = method.fit(task)
        with _Timer() as timer:
            rollouts = method.rollouts(model, goals)
            outcome = result(name, rollouts, 0.0)
            if repairer is not None and method.repairs:
                outcome, model = _repaired(
                    outcome, (repairer, arm), model, scenario, labels, result, progress
                )
        outcome.runtime_s = fit_seconds + timer.seconds
        report.methods[name] = outcome
        report.fitted[name] = model
    if scenario.demonstrations and not report.forgetting and not scenario.is_pose:
        dmp, _ = task.fitted_dmp()
        report.forgetting = forgetting_runs(
            dmp,
            list(scenario.demonstrations.values()),
            ("nearest", "latest"),
            **scenario.bidmp.arguments,
        )
    return report


def _repairer(scenario, allowance: float):
    """The scenario's repairs: its contract, demonstration, extension options and seed."""
    from .contract import Contract
    from .repair import Repairer

    return Repairer(
        Contract.of(scenario),
        scenario.demonstration,
        extension=scenario.extension,
        seed=scenario.seed,
        allowance=allowance,
        bidmp=scenario.bidmp,
    )


def _repaired(
    outcome: MethodResult, repairs_by, model, scenario, labels, result, progress
) -> tuple[MethodResult, object]:
    """``outcome`` with every motion that broke the contract repaired where a repair keeps it
    (``outcome.repairs``: label -> :class:`~bidmp.tasks.repair.Repaired` of each one tried), and
    the model: the method's, or grown by the skills the planner's routes taught. A route is
    learned as a skill and kept: the targets repaired after it start from the grown model's own
    motion (``how`` "learned" where that keeps the contract without another repair).
    ``repairs_by`` = (the repairer, the arm's check or None): a motion the arm's links cannot run
    is repaired too, and every repair is kept only where they can."""
    repairer, arm = repairs_by
    failed = [label for label in labels if not outcome.verdicts[label].ok]
    if arm is not None:  # the motions the contract keeps but the arm's links cannot run
        blocked = {
            label: arm(_rollout(outcome, label), label)
            for label in labels
            if outcome.verdicts[label].ok
        }
        failed = [label for label in labels if label in failed or blocked.get(label)]
    if not failed:
        return outcome, model
    scene = scenario.scene
    rollouts = dict(outcome.rollouts)  # positions; a pose motion is rebuilt with its frames
    if outcome.orientations is not None:
        rollouts = {
            label: np.hstack([path, outcome.orientations[label]])
            for label, path in rollouts.items()
        }
    repairs, grown = {}, False
    for done, label in enumerate(failed):
        report("repairs", done, len(failed))
        if progress is not None:
            progress(f"{outcome.name}: repair {label}")
        known = {} if grown else {"motion": rollouts[label], "verdict": outcome.verdicts[label]}
        fixed = repairer.repair(
            model,
            scenario.targets[label],
            label,
            axis=scenario.target_axis(label),
            exclude=scene.target_parts(label, scenario.targets[label]),
            arm=None if arm is None else (lambda motion, label=label: arm(motion, label)),
            **known,
        )
        if grown and fixed.ok and not fixed.how:
            fixed.how = "learned"  # the grown model's own motion: a skill a route taught
        repairs[label] = fixed
        if fixed.how:
            rollouts[label] = fixed.motion
        if fixed.how == "route" and fixed.model is not None:
            model, grown = fixed.model, True
    report("repairs", len(failed), len(failed))
    verdicts = dict(outcome.verdicts)  # the repaired motions' verdicts are the repairs' own
    verdicts.update({label: fixed.verdict for label, fixed in repairs.items() if fixed.how})
    repaired = result(
        outcome.name, [rollouts[label] for label in labels], outcome.runtime_s, verdicts
    )
    repaired.repairs = repairs
    return repaired, model


def _rollout(outcome: MethodResult, label: str) -> np.ndarray:
    """The method's motion to ``label``: positions, or poses with their frames."""
    path = np.asarray(outcome.rollouts[label])
    if outcome.orientations is None:
        return path
    return np.hstack([path, np.asarray(outcome.orientations[label])])


def _failed_targets(scenario, task, labels, goals) -> list[str]:
    """The targets the plain DMP misses by more than the success threshold (positions)."""
    dmp, _ = task.fitted_dmp()
    if scenario.is_pose:
        ends = np.array([dmp.rollout(goal)[-1, :3] for goal in goals])
    else:
        ends = dmp.rollout_many(goals)[:, -1]
    errors = np.linalg.norm(ends - goals[:, :3], axis=1)
    return [label for label, error in zip(labels, errors) if error > scenario.success_threshold]


def _results_builder(scenario, labels, geometry: bool):
    """``result(name, rollouts, seconds) -> MethodResult``: every motion judged by the scenario's
    :class:`~bidmp.tasks.contract.Contract` (end, engagement along the target's axis, clearance from
    every part but the target's own, alignment for poses), plus the paper's "difference" against the
    reference motion to the same target."""
    from .contract import Contract

    n_steps = scenario.demonstration.shape[0]
    contract = Contract.of(scenario, geometry=geometry and scenario.scene is not None)
    scene = contract.scene
    poses = scenario.is_pose
    references = {
        label: resample_time(
            scenario.reference(label)[:, :3] if poses else scenario.reference(label), n_steps
        )
        for label in labels
    }
    excluded = (
        {}
        if scene is None
        else {label: scene.target_parts(label, scenario.targets[label]) for label in labels}
    )

    def result(name, rollouts, seconds, known=None):
        """``known``: verdicts already reached (label -> Verdict), not judged again."""
        rollouts = dict(zip(labels, rollouts))
        positions = {
            label: rollout[:, :3] if poses else rollout for label, rollout in rollouts.items()
        }
        orientations = (
            {label: rollout[:, 3:] for label, rollout in rollouts.items()} if poses else None
        )
        known = known or {}
        verdicts = {
            label: known[label]
            if label in known
            else contract.judge(
                positions[label],
                scenario.targets[label],
                label=label,
                axis=scenario.target_axis(label),
                exclude=excluded.get(label, ()),
                orientations=None if orientations is None else orientations[label],
                applies=scene is not None and scene.applies_to(label),
            )
            for label in labels
        }
        errors = {label: verdict.end_error for label, verdict in verdicts.items()}
        approach = (
            None
            if contract.approach_height is None
            else {label: verdict.approach_error for label, verdict in verdicts.items()}
        )
        deviations = (
            None
            if contract.alignment_threshold is None
            else {label: verdict.axis_deviation for label, verdict in verdicts.items()}
        )
        clearances = (
            None
            if scene is None
            else {label: verdict.clearance for label, verdict in verdicts.items()}
        )
        differences = {
            label: path_difference(positions[label], references[label]) for label in labels
        }
        return MethodResult(
            name,
            positions,
            seconds,
            errors,
            approach,
            differences,
            scenario.success_threshold,
            n_steps,
            clearances,
            orientations,
            deviations,
            scenario.alignment_threshold,
            verdicts,
        )

    return result
