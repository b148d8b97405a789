"""What every command of the ``bidmp`` command line shares: exit codes, the one-line error parser,
argument types and flags. Imports nothing heavy (``bidmp --help`` must not load NumPy)."""

from __future__ import annotations

import argparse
import contextlib
import time

__all__ = [
    "EXIT_OK",
    "EXIT_INTERNAL",
    "EXIT_BAD_INPUT",
    "EXIT_TARGETS_FAILED",
    "judged_methods",
    "EXIT_BROKEN_PIPE",
    "MAX_MESSAGE",
    "MAX_SEEDS",
    "Parser",
    "parse_K",
    "allow_outside_files",
    "one_line",
    "split_names",
    "progress_bars",
    "overwrite_option",
    "output_folder",
    "shown_written",
]

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_BAD_INPUT = 2
# A run that went through but not every target succeeded (bidmp demo, sim, job): the summary says how
# many and why. Judged on the pipeline's method (bidmp) when it ran, else on every method run.
EXIT_TARGETS_FAILED = 3
EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, what a tool killed by a closed pipe reports
MAX_MESSAGE = 600  # characters of one error line
MAX_SEEDS = 200  # = bidmp.experiments.MAX_SEEDS (not imported: --help must not load NumPy)


class Parser(argparse.ArgumentParser):
    """argparse, but usage errors are one line (plus a pointer to --help), exit code 2."""

    def error(self, message: str):  # noqa: D401 - argparse API
        self.exit(
            EXIT_BAD_INPUT,
            one_line(f"{self.prog}: error: {message} (see '{self.prog} --help')") + "\n",
        )


def parse_K(text: str):
    if text in ("paper", "pastor"):
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(
            f"must be 'paper', 'pastor' or a number, got {text!r}"
        ) from None


# ---------------------------------------------------------------------------------------------
# Parser
# ---------------------------------------------------------------------------------------------
def allow_outside_files(parser, shown: bool = True) -> None:
    """The --allow-outside-files flag of every command that reads a scenario file."""
    parser.add_argument(
        "--allow-outside-files",
        action="store_true",
        help="let the scenario read demonstration files outside its own folder"
        if shown
        else argparse.SUPPRESS,
    )


def backend_option(parser) -> None:
    """The --backend option of every command that runs the simulator (its names are checked
    when it is used: the registry is not imported to print the help)."""
    parser.add_argument(
        "--backend",
        default="pybullet",
        metavar="NAME",
        help="the simulator: pybullet (default; the sim extra), kinematic (an ideal arm in "
        "memory: no physics, no extra), or a backend registered with "
        "bidmp.sim.register_backend",
    )


def one_line(text: str) -> str:
    """One printable line: whitespace runs collapsed, control characters (a file name or argument
    may carry terminal escapes) shown as '?', at most MAX_MESSAGE characters."""
    # no NumPy import here
    text = "".join(c if c.isprintable() else "?" for c in " ".join(str(text).split()))
    return text if len(text) <= MAX_MESSAGE else text[: MAX_MESSAGE - 1] + "…"


def split_names(text: str | None, option: str) -> list[str] | None:
    """A comma-separated list of names (None stays None); an empty list is refused, naming the option."""
    if text is None:
        return None
    names = [name.strip() for name in text.split(",") if name.strip()]
    if not names:
        raise ValueError(f"{option} names no method: {text!r}")
    return names


def judged_methods(methods) -> list:
    """The methods a run's exit status is judged on: the pipeline's (those that repair their motions:
    bidmp) when any ran, else every one (a baseline asked for alone is judged on its own)."""
    from ..tasks.methods import get

    methods = list(methods)
    return [name for name in methods if get(name).repairs] or methods


@contextlib.contextmanager
def progress_bars():
    """A context in which the library's reported progress (:mod:`bidmp._progress`) shows as tqdm
    bars on stderr, one per stage, when stderr is a terminal (tqdm's ``disable=None``)."""
    from tqdm import tqdm

    from .._progress import reporting

    bars: dict = {}

    def show(stage: str, done: int, total: int) -> None:
        bar = bars.get(stage)
        if bar is None or bar.total != total or done < bar.n:  # a new round (another planning)
            if bar is not None:
                bar.close()
            bar = bars[stage] = tqdm(
                total=total, desc=stage, unit="step", disable=None, leave=False
            )
        bar.update(done - bar.n)

    try:
        with reporting(show):
            yield
    finally:
        for bar in bars.values():
            bar.close()


_STARTED: list[float] = []  # when main() began handling the command (perf_counter seconds)
_ARGV: list[str] = []  # its arguments, for a run folder's manifest


def command_started(argv=None) -> None:
    """Note the command's start (main() calls it first), for :func:`print_real_time`, and its
    arguments (default ``sys.argv[1:]``), for :func:`output_folder`'s manifest."""
    import sys

    _STARTED[:] = [time.perf_counter()]
    _ARGV[:] = [str(arg) for arg in (sys.argv[1:] if argv is None else argv)]


def overwrite_option(parser) -> None:
    """The --overwrite flag of every command that writes an output folder."""
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="replace an output folder that holds files no bidmp run wrote (every file in it is "
        "deleted); without it such a folder is refused. A folder of an earlier bidmp run is "
        "always replaced whole",
    )


@contextlib.contextmanager
def output_folder(out, overwrite: bool = False, **options):
    """The command's output folder as one run (:func:`bidmp.io.runs.run_folder`): the handler
    writes into the yielded run's ``path``; on success the run is swapped in, whole, with its
    manifest (this command line in it); on a failure the earlier run stays as it was."""
    import shlex

    from ..io.runs import run_folder

    with run_folder(out, "bidmp " + shlex.join(_ARGV), overwrite=overwrite, **options) as run:
        yield run


def shown_written(run, written) -> str:
    """The files a run wrote, where they are once it is in place, comma-separated."""
    return ", ".join(str(run.shown(path)) for path in written)


def print_real_time(simulated_s: float) -> None:
    """One line: the whole command's wall time (reading, learning, simulating, writing; from
    main's start, the interpreter's own start-up of ~0.05 s aside) against the simulated time."""
    if not _STARTED or simulated_s <= 0.0:
        return
    elapsed = time.perf_counter() - _STARTED[0]
    print(
        f"the whole command: {elapsed:.1f} s for {simulated_s:.1f} s simulated "
        f"({simulated_s / elapsed:.1f}x real time)"
    )
