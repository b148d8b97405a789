"""The built-in 14-nut job's speed on the two physics engines, PyBullet and MuJoCo, against real
time, the engines interleaved round by round (a noisy stretch of the machine hits both alike).

    .venv/bin/python benchmarks/bench_engines.py [--repeats N]

Prints, per engine, simulated seconds over wall seconds and over the process's CPU seconds (the
skills' evaluation before the job not counted: it is the same on both), the median of the rounds,
with the machine's load average before and after (on a shared machine the wall-time factor is the
load's as much as the engine's; the CPU-time factor is the engine's). Target: MuJoCo >= 30x real
time; PyBullet no slower than before.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

from bidmp.sim.job import run_job
from bidmp.tasks import evaluate, scenarios

ENGINES = ("pybullet", "mujoco")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    nut = scenarios.load("nut-unscrewing")
    report = evaluate(nut.with_robot_protocol(), ["bidmp"], geometry=False)
    print(
        f"load average before: {' '.join(f'{v:.1f}' for v in os.getloadavg())} on {os.cpu_count()} cores"
    )
    wall = {engine: [] for engine in ENGINES}
    cpu = {engine: [] for engine in ENGINES}
    removed = {}
    for _ in range(args.repeats):
        for engine in ENGINES:
            start = time.process_time()
            job = run_job(nut, report=report, backend=engine)
            cpu[engine].append(job.simulated_s / (time.process_time() - start))
            wall[engine].append(job.simulated_s / job.wall_s)
            removed[engine] = sum(record.removed for record in job.targets)
    for engine in ENGINES:
        print(
            f"  {engine:9s} {statistics.median(wall[engine]):5.1f}x real time by the wall clock, "
            f"{statistics.median(cpu[engine]):5.1f}x by CPU time (medians of {args.repeats}: "
            f"{', '.join(f'{v:.1f}' for v in wall[engine])} / "
            f"{', '.join(f'{v:.1f}' for v in cpu[engine])}); {removed[engine]}/14 removed"
        )
    print(f"load average after: {' '.join(f'{v:.1f}' for v in os.getloadavg())}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
