"""Figures of incremental learning: Bi-DMP skills on LASA shapes (paper Fig. 11)."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ._base import _finish, _matplotlib, _save

__all__ = ["plot_incremental"]


def plot_incremental(path, results) -> Path:
    """Paper Fig. 11 analogue: per LASA shape, the demonstration, the extended demonstrations,
    the Bi-DMP rollouts to their targets and the plain DMP's rollouts to the same targets."""
    from .._checks import check_sequence_of

    results = check_sequence_of(
        results,
        ("demonstration", "targets", "extensions", "bidmp_rollouts"),
        "results",
        "bidmp.experiments.IncrementalResult (bidmp.experiments.lasa_incremental)",
    )
    mpl = _matplotlib()
    fig, axes = mpl.subplots(
        1, len(results), figsize=(5.5 * len(results), 5.2), dpi=100, squeeze=False
    )
    for ax, result in zip(axes[0], results):
        demo = result.demonstration
        ax.plot(demo[:, 0], demo[:, 1], color="0.6", linewidth=3, alpha=0.6, label="demonstration")
        colours = mpl.cm.tab10(np.arange(len(result.targets)))
        for index, (colour, extension) in enumerate(zip(colours, result.extensions)):
            first = index == 0
            ax.plot(
                *extension.complete.T,
                "--",
                color=colour,
                linewidth=2.5,
                alpha=0.5,
                label="extended demonstration" if first else None,
            )
            ax.plot(
                *result.bidmp_rollouts[index].T,
                color=colour,
                linewidth=1.3,
                label="Bi-DMP rollout" if first else None,
            )
            ax.plot(
                *result.dmp_rollouts[index].T,
                ":",
                color=colour,
                linewidth=1.0,
                label="plain DMP rollout" if first else None,
            )
            ax.plot(*result.targets[index], "*", color=colour, markersize=13, markeredgecolor="k")
        ax.plot(*demo[0], "ko")
        errors = result.reproduction_errors()
        ax.set_title(
            f"LASA {result.shape}: Bi-DMP RMSE {errors.min():.2f}–{errors.max():.2f} mm",
            fontsize=10,
        )
        _finish(ax, 2, "mm")
    axes[0][0].legend(fontsize=7, loc="best")
    fig.tight_layout()
    return _save(fig, path)
