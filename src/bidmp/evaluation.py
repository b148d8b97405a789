"""Evaluation of learned skills: metrics and worked examples.

For now this holds the LASA fit-and-generalise example behind ``bidmp demo`` and the G-PRM vs
classic PRM comparison behind ``bidmp reproduce table5``; the battery scenarios of SPEC §9 build
on it.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np

from .datasets import lasa, minimum_jerk
from .dmp import DMP
from .extension import ExtendedDemonstration, extend_demonstration
from .incremental import BiDMP, ForgettingResult, forgetting_runs
from .segmentation import resample_time
from .roadmap import RoadmapResult, classic_prm, gaussian_prm

__all__ = [
    "rmse",
    "path_extent",
    "GeneralisationResult",
    "lasa_generalisation",
    "PRMComparison",
    "table5_cases",
    "compare_prm",
    "IncrementalResult",
    "lasa_incremental",
    "approach_error",
    "MethodResult",
    "Report",
    "evaluate",
    "case_studies",
]


def rmse(a: np.ndarray, b: np.ndarray) -> float:
    """Root-mean-square Euclidean distance between two trajectories of equal shape (T, D)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    if a.shape != b.shape:
        raise ValueError(f"trajectories must have the same shape, got {a.shape} and {b.shape}")
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=-1))))


def path_extent(y: np.ndarray) -> float:
    """Diagonal of the axis-aligned bounding box of a trajectory (same unit as ``y``)."""
    return float(np.linalg.norm(np.ptp(np.asarray(y, dtype=float), axis=0)))


@dataclass
class GeneralisationResult:
    """Outcome of :func:`lasa_generalisation` (lengths in the data set's unit, mm)."""

    shape: str
    demonstration: np.ndarray  # (T, D)
    reproduction: np.ndarray  # (T, D)
    goals: np.ndarray  # (G, D)
    fixed_horizon: np.ndarray  # (G, T, D): the paper's protocol, T steps
    converged: np.ndarray  # (G, n_converged, D)
    endpoint_gain: float
    endpoint_gain_converged: float
    dmp_params: dict = field(default_factory=dict)

    @property
    def extent(self) -> float:
        return path_extent(self.demonstration)

    @property
    def reproduction_rmse(self) -> float:
        return rmse(self.reproduction, self.demonstration)

    @property
    def goal_shifts(self) -> np.ndarray:
        return np.linalg.norm(self.goals - self.demonstration[-1], axis=1)

    @property
    def goal_error(self) -> float:
        """End-point error of the reproduction at the demonstrated goal (T steps)."""
        return float(np.linalg.norm(self.reproduction[-1] - self.demonstration[-1]))

    @property
    def errors_fixed(self) -> np.ndarray:
        return np.linalg.norm(self.fixed_horizon[:, -1] - self.goals, axis=1)

    @property
    def errors_converged(self) -> np.ndarray:
        return np.linalg.norm(self.converged[:, -1] - self.goals, axis=1)

    def to_dict(self) -> dict:
        """JSON-ready summary."""
        return {
            "shape": self.shape,
            "dmp": self.dmp_params,
            "n_samples": int(self.demonstration.shape[0]),
            "extent": self.extent,
            "reproduction_rmse": self.reproduction_rmse,
            "reproduction_rmse_percent": 100.0 * self.reproduction_rmse / self.extent,
            "endpoint_gain": self.endpoint_gain,
            "endpoint_gain_converged": self.endpoint_gain_converged,
            "n_steps_converged": int(self.converged.shape[1]),
            "goal_error": self.goal_error,
            "goals": self.goals.tolist(),
            "goal_shifts": self.goal_shifts.tolist(),
            "endpoint_errors_fixed_horizon": self.errors_fixed.tolist(),
            "endpoint_errors_converged": self.errors_converged.tolist(),
        }


def lasa_generalisation(
    name: str = "Sshape",
    *,
    demo_index: int = 0,
    n_goals: int = 6,
    shift: float = 0.3,
    convergence_factor: int = 10,
    **dmp_params,
) -> GeneralisationResult:
    """Fit a DMP to one LASA demonstration and roll it out to shifted goals.

    The goals lie on a circle of radius ``shift × extent`` around the demonstrated goal. Each is
    reached twice: with the paper's fixed horizon (T steps; the end-point error is
    ``endpoint_gain · shift``) and run ``convergence_factor`` times longer (error → 0).
    """
    if not 0 <= demo_index < 7:
        raise ValueError(f"demo_index must be 0-6 (LASA has 7 demonstrations per shape), got {demo_index}")
    if n_goals < 1:
        raise ValueError(f"n_goals must be >= 1, got {n_goals}")
    if convergence_factor < 1:
        raise ValueError(f"convergence_factor must be >= 1, got {convergence_factor}")
    demonstration = lasa(name)[demo_index]
    dmp = DMP(**dmp_params).fit(demonstration)
    angles = np.linspace(0.0, 2.0 * np.pi, n_goals, endpoint=False)
    radius = shift * path_extent(demonstration)
    goals = demonstration[-1] + radius * np.column_stack([np.cos(angles), np.sin(angles)])
    n_converged = convergence_factor * dmp.n_steps_
    return GeneralisationResult(
        shape=name,
        demonstration=demonstration,
        reproduction=dmp.rollout(),
        goals=goals,
        fixed_horizon=dmp.rollout_many(goals),
        converged=dmp.rollout_many(goals, n_steps=n_converged),
        endpoint_gain=dmp.endpoint_gain(),
        endpoint_gain_converged=dmp.endpoint_gain(n_converged),
        dmp_params=dmp.get_params(),
    )


# ---------------------------------------------------------------------------------------------
# Paper Table 5: G-PRM vs classic PRM
# ---------------------------------------------------------------------------------------------
BATTERY_APPROACH_VIA = ((-80.0, -120.0, 200.0), (0.0, 0.0, 40.0), (0.0, 0.0, 0.0))  # SPEC §9, mm
BATTERY_EXTENSION_TARGET = (150.0, 25.0, 0.0)  # centre of the nuts the plain DMP misses


def table5_cases() -> dict[str, tuple[np.ndarray, np.ndarray, str]]:
    """The cases of ``bidmp reproduce table5``: name -> (demonstration, new target, unit).

    Four LASA shapes (demonstration 0; new target = end + (0.3, −0.2) × extent) and the battery
    approach path of SPEC §9 (T = 200) extended to (150, 25, 0) mm.
    """
    cases = {}
    for name in ("Sshape", "WShape", "NShape", "Angle"):
        y = lasa(name)[0]
        cases[f"LASA {name}"] = (y, y[-1] + np.array([0.3, -0.2]) * path_extent(y), "mm")
    battery = minimum_jerk(BATTERY_APPROACH_VIA, 200)
    cases["battery approach"] = (battery, np.array(BATTERY_EXTENSION_TARGET), "mm")
    return cases


@dataclass
class PRMComparison:
    """G-PRM vs classic PRM on one case over many seeds (similarities per seed and iteration)."""

    name: str
    units: str
    gprm: np.ndarray  # (n_seeds, n_iter)
    prm: np.ndarray  # (n_seeds, n_iter)
    extension: ExtendedDemonstration  # seed 0, for figures
    example_prm: RoadmapResult  # seed 0, for figures

    def to_dict(self) -> dict:
        def stats(values):
            return {"mean": float(np.mean(values)), "std": float(np.std(values))}

        return {
            "case": self.name,
            "n_seeds": int(self.gprm.shape[0]),
            "gprm_per_iteration": [stats(column) for column in self.gprm.T],
            "prm_per_iteration": [stats(column) for column in self.prm.T],
            "gprm_first": stats(self.gprm[:, 0]),
            "gprm_final": stats(self.gprm.max(axis=1)),
            "prm_all": stats(self.prm),
            "prm_final": stats(self.prm.max(axis=1)),
        }


def compare_prm(y, new_target, *, name: str = "", units: str = "", n_seeds: int = 20, **options) -> PRMComparison:
    """Run G-PRM and classic PRM on the piece that :func:`extend_demonstration` imitates.

    Seeds ``0 … n_seeds − 1``; ``options`` go to :func:`extend_demonstration` (segmentation and
    roadmap options shared by both methods).
    """
    if n_seeds < 1:
        raise ValueError(f"n_seeds must be >= 1, got {n_seeds}")
    extension = extend_demonstration(y, new_target, seed=0, **options)
    roadmap_options = {k: v for k, v in options.items() if k not in ("eps_frac", "method")}
    prm_options = {k: v for k, v in roadmap_options.items() if k not in ("sigma_rel", "rho", "schedule")}
    gprm, prm, example_prm = [], [], None
    for seed in range(n_seeds):
        if seed == 0 and len(extension.similarity_history):
            gprm.append(extension.similarity_history)  # the extension already ran G-PRM with seed 0
        else:
            gprm.append(gaussian_prm(extension.tra_imi, extension.new_target, seed=seed, **roadmap_options).history)
        result = classic_prm(extension.tra_imi, extension.new_target, seed=seed, **prm_options)
        prm.append(result.history)
        example_prm = example_prm or result
    return PRMComparison(name=name, units=units, gprm=np.array(gprm), prm=np.array(prm),
                         extension=extension, example_prm=example_prm)


# ---------------------------------------------------------------------------------------------
# Paper Fig. 11: Bi-DMP on LASA shapes
# ---------------------------------------------------------------------------------------------
LASA_TARGET_OFFSETS = ((0.3, -0.2), (-0.25, -0.3), (0.15, 0.35))  # × extent, from the demonstrated end


@dataclass
class IncrementalResult:
    """One LASA shape: extended demonstrations to several targets, learned in turn by a Bi-DMP."""

    shape: str
    demonstration: np.ndarray
    targets: np.ndarray  # (P, 2)
    extensions: list  # ExtendedDemonstration per target
    bidmp_rollouts: np.ndarray  # (P, T, 2), skill="nearest"
    dmp_rollouts: np.ndarray  # (P, T, 2), the plain DMP to the same targets
    forgetting_nearest: ForgettingResult
    forgetting_latest: ForgettingResult

    def reproduction_errors(self) -> np.ndarray:
        """RMSE of each Bi-DMP rollout against its extended demonstration (mm)."""
        return np.array([
            rmse(rollout, resample_time(extension.complete, rollout.shape[0]))
            for rollout, extension in zip(self.bidmp_rollouts, self.extensions)
        ])

    def dmp_errors(self) -> np.ndarray:
        return np.array([
            rmse(rollout, resample_time(extension.complete, rollout.shape[0]))
            for rollout, extension in zip(self.dmp_rollouts, self.extensions)
        ])

    def to_dict(self) -> dict:
        return {
            "shape": self.shape,
            "targets": self.targets.tolist(),
            "bidmp_rmse": self.reproduction_errors().tolist(),
            "dmp_rmse": self.dmp_errors().tolist(),
            "forgetting_nearest": self.forgetting_nearest.to_dict(),
            "forgetting_latest": self.forgetting_latest.to_dict(),
        }


def lasa_incremental(name: str = "Sshape", *, seed: int = 0, offsets=LASA_TARGET_OFFSETS, **bidmp_params) -> IncrementalResult:
    """Fit a DMP to LASA demonstration 0, extend it to several new targets (1D-SEG + G-PRM) and
    learn the extensions in turn with a Bi-DMP; measure reproduction and forgetting."""
    demonstration = lasa(name)[0]
    dmp = DMP().fit(demonstration)
    targets = demonstration[-1] + np.asarray(offsets, dtype=float) * path_extent(demonstration)
    extensions = [extend_demonstration(demonstration, target, seed=seed + index) for index, target in enumerate(targets)]
    model = BiDMP(dmp, **bidmp_params)
    for extension in extensions:
        model.learn(extension.complete)
    completes = [extension.complete for extension in extensions]
    runs = forgetting_runs(dmp, completes, ("nearest", "latest"), **bidmp_params)
    return IncrementalResult(
        shape=name,
        demonstration=demonstration,
        targets=targets,
        extensions=extensions,
        bidmp_rollouts=np.stack([model.rollout(target) for target in targets]),
        dmp_rollouts=dmp.rollout_many(targets),
        forgetting_nearest=runs["nearest"],
        forgetting_latest=runs["latest"],
    )


# ---------------------------------------------------------------------------------------------
# Scenarios: evaluate every method on every target (SPEC §9, report JSON of §10)
# ---------------------------------------------------------------------------------------------
CONVERGED_GAIN = 1e-4  # dmp-converged runs whole multiples of T until endpoint_gain() <= this


def approach_error(trajectory: np.ndarray, target: np.ndarray, height: float) -> float:
    """Largest horizontal distance from the target's vertical axis while the trajectory is less
    than ``height`` above the target (SPEC §9). 0 if it never comes that low."""
    low = trajectory[:, 2] - target[2] < height
    if not np.any(low):
        return 0.0
    return float(np.max(np.linalg.norm(trajectory[low, :2] - target[:2], axis=1)))


@dataclass
class MethodResult:
    """One method on one scenario."""

    name: str
    rollouts: dict  # label -> (n, D)
    runtime_s: float
    errors: dict
    approach_errors: dict | None
    differences: dict
    success_threshold: float
    n_steps: int

    @property
    def successes(self) -> int:
        return sum(error <= self.success_threshold for error in self.errors.values())

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
            "approach_errors": None if self.approach_errors is None else {label: round(float(e), 4) for label, e in self.approach_errors.items()},
            "max_error": round(float(max(self.errors.values())), 4),
            "difference_range": [round(float(min(self.differences.values())), 2), round(float(max(self.differences.values())), 2)],
            "runtime_s": round(self.runtime_s, 5),
            "n_steps": self.n_steps,
        }
        if self.approach_errors is not None:
            out["approach_successes"] = self.approach_successes
            out["approach_success_rate"] = round(self.approach_successes / n_targets, 4)
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
        return out


class _Timer:
    def __enter__(self):
        self._start = time.perf_counter()
        return self

    def __exit__(self, *exc):
        self.seconds = time.perf_counter() - self._start
        return False


def _resolve_target(target, scenario, failed: list[str]) -> np.ndarray | None:
    if isinstance(target, str) and target == "centre_of_failed":
        if not failed:
            return None
        return np.mean([scenario.targets[label] for label in failed], axis=0)
    if isinstance(target, str):
        return scenario.targets[target]
    return np.asarray(target, dtype=float)


def _bidmp_model(scenario, dmp, failed):
    """Build the scenario's Bi-DMP: chained extensions, then further demonstrations."""
    model = BiDMP(dmp)
    extensions, targets = [], []
    previous = None
    for stage in scenario.extensions:
        target = _resolve_target(stage["target"], scenario, failed)
        if target is None:
            continue  # nothing failed: no extension needed
        source = scenario.demonstration if stage["from"] == "demonstration" or previous is None else previous.complete
        previous = extend_demonstration(source, target, seed=scenario.seed)
        model.learn(previous.complete)
        extensions.append(previous)
        targets.append(target)
    for demonstration in scenario.demonstrations.values():
        model.learn(demonstration)
    return model, extensions, targets


def evaluate(scenario, methods=None, progress=None) -> Report:
    """Run ``methods`` (default: the scenario's) on every target of ``scenario``.

    Parameters
    ----------
    scenario : Scenario or str
        A scenario, a scenario file, or a built-in name.
    methods : list of str, optional
        From dmp, dmp-converged, bidmp, bidmp-latest, gmm, tpgmm.
    progress : callable, optional
        Called with each method name before it runs (the CLI hooks a progress bar here).

    Returns
    -------
    Report
        ``report.to_dict()`` is the JSON of SPEC §10.
    """
    from . import scenarios as scenario_module
    from .baselines import GMMRegressor, TPGMM

    if not isinstance(scenario, scenario_module.Scenario):
        scenario = scenario_module.load(scenario)
    methods = list(scenario.methods if methods is None else methods)
    for method in methods:
        if method not in scenario_module.METHODS:
            raise ValueError(f"unknown method {method!r}; known: {', '.join(scenario_module.METHODS)}")
    labels = scenario.labels
    goals = scenario.target_array
    demo = scenario.demonstration
    n_steps = demo.shape[0]
    references = {label: resample_time(scenario.reference(label), n_steps) for label in labels}

    def result(name, trajectories, seconds):
        trajectories = dict(zip(labels, trajectories))
        errors = {label: float(np.linalg.norm(trajectories[label][-1] - scenario.targets[label])) for label in labels}
        approach = None
        if scenario.approach_height is not None and demo.shape[1] == 3:
            approach = {label: approach_error(trajectories[label], scenario.targets[label], scenario.approach_height) for label in labels}
        # Over the demonstration's duration: the first T samples (a run to convergence goes on
        # afterwards; squeezing it into T samples would compare different times).
        differences = {
            label: float(np.sum(np.linalg.norm(trajectories[label][:n_steps] - references[label], axis=1)))
            for label in labels
        }
        return MethodResult(name, trajectories, seconds, errors, approach, differences, scenario.success_threshold,
                            next(iter(trajectories.values())).shape[0])

    report = Report(scenario=scenario, methods={})
    with _Timer() as dmp_time:
        dmp = DMP(**scenario.dmp).fit(demo)
        plain = dmp.rollout_many(goals)
    plain_errors = np.linalg.norm(plain[:, -1] - goals, axis=1)
    failed = [label for label, error in zip(labels, plain_errors) if error > scenario.success_threshold]
    report.failed_targets = failed
    model = None
    model_seconds = 0.0

    for method in methods:
        if progress is not None:
            progress(method)
        if method == "dmp":
            report.methods[method] = result(method, plain, dmp_time.seconds)
        elif method == "dmp-converged":
            with _Timer() as timer:
                factor = next((k for k in range(2, 101) if dmp.endpoint_gain(k * n_steps) <= CONVERGED_GAIN), 100)
                trajectories = dmp.rollout_many(goals, n_steps=factor * n_steps)
            report.methods[method] = result(method, trajectories, dmp_time.seconds + timer.seconds)
        elif method in ("bidmp", "bidmp-latest"):
            if model is None:
                with _Timer() as timer:
                    model, report.extensions, report.extension_targets = _bidmp_model(scenario, dmp, failed)
                model_seconds = dmp_time.seconds + timer.seconds
                report.model = model
            skill = "nearest" if method == "bidmp" else "latest"
            with _Timer() as timer:
                trajectories = [model.rollout(goal, skill=skill) for goal in goals]
            report.methods[method] = result(method, trajectories, model_seconds + timer.seconds)
        elif method == "gmm":
            with _Timer() as timer:
                mean, _ = GMMRegressor(seed=scenario.seed).fit(demo).generate()
                trajectories = [mean] * len(labels)  # GMM has no notion of a new target
            report.methods[method] = result(method, trajectories, timer.seconds)
        elif method == "tpgmm":
            with _Timer() as timer:
                tpgmm = TPGMM(seed=scenario.seed).fit(demo)
                trajectories = [tpgmm.generate(demo[0], goal)[0] for goal in goals]
            report.methods[method] = result(method, trajectories, timer.seconds)
    if scenario.demonstrations:
        demos = list(scenario.demonstrations.values())
        report.forgetting = forgetting_runs(dmp, demos, ("nearest", "latest"))
    return report


def case_studies() -> dict:
    """The case-study numbers of ``bidmp reproduce table4`` beyond the per-method tables.

    Cell removal: Bi-DMP end-point errors at the cells with the nut skill only ("before") and
    after the second extended demonstration to B6 is learned on top ("after"), plus the path
    difference at B6. Pick-and-place: forgetting of each operator's skill.
    """
    from . import scenarios as scenario_module

    cells = scenario_module.load("cell-removal")
    before_spec = cells.to_dict()
    before_spec["extensions"] = before_spec["extensions"][:1]
    before = evaluate(scenario_module.from_dict(before_spec, source="cell-removal (nut skill only)"), ["bidmp"])
    after = evaluate(cells, ["bidmp"])
    picking = evaluate("pick-and-place", ["bidmp"])
    return {
        "cell_removal": {
            "before": before.methods["bidmp"].errors,
            "after": after.methods["bidmp"].errors,
            "difference_before": before.methods["bidmp"].differences["B6"],
            "difference_after": after.methods["bidmp"].differences["B6"],
        },
        "pick_and_place": {skill: result.to_dict() for skill, result in picking.forgetting.items()},
    }
