"""The protocol's runner: cells (method × seed) run serially or on a Dask cluster, each learning
the tasks one after the other and evaluating every task seen after each; the results, their
tables and their files."""

from __future__ import annotations

import inspect
import json
import logging
import time
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..._checks import check_choice, check_int, short_token
from ..._progress import report
from .data import ClfdTask, clfd_tasks
from .methods import METHODS
from .metrics import CLFD_THRESHOLDS, accuracy_matrix, continual_metrics, demonstration_errors

__all__ = ["ClfdResult", "ClfdRow", "run_clfd", "write_clfd"]

logger = logging.getLogger(__name__)

# The smallest of the published hypernetworks (Auddy et al.: 1.8-4.3 M parameters): the models
# compared for FS include it, as the field's tables do
PUBLISHED_HYPERNETWORK_PARAMETERS = 1_800_000
# The published best's figures (read from the authors' figures, about ±5 %): LASA's mean DTW
# over the tasks seen after all 26 tasks; RoboTasks9's position DTW and orientation medians
PUBLISHED_BEST = {
    "lasa": {"mean_dtw": 1.7e3},
    "robottasks": {"median_dtw": 1.8e3, "median_orientation": 0.045},
}
PUBLISHED_BEST_MEAN_DTW = PUBLISHED_BEST["lasa"]["mean_dtw"]


@dataclass
class ClfdRow:
    """One cell's run (a method, a seed): ``errors[metric][i][j]`` (M,) per demonstration of task
    j after task i, the accuracy matrices of the metrics with a threshold, the figures (per
    metric), the sizes (parameters) and training times (s, one core) per task."""

    method: str
    seed: int | None = None
    errors: dict = field(default_factory=dict)
    matrices: dict = field(default_factory=dict)
    metrics: dict = field(default_factory=dict)
    sizes: list = field(default_factory=list)
    times: list = field(default_factory=list)

    @property
    def mean_dtw_seen(self) -> list[float]:
        """After each task i, the mean over the tasks seen of their mean DTW."""
        return [float(np.mean([np.mean(e) for e in seen])) for seen in self.errors["dtw"]]

    @property
    def medians(self) -> dict[str, float]:
        """Each metric's median over every demonstration of every task after the last task."""
        return {name: float(np.median(np.concatenate(e[-1]))) for name, e in self.errors.items()}

    def to_dict(self) -> dict:
        return {
            "method": self.method,
            "seed": self.seed,
            "metrics": self.metrics,
            "accuracy_matrices": {
                name: [[None if np.isnan(v) else float(v) for v in row] for row in matrix]
                for name, matrix in self.matrices.items()
            },
            "mean_dtw_over_tasks_seen": self.mean_dtw_seen,
            "medians_after_last_task": self.medians,
            "model_size": [int(v) for v in self.sizes],
            "training_time_s": [float(v) for v in self.times],
        }


@dataclass
class ClfdResult:
    """The protocol's outcome: the dataset, its task names, one :class:`ClfdRow` per method (its
    first seed's) and every seed's rows per method (``seed_rows``)."""

    dataset: str
    tasks: list
    rows: dict
    seed_rows: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        return {
            "dataset": self.dataset,
            "tasks": self.tasks,
            "thresholds": CLFD_THRESHOLDS[self.dataset],
            "published_best": PUBLISHED_BEST[self.dataset],
            "methods": {name: row.to_dict() for name, row in self.rows.items()},
            "seeds": {
                name: [{"seed": r.seed, "metrics": r.metrics, "medians": r.medians} for r in runs]
                for name, runs in self.seed_rows.items()
                if len(runs) > 1
            },
        }

    def markdown(self) -> str:
        pose = self.dataset == "robottasks"
        threshold = CLFD_THRESHOLDS[self.dataset]["dtw"]
        extra = (
            ("median DTW", "median orientation (rad)", "ACC orientation")
            if pose
            else ("ACC Fréchet", "ACC area")
        )
        lines = [
            f"# Continual learning from demonstration: CLFD protocol, {self.dataset} "
            f"({len(self.tasks)} tasks)",
            "",
            f"Accuracy by DTW (threshold {threshold:g}); mean DTW over the tasks seen after the "
            "last task; FS against the largest model compared, at least the published "
            f"hypernetwork's {PUBLISHED_HYPERNETWORK_PARAMETERS:,} parameters.",
            "",
            "| method | ACC | BWT | REM | MS | TE | FS | CL_score | CL_stability | mean DTW | "
            + " | ".join(extra)
            + " |",
            "|---|" + "---:|" * (9 + len(extra)),
        ]
        for name, row in self.rows.items():
            m = row.metrics["dtw"]
            cells = [m[key] for key in ("ACC", "BWT", "REM", "MS", "TE", "FS")]
            cells += [m["CL_score"], m["CL_stability"]]
            text = " | ".join(f"{v:.3f}" for v in cells)
            if pose:
                tail = (
                    f"{row.medians['dtw']:.0f} | {row.medians['orientation']:.4f} | "
                    f"{row.metrics['orientation']['ACC']:.3f}"
                )
            else:
                tail = f"{row.metrics['frechet']['ACC']:.3f} | {row.metrics['area']['ACC']:.3f}"
            lines.append(f"| {name} | {text} | {row.mean_dtw_seen[-1]:.0f} | {tail} |")
        published = ", ".join(f"{k} {v:g}" for k, v in PUBLISHED_BEST[self.dataset].items())
        lines += ["", f"Published best (hypernetwork): {published}."]
        spread = {name: runs for name, runs in self.seed_rows.items() if len(runs) > 1}
        if spread:
            lines += [
                "",
                "| method | seeds | CL_score min–max | mean DTW min–max |",
                "|---|---:|---:|---:|",
            ]
            for name, runs in spread.items():
                scores = [r.metrics["dtw"]["CL_score"] for r in runs]
                dtw = [r.mean_dtw_seen[-1] for r in runs]
                lines.append(
                    f"| {name} | {len(runs)} | {min(scores):.4f}–{max(scores):.4f} | "
                    f"{min(dtw):.1f}–{max(dtw):.1f} |"
                )
        return "\n".join(lines) + "\n"


def _seeded(name: str) -> bool:
    return "seed" in inspect.signature(METHODS[name]).parameters


def run_clfd(  # noqa: PLR0913 - the protocol's knobs, each one a command-line option
    dataset: str = "lasa",
    methods=("dmp-library",),
    n_tasks: int | None = None,
    seeds=(0,),
    workers: int = 1,
) -> ClfdResult:
    """The protocol for each of ``methods`` (names of :data:`METHODS`) on the first ``n_tasks``
    tasks of ``dataset`` (default all): one cell per method and seed of ``seeds`` (a method
    without a seed: one cell). With ``workers`` > 1 and more than one cell, the cells run on an
    embedded Dask cluster of that many single-threaded processes (a LASA cell takes about 25 s,
    the cluster about 2 s to start); otherwise one after the other here."""
    check_choice(dataset, "dataset", tuple(CLFD_THRESHOLDS))
    tasks = clfd_tasks(dataset)
    if n_tasks is not None:
        n_tasks = check_int(n_tasks, "n_tasks", minimum=1, maximum=len(tasks))
    workers = check_int(workers, "workers", minimum=1, maximum=256)
    seeds = [check_int(s, "seeds", minimum=0, maximum=2**31) for s in _listed(seeds, "seeds")]
    if not seeds:
        raise ValueError("seeds must hold at least one seed")
    methods = _listed(methods, "methods")
    for name in methods:
        check_choice(name, "methods", tuple(METHODS))
    cells = [(name, s) for name in methods for s in (seeds if _seeded(name) else [None])]
    if workers > 1 and len(cells) > 1:
        runs = _run_on_dask(dataset, cells, n_tasks, workers)
    else:
        runs = [_run_cell(dataset, name, seed, n_tasks, tasks) for name, seed in cells]
    largest = max([PUBLISHED_HYPERNETWORK_PARAMETERS] + [row.sizes[-1] for row in runs])
    for row in runs:
        row.metrics = {
            metric: continual_metrics(matrix, row.sizes, row.times, largest)
            for metric, matrix in row.matrices.items()
        }
    seed_rows: dict = {}
    for row in runs:
        seed_rows.setdefault(row.method, []).append(row)
    rows = {name: runs[0] for name, runs in seed_rows.items()}
    names = [task.name for task in tasks[:n_tasks]]
    return ClfdResult(dataset, names, rows, seed_rows)


def _listed(values, name: str) -> list:
    """``values`` as a list: a sequence (list, tuple, range) or 1-D array of them (a scalar, or
    one method's name as a string, is refused: one cell's value where the list of cells goes)."""
    if isinstance(values, np.ndarray) and values.ndim == 1:
        values = values.tolist()
    if isinstance(values, (str, bytes)) or not isinstance(values, Sequence):
        shown = f"{type(values).__name__} {short_token(values)}"
        raise TypeError(f"{name} must be a list (one cell per entry), got {shown}")
    if len(values) > 1000:
        raise ValueError(f"{name} holds {len(values):,} entries, more than 1000 cells")
    return list(values)


def _run_cell(
    dataset: str,
    name: str,
    seed: int | None,
    n_tasks: int | None,
    tasks: list[ClfdTask] | None = None,
) -> ClfdRow:
    """One cell: method ``name`` (with ``seed``) through the first ``n_tasks`` tasks."""
    tasks = (tasks if tasks is not None else clfd_tasks(dataset))[:n_tasks]
    method = METHODS[name]() if seed is None else METHODS[name](seed=seed)
    return _protocol_row(method, tasks, CLFD_THRESHOLDS[dataset], name, seed)


def _protocol_row(method, tasks: list[ClfdTask], thresholds: dict, name: str, seed) -> ClfdRow:
    """``method`` (a fresh instance) through ``tasks`` one after the other, every task seen
    evaluated by each metric of ``thresholds`` (name -> threshold or None) after each."""
    row = ClfdRow(name, seed, errors={metric: [] for metric in thresholds})
    for i, task in enumerate(tasks):
        began = time.process_time()  # one core's time: the protocol's training time per task
        method.learn(task)
        row.times.append(time.process_time() - began)
        row.sizes.append(method.n_parameters)
        seen = {metric: [] for metric in thresholds}
        for j, earlier in enumerate(tasks[: i + 1]):
            poses = earlier.poses
            reproduced = method.reproduce(j, poses[:, 0], earlier.times[0])
            for metric, values in demonstration_errors(reproduced, poses, thresholds).items():
                seen[metric].append(values)
        for metric in thresholds:
            row.errors[metric].append(seen[metric])
        report(f"CLFD {name}", i + 1, len(tasks))
    row.matrices = {
        metric: accuracy_matrix(row.errors[metric], limit)
        for metric, limit in thresholds.items()
        if limit is not None
    }
    return row


def _run_on_dask(dataset: str, cells: list, n_tasks: int | None, workers: int) -> list[ClfdRow]:
    """The cells on an embedded Dask cluster (the LASA benchmark's), in the cells' order."""
    from .._lasa_dask import _client

    client, cluster = _client(None, workers)
    try:
        futures = [
            client.submit(_run_cell, dataset, name, seed, n_tasks, pure=False)
            for name, seed in cells
        ]
        rows = []
        for done, future in enumerate(futures, start=1):
            rows.append(future.result())
            report("CLFD cells", done, len(futures))
        return rows
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


def write_clfd(result: ClfdResult, out) -> list[Path]:
    """``clfd.json``, ``clfd.md`` and the figures (``clfd_accuracy.png``: the accuracy matrices
    as heat maps; ``clfd_dtw.png``: the mean DTW over the tasks seen against the task index,
    the published best marked) in the folder ``out`` (written atomically). A RoboTasks9 run's
    files are named ``clfd_robottasks*``."""
    from ...io.atomic import atomic_write
    from ...plotting.clfd import plot_clfd

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    stem = "clfd" if result.dataset == "lasa" else f"clfd_{result.dataset}"
    written = [out / f"{stem}.json", out / f"{stem}.md"]
    for path, text in zip(
        written, (json.dumps(result.to_dict(), indent=1) + "\n", result.markdown())
    ):
        with atomic_write(path, "w") as handle:
            handle.write(text)
    # the published LASA figure is after all 26 tasks: marked only on a run of them all
    full_lasa = result.dataset == "lasa" and len(result.tasks) == 26
    reference = PUBLISHED_BEST_MEAN_DTW if full_lasa else None
    return written + plot_clfd(out, result.rows, reference, stem=stem)
