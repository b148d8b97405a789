"""every command that can run for minutes shows its progress on stderr when stderr is a
terminal (tqdm bars: the extension's G-PRM iterations, the evaluation with each repair it tries,
the simulated motions, the job's parts, the LASA cells), and nothing when it is not (a log or a
pipe stays clean). Each command runs in a child process whose stderr is a pseudo-terminal of 120
columns, as a shell gives it."""

import fcntl
import os
import pty
import struct
import subprocess
import sys
import termios
from pathlib import Path

import pytest

from bidmp.experiments import BATTERY_APPROACH_VIA  # noqa: F401  (the package imports: a broken install fails here)

ROOT = Path(__file__).resolve().parents[2]
RECORDING = ROOT / "src" / "bidmp" / "data" / "recordings" / "operator1_nut3.csv"


def _bidmp(argv, cwd, terminal: bool) -> tuple[int, str]:
    """Run ``python -m bidmp argv``; (exit code, what it wrote on stderr)."""
    command = [sys.executable, "-m", "bidmp", *map(str, argv)]
    if not terminal:
        done = subprocess.run(command, cwd=cwd, capture_output=True, text=True, timeout=120)
        return done.returncode, done.stderr
    master, slave = pty.openpty()
    fcntl.ioctl(slave, termios.TIOCSWINSZ, struct.pack("HHHH", 40, 120, 0, 0))
    child = subprocess.Popen(command, cwd=cwd, stdout=subprocess.DEVNULL, stderr=slave)
    os.close(slave)
    chunks = []
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:  # the child closed its end
            break
        if not chunk:
            break
        chunks.append(chunk)
    os.close(master)
    return child.wait(timeout=120), b"".join(chunks).decode("utf-8", "replace")


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    folder = tmp_path_factory.mktemp("progress")
    code, err = _bidmp(
        ["fit", RECORDING, "--units", "mm", "-o", folder / "nut.npz"], folder, terminal=False
    )
    assert code == 0, err
    return folder


COMMANDS = {
    "extend": (
        [
            "extend",
            "nut.npz",
            RECORDING,
            "--target",
            "200",
            "-100",
            "0",
            "--units",
            "mm",
            "-o",
            "ext.npz",
        ],
        "G-PRM iterations",
    ),
    # the bars are the point here, not the physics: the kinematic backend runs in a fraction
    "sim": (
        ["sim", "--targets", "3", "--methods", "bidmp", "--no-pictures", "--out", "sim"]
        + ["--backend", "kinematic"],
        "nut-unscrewing (sim)",
    ),
    "job": (
        ["job", "--targets", "3", "--no-pictures", "--out", "job", "--backend", "kinematic"],
        "nut-unscrewing (job)",
    ),
    "lasa": (
        [
            "benchmark",
            "lasa",
            "--shapes",
            "Sshape",
            "--demos",
            "first3",
            "--every",
            "10",
            "--methods",
            "dmp",
            "--workers",
            "1",
            "--out",
            "lasa",
        ],
        "LASA",
    ),
    "repair": (
        [
            "demo",
            "--scenario",
            ROOT / "tests" / "data" / "two_posts.json",
            "--methods",
            "bidmp",
            "--out",
            "demo",
        ],
        "bidmp: repair 8",
    ),
}


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_a_long_command_shows_progress_on_a_terminal_and_not_in_a_pipe(model, name):
    argv, shown = COMMANDS[name]
    code, err = _bidmp(argv, model, terminal=True)
    assert code in (0, 3), err[
        -2000:
    ]  # 3: ran, not every target succeeded (the exit status says so)
    assert shown in err and "%|" in err, err[-2000:]
    if name in (
        "extend",
        "sim",
    ):  # the library's own reports and a command's bar alike (the others cost seconds each)
        code, err = _bidmp(argv, model, terminal=False)
        assert code in (0, 3) and "%|" not in err and shown not in err, err[-2000:]
