"""The CLFD protocol's figures (:func:`bidmp.experiments.write_clfd` draws them): each method's
accuracy matrix as a heat map, and the mean DTW over the tasks seen against the task index with
the published reference point marked; and ``bidmp-continual``'s capacity sweep against the plain
library of its maps (:func:`bidmp.experiments.clfd.write_capacity`)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._base import _matplotlib, _save

__all__ = ["plot_clfd", "plot_clfd_capacity"]


def plot_clfd(
    out: Path, rows: dict, reference_dtw: float | None = None, stem: str = "clfd"
) -> list[Path]:
    """``clfd_accuracy.png`` (one heat map per method: entry (i, j), the share of task j's
    demonstrations within the DTW threshold after task i) and ``clfd_dtw.png`` (the mean DTW over
    the tasks seen after each task, per method; ``reference_dtw``: the published figure after
    the last task, marked) in folder ``out``, their names starting with ``stem``. ``rows``:
    method name -> an object with
    ``matrices["dtw"]`` (N, N) and ``mean_dtw_seen`` (N,)."""
    mpl = _matplotlib()
    written = []
    names = list(rows)
    fig, axes = mpl.subplots(1, len(names), figsize=(3.4 * len(names), 3.2), dpi=90, squeeze=False)
    image = None
    for ax, name in zip(axes[0], names):
        matrix = np.asarray(rows[name].matrices["dtw"], dtype=float)
        image = ax.imshow(np.ma.masked_invalid(matrix), vmin=0.0, vmax=1.0, cmap="viridis")
        ax.set_title(name, fontsize=9)
        ax.set_xlabel("task evaluated (j)", fontsize=8)
        ax.set_ylabel("after learning task (i)", fontsize=8)
        ax.xaxis.get_major_locator().set_params(integer=True)
        ax.yaxis.get_major_locator().set_params(integer=True)
    if image is not None:
        fig.colorbar(image, ax=list(axes[0]), shrink=0.8, label="accuracy (DTW)")
    written.append(_save(fig, Path(out) / f"{stem}_accuracy.png"))

    fig, ax = mpl.subplots(figsize=(7.0, 3.4), dpi=90)
    for name in names:
        values = np.asarray(rows[name].mean_dtw_seen, dtype=float)
        ax.plot(np.arange(1, len(values) + 1), values, marker="o", markersize=3, label=name)
    if reference_dtw is not None and names:
        last = len(rows[names[0]].mean_dtw_seen)
        ax.plot([last], [reference_dtw], marker="*", markersize=12, color="black", linestyle="")
        ax.annotate(
            "published best (hypernetwork)",
            (last, reference_dtw),
            textcoords="offset points",
            xytext=(-160, -4),
            fontsize=8,
        )
    ax.set_xlabel("tasks learned")
    ax.xaxis.get_major_locator().set_params(integer=True)
    ax.set_ylabel("mean DTW over the tasks seen")
    ax.set_yscale("log")
    ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.01, 0.5))
    ax.grid(True, alpha=0.3)
    written.append(_save(fig, Path(out) / f"{stem}_dtw.png"))
    return written


def plot_clfd_capacity(path: Path, result) -> Path:
    """The capacity sweep in one figure at ``path``: left, ACC (every seed) and the median stored
    map's error (%) against the node count, the map library's ACC dashed and the number of tasks
    dotted; right, the numbers kept against the node count — the weights a reproduction reads
    and, on top, the normal equations learning needs — with the map library's dashed. ``result``:
    an object with ``tasks``, ``library`` (a row with ``acc`` and ``kept``) and ``by_nodes()``
    (node count -> rows with ``acc``, ``map_errors``, ``reproduced_from`` and ``kept``)."""
    mpl = _matplotlib()
    groups = result.by_nodes()
    nodes = np.array(list(groups), dtype=float)
    library = result.library
    fig, (left, right) = mpl.subplots(1, 2, figsize=(11.0, 3.8), dpi=90)
    fig.subplots_adjust(wspace=0.5)
    for count, rows in groups.items():
        left.plot([count] * len(rows), [r.acc for r in rows], "o", color="C0", markersize=4)
    left.plot(
        nodes,
        [np.median([r.acc for r in rows]) for rows in groups.values()],
        color="C0",
        label="bidmp-continual: ACC",
    )
    left.axhline(library.acc, color="C0", linestyle="--", label="map-library: ACC")
    left.axvline(len(result.tasks), color="grey", linestyle=":", label="as many nodes as tasks")
    _node_axis(left, nodes)
    left.set_xlabel("enhancement nodes")
    left.set_ylabel("ACC (DTW)")
    left.set_ylim(-0.02, 1.02)
    twin = left.twinx()
    median_error = [
        np.median([100 * np.median(r.map_errors) for r in rows]) for rows in groups.values()
    ]
    twin.plot(
        nodes,
        median_error,
        color="C3",
        marker="s",
        markersize=3,
        label="stored map off (median, %)",
    )
    twin.set_ylabel("stored map off, median (%)", color="C3")
    handles = left.get_legend_handles_labels()
    more = twin.get_legend_handles_labels()
    left.legend(handles[0] + more[0], handles[1] + more[1], fontsize=7, loc="center right")
    left.grid(True, alpha=0.3)

    weights = [rows[0].reproduced_from for rows in groups.values()]
    kept = [rows[0].kept for rows in groups.values()]
    right.plot(nodes, weights, marker="o", markersize=3, label="weights (R, b, W)")
    right.plot(nodes, kept, marker="o", markersize=3, label="+ normal equations (A, B)")
    right.axhline(library.kept, color="black", linestyle="--", label="map-library (the maps)")
    right.axvline(len(result.tasks), color="grey", linestyle=":")
    _node_axis(right, nodes)
    right.set_xlabel("enhancement nodes")
    right.set_ylabel("numbers kept")
    right.legend(fontsize=7, loc="upper left")
    right.grid(True, alpha=0.3)
    fig.suptitle(
        f"bidmp-continual against the plain library of its maps, LASA ({len(result.tasks)} tasks)",
        fontsize=10,
    )
    return _save(fig, path)


def _node_axis(ax, nodes: np.ndarray) -> None:
    """A log-2 axis ticked at the node counts swept, labelled as plain numbers."""
    ax.set_xscale("log", base=2)
    ax.set_xticks(nodes, [f"{n:g}" for n in nodes])
    ax.minorticks_off()
