"""Progress of long work, reported by the library and shown by whoever runs it.

The library never prints: its long loops (the G-PRM iterations of an extension, its plannings with
a wider margin) call :func:`report`, which does nothing unless a caller has installed a reporter
with :func:`reporting` — the command line installs tqdm bars on stderr when it is a terminal. A
context variable rather than a ``progress=`` argument threaded through every signature on the
way down: the loops sit several calls below the public functions, whose options are already many.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import contextmanager
from contextvars import ContextVar

__all__ = ["report", "reporting"]

Reporter = Callable[[str, int, int], None]
_REPORTER: ContextVar[Reporter | None] = ContextVar("bidmp_progress", default=None)


def report(stage: str, done: int, total: int) -> None:
    """Tell the installed reporter (if any) that ``done`` of ``total`` steps of ``stage`` are done."""
    reporter = _REPORTER.get()
    if reporter is not None:
        reporter(stage, done, total)


@contextmanager
def reporting(reporter: Reporter | None) -> Iterator[None]:
    """Within the block, :func:`report` calls ``reporter(stage, done, total)``."""
    token = _REPORTER.set(reporter)
    try:
        yield
    finally:
        _REPORTER.reset(token)
