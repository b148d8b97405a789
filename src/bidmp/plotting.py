"""Figures (matplotlib, Agg backend; nothing is shown on screen). Every function writes a PNG
atomically and returns its path."""

from __future__ import annotations

import io as _io
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .io import atomic_write

__all__ = ["plot_trajectories", "plot_generalisation"]


def _figure(projection_3d: bool):
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(7.0, 6.0), dpi=110)
    ax = fig.add_subplot(projection="3d" if projection_3d else None)
    return plt, fig, ax


def _save(plt, fig, path: str | os.PathLike) -> Path:
    buffer = _io.BytesIO()
    fig.savefig(buffer, format="png", bbox_inches="tight")
    plt.close(fig)
    path = Path(path)
    with atomic_write(path, "wb") as handle:
        handle.write(buffer.getvalue())
    return path


def plot_trajectories(
    path: str | os.PathLike,
    demonstration: np.ndarray,
    trajectories: Sequence[np.ndarray] = (),
    labels: Sequence[str] | None = None,
    goals: np.ndarray | None = None,
    title: str = "",
    units: str = "",
) -> Path:
    """Plot a demonstration (thick grey), generated trajectories and their goals (stars).

    Parameters
    ----------
    path : path of the PNG to write.
    demonstration : array, shape (T, D), D = 2 or 3 (D = 1 is plotted against the sample index).
    trajectories : sequence of arrays (n, D).
    labels : one legend entry per trajectory (optional).
    goals : array, shape (G, D), optional; drawn as stars.
    """
    demonstration = np.asarray(demonstration, dtype=float)
    n_dims = demonstration.shape[1]
    if n_dims not in (1, 2, 3):
        raise ValueError(f"can only plot 1-, 2- or 3-D trajectories, got D = {n_dims}")
    plt, fig, ax = _figure(n_dims == 3)

    def coords(points: np.ndarray):
        points = np.asarray(points, dtype=float)
        if n_dims == 1:
            return np.arange(len(points)), points[:, 0]
        return tuple(points[:, i] for i in range(n_dims))

    ax.plot(*coords(demonstration), color="0.55", linewidth=4, alpha=0.6, label="demonstration")
    ax.scatter(*[[c[0]] for c in coords(demonstration)], color="k", marker="o", zorder=5, label="start")
    colours = plt.cm.viridis(np.linspace(0.0, 0.9, max(len(trajectories), 1)))
    for index, trajectory in enumerate(trajectories):
        label = labels[index] if labels is not None and index < len(labels) else None
        ax.plot(*coords(trajectory), color=colours[index], linewidth=1.5, label=label)
    if goals is not None and n_dims > 1:
        goals = np.asarray(goals, dtype=float).reshape(-1, n_dims)
        ax.scatter(*[goals[:, i] for i in range(n_dims)], marker="*", s=140, color="crimson", zorder=6, label="goals")
    suffix = f" [{units}]" if units else ""
    names = ("x", "y", "z")
    if n_dims == 1:
        ax.set_xlabel("sample")
        ax.set_ylabel("x" + suffix)
    else:
        ax.set_xlabel(names[0] + suffix)
        ax.set_ylabel(names[1] + suffix)
        if n_dims == 3:
            ax.set_zlabel(names[2] + suffix)
        else:
            ax.set_aspect("equal", adjustable="datalim")
    ax.set_title(title)
    ax.grid(True, alpha=0.3)
    ax.legend(loc="best", fontsize=8)
    return _save(plt, fig, path)


def plot_generalisation(path: str | os.PathLike, result) -> Path:
    """Two panels for a :class:`bidmp.evaluation.GeneralisationResult` (2-D): the rollouts to moved
    goals with the paper's fixed horizon (left) and run to convergence (right)."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(1, 2, figsize=(12.0, 5.5), dpi=110)
    panels = (
        (result.fixed_horizon, f"T = {result.demonstration.shape[0]} steps (paper): end-point gain c = {result.endpoint_gain:.3f}"),
        (result.converged, f"{result.converged.shape[1]} steps (run to convergence): c = {result.endpoint_gain_converged:.1e}"),
    )
    colours = plt.cm.viridis(np.linspace(0.0, 0.85, len(result.goals)))
    for ax, (rollouts, title) in zip(axes, panels):
        demo = result.demonstration
        ax.plot(demo[:, 0], demo[:, 1], color="0.55", linewidth=4, alpha=0.6, label="demonstration")
        ax.plot(result.reproduction[:, 0], result.reproduction[:, 1], "k--", linewidth=1, label="reproduction")
        for colour, rollout, goal in zip(colours, rollouts, result.goals):
            ax.plot(rollout[:, 0], rollout[:, 1], color=colour, linewidth=1.3)
            ax.plot(*goal, marker="*", markersize=12, color=colour, markeredgecolor="crimson")
            ax.plot(*rollout[-1], marker="x", markersize=7, color="crimson")
        ax.plot(*demo[0], "ko", label="start")
        ax.plot([], [], "*", color="0.3", markeredgecolor="crimson", label="moved goal")
        ax.plot([], [], "x", color="crimson", label="end point")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("x [mm]")
        ax.set_aspect("equal", adjustable="datalim")
        ax.grid(True, alpha=0.3)
    axes[0].set_ylabel("y [mm]")
    axes[0].legend(loc="best", fontsize=8)
    fig.suptitle(f"LASA {result.shape}: one demonstration, DMP rollouts to moved goals")
    return _save(plt, fig, path)
