"""The ``bidmp`` command line: a thin shell over the library.

Parse, call the library, print, exit. Bad input of any kind ends with a one-line message on
stderr and exit code 2, never a traceback (``--debug`` shows it). NumPy and the library are
imported inside the command handlers so that ``bidmp --help`` starts fast.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from collections.abc import Sequence

from .. import __version__

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_BAD_INPUT = 2
_MAX_SEEDS = 200  # = bidmp.reproduce.MAX_SEEDS (not imported: --help must not load NumPy)


class _Parser(argparse.ArgumentParser):
    """argparse, but usage errors are one line (plus a pointer to --help), exit code 2."""

    def error(self, message: str):  # noqa: D401 - argparse API
        self.exit(EXIT_BAD_INPUT, _one_line(f"{self.prog}: error: {message} (see '{self.prog} --help')") + "\n")


def _parse_K(text: str):
    if text in ("paper", "pastor"):
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be 'paper', 'pastor' or a number, got {text!r}") from None


# ---------------------------------------------------------------------------------------------
# Command handlers
# ---------------------------------------------------------------------------------------------
def _cmd_lasa(args: argparse.Namespace) -> int:
    from ..demonstrations.datasets import lasa, lasa_names

    if args.lasa_command == "list":
        for name in lasa_names():
            print(name)
        return EXIT_OK
    from ..io.trajectories import save_trajectory

    demos = lasa(args.name)
    if not 0 <= args.demo < demos.shape[0]:
        raise ValueError(f"--demo must be 0-{demos.shape[0] - 1}, got {args.demo}")
    path = save_trajectory(demos[args.demo], args.output)
    print(f"wrote {args.name} demonstration {args.demo} ({demos.shape[1]} x {demos.shape[2]}) to {path}")
    return EXIT_OK


def _run_scenario(scenario, out, methods=None):
    """Evaluate a scenario with a progress bar, print its report, write results and figures."""
    from tqdm import tqdm

    from ..tasks.evaluation import evaluate, write_report

    names = list(scenario.methods if methods is None else methods)
    with tqdm(total=len(names), desc=scenario.name, unit="method", disable=None) as bar:
        def progress(method):  # called as each method starts
            bar.set_postfix_str(method)
            bar.update(1)

        report = evaluate(scenario, names, progress=progress)
    print()
    print(report.summary())
    written = write_report(report, out)
    print(f"\nwrote {', '.join(str(path) for path in written)}")
    return report


def _run_sim(scenario, out, methods, *, closed_loop=False, hold=None, workers=None, pictures=True, targets=None,
             report=None):
    """Execute a scenario on the simulated Panda with a progress bar; print and write the results."""
    from tqdm import tqdm

    from ..sim.report import write_sim_report
    from ..sim.run import simulate

    methods = list(methods)
    labels = scenario.labels if targets is None else targets
    frames = {}
    if pictures:
        origin = scenario.targets[scenario.demonstrated]
        far = max(labels, key=lambda label: float(((scenario.targets[label] - origin) ** 2).sum()))
        frames = {(method, far): 30 for method in methods}
    with tqdm(total=len(methods) * len(labels), desc=f"{scenario.name} (sim)", unit="motion", disable=None) as bar:
        def progress(method, label):
            bar.set_postfix_str(f"{method} {label}")
            bar.update(1)

        result = simulate(scenario, methods, closed_loop=closed_loop, hold=hold, workers=workers, targets=targets,
                          frames=frames, progress=progress, report=report)
    print()
    print(result.summary())
    written = write_sim_report(result, out)
    print(f"\nwrote {', '.join(str(path) for path in written)}")
    return result


def _cmd_sim(args: argparse.Namespace) -> int:
    from pathlib import Path

    from ..tasks.scenarios import load
    from ..sim.backend import Hold
    from ..sim.pybullet.world import pybullet_module as _pybullet

    _pybullet()  # without the extra: the install command, before any work
    scenario = load(args.scenario, allow_outside_files=args.allow_outside_files)
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    if not methods:
        raise ValueError(f"--methods names no method: {args.methods!r}")
    hold = None
    if args.hold is not None:
        joint, start, duration = args.hold
        if joint != int(joint) or not 1 <= joint <= 7:
            raise ValueError(f"--hold: the joint must be 1-7, got {joint:g}")
        if not (start >= 0 and duration > 0):
            raise ValueError("--hold: START must be >= 0 s and DURATION > 0 s")
        hold = Hold(int(joint) - 1, start, duration)
    targets = None if args.targets is None else [t.strip() for t in args.targets.split(",") if t.strip()]
    _run_sim(scenario, Path(args.out), methods, closed_loop=args.closed_loop, hold=hold, workers=args.workers,
             pictures=not args.no_pictures, targets=targets)
    return EXIT_OK


def _cmd_benchmark(args: argparse.Namespace) -> int:
    from pathlib import Path

    from tqdm import tqdm

    from ..experiments.lasa import _validate, lasa

    shapes = None if args.shapes is None else [s.strip() for s in args.shapes.split(",") if s.strip()]
    methods = None if args.methods is None else [m.strip() for m in args.methods.split(",") if m.strip()]
    shapes_checked, _, indices = _validate(shapes, methods, args.demos, args.every)  # before starting a cluster
    if args.workers is not None and not 1 <= args.workers <= 256:
        raise ValueError(f"--workers must be 1-256, got {args.workers}")
    with tqdm(total=len(shapes_checked) * len(indices), desc="LASA", unit="cell", disable=None) as bar:
        result = lasa(Path(args.out), shapes=shapes, methods=methods, demos=args.demos, every=args.every,
                      workers=args.workers, scheduler=args.scheduler, resume=args.resume, output_format=args.format,
                      progress=lambda key: bar.update(1))
    print(f"LASA benchmark: {len(result.computed)} cells computed, {len(result.resumed)} resumed, "
          f"{result.workers} worker(s), {result.wall_s:.1f} s")
    print((Path(args.out) / "lasa.md").read_text())
    print(f"wrote {', '.join(str(path) for path in result.written)}")
    return EXIT_OK


def _cmd_demo(args: argparse.Namespace) -> int:
    from pathlib import Path

    out = Path(args.out)
    if args.lasa:
        return _lasa_demo(args.lasa, out)
    from ..tasks.scenarios import load

    scenario = load(args.scenario, allow_outside_files=args.allow_outside_files)
    if args.approach is not None:
        from ..tasks.scenarios import from_dict

        spec = scenario.to_dict()
        spec["extension"] = {**spec.get("extension", {}), "approach": args.approach}
        scenario = from_dict(spec, source=args.scenario, base_dir=scenario.base_dir,
                             allow_outside_files=args.allow_outside_files)
    methods = None
    if args.methods is not None:
        methods = [m.strip() for m in args.methods.split(",") if m.strip()]
        if not methods:
            raise ValueError(f"--methods names no method: {args.methods!r}")
    if args.sim:
        from ..sim.pybullet.world import pybullet_module as _pybullet

        _pybullet()
    report = _run_scenario(scenario, out, methods)
    if args.sim:
        sim_methods = [m for m in (methods or scenario.methods) if m in ("dmp", "bidmp")] or ["dmp", "bidmp"]
        _run_sim(scenario, out, sim_methods, report=report if set(sim_methods) <= set(report.methods) else None)
    return EXIT_OK


def _lasa_demo(shape: str, out) -> int:
    from ..io.atomic import atomic_write
    from ..plotting.figures import plot_generalisation
    from ..experiments.reproduce import lasa_generalisation

    out.mkdir(parents=True, exist_ok=True)
    result = lasa_generalisation(shape)
    print("bidmp demo --lasa: " + result.summary())
    with atomic_write(out / "lasa_generalisation.json", "w") as handle:
        json.dump(result.to_dict(), handle, indent=2)
    figure = plot_generalisation(out / "lasa_generalisation.png", result)
    print(f"wrote {out / 'lasa_generalisation.json'} and {figure}")
    return EXIT_OK


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
    print(f"{args.file}: valid scenario '{scenario.name}' with {len(scenario.targets)} targets, "
          f"demonstration of {scenario.demonstration.shape[0]} samples in {scenario.demonstration.shape[1]}-D")
    return EXIT_OK


def _cmd_reproduce(args: argparse.Namespace) -> int:
    from functools import partial
    from pathlib import Path

    from tqdm import tqdm

    from ..experiments import reproduce

    out = Path(args.out)
    if not 1 <= args.seeds <= _MAX_SEEDS:
        raise ValueError(f"--seeds must be 1-{_MAX_SEEDS}, got {args.seeds}")
    if args.what == "table4":
        with tqdm(total=len(reproduce.TABLE4_SCENARIOS), desc="table4", unit="scenario", disable=None) as bar:
            result = reproduce.run_table4(progress=lambda name: (bar.set_postfix_str(name), bar.update(1)))
    elif args.what == "figures":
        result = reproduce.run_figures(progress=partial(tqdm, desc="figures", unit="shape", disable=None))
    else:
        result = reproduce.run_table5(args.seeds, progress=partial(tqdm, desc="table5", unit="case", disable=None))
    print(result.summary())
    written = reproduce.write_results(result, args.what, out)
    print(f"\nwrote {', '.join(str(path) for path in written)}")
    return EXIT_OK


# ---------------------------------------------------------------------------------------------
# Parser
# ---------------------------------------------------------------------------------------------
def _allow_outside_files(parser, shown: bool = True) -> None:
    """The --allow-outside-files flag of every command that reads a scenario file."""
    parser.add_argument("--allow-outside-files", action="store_true",
                        help="let the scenario read demonstration files outside its own folder" if shown else argparse.SUPPRESS)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="bidmp",
        description="Learn robot movements from one demonstration: DMP, extended demonstrations, Bi-DMP.",
        epilog="Trajectory files are .csv (optional header x,y[,z] or t,x,y[,z]) or .npy of shape (T, D).",
    )
    parser.add_argument("--version", action="version", version=f"bidmp {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks and debug logging")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    from .skills import add_commands

    add_commands(commands, _parse_K, _allow_outside_files)

    reproduce = commands.add_parser("reproduce", help="reproduce a table of the paper",
                                    description="Reproduce the paper's comparisons. table4: the three case studies (nut "
                                                "unscrewing, cell removal before/after the second extension, pick-and-place with "
                                                "three operators). table5: G-PRM vs classic PRM similarity "
                                                "per iteration over many seeds (LASA shapes and the battery approach path). "
                                                "figures: Bi-DMP on LASA shapes, three new targets each (Fig. 11), "
                                                "with reproduction errors and forgetting.")
    reproduce.add_argument("what", choices=("table4", "table5", "figures"), help="which result")
    reproduce.add_argument("--out", default="bidmp-out", help="output folder (default ./bidmp-out)")
    reproduce.add_argument("--seeds", type=int, default=20, help="number of seeds (default 20)")
    reproduce.set_defaults(handler=_cmd_reproduce)

    lasa = commands.add_parser("lasa", help="the bundled LASA handwriting data", description="List or export the LASA handwriting shapes.")
    lasa_commands = lasa.add_subparsers(dest="lasa_command", metavar="{list,export}", required=True, parser_class=_Parser)
    lasa_commands.add_parser("list", help="list the shape names")
    export = lasa_commands.add_parser("export", help="write one demonstration of a shape")
    export.add_argument("name", metavar="NAME", help="shape name, e.g. Sshape")
    export.add_argument("--demo", type=int, default=0, help="which of the 7 demonstrations (0-6, default 0)")
    export.add_argument("-o", "--output", required=True, metavar="OUT", help="file to write (.csv or .npy)")
    lasa.set_defaults(handler=_cmd_lasa)

    demo = commands.add_parser("demo", help="run a scenario with every method (default: nut unscrewing)",
                               description="Run a scenario (default: the built-in EV-battery nut-unscrewing task) with every "
                                           "method, print the paper's Table 4 and per-target errors, write results.json and figures.")
    demo.add_argument("--scenario", default="nut-unscrewing", metavar="FILE|NAME", help="scenario file or built-in name (see 'bidmp scenario list')")
    demo.add_argument("--methods", default=None, help="comma-separated subset of dmp,dmp-converged,bidmp,bidmp-latest,gmm,tpgmm")
    demo.add_argument("--out", default="bidmp-out", help="output folder (default ./bidmp-out)")
    demo.add_argument("--approach", choices=("keep", "paper"), default=None,
                      help="how Bi-DMP's extensions are grown (default: the scenario's, else keep); paper = the paper's protocol")
    demo.add_argument("--sim", action="store_true",
                      help="then execute dmp and bidmp on the simulated Franka Panda (see 'bidmp sim'; needs bidmp[sim])")
    demo.add_argument("--lasa", metavar="SHAPE", help="instead: the LASA fit-and-generalise example on SHAPE (e.g. Sshape)")
    _allow_outside_files(demo)
    demo.set_defaults(handler=_cmd_demo)

    sim = commands.add_parser("sim", help="execute a scenario on a simulated Franka Panda (PyBullet)",
                              description="Execute every method's motion to every target of a scenario on a simulated "
                                          "Franka Panda (PyBullet, headless): inverse kinematics, timing to the Panda's joint "
                                          "limits, 1 kHz position control, contacts with the parts. Prints the Table 4 analogue "
                                          "in simulation and writes sim_results.json, keyframe strips and a GIF. Needs the "
                                          "sim extra: pip install 'bidmp[sim]'.")
    sim.add_argument("--scenario", default="nut-unscrewing", metavar="FILE|NAME", help="scenario with a \"scene\" (default nut-unscrewing)")
    sim.add_argument("--methods", default="dmp,bidmp", help="comma-separated methods to execute (default dmp,bidmp)")
    sim.add_argument("--targets", default=None, help="comma-separated subset of the targets (default all)")
    sim.add_argument("--closed-loop", action="store_true",
                     help="run the DMP/Bi-DMP stepper on the measured tool position with phase stopping (dmp, bidmp)")
    sim.add_argument("--hold", type=float, nargs=3, metavar=("JOINT", "START", "DURATION"),
                     help="a scripted disturbance: hold joint JOINT (1-7) still from START for DURATION seconds")
    sim.add_argument("--workers", type=int, default=None, help="worker processes (default: one per core, at most 2)")
    sim.add_argument("--no-pictures", action="store_true", help="skip the keyframe strips and the GIF")
    sim.add_argument("--out", default="bidmp-sim", help="output folder (default ./bidmp-sim)")
    _allow_outside_files(sim)
    sim.set_defaults(handler=_cmd_sim)

    benchmark = commands.add_parser("benchmark", help="the full LASA benchmark with the standard metrics, on Dask",
                                    description="Sweep every LASA shape x demonstration with every method (reproduction, "
                                                "near and far goals): RMSE, DTW, swept area, Fréchet, end-point error, "
                                                "times. Runs on an embedded Dask LocalCluster (one worker per core) or on "
                                                "--scheduler ADDRESS. Needs bidmp[benchmark].")
    bench_commands = benchmark.add_subparsers(dest="benchmark_command", metavar="{lasa}", required=True, parser_class=_Parser)
    bench = bench_commands.add_parser("lasa", help="the LASA handwriting benchmark")
    bench.add_argument("--shapes", default=None, help="comma-separated shapes (default all 30)")
    bench.add_argument("--methods", default=None, help="comma-separated methods (default dmp-paper,dmp-robot,bidmp,gmm,tpgmm,mp-dmp)")
    bench.add_argument("--demos", choices=("all", "first3"), default="all", help="all 7 demonstrations or the first 3")
    bench.add_argument("--every", type=int, default=1, metavar="K", help="use every K-th sample (papers use 1 or 10)")
    bench.add_argument("--workers", type=int, default=None, help="worker processes of the embedded cluster (default: one per core)")
    bench.add_argument("--scheduler", default=None, metavar="ADDRESS", help="run on an existing Dask scheduler (tcp://host:8786)")
    bench.add_argument("--resume", action="store_true", help="skip the cells a previous run into --out finished")
    bench.add_argument("--format", choices=("parquet", "csv"), default="parquet", help="results table format (default parquet)")
    bench.add_argument("--out", default="bidmp-lasa", help="output folder (default ./bidmp-lasa)")
    benchmark.set_defaults(handler=_cmd_benchmark)

    scenario = commands.add_parser("scenario", help="built-in scenarios: list, show, check a file",
                                   description="List the built-in scenarios, print one as JSON to copy and edit "
                                               "('bidmp scenario show nut-unscrewing > my.json'), or validate a scenario file.")
    scenario_commands = scenario.add_subparsers(dest="scenario_command", metavar="{list,show,check}", required=True, parser_class=_Parser)
    scenario_commands.add_parser("list", help="list the built-in scenarios")
    show = scenario_commands.add_parser("show", help="print a built-in scenario as JSON")
    show.add_argument("name", metavar="NAME")
    check = scenario_commands.add_parser("check", help="validate a scenario file")
    check.add_argument("file", metavar="FILE")
    _allow_outside_files(check)
    scenario.set_defaults(handler=_cmd_scenario)
    return parser


EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, what a tool killed by a closed pipe reports
_MAX_MESSAGE = 600  # characters of one error line


class _BufferedLog(logging.Handler):
    """Holds the library's log records while a command runs: they are printed (one line each)
    if it succeeds and dropped if it fails, so that a failure is exactly one line on stderr."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.records: list[logging.LogRecord] = []
        self.setFormatter(logging.Formatter("bidmp: %(levelname)s: %(message)s"))

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)

    def flush_to(self, stream) -> None:
        for record in self.records:
            stream.write(" ".join(self.format(record).split())[:_MAX_MESSAGE] + "\n")
        self.records.clear()


def _one_line(text: str) -> str:
    """One printable line: whitespace runs collapsed, control characters (a file name or argument
    may carry terminal escapes) shown as '?', at most _MAX_MESSAGE characters."""
    text = "".join(c if c.isprintable() else "?" for c in " ".join(str(text).split()))
    return text if len(text) <= _MAX_MESSAGE else text[: _MAX_MESSAGE - 1] + "…"


def _quiet_stdout() -> None:
    """After a closed pipe: point stdout at /dev/null so that Python's final flush is silent."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # a replaced sys.stdout (tests) has no file number
        pass


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code.

    Every failure is one line on stderr: exit 2 for bad input of any kind (including sizes over
    the limits and settings that would overflow), 1 for an internal error, 130 on Ctrl-C, 141
    when stdout is a closed pipe (``bidmp lasa list | head -1``), silently.
    """
    import warnings

    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        print("bidmp: error: no command given (see 'bidmp --help')", file=sys.stderr)
        return EXIT_BAD_INPUT
    from .._checks import MissingExtraError

    buffered = _BufferedLog()
    root = logging.getLogger()
    debug_handler = None
    if args.debug:
        debug_handler = logging.StreamHandler(sys.stderr)
        debug_handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
        root.addHandler(debug_handler)
        root.setLevel(logging.DEBUG)
    else:
        root.addHandler(buffered)
    try:
        with warnings.catch_warnings():
            # A numerical warning means a non-finite result is on its way: never report it as a
            # success. Other warnings go to the log (one line each, printed on success).
            warnings.simplefilter("error", RuntimeWarning)
            logging.captureWarnings(True)
            code = args.handler(args)
        sys.stdout.flush()
    except BrokenPipeError:
        _quiet_stdout()
        return EXIT_BROKEN_PIPE
    except KeyboardInterrupt:
        print("bidmp: interrupted", file=sys.stderr)
        return 130
    except (ValueError, TypeError, OSError, ArithmeticError, RuntimeWarning, RecursionError, MemoryError,
            MissingExtraError) as exc:
        if args.debug:
            raise
        if isinstance(exc, MemoryError):
            message = "out of memory; lower the sizes (see the limits in the README)"
        elif isinstance(exc, RecursionError):
            message = "input nested too deeply"
        elif isinstance(exc, (ArithmeticError, RuntimeWarning)):
            message = f"numerical failure ({exc}): the input's scale or the settings are out of range"
        elif isinstance(exc, OSError) and exc.strerror:
            message = f"{exc.strerror}: {exc.filename}" if exc.filename else exc.strerror
        else:
            message = str(exc) or type(exc).__name__
        print(f"bidmp {args.command}: error: {_one_line(message)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except Exception as exc:  # noqa: BLE001 - the CLI promises no tracebacks
        if args.debug:
            raise
        print(_one_line(f"bidmp {args.command}: internal error: {type(exc).__name__}: {exc} (rerun with --debug for details)"),
              file=sys.stderr)
        return EXIT_INTERNAL
    finally:
        logging.captureWarnings(False)
        root.removeHandler(buffered)
        if debug_handler is not None:
            root.removeHandler(debug_handler)
    buffered.flush_to(sys.stderr)
    return code


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
