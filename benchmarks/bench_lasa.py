"""The full LASA benchmark on Dask: 2 workers vs 1 on this 2-core machine, and Dask's per-task
overhead (issue #14), in one run.

    make bench            # runs every script in benchmarks/ (this one takes about 12 minutes)
    .venv/bin/python benchmarks/bench_lasa.py [--every K] [--out DIR]

Runs `bidmp.benchmark.lasa` on all 30 shapes x 7 demonstrations with every method, first on an
embedded LocalCluster with 1 worker, then with 2, and prints the speed-up (target >= 1.6x) and
that the two tables agree. Then submits 2000 empty tasks to a 2-worker cluster and prints
tasks/s. The 2-worker run's Markdown summary is left in DIR/lasa.md (default bidmp-lasa-bench).
"""

from __future__ import annotations

import argparse
import shutil
import time
from pathlib import Path

from bidmp import benchmark


def _nothing(index: int) -> int:
    return index


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--every", type=int, default=1)
    parser.add_argument("--out", default="bidmp-lasa-bench")
    args = parser.parse_args()
    out = Path(args.out)
    shutil.rmtree(out, ignore_errors=True)
    runs = {}
    for workers in (1, 2):
        # workers=1 still goes through a 1-worker LocalCluster, so both runs pay Dask's costs.
        runs[workers] = benchmark.lasa(out / f"workers{workers}", workers=workers, every=args.every, dask=True)
    ones, twos = runs[1], runs[2]
    strip = lambda rows: [{k: v for k, v in r.items() if k not in benchmark.TIMES} for r in rows]  # noqa: E731
    cells = len(ones.computed)
    print(f"LASA, {cells} cells (30 shapes x 7 demonstrations), every {args.every} sample(s), all methods")
    print(f"  1 worker:  {ones.wall_s:7.1f} s")
    print(f"  2 workers: {twos.wall_s:7.1f} s   speed-up {ones.wall_s / twos.wall_s:.2f}x (target >= 1.6x); "
          f"tables identical: {strip(ones.rows) == strip(twos.rows)}")
    shutil.copy(out / "workers2" / "lasa.md", out / "lasa.md")

    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster, \
            Client(cluster) as client:
        client.gather(client.map(_nothing, range(100)))  # warm
        n = 2000
        start = time.perf_counter()
        client.gather(client.map(_nothing, range(n), pure=False))
        rate = n / (time.perf_counter() - start)
    print(f"  Dask overhead: {rate:.0f} empty tasks/s on 2 workers ({1e3 / rate:.2f} ms per task; a LASA cell "
          f"takes {twos.wall_s * 2 / cells:.2f} s of worker time)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
