"""What a short call costs warm and after other work: why the robot protocol's fit + trajectory is
0.4-0.7 ms alone but 1.2-1.6 ms interleaved with movement_primitives (benchmarks/bench_dmp.py).

    .venv/bin/python benchmarks/bench_cold.py [--rounds N]

Each call is timed right after 20 ms of something else: nothing (warm), a Python busy loop (the
same thread kept busy, no data), a sleep, NumPy over 8 MB (the caches flushed), and
movement_primitives' fit + open loop (what bench_dmp interleaves). The control is a chain of 300
NumPy calls that repeats one operation on 24 kB: it is as long as a fit but touches few distinct
code paths. Printed: each call's median and its ratio to warm. What the numbers say: the penalty
follows the number of distinct operations a call runs (every one of them pays a few µs cold),
not the data it reads (the same at T = 100 as at T = 1000).
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

import numpy as np

from bidmp import DMP
from bidmp.demonstrations import minimum_jerk


def demonstration(n_samples: int) -> tuple[np.ndarray, np.ndarray]:
    t = np.linspace(0.0, 2.0, n_samples)
    y = minimum_jerk(np.array([[-80.0, -120.0, 200.0], [0.0, 0.0, 0.0]]), n_samples)
    return y + 30.0 * np.sin(np.pi * t / 2.0)[:, None] ** 2, t


def spin(seconds: float = 0.02) -> None:
    start = time.perf_counter()
    while time.perf_counter() - start < seconds:
        pass


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=60)
    args = parser.parse_args()
    big = np.random.default_rng(0).random(1_000_000)
    before = {
        "warm": lambda: None,
        "spin 20 ms": spin,
        "sleep 20 ms": lambda: time.sleep(0.02),
        "NumPy over 8 MB": lambda: [np.sin(big) for _ in range(3)],
    }
    try:
        from movement_primitives.dmp import DMP as PeerDMP
    except ImportError:  # pragma: no cover - optional peer
        PeerDMP = None
    small = np.random.default_rng(1).random(3000)

    def chain() -> float:
        total = 0.0
        for _ in range(300):
            total += float(np.sum(small * 2.0 + 1.0))
        return total

    print(f"load {os.getloadavg()}; median of {args.rounds} calls, each after the named work")
    for n_samples in (100, 1000):
        y, t = demonstration(n_samples)
        if PeerDMP is not None:

            def peer(y=y, t=t, n_samples=n_samples):
                dmp = PeerDMP(n_dims=3, execution_time=t[-1], dt=t[1], n_weights_per_dim=100)
                dmp.imitate(t, y)
                dmp.configure(start_y=y[0], goal_y=y[-1])
                dmp.open_loop(step_function="euler-cython")

            before["movement_primitives fit+open_loop"] = peer
        calls = {
            f"DMP().fit(y, t).trajectory(), T = {n_samples}": lambda y=y, t=t: (
                DMP().fit(y, t).trajectory()
            ),
            "control: 300 NumPy calls of one operation": chain,
        }
        for label, call in calls.items():
            call()
            warm = None
            print(f"\n  {label}")
            for name, work in before.items():
                samples = []
                for _ in range(args.rounds):
                    work()
                    start = time.perf_counter()
                    call()
                    samples.append(time.perf_counter() - start)
                median = statistics.median(samples)
                warm = median if warm is None else warm
                print(f"    after {name:36s} {1e3 * median:7.3f} ms  {median / warm:5.2f}x warm")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
