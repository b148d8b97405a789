"""``bidmp job`` (and ``bidmp demo --job``): a scenario's whole task sequence on the simulated arm."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import NamedTuple

from .common import (
    EXIT_OK,
    EXIT_TARGETS_FAILED,
    allow_outside_files,
    backend_option,
    output_folder,
    overwrite_option,
    print_real_time,
    shown_written,
)


class JobWritten(NamedTuple):
    """What :func:`run_job_command` wrote (into the run folder's new path) and its exit code."""

    code: int
    written: list  # the report's files and the viewer's
    commands: list | None  # the command files (None: not asked for)
    simulated_s: float


def run_job_command(
    scenario,
    out: Path,
    *,
    targets=None,
    pictures: bool = True,
    view: bool = False,
    backend: str | None = None,
    commands: bool = False,
) -> JobWritten:
    """Run the job with a progress bar, print its report, write its files into ``out`` (and the
    viewer; ``commands``: every motion's 1 kHz joint commands, out/commands/*.csv). The caller
    puts the run in place and then says what it wrote (:func:`print_job_written`)."""
    from tqdm import tqdm

    from ..sim.job import job_targets, run_job
    from ..sim.job_report import write_job_report
    from .common import progress_bars

    labels = job_targets(scenario, targets)
    with tqdm(total=len(labels), desc=f"{scenario.name} (job)", unit="part", disable=None) as bar:

        def progress(label):
            bar.set_postfix_str(label)
            bar.update(1)

        with progress_bars():  # the learning and repairs of each cycle (G-PRM, repairs)
            report = run_job(
                scenario,
                targets=labels,
                progress=progress,
                pictures=pictures,
                view=view,
                backend=backend,
                record=commands,
            )
    print()
    print(report.summary())
    written = write_job_report(report, out)
    files = None
    if commands:
        from ..sim.job_report import write_job_commands

        # the arm that ran (the kinematic backend is its own six-joint arm, not the scenario's)
        files = write_job_commands(report, Path(out) / "commands")
    if view:
        from .view import write_view_files

        own = {solid.label for solid in scenario.scene.solids}
        # the bin, the rack
        extra = [solid for solid in report.scene.solids if solid.label not in own]
        written += write_view_files(
            out, report=report.evaluation, sim_result=report, extra_solids=extra
        )
    code = EXIT_OK if report.removed == len(report.targets) else EXIT_TARGETS_FAILED
    return JobWritten(code, written, files, report.simulated_s)


def print_job_written(run, job: JobWritten, folder: Path) -> None:
    """After the run is in place: the files the job wrote (``folder``: where it wrote them, in
    the run's new path), and the whole command's time."""
    if job.commands is not None:
        print(
            f"wrote {len(job.commands)} command files to {run.shown(Path(folder) / 'commands')} "
            f"(bidmp verify judges them)"
        )
    print(f"\nwrote {shown_written(run, job.written)}")
    print_real_time(job.simulated_s)


def _cmd_job(args: argparse.Namespace) -> int:
    from ..sim.backend import get_backend
    from ..tasks.scenarios import load

    if args.backend in ("pybullet", "mujoco"):
        # without the extra(s): the install command, before any work
        get_backend(args.backend)
    scenario = load(args.scenario, allow_outside_files=args.allow_outside_files)
    targets = (
        None if args.targets is None else [t.strip() for t in args.targets.split(",") if t.strip()]
    )
    with output_folder(args.out, args.overwrite) as run:
        job = run_job_command(
            scenario,
            run.path,
            targets=targets,
            pictures=not args.no_pictures,
            view=args.view,
            backend=args.backend,
            commands=args.commands,
        )
    print_job_written(run, job, run.path)
    return job.code


def add_commands(commands) -> None:
    """``bidmp job``."""
    job = commands.add_parser(
        "job",
        help="the whole task sequence on the simulated arm (unscrew every nut, ...)",
        description="Run a scenario's \"job\" on the simulated arm: at every target, in the job's "
        "order, the learned approach, engaging, unscrewing (a spindle coupled to the "
        "arm's retraction), retracting with the nut and dropping it into the bin. "
        "Prints per target and phase: success, contacts, joint peaks as fractions of the "
        "limits, times; writes job_results.json, job.md and job_cycle.png. Needs bidmp[sim].",
    )
    job.add_argument(
        "--scenario",
        default="nut-unscrewing",
        metavar="FILE|NAME",
        help='a scenario with a "job" (default nut-unscrewing)',
    )
    job.add_argument(
        "--targets",
        default=None,
        help="comma-separated subset of the targets (default all, in the job's order)",
    )
    job.add_argument(
        "--no-pictures", action="store_true", help="skip the keyframes of the first cycle"
    )
    job.add_argument(
        "--view",
        action="store_true",
        help="also write view.html: the 3-D viewer, the first cycle on a time slider",
    )
    job.add_argument(
        "--out",
        default="bidmp-job",
        help="output folder (default ./bidmp-job): one run, replaced whole by the next",
    )
    overwrite_option(job)
    job.add_argument(
        "--commands",
        action="store_true",
        help="also write every motion's 1 kHz joint commands, OUT/commands/NNN_<target>_<phase>.csv "
        "(t and the arm's joint names): what 'bidmp verify' judges",
    )
    backend_option(job)
    allow_outside_files(job)
    job.set_defaults(handler=_cmd_job)
