"""``bidmp-continual``'s capacity on the CLFD protocol's LASA tasks: the ridge memory of the tasks'
start maps (:class:`~bidmp.experiments.clfd.ContinualBLS`) at several node counts against the plain
library of the same maps (:class:`~bidmp.experiments.clfd.MapLibrary`).

Each cell runs the protocol (every task seen evaluated after each task, DTW against the protocol's
threshold) for one node count and seed, and reports ACC, BWT, the mean DTW over the 26 tasks after
the last, how far each stored map is from the map the task taught (‖given − taught‖ / ‖taught‖,
after the last task) and every number the method keeps, by part. ``tools/clfd_capacity.py`` (``make
clfd-capacity``) writes ``docs/results/clfd_capacity.json``, ``.md`` and ``.png``.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..._checks import check_int
from ..._progress import report
from .data import clfd_tasks
from .methods import ContinualBLS, MapLibrary
from .metrics import CLFD_THRESHOLDS, continual_metrics
from .protocol import _listed, _protocol_row

__all__ = ["CAPACITY_NODES", "CapacityResult", "CapacityRow", "capacity_sweep", "write_capacity"]

# The committed sweep's node counts: below, at and above LASA's 26 tasks (the default is 64)
CAPACITY_NODES = (8, 12, 16, 20, 24, 26, 32, 64)


@dataclass
class CapacityRow:
    """One cell: ``method`` ("bidmp-continual" with ``nodes`` and ``seed``, or "map-library"),
    its ACC and BWT by DTW, the mean DTW over the tasks seen after the last task, each task's
    stored-map error after the last task (relative, one per task) and every number it keeps by
    part (``numbers``)."""

    method: str
    nodes: int | None
    seed: int | None
    acc: float
    bwt: float
    mean_dtw: float
    map_errors: list = field(default_factory=list)
    numbers: dict = field(default_factory=dict)

    @property
    def kept(self) -> int:
        """Every number kept."""
        return int(sum(self.numbers.values()))

    @property
    def reproduced_from(self) -> int:
        """The numbers a reproduction reads (all but the normal equations)."""
        return self.kept - int(self.numbers.get("normal_equations", 0))

    def to_dict(self) -> dict:
        return {
            "method": self.method,
            "nodes": self.nodes,
            "seed": self.seed,
            "ACC": self.acc,
            "BWT": self.bwt,
            "mean_dtw": self.mean_dtw,
            "map_error_median": float(np.median(self.map_errors)),
            "map_error_max": float(np.max(self.map_errors)),
            "map_errors": [float(v) for v in self.map_errors],
            "numbers": {k: int(v) for k, v in self.numbers.items()},
            "reproduced_from": self.reproduced_from,
            "kept": self.kept,
        }


@dataclass
class CapacityResult:
    """The sweep: the tasks' names and one :class:`CapacityRow` per cell (the library's last)."""

    tasks: list
    rows: list

    @property
    def library(self) -> CapacityRow:
        return next(row for row in self.rows if row.method == MapLibrary.name)

    def by_nodes(self) -> dict[int, list[CapacityRow]]:
        """``bidmp-continual``'s rows per node count (every seed), in increasing node counts."""
        groups: dict[int, list[CapacityRow]] = {}
        for row in sorted(self.rows, key=lambda r: (r.nodes or 0, r.seed or 0)):
            if row.method == ContinualBLS.name:
                groups.setdefault(row.nodes, []).append(row)
        return groups

    def to_dict(self) -> dict:
        return {
            "dataset": "lasa",
            "tasks": self.tasks,
            "threshold_dtw": CLFD_THRESHOLDS["lasa"]["dtw"],
            "map_size": int(self.library.numbers["maps"] // len(self.tasks)),
            "rows": [row.to_dict() for row in self.rows],
        }

    def markdown(self) -> str:
        library = self.library
        lines = [
            f"CLFD protocol, LASA ({len(self.tasks)} tasks): "
            "`bidmp-continual` (a ridge memory of each task's start map: one-hot task code, "
            "`n_nodes` tanh nodes, linear output weights) at each node count against "
            "`map-library` (the same maps kept as they are). ACC by DTW (threshold "
            f"{CLFD_THRESHOLDS['lasa']['dtw']:g}); mean DTW over the tasks after the last; a "
            "stored map's error ‖given − taught‖ / ‖taught‖ after the last task (median and "
            "largest over the tasks); the numbers kept: weights (R, b, W: what a reproduction "
            "reads) and the normal equations (A, B: what learning the next task needs). Ranges "
            "are over the seeds of the nodes' draw. Produced by `make clfd-capacity` "
            "(`tools/clfd_capacity.py --workers 2 --out docs/results`).",
            "",
            "| method | nodes | seeds | ACC | BWT | mean DTW | stored map off: median | "
            "largest | weights | normal equations | every number kept | × the library |",
            "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|",
        ]
        for nodes, rows in self.by_nodes().items():
            weights = rows[0].reproduced_from
            normal = rows[0].numbers["normal_equations"]
            lines.append(
                f"| bidmp-continual | {nodes} | {len(rows)} | "
                f"{_span([r.acc for r in rows], '.3f')} | {_span([r.bwt for r in rows], '.3f')} | "
                f"{_span([r.mean_dtw for r in rows], '.0f')} | "
                f"{_span([100 * np.median(r.map_errors) for r in rows], '.1f')} % | "
                f"{_span([100 * np.max(r.map_errors) for r in rows], '.1f')} % | "
                f"{weights:,} | {normal:,} | {weights + normal:,} | "
                f"{(weights + normal) / library.kept:.2f} |"
            )
        lines.append(
            f"| map-library | - | - | {library.acc:.3f} | {library.bwt:.3f} | "
            f"{library.mean_dtw:.0f} | 0.0 % | 0.0 % | {library.kept:,} | - | {library.kept:,} | "
            "1.00 |"
        )
        return "\n".join(lines) + "\n"


def _span(values, spec: str) -> str:
    """``values`` printed with ``spec``: one number where they print alike, else min–max (min
    to max where one is negative)."""
    low, high = format(min(values), spec), format(max(values), spec)
    if low == high:
        return low
    return f"{low} to {high}" if min(values) < 0 else f"{low}–{high}"


def _capacity_cell(nodes: int | None, seed: int | None, n_tasks: int | None) -> CapacityRow:
    """The protocol on the first ``n_tasks`` LASA tasks for ``bidmp-continual`` with ``nodes``
    and ``seed``, or (``nodes`` None) for the map library."""
    tasks = clfd_tasks("lasa")[:n_tasks]
    if nodes is None:
        method, name = MapLibrary(), MapLibrary.name
    else:
        method, name = ContinualBLS(n_nodes=nodes, seed=seed), ContinualBLS.name
    threshold = CLFD_THRESHOLDS["lasa"]["dtw"]
    row = _protocol_row(method, tasks, {"dtw": threshold}, name, seed)
    figures = continual_metrics(row.matrices["dtw"], row.sizes, row.times)
    errors = []
    for index, task in enumerate(tasks):
        taught = method.task_target(task)
        errors.append(np.linalg.norm(method.task_map(index) - taught) / np.linalg.norm(taught))
    numbers = method.numbers_kept if nodes is not None else {"maps": method.n_parameters}
    return CapacityRow(
        name,
        nodes,
        seed,
        float(figures["ACC"]),
        float(figures["BWT"]),
        row.mean_dtw_seen[-1],
        errors,
        dict(numbers),
    )


def capacity_sweep(
    nodes=CAPACITY_NODES, seeds=(0, 1, 2), n_tasks: int | None = None, workers: int = 1
) -> CapacityResult:
    """``bidmp-continual`` on the CLFD protocol's LASA tasks (the first ``n_tasks``; default all
    26) at each node count of ``nodes`` with each seed of ``seeds`` (the draw of its nodes), and
    the map library once: one cell each, on an embedded Dask cluster of ``workers``
    single-threaded processes when ``workers`` > 1 (a full cell takes about 25 s of one core),
    else one after the other here."""
    nodes = [check_int(n, "nodes", minimum=1, maximum=100_000) for n in _listed(nodes, "nodes")]
    seeds = [check_int(s, "seeds", minimum=0, maximum=2**31) for s in _listed(seeds, "seeds")]
    if not nodes or not seeds:
        raise ValueError("nodes and seeds must each hold at least one value")
    tasks = clfd_tasks("lasa")
    if n_tasks is not None:
        n_tasks = check_int(n_tasks, "n_tasks", minimum=1, maximum=len(tasks))
    workers = check_int(workers, "workers", minimum=1, maximum=256)
    cells = [(n, s) for n in nodes for s in seeds] + [(None, None)]
    if workers > 1:
        from .._lasa_dask import _client

        client, cluster = _client(None, workers)
        try:
            futures = [client.submit(_capacity_cell, n, s, n_tasks, pure=False) for n, s in cells]
            rows = []
            for done, future in enumerate(futures, start=1):
                rows.append(future.result())
                report("CLFD capacity cells", done, len(futures))
        finally:
            client.close()
            if cluster is not None:
                cluster.close()
    else:
        rows = [_capacity_cell(n, s, n_tasks) for n, s in cells]
    return CapacityResult([task.name for task in tasks[:n_tasks]], rows)


def write_capacity(result: CapacityResult, out) -> list[Path]:
    """``clfd_capacity.json``, ``clfd_capacity.md`` and ``clfd_capacity.png`` (ACC and the
    stored maps' error against the node count; the numbers kept against it, the library's
    marked) in the folder ``out`` (written atomically)."""
    from ...io.atomic import atomic_write
    from ...plotting.clfd import plot_clfd_capacity

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = [out / "clfd_capacity.json", out / "clfd_capacity.md"]
    texts = (json.dumps(result.to_dict(), indent=1) + "\n", result.markdown())
    for path, text in zip(written, texts):
        with atomic_write(path, "w") as handle:
            handle.write(text)
    return [*written, plot_clfd_capacity(out / "clfd_capacity.png", result)]
