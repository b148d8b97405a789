"""The whole CLFD protocol on LASA for every row (issue #52: at most 10 minutes on 2 cores; every
row's training at most 1 s per task on one core), on 2 Dask workers and serially, in one run.

    .venv/bin/python benchmarks/bench_clfd.py [--tasks N] [--sides dask,serial]

The two sides run one after the other (Dask first, then serial) and must give the same figures;
prints each side's wall time, their ratio, the machine's load before and after, and each row's
largest training time per task (process time: one core). ``--tasks 3`` is a quick look.
"""

from __future__ import annotations

import argparse
import os
import time

from bidmp.experiments.clfd import METHODS, run_clfd


def _side(workers: int, n_tasks: int | None):
    start = time.perf_counter()
    result = run_clfd("lasa", list(METHODS), n_tasks=n_tasks, workers=workers)
    return result, time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--tasks", type=int, default=None, help="only the first N tasks")
    parser.add_argument("--sides", default="dask,serial", help="dask, serial or both")
    args = parser.parse_args()
    sides = [s.strip() for s in args.sides.split(",") if s.strip()]
    print(f"load average before: {os.getloadavg()}; {os.cpu_count()} CPUs")
    walls, results = {}, {}
    for side in sides:
        results[side], walls[side] = _side(2 if side == "dask" else 1, args.tasks)
        print(f"{side}: every row ({len(METHODS)}) through the protocol in {walls[side]:.1f} s")
    print(f"load average after: {os.getloadavg()}")
    if len(walls) == 2:
        print(f"serial / dask: {walls['serial'] / walls['dask']:.2f}x")
        a, b = (results[s].rows for s in ("dask", "serial"))
        same = all(
            abs(a[n].mean_dtw_seen[-1] - b[n].mean_dtw_seen[-1]) <= 1e-9 * b[n].mean_dtw_seen[-1]
            for n in a
        )
        print(f"the two sides' mean DTW agree to 1e-9: {same}")
    any_result = next(iter(results.values()))
    for name, row in any_result.rows.items():
        print(f"  {name}: training at most {max(row.times) * 1e3:.1f} ms per task (one core)")
    limit = 600.0
    side = "dask" if "dask" in walls else "serial"  # the 2-worker side, else the serial one
    print(
        f"target: the whole protocol within {limit:.0f} s on 2 cores ({side}): {walls[side] <= limit}"
    )


if __name__ == "__main__":
    main()
