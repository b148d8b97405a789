"""Every fit with the machine's default BLAS threads against the same fit on one thread (issue
#53: every fit as fast with the default threads as single-threaded), interleaved, in one run; with
``--load N``, N processes spinning beside it (a loaded machine, where idle BLAS threads that spin
steal the core the fit runs on).

    .venv/bin/python benchmarks/bench_threads.py [--rounds 15] [--load 1]

Prints each fit's median with default threads and on one thread (``threadpoolctl``, every loaded
pool limited to 1) and their ratio; target: default / one thread <= 1.1 for every fit.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import statistics
import time

import numpy as np
from threadpoolctl import threadpool_limits


def _spin(stop) -> None:  # a busy core
    while not stop.is_set():
        sum(range(10_000))


def _fits():
    from bidmp import DMP, BiDMP, CartesianDMP
    from bidmp.demonstrations import minimum_jerk
    from bidmp.primitives import MultiDMP, ProDMP, ProMP, RhythmicDMP

    t = np.linspace(0.0, 3.0, 1000)
    y = minimum_jerk([[-80, -120, 200], [0, 0, 40], [0, 0, 0]], 1000)
    y = y + 20.0 * np.sin(np.pi * t / 3.0)[:, None] ** 2
    demos = [y + k for k in range(5)]
    s = np.linspace(0, 1, 1000)[:, None]
    quats = np.column_stack(
        [np.sin(0.3 * s[:, 0]), np.zeros(1000), np.zeros(1000), np.cos(0.3 * s[:, 0])]
    )
    poses = np.hstack([y, quats])
    periodic_t = np.arange(2000) / 200.0
    periodic = np.column_stack(
        [np.sin(2 * np.pi * 1.3 * periodic_t), np.cos(2 * np.pi * 1.3 * periodic_t) ** 3]
    )
    dmp = DMP().fit(y, t, units="mm")
    return {
        "DMP (robot protocol)": lambda: DMP().fit(y, t, units="mm"),
        "DMP (paper protocol)": lambda: DMP(protocol="paper").fit(y, t),
        "CartesianDMP": lambda: CartesianDMP().fit(poses, t),
        "RhythmicDMP": lambda: RhythmicDMP().fit(periodic, periodic_t),
        "ProMP (5 demonstrations)": lambda: ProMP().fit(demos),
        "MultiDMP (5 demonstrations)": lambda: MultiDMP().fit(demos),
        "ProDMP (5 demonstrations)": lambda: ProDMP().fit(demos),
        "BiDMP learn (one skill)": lambda: BiDMP(dmp).learn(y + [30.0, 0.0, 0.0]),
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=15)
    parser.add_argument("--load", type=int, default=1, help="busy processes beside the run")
    args = parser.parse_args()
    stop = multiprocessing.Event()
    burners = [multiprocessing.Process(target=_spin, args=(stop,)) for _ in range(args.load)]
    for process in burners:
        process.start()
    try:
        fits = _fits()
        print(f"{os.cpu_count()} CPUs, {args.load} busy process(es); load {os.getloadavg()}")
        print(f"{'fit':30s} {'default ms':>11s} {'1 thread ms':>12s} {'ratio':>7s}")
        worst = 0.0
        for name, fit in fits.items():
            fit()
            samples = {"default": [], "one": []}
            for index in range(args.rounds):
                order = ("default", "one") if index % 2 == 0 else ("one", "default")
                for side in order:
                    if side == "one":
                        with threadpool_limits(1):  # set up outside the timing
                            began = time.perf_counter()
                            fit()
                            samples[side].append(time.perf_counter() - began)
                    else:
                        began = time.perf_counter()
                        fit()
                        samples[side].append(time.perf_counter() - began)
            default, one = (statistics.median(samples[k]) for k in ("default", "one"))
            worst = max(worst, default / one)
            print(f"{name:30s} {1e3 * default:11.2f} {1e3 * one:12.2f} {default / one:6.2f}x")
        print(f"worst default / one thread: {worst:.2f}x (target <= 1.1)")
    finally:
        stop.set()
        for process in burners:
            process.join()


if __name__ == "__main__":
    main()
