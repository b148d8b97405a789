"""``bidmp demo``, ``bidmp sim`` and ``bidmp scenario``: a scenario's task with every method, in
evaluation and on the simulated robot, and the scenario files themselves."""

from __future__ import annotations

import argparse
import sys

from .common import (
    EXIT_OK,
    EXIT_TARGETS_FAILED,
    Parser,
    allow_outside_files,
    backend_option,
    judged_methods,
    output_folder,
    overwrite_option,
    print_real_time,
    progress_bars,
    shown_written,
)

__all__ = ["add_commands"]


def _run_scenario(scenario, out, methods=None, view=False):
    """Evaluate a scenario with a progress bar, print its report, write results and figures into
    ``out`` (a run folder's new path); returns (the report, the files written)."""
    from tqdm import tqdm

    from ..tasks.evaluation import evaluate, write_report

    names = list(scenario.methods if methods is None else methods)
    with tqdm(total=len(names), desc=scenario.name, unit="method", disable=None) as bar:
        # each method as it starts, each repair as it is tried ("bidmp: repair 12")
        def progress(step):
            bar.set_postfix_str(step)
            if step in names:
                bar.update(1)

        with progress_bars():
            report = evaluate(scenario, names, progress=progress)
    print()
    print(report.summary())
    written = write_report(report, out)
    if view:
        from .view import write_view_files

        written += write_view_files(out, report=report)
    return report, written


def _run_sim(scenario, out, methods, *, pictures=True, view=False, **options):
    """Execute a scenario on the simulated arm with a progress bar; print and write the results
    (and with ``view`` the 3-D viewer, the arm's motion to the furthest target in it).
    ``options``: :func:`bidmp.sim.simulate`'s, passed on whole (``closed_loop``, ``hold``,
    ``workers``, ``targets``, ``avoid``, ``goal_update``, ``backend``). The simulator evaluates
    the motions it executes itself (judged and repaired with room for the arm's tracking): no
    flag here changes what runs, and the viewer draws that evaluation. Returns (the result, the
    files written into ``out``): ``out`` is a run folder's new path."""
    from tqdm import tqdm

    from ..sim.execution import execution_report
    from ..sim.report import picture_frames, write_sim_report
    from ..sim.run import simulate, target_labels

    methods = list(methods)
    labels = target_labels(scenario, options.get("targets"))
    run_as = scenario.with_robot_protocol() if options.get("closed_loop", False) else scenario
    with progress_bars():  # the learning and repairs before the motions run (G-PRM, repairs)
        report = execution_report(run_as, methods)
    pictured = {(method, _pictured_target(scenario, report, method, labels)) for method in methods}
    frames = picture_frames(pictured) if pictures else {}
    with tqdm(
        total=len(methods) * len(labels), desc=f"{scenario.name} (sim)", unit="motion", disable=None
    ) as bar:

        def progress(method, label):
            bar.set_postfix_str(f"{method} {label}")
            bar.update(1)

        with progress_bars():
            result = simulate(
                scenario,
                methods,
                report=report,
                frames=frames,
                progress=progress,
                views=pictured if view else (),
                **options,
            )
    print()
    print(result.summary())
    written = write_sim_report(result, out)
    if view:
        from .view import write_view_files

        written += write_view_files(out, report=result.evaluation, sim_result=result)
    return result, written


def _pictured_target(scenario, report, method, labels) -> str:
    """The target whose motion of ``method`` is pictured: the farthest from the demonstrated one
    that its motion runs to (the contract refuses it none), else the farthest. Where two
    methods' pictured targets are the same, their motions are also shown side by side."""
    origin = scenario.targets[scenario.demonstrated][:3]

    def distance(label) -> float:
        return float(((scenario.targets[label][:3] - origin) ** 2).sum())

    running = [label for label in labels if report.methods[method].verdicts[label].ok]
    return max(running or labels, key=distance)


def _cmd_demo(args: argparse.Namespace) -> int:
    from pathlib import Path

    out = Path(args.out)
    if args.lasa:
        from .experiments import lasa_demo

        return lasa_demo(args.lasa, out, args.overwrite)
    from ..tasks.scenarios import load

    scenario = load(args.scenario, allow_outside_files=args.allow_outside_files)
    if args.approach is not None:
        scenario = scenario.replace(
            extension={**scenario.extension.flat, "approach": args.approach}
        )
    methods = None
    if args.methods is not None:
        methods = [m.strip() for m in args.methods.split(",") if m.strip()]
        if not methods:
            raise ValueError(f"--methods names no method: {args.methods!r}")
    if (args.sim or args.job) and args.backend in ("pybullet", "mujoco"):
        from ..sim.backend import get_backend

        get_backend(args.backend)
    if args.job and scenario.job is None:
        raise ValueError(
            f'--job: scenario {scenario.name!r} has no "job" (the steps to run at each target)'
        )
    with output_folder(out, args.overwrite) as run:
        report, written = _run_scenario(scenario, run.path, methods, view=args.view)
        failed = report.failed(judged_methods(report.methods))
        sim_written, job = None, None
        if args.sim:
            sim_methods = [m for m in (methods or scenario.methods) if m in ("dmp", "bidmp")] or [
                "dmp",
                "bidmp",
            ]
            result, sim_written = _run_sim(
                scenario,
                run.path,
                sim_methods,
                view=args.view,
                backend=args.backend,
            )
            failed += result.failed(judged_methods(sim_methods))
        if args.job:
            from .job import run_job_command

            job = run_job_command(scenario, run.path / "job", view=args.view, backend=args.backend)
            failed += job.code != EXIT_OK
    # the run is in place: what it wrote, in the order it was written
    print(f"\nwrote {shown_written(run, written)}")
    if sim_written is not None:
        print(f"\nwrote {shown_written(run, sim_written)}")
        print_real_time(result.simulated_s)
    if job is not None:
        from .job import print_job_written

        print_job_written(run, job, run.path / "job")
    return EXIT_TARGETS_FAILED if failed else EXIT_OK


def _cmd_sim(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..sim.backend import GoalUpdate, Hold, get_backend
    from ..tasks.scenarios import load

    if args.backend in ("pybullet", "mujoco"):
        # without the extra(s): the install command, before any work
        get_backend(args.backend)
    scenario = load(args.scenario, allow_outside_files=args.allow_outside_files)
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    if not methods:
        raise ValueError(f"--methods names no method: {args.methods!r}")
    hold = None
    if args.hold is not None:
        joint, start, duration = args.hold
        if joint != int(joint) or not 1 <= joint <= 64:
            raise ValueError(
                f"--hold: the joint must be a joint's number, 1 to the arm's last, got {joint:g}"
            )
        if not (start >= 0 and duration > 0):
            raise ValueError("--hold: START must be >= 0 s and DURATION > 0 s")
        hold = Hold(int(joint) - 1, start, duration)
    targets = (
        None if args.targets is None else [t.strip() for t in args.targets.split(",") if t.strip()]
    )
    update = (
        None
        if args.goal_update is None
        else GoalUpdate(args.goal_update[0], tuple(args.goal_update[1:]))
    )
    if (args.avoid or update is not None) and not args.closed_loop:
        raise ValueError("--avoid and --goal-update act on the closed loop: add --closed-loop")
    with output_folder(Path(args.out), args.overwrite) as run:
        result, written = _run_sim(
            scenario,
            run.path,
            methods,
            closed_loop=args.closed_loop,
            hold=hold,
            workers=args.workers,
            pictures=not args.no_pictures,
            targets=targets,
            avoid=args.avoid,
            goal_update=update,
            view=args.view,
            backend=args.backend,
        )
    print(f"\nwrote {shown_written(run, written)}")
    print_real_time(result.simulated_s)
    return EXIT_TARGETS_FAILED if result.failed(judged_methods(methods)) else EXIT_OK


def _cmd_scenario(args: argparse.Namespace) -> int:
    from ..tasks.scenarios import builtin_names, builtin_text, load

    if args.scenario_command == "list":
        for name in builtin_names():
            scenario = load(name)
            print(f"{name:16s} {len(scenario.targets):3d} targets  {scenario.description[:90]}")
        return EXIT_OK
    if args.scenario_command == "show":
        sys.stdout.write(builtin_text(args.name))
        return EXIT_OK
    scenario = load(args.file, allow_outside_files=args.allow_outside_files)  # what demo validates
    if scenario.robot.own_arm:  # the arm's own file, as the simulator reads it
        from ..sim.robots import robot_model

        robot_model(scenario.robot, scenario.base_dir)
    print(
        f"{args.file}: valid scenario '{scenario.name}' with {len(scenario.targets)} targets, "
        f"demonstration of {scenario.demonstration.shape[0]} samples in {scenario.demonstration.shape[1]}-D"
    )
    return EXIT_OK


def _demo_parser(commands) -> None:
    """``bidmp demo``."""
    demo = commands.add_parser(
        "demo",
        help="run a scenario with every method (default: nut unscrewing)",
        description="Run a scenario (default: the built-in EV-battery nut-unscrewing task) with every "
        "method, print the paper's Table 4 and per-target errors, write results.json and figures.",
    )
    demo.add_argument(
        "--scenario",
        default="nut-unscrewing",
        metavar="FILE|NAME",
        help="scenario file or built-in name (see 'bidmp scenario list')",
    )
    demo.add_argument(
        "--methods",
        default=None,
        help="comma-separated subset of dmp,dmp-converged,bidmp,bidmp-latest,gmm,tpgmm",
    )
    demo.add_argument(
        "--out",
        default="bidmp-out",
        help="output folder (default ./bidmp-out): one run, replaced whole by the next",
    )
    overwrite_option(demo)
    demo.add_argument(
        "--approach",
        choices=("keep", "paper"),
        default=None,
        help="how Bi-DMP's extensions are grown (default: the scenario's, else keep); paper = the paper's protocol",
    )
    demo.add_argument(
        "--sim",
        action="store_true",
        help="then execute dmp and bidmp on the simulated Franka Panda (see 'bidmp sim'; needs bidmp[sim])",
    )
    demo.add_argument(
        "--job",
        action="store_true",
        help="then run the scenario's whole task sequence on the simulated arm (see 'bidmp job'; needs bidmp[sim])",
    )
    demo.add_argument(
        "--view",
        action="store_true",
        help="also write view.html: the 3-D viewer (one offline file; with --sim the robot's motion on a "
        "time slider; needs bidmp[view])",
    )
    demo.add_argument(
        "--lasa",
        metavar="SHAPE",
        help="instead: the LASA fit-and-generalise example on SHAPE (e.g. Sshape)",
    )
    backend_option(demo)
    allow_outside_files(demo)
    demo.set_defaults(handler=_cmd_demo)


def _sim_parser(commands) -> None:
    """``bidmp sim``."""
    sim = commands.add_parser(
        "sim",
        help="execute a scenario on a simulated arm (PyBullet; Panda, iiwa or your URDF)",
        description="Execute every method's motion to every target of a scenario on a simulated "
        'arm (PyBullet, headless; the Franka Panda unless the scenario\'s "robot" names the '
        "iiwa or a URDF): inverse kinematics, timing to the arm's joint "
        "limits, 1 kHz position control, contacts with the parts. Prints the Table 4 analogue "
        "in simulation and writes sim_results.json, keyframe strips and a GIF. Needs the "
        "sim extra: pip install 'bidmp[sim]'.",
    )
    sim.add_argument(
        "--scenario",
        default="nut-unscrewing",
        metavar="FILE|NAME",
        help='scenario with a "scene" (default nut-unscrewing)',
    )
    sim.add_argument(
        "--methods",
        default="dmp,bidmp",
        help="comma-separated methods to execute (default dmp,bidmp)",
    )
    sim.add_argument(
        "--targets", default=None, help="comma-separated subset of the targets (default all)"
    )
    sim.add_argument(
        "--closed-loop",
        action="store_true",
        help="run the DMP/Bi-DMP stepper on the measured tool position with phase stopping (dmp, bidmp)",
    )
    sim.add_argument(
        "--hold",
        type=float,
        nargs=3,
        metavar=("JOINT", "START", "DURATION"),
        help="a scripted disturbance: hold joint JOINT (1 = the base's) still from START for DURATION seconds",
    )
    sim.add_argument(
        "--avoid",
        action="store_true",
        help="closed loop: also steer round every part but the target's (SceneAvoidance)",
    )
    sim.add_argument(
        "--goal-update",
        type=float,
        nargs=4,
        metavar=("T", "DX", "DY", "DZ"),
        help="closed loop: at T s of each motion the target turns out DX DY DZ (scenario units) away; the part "
        "and the goal move there (a scripted perception update)",
    )
    sim.add_argument(
        "--workers",
        type=int,
        default=None,
        help="worker processes (default: one per core, at most 2)",
    )
    sim.add_argument(
        "--no-pictures", action="store_true", help="skip the keyframe strips and the GIF"
    )
    sim.add_argument(
        "--view",
        action="store_true",
        help="also write view.html: the 3-D viewer with the robot's motion to the furthest target on a time "
        "slider (needs bidmp[view])",
    )
    sim.add_argument(
        "--out",
        default="bidmp-sim",
        help="output folder (default ./bidmp-sim): one run, replaced whole by the next",
    )
    overwrite_option(sim)
    backend_option(sim)
    allow_outside_files(sim)
    sim.set_defaults(handler=_cmd_sim)


def _scenario_parser(commands) -> None:
    """``bidmp scenario list|show|check``."""
    scenario = commands.add_parser(
        "scenario",
        help="built-in scenarios: list, show, check a file",
        description="List the built-in scenarios, print one as JSON to copy and edit "
        "('bidmp scenario show nut-unscrewing > my.json'), or validate a scenario file.",
    )
    scenario_commands = scenario.add_subparsers(
        dest="scenario_command", metavar="{list,show,check}", required=True, parser_class=Parser
    )
    scenario_commands.add_parser("list", help="list the built-in scenarios")
    show = scenario_commands.add_parser("show", help="print a built-in scenario as JSON")
    show.add_argument("name", metavar="NAME")
    check = scenario_commands.add_parser("check", help="validate a scenario file")
    check.add_argument("file", metavar="FILE")
    allow_outside_files(check)
    scenario.set_defaults(handler=_cmd_scenario)


def add_commands(commands) -> None:
    """The demo, sim and scenario commands of ``bidmp``'s parser."""
    _demo_parser(commands)
    _sim_parser(commands)
    _scenario_parser(commands)
