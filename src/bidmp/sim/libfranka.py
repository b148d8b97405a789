"""Joint-position command streams judged by real robot software: libfranka (pylibfranka) streaming
them at 1 kHz to franka-sim, an FCI server that simulates an FR3 and aborts a motion with the
reflex the real controller raises.

Both run in their own virtual environment (``make franka``: franka-sim, pylibfranka and MuJoCo at
their pins, which need NumPy 1.26, and an FR3 model built offline), found as ``$BIDMP_FRANKA_VENV``,
else ``.venv-franka`` in the working folder, else beside the source tree. bidmp hands the streams to
``_franka_side.py`` (the only file that runs there; it imports nothing of bidmp) in a ``.npz`` and
reads one JSON line per stream back. The server runs on a free loopback address (libfranka's
command port is fixed at 1337, the address is not) and is stopped when the streams are done, or
with the process that started it.

franka-sim serves an FR3 only (robot protocol 10; the Panda's protocol 5 is libfranka 0.9's):
a Panda's commands are judged by the FER tables of :mod:`bidmp.sim.fci`, not here.
"""

from __future__ import annotations

import json
import logging
import os
import signal
import subprocess
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._checks import MissingExtraError
from .._progress import report

__all__ = ["LibfrankaOutcome", "SideEnvironmentError", "franka_side_environment", "stream_fr3"]

logger = logging.getLogger(__name__)

SIDE_SCRIPT = Path(__file__).with_name("_franka_side.py")
SIDE_VENV_VARIABLE = "BIDMP_FRANKA_VENV"
SIDE_VENV_NAME = ".venv-franka"
SIDE_MODEL_NAME = "fr3_meshless.xml"  # what make franka builds inside the side environment


class SideEnvironmentError(MissingExtraError):
    """The libfranka side environment is missing or broken (``make franka`` builds it): like a
    missing extra, a set-up to do, not bad input nor a bug."""


@dataclass(frozen=True)
class LibfrankaOutcome:
    """libfranka's verdict on one stream: ``accepted``, or the ``reflexes`` its ControlException
    named, the ``phase`` they came in (``"approach"``: the slow move to the stream's first
    command; ``"motion"``: the stream itself, or the rest held after it) and the stream's
    ``sample`` (0-based; ``len(q)`` and after: the rest held after its last command), and how
    often it was streamed again because the client had missed a cycle just before a reflex (a
    loaded machine's doing, not the motion's)."""

    accepted: bool
    reflexes: tuple = ()
    phase: str = ""
    sample: int = -1
    message: str = ""
    retries: int = 0  # streamed again after a reflex that followed a missed 1 ms cycle here

    def reason(self) -> str:
        if self.accepted:
            return ""
        return f"libfranka: {', '.join(self.reflexes) or self.message} at sample {self.sample} ({self.phase})"


def franka_side_environment() -> tuple[Path, Path]:
    """(the side environment's Python, its FR3 model), or :class:`SideEnvironmentError` saying how
    to build it."""
    candidates = []
    if os.environ.get(SIDE_VENV_VARIABLE):
        candidates.append(Path(os.environ[SIDE_VENV_VARIABLE]))
    else:
        candidates += [Path.cwd() / SIDE_VENV_NAME, Path(__file__).parents[3] / SIDE_VENV_NAME]
    for venv in candidates:
        python, model = venv / "bin" / "python", venv / SIDE_MODEL_NAME
        if python.exists() and model.exists():
            return python, model
    raise SideEnvironmentError(
        f"the libfranka side environment is missing (looked for {' and '.join(map(str, candidates))} "
        f"with bin/python and {SIDE_MODEL_NAME}): run 'make franka' in bidmp's source folder, or "
        f"set {SIDE_VENV_VARIABLE} to one built that way"
    )


def stream_fr3(streams, *, timeout_s: float | None = None) -> list[LibfrankaOutcome]:
    """Stream joint-position commands through libfranka to a simulated FR3, each in one motion:
    a slow quintic move from where the arm stands to its first command, 3 ms held, the stream at
    1 kHz, 3 ms held at its last command (the motion finishes at rest).

    Parameters
    ----------
    streams : sequence of arrays (T, 7)
        Joint positions (rad), one per millisecond, in the FR3's joint order.
    timeout_s : float, optional
        Wall-clock bound on the whole run (default: 60 s plus three times the streams' length and
        their approaches in real time); the server and the client are killed past it.

    Returns
    -------
    list of LibfrankaOutcome
        One per stream, in order.
    """
    arrays = []
    for index, q in enumerate(streams):
        q = np.asarray(q, dtype=float)
        if q.ndim != 2 or q.shape[1] != 7 or q.shape[0] < 1 or not np.all(np.isfinite(q)):
            raise ValueError(
                f"streams[{index}] must be finite joint positions of shape (T, 7), got {q.shape}"
            )
        arrays.append(q)
    python, model = franka_side_environment()
    if timeout_s is None:
        timeout_s = 60.0 + 3e-3 * sum(q.shape[0] + 4000 for q in arrays)
    with tempfile.TemporaryDirectory(prefix="bidmp-libfranka-") as folder:
        archive = Path(folder) / "streams.npz"
        np.savez(archive, **{f"stream_{index}": q for index, q in enumerate(arrays)})
        outcomes = _run_side(
            python, [str(SIDE_SCRIPT), "stream", str(archive), str(model)], timeout_s, len(arrays)
        )
    return outcomes


def _run_side(
    python: Path, arguments: list, timeout_s: float, count: int
) -> list[LibfrankaOutcome]:
    """Run the side script, reading its JSON lines as they come (a progress report per stream);
    its whole process group killed past ``timeout_s`` or on any exception here (an interrupt)."""
    import threading

    expired = threading.Event()
    outcomes: list[LibfrankaOutcome] = []
    with (
        tempfile.TemporaryFile(mode="w+") as errors,  # a file: a full pipe would stall the side
        subprocess.Popen(
            [str(python), *arguments],
            stdout=subprocess.PIPE,
            stderr=errors,
            text=True,
            start_new_session=True,
        ) as process,
    ):

        def kill():
            expired.set()
            _kill_group(process)

        watchdog = threading.Timer(timeout_s, kill)
        watchdog.start()
        try:
            for line in process.stdout:
                outcomes.append(_outcome(json.loads(line)))
                report("libfranka streams", len(outcomes), count)
            process.wait()
        finally:
            watchdog.cancel()
            _kill_group(process)
        errors.seek(0)
        tail = (errors.read().strip().splitlines() or ["no message"])[-1]
    if expired.is_set():
        raise SideEnvironmentError(
            f"libfranka and franka-sim did not finish {count} streams within {timeout_s:.0f} s"
        )
    if process.returncode != 0 or len(outcomes) != count:
        raise SideEnvironmentError(
            f"the libfranka side ended with exit {process.returncode} after {len(outcomes)} of "
            f"{count} streams: {tail[:300]}"
        )
    return outcomes


def _outcome(record: dict) -> LibfrankaOutcome:
    return LibfrankaOutcome(
        bool(record["accepted"]),
        tuple(record["reflexes"]),
        str(record["phase"]),
        int(record["sample"]),
        str(record["message"]),
        int(record.get("retries", 0)),
    )


def _kill_group(process: subprocess.Popen) -> None:
    if process.poll() is None:
        try:
            os.killpg(process.pid, signal.SIGKILL)
        except ProcessLookupError:  # pragma: no cover - it ended between the poll and the kill
            pass
        process.wait()
