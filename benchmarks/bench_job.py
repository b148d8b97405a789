"""The whole job's speed against real time, and bidmp sim's with 1 and 2 worker
processes, in one run, the sides interleaved; then the whole commands a user types.

    .venv/bin/python benchmarks/bench_job.py [--repeats N]

Prints, for the built-in 14-nut job (target >= 5x real time on 2 cores) and the 12-cell job,
simulated seconds over wall seconds (the skills' evaluation before the job not counted: it is
the same for any run length), and for ``bidmp.sim.simulate`` on every nut with dmp and bidmp
without pictures (target >= 10x) the real-time factor with 1 and with 2 workers and their ratio.

Then ``bidmp sim --targets 1,12`` (target >= 10x) and ``bidmp job`` (target >= 15x) as fresh
processes, timed from outside (interpreter start-up, imports, learning, simulation, pictures,
writing and the interpreter's teardown): the simulated seconds the command prints over that wall
time, the two commands interleaved round by round.
"""

from __future__ import annotations

import argparse
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from bidmp.sim import execution_report, simulate
from bidmp.sim.job import run_job
from bidmp.tasks import evaluate, scenarios


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    nut, cells = scenarios.load("nut-unscrewing"), scenarios.load("cell-removal")
    job_reports = {
        "nut": evaluate(nut.with_robot_protocol(), ["bidmp"], geometry=False),
        "cells": evaluate(cells.with_robot_protocol(), ["bidmp"], geometry=False),
    }
    sim_report = execution_report(nut, ["dmp", "bidmp"])
    factors = {"nut job": [], "cell job": [], "sim 1 worker": [], "sim 2 workers": []}
    for _ in range(args.repeats):  # each round runs every side once: load drift falls on all alike
        for name, scenario, key in (("nut job", nut, "nut"), ("cell job", cells, "cells")):
            report = run_job(scenario, report=job_reports[key])
            factors[name].append(report.simulated_s / report.wall_s)
        for workers in (1, 2):
            start = time.perf_counter()
            result = simulate(nut, ["dmp", "bidmp"], report=sim_report, workers=workers)
            factors[f"sim {workers} worker{'s' if workers > 1 else ''}"].append(
                result.simulated_s / (time.perf_counter() - start)
            )
    for name, values in factors.items():
        print(
            f"  {name:14s} {statistics.median(values):5.1f}x real time (median of {len(values)}: "
            f"{', '.join(f'{v:.1f}' for v in values)})"
        )
    ratio = statistics.median(factors["sim 2 workers"]) / statistics.median(factors["sim 1 worker"])
    print(f"  bidmp sim: 2 workers / 1 worker = {ratio:.2f}x (target >= 1.6x, or the workers go)")
    print("the whole commands, fresh processes timed from outside:")
    for name, values in whole_commands(args.repeats).items():
        print(
            f"  {name:28s} {statistics.median(values):5.1f}x real time (target >= "
            f"{COMMAND_TARGETS[name]:g}x; median of {len(values)}: "
            f"{', '.join(f'{v:.1f}' for v in values)})"
        )
    return 0


COMMANDS = {"bidmp sim --targets 1,12": ["sim", "--targets", "1,12"], "bidmp job": ["job"]}
COMMAND_TARGETS = {"bidmp sim --targets 1,12": 10.0, "bidmp job": 15.0}
_SIMULATED = re.compile(r"for ([0-9.]+) s simulated")


def whole_commands(rounds: int) -> dict[str, list[float]]:
    """Simulated seconds (as the command prints them) over the process's wall time, per command,
    the commands interleaved round by round."""
    bidmp = Path(sys.executable).with_name("bidmp")
    factors = {name: [] for name in COMMANDS}
    with tempfile.TemporaryDirectory() as folder:
        for _ in range(rounds):
            for name, arguments in COMMANDS.items():
                start = time.perf_counter()
                done = subprocess.run(
                    [str(bidmp), *arguments, "--out", str(Path(folder) / arguments[0])],
                    capture_output=True,
                    text=True,
                    check=True,
                )
                wall = time.perf_counter() - start
                simulated = float(_SIMULATED.findall(done.stdout)[-1])
                factors[name].append(simulated / wall)
    return factors


if __name__ == "__main__":
    raise SystemExit(main())
