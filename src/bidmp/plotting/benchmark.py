"""The LASA handwriting benchmark's figures (:func:`bidmp.experiments.lasa` draws them when its
sweep is done)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._base import _matplotlib

__all__ = ["plot_lasa_benchmark"]


def plot_lasa_benchmark(out: Path, rows: list, cells: dict, shapes: list) -> list[Path]:
    """The LASA benchmark's figures in folder ``out``: a grid of the shapes (the first
    demonstration of each and every method's reproduction of it, ``lasa_shapes.png``) and box
    plots of the far goals' RMSE, DTW per sample and end-point error per method
    (``lasa_metrics.png``, log scales, mm). ``rows`` are the benchmark's table rows, ``cells``
    its cells by key (:func:`bidmp.experiments.lasa` writes both)."""
    from ..demonstrations.datasets import lasa as lasa_data
    from ..io.atomic import atomic_write

    mpl = _matplotlib()
    written = []
    n_cols = min(6, len(shapes))
    n_rows = int(np.ceil(len(shapes) / n_cols))
    fig, axes = mpl.subplots(
        n_rows, n_cols, figsize=(2.6 * n_cols, 2.4 * n_rows), dpi=90, squeeze=False
    )
    colours = mpl.cm.tab10
    for ax, shape in zip(axes.ravel(), shapes):
        key = next((k for k in cells if k.startswith(f"{shape}__")), None)
        demo = int(key.split("__")[1]) if key else 0
        ax.plot(*lasa_data(shape)[demo].T, color="0.6", linewidth=2.5, label="demonstration")
        if key is not None:
            for index, (method, rollout) in enumerate(cells[key].get("rollouts", {}).items()):
                ax.plot(
                    *np.asarray(rollout).T, color=colours(index % 10), linewidth=0.9, label=method
                )
        ax.set_title(shape, fontsize=8)
        ax.set_xticks([])
        ax.set_yticks([])
    for ax in axes.ravel()[len(shapes) :]:
        ax.axis("off")
    handles, labels = axes.ravel()[0].get_legend_handles_labels()
    fig.tight_layout()
    if handles:  # below the grid, as many columns as fit its width; the saved area grows to hold it
        fig.legend(
            handles,
            labels,
            loc="upper center",
            bbox_to_anchor=(0.5, 0.0),
            ncol=min(len(labels), max(2, n_cols)),
            fontsize=8,
            frameon=False,
        )
    written.append(out / "lasa_shapes.png")
    with atomic_write(written[-1], "wb") as handle:
        fig.savefig(handle, format="png", bbox_inches="tight")
    from matplotlib.ticker import FuncFormatter

    plain = FuncFormatter(lambda value, _: f"{value:g}")
    # Within two decades, the 2s and 5s between the powers of ten are labelled too.
    two_five = FuncFormatter(
        lambda value, _: (
            f"{value:g}" if round(value / 10 ** np.floor(np.log10(value))) in (2, 5) else ""
        )
    )
    methods = list(dict.fromkeys(row["method"] for row in rows))
    fig, axes = mpl.subplots(1, 3, figsize=(15, 4.2), dpi=90, squeeze=False)
    for ax, metric in zip(axes[0], ("rmse", "dtw_per_sample", "endpoint_error")):
        data = [
            [row[metric] for row in rows if row["method"] == method and row["case"] == "far"]
            for method in methods
        ]
        ax.boxplot(data, tick_labels=methods, showfliers=False)
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(plain)  # 10, 0.01 rather than 10^1, 10^-2
        low, high = ax.get_ylim()
        ax.yaxis.set_minor_formatter(
            two_five if high / low < 300 else FuncFormatter(lambda value, _: "")
        )
        ax.set_title(f"{metric}, far goals", fontsize=10)
        # LASA: tablet mm
        ax.set_ylabel(f"{metric} [mm{' per sample' if metric == 'dtw_per_sample' else ''}] (log)")
        ax.tick_params(axis="x", labelrotation=30, labelsize=8)
    fig.tight_layout()
    written.append(out / "lasa_metrics.png")
    with atomic_write(written[-1], "wb") as handle:
        fig.savefig(handle, format="png")
    return written
