"""The built-in nut task on the simulated Franka Panda (issue #12), timed in one run.

    make bench            # runs every script in benchmarks/
    .venv/bin/python benchmarks/bench_sim.py

Targets: simulated time / wall time >= 10 for the whole nut task (dmp + bidmp, 28 motions, 1 kHz
physics and position control, IK and timing included), and the whole `bidmp sim --methods
dmp,bidmp` <= 60 s on 2 cores. Also the per-step cost of PyBullet's stepSimulation alone, and
the ratio with one worker process and with two.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time

from bidmp import sim
from bidmp.tasks import scenarios


def main() -> int:
    scenario = scenarios.load("nut-unscrewing")
    report = sim.execution_report(scenario, ["dmp", "bidmp"])
    print("nut-unscrewing on the simulated Panda, dmp + bidmp, 28 motions")
    for workers in (1, 2):
        result = sim.simulate(scenario, ["dmp", "bidmp"], report=report, workers=workers)
        print(
            f"  {workers} worker process{'es' if workers > 1 else '  '}: simulated {result.simulated_s:6.1f} s in "
            f"{result.wall_s:5.1f} s wall = {result.simulated_s / result.wall_s:5.1f}x real time (target >= 10)"
        )
    # The defaults a user meets: the robot protocol's skills (timed, settling at rest).
    robot = scenario.with_robot_protocol()
    robot_report = sim.execution_report(robot, ["dmp", "bidmp"])
    result = sim.simulate(robot, ["dmp", "bidmp"], report=robot_report, workers=2)
    print(
        f"  robot protocol (defaults), 2 worker processes: simulated {result.simulated_s:6.1f} s in "
        f"{result.wall_s:5.1f} s wall = {result.simulated_s / result.wall_s:5.1f}x real time"
    )
    with sim.RobotCell(scenario.scene, scenario.units, *sim.robot_placement(scenario)) as cell:
        n = 5000
        start = time.perf_counter()
        for _ in range(n):
            cell.p.stepSimulation(physicsClientId=cell.client)
        print(
            f"  PyBullet stepSimulation alone: {(time.perf_counter() - start) / n * 1e6:.0f} us per 1 ms step"
        )
        points = seconds = 0.0
        for label in scenario.labels:
            start = time.perf_counter()
            plan = cell.plan(report.methods["bidmp"].rollouts[label], label)
            seconds += time.perf_counter() - start
            points += len(plan.points)
        print(
            f"  inverse kinematics and timing: {seconds / points * 1e3:.2f} ms per IK point "
            f"({points / len(scenario.labels):.0f} points per motion)"
        )
    with tempfile.TemporaryDirectory() as out:
        start = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "bidmp", "sim", "--methods", "dmp,bidmp", "--out", out],
            check=True,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        print(
            f"  bidmp sim --methods dmp,bidmp (whole command, pictures included): {time.perf_counter() - start:.1f} s "
            f"(target <= 60 s on 2 cores)"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
