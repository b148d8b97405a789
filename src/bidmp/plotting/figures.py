"""Figures. Every function writes a PNG atomically and returns its path.

Figures are built as :class:`matplotlib.figure.Figure` objects, never through ``pyplot``: nothing
is shown, no global figure registry fills up, and the process-wide backend is left alone, so a
notebook user keeps theirs.
"""

from __future__ import annotations

import io as _io
import os
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .._checks import as_points, as_trajectory
from ..io.atomic import atomic_write

__all__ = ["plot_trajectories", "plot_generalisation", "plot_segmentation", "plot_extension", "plot_prm_comparison", "plot_incremental", "plot_targets_top_view",
           "plot_error_vs_distance", "plot_scenario_3d"]


class _Matplotlib:
    """The parts of matplotlib the figures use, without ``pyplot`` (which would pick a backend)."""

    def __init__(self):
        from types import SimpleNamespace

        import mpl_toolkits.mplot3d  # noqa: F401 - registers the "3d" projection
        from matplotlib import colormaps
        from matplotlib.figure import Figure
        from matplotlib.patches import Circle, Rectangle

        self._figure_class = Figure
        self.Circle = Circle
        self.Rectangle = Rectangle
        self.cm = SimpleNamespace(viridis=colormaps["viridis"], tab10=colormaps["tab10"])

    def figure(self, figsize, dpi):
        return self._figure_class(figsize=figsize, dpi=dpi)

    def subplots(self, *grid, figsize, dpi, **kwargs):
        fig = self._figure_class(figsize=figsize, dpi=dpi)
        return fig, fig.subplots(*grid, **kwargs)


def _matplotlib() -> _Matplotlib:
    return _Matplotlib()


def _figure(projection_3d: bool):
    mpl = _matplotlib()
    fig = mpl.figure(figsize=(7.0, 6.0), dpi=110)
    ax = fig.add_subplot(projection="3d" if projection_3d else None)
    return mpl, fig, ax


def _save(fig, path: str | os.PathLike) -> Path:
    buffer = _io.BytesIO()
    fig.savefig(buffer, format="png", bbox_inches="tight")
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
    demonstration = as_trajectory(demonstration, "demonstration", min_points=1, allow_static=True)
    n_dims = demonstration.shape[1]
    if n_dims not in (1, 2, 3):
        raise ValueError(f"can only plot 1-, 2- or 3-D trajectories, got D = {n_dims}")
    trajectories = [as_trajectory(t, f"trajectories[{i}]", min_points=1, allow_static=True) for i, t in enumerate(trajectories)]
    for index, trajectory in enumerate(trajectories):
        if trajectory.shape[1] != n_dims:
            raise ValueError(f"trajectories[{index}] has D = {trajectory.shape[1]}, the demonstration D = {n_dims}")
    if goals is not None:
        goals = as_points(goals, n_dims, "goals")
    mpl, fig, ax = _figure(n_dims == 3)

    def coords(points: np.ndarray):
        points = np.asarray(points, dtype=float)
        if n_dims == 1:
            return np.arange(len(points)), points[:, 0]
        return tuple(points[:, i] for i in range(n_dims))

    ax.plot(*coords(demonstration), color="0.55", linewidth=4, alpha=0.6, label="demonstration")
    ax.scatter(*[[c[0]] for c in coords(demonstration)], color="k", marker="o", zorder=5, label="start")
    colours = mpl.cm.viridis(np.linspace(0.0, 0.9, max(len(trajectories), 1)))
    for index, trajectory in enumerate(trajectories):
        label = labels[index] if labels is not None and index < len(labels) else None
        ax.plot(*coords(trajectory), color=colours[index], linewidth=1.5, label=label)
    if goals is not None and n_dims > 1:
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
    return _save(fig, path)


def plot_generalisation(path: str | os.PathLike, result) -> Path:
    """Two panels for a :class:`bidmp.evaluation.GeneralisationResult` (2-D): the rollouts to moved
    goals with the paper's fixed horizon (left) and run to convergence (right)."""
    mpl = _matplotlib()
    fig, axes = mpl.subplots(1, 2, figsize=(12.0, 5.5), dpi=110)
    panels = (
        (result.fixed_horizon, f"T = {result.demonstration.shape[0]} steps (paper): end-point gain c = {result.endpoint_gain:.3f}"),
        (result.converged, f"{result.converged.shape[1]} steps (run to convergence): c = {result.endpoint_gain_converged:.1e}"),
    )
    colours = mpl.cm.viridis(np.linspace(0.0, 0.85, len(result.goals)))
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
    return _save(fig, path)


def _axes_for(fig, n_dims: int, *grid):
    return fig.add_subplot(*grid, projection="3d" if n_dims == 3 else None)


def _draw(ax, points: np.ndarray, *args, **kwargs):
    points = np.asarray(points, dtype=float).reshape(-1, points.shape[-1])
    return ax.plot(*(points[:, i] for i in range(points.shape[1])), *args, **kwargs)


def _finish(ax, n_dims: int, units: str, title: str = "") -> None:
    suffix = f" [{units}]" if units else ""
    ax.set_xlabel("x" + suffix)
    ax.set_ylabel("y" + suffix)
    if n_dims == 3:
        ax.set_zlabel("z" + suffix)
    else:
        ax.set_aspect("equal", adjustable="datalim")
    ax.grid(True, alpha=0.3)
    if title:
        ax.set_title(title, fontsize=10)


def plot_segmentation(path, y: np.ndarray, points: np.ndarray, kinds: np.ndarray | None = None,
                      curvature: np.ndarray | None = None, units: str = "", title: str = "1D-SEG") -> Path:
    """The demonstration with its segmentation points (maxima ▲, minima ▼) and, if given, the
    curvature along the normalised arc length with the same points."""
    mpl = _matplotlib()
    y = np.asarray(y, dtype=float)
    n_dims = y.shape[1]
    fig = mpl.figure(figsize=(12.0 if curvature is not None else 6.5, 5.5), dpi=110)
    ax = _axes_for(fig, n_dims, 1, 2 if curvature is not None else 1, 1)
    _draw(ax, y, color="0.4", linewidth=2, label="demonstration")
    _draw(ax, y[:1], "ko", label="start")
    kinds = np.ones(len(points), int) if kinds is None else np.asarray(kinds)
    for kind, marker, colour, label in ((1, "^", "crimson", "curvature maximum"), (-1, "v", "royalblue", "curvature minimum")):
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
            ax2.axvline(s[point] / s[-1], color="crimson" if kind == 1 else "royalblue", alpha=0.6, linestyle="--")
        ax2.set_xlabel("normalised arc length")
        ax2.set_ylabel("curvature" + (f" [1/{units}]" if units else ""))
        ax2.grid(True, alpha=0.3)
        ax2.set_title("curvature and segmentation points", fontsize=10)
    return _save(fig, path)


def _draw_extension(ax, extension, prm_path: np.ndarray | None = None, show_samples: bool = True) -> None:
    y = extension.demonstration
    _draw(ax, y, color="0.6", linewidth=3, alpha=0.6, label="demonstration")
    if len(extension.segmentation_points):
        _draw(ax, y[extension.segmentation_points], "^", color="0.2", markersize=6, linestyle="none", label="segmentation points")
    if show_samples and extension.samples is not None:
        _draw(ax, extension.samples, ".", color="c", markersize=2, alpha=0.5, linestyle="none", label="G-PRM samples")
    _draw(ax, extension.tra_imi, "--", color="royalblue", linewidth=2, label="Tra_imi")
    if prm_path is not None:
        _draw(ax, prm_path, ":", color="purple", linewidth=1.5, label="classic PRM")
    _draw(ax, extension.tra_gen, color="crimson", linewidth=2, label="Tra_gen (G-PRM)")
    _draw(ax, extension.complete, color="goldenrod", linewidth=1, alpha=0.9, label="complete y_dn")
    _draw(ax, y[:1], "ko")
    _draw(ax, extension.tra_imi[-1:], "o", color="royalblue", markersize=7)
    _draw(ax, extension.new_target[None], "*", color="green", markersize=14, label="new target")


def plot_extension(path, extension, units: str = "", title: str = "Extended demonstration (1D-SEG + G-PRM)") -> Path:
    """An :class:`bidmp.extension.ExtendedDemonstration`: demonstration, segmentation points,
    sampling points, Tra_imi, Tra_gen and the complete extended demonstration."""
    mpl = _matplotlib()
    n_dims = extension.demonstration.shape[1]
    fig = mpl.figure(figsize=(7.5, 6.5), dpi=110)
    ax = _axes_for(fig, n_dims, 1, 1, 1)
    _draw_extension(ax, extension)
    history = extension.similarity_history
    subtitle = f"\nG-PRM similarity {history[0]:.3f} → best {np.max(history):.3f}" if len(history) else ""
    _finish(ax, n_dims, units, title + subtitle)
    ax.legend(fontsize=7, loc="best")
    return _save(fig, path)


def plot_prm_comparison(path, comparisons) -> Path:
    """Paper Table 5 / Fig. 9 analogue: per case, the example paths (left) and the similarity
    per iteration, mean ± std over seeds, G-PRM vs classic PRM (right)."""
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
        for data, colour, label in ((comparison.gprm, "crimson", "G-PRM"), (comparison.prm, "purple", "classic PRM")):
            mean, std = data.mean(axis=0), data.std(axis=0)
            ax2.plot(iterations, mean, "o-", color=colour, label=label)
            ax2.fill_between(iterations, mean - std, mean + std, color=colour, alpha=0.15)
        ax2.set_xlabel("iteration")
        ax2.set_ylabel("Fréchet similarity")
        ax2.set_ylim(0.0, 1.02)
        ax2.grid(True, alpha=0.3)
        ax2.set_title(f"{comparison.name}: mean ± std over {comparison.gprm.shape[0]} seeds", fontsize=10)
        ax2.legend(fontsize=8, loc="lower right")
    fig.tight_layout()
    return _save(fig, path)


def plot_incremental(path, results) -> Path:
    """Paper Fig. 11 analogue: per LASA shape, the demonstration, the extended demonstrations,
    the Bi-DMP rollouts to their targets and the plain DMP's rollouts to the same targets."""
    mpl = _matplotlib()
    fig, axes = mpl.subplots(1, len(results), figsize=(5.5 * len(results), 5.2), dpi=100, squeeze=False)
    for ax, result in zip(axes[0], results):
        demo = result.demonstration
        ax.plot(demo[:, 0], demo[:, 1], color="0.6", linewidth=3, alpha=0.6, label="demonstration")
        colours = mpl.cm.tab10(np.arange(len(result.targets)))
        for index, (colour, extension) in enumerate(zip(colours, result.extensions)):
            first = index == 0
            ax.plot(*extension.complete.T, "--", color=colour, linewidth=2.5, alpha=0.5, label="extended demonstration" if first else None)
            ax.plot(*result.bidmp_rollouts[index].T, color=colour, linewidth=1.3, label="Bi-DMP rollout" if first else None)
            ax.plot(*result.dmp_rollouts[index].T, ":", color=colour, linewidth=1.0, label="plain DMP rollout" if first else None)
            ax.plot(*result.targets[index], "*", color=colour, markersize=13, markeredgecolor="k")
        ax.plot(*demo[0], "ko")
        errors = result.reproduction_errors()
        ax.set_title(f"LASA {result.shape}: Bi-DMP RMSE {errors.min():.2f}–{errors.max():.2f} mm", fontsize=10)
        _finish(ax, 2, "mm")
    axes[0][0].legend(fontsize=7, loc="best")
    fig.tight_layout()
    return _save(fig, path)


_METHOD_COLOURS = {"dmp": "tab:blue", "dmp-converged": "tab:cyan", "bidmp": "tab:red", "bidmp-latest": "tab:orange",
                   "gmm": "tab:purple", "tpgmm": "tab:brown"}


def plot_targets_top_view(path, report) -> Path:
    """Top view of the targets, one panel per method: green = success, red = failure (paper
    Fig. 16c analogue), with the end point of each rollout."""
    mpl = _matplotlib()
    scenario = report.scenario
    names = list(report.methods)
    n_cols = min(3, len(names))
    n_rows = int(np.ceil(len(names) / n_cols))
    fig, axes = mpl.subplots(n_rows, n_cols, figsize=(4.6 * n_cols, 3.8 * n_rows), dpi=100, squeeze=False)
    targets = scenario.target_array
    checked = any(result.clearances is not None for result in report.methods.values())
    scene = scenario.scene if checked else None
    for ax, name in zip(axes.ravel(), names):
        result = report.methods[name]
        if scene is not None:  # the parts' footprints, under everything else
            for solid in scene.solids:
                ax.add_patch(mpl.Rectangle(solid.lower[:2], *(solid.upper[:2] - solid.lower[:2]), fill=False,
                                           edgecolor="0.75", linewidth=0.6, zorder=0))
        for label, target in scenario.targets.items():
            ok = result.task_success_at(label) if scene is not None else result.errors[label] <= scenario.success_threshold
            ax.add_patch(mpl.Circle(target[:2], 8.0, color="tab:green" if ok else "tab:red", alpha=0.35))
            ax.text(target[0], target[1], label, ha="center", va="center", fontsize=8)
            end = result.rollouts[label][-1]
            ax.plot(end[0], end[1], "k.", markersize=3)
            clearance = result.clearance_at(label)
            if clearance is not None and not clearance.collision_free:
                ax.plot(clearance.point[0], clearance.point[1], "x", color="darkred", markersize=7, markeredgewidth=2)
        if scene is not None:
            title = (f"{name}: task success {result.task_successes}/{len(targets)}, "
                     f"{result.collision_free}/{len(result.checked)} collision-free (x = hit)")
        else:
            title = f"{name}: {result.successes}/{len(targets)} within {scenario.success_threshold:g} {scenario.units}"
        ax.set_title(title, fontsize=9)
        pad = 20.0
        ax.set_xlim(targets[:, 0].min() - pad, targets[:, 0].max() + pad)
        ax.set_ylim(targets[:, 1].min() - pad, targets[:, 1].max() + pad)
        ax.set_aspect("equal")
        ax.grid(True, alpha=0.3)
    for ax in axes.ravel()[len(names):]:
        ax.axis("off")
    fig.suptitle(f"{scenario.name}: {'task ' if scene is not None else ''}success per target (green) and failure (red)")
    fig.tight_layout()
    return _save(fig, path)


def plot_error_vs_distance(path, report) -> Path:
    """End-point error (and approach error) against the distance from the demonstrated target."""
    mpl = _matplotlib()
    scenario = report.scenario
    origin = scenario.targets[scenario.demonstrated]
    distance = {label: float(np.linalg.norm(target - origin)) for label, target in scenario.targets.items()}
    order = sorted(distance, key=distance.get)
    has_approach = any(r.approach_errors is not None for r in report.methods.values())
    fig, axes = mpl.subplots(1, 2 if has_approach else 1, figsize=(12 if has_approach else 6.5, 4.8), dpi=100, squeeze=False)
    panels = [("errors", "end-point error")] + ([("approach_errors", "approach error")] if has_approach else [])
    for ax, (attribute, title) in zip(axes[0], panels):
        for name, result in report.methods.items():
            values = getattr(result, attribute)
            if values is None:
                continue
            ax.plot([distance[label] for label in order], [values[label] for label in order], "o-",
                    color=_METHOD_COLOURS.get(name), label=name, markersize=4)
        ax.axhline(scenario.success_threshold, color="k", linestyle="--", linewidth=1, label="threshold")
        ax.set_yscale("symlog", linthresh=1.0)
        ax.set_ylim(bottom=0.0)
        ax.set_xlabel(f"distance from the demonstrated target [{scenario.units}]")
        ax.set_ylabel(f"{title} [{scenario.units}]")
        ax.grid(True, alpha=0.3)
        ax.set_title(title, fontsize=10)
    axes[0][0].legend(fontsize=8)
    fig.suptitle(f"{scenario.name}: error against distance (symlog scale)")
    fig.tight_layout()
    return _save(fig, path)


def plot_scenario_3d(path, report) -> Path:
    """3-D view: demonstration, segmentation points, extended demonstration(s), Bi-DMP rollouts
    and the plain DMP's rollouts to the targets it misses (paper Fig. 17 / 19 analogue)."""
    mpl = _matplotlib()
    scenario = report.scenario
    demo = scenario.demonstration
    n_dims = demo.shape[1]
    fig = mpl.figure(figsize=(8.0, 6.8), dpi=100)
    ax = _axes_for(fig, n_dims, 1, 1, 1)
    _draw(ax, demo, color="0.4", linewidth=3, label="demonstration")
    for index, extension in enumerate(report.extensions):
        if len(extension.segmentation_points):
            _draw(ax, extension.demonstration[extension.segmentation_points], "^", color="k", markersize=6,
                  linestyle="none", label="segmentation points" if index == 0 else None)
        _draw(ax, extension.complete, color="goldenrod", linewidth=2.5, alpha=0.8, label="extended demonstration" if index == 0 else None)
    for label, trajectory in scenario.demonstrations.items():
        _draw(ax, trajectory, color="goldenrod", linewidth=2.0, alpha=0.6)
    if "bidmp" in report.methods:
        for index, trajectory in enumerate(report.methods["bidmp"].rollouts.values()):
            _draw(ax, trajectory, color="tab:red", linewidth=0.8, alpha=0.7, label="Bi-DMP rollouts" if index == 0 else None)
    if "dmp" in report.methods:
        for index, label in enumerate(report.failed_targets):
            _draw(ax, report.methods["dmp"].rollouts[label], "--", color="tab:blue", linewidth=0.8,
                  label="plain DMP, missed targets" if index == 0 else None)
    _draw(ax, scenario.target_array, "o", color="tab:green", markersize=4, linestyle="none", label="targets")
    hits = [clearance.point for result in report.methods.values() if result.clearances is not None
            for clearance in result.clearances.values() if clearance is not None and not clearance.collision_free]
    if scenario.scene is not None and n_dims == 3:
        for solid in scenario.scene.solids:  # each part as the vertical edges of its box
            for x, y in ((solid.lower[0], solid.lower[1]), (solid.upper[0], solid.lower[1]),
                         (solid.upper[0], solid.upper[1]), (solid.lower[0], solid.upper[1])):
                ax.plot([x, x], [y, y], [solid.lower[2], solid.upper[2]], color="0.7", linewidth=0.5)
    if hits:
        _draw(ax, np.array(hits), "X", color="darkred", markersize=7, linestyle="none", label="collisions")
    _finish(ax, n_dims, scenario.units, f"{scenario.name}")
    ax.legend(fontsize=7, loc="upper left")
    return _save(fig, path)


def plot_recordings(path, recordings, goal_shift=None) -> Path:
    """Kinesthetic recordings raw and prepared, the DMP's rollout to a moved goal, and the speed
    profiles in real time (top view, side view, speed).

    Parameters
    ----------
    recordings : list of (name, y, t, prepared, info, moved)
        ``y``, ``t``: the recording; ``prepared``, ``info``: :func:`bidmp.prepare`'s result;
        ``moved``: a :class:`bidmp.Trajectory` (the rollout to the moved goal), or None.
    """
    mpl = _matplotlib()
    fig, (top, side, speed) = mpl.subplots(1, 3, figsize=(12.0, 4.6), dpi=110)
    colours = mpl.cm.tab10(np.arange(10))
    for index, (name, y, t, prepared, info, moved) in enumerate(recordings):
        colour = colours[index % 10]
        top.plot(y[:, 0], y[:, 1], color=colour, alpha=0.35, linewidth=3, label=f"{name} (raw)")
        side.plot(y[:, 0], y[:, 2], color=colour, alpha=0.35, linewidth=3)
        raw_speed = np.linalg.norm(np.gradient(y, t, axis=0), axis=1)
        speed.plot(t - t[0], raw_speed, color=colour, alpha=0.25, linewidth=0.6)
        speed.plot(prepared.t + info.start_s, np.linalg.norm(prepared.yd, axis=1), color=colour, linewidth=2,
                   label=f"{name}: prepared, kept {info.start_s:.2f}-{info.end_s:.2f} s")
        if moved is not None:
            top.plot(moved.y[:, 0], moved.y[:, 1], color=colour, linewidth=1.2, label="DMP to the moved goal")
            side.plot(moved.y[:, 0], moved.y[:, 2], color=colour, linewidth=1.2)
            speed.plot(moved.t + info.start_s, np.linalg.norm(moved.yd, axis=1), color=colour, linestyle="--", linewidth=1)
            top.plot(moved.y[-1, 0], moved.y[-1, 1], marker="*", markersize=12, color="crimson")
            side.plot(moved.y[-1, 0], moved.y[-1, 2], marker="*", markersize=12, color="crimson")
    units = recordings[0][3].units if recordings else ""
    suffix = f" [{units}]" if units else ""
    top.set(xlabel="x" + suffix, ylabel="y" + suffix, title="top view")
    side.set(xlabel="x" + suffix, ylabel="z" + suffix, title="side view")
    speed.set(xlabel="time in the recording [s]", ylabel=f"speed [{units or 'units'}/s]",
              title="speed: raw (thin), prepared, rollout (dashed)")
    speed.set_ylim(0.0, 1.3 * max(float(np.max(np.linalg.norm(r[3].yd, axis=1))) for r in recordings))
    top.legend(fontsize=7, loc="lower right")
    speed.legend(fontsize=7, loc="upper right")
    for axes in (top, side, speed):
        axes.grid(True, alpha=0.3)
    fig.tight_layout()
    return _save(fig, path)
