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

from . import __version__

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
def _cmd_fit(args: argparse.Namespace) -> int:
    import numpy as np

    from .dmp import DMP
    from ._trajectory import resample_time
    from .io import load_trajectory, save_model
    from .metrics import path_extent, rmse

    demonstration = load_trajectory(args.demo)
    dmp = DMP(
        n_kernels=args.n_kernels, alpha=args.alpha, beta=args.beta, K=args.K,
        alpha_phase=args.alpha_phase, tau=args.tau, regression=args.regression,
    ).fit(demonstration)
    path = save_model(dmp, args.output)
    reproduction = dmp.rollout()  # round(tau * T) samples: with tau != 1 the same path, slower
    error = rmse(reproduction, resample_time(demonstration, reproduction.shape[0]))
    extent = path_extent(demonstration)
    if not np.isfinite(error):  # never print a non-finite result as a success
        raise ValueError(f"the fitted DMP does not reproduce {args.demo} (RMSE {error}); the settings are out of range")
    print(f"fitted a DMP on {args.demo}: T = {dmp.n_steps_} samples, D = {dmp.n_dims_}, "
          f"rollouts take {reproduction.shape[0]} samples of {dmp.dt_:.4g} s (tau = {dmp.tau:g})")
    print(f"  start {np.array2string(dmp.start_, precision=4)}  goal {np.array2string(dmp.goal_, precision=4)}")
    print(f"  reproduction RMSE {error:.4g} ({100 * error / extent:.3g} % of the extent {extent:.4g})")
    print(f"  end-point gain c = {dmp.endpoint_gain():.4g}: a goal moved by d is missed by c*d after {reproduction.shape[0]} samples")
    print(f"wrote {path}")
    return EXIT_OK


def _rollout_goal(model, goal):
    """The goal a rollout went to: the one given, else the model's default (a Bi-DMP's latest skill)."""
    if goal is not None:
        return goal
    return model.skill_goals_[-1] if hasattr(model, "skill_goals_") else model.goal_


def _cmd_rollout(args: argparse.Namespace) -> int:
    import numpy as np

    from .dmp import DMP
    from .incremental import BiDMP
    from .io import load_model, save_trajectory

    model = load_model(args.model)
    if isinstance(model, DMP):
        if args.skill is not None:
            raise ValueError(f"--skill needs a Bi-DMP model; {args.model} holds a plain DMP")
        trajectory = model.rollout(goal=args.goal, start=args.start, n_steps=args.n_steps)
        dmp = model
    elif isinstance(model, BiDMP):
        skill = "nearest" if args.skill is None else (int(args.skill) if args.skill.lstrip("-").isdigit() else args.skill)
        query = _rollout_goal(model, args.goal)
        index = model.select_skill(query, skill)
        trajectory = model.rollout(goal=query, skill=skill, start=args.start, n_steps=args.n_steps)
        print(f"Bi-DMP with {model.n_skills} skills: using skill {index} (training goal "
              f"{np.array2string(model.skill_goals_[index], precision=3)})")
        dmp = model.dmp_
    else:
        raise ValueError(f"{args.model} holds a {type(model).__name__}, which cannot be rolled out")
    times = np.arange(trajectory.shape[0]) * dmp.dt_  # one Euler step is dt seconds
    path = save_trajectory(trajectory, args.output, times=times if args.output.lower().endswith(".csv") else None)
    goal = np.asarray(_rollout_goal(model, args.goal), dtype=float)
    print(f"rolled out {trajectory.shape[0]} steps to goal {np.array2string(goal, precision=4)}")
    print(f"  end point {np.array2string(trajectory[-1], precision=4)}, distance to goal {np.linalg.norm(trajectory[-1] - goal):.4g}")
    print(f"wrote {path}")
    if args.plot:
        from .plotting import plot_trajectories

        figure = plot_trajectories(args.plot, dmp.rollout(), [trajectory], ["rollout"], goals=goal[None], title="rollout")
        print(f"wrote {figure}")
    return EXIT_OK


def _cmd_lasa(args: argparse.Namespace) -> int:
    from .datasets import lasa, lasa_names

    if args.lasa_command == "list":
        for name in lasa_names():
            print(name)
        return EXIT_OK
    from .io import save_trajectory

    demos = lasa(args.name)
    if not 0 <= args.demo < demos.shape[0]:
        raise ValueError(f"--demo must be 0-{demos.shape[0] - 1}, got {args.demo}")
    path = save_trajectory(demos[args.demo], args.output)
    print(f"wrote {args.name} demonstration {args.demo} ({demos.shape[1]} x {demos.shape[2]}) to {path}")
    return EXIT_OK


def _run_scenario(scenario, out, methods=None):
    """Evaluate a scenario with a progress bar, print its report, write results and figures."""
    from tqdm import tqdm

    from .evaluation import evaluate, write_report

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


def _cmd_demo(args: argparse.Namespace) -> int:
    from pathlib import Path

    out = Path(args.out)
    if args.lasa:
        return _lasa_demo(args.lasa, out)
    from .scenarios import load

    scenario = load(args.scenario, allow_outside_files=args.allow_outside_files)
    methods = None
    if args.methods is not None:
        methods = [m.strip() for m in args.methods.split(",") if m.strip()]
        if not methods:
            raise ValueError(f"--methods names no method: {args.methods!r}")
    _run_scenario(scenario, out, methods)
    return EXIT_OK


def _lasa_demo(shape: str, out) -> int:
    from .io import atomic_write
    from .plotting import plot_generalisation
    from .reproduce import lasa_generalisation

    out.mkdir(parents=True, exist_ok=True)
    result = lasa_generalisation(shape)
    print("bidmp demo --lasa: " + result.summary())
    with atomic_write(out / "lasa_generalisation.json", "w") as handle:
        json.dump(result.to_dict(), handle, indent=2)
    figure = plot_generalisation(out / "lasa_generalisation.png", result)
    print(f"wrote {out / 'lasa_generalisation.json'} and {figure}")
    return EXIT_OK


def _cmd_scenario(args: argparse.Namespace) -> int:
    from .scenarios import builtin_names, builtin_text, load

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


def _cmd_segment(args: argparse.Namespace) -> int:
    import numpy as np

    from ._tables import text_table
    from ._trajectory import arclength, resample_arclength
    from .io import load_trajectory
    from .segmentation import curvature, segment

    y = load_trajectory(args.demo)
    result = segment(y, eps_frac=args.eps_frac, method=args.method)
    points, kinds = result.points, result.kinds
    s = arclength(y)
    print(f"{args.demo}: {y.shape[0]} samples, D = {y.shape[1]}, {len(points)} segmentation point(s)")
    if len(points):
        rows = [
            [str(point), "max" if kind > 0 else "min", f"{100 * s[point] / s[-1]:.1f}", np.array2string(y[point], precision=3)]
            for point, kind in zip(points, kinds)
        ]
        print(text_table(["index", "curvature", "arc length %", "position"], rows))
    if args.plot:
        from .plotting import plot_segmentation

        from .segmentation import MAX_ANALYSIS_POINTS

        kappa = curvature(resample_arclength(y, min(y.shape[0], MAX_ANALYSIS_POINTS)))
        print(f"wrote {plot_segmentation(args.plot, y, points, kinds, curvature=kappa, title=f'1D-SEG of {args.demo}')}")
    return EXIT_OK


def _cmd_extend(args: argparse.Namespace) -> int:
    import numpy as np

    from .dmp import DMP
    from .extension import extend_demonstration
    from ._trajectory import resample_time
    from .incremental import BiDMP
    from .io import load_model, load_trajectory, save_model, save_trajectory
    from .metrics import path_extent, rmse

    if not args.output.lower().endswith(".npz"):
        raise ValueError(f"-o must be the Bi-DMP model file to write (.npz), got {args.output}; "
                         "use --save-demo to write the extended demonstration")
    model = load_model(args.model)
    if isinstance(model, DMP):
        model = BiDMP(model)
    elif not isinstance(model, BiDMP):
        raise ValueError(f"{args.model} holds a {type(model).__name__}; extend needs a DMP or a Bi-DMP model")
    y = load_trajectory(args.demo)
    n_dims = model.n_dims_
    if y.shape[1] != n_dims:
        raise ValueError(f"{args.demo} has D = {y.shape[1]} but the model {args.model} has D = {n_dims}")
    extension = extend_demonstration(y, args.target, seed=args.seed)
    target = extension.new_target
    history = extension.similarity_history
    print(f"segmentation points {extension.segmentation_points.tolist()}; imitating piece {extension.piece.index} "
          f"(samples {extension.piece.start}-{extension.piece.end}) from seg = {np.array2string(y[extension.seg_index], precision=3)}")
    if len(history):
        print(f"G-PRM similarity per iteration: {' '.join(f'{v:.3f}' for v in history)} (best {extension.similarity:.3f})")
    before = np.linalg.norm(model.rollout(target)[-1] - target)
    model.learn(extension.complete)
    rollout = model.rollout(target)
    scale = path_extent(extension.complete)
    error = rmse(rollout, resample_time(extension.complete, rollout.shape[0]))
    print(f"learned skill {model.n_skills - 1}: rollout to the target reproduces the extended demonstration with "
          f"RMSE {error:.4g} ({100 * error / scale:.3g} % of its extent)")
    print(f"end-point error at the target: {before:.4g} before, {np.linalg.norm(rollout[-1] - target):.4g} after")
    print(f"wrote {save_model(model, args.output)} ({model.n_skills} skills)")
    if args.save_demo:
        print(f"wrote the extended demonstration to {save_trajectory(extension.complete, args.save_demo)}")
    if args.plot:
        from .plotting import plot_extension

        print(f"wrote {plot_extension(args.plot, extension)}")
    return EXIT_OK


def _cmd_reproduce(args: argparse.Namespace) -> int:
    from functools import partial
    from pathlib import Path

    from tqdm import tqdm

    from . import reproduce

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
def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="bidmp",
        description="Learn robot movements from one demonstration: DMP, extended demonstrations, Bi-DMP.",
        epilog="Trajectory files are .csv (optional header x,y[,z] or t,x,y[,z]) or .npy of shape (T, D).",
    )
    parser.add_argument("--version", action="version", version=f"bidmp {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks and debug logging")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    fit = commands.add_parser("fit", help="learn a DMP from a demonstration", description="Learn a DMP from one demonstration and save it as a model file (.npz).")
    fit.add_argument("demo", metavar="DEMO", help="demonstration (.csv or .npy)")
    fit.add_argument("-o", "--output", required=True, metavar="MODEL", help="model file to write (.npz)")
    fit.add_argument("--n-kernels", type=int, default=50, help="kernels per dimension (default 50)")
    fit.add_argument("--alpha", type=float, default=25.0, help="spring-damper gain alpha (default 25)")
    fit.add_argument("--beta", type=float, default=None, help="spring ratio beta (default alpha/4)")
    fit.add_argument("--K", type=_parse_K, default="paper", help="forcing gain: paper (K=alpha), pastor (K=alpha*beta) or a number")
    fit.add_argument("--alpha-phase", type=float, default=1.0, help="phase decay alpha_phase (default 1)")
    fit.add_argument("--tau", type=float, default=1.0, help="temporal scaling: rollouts take tau times the demonstration's duration (default 1)")
    fit.add_argument("--regression", "--fit", dest="regression", choices=("lwr", "ridge"), default="lwr", help="weight regression (default lwr)")
    fit.set_defaults(handler=_cmd_fit)

    rollout = commands.add_parser("rollout", help="generate a trajectory from a model", description="Roll a saved model out to a goal and write the trajectory.")
    rollout.add_argument("model", metavar="MODEL", help="model file (.npz) written by 'bidmp fit' or 'bidmp extend'")
    rollout.add_argument("--goal", type=float, nargs="+", metavar="X", help="goal coordinates (default: the demonstrated goal)")
    rollout.add_argument("--start", type=float, nargs="+", metavar="X", help="start coordinates (default: the demonstrated start)")
    rollout.add_argument("--n-steps", type=int, default=None, help="number of samples (default: round(tau * T), T = the demonstration's)")
    rollout.add_argument("-o", "--output", required=True, metavar="OUT", help="trajectory file to write (.csv or .npy)")
    rollout.add_argument("--skill", default=None, help="Bi-DMP models: nearest (default), latest or a skill number (0 = plain DMP)")
    rollout.add_argument("--plot", metavar="PNG", help="also write a figure of the rollout")
    rollout.set_defaults(handler=_cmd_rollout)

    seg = commands.add_parser("segment", help="find the segmentation points of a demonstration (1D-SEG)",
                              description="Cut a 2-D or 3-D demonstration at its curvature extrema (1D-SEG).")
    seg.add_argument("demo", metavar="DEMO", help="demonstration (.csv or .npy)")
    seg.add_argument("--eps-frac", type=float, default=0.1, help="pruning threshold, fraction of the curvature range (default 0.1)")
    seg.add_argument("--method", choices=("persistence", "paper"), default="persistence", help="pruning rule (default persistence)")
    seg.add_argument("--plot", metavar="PNG", help="also write a figure with the points and the curvature")
    seg.set_defaults(handler=_cmd_segment)

    extend = commands.add_parser("extend", help="learn a new target incrementally (1D-SEG + G-PRM + Bi-DMP)",
                                 description="Segment DEMO, grow an extended demonstration to the new target with G-PRM, "
                                             "and learn it incrementally on top of MODEL (a DMP or a Bi-DMP) as a new skill.")
    extend.add_argument("model", metavar="MODEL", help="a DMP (from 'bidmp fit') or Bi-DMP (from 'bidmp extend') model file")
    extend.add_argument("demo", metavar="DEMO", help="the demonstration to extend (.csv or .npy)")
    extend.add_argument("--target", type=float, nargs="+", required=True, metavar="X", help="new target coordinates")
    extend.add_argument("-o", "--output", required=True, metavar="MODEL2", help="Bi-DMP model file to write (.npz)")
    extend.add_argument("--save-demo", metavar="OUT", help="also write the extended demonstration (.csv or .npy)")
    extend.add_argument("--seed", type=int, default=0, help="G-PRM random seed (default 0)")
    extend.add_argument("--plot", metavar="PNG", help="also write a figure")
    extend.set_defaults(handler=_cmd_extend)

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
    demo.add_argument("--lasa", metavar="SHAPE", help="instead: the LASA fit-and-generalise example on SHAPE (e.g. Sshape)")
    demo.add_argument("--allow-outside-files", action="store_true",
                      help="let the scenario read demonstration files outside its own folder")
    demo.set_defaults(handler=_cmd_demo)

    scenario = commands.add_parser("scenario", help="built-in scenarios: list, show, check a file",
                                   description="List the built-in scenarios, print one as JSON to copy and edit "
                                               "('bidmp scenario show nut-unscrewing > my.json'), or validate a scenario file.")
    scenario_commands = scenario.add_subparsers(dest="scenario_command", metavar="{list,show,check}", required=True, parser_class=_Parser)
    scenario_commands.add_parser("list", help="list the built-in scenarios")
    show = scenario_commands.add_parser("show", help="print a built-in scenario as JSON")
    show.add_argument("name", metavar="NAME")
    check = scenario_commands.add_parser("check", help="validate a scenario file")
    check.add_argument("file", metavar="FILE")
    check.add_argument("--allow-outside-files", action="store_true",
                       help="let the scenario read demonstration files outside its own folder")
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
    except (ValueError, TypeError, OSError, ArithmeticError, RuntimeWarning, RecursionError, MemoryError) as exc:
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
