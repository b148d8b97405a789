"""The ``bidmp`` command line: a thin shell over the library.

Parse, call the library, print, exit. Bad input of any kind ends with a one-line message on
stderr and exit code 2, never a traceback (``--debug`` shows it). NumPy and the library are
imported inside the command handlers so that ``bidmp --help`` starts fast.

One module per command group, each adding its commands to the parser: ``skills`` (fit, rollout,
segment, extend, learn), ``tasks`` (demo, sim, scenario), ``view`` (view), ``job`` (job),
``experiments`` (reproduce, lasa,
benchmark); ``common`` holds what they share, ``inputs`` how demonstrations are read.

Layer 4 (the shell): may import any layer, inside the handlers; nothing imports it.
"""

from __future__ import annotations

import contextlib
import logging
import sys
from collections.abc import Sequence as _Sequence

from .. import __version__
from .common import EXIT_BAD_INPUT, EXIT_BROKEN_PIPE, EXIT_INTERNAL, EXIT_OK
from .common import MAX_MESSAGE as _MAX_MESSAGE
from .common import Parser as _Parser
from .common import one_line as _one_line

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_INTERNAL", "EXIT_BAD_INPUT", "EXIT_BROKEN_PIPE"]


def build_parser() -> _Parser:
    """The ``bidmp`` parser: global options, then each command group's commands."""
    from . import experiments, job, skills, tasks, verify, view
    from .common import allow_outside_files, parse_K

    parser = _Parser(
        prog="bidmp",
        description="Learn robot movements from one demonstration: DMP, extended demonstrations, Bi-DMP.",
        epilog="Trajectory files are .csv (optional header x,y[,z] or t,x,y[,z]) or .npy of shape (T, D).",
    )
    parser.add_argument("--version", action="version", version=f"bidmp {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks and debug logging")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    skills.add_commands(commands, parse_K, allow_outside_files)
    experiments.add_commands(commands)
    tasks.add_commands(commands)
    view.add_commands(commands)
    job.add_commands(commands)
    verify.add_commands(commands)
    return parser


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


def _quiet_stdout() -> None:
    """After a closed pipe: point stdout at /dev/null so that Python's final flush is silent."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    # a replaced sys.stdout (tests) has no file number
    except (
        OSError,
        ValueError,
        AttributeError,
    ):
        pass


class _Printable:
    """stdout with control characters (a scenario name, a label or a file name may carry terminal
    escapes) shown as '?', like the error lines; newlines and tabs pass."""

    _TABLE = {code: "?" for code in (*range(0, 9), *range(11, 32), 127, *range(128, 160))}

    def __init__(self, stream) -> None:
        self._stream = stream

    def write(self, text: str) -> int:
        return self._stream.write(text.translate(self._TABLE))

    def __getattr__(self, name: str):
        return getattr(self._stream, name)


@contextlib.contextmanager
def _printable_stdout():
    """Every line a command prints, sanitised (restored afterwards, also on errors)."""
    original = sys.stdout
    sys.stdout = _Printable(original)
    try:
        yield
    finally:
        sys.stdout = original


def _log_handlers(root: logging.Logger, debug: bool) -> tuple[_BufferedLog, logging.Handler | None]:
    """The library's log while a command runs: buffered (printed on success), or with ``--debug``
    streamed at debug level."""
    buffered = _BufferedLog()
    if not debug:
        root.addHandler(buffered)
        return buffered, None
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
    root.addHandler(handler)
    root.setLevel(logging.DEBUG)
    return buffered, handler


def _bad_input_message(exc: BaseException) -> str:
    """What a failure from bad input says on its one line."""
    if isinstance(exc, MemoryError):
        return "out of memory; lower the sizes (see the limits in the README)"
    if isinstance(exc, RecursionError):
        return "input nested too deeply"
    if isinstance(exc, (ArithmeticError, RuntimeWarning)):
        return f"numerical failure ({exc}): the input's scale or the settings are out of range"
    if isinstance(exc, OSError) and exc.strerror:
        return f"{exc.strerror}: {exc.filename}" if exc.filename else exc.strerror
    return str(exc) or type(exc).__name__


def main(argv: _Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code.

    Every failure is one line on stderr: exit 2 for bad input of any kind (including sizes over
    the limits and settings that would overflow), 1 for an internal error, 130 on Ctrl-C, 141
    when stdout is a closed pipe (``bidmp lasa list | head -1``), silently.
    """
    import warnings

    from .common import command_started

    command_started(argv)
    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        print("bidmp: error: no command given (see 'bidmp --help')", file=sys.stderr)
        return EXIT_BAD_INPUT
    empty = [
        dest
        for dest, value in vars(args).items()
        if value == "" or isinstance(value, list) and "" in value
    ]
    if empty:  # an empty file name or option would silently mean "here" or "none"
        print(
            f"bidmp {args.command}: error: argument {empty[0].replace('_', '-')} is empty",
            file=sys.stderr,
        )
        return EXIT_BAD_INPUT
    from .._checks import MissingExtraError

    root = logging.getLogger()
    buffered, debug_handler = _log_handlers(root, args.debug)
    try:
        with warnings.catch_warnings():
            # A numerical warning means a non-finite result is on its way: never report it as a
            # success. Other warnings go to the log (one line each, printed on success).
            warnings.simplefilter("error", RuntimeWarning)
            logging.captureWarnings(True)
            with _printable_stdout():
                code = args.handler(args)
        sys.stdout.flush()
    except BrokenPipeError:
        _quiet_stdout()
        return EXIT_BROKEN_PIPE
    except KeyboardInterrupt:
        print("bidmp: interrupted", file=sys.stderr)
        return 130
    except (
        ValueError,
        TypeError,
        OSError,
        ArithmeticError,
        RuntimeWarning,
        RecursionError,
        MemoryError,
        MissingExtraError,
    ) as exc:
        if args.debug:
            raise
        print(f"bidmp {args.command}: error: {_one_line(_bad_input_message(exc))}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except Exception as exc:  # noqa: BLE001 - the CLI promises no tracebacks
        if args.debug:
            raise
        print(
            _one_line(
                f"bidmp {args.command}: internal error: {type(exc).__name__}: {exc} (rerun with --debug for details)"
            ),
            file=sys.stderr,
        )
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
