"""bidmp-continual's capacity on the CLFD protocol's 26 LASA tasks: the node counts of
:data:`bidmp.experiments.clfd.CAPACITY_NODES` (8-64), three seeds each, against the plain library
of the same start maps — ACC, BWT, mean DTW, how far each stored map is from its task's and every
number kept (``bidmp.experiments.clfd.capacity_sweep``).

    .venv/bin/python tools/clfd_capacity.py [--nodes 8,12,...] [--seeds 3] [--tasks N]
                                            [--workers 2] [--out docs/results]

Writes clfd_capacity.json, clfd_capacity.md and clfd_capacity.png into ``--out`` (make
clfd-capacity: docs/results/) and prints the table and the wall time.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

from bidmp.experiments.clfd import CAPACITY_NODES, capacity_sweep, write_capacity

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--nodes", default=",".join(map(str, CAPACITY_NODES)))
    parser.add_argument("--seeds", type=int, default=3, help="seeds 0..N-1 (default 3)")
    parser.add_argument("--tasks", type=int, default=None, help="only the first N tasks")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "results")
    args = parser.parse_args()
    nodes = [int(n) for n in args.nodes.split(",") if n.strip()]
    started = time.perf_counter()
    result = capacity_sweep(nodes, range(args.seeds), n_tasks=args.tasks, workers=args.workers)
    write_capacity(result, args.out)
    print(result.markdown())
    print(
        f"{len(result.rows)} cells on {args.workers} worker(s) in {time.perf_counter() - started:.0f} s"
    )


if __name__ == "__main__":
    main()
