"""What :func:`bidmp.tasks.evaluation.evaluate` returns: one :class:`MethodResult` per method and
the :class:`Report` over them (the report JSON, its tables and summary), and
:func:`write_report`, which writes the JSON and the figures."""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._units import length_digits
from ..io.strict_json import json_number
from ._tables import markdown_table, text_table

__all__ = ["MethodResult", "Report", "write_report"]


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
    # label -> Clearance, or None where the scene does not apply; None without a scene
    clearances: dict | None = None
    orientations: dict | None = None  # pose scenarios: label -> (n, 4) quaternions of the rollout
    # pose scenarios: label -> degrees between tool and target axes
    axis_deviations: dict | None = None
    alignment_threshold: float = 2.0
    # label -> bidmp.tasks.contract.Verdict: the contract's judgement of each motion
    verdicts: dict | None = None
    # label -> bidmp.tasks.repair.Repaired, where a repair was tried
    repairs: dict = field(default_factory=dict)

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
        """The motion contract (:mod:`bidmp.tasks.contract`): end point within the threshold,
        engaged (where measured), clear of every part but the target's by the margin (where the
        scene applies), aligned (poses)."""
        if self.verdicts is not None:
            return self.verdicts[label].ok
        clearance = self.clearance_at(label)
        return bool(
            self.errors[label] <= self.success_threshold
            and self.engaged_at(label) is not False
            and (clearance is None or clearance.clear)
            and self.aligned_at(label) is not False
        )

    def reason_at(self, label: str) -> str:
        """Why the motion to ``label`` breaks the contract, in one sentence (empty when it does not)."""
        if label in self.repairs:
            return self.repairs[label].reason()
        return "" if self.verdicts is None else self.verdicts[label].reason()

    def repaired_at(self, label: str) -> str:
        """Which repair brought the motion to ``label`` within the contract (empty: none did, or none was needed)."""
        repair = self.repairs.get(label)
        return "" if repair is None else repair.how

    @property
    def repaired(self) -> int:
        """Motions a repair brought within the contract."""
        return sum(bool(repair.how) for repair in self.repairs.values())

    def aligned_at(self, label: str) -> bool | None:
        """Pose scenarios: the tool's axis within the alignment threshold of the target's over
        the approach height (None otherwise)."""
        if self.axis_deviations is None:
            return None
        return bool(self.axis_deviations[label] <= self.alignment_threshold)

    @property
    def aligned(self) -> int | None:
        return (
            None
            if self.axis_deviations is None
            else sum(bool(self.aligned_at(label)) for label in self.errors)
        )

    @property
    def task_successes(self) -> int:
        return sum(self.task_success_at(label) for label in self.errors)

    @property
    def engaged(self) -> int | None:
        return (
            None
            if self.approach_errors is None
            else sum(bool(self.engaged_at(label)) for label in self.errors)
        )

    @property
    def checked(self) -> list[str]:
        """Labels whose motion was checked against the scene."""
        return (
            []
            if self.clearances is None
            else [label for label, c in self.clearances.items() if c is not None]
        )

    @property
    def collision_free(self) -> int | None:
        return (
            None
            if self.clearances is None
            else sum(self.clearances[label].clear for label in self.checked)
        )

    @property
    def worst_clearance(self):
        """The smallest Clearance over the checked targets (None without a scene)."""
        checked = [self.clearances[label] for label in self.checked]
        return min(checked, key=lambda c: c.distance) if checked else None

    @property
    def approach_successes(self) -> int | None:
        if self.approach_errors is None:
            return None
        return sum(
            self.errors[label] <= self.success_threshold
            and self.approach_errors[label] <= self.success_threshold
            for label in self.errors
        )

    def to_dict(self) -> dict:
        n_targets = len(self.errors)
        out = {
            "success_rate": round(self.successes / n_targets, 4),
            "successes": self.successes,
            "n_targets": n_targets,
            # lengths at full precision: a metre cell's 0.0109 m is not 0.0109 rounded to 0.1 mm
            "errors": {label: float(e) for label, e in self.errors.items()},
            "approach_errors": None
            if self.approach_errors is None
            else {label: json_number(e) for label, e in self.approach_errors.items()},
            "max_error": float(max(self.errors.values())),
            "difference_range": [
                float(min(self.differences.values())),
                float(max(self.differences.values())),
            ],
            "runtime_s": round(self.runtime_s, 5),
            "n_steps": self.n_steps,
        }
        if self.approach_errors is not None:
            out["approach_successes"] = self.approach_successes
            out["approach_success_rate"] = round(self.approach_successes / n_targets, 4)
        worst = self.worst_clearance
        out.update(
            {
                "task_successes": self.task_successes,
                "engaged": self.engaged,
                "collision_free": self.collision_free,
                "n_checked": None if self.clearances is None else len(self.checked),
                "min_clearance": None if worst is None else json_number(worst.distance),
                "min_clearance_part": None if worst is None else worst.part,
                "aligned": self.aligned,
            }
        )
        targets = {}
        for label, error in self.errors.items():
            clearance = self.clearance_at(label)
            targets[label] = {
                "error": float(error),
                "approach_error": None
                if self.approach_errors is None
                else json_number(self.approach_errors[label]),
                "engaged": self.engaged_at(label),
                "clearance": None if clearance is None else json_number(clearance.distance),
                "clearance_part": None if clearance is None else clearance.part,
                "collision_part": None if clearance is None else clearance.collision_part,
                "task_success": self.task_success_at(label),
                "axis_deviation": None
                if self.axis_deviations is None
                else json_number(self.axis_deviations[label]),
                "reason": self.reason_at(label),
                "repair": None if label not in self.repairs else self.repairs[label].to_dict(),
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
    # method name -> its fitted model (the simulator's closed loop)
    fitted: dict = field(default_factory=dict)
    # extension stages with no free route: {target, reason}
    route_failures: list = field(default_factory=list)
    # skill -> ForgettingResult (several demonstrations)
    forgetting: dict = field(default_factory=dict)
    # How the motions were judged and repaired: {"geometry", "repair", "allowance"} as evaluate
    # resolved them. The simulator executes a report's motions only when these are its own.
    settings: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """The report JSON: per method its counts and per target its verdict (plus the
        extension and forgetting details)."""
        out = {
            "scenario": self.scenario.name,
            "units": self.scenario.units,
            "success_threshold": self.scenario.success_threshold,
            "approach_height": self.scenario.approach_height,
            "methods": {name: result.to_dict() for name, result in self.methods.items()},
        }
        if self.extension_targets:
            out["extension_targets"] = [
                np.asarray(t, dtype=float).tolist() for t in self.extension_targets
            ]
            out["failed_targets"] = list(self.failed_targets)
        if self.forgetting:
            out["forgetting"] = {
                skill: result.to_dict() for skill, result in self.forgetting.items()
            }
        if self.route_failures:
            out["route_failures"] = list(self.route_failures)
        return out

    def failed(self, methods=None) -> int:
        """Targets whose motion breaks the contract, over ``methods`` (default every method run)."""
        names = self.methods if methods is None else [m for m in methods if m in self.methods]
        return sum(
            not self.methods[m].task_success_at(label)
            for m in names
            for label in self.methods[m].errors
        )

    # -- tables ------------------------------------------------------------------------------
    def method_rows(self, runtimes: bool = True) -> tuple[list[str], list[list[str]]]:
        """The Table 4 analogue: header and one row per method. With a scene: engaged,
        collision-free (of the targets the scene applies to), worst clearance and task success
        (end point ∧ engaged ∧ collision-free) beside the paper's end-point success."""
        geometry = any(result.clearances is not None for result in self.methods.values())
        poses = any(result.axis_deviations is not None for result in self.methods.values())
        header = (
            ["method", "success rate", "successes", "engaged"]
            + (["aligned"] if poses else [])
            + ["max error", "difference range"]
        )
        if geometry:
            header += ["collision-free", "min clearance (part)", "task success"]
        if runtimes:
            header.append("run time [s]")
        digits = length_digits(self.scenario.units)  # 0.01 mm detail in any unit
        rows = []
        for name, result in self.methods.items():
            data = result.to_dict()
            n = data["n_targets"]
            engaged = "-" if data["engaged"] is None else f"{data['engaged']}/{n}"
            row = [name, f"{100 * data['success_rate']:.2f} %", f"{data['successes']}/{n}", engaged]
            if poses:
                row.append(f"{data['aligned']}/{n}")
            row += [
                f"{data['max_error']:.{max(3, digits)}f}",
                f"{data['difference_range'][0]:.{max(1, digits - 1)}f}-"
                f"{data['difference_range'][1]:.{max(1, digits - 1)}f}",
            ]
            if geometry:
                worst = (
                    "-"
                    if data["min_clearance"] is None
                    else f"{data['min_clearance']:.{max(2, digits)}f} ({data['min_clearance_part']})"
                )
                row += [
                    f"{data['collision_free']}/{data['n_checked']}",
                    worst,
                    f"{data['task_successes']}/{n}",
                ]
            if runtimes:
                row.append(f"{data['runtime_s']:.4f}")
            rows.append(row)
        return header, rows

    def target_rows(self) -> tuple[list[str], list[list[str]]]:
        """Tables 1 and 2 analogue: end-point error per target and method (x = failure)."""
        scenario = self.scenario
        origin = scenario.targets[scenario.demonstrated]
        header = ["target", "distance"] + list(self.methods)
        digits = length_digits(scenario.units)  # 0.01 mm detail in any unit
        rows = []
        for label, target in scenario.targets.items():
            distance = float(np.linalg.norm((target - origin)[:3]))
            cells = [label, f"{distance:.{max(1, digits - 1)}f}"]
            for result in self.methods.values():
                error = result.errors[label]
                mark = "" if error <= scenario.success_threshold else " x"
                cells.append(f"{error:.{max(3, digits)}f}{mark}")
            rows.append(cells)
        return header, rows

    def summary(self) -> str:
        """The plain-text report ``bidmp demo`` prints (run times include one-time imports when
        this is the first run in the process)."""
        scenario = self.scenario
        units = scenario.units
        lines = [
            f"{scenario.name}: {len(scenario.targets)} targets, demonstrated '{scenario.demonstrated}', "
            f"success = end-point error <= {scenario.success_threshold:g} {units}"
        ]
        if any(result.clearances is not None for result in self.methods.values()):
            engaged = (
                f"engaged (a final descent along the target's axis, within {scenario.success_threshold:g} {units} of "
                f"it over the last {scenario.approach_height:g} {units}) and "
                if scenario.approach_height is not None
                else ""
            )
            lines.append(
                f"task success = success and {engaged}collision-free (tool radius {scenario.scene.tool.radius:g} "
                f"{units}, clearance to every part but the target)"
            )
        if self.extension_targets:
            lines.append(
                f"plain DMP misses {len(self.failed_targets)} target(s) "
                f"({', '.join(self.failed_targets)}); Bi-DMP extended to "
                + ", ".join(
                    np.array2string(np.asarray(t), precision=1) for t in self.extension_targets
                )
            )
        for failure in self.route_failures:
            lines.append(f"no extension to {failure['target']}: {failure['reason']}")
        lines += [
            "",
            f"Table 4 analogue (errors in {units}; run time in s, measured in this run)",
            text_table(*self.method_rows()),
        ]
        lines += [
            "",
            f"Tables 1 and 2 analogue: end-point error per target ({units}; x = failure)",
            text_table(*self.target_rows()),
        ]
        for name, result in self.methods.items():
            if not result.repairs:
                continue
            hows = [
                result.repaired_at(label) for label in result.repairs if result.repaired_at(label)
            ]
            counts = ", ".join(f"{how} {hows.count(how)}" for how in dict.fromkeys(hows))
            failed = [label for label in result.errors if not result.task_success_at(label)]
            lines += [
                "",
                f"{name}: {len(hows)} of {len(result.errors)} motions repaired to keep the contract"
                + (f" ({counts})" if counts else "")
                + (f"; {len(failed)} still fail:" if failed else ""),
            ]
            lines += [f"  {label}: {result.reason_at(label)}" for label in failed]
        if self.forgetting:
            lines += [
                "",
                f"forgetting (error after learning every demonstration minus error when learned, {units}):",
            ]
            lines += [
                f"  skill={skill}: " + ", ".join(f"{v:.3f}" for v in result.forgetting)
                for skill, result in self.forgetting.items()
            ]
        return "\n".join(lines)

    def markdown(self) -> str:
        """The deterministic part of the report as Markdown (no run times)."""
        return "\n\n".join(
            [markdown_table(*self.method_rows(runtimes=False)), markdown_table(*self.target_rows())]
        )


def write_report(report: Report, out: str | os.PathLike) -> list[Path]:
    """Write ``results.json`` and the three figures of a report into folder ``out`` (created if
    needed); return the paths written."""
    from .._checks import check_kind

    check_kind(report, Report, "report", "a bidmp evaluation Report (bidmp.evaluate)")
    from ..io.atomic import atomic_write
    from ..plotting.tasks import (
        plot_error_vs_distance,
        plot_scenario_3d,
        plot_targets_top_view,
    )

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    with atomic_write(out / "results.json", "w") as handle:
        json.dump(report.to_dict(), handle, indent=2)
    return [
        out / "results.json",
        plot_targets_top_view(out / "targets_top_view.png", report),
        plot_error_vs_distance(out / "error_vs_distance.png", report),
        plot_scenario_3d(out / "scenario_3d.png", report),
    ]
