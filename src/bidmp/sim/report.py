"""Results of simulated runs, apart from any backend: per target (:class:`SimTarget`), per method
(:class:`SimMethod`) and per run (:class:`SimReport`), measured from an execution, written as JSON,
a Markdown table and pictures."""

from __future__ import annotations

import json
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._units import length_digits
from ..io.strict_json import json_number
from ..tasks._tables import markdown_table, text_table
from ..tasks.contract import CommandPeaks
from .backend import LIMIT_MARGIN, RECORD_EVERY, SETTLE, SIM_STEP, Execution, MotionPlan
from .limits import _measured_breach, _measured_peaks
from .robots import PANDA

__all__ = ["SimTarget", "SimMethod", "SimReport", "picture_frames", "write_sim_report"]


# ---------------------------------------------------------------------------------------------
# Results
# ---------------------------------------------------------------------------------------------
@dataclass
class SimTarget:
    """One executed motion (lengths in the scenario's unit, times in s)."""

    label: str
    commanded_error: float  # end of the commanded path vs the target
    measured_error: float  # measured TCP after settling vs the target
    approach_error: float | None
    engaged: bool | None
    contacts: dict  # part label -> penetration depth (scenario unit)
    peak_velocity: float  # the 1 kHz commands, fractions of the joint limits (largest joint)
    peak_acceleration: float
    measured_peak_velocity: float  # what the simulated joints did
    measured_peak_acceleration: float  # (over 10 ms windows)
    motion_time: float
    tracking_error: float  # largest distance between the commanded and the measured TCP
    # every 1 kHz command within the velocity, acceleration and jerk limits, from rest to rest,
    # and the measured joints within theirs (measured_breach empty)
    within_limits: bool
    peak_jerk: float = 0.0
    measured_peak_jerk: float = 0.0
    # the command's depth into a part, from the scene geometry
    commanded_penetration: float | None = None
    paused: float = 0.0  # closed loop: seconds the motion's own time stood (nearly) still
    # pose scenarios: degrees between tool and target axes over the approach
    axis_deviation: float | None = None
    aligned: bool | None = None
    verdict: object = None  # bidmp.tasks.contract.Verdict on the executed motion and the commands
    repair: str = ""  # how the motion was repaired (empty: the method's own motion ran)
    # why the motion did not run (unreachable, outside the joint limits); empty: it ran
    error: str = ""
    # simulate(record=True): the measured tool path (n, 3), scene units, 500 Hz
    path: np.ndarray | None = None
    # ... and the joint commands (m, J) rad the arm was sent every 1 ms, and the measured joint
    # velocities (n, J) rad/s at 500 Hz
    commands: np.ndarray | None = None
    joint_velocities: np.ndarray | None = None
    # the measured joints' first breach of the limits, as the robot's safety controller sees the
    # arm itself (bidmp.sim.limits._measured_breach); empty: within them
    measured_breach: str = ""

    @classmethod
    def not_run(cls, label: str, error: str) -> SimTarget:
        """A motion that could not run (its target out of reach, a joint past its limits): a row
        with its reason, no measurements."""
        nan = float("nan")
        return cls(
            label=label,
            commanded_error=nan,
            measured_error=nan,
            approach_error=None,
            engaged=False,
            contacts={},
            peak_velocity=0.0,
            peak_acceleration=0.0,
            measured_peak_velocity=0.0,
            measured_peak_acceleration=0.0,
            motion_time=0.0,
            tracking_error=0.0,
            within_limits=False,
            error=error,
        )

    @property
    def ran(self) -> bool:
        return not self.error

    def task_success(self, threshold: float) -> bool:
        """The motion contract on what the arm did (:mod:`bidmp.tasks.contract`): the measured end,
        the measured final descent, the executed tool's clearance by the margin and no contact, the
        1 kHz commands within the limits (and the arm's own controller's); and the measured joints
        within theirs. A target never judged (no verdict) is no success. ``threshold``: the
        scenario's, which the verdict already holds (kept for the callers' symmetry with the
        evaluation's results)."""
        if self.error or self.measured_breach or self.verdict is None:
            return False
        return bool(self.verdict.ok)

    @property
    def reason(self) -> str:
        if self.error:
            return self.error
        reasons = [] if self.verdict is None or self.verdict.ok else [self.verdict.reason()]
        return "; ".join(reasons + ([self.measured_breach] if self.measured_breach else []))

    def to_dict(self, threshold: float) -> dict:
        if self.error:
            return {"ran": False, "task_success": False, "reason": self.error}
        return {
            "ran": True,
            "commanded_error": float(self.commanded_error),
            "measured_error": float(self.measured_error),
            "approach_error": json_number(self.approach_error),
            "engaged": self.engaged,
            "contacts": sorted(self.contacts),
            "contact_depths": {k: float(v) for k, v in sorted(self.contacts.items())},
            "peak_joint_velocity": round(self.peak_velocity, 4),
            "peak_joint_acceleration": round(self.peak_acceleration, 4),
            "measured_peak_joint_velocity": round(self.measured_peak_velocity, 4),
            "measured_peak_joint_acceleration": round(self.measured_peak_acceleration, 4),
            "peak_joint_jerk": round(self.peak_jerk, 4),
            "measured_peak_joint_jerk": round(self.measured_peak_jerk, 4),
            "commanded_penetration": json_number(self.commanded_penetration),
            "paused_s": round(self.paused, 3),
            "motion_time_s": round(self.motion_time, 3),
            "tracking_error": float(self.tracking_error),
            "within_limits": self.within_limits,
            "measured_breach": self.measured_breach,
            "task_success": self.task_success(threshold),
            "axis_deviation_deg": json_number(self.axis_deviation),
            "aligned": self.aligned,
            "clearance": None
            if self.verdict is None or self.verdict.clearance is None
            else json_number(self.verdict.clearance.distance),
            "clearance_part": None
            if self.verdict is None or self.verdict.clearance is None
            else self.verdict.clearance.part,
            "reason": self.reason,
            "repair": self.repair,
        }


@dataclass
class SimMethod:
    name: str
    targets: dict  # label -> SimTarget
    threshold: float

    @property
    def task_successes(self) -> int:
        return sum(t.task_success(self.threshold) for t in self.targets.values())

    @property
    def end_successes(self) -> int:
        return sum(t.measured_error <= self.threshold for t in self.targets.values())

    @property
    def engaged(self) -> int | None:
        values = [t.engaged for t in self.targets.values()]
        return None if any(v is None for v in values) else sum(values)

    @property
    def contacts(self) -> int:
        """Motions with at least one contact."""
        return sum(bool(t.contacts) for t in self.targets.values())

    @property
    def within_limits(self) -> int:
        return sum(t.within_limits for t in self.targets.values())

    @property
    def sent(self) -> int:
        """Motions sent to the arm (the others were refused by the contract, or out of reach)."""
        return sum(t.ran for t in self.targets.values())

    @property
    def aligned(self) -> int | None:
        values = [t.aligned for t in self.targets.values()]
        return None if any(v is None for v in values) else sum(values)

    def to_dict(self) -> dict:
        return {
            "task_successes": self.task_successes,
            "end_successes": self.end_successes,
            "engaged": self.engaged,
            "aligned": self.aligned,
            "contacts": self.contacts,
            "within_limits": self.within_limits,
            "sent": self.sent,
            "n_targets": len(self.targets),
            "targets": {label: t.to_dict(self.threshold) for label, t in self.targets.items()},
        }


@dataclass
class SimReport:
    scenario: object
    methods: dict  # name -> SimMethod
    base: np.ndarray
    yaw: float
    closed_loop: bool
    simulated_s: float = 0.0
    wall_s: float = 0.0
    pictures: list = field(default_factory=list)
    workers: int = 1
    limits: object = None  # the robot's JointLimits (default the Panda's)
    robot: str = "panda"  # the arm's model name
    # (method, label) -> {"times", "links"}: the viewer's arm
    motions: dict = field(default_factory=dict)
    simulator: str = "PyBullet, 1 kHz position control"  # the backend's own words, for the summary
    evaluation: object = None  # the evaluation whose motions ran (bidmp.sim.execution_report)

    @property
    def _short_name(self) -> str:
        return "Panda" if self.robot == "panda" else self.robot

    @property
    def robot_name(self) -> str:
        from .robots import ROBOT_NAMES

        return ROBOT_NAMES.get(self.robot, self.robot)

    def to_dict(self) -> dict:
        return {
            "scenario": self.scenario.name,
            "units": self.scenario.units,
            "closed_loop": self.closed_loop,
            "robot": {
                **({} if self.robot == "panda" else {"model": self.robot}),
                "base": np.asarray(self.base, dtype=float).tolist(),
                "yaw_deg": self.yaw,
            },
            "success_threshold": self.scenario.success_threshold,
            "limits": {
                "velocity_rad_s": list((self.limits or PANDA).velocity),
                "acceleration_rad_s2": list((self.limits or PANDA).acceleration),
                "timed_to": LIMIT_MARGIN,
            },
            "methods": {name: method.to_dict() for name, method in self.methods.items()},
        }

    def rows(self) -> tuple[list[str], list[list[str]]]:
        poses = any(method.aligned is not None for method in self.methods.values())
        header = (
            ["method", "sent to the arm", "end point", "engaged"]
            + (["aligned"] if poses else [])
            + [
                "contacts",
                "within limits",
                "peak jerk: commands / joints",
                "task success",
                "motion time s",
            ]
        )
        rows = []
        for name, method in self.methods.items():
            n = len(method.targets)
            times = [t.motion_time for t in method.targets.values() if t.ran] or [0.0]
            row = [
                name,
                f"{method.sent}/{n}",
                f"{method.end_successes}/{n}",
                "-" if method.engaged is None else f"{method.engaged}/{n}",
            ]
            if poses:
                row.append("-" if method.aligned is None else f"{method.aligned}/{n}")
            jerk = (
                max(t.peak_jerk for t in method.targets.values()),
                max(t.measured_peak_jerk for t in method.targets.values()),
            )
            rows.append(
                row
                + [
                    f"{method.contacts}/{n}",
                    f"{method.within_limits}/{n}",
                    f"{jerk[0]:.2f} / {jerk[1]:.2f}",
                    f"{method.task_successes}/{n}",
                    f"{min(times):.1f}-{max(times):.1f}",
                ]
            )
        return header, rows

    def summary(self) -> str:
        scenario = self.scenario
        aligned = (
            f", tool axis within {scenario.alignment_threshold:g} deg of the nut's"
            if scenario.is_pose
            else ""
        )
        lines = [
            f"{scenario.name} on a simulated {self.robot_name} ({self.simulator}), robot base "
            f"{np.round(self.base, length_digits(scenario.units)).tolist()} {scenario.units}, "
            f"{'closed' if self.closed_loop else 'open'} loop",
            f"task success = measured end point <= {scenario.success_threshold:g} {scenario.units}, engaged{aligned}, "
            f"no contact with another part, every 1 kHz joint command within the "
            f"{self._short_name}'s velocity, acceleration "
            f"and jerk limits, from rest to rest (peak jerk as a fraction of the limit; joints: measured, 10 ms "
            f"differences)",
            "",
            text_table(*self.rows()),
        ]
        if self.wall_s > 0:
            lines.append(
                f"\nsimulated {self.simulated_s:.1f} s in {self.wall_s:.1f} s wall time "
                f"({self.simulated_s / self.wall_s:.1f}x real time, {self.workers} worker process"
                f"{'es' if self.workers > 1 else ''})"
            )
        for name, method in self.methods.items():
            failed = [t for t in method.targets.values() if not t.task_success(method.threshold)]
            if failed:
                lines.append(f"\n{name}: {len(failed)} of {len(method.targets)} targets failed")
                lines += [f"  {t.label}: {t.reason or 'breaks the contract'}" for t in failed]
        return "\n".join(lines)

    def failed(self, methods=None) -> int:
        """Targets that failed, over ``methods`` (default every method run)."""
        names = self.methods if methods is None else [m for m in methods if m in self.methods]
        return sum(
            not t.task_success(self.methods[m].threshold)
            for m in names
            for t in self.methods[m].targets.values()
        )

    def markdown(self) -> str:
        return markdown_table(*self.rows())


@dataclass(frozen=True)
class _SimTask:
    """What judging a simulated motion needs of its scenario, as plain data (a worker process
    gets a copy): the targets (label -> point or pose), the unit, the success threshold, the
    approach height, each target's axis (or None) and, for pose skills, the alignment threshold."""

    targets: dict
    units: str
    success_threshold: float
    approach_height: float | None
    axes: dict
    alignment_threshold: float | None

    @classmethod
    def of(cls, scenario, labels) -> _SimTask:
        """The task of ``scenario`` (a :class:`bidmp.tasks.Scenario`) at ``labels``."""
        axes = {label: scenario.target_axis(label) for label in labels}
        return cls(
            {k: v.tolist() for k, v in scenario.targets.items()},
            scenario.units,
            scenario.success_threshold,
            scenario.approach_height,
            {label: None if axis is None else axis.tolist() for label, axis in axes.items()},
            scenario.alignment_threshold if scenario.is_pose else None,
        )

    def contract(self, scene, limits):
        """The motion contract of the task: its threshold, approach height and alignment,
        ``scene`` (margin and stand-offs; None: no clearance) and the arm's joint ``limits``."""
        from ..tasks.contract import Contract

        return Contract(
            self.success_threshold,
            self.approach_height,
            scene,
            self.units,
            self.alignment_threshold,
            limits,
        )


def _measure(
    task: _SimTask,
    label: str,
    target: np.ndarray,
    executed: tuple[MotionPlan, Execution],
    unit: float,
    closed_loop: bool,
    judge: tuple = (PANDA, None, ()),
) -> SimTarget:
    """The per-target results of one execution, ``executed`` = (its plan, what the arm did)
    (``task``: its targets, units, threshold), judged by ``judge`` = (the robot's joint limits, a
    :class:`bidmp.tasks.contract.Contract` with the scene or None for the task's without one, the
    parts excluded) on the executed motion: the measured tool path, the commands, the
    contacts."""
    plan, run = executed
    limits, contract, exclude = judge
    if contract is None:
        contract = task.contract(None, limits)
    # the tool judged as it was turned: a pose's, or a plan that turns it (the arm's own route)
    turned = task.alignment_threshold is not None or plan.orientations is not None
    verdict, breach = _judged(
        task, (label, target), run, unit, (limits, contract, exclude), turned=turned
    )
    sent = verdict.limits or CommandPeaks(
        plan.peak_velocity, plan.peak_acceleration, plan.peak_jerk
    )
    measured = _measured_peaks(run.joint_velocities, SIM_STEP * RECORD_EVERY, limits)
    motion_time = float(run.times[-1]) - SETTLE if closed_loop else plan.duration
    return SimTarget(
        label=label,
        commanded_error=float(np.linalg.norm(plan.points[-1] / unit - target)),
        measured_error=verdict.end_error,
        approach_error=verdict.approach_error,
        engaged=verdict.engaged,
        contacts=verdict.contacts,  # (in the scene's unit, as the verdict judged them)
        peak_velocity=sent.velocity,
        peak_acceleration=sent.acceleration,
        peak_jerk=sent.jerk,
        measured_peak_velocity=measured.velocity,
        measured_peak_acceleration=measured.acceleration,
        measured_peak_jerk=measured.jerk,
        motion_time=motion_time,
        tracking_error=float(np.max(np.linalg.norm(run.tcp - run.commanded_tcp, axis=1)) / unit),
        within_limits=sent.within and not breach,
        measured_breach=breach,
        paused=run.paused,
        axis_deviation=verdict.axis_deviation,
        aligned=verdict.aligned,
        verdict=verdict,
    )


def _judged(task: _SimTask, aim: tuple, run: Execution, unit, judge: tuple, turned: bool = False):
    """(the contract's verdict, the measured joints' breach) on one execution towards ``aim`` =
    (label, target), ``judge`` = (joint limits, contract, parts excluded): the verdict on the
    measured tool path (scene units), its orientations in a pose scenario or where the motion
    turned the tool (``turned``), the 1 kHz commands
    the position control was sent (the arm's own controller asked too, where the limits carry
    it) and the contacts; the breach on the measured joint velocities outside the run's
    disturbance (``""``: within)."""
    label, target = aim
    limits, contract, exclude = judge
    verdict = contract.judge(
        run.tcp / unit,
        target,
        label=label,
        axis=task.axes.get(label),
        exclude=exclude,
        orientations=run.tcp_orientation if turned else None,
        commands=run.commands,
        contacts={k: v / unit for k, v in run.contacts.items()},
    )
    breach = _measured_breach(run.joint_velocities, SIM_STEP * RECORD_EVERY, limits, run.disturbed)
    return verdict, breach


# ---------------------------------------------------------------------------------------------
# Writing
# ---------------------------------------------------------------------------------------------
def write_sim_report(report: SimReport, out) -> list[Path]:
    """``sim_results.json``, ``sim.md`` (the table), a keyframe strip per method and, when both dmp and bidmp have
    frames of the same target, an animated GIF of the two side by side."""
    from .._checks import check_kind

    check_kind(report, SimReport, "report", "a bidmp.sim.SimReport (bidmp.sim.simulate)")
    written = _write_results(out, "sim_results.json", "sim.md", report.to_dict(), report.markdown())
    by_method = {}
    for method, label, frames in report.pictures:
        by_method.setdefault(method, (label, frames))
    for method, (label, frames) in by_method.items():
        target = report.methods[method].targets.get(label) if method in report.methods else None
        failed = target is not None and not target.task_success(report.scenario.success_threshold)
        title = f"{method}: motion to target {label} on the simulated {report.robot_name}"
        if failed:  # the picture of a failed target says so, in the warning colour
            title = f"FAILED {title}: {target.reason or 'not a task success'}"
        strip = _write_strip(
            out / f"sim_keyframes_{method}.png",
            _strip_frames(frames),
            title,
            failed=failed,
        )
        written.append(strip)
    # (a motion not run has one still of the arm, not frames of its motion: no GIF)
    if (
        _side_by_side({method: label for method, (label, _) in by_method.items()})
        and by_method["dmp"][1][0].shape == by_method["bidmp"][1][0].shape
    ):
        written.append(
            _write_gif(
                out / f"sim_{by_method['dmp'][0]}_dmp_vs_bidmp.gif",
                by_method["dmp"][1],
                by_method["bidmp"][1],
                f"target {by_method['dmp'][0]}",
            )
        )
    return written


STRIP_FRAMES = 6  # the keyframes of a method's strip
GIF_FRAMES = 31  # the frames of the side-by-side GIF: every sixth one is a strip's


def _side_by_side(targets: dict) -> bool:
    """Whether dmp and bidmp are pictured at the same target (``targets``: method -> label): their
    motions are then also shown side by side, in a GIF."""
    return {"dmp", "bidmp"} <= set(targets) and targets["dmp"] == targets["bidmp"]


def picture_frames(pictured) -> dict:
    """The frames to render (``simulate(frames=...)``) of each pictured ``(method, target)`` pair
    for :func:`write_sim_report`: those it writes. A strip's :data:`STRIP_FRAMES`, from the
    start to the end of the motion; :data:`GIF_FRAMES` where dmp and bidmp are pictured at the
    same target (every sixth of them the strip's). A keyframe of the Panda costs about 40 ms."""
    if not isinstance(pictured, (set, frozenset, list, tuple)) or not all(
        isinstance(pair, tuple) and len(pair) == 2 and all(isinstance(v, str) for v in pair)
        for pair in pictured
    ):
        raise TypeError("pictured must be a collection of (method, target label) pairs of text")
    count = GIF_FRAMES if _side_by_side(dict(pictured)) else STRIP_FRAMES
    return {pair: count for pair in pictured}


def _strip_frames(frames: list) -> list:
    """The strip's keyframes of a motion's ``frames``: :data:`STRIP_FRAMES` of them evenly spaced
    from its first to its last (the arm at its start and at the target), or all of fewer. Of
    :data:`GIF_FRAMES`, exactly every sixth: the strip shows the times a run of
    :data:`STRIP_FRAMES` frames renders, so a command renders no more frames than it writes."""
    if len(frames) <= STRIP_FRAMES:
        return list(frames)
    picked = np.round(np.linspace(0.0, len(frames) - 1, STRIP_FRAMES)).astype(int)
    return [frames[index] for index in picked]


def _write_results(out, json_name: str, table_name: str, data: dict, table: str) -> list[Path]:
    """A run's results as JSON and its Markdown table, into folder ``out`` (made if missing)."""
    from ..io.atomic import atomic_write

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = [out / json_name, out / table_name]
    with atomic_write(written[0], "w") as handle:
        json.dump(data, handle, indent=2)
    with atomic_write(written[1], "w") as handle:
        handle.write(table + "\n")
    return written


FAILED_COLOUR = (214, 39, 40)  # the band and frame of a picture of a failed target or phase


def _titled(image: np.ndarray, title: str, failed: bool = False) -> np.ndarray:
    """``image`` under a band with ``title`` (the method and target) written in it: white, or for
    a failure red with white words and the image framed in red (seen at a glance in a strip)."""
    from PIL import Image, ImageDraw, ImageFont

    font = ImageFont.load_default(size=16)
    band = Image.new("RGB", (image.shape[1], 26), FAILED_COLOUR if failed else (255, 255, 255))
    draw = ImageDraw.Draw(band)
    width = image.shape[1] - 12
    if draw.textlength(title, font=font) > width:  # cut to the band's width, marked
        while len(title) > 8 and draw.textlength(title + "…", font=font) > width:
            title = title[: int(len(title) * 0.95)]
        title = title.rstrip() + "…"
    draw.text((8, 4), title, fill=(255, 255, 255) if failed else (20, 20, 20), font=font)
    if failed:
        image = image.copy()
        image[:4], image[-4:], image[:, :4], image[:, -4:] = (FAILED_COLOUR,) * 4
    return np.concatenate([np.asarray(band), image], axis=0)


def _write_strip(path: Path, frames, title: str = "", failed: bool = False) -> Path:
    from PIL import Image

    from ..io.atomic import atomic_write

    gap = np.full((frames[0].shape[0], 4, 3), 255, np.uint8)
    strip = np.concatenate([part for frame in frames for part in (frame, gap)][:-1], axis=1)
    strip = _titled(strip, title, failed) if title else strip
    with atomic_write(path, "wb") as handle:
        Image.fromarray(strip).save(handle, format="PNG")
    return path


def _write_gif(path: Path, left, right, target: str = "") -> Path:
    from PIL import Image

    from ..io.atomic import atomic_write

    n = min(len(left), len(right))
    title = (
        f"left: plain DMP    right: Bi-DMP    ({target})"
        if target
        else "left: plain DMP    right: Bi-DMP"
    )
    images = [
        Image.fromarray(
            _titled(
                np.concatenate(
                    [left[i], np.full((left[i].shape[0], 6, 3), 255, np.uint8), right[i]], axis=1
                ),
                title,
            )
        )
        for i in range(n)
    ]
    # Each frame's palette (PIL's median cut, what saving an RGB frame would do: the same
    # bytes) on two threads: PIL lets go of the GIL while it quantises, most of the file's cost.
    with ThreadPoolExecutor(2) as pool:
        images = list(pool.map(lambda image: image.quantize(256), images))
    with atomic_write(path, "wb") as handle:
        images[0].save(
            handle, format="GIF", save_all=True, append_images=images[1:], duration=120, loop=0
        )
    return path
