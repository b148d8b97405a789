"""The LASA handwriting benchmark with the LfD literature's metrics, swept on Dask.

``lasa(out, ...)`` evaluates every method on every (shape, demonstration) cell of the LASA set:
the reproduction of the demonstration, and generalisation to two shifted goals. ``near`` moves
the goal by 10 % of the shape's extent, inside the plain DMP's reach; ``far`` moves it by 60 %,
beyond it. The direction comes from the cell's seed. Metrics per (cell, method, case):

* ``rmse``: time-aligned RMSE against the reference (the demonstration, or for a shifted goal the
  demonstration with the goal offset blended in linearly over time, so that it starts where the
  demonstration starts and ends at the new goal);
* ``dtw`` and ``dtw_per_sample``: DTW distance (:func:`bidmp.extension.similarity.dtw_distance`), raw and
  divided by the reference's length;
* ``swept_area``: CLF-DM's swept error area (:func:`bidmp.tasks.metrics.swept_area`);
* ``frechet``: discrete Fréchet distance;
* ``endpoint_error``: to the (shifted) goal;
* ``fit_s`` and ``rollout_s``: wall times, which are not reproducible.

The protocol is explicit and recorded with every row: ``demos`` ("all" 7 or "first3"), ``every``
(use every k-th sample: 1 or 10, as papers do).

**Dask.** The sweep is one task per cell. The default is an embedded ``distributed.LocalCluster``
with one single-threaded worker process per core, started and stopped here. ``scheduler=ADDRESS``
runs on an existing cluster instead. Each finished cell is written at once to
``cells/<shape>__<demo>.json`` (atomically), so a partial run is kept. ``resume=True`` skips the
cells already written with the same protocol. Seeds come from the cell's key, so results do not
depend on scheduling. The final table (``lasa.parquet``, or ``lasa.csv``), ``lasa.md`` (median
and IQR per method and case) and the figures are written only when every cell is done.

Needs the ``benchmark`` extra (dask[distributed], pyarrow): ``pip install 'bidmp[benchmark]'``.
"""

from __future__ import annotations

import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._checks import check_choice, check_int, require_extra, short_token
from ._lasa_dask import _client, _run_on_dask  # noqa: F401  (_client: the benchmark script's cluster)
from .lasa_cells import (
    CASES,
    METRICS,
    TIMES,
    _cell_path,
    _load_cell,
    _methods_available,
    _write_cell,
    cell_key,
    run_cell,
)

__all__ = ["lasa", "check_lasa_options", "BenchmarkResult", "summary_rows", "summary_markdown"]

logger = logging.getLogger(__name__)


# ---------------------------------------------------------------------------------------------
# The sweep
# ---------------------------------------------------------------------------------------------
@dataclass
class BenchmarkResult:
    """What :func:`lasa` did: the tidy rows, the cells computed now and those resumed."""

    rows: list
    protocol: dict
    computed: list = field(default_factory=list)
    resumed: list = field(default_factory=list)
    written: list = field(default_factory=list)
    wall_s: float = 0.0
    workers: int = 0


def check_lasa_options(shapes, methods, demos: str, every: int) -> tuple[list, list, list]:
    """The LASA benchmark's options checked before anything starts (a cluster, a sweep): the
    shapes, the methods, which demonstrations and every k-th sample; returns (shapes, the methods
    available here, the demonstrations' indices). Refuses an unknown shape or method by name."""
    from ..demonstrations.datasets import lasa_names

    names = lasa_names()
    for given, what in ((shapes, "shapes"), (methods, "methods")):
        if given is None:
            continue
        if not isinstance(given, (list, tuple)):
            raise TypeError(f"{what} must be a list of names, got {type(given).__name__}")
        if not list(given):
            raise ValueError(f"{what} names none; give at least one (or None for all)")
        if not all(isinstance(name, str) for name in given):
            raise TypeError(f"{what} must be a list of names (strings)")
    shapes = names if shapes is None else list(shapes)
    for shape in shapes:
        if shape not in names:
            raise ValueError(f"shapes: unknown LASA shape {shape!r}; see 'bidmp lasa list'")
    from ..tasks import methods as registry

    methods = list(registry.names(lasa=True) if methods is None else methods)
    for method in methods:
        try:
            registry.get(method)  # an unknown name is refused, listing the known ones
        except ValueError as exc:
            raise ValueError(f"methods: {exc}") from None
    check_choice(demos, "demos", ("all", "first3"))
    every = check_int(every, "every", minimum=1, maximum=100)
    indices = list(range(7)) if demos == "all" else [0, 1, 2]
    return shapes, _methods_available(methods), indices


def lasa(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    out,
    *,
    shapes=None,
    methods=None,
    demos: str = "all",
    every: int = 1,
    workers: int | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    output_format: str = "parquet",
    progress=None,
    synchronous: bool = False,
    dask: bool = False,
    _kill_once: str | None = None,
) -> BenchmarkResult:
    """Run the LASA benchmark into folder ``out``.

    Parameters
    ----------
    shapes : list of str, optional
        Default all 30.
    methods : list of str, optional
        Names in the methods registry (:mod:`bidmp.tasks.methods`); default those marked for
        LASA, :data:`LASA_METHODS` (``mp-dmp`` needs movement_primitives).
    demos : {"all", "first3"}
    every : int
        Use every k-th sample (1 or 10 in the literature).
    workers : int, optional
        Worker processes of the embedded cluster (default: one per core).
    scheduler : str, optional
        Address of an existing Dask scheduler (``tcp://host:8786``) instead.
    resume : bool
        Skip cells already in ``out/cells`` for this protocol.
    output_format : {"parquet", "csv"}
    synchronous : bool
        Run the cells in this process, one after another (no Dask): the serial reference; also
        what ``workers=1`` does unless ``dask`` is true.
    dask : bool
        Use a LocalCluster even for ``workers=1`` (to time Dask against itself).
    progress : callable, optional
        Called with the cell key as each cell finishes.
    """
    shapes, methods, indices = check_lasa_options(shapes, methods, demos, every)
    check_choice(output_format, "output_format", ("parquet", "csv"))
    out = Path(out)
    if out.exists() and not out.is_dir():
        raise ValueError(f"out {out} exists and is not a folder")
    protocol = {
        "demos": demos,
        "every": every,
        "methods": methods,
        "cases": [list(c) for c in CASES],
    }
    cells = [(shape, demo) for shape in shapes for demo in indices]
    done, todo = _resumed(out, protocol, cells) if resume else ({}, list(cells))
    result = BenchmarkResult(
        [], protocol, computed=[cell_key(*c) for c in todo], resumed=sorted(done)
    )
    out.mkdir(parents=True, exist_ok=True)
    start = time.perf_counter()
    if todo and (synchronous or workers == 1 and scheduler is None and not dask):
        result.workers = _run_here(todo, methods, every, out, protocol, done, progress)
    elif todo:
        result.workers = _run_on_dask(
            todo, (methods, every, out, protocol), (workers, scheduler), _kill_once, done, progress
        )
    result.wall_s = time.perf_counter() - start
    # The table: every row of every cell in a fixed order (shape, demo, method, case).
    order = {cell_key(*c): i for i, c in enumerate(cells)}
    rows = [row for key in sorted(done, key=order.get) for row in done[key]["rows"]]
    for row in rows:
        row.update({"demos": demos, "every": every})
    result.rows = rows
    table = _write_tables(out, rows, protocol, output_format)
    from ..plotting import plot_lasa_benchmark

    result.written = [table, out / "lasa.md"] + plot_lasa_benchmark(out, rows, done, shapes)
    return result


def _resumed(out: Path, protocol: dict, cells) -> tuple[dict, list]:
    """The cells already computed for this protocol (``{key: cell}``, read back and checked) and
    those still to compute."""
    loaded = {cell_key(*c): _load_cell(_cell_path(out, cell_key(*c)), protocol, *c) for c in cells}
    return {key: cell for key, cell in loaded.items() if cell is not None}, [
        c for c in cells if loaded[cell_key(*c)] is None
    ]


def _run_here(todo, methods, every, out, protocol, done, progress) -> int:
    """Run the cells in this process, one after another, each written as it finishes; 1 worker."""
    for shape, demo in todo:
        cell = run_cell(shape, demo, methods, every)
        _write_cell(out, protocol, cell)
        done[cell["key"]] = cell
        if progress is not None:
            progress(cell["key"])
    return 1


def _write_tables(out: Path, rows: list, protocol: dict, output_format: str) -> Path:
    """Write the table (Parquet or CSV) and its Markdown summary; return the table's path."""
    from ..io.atomic import atomic_write

    table = out / ("lasa.parquet" if output_format == "parquet" else "lasa.csv")
    _write_table(rows, table, output_format)
    with atomic_write(out / "lasa.md", "w") as handle:
        handle.write(summary_markdown(rows, protocol) + "\n")
    return table


_COLUMNS = (
    "shape",
    "demo",
    "method",
    "case",
    "seed",
    "goal_x",
    "goal_y",
    *METRICS,
    *TIMES,
    "demos",
    "every",
)


def _write_table(rows: list, path: Path, output_format: str) -> None:
    from ..io.atomic import atomic_write

    columns = {name: [row[name] for row in rows] for name in _COLUMNS}
    if output_format == "csv":
        import csv

        with atomic_write(path, "w") as handle:
            writer = csv.writer(handle, lineterminator="\n")
            writer.writerow(_COLUMNS)
            writer.writerows(zip(*(columns[name] for name in _COLUMNS)))
        return
    require_extra("pyarrow", "benchmark", "Parquet output (or use --format csv)")
    import pyarrow as pa
    import pyarrow.parquet as pq

    with atomic_write(path, "wb") as handle:
        pq.write_table(pa.Table.from_pydict(columns), handle)


def _checked_rows(rows) -> list:
    """The benchmark's rows (dicts with shape, demo, method, case and the metrics), checked."""
    if not isinstance(rows, (list, tuple)):
        raise TypeError(f"rows must be a list of the benchmark's rows, got {type(rows).__name__}")
    needed = {"shape", "demo", "method", "case", *METRICS}
    for index, row in enumerate(rows):
        if not isinstance(row, dict) or not needed <= set(row):
            raise TypeError(
                f"rows[{index}] must be one of the benchmark's rows (a dict with {', '.join(sorted(needed))})"
            )
    return list(rows)


def summary_rows(rows: list, metric: str) -> tuple[list[str], list[list[str]]]:
    """Median (IQR) of ``metric`` per method (rows) and case (columns)."""
    rows = _checked_rows(rows)
    metric = check_choice(metric, "metric", METRICS)
    methods = list(dict.fromkeys(row["method"] for row in rows))
    header = ["method"] + [name for name, _ in CASES]
    table = []
    for method in methods:
        cells = [method]
        for case, _ in CASES:
            values = np.array(
                [row[metric] for row in rows if row["method"] == method and row["case"] == case]
            )
            if values.size == 0:
                cells.append("-")
                continue
            q1, median, q3 = np.percentile(values, [25, 50, 75])
            cells.append(f"{median:.3g} ({q1:.3g}-{q3:.3g})")
        table.append(cells)
    return header, table


def summary_markdown(rows: list, protocol: dict) -> str:
    """The benchmark's Markdown summary (medians and ranges per method and case) from its rows."""
    from ..tasks._tables import markdown_table

    rows = _checked_rows(rows)
    if not isinstance(protocol, dict) or not {"demos", "every"} <= set(protocol):
        raise TypeError(
            f"protocol must be the benchmark's protocol (a dict with demos and every), got "
            f"{short_token(protocol, 30)}"
        )
    n_cells = len({(row["shape"], row["demo"]) for row in rows})
    parts = [
        f"LASA benchmark: {n_cells} cells (shape x demonstration), demos {protocol['demos']}, every "
        f"{protocol['every']} sample(s); median (IQR) per method; goal shifted by 0, 10 % and 60 % of the "
        f"shape's extent (reproduction, near, far)."
    ]
    for metric in ("rmse", "dtw_per_sample", "swept_area", "frechet", "endpoint_error"):
        parts.append(f"**{metric}**\n\n" + markdown_table(*summary_rows(rows, metric)))
    return "\n\n".join(parts)
