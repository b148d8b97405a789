"""Scenario evaluation: every method on every target of a scenario (SPEC §9, report JSON of §10).

``evaluate(scenario, methods)`` returns a :class:`Report`; ``report.to_dict()`` is the JSON the
CLI writes, ``report.summary()`` the tables it prints, and :func:`write_report` writes the
results and figures. The paper's experiments built on it live in :mod:`bidmp.experiments.reproduce`.
"""

from __future__ import annotations

import json
import logging
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ._tables import markdown_table, text_table
from .._trajectory import resample_time
from ..extension.extend import extend_demonstration
from ..extension.roadmap import NoFreeRouteError
from ..incremental.bidmp import BiDMP, forgetting_runs
from .metrics import approach_error, endpoint_error, json_length, path_difference
from .methods.dmp_converged import CONVERGED_GAIN

logger = logging.getLogger(__name__)

__all__ = ["CONVERGED_GAIN", "MethodResult", "Report", "evaluate", "write_report"]


@dataclass
class MethodResult:
    """One method on one scenario (lengths in the scenario's unit, times in s)."""

    name: str
    rollouts: dict  # label -> (n, D)
    runtime_s: float
    errors: dict
    approach_errors: dict | None
    differences: dict
    success_threshold: float
    n_steps: int
    clearances: dict | None = None  # label -> Clearance, or None where the scene does not apply; None without a scene
    orientations: dict | None = None  # pose scenarios: label -> (n, 4) quaternions of the rollout
    axis_deviations: dict | None = None  # pose scenarios: label -> degrees between tool and target axes
    alignment_threshold: float = 2.0

    @property
    def successes(self) -> int:
        return sum(error <= self.success_threshold for error in self.errors.values())

    def engaged_at(self, label: str) -> bool | None:
        """Whether the tool stayed within the threshold of the target's axis over the approach
        height (None when the scenario has no approach height)."""
        if self.approach_errors is None:
            return None
        return bool(self.approach_errors[label] <= self.success_threshold)

    def clearance_at(self, label: str):
        return None if self.clearances is None else self.clearances.get(label)

    def task_success_at(self, label: str) -> bool:
        """End point within the threshold, engaged (where measured) and collision-free (where
        the scene applies)."""
        clearance = self.clearance_at(label)
        return bool(self.errors[label] <= self.success_threshold and self.engaged_at(label) is not False
                    and (clearance is None or clearance.clear) and self.aligned_at(label) is not False)

    def aligned_at(self, label: str) -> bool | None:
        """Pose scenarios: the tool's axis within the alignment threshold of the target's over
        the approach height (None otherwise)."""
        if self.axis_deviations is None:
            return None
        return bool(self.axis_deviations[label] <= self.alignment_threshold)

    @property
    def aligned(self) -> int | None:
        return None if self.axis_deviations is None else sum(bool(self.aligned_at(label)) for label in self.errors)

    @property
    def task_successes(self) -> int:
        return sum(self.task_success_at(label) for label in self.errors)

    @property
    def engaged(self) -> int | None:
        return None if self.approach_errors is None else sum(bool(self.engaged_at(label)) for label in self.errors)

    @property
    def checked(self) -> list[str]:
        """Labels whose motion was checked against the scene."""
        return [] if self.clearances is None else [label for label, c in self.clearances.items() if c is not None]

    @property
    def collision_free(self) -> int | None:
        return None if self.clearances is None else sum(self.clearances[label].clear for label in self.checked)

    @property
    def worst_clearance(self):
        """The smallest Clearance over the checked targets (None without a scene)."""
        checked = [self.clearances[label] for label in self.checked]
        return min(checked, key=lambda c: c.distance) if checked else None

    @property
    def approach_successes(self) -> int | None:
        if self.approach_errors is None:
            return None
        return sum(self.errors[label] <= self.success_threshold and self.approach_errors[label] <= self.success_threshold
                   for label in self.errors)

    def to_dict(self) -> dict:
        n_targets = len(self.errors)
        out = {
            "success_rate": round(self.successes / n_targets, 4),
            "successes": self.successes,
            "n_targets": n_targets,
            "errors": {label: round(float(e), 4) for label, e in self.errors.items()},
            "approach_errors": None if self.approach_errors is None else {label: json_length(e) for label, e in self.approach_errors.items()},
            "max_error": round(float(max(self.errors.values())), 4),
            "difference_range": [round(float(min(self.differences.values())), 2), round(float(max(self.differences.values())), 2)],
            "runtime_s": round(self.runtime_s, 5),
            "n_steps": self.n_steps,
        }
        if self.approach_errors is not None:
            out["approach_successes"] = self.approach_successes
            out["approach_success_rate"] = round(self.approach_successes / n_targets, 4)
        worst = self.worst_clearance
        out.update({
            "task_successes": self.task_successes,
            "engaged": self.engaged,
            "collision_free": self.collision_free,
            "n_checked": None if self.clearances is None else len(self.checked),
            "min_clearance": None if worst is None else json_length(worst.distance),
            "min_clearance_part": None if worst is None else worst.part,
            "aligned": self.aligned,
        })
        targets = {}
        for label, error in self.errors.items():
            clearance = self.clearance_at(label)
            targets[label] = {
                "error": round(float(error), 4),
                "approach_error": None if self.approach_errors is None else json_length(self.approach_errors[label]),
                "engaged": self.engaged_at(label),
                "clearance": None if clearance is None else json_length(clearance.distance),
                "clearance_part": None if clearance is None else clearance.part,
                "collision_part": None if clearance is None else clearance.collision_part,
                "task_success": self.task_success_at(label),
                "axis_deviation": None if self.axis_deviations is None else json_length(self.axis_deviations[label]),
            }
        out["targets"] = targets
        return out


@dataclass
class Report:
    """Result of :func:`evaluate`: per-method metrics plus what the figures need."""

    scenario: object
    methods: dict  # name -> MethodResult
    extensions: list = field(default_factory=list)  # ExtendedDemonstration per stage
    extension_targets: list = field(default_factory=list)
    failed_targets: list = field(default_factory=list)  # labels the plain DMP misses
    model: object = None  # the Bi-DMP
    fitted: dict = field(default_factory=dict)  # method name -> its fitted model (the simulator's closed loop)
    route_failures: list = field(default_factory=list)  # extension stages with no free route: {target, reason}
    forgetting: dict = field(default_factory=dict)  # skill -> ForgettingResult (several demonstrations)

    def to_dict(self) -> dict:
        """The report JSON of SPEC §10 (plus the extension and forgetting details)."""
        out = {
            "scenario": self.scenario.name,
            "units": self.scenario.units,
            "success_threshold": self.scenario.success_threshold,
            "approach_height": self.scenario.approach_height,
            "methods": {name: result.to_dict() for name, result in self.methods.items()},
        }
        if self.extension_targets:
            out["extension_targets"] = [np.asarray(t).round(4).tolist() for t in self.extension_targets]
            out["failed_targets"] = list(self.failed_targets)
        if self.forgetting:
            out["forgetting"] = {skill: result.to_dict() for skill, result in self.forgetting.items()}
        if self.route_failures:
            out["route_failures"] = list(self.route_failures)
        return out

    # -- tables ------------------------------------------------------------------------------
    def method_rows(self, runtimes: bool = True) -> tuple[list[str], list[list[str]]]:
        """The Table 4 analogue: header and one row per method. With a scene: engaged,
        collision-free (of the targets the scene applies to), worst clearance and task success
        (end point ∧ engaged ∧ collision-free) beside the paper's end-point success."""
        geometry = any(result.clearances is not None for result in self.methods.values())
        poses = any(result.axis_deviations is not None for result in self.methods.values())
        header = ["method", "success rate", "successes", "engaged"] + (["aligned"] if poses else []) + \
            ["max error", "difference range"]
        if geometry:
            header += ["collision-free", "min clearance (part)", "task success"]
        if runtimes:
            header.append("run time [s]")
        rows = []
        for name, result in self.methods.items():
            data = result.to_dict()
            n = data["n_targets"]
            engaged = "-" if data["engaged"] is None else f"{data['engaged']}/{n}"
            row = [name, f"{100 * data['success_rate']:.2f} %", f"{data['successes']}/{n}", engaged]
            if poses:
                row.append(f"{data['aligned']}/{n}")
            row += [f"{data['max_error']:.3f}", f"{data['difference_range'][0]:.1f}-{data['difference_range'][1]:.1f}"]
            if geometry:
                worst = "-" if data["min_clearance"] is None else f"{data['min_clearance']:.2f} ({data['min_clearance_part']})"
                row += [f"{data['collision_free']}/{data['n_checked']}", worst, f"{data['task_successes']}/{n}"]
            if runtimes:
                row.append(f"{data['runtime_s']:.4f}")
            rows.append(row)
        return header, rows

    def target_rows(self) -> tuple[list[str], list[list[str]]]:
        """Tables 1 and 2 analogue: end-point error per target and method (x = failure)."""
        scenario = self.scenario
        origin = scenario.targets[scenario.demonstrated]
        header = ["target", "distance"] + list(self.methods)
        rows = []
        for label, target in scenario.targets.items():
            cells = [label, f"{np.linalg.norm(target - origin):.1f}"]
            for result in self.methods.values():
                error = result.errors[label]
                cells.append(f"{error:.3f}{'' if error <= scenario.success_threshold else ' x'}")
            rows.append(cells)
        return header, rows

    def summary(self) -> str:
        """The plain-text report ``bidmp demo`` prints (run times include one-time imports when
        this is the first run in the process)."""
        scenario = self.scenario
        units = scenario.units
        lines = [f"{scenario.name}: {len(scenario.targets)} targets, demonstrated '{scenario.demonstrated}', "
                 f"success = end-point error <= {scenario.success_threshold:g} {units}"]
        if any(result.clearances is not None for result in self.methods.values()):
            engaged = (f"engaged (a final descent along the target's axis, within {scenario.success_threshold:g} {units} of "
                       f"it over the last {scenario.approach_height:g} {units}) and " if scenario.approach_height is not None else "")
            lines.append(f"task success = success and {engaged}collision-free (tool radius {scenario.scene.tool.radius:g} "
                         f"{units}, clearance to every part but the target)")
        if self.extension_targets:
            lines.append(f"plain DMP misses {len(self.failed_targets)} target(s) ({', '.join(self.failed_targets)}); Bi-DMP extended to "
                         + ", ".join(np.array2string(np.asarray(t), precision=1) for t in self.extension_targets))
        for failure in self.route_failures:
            lines.append(f"no extension to {failure['target']}: {failure['reason']}")
        lines += ["", f"Table 4 analogue (errors in {units}; run time in s, measured in this run)", text_table(*self.method_rows())]
        lines += ["", f"Tables 1 and 2 analogue: end-point error per target ({units}; x = failure)", text_table(*self.target_rows())]
        if self.forgetting:
            lines += ["", f"forgetting (error after learning every demonstration minus error when learned, {units}):"]
            lines += [f"  skill={skill}: " + ", ".join(f"{v:.3f}" for v in result.forgetting) for skill, result in self.forgetting.items()]
        return "\n".join(lines)

    def markdown(self) -> str:
        """The deterministic part of the report as Markdown (no run times)."""
        return "\n\n".join([markdown_table(*self.method_rows(runtimes=False)), markdown_table(*self.target_rows())])


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

            return np.concatenate([points[:, :3].mean(axis=0), Rotation.from_quat(points[:, 3:]).mean().as_quat()])
        return points.mean(axis=0)
    if isinstance(target, str):
        return scenario.targets[target]
    return np.asarray(target, dtype=float)


def _route_failure(target, exc) -> dict:
    """What the report says of an extension stage the roadmap found no free route for."""
    logger.warning("no collision-free route to %s: %s", np.round(np.asarray(target)[:3], 3).tolist(), exc)
    return {"target": np.round(np.asarray(target, dtype=float), 4).tolist(), "reason": str(exc)}


def _bidmp_model(scenario, dmp, failed, route_failures: list):
    """Build the scenario's Bi-DMP: chained extensions, then further demonstrations. A stage the
    roadmap finds no free route for is skipped and recorded in ``route_failures`` (the targets it
    was for then fail on their own; the rest of the evaluation goes on)."""
    model = BiDMP(dmp, **scenario.bidmp)
    extensions, targets = [], []
    previous = None
    # The paper's protocol knows no battery geometry: approach "paper" grows the extension blind.
    keep = scenario.extension.get("approach", "keep") == "keep"
    for stage in scenario.extensions:
        target = _resolve_target(stage["target"], scenario, failed)
        if target is None:
            continue  # nothing failed: no extension needed
        source = scenario.demonstration if stage["from"] == "demonstration" or previous is None else previous.complete
        scene = scenario.scene if keep and stage.get("in_scene", True) else None
        try:
            previous = extend_demonstration(source, target, seed=scenario.seed, scene=scene, **scenario.extension)
        except NoFreeRouteError as exc:  # that target's failure, not the whole evaluation's
            route_failures.append(_route_failure(target, exc))
            continue
        model.learn(previous.complete)
        extensions.append(previous)
        targets.append(target)
    forgetting = {}
    if scenario.demonstrations:
        if model.n_skills == 1:  # learn the operators' demonstrations and measure forgetting in one pass
            forgetting = forgetting_runs(model, list(scenario.demonstrations.values()), ("nearest", "latest"))
        else:
            for demonstration in scenario.demonstrations.values():
                model.learn(demonstration)
    return model, extensions, targets, forgetting


def _pose_bidmp_model(scenario, cartesian, failed, report):
    """The pose scenario's Bi-DMP: extensions on poses, then further demonstrations."""
    from ..extension.extend import extend_pose_demonstration
    from ..incremental.cartesian import CartesianBiDMP

    model = CartesianBiDMP(cartesian, **scenario.bidmp)
    previous = None
    options = {k: v for k, v in scenario.extension.items() if k != "approach"}
    for stage in scenario.extensions:
        target = _resolve_target(stage["target"], scenario, failed)
        if target is None:
            continue
        source = scenario.demonstration if stage["from"] == "demonstration" or previous is None else previous
        stage_scene = scenario.scene if stage.get("in_scene", True) else None
        try:
            extension = extend_pose_demonstration(source, target, seed=scenario.seed, scene=stage_scene, **options)
        except NoFreeRouteError as exc:
            report.route_failures.append(_route_failure(target, exc))
            continue
        previous = extension.poses
        model.learn(previous)
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
            report.model, report.extensions, report.extension_targets, report.forgetting = \
                _bidmp_model(scenario, dmp, failed, report.route_failures)
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
            raise ValueError(f"method {name!r} does not learn poses; a pose scenario runs "
                             f"{', '.join(registry.names(poses=True))}")
    return names


def evaluate(scenario, methods=None, progress=None, geometry: bool = True) -> Report:
    """Run ``methods`` (default: the scenario's) on every target of ``scenario``.

    Parameters
    ----------
    scenario : Scenario or str
        A scenario, a scenario file, or a built-in name.
    methods : list of str, optional
        Names from the methods registry (:mod:`bidmp.tasks.methods`): dmp, dmp-converged, bidmp,
        bidmp-latest, gmm, tpgmm, mp-dmp, or any registered one.
    progress : callable, optional
        Called with each method name before it runs (the CLI hooks a progress bar here).
    geometry : bool, default True
        Check every rollout against the scenario's scene (clearance, collisions, task success).
        False skips the checks (the extensions are still grown around the parts); the report
        then has no geometry columns.

    Returns
    -------
    Report
        ``report.to_dict()`` is the JSON of SPEC §10; ``report.fitted`` holds each method's model.
    """
    from . import methods as registry
    from . import scenarios as scenario_module

    if not isinstance(scenario, scenario_module.Scenario):
        scenario = scenario_module.load(scenario)
    names = _method_names(scenario, methods)
    labels = scenario.labels
    goals = np.stack([scenario.targets[label] for label in labels])
    task = registry.Task(scenario.demonstration, goals, seed=scenario.seed, dmp=scenario.dmp, bidmp=scenario.bidmp,
                         poses=scenario.is_pose)
    report = Report(scenario=scenario, methods={})
    report.failed_targets = failed = _failed_targets(scenario, task, labels, goals)
    task.build_skills = _skills_builder(scenario, failed, report)
    result = (_pose_results if scenario.is_pose else _position_results)(scenario, labels, geometry)
    for name in names:
        if progress is not None:
            progress(name)
        method = registry.get(name)
        model, fit_seconds = method.fit(task)
        with _Timer() as timer:
            rollouts = method.rollouts(model, goals)
        report.methods[name] = result(name, rollouts, fit_seconds + timer.seconds)
        report.fitted[name] = model
    if scenario.demonstrations and not report.forgetting and not scenario.is_pose:
        dmp, _ = task.fitted_dmp()
        report.forgetting = forgetting_runs(dmp, list(scenario.demonstrations.values()), ("nearest", "latest"),
                                            **scenario.bidmp)
    return report


def _failed_targets(scenario, task, labels, goals) -> list[str]:
    """The targets the plain DMP misses by more than the success threshold (positions)."""
    dmp, _ = task.fitted_dmp()
    if scenario.is_pose:
        ends = np.array([dmp.rollout(goal)[-1, :3] for goal in goals])
    else:
        ends = dmp.rollout_many(goals)[:, -1]
    errors = np.linalg.norm(ends - goals[:, :3], axis=1)
    return [label for label, error in zip(labels, errors) if error > scenario.success_threshold]


def _position_results(scenario, labels, geometry: bool):
    """``result(name, trajectories, seconds) -> MethodResult`` for a position scenario."""
    demo = scenario.demonstration
    n_steps = demo.shape[0]
    references = {label: resample_time(scenario.reference(label), n_steps) for label in labels}
    scene = scenario.scene if geometry else None
    excluded = {} if scene is None else {label: scene.target_parts(label, scenario.targets[label]) for label in labels}

    def result(name, trajectories, seconds):
        trajectories = dict(zip(labels, trajectories))
        errors = {label: endpoint_error(trajectories[label], scenario.targets[label]) for label in labels}
        approach = None
        if scenario.approach_height is not None and demo.shape[1] == 3:
            approach = {label: approach_error(trajectories[label], scenario.targets[label], scenario.approach_height) for label in labels}
        differences = {label: path_difference(trajectories[label], references[label]) for label in labels}
        clearances = None
        if scene is not None:
            clearances = {label: scene.clearance(trajectories[label], exclude=excluded[label]) if scene.applies_to(label)
                          else None for label in labels}
        return MethodResult(name, trajectories, seconds, errors, approach, differences, scenario.success_threshold,
                            next(iter(trajectories.values())).shape[0], clearances)

    return result


def _pose_results(scenario, labels, geometry: bool):
    """``result(name, rollouts, seconds) -> MethodResult`` for a pose scenario: metrics on
    positions, the engagement along each target's axis, and the tool's axis alignment (task success
    needs it too)."""
    from .metrics import axis_deviation

    n_steps = scenario.demonstration.shape[0]
    scene = scenario.scene if geometry else None
    references = {label: resample_time(scenario.reference(label)[:, :3], n_steps) for label in labels}
    excluded = {} if scene is None else {label: scene.target_parts(label, scenario.targets[label]) for label in labels}

    def result(name, rollouts, seconds):
        positions = {label: rollout[:, :3] for label, rollout in zip(labels, rollouts)}
        orientations = {label: rollout[:, 3:] for label, rollout in zip(labels, rollouts)}
        targets = {label: scenario.targets[label][:3] for label in labels}
        errors = {label: endpoint_error(positions[label], targets[label]) for label in labels}
        approach = deviations = None
        if scenario.approach_height is not None:
            approach = {label: approach_error(positions[label], targets[label], scenario.approach_height,
                                              scenario.target_axis(label)) for label in labels}
            deviations = {label: axis_deviation(positions[label], orientations[label], targets[label],
                                                scenario.approach_height, scenario.target_axis(label)) for label in labels}
        differences = {label: path_difference(positions[label], references[label]) for label in labels}
        clearances = None
        if scene is not None:
            clearances = {label: scene.clearance(positions[label], exclude=excluded[label], orientations=orientations[label])
                          if scene.applies_to(label) else None for label in labels}
        return MethodResult(name, positions, seconds, errors, approach, differences, scenario.success_threshold,
                            n_steps, clearances, orientations, deviations, scenario.alignment_threshold)

    return result


def write_report(report: Report, out: str | os.PathLike) -> list[Path]:
    """Write ``results.json`` and the three figures of a report into folder ``out`` (created if
    needed); return the paths written."""
    from ..io.atomic import atomic_write
    from ..plotting.tasks import plot_error_vs_distance, plot_scenario_3d, plot_targets_top_view

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with atomic_write(out / "results.json", "w") as handle:
        json.dump(report.to_dict(), handle, indent=2)
    return [out / "results.json",
            plot_targets_top_view(out / "targets_top_view.png", report),
            plot_error_vs_distance(out / "error_vs_distance.png", report),
            plot_scenario_3d(out / "scenario_3d.png", report)]
