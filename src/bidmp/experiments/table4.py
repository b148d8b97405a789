"""Paper Tables 1, 2 and 4: the battery case studies (nut unscrewing, cell removal) with every
method, against the paper's numbers, and the task-success table."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from ..tasks._tables import markdown_table, text_table
from ..tasks.evaluation import Report, evaluate

__all__ = [
    "TABLE4_SCENARIOS",
    "TASK_SCENARIOS",
    "PAPER_TABLE4",
    "PAPER_NUT_ERRORS",
    "Table4",
    "run_table4",
]


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
    "dmp": dict(
        zip(
            map(str, range(1, 15)),
            (0.40, 0.26, 0, 0.99, 1.02, 1.07, 1.49, 1.43, 1.75, 1.76, 1.79, 2.76, 2.74, 2.73),
        )
    ),
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
    # nut and cell tasks with the defaults (approach "keep"), dmp + bidmp
    keep: dict = field(default_factory=dict)

    def task_rows(self) -> tuple[list[str], list[list[str]]]:
        """Task success with the battery geometry: end point ∧ engaged ∧ collision-free, for the
        defaults (approach "keep") beside the paper-literal extension (approach "paper")."""
        header = [
            "task",
            "method",
            "end point",
            "engaged",
            "collision-free",
            "worst clearance mm (part)",
            "to the other targets' parts",
            "task success",
        ]
        rows = []
        for name, report in self.keep.items():
            variants = [
                ("dmp", report.methods["dmp"]),
                ('bidmp, approach "keep" (default)', report.methods["bidmp"]),
                ('bidmp, approach "paper" (paper-literal)', self.reports[name].methods["bidmp"]),
            ]
            for method, result in variants:
                data = result.to_dict()
                n = data["n_targets"]
                rows.append(
                    [
                        name,
                        method,
                        f"{data['successes']}/{n}",
                        f"{data['engaged']}/{n}",
                        f"{data['collision_free']}/{data['n_checked']}",
                        f"{data['min_clearance']:.2f} ({data['min_clearance_part']})",
                        _neighbour_clearance(report.scenario, result),
                        f"{data['task_successes']}/{n}",
                    ]
                )
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
            "pick_and_place": {
                skill: result.to_dict() for skill, result in picking.forgetting.items()
            },
        }

    def to_dict(self) -> dict:
        out = {name: report.to_dict() for name, report in self.reports.items()}
        out["case_studies"] = self.case_studies()
        out["approach_keep"] = {name: report.to_dict() for name, report in self.keep.items()}
        return out

    def summary(self) -> str:
        studies = self.case_studies()
        parts = [
            f"==================== {name} ====================\n{report.summary()}"
            for name, report in self.reports.items()
        ]
        rows = [
            [
                label,
                f"{studies['cell_removal']['before'][label]:.3f}",
                f"{studies['cell_removal']['after'][label]:.3f}",
            ]
            for label in studies["cell_removal"]["before"]
        ]
        parts.append(
            "cell removal, Bi-DMP before (nut skill only) and after the second extended demonstration to B6:\n"
            + text_table(["target", "end error before", "end error after"], rows)
            + f"\n  difference (path deviation from the reference) at B6: before "
            f"{studies['cell_removal']['difference_before']:.1f}, "
            f"after {studies['cell_removal']['difference_after']:.1f}"
        )
        return "\n\n".join(parts)

    def nut_rows(self) -> tuple[list[str], list[list[str]]]:
        """Table 4 for the nut task beside the paper's."""
        names = {
            "gmm": "GMM",
            "tpgmm": "TP-GMM",
            "dmp": "DMP (fixed horizon)",
            "bidmp": 'Bi-DMP (`skill="nearest"`)',
            "dmp-converged": "DMP run to convergence",
            "bidmp-latest": 'Bi-DMP `skill="latest"` (paper-literal)',
        }
        header = [
            "method",
            "success rate (ours / paper)",
            "max error mm (ours / paper)",
            "approach ok (ours)",
        ]
        rows = []
        for method in ("gmm", "tpgmm", "dmp", "bidmp", "dmp-converged", "bidmp-latest"):
            data = self.reports["nut-unscrewing"].methods[method].to_dict()
            paper = PAPER_TABLE4.get(method, ("–", "–", "–"))
            rows.append(
                [
                    names[method],
                    f"{100 * data['success_rate']:.2f} % / {paper[0]} %".replace("– %", "–"),
                    f"{data['max_error']:.2f} / {paper[1]}",
                    f"{data['approach_successes']}/{data['n_targets']}",
                ]
            )
        return header, rows

    def per_nut_rows(self) -> tuple[list[str], list[list[str]]]:
        """Tables 1 and 2: end-point error per nut, ours (paper)."""
        report = self.reports["nut-unscrewing"]
        labels = sorted(report.scenario.targets, key=int)
        rows = []
        for method, name in (("dmp", "DMP"), ("bidmp", "Bi-DMP")):
            errors = report.methods[method].errors
            paper = PAPER_NUT_ERRORS[method]
            rows.append(
                [name]
                + [
                    f"{errors[label]:.2f} ({paper[label]:.2f})" if label in paper else ""
                    for label in labels
                ]
            )
        return ["nut"] + labels, rows

    def markdown(self) -> str:
        studies = self.case_studies()
        picking = studies["pick_and_place"]
        cells = [
            [
                label,
                f"{studies['cell_removal']['before'][label]:.2f}",
                f"{studies['cell_removal']['after'][label]:.2f}",
            ]
            for label in ("N3", "B6")
        ]
        return "\n\n".join(
            [
                markdown_table(*self.nut_rows()),
                markdown_table(*self.per_nut_rows()),
                markdown_table(
                    [
                        "cell removal, Bi-DMP end error (mm)",
                        "nut skill only",
                        "after the second extension to B6",
                    ],
                    cells,
                ),
                markdown_table(
                    [
                        "pick-and-place forgetting (mm)",
                        "demonstrated operator",
                        "operator 2",
                        "operator 3",
                    ],
                    [
                        [f'`skill="{skill}"`'] + [f"{v:.3f}" for v in result["forgetting"]]
                        for skill, result in picking.items()
                    ],
                ),
            ]
        )

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
        scenario = scenarios.load(name)
        # the paper's protocol: the nearest piece imitated down to the target
        paper = scenario.replace(extension={**scenario.extension.flat, "approach": "paper"})
        reports[name] = evaluate(paper, repair=False)
        if name in TASK_SCENARIOS:
            # approach keep, as learned
            keep[name] = evaluate(scenarios.load(name), ["dmp", "bidmp"], repair=False)
    cells = reports["cell-removal"].scenario
    nut_skill_only = cells.replace(extensions=cells.spec["extensions"][:1])
    before = evaluate(nut_skill_only, ["bidmp"], repair=False)
    return Table4(reports, before, keep)
