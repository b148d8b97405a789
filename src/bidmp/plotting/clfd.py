"""The CLFD protocol's figures (:func:`bidmp.experiments.write_clfd` draws them): each method's
accuracy matrix as a heat map, and the mean DTW over the tasks seen against the task index with
the published reference point marked."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._base import _matplotlib, _save

__all__ = ["plot_clfd"]


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
