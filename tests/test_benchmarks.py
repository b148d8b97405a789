"""The benchmark scripts run: a smoke run of the quick ones with one repetition, so that none can
break silently between the full runs of ``make bench`` (``bench_scenario.py`` crashed on a
scenario check for weeks). Timings are not judged here (speed targets live in the benchmarks)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

BENCHMARKS = Path(__file__).resolve().parents[1] / "benchmarks"

# script -> (its arguments for one quick repetition, what it must print)
SMOKE = {
    "bench_dmp.py": (["--repeats", "1", "--goals", "50"], ("the robot protocol", "x faster")),
    "bench_scenario.py": (["--repeats", "1"], ("GMM / Bi-DMP run time ratio",)),
}


@pytest.mark.parametrize("script", sorted(SMOKE))
def test_a_benchmark_runs_and_prints_its_ratios(script):
    arguments, printed = SMOKE[script]
    done = subprocess.run(
        [sys.executable, str(BENCHMARKS / script), *arguments],
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
        cwd=BENCHMARKS,
        env={**os.environ, "PYTHONWARNINGS": "ignore"},
    )
    assert done.returncode == 0, done.stderr[-2000:]
    for text in printed:
        assert text in done.stdout, done.stdout[-2000:]
