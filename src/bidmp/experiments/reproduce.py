"""The paper's experiments: Tables 1, 2 and 4 (battery case studies), Table 5 (G-PRM vs classic
PRM), Fig. 11 (Bi-DMP on LASA shapes), and the LASA fit-and-generalise example.

Each ``run_*`` function returns a result object with ``to_dict()`` (JSON), ``summary()`` (the
text the CLI prints) and ``markdown()`` (deterministic tables, no run times: the README embeds
them, and a test checks the README against them). ``write_*`` functions write JSON, Markdown and
figures into a folder.
"""

from __future__ import annotations

import json
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._checks import as_points, check_int, check_real
from ..tasks._tables import markdown_table, text_table
from .._trajectory import path_extent, resample_time, rmse
from ..demonstrations.datasets import lasa, minimum_jerk
from ..primitives.dmp import DMP
from ..tasks.evaluation import Report, evaluate, write_report
from ..extension.extend import ExtendedDemonstration, extend_demonstration
from ..incremental.bidmp import BiDMP, ForgettingResult, forgetting_runs
from ..io.atomic import atomic_write
from ..extension.roadmap import RoadmapResult, classic_prm, gaussian_prm

MAX_SEEDS = 200  # seeds of one G-PRM vs PRM comparison (each runs both roadmaps, ~30 ms a seed)

__all__ = [
    "GeneralisationResult",
    "lasa_generalisation",
    "PRMComparison",
    "Table5",
    "table5_cases",
    "compare_prm",
    "run_table5",
    "IncrementalResult",
    "Figures",
    "lasa_incremental",
    "run_figures",
    "Table4",
    "run_table4",
    "write_results",
]


def _write_json(path: Path, data) -> None:
    with atomic_write(path, "w") as handle:
        json.dump(data, handle, indent=2)


def _write_text(path: Path, text: str) -> None:
    with atomic_write(path, "w") as handle:
        handle.write(text if text.endswith("\n") else text + "\n")


# ---------------------------------------------------------------------------------------------
# LASA fit-and-generalise example (bidmp demo --lasa)
# ---------------------------------------------------------------------------------------------
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

    def summary(self) -> str:
        data = self.to_dict()
        rows = [
            [str(i + 1), f"{shift:.2f}", f"{fixed:.3f}", f"{self.endpoint_gain * shift:.3f}", f"{conv:.2e}"]
            for i, (shift, fixed, conv) in enumerate(zip(self.goal_shifts, self.errors_fixed, self.errors_converged))
        ]
        return "\n".join([
            f"one LASA '{self.shape}' demonstration ({data['n_samples']} samples, 2-D), DMP with defaults",
            f"  reproduction RMSE {data['reproduction_rmse']:.3f} mm = {data['reproduction_rmse_percent']:.2f} % of the extent",
            f"  end-point gain c = {self.endpoint_gain:.4f} after T steps, {self.endpoint_gain_converged:.2e} after "
            f"{data['n_steps_converged']} steps",
            f"  end-point error at the demonstrated goal after T steps: e0 = {self.goal_error:.3f} mm",
            "",
            text_table(["goal", "shift [mm]", "error, T steps", "c * shift", f"error, {data['n_steps_converged']} steps"], rows),
            "",
            "Stopped after the demonstration's T steps (the paper's protocol), a DMP misses a moved goal by",
            "c * shift on top of e0 (the error vector is e0 + (B - 1) * shift, exactly); run to convergence it",
            "reaches every goal.",
        ])


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
    demo_index = check_int(demo_index, "demo_index", minimum=0, maximum=6)  # LASA has 7 demonstrations per shape
    n_goals = check_int(n_goals, "n_goals", minimum=1, limit="max_targets")
    convergence_factor = check_int(convergence_factor, "convergence_factor", minimum=1, maximum=1000)
    shift = check_real(shift, "shift", nonnegative=True, maximum=1e3)
    demonstration = lasa(name)[demo_index]
    dmp = DMP(**{"protocol": "paper", **dmp_params}).fit(demonstration)
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
    n_seeds = check_int(n_seeds, "n_seeds", minimum=1, maximum=MAX_SEEDS)
    extension = extend_demonstration(y, new_target, seed=0, approach="paper", **options)
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


@dataclass
class Table5:
    """All Table 5 cases."""

    comparisons: list[PRMComparison]
    n_seeds: int

    def rows(self) -> tuple[list[str], list[list[str]]]:
        n_iter = self.comparisons[0].gprm.shape[1]
        header = ["case", "method"] + [f"it {i}" for i in range(1, n_iter + 1)] + ["best-of"]
        rows = []
        for comparison in self.comparisons:
            for label, data in (("G-PRM", comparison.gprm), ("PRM", comparison.prm)):
                best = data.max(axis=1)
                rows.append([comparison.name, label]
                            + [f"{m:.3f}±{sd:.3f}" for m, sd in zip(data.mean(axis=0), data.std(axis=0))]
                            + [f"{best.mean():.3f}±{best.std():.3f}"])
        return header, rows

    def compact_rows(self) -> tuple[list[str], list[list[str]]]:
        """The README's columns: G-PRM first/last/best-of, classic PRM all iterations/best-of."""
        header = ["case", "G-PRM it 1", f"G-PRM it {self.comparisons[0].gprm.shape[1]}", "G-PRM best-of",
                  "classic PRM (all iterations)", "classic PRM best-of"]

        def cell(values):
            return f"{np.mean(values):.3f} ± {np.std(values):.3f}"

        rows = [[c.name, cell(c.gprm[:, 0]), cell(c.gprm[:, -1]), cell(c.gprm.max(axis=1)), cell(c.prm),
                 cell(c.prm.max(axis=1))] for c in self.comparisons]
        return header, rows

    def to_dict(self) -> dict:
        return {"table": "5", "n_seeds": self.n_seeds, "cases": [c.to_dict() for c in self.comparisons]}

    def summary(self) -> str:
        return (f"Table 5 analogue: Fréchet similarity of the generated path, mean ± std over {self.n_seeds} seeds\n"
                + text_table(*self.rows()))

    def markdown(self) -> str:
        return markdown_table(*self.compact_rows())


def run_table5(n_seeds: int = 20, progress: Callable | None = None) -> Table5:
    """G-PRM vs classic PRM on every case of :func:`table5_cases`. ``progress`` wraps the case
    iterator (e.g. ``tqdm``)."""
    n_seeds = check_int(n_seeds, "n_seeds", minimum=1, maximum=MAX_SEEDS)
    cases = table5_cases().items()
    iterator = progress(cases) if progress is not None else cases
    return Table5([compare_prm(y, target, name=name, units=units, n_seeds=n_seeds) for name, (y, target, units) in iterator],
                  n_seeds)


# ---------------------------------------------------------------------------------------------
# Paper Fig. 11: Bi-DMP on LASA shapes
# ---------------------------------------------------------------------------------------------
LASA_TARGET_OFFSETS = ((0.3, -0.2), (-0.25, -0.3), (0.15, 0.35))  # × extent, from the demonstrated end
FIGURE_SHAPES = ("Sshape", "WShape", "NShape")


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
    learn the extensions in turn with a Bi-DMP; measure reproduction and forgetting (one
    learning pass: the forgetting measurement learns into the model that is then rolled out)."""
    demonstration = lasa(name)[0]
    offsets = as_points(offsets, 2, "offsets")
    check_int(offsets.shape[0], "the number of offsets", limit="max_targets")
    seed = check_int(seed, "seed", minimum=0, maximum=2**32)
    dmp = DMP(protocol="paper").fit(demonstration)
    targets = demonstration[-1] + offsets * path_extent(demonstration)
    extensions = [extend_demonstration(demonstration, target, seed=seed + index, approach="paper")
                  for index, target in enumerate(targets)]
    model = BiDMP(dmp, **bidmp_params)
    runs = forgetting_runs(model, [extension.complete for extension in extensions], ("nearest", "latest"))
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


@dataclass
class Figures:
    """Fig. 11 analogue: :class:`IncrementalResult` per shape."""

    results: list[IncrementalResult]

    def rows(self) -> tuple[list[str], list[list[str]]]:
        header = ["shape", "skill", "Bi-DMP RMSE", "plain DMP RMSE", "forgetting nearest", "forgetting latest"]
        rows = []
        for result in self.results:
            for index, (bidmp_error, dmp_error) in enumerate(zip(result.reproduction_errors(), result.dmp_errors()), start=1):
                rows.append([result.shape, str(index), f"{bidmp_error:.3f}", f"{dmp_error:.1f}",
                             f"{result.forgetting_nearest.forgetting[index]:.3f}", f"{result.forgetting_latest.forgetting[index]:.1f}"])
            rows.append([result.shape, "0 (demo)", "-", "-", f"{result.forgetting_nearest.forgetting[0]:.3f}",
                         f"{result.forgetting_latest.forgetting[0]:.1f}"])
        return header, rows

    def to_dict(self) -> dict:
        return {"results": [result.to_dict() for result in self.results]}

    def summary(self) -> str:
        return ("Bi-DMP on LASA shapes: three extended demonstrations learned in turn (errors in mm)\n"
                + text_table(*self.rows())
                + "\nforgetting = error of a skill after all learning minus its error when it was learned")

    def markdown(self) -> str:
        return markdown_table(*self.rows())


def run_figures(shapes=FIGURE_SHAPES, progress: Callable | None = None) -> Figures:
    """:func:`lasa_incremental` on each shape. ``progress`` wraps the shape iterator."""
    iterator = progress(shapes) if progress is not None else shapes
    return Figures([lasa_incremental(name) for name in iterator])


# ---------------------------------------------------------------------------------------------
# Paper Tables 1, 2 and 4: the battery case studies
# ---------------------------------------------------------------------------------------------
TABLE4_SCENARIOS = ("nut-unscrewing", "cell-removal", "pick-and-place")
TASK_SCENARIOS = ("nut-unscrewing", "cell-removal")  # the battery tasks with a task-success row
# The paper's Table 4 (nut unscrewing): success rate [%], max error [mm], run time [s].
PAPER_TABLE4 = {
    "gmm": ("7.14", "11.21", "0.97"),
    "tpgmm": ("14.29", "105.34", "1.36"),
    "dmp": ("57.14", "2.76", "0.16"),
    "bidmp": ("100", "1.48", "0.67"),
}
# The paper's Tables 1 and 2: end-point error per nut [mm] (DMP; Bi-DMP on nuts 9-14).
PAPER_NUT_ERRORS = {
    "dmp": dict(zip(map(str, range(1, 15)), (0.40, 0.26, 0, 0.99, 1.02, 1.07, 1.49, 1.43, 1.75, 1.76, 1.79, 2.76, 2.74, 2.73))),
    "bidmp": dict(zip(map(str, range(9, 15)), (1.48, 1.25, 1.48, 1.48, 1.25, 1.48))),
}


def _neighbour_clearance(scenario, result) -> str:
    """Worst clearance of a method's checked motions to the parts of the other targets only (the
    neighbouring nuts and studs, cells), leaving out supports such as the plate."""
    scene = scenario.scene
    others = [label for label in scenario.labels if label in scene.labels]
    worst = None
    for label in result.checked:
        exclude = [part for part in scene.labels if part not in others or part == label]
        clearance = scene.clearance(result.rollouts[label], exclude=exclude)
        if worst is None or clearance.distance < worst.distance:
            worst = clearance
    return "-" if worst is None else f"{worst.distance:.2f} ({worst.part})"


@dataclass
class Table4:
    """The three case studies plus the cell-removal before/after comparison."""

    reports: dict[str, Report]  # the paper's protocol (extension approach "paper")
    cells_before: Report  # cell removal with the nut extension only, Bi-DMP
    keep: dict = field(default_factory=dict)  # nut and cell tasks with the defaults (approach "keep"), dmp + bidmp

    def task_rows(self) -> tuple[list[str], list[list[str]]]:
        """Task success with the battery geometry: end point ∧ engaged ∧ collision-free, for the
        defaults (approach "keep") beside the paper-literal extension (approach "paper")."""
        header = ["task", "method", "end point", "engaged", "collision-free", "worst clearance mm (part)",
                  "to the other targets' parts", "task success"]
        rows = []
        for name, report in self.keep.items():
            variants = [("dmp", report.methods["dmp"]), ('bidmp, approach "keep" (default)', report.methods["bidmp"]),
                        ('bidmp, approach "paper" (paper-literal)', self.reports[name].methods["bidmp"])]
            for method, result in variants:
                data = result.to_dict()
                n = data["n_targets"]
                rows.append([name, method, f"{data['successes']}/{n}", f"{data['engaged']}/{n}",
                             f"{data['collision_free']}/{data['n_checked']}",
                             f"{data['min_clearance']:.2f} ({data['min_clearance_part']})",
                             _neighbour_clearance(report.scenario, result), f"{data['task_successes']}/{n}"])
        return header, rows

    def case_studies(self) -> dict:
        after = self.reports["cell-removal"].methods["bidmp"]
        before = self.cells_before.methods["bidmp"]
        picking = self.reports["pick-and-place"]
        return {
            "cell_removal": {
                "before": before.errors,
                "after": after.errors,
                "difference_before": before.differences["B6"],
                "difference_after": after.differences["B6"],
            },
            "pick_and_place": {skill: result.to_dict() for skill, result in picking.forgetting.items()},
        }

    def to_dict(self) -> dict:
        out = {name: report.to_dict() for name, report in self.reports.items()}
        out["case_studies"] = self.case_studies()
        out["approach_keep"] = {name: report.to_dict() for name, report in self.keep.items()}
        return out

    def summary(self) -> str:
        studies = self.case_studies()
        parts = [f"==================== {name} ====================\n{report.summary()}" for name, report in self.reports.items()]
        rows = [[label, f"{studies['cell_removal']['before'][label]:.3f}", f"{studies['cell_removal']['after'][label]:.3f}"]
                for label in studies["cell_removal"]["before"]]
        parts.append("cell removal, Bi-DMP before (nut skill only) and after the second extended demonstration to B6:\n"
                     + text_table(["target", "end error before", "end error after"], rows)
                     + f"\n  difference (path deviation from the reference) at B6: before {studies['cell_removal']['difference_before']:.1f}, "
                     f"after {studies['cell_removal']['difference_after']:.1f}")
        return "\n\n".join(parts)

    def nut_rows(self) -> tuple[list[str], list[list[str]]]:
        """Table 4 for the nut task beside the paper's."""
        names = {"gmm": "GMM", "tpgmm": "TP-GMM", "dmp": "DMP (fixed horizon)", "bidmp": 'Bi-DMP (`skill="nearest"`)',
                 "dmp-converged": "DMP run to convergence", "bidmp-latest": 'Bi-DMP `skill="latest"` (paper-literal)'}
        header = ["method", "success rate (ours / paper)", "max error mm (ours / paper)", "approach ok (ours)"]
        rows = []
        for method in ("gmm", "tpgmm", "dmp", "bidmp", "dmp-converged", "bidmp-latest"):
            data = self.reports["nut-unscrewing"].methods[method].to_dict()
            paper = PAPER_TABLE4.get(method, ("–", "–", "–"))
            rows.append([names[method], f"{100 * data['success_rate']:.2f} % / {paper[0]} %".replace("– %", "–"),
                         f"{data['max_error']:.2f} / {paper[1]}", f"{data['approach_successes']}/{data['n_targets']}"])
        return header, rows

    def per_nut_rows(self) -> tuple[list[str], list[list[str]]]:
        """Tables 1 and 2: end-point error per nut, ours (paper)."""
        report = self.reports["nut-unscrewing"]
        labels = sorted(report.scenario.targets, key=int)
        rows = []
        for method, name in (("dmp", "DMP"), ("bidmp", "Bi-DMP")):
            errors = report.methods[method].errors
            paper = PAPER_NUT_ERRORS[method]
            rows.append([name] + [f"{errors[label]:.2f} ({paper[label]:.2f})" if label in paper else "" for label in labels])
        return ["nut"] + labels, rows

    def markdown(self) -> str:
        studies = self.case_studies()
        picking = studies["pick_and_place"]
        cells = [[label, f"{studies['cell_removal']['before'][label]:.2f}", f"{studies['cell_removal']['after'][label]:.2f}"]
                 for label in ("N3", "B6")]
        return "\n\n".join([
            markdown_table(*self.nut_rows()),
            markdown_table(*self.per_nut_rows()),
            markdown_table(["cell removal, Bi-DMP end error (mm)", "nut skill only", "after the second extension to B6"], cells),
            markdown_table(["pick-and-place forgetting (mm)", "demonstrated operator", "operator 2", "operator 3"],
                           [[f'`skill="{skill}"`'] + [f"{v:.3f}" for v in result["forgetting"]] for skill, result in picking.items()]),
        ])

    def task_markdown(self) -> str:
        """The task-success table (``tasks.md``): defaults beside the paper-literal extension."""
        return markdown_table(*self.task_rows())


def run_table4(progress: Callable | None = None) -> Table4:
    """Every method on the three built-in case studies, plus cell removal with the nut
    extension only (Bi-DMP), for the before/after comparison. ``progress(name)`` is called
    before each scenario."""
    from ..tasks import scenarios

    reports, keep = {}, {}
    for name in TABLE4_SCENARIOS:
        if progress is not None:
            progress(name)
        spec = scenarios.load(name).to_dict()
        spec["extension"] = {**spec.get("extension", {}), "approach": "paper"}  # the paper's protocol
        reports[name] = evaluate(scenarios.from_dict(spec, source=f"built-in {name} (approach paper)"))
        if name in TASK_SCENARIOS:
            keep[name] = evaluate(scenarios.load(name), ["dmp", "bidmp"])  # the default: approach keep
    spec = reports["cell-removal"].scenario.to_dict()
    spec["extensions"] = spec["extensions"][:1]
    before = evaluate(scenarios.from_dict(spec, source="cell-removal (nut skill only)"), ["bidmp"])
    return Table4(reports, before, keep)


# ---------------------------------------------------------------------------------------------
# Writing results
# ---------------------------------------------------------------------------------------------
def write_results(result, name: str, out: str | os.PathLike) -> list[Path]:
    """Write a reproduction result into folder ``out``: ``NAME.json``, ``NAME.md`` and its
    figures (per-scenario folders with ``results.json`` and figures for Table 4)."""
    from ..plotting import figures as plotting

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = [out / f"{name}.json", out / f"{name}.md"]
    _write_json(written[0], result.to_dict())
    _write_text(written[1], result.markdown())
    if isinstance(result, Table4):
        if result.keep:
            written.append(out / "tasks.md")
            _write_text(written[-1], result.task_markdown())
        for scenario_name, report in result.reports.items():
            written += write_report(report, out / scenario_name)
    elif isinstance(result, Figures):
        written.append(plotting.plot_incremental(out / "bidmp_lasa.png", result.results))
    elif isinstance(result, Table5):
        written.append(plotting.plot_prm_comparison(out / f"{name}.png", result.comparisons))
    return written
