"""Figures of extended demonstrations: segmentation points, the extension, G-PRM against PRM."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._checks import as_indices, as_trajectory, as_vector
from ._base import _axes_for, _draw, _finish, _matplotlib, _save

__all__ = ["plot_segmentation", "plot_extension", "plot_prm_comparison"]


def plot_segmentation(
    path,
    y: np.ndarray,
    points: np.ndarray,
    kinds: np.ndarray | None = None,
    curvature: np.ndarray | None = None,
    units: str = "",
    title: str = "1D-SEG",
) -> Path:
    """The demonstration with its segmentation points (maxima ▲, minima ▼) and, if given, the
    curvature along the normalised arc length with the same points."""
    y = as_trajectory(y, "y", min_points=2, allow_static=True)
    points = as_indices(points, "points", y.shape[0] - 1, "y")
    if kinds is not None:
        kinds = as_vector(kinds, "kinds", length=points.shape[0])
        if np.any(np.abs(kinds) != 1.0):
            raise ValueError(f"kinds must be +1 or -1 for each of the {points.shape[0]} points")
    if curvature is not None:
        curvature = as_vector(curvature, "curvature", min_length=2)
    mpl = _matplotlib()
    y = np.asarray(y, dtype=float)
    n_dims = y.shape[1]
    fig = mpl.figure(figsize=(12.0 if curvature is not None else 6.5, 5.5), dpi=110)
    ax = _axes_for(fig, n_dims, 1, 2 if curvature is not None else 1, 1)
    _draw(ax, y, color="0.4", linewidth=2, label="demonstration")
    _draw(ax, y[:1], "ko", label="start")
    kinds = np.ones(len(points), int) if kinds is None else np.asarray(kinds)
    for kind, marker, colour, label in (
        (1, "^", "crimson", "curvature maximum"),
        (-1, "v", "royalblue", "curvature minimum"),
    ):
        chosen = np.asarray(points)[kinds == kind]
        if chosen.size:
            _draw(ax, y[chosen], marker, color=colour, markersize=9, linestyle="none", label=label)
    _finish(ax, n_dims, units, title)
    ax.legend(fontsize=8, loc="best")
    if curvature is not None:
        ax2 = fig.add_subplot(1, 2, 2)
        lam = np.linspace(0.0, 1.0, len(curvature))
        ax2.plot(lam, curvature, color="0.3")
        s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(y, axis=0), axis=1))])
        for point, kind in zip(points, kinds):
            ax2.axvline(
                s[point] / s[-1],
                color="crimson" if kind == 1 else "royalblue",
                alpha=0.6,
                linestyle="--",
            )
        ax2.set_xlabel("normalised arc length")
        ax2.set_ylabel("curvature" + (f" [1/{units}]" if units else ""))
        ax2.grid(True, alpha=0.3)
        ax2.set_title("curvature and segmentation points", fontsize=10)
        # The 3-D panel's z label sat on the curvature axis's label: room between the panels.
        fig.subplots_adjust(wspace=0.38)
        if n_dims == 3:
            ax.set_zlabel(ax.get_zlabel(), labelpad=8)
    return _save(fig, path)


def _draw_extension(
    ax, extension, prm_path: np.ndarray | None = None, show_samples: bool = True
) -> None:
    y = extension.demonstration
    _draw(ax, y, color="0.6", linewidth=3, alpha=0.6, label="demonstration")
    if len(extension.segmentation_points):
        _draw(
            ax,
            y[extension.segmentation_points],
            "^",
            color="0.2",
            markersize=6,
            linestyle="none",
            label="segmentation points",
        )
    if show_samples and extension.samples is not None:
        _draw(
            ax,
            extension.samples,
            ".",
            color="c",
            markersize=2,
            alpha=0.5,
            linestyle="none",
            label="G-PRM samples",
        )
    _draw(
        ax,
        extension.tra_imi,
        "--",
        color="royalblue",
        linewidth=2,
        label="imitated segment (Tra_imi)",
    )
    if prm_path is not None:
        _draw(ax, prm_path, ":", color="purple", linewidth=1.5, label="classic PRM")
    _draw(
        ax,
        extension.tra_gen,
        color="crimson",
        linewidth=2,
        label="new transfer to the target (Tra_gen, G-PRM)",
    )
    _draw(
        ax,
        extension.complete,
        color="goldenrod",
        linewidth=1,
        alpha=0.9,
        label="extended demonstration Bi-DMP learns",
    )
    _draw(ax, y[:1], "ko")
    _draw(ax, extension.tra_imi[-1:], "o", color="royalblue", markersize=7)
    _draw(ax, extension.new_target[None], "*", color="green", markersize=14, label="new target")


def plot_extension(
    path, extension, units: str = "", title: str = "Extended demonstration (1D-SEG + G-PRM)"
) -> Path:
    """An :class:`bidmp.extension.extend.ExtendedDemonstration`: demonstration, segmentation points,
    sampling points, the imitated segment (Tra_imi), the new transfer (Tra_gen) and the complete
    extended demonstration, labelled in words."""
    from .._checks import check_kind
    from ..extension.extend import ExtendedDemonstration

    check_kind(
        extension,
        ExtendedDemonstration,
        "extension",
        "an ExtendedDemonstration (bidmp.extend_demonstration)",
    )
    mpl = _matplotlib()
    n_dims = extension.demonstration.shape[1]
    fig = mpl.figure(figsize=(7.5, 6.5), dpi=110)
    ax = _axes_for(fig, n_dims, 1, 1, 1)
    _draw_extension(ax, extension)
    history = extension.similarity_history
    subtitle = (
        f"\nG-PRM similarity {history[0]:.3f} → best {np.max(history):.3f}" if len(history) else ""
    )
    _finish(ax, n_dims, units, title + subtitle)
    # Below the axes: inside, the legend covered the transfer it explains.
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.06), ncol=2)
    return _save(fig, path)


def plot_prm_comparison(path, comparisons) -> Path:
    """Paper Table 5 / Fig. 9 analogue: per case, the example paths (left) and the similarity
    per iteration, mean ± std over seeds, G-PRM vs classic PRM (right)."""
    from .._checks import check_sequence_of

    comparisons = check_sequence_of(
        comparisons,
        ("extension", "example_prm", "gprm", "prm", "units", "name"),
        "comparisons",
        "bidmp.experiments.PRMComparison (bidmp.experiments.compare_prm)",
    )
    mpl = _matplotlib()
    fig = mpl.figure(figsize=(12.0, 4.2 * len(comparisons)), dpi=100)
    for row, comparison in enumerate(comparisons):
        n_dims = comparison.extension.demonstration.shape[1]
        ax = _axes_for(fig, n_dims, len(comparisons), 2, 2 * row + 1)
        _draw_extension(ax, comparison.extension, prm_path=comparison.example_prm.path)
        _finish(ax, n_dims, comparison.units, comparison.name)
        if row == 0:
            ax.legend(fontsize=7, loc="best")
        ax2 = fig.add_subplot(len(comparisons), 2, 2 * row + 2)
        iterations = np.arange(1, comparison.gprm.shape[1] + 1)
        for data, colour, label in (
            (comparison.gprm, "crimson", "G-PRM"),
            (comparison.prm, "purple", "classic PRM"),
        ):
            mean, std = data.mean(axis=0), data.std(axis=0)
            ax2.plot(iterations, mean, "o-", color=colour, label=label)
            ax2.fill_between(iterations, mean - std, mean + std, color=colour, alpha=0.15)
        ax2.set_xlabel("iteration")
        ax2.set_ylabel("Fréchet similarity")
        ax2.set_ylim(0.0, 1.02)
        ax2.grid(True, alpha=0.3)
        ax2.set_title(
            f"{comparison.name}: mean ± std over {comparison.gprm.shape[0]} seeds", fontsize=10
        )
        ax2.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    return _save(fig, path)
