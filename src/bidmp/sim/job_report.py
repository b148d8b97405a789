"""What a simulated job did: per target and per phase, and in all (lengths in the scenario's unit,
times in simulated seconds, peaks as fractions of the arm's joint limits)."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._checks import as_point, as_vector, check_real
from ..tasks._tables import markdown_table, text_table
from .backend import RECORD_EVERY, SETTLE, SIM_STEP
from .limits import _command_peaks, _measured_peaks
from .report import _titled, _write_results, _write_strip

__all__ = [
    "JobPhase",
    "JobTarget",
    "JobReport",
    "write_job_report",
    "write_job_commands",
    "in_bin",
    "in_slot",
]

FORMAT = 2  # of job_results.json (2: each motion's contract verdict)


@dataclass
class JobPhase:
    """One step at one target: done or not (and why), how long, what it touched, how hard."""

    name: str
    ok: bool
    seconds: float  # simulated time, the settling after a motion included
    note: str = ""
    # part label -> deepest penetration (scene unit), non-targets
    contacts: dict = field(default_factory=dict)
    # commanded joint velocity, acceleration, jerk / their limits (largest joint)
    peaks: tuple = (
        0.0,
        0.0,
        0.0,
    )
    measured_peaks: tuple = (0.0, 0.0, 0.0)  # what the simulated joints did (10 ms differences)
    within_limits: bool = True  # every 1 kHz command within the limits, from rest to rest
    verdict: object = None  # the motion contract on what the arm did (bidmp.tasks.contract.Verdict); None: no motion
    # run_job(record=True): the measured tool path (n, 3), scene units
    path: np.ndarray | None = None
    commands: np.ndarray | None = None  # ... and the joint commands (m, J) rad sent every 1 ms

    def to_dict(self) -> dict:
        return {
            "phase": self.name,
            "ok": self.ok,
            "seconds": round(self.seconds, 3),
            "note": self.note,
            "verdict": None if self.verdict is None else self.verdict.to_dict(),
            "contacts": {k: float(v) for k, v in self.contacts.items()},
            "peak_velocity": round(self.peaks[0], 3),
            "peak_acceleration": round(self.peaks[1], 3),
            "peak_jerk": round(self.peaks[2], 3),
            "measured_peak_velocity": round(self.measured_peaks[0], 3),
            "measured_peak_acceleration": round(self.measured_peaks[1], 3),
            "measured_peak_jerk": round(self.measured_peaks[2], 3),
            "within_limits": self.within_limits,
        }


def _phase(name: str, run, plan, cell, carried_contacts=None) -> JobPhase:
    """A motion's phase from its execution: the commands' and the joints' peaks, the contacts
    (the arm's, and ``carried_contacts`` of a part it held, both in scene units)."""
    sent = _command_peaks(run.commands, cell.limits)
    measured = _measured_peaks(run.joint_velocities, SIM_STEP * RECORD_EVERY, cell.limits)
    contacts = {label: depth / cell.unit for label, depth in run.contacts.items()}
    for label, depth in (carried_contacts or {}).items():
        contacts[label] = max(contacts.get(label, 0.0), depth)
    return JobPhase(
        name,
        not contacts,
        plan.duration + SETTLE,
        "",
        contacts,
        (sent.velocity, sent.acceleration, sent.jerk),
        (measured.velocity, measured.acceleration, measured.jerk),
        sent.within,
    )


def in_bin(centre, floor, inner) -> bool:
    """Whether a part that came to rest with its centre at ``centre`` (3,) lies in the bin whose
    floor's centre is ``floor`` (3,) and whose inside measures ``inner`` (3,): over its floor
    (within half the inner width and half the inner depth of the floor's centre) and between the
    floor and the rim. Scene units."""
    centre, floor = as_point(centre, 3, "centre"), as_point(floor, 3, "floor")
    inner = as_vector(inner, "inner", length=3, positive=True)
    over_floor = bool(np.all(np.abs(centre[:2] - floor[:2]) <= inner[:2] / 2.0))
    return over_floor and bool(floor[2] <= centre[2] <= floor[2] + inner[2])


def in_slot(centre, slot, height: float, off_tolerance: float, height_tolerance: float) -> bool:
    """Whether a part of ``height`` that came to rest with its centre at ``centre`` (3,) stands in
    its rack slot (the slot's floor centre ``slot``, 3): its axis within ``off_tolerance`` of the
    slot's centre sideways, its bottom within ``height_tolerance`` of the slot's floor."""
    centre, slot = as_point(centre, 3, "centre"), as_point(slot, 3, "slot")
    height = check_real(height, "height", positive=True)
    off_tolerance = check_real(off_tolerance, "off_tolerance", nonnegative=True)
    height_tolerance = check_real(height_tolerance, "height_tolerance", nonnegative=True)
    off = float(np.linalg.norm(centre[:2] - slot[:2]))
    return off <= off_tolerance and abs(centre[2] - height / 2.0 - slot[2]) <= height_tolerance


@dataclass
class JobTarget:
    label: str
    phases: list = field(default_factory=list)
    removed: bool = False  # the part ended where it belongs (in the bin, in its slot)
    reason: str = ""  # the first step that failed, and why
    final_position: np.ndarray | None = None  # where the part came to rest (scene units)
    # (n, 3) while unscrewing: rise (scene units), angle turned (rad), time (s)
    thread: np.ndarray | None = None

    @property
    def seconds(self) -> float:
        return float(sum(phase.seconds for phase in self.phases))

    @property
    def contacts(self) -> dict:
        found = {}
        for phase in self.phases:
            for label, depth in phase.contacts.items():
                found[label] = max(found.get(label, 0.0), depth)
        return found

    @property
    def within_limits(self) -> bool:
        return all(phase.within_limits for phase in self.phases)

    def to_dict(self) -> dict:
        return {
            "target": self.label,
            "removed": self.removed,
            "reason": self.reason,
            "seconds": round(self.seconds, 3),
            "final_position": None
            if self.final_position is None
            else np.asarray(self.final_position, dtype=float).tolist(),
            "phases": [phase.to_dict() for phase in self.phases],
        }


@dataclass
class JobReport:
    scenario: object
    kind: str
    robot: str
    targets: list
    wall_s: float = 0.0
    # (target, phase, s into its cycle, image) of the first cycle
    pictures: list = field(default_factory=list)
    # ("job", first target) -> {"times", "links"}: the viewer's arm
    motions: dict = field(default_factory=dict)
    evaluation: object = None  # the evaluation whose learned skills ran (bidmp.evaluate's report)
    # the scene the job ran in: the scenario's parts and the job's own (bin, rack)
    scene: object = None
    # (target, phase, image, reason) where a motion broke the contract
    failures: list = field(default_factory=list)
    # the arm that ran: its driven joints' names and units ("rad", "m"), base to flange
    joint_names: tuple = ()
    joint_units: tuple = ()

    @property
    def removed(self) -> int:
        return sum(target.removed for target in self.targets)

    @property
    def simulated_s(self) -> float:
        return float(sum(target.seconds for target in self.targets))

    def phase_names(self) -> list:
        return list(dict.fromkeys(phase.name for target in self.targets for phase in target.phases))

    def rows(self) -> tuple[list, list]:
        names = self.phase_names()
        header = (
            ["target", "removed"]
            + [f"{name} s" for name in names]
            + ["cycle s", "contacts", "peak v / a / j", "failed step"]
        )
        rows = []
        for target in self.targets:
            times = {phase.name: phase for phase in target.phases}
            peaks = (
                np.max([phase.peaks for phase in target.phases], axis=0)
                if target.phases
                else np.zeros(3)
            )
            rows.append(
                [target.label, "yes" if target.removed else "no"]
                + [
                    (
                        "-"
                        if name not in times
                        else f"{times[name].seconds:.2f}" + ("" if times[name].ok else " ✗")
                    )
                    for name in names
                ]
                + [
                    f"{target.seconds:.2f}",
                    str(len(target.contacts)),
                    "/".join(f"{v:.2f}" for v in peaks),
                    target.reason or "-",
                ]
            )
        return header, rows

    def totals(self) -> dict:
        cycles = [target.seconds for target in self.targets if target.removed]
        # simulated seconds; the wall time is not reproducible
        return {
            "targets": len(self.targets),
            "removed": self.removed,
            "contacts": sum(len(target.contacts) for target in self.targets),
            "within_limits": sum(target.within_limits for target in self.targets),
            "cycle_s_mean": round(float(np.mean(cycles)), 3) if cycles else None,
            "cycle_s_max": round(float(np.max(cycles)), 3) if cycles else None,
            "total_s": round(self.simulated_s, 3),
        }

    def summary(self) -> str:
        totals = self.totals()
        lines = [
            f"{self.scenario.name}: the whole {self.kind} job on the simulated {self.robot}, "
            f"{totals['removed']}/{totals['targets']} parts removed, {totals['contacts']} contacts with other parts, "
            f"{totals['within_limits']}/{totals['targets']} within the joint limits",
            "",
            text_table(*self.rows()),
        ]
        if totals["cycle_s_mean"] is not None:
            lines.append(
                f"\ncycle per part {totals['cycle_s_mean']:.2f} s (longest {totals['cycle_s_max']:.2f} s), "
                f"{totals['total_s']:.1f} s in all"
            )
        if self.wall_s > 0:
            lines.append(
                f"simulated {self.simulated_s:.1f} s in {self.wall_s:.1f} s wall time "
                f"({self.simulated_s / self.wall_s:.1f}x real time)"
            )
        failed = [target for target in self.targets if not target.removed]
        if failed:
            lines.append(f"\n{len(failed)} of {len(self.targets)} not removed:")
            lines += [
                f"  {target.label}: {target.reason or 'not where it belongs'}" for target in failed
            ]
        return "\n".join(lines)

    def markdown(self) -> str:
        return markdown_table(*self.rows())

    def to_dict(self) -> dict:
        return {
            "format": FORMAT,
            "scenario": self.scenario.name,
            "job": self.kind,
            "robot": self.robot,
            "units": self.scenario.units,
            "totals": self.totals(),
            "targets": [target.to_dict() for target in self.targets],
        }


def write_job_report(report: JobReport, out) -> list[Path]:
    """``job_results.json``, ``job.md`` (the table) and ``job_cycle.png`` into folder ``out``."""
    from .._checks import check_kind

    check_kind(report, JobReport, "report", "a bidmp.sim.JobReport (bidmp.sim.run_job)")

    written = _write_results(out, "job_results.json", "job.md", report.to_dict(), report.markdown())
    # the first cycle's keyframes side by side, each titled with its phase, target, time
    if report.pictures:
        failed = {
            (target.label, phase.name)
            for target in report.targets
            for phase in target.phases
            if not phase.ok
        }
        tiles = [
            _titled(image, f"{phase} FAILED, target {label}, {seconds:.2f} s", True)
            if (label, phase) in failed
            else _titled(image, f"{phase} done, target {label}, {seconds:.2f} s")
            for label, phase, seconds, image in report.pictures
        ]
        written.append(_write_strip(Path(out) / "job_cycle.png", tiles))
    if report.failures:  # where each failing motion ended, looking at the part it came too close to
        tiles = [
            _titled(image, f"target {label}: {phase} failed: {reason}", True)
            for label, phase, image, reason in report.failures[:6]
        ]
        written.append(_write_strip(Path(out) / "job_failures.png", tiles))
    return written


def write_job_commands(report: JobReport, folder, joint_names=None) -> list[Path]:
    """Every motion's 1 kHz joint commands of a job run with ``record=True``, one CSV per motion:
    ``<folder>/<NN>_<target>_<phase>.csv`` (NN its order in the job), columns ``t`` (s from the
    motion's first command, 1 ms apart) and the joint names of the arm that ran
    (``report.joint_names``; ``joint_names`` renames them, one per joint), a ``# units: rad``
    line first when every joint is revolute (an arm with prismatic joints, the kinematic
    backend's carriage, says each joint's unit in a comment instead): what ``bidmp verify``
    judges by the arm's own (FCI) limits."""
    from .._checks import check_kind, check_path, printable
    from ..io.atomic import atomic_write

    check_kind(report, JobReport, "report", "a bidmp.sim.JobReport (bidmp.sim.run_job)")
    folder = Path(check_path(folder, "folder"))
    if joint_names is None:
        joint_names = report.joint_names
    elif not isinstance(joint_names, (list, tuple)) or not all(
        isinstance(name, str) and name.isprintable() and name and "," not in name
        for name in joint_names
    ):
        raise TypeError(
            "joint_names must be a list of joint names (text, no commas), one per joint"
        )
    names = [str(name) for name in joint_names]
    if len(set(names)) != len(names):
        raise ValueError(f"joint_names: a name repeats among {', '.join(names[:8])}")
    units = tuple(report.joint_units) or ("rad",) * len(names)
    if set(units) == {"rad"}:
        first = "# units: rad\n"
    else:
        first = "# joint units: " + ", ".join(f"{n} {u}" for n, u in zip(names, units)) + "\n"
    folder.mkdir(parents=True, exist_ok=True)
    written, index = [], 0
    for target in report.targets:
        for phase in target.phases:
            commands = getattr(phase, "commands", None)
            if commands is None or len(commands) == 0:
                continue  # (a step that sent no motion: engaging, a refusal)
            commands = np.asarray(commands, dtype=float)
            if commands.shape[1] != len(names):
                raise ValueError(
                    f"joint_names: {len(names)} names for commands of {commands.shape[1]} joints"
                )
            index += 1
            safe = "".join(c if c.isalnum() or c in "-." else "_" for c in printable(target.label))
            path = folder / f"{index:03d}_{safe}_{phase.name}.csv"
            t = np.arange(len(commands)) * 1e-3
            with atomic_write(path, "w") as handle:
                handle.write(first)
                handle.write("t," + ",".join(names) + "\n")
                np.savetxt(handle, np.column_stack([t, commands]), delimiter=",", fmt="%.17g")
            written.append(path)
    return written
