"""What judging a motion by the FCI's limits costs (bidmp.sim.fci.judge_commands, and the whole
``bidmp verify`` command reading the file): a 10 s joint motion of the FR3 at 1 kHz (10 000
commands), against the plain per-sample loop of tests/sim/test_fci.py (the same check written as
libfranka describes it), the two sides interleaved. The target: the command within 50 ms.

    .venv/bin/python benchmarks/bench_verify.py [--rounds 7] [--smoke]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
from pathlib import Path

import numpy as np
from _timing import interleaved_times

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "sim"))
from test_fci import reference  # noqa: E402

from bidmp.cli import main  # noqa: E402
from bidmp.sim.fci import judge_commands  # noqa: E402


def stream(seconds: float) -> np.ndarray:
    """A rest-to-rest FR3 move of ``seconds`` at 1 kHz, within its limits."""
    n = int(round(seconds * 1000)) + 1
    s = np.linspace(0.0, 1.0, n)[:, None]
    start = np.array([0.0, -0.4, 0.0, -2.0, 0.0, 1.9, 0.8])
    return start + 0.6 * (10 * s**3 - 15 * s**4 + 6 * s**5)


def main_bench() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--smoke", action="store_true", help="one round, a 1 s motion (CI)")
    args = parser.parse_args()
    seconds = 1.0 if args.smoke else 10.0
    q = stream(seconds)
    folder = Path(tempfile.mkdtemp())
    path = folder / "motion.csv"
    names = [f"fr3_joint{i}" for i in range(1, 8)]
    t = np.arange(len(q)) / 1000.0
    np.savetxt(
        path, np.column_stack([t, q]), delimiter=",", header="t," + ",".join(names), comments=""
    )
    assert judge_commands(q, "fr3").ok and reference(q, "fr3") is None
    rounds = 1 if args.smoke else args.rounds
    devnull = open(os.devnull, "w")  # the command's own printing, not timed apart

    def command():
        stdout, sys.stdout = sys.stdout, devnull
        try:
            assert main(["verify", str(path), "--robot", "fr3"]) == 0
        finally:
            sys.stdout = stdout

    times = interleaved_times(
        {
            "judge_commands": lambda: judge_commands(q, "fr3"),
            "plain loop": lambda: reference(q, "fr3"),
            "bidmp verify (file)": command,
        },
        rounds,
    )
    load = os.getloadavg()[0]
    print(f"{seconds:g} s motion, {len(q)} commands; load average {load:.2f}; medians of {rounds}")
    for name, value in times.items():
        print(f"  {name:22s} {1e3 * value:9.2f} ms")
    print(f"  plain loop / judge_commands: {times['plain loop'] / times['judge_commands']:.0f}x")
    verdict = "within" if times["bidmp verify (file)"] <= 0.05 else "over"
    print(f"  bidmp verify: {verdict} the 50 ms target")
    devnull.close()


if __name__ == "__main__":
    main_bench()
