"""The LASA benchmark on 2 Dask workers against the serial path, interleaved, and Dask's per-task
overhead (issues #14, #24.6), in one run.

    make bench            # runs every script in benchmarks/ (this one takes about 10 minutes)
    .venv/bin/python benchmarks/bench_lasa.py [--rounds N] [--every K] [--out DIR]

The 30 shapes are cut into ``--rounds`` groups. Each round runs its group's cells (x 7
demonstrations, every method) once on the serial path (``synchronous=True``: in this process, no
Dask) and once on 2 Dask workers (the embedded LocalCluster ``bidmp benchmark lasa`` starts, here
started once before the rounds and stopped after them, both counted on its side), the order
alternating from round to round so that load drifting on the machine falls on both sides alike.
Prints each round's ratio, the total speed-up (target
>= 1.6x) and that the two tables agree; then submits 2000 empty tasks to a 2-worker cluster and
prints tasks/s. ``--rounds 1 --shapes 2`` is a quick look.
"""

from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

from bidmp.demonstrations.datasets import lasa_names
from bidmp.experiments import benchmark, lasa_cells


def _nothing(index: int) -> int:
    return index


def _one_side(out: Path, shapes, every: int, scheduler: str | None) -> benchmark.BenchmarkResult:
    if scheduler is None:
        return benchmark.lasa(out, shapes=shapes, every=every, synchronous=True)
    return benchmark.lasa(out, shapes=shapes, every=every, scheduler=scheduler)


def _strip(rows):
    return [{k: v for k, v in row.items() if k not in lasa_cells.TIMES} for row in rows]


def _rounds(out: Path, shapes, rounds: int, every: int) -> tuple[float, float, bool]:
    """Serial and 2-worker wall times summed over the rounds, and whether every table agreed."""
    from bidmp.experiments.benchmark import _client

    groups = [shapes[i::rounds] for i in range(rounds)]
    start = time.perf_counter()
    client, cluster = _client(None, 2)  # what lasa(workers=2) starts
    totals = {1: 0.0, 2: time.perf_counter() - start}
    identical = True
    try:
        for index, group in enumerate(groups):
            order = (1, 2) if index % 2 == 0 else (2, 1)
            runs = {
                workers: _one_side(
                    out / f"round{index}" / f"workers{workers}",
                    group,
                    every,
                    None if workers == 1 else cluster.scheduler_address,
                )
                for workers in order
            }
            for workers, run in runs.items():
                totals[workers] += run.wall_s
            identical &= _strip(runs[1].rows) == _strip(runs[2].rows)
            print(
                f"  round {index + 1}/{rounds} ({len(group)} shapes, "
                f"{'serial' if order[0] == 1 else '2 workers'} first): "
                f"serial {runs[1].wall_s:6.1f} s, 2 workers {runs[2].wall_s:6.1f} s, ratio "
                f"{runs[1].wall_s / runs[2].wall_s:.2f}x",
                flush=True,
            )
    finally:
        start = time.perf_counter()
        client.close()
        cluster.close()
        totals[2] += time.perf_counter() - start
    return totals[1], totals[2], identical


def _dask_overhead() -> float:
    from distributed import Client, LocalCluster

    with (
        LocalCluster(
            n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
        ) as cluster,
        Client(cluster) as client,
    ):
        client.gather(client.map(_nothing, range(100)))  # warm
        n = 2000
        start = time.perf_counter()
        client.gather(client.map(_nothing, range(n), pure=False))
        return n / (time.perf_counter() - start)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--every", type=int, default=1)
    parser.add_argument("--rounds", type=int, default=6)
    parser.add_argument(
        "--shapes", type=int, default=30, help="how many of the 30 shapes (default all)"
    )
    parser.add_argument("--out", default="bidmp-lasa-bench")
    args = parser.parse_args()
    out = Path(args.out)
    shutil.rmtree(out, ignore_errors=True)
    shapes = list(lasa_names())[: args.shapes]
    print(
        f"LASA, {len(shapes)} shapes x 7 demonstrations, every {args.every} sample(s), all methods; "
        f"serial path and 2 Dask workers interleaved in {args.rounds} round(s)",
        flush=True,
    )
    serial, parallel, identical = _rounds(out, shapes, args.rounds, args.every)
    print(f"  serial:    {serial:7.1f} s")
    print(
        f"  2 workers: {parallel:7.1f} s (cluster start and stop included)   speed-up "
        f"{serial / parallel:.2f}x (target >= 1.6x); tables identical: {identical}"
    )
    rate = _dask_overhead()
    print(
        f"  Dask overhead: {rate:.0f} empty tasks/s on 2 workers ({1e3 / rate:.2f} ms per task; a LASA cell "
        f"takes {serial / (7 * len(shapes)):.2f} s serially)"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
