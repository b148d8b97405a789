"""Figures of a scenario's evaluation: targets from above, error against distance, the scene in 3-D."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from .._checks import printable
from ._base import _axes_for, _draw, _finish, _matplotlib, _save

__all__ = ["plot_targets_top_view", "plot_error_vs_distance", "plot_scenario_3d"]


_METHOD_COLOURS = {
    "dmp": "tab:blue",
    "dmp-converged": "tab:cyan",
    "bidmp": "tab:red",
    "bidmp-latest": "tab:orange",
    "gmm": "tab:purple",
    "tpgmm": "tab:brown",
}


def _sizes(targets: np.ndarray, units: str) -> tuple[float, float]:
    """(disc radius, margin round the targets) in the scene's unit: 8 mm and 20 mm as drawn in mm
    cells, never more than 0.4 of the nearest two targets' distance (discs do not overlap) nor a
    margin less than a twentieth of the targets' spread (a metre cell's were 16 m discs on ±20 m
    axes when the sizes were millimetre numbers)."""
    from .._units import mm

    length = units if units in ("m", "cm", "mm") else "mm"
    radius, pad = mm(8.0, length), mm(20.0, length)
    xy = targets[:, :2]
    if len(xy) > 1:
        gaps = np.linalg.norm(xy[:, None] - xy[None], axis=-1)
        nearest = float(np.min(gaps[gaps > 0])) if np.any(gaps > 0) else radius
        radius = min(radius, 0.4 * nearest)
        pad = max(pad, 0.05 * float(np.ptp(xy, axis=0).max()))
    return radius, pad


def plot_targets_top_view(path, report) -> Path:
    """Top view of the targets, one panel per method: green = success, red = failure (paper
    Fig. 16c analogue, a failed target also crossed), with the end point of each rollout. Sizes
    follow the scene's unit."""
    _check_report(report)
    mpl = _matplotlib()
    scenario = report.scenario
    names = list(report.methods)
    n_cols = min(3, len(names))
    n_rows = int(np.ceil(len(names) / n_cols))
    fig, axes = mpl.subplots(
        n_rows, n_cols, figsize=(4.6 * n_cols, 3.8 * n_rows), dpi=100, squeeze=False
    )
    targets = scenario.target_array
    radius, pad = _sizes(targets, scenario.units)
    checked = any(result.clearances is not None for result in report.methods.values())
    scene = scenario.scene if checked else None
    for ax, name in zip(axes.ravel(), names):
        result = report.methods[name]
        if scene is not None:  # the parts' footprints, under everything else
            for solid in scene.solids:
                ax.add_patch(
                    mpl.Rectangle(
                        solid.lower[:2],
                        *(solid.upper[:2] - solid.lower[:2]),
                        fill=False,
                        edgecolor="0.75",
                        linewidth=0.6,
                        zorder=0,
                    )
                )
        for label, target in scenario.targets.items():
            ok = (
                result.task_success_at(label)
                if scene is not None
                else result.errors[label] <= scenario.success_threshold
            )
            ax.add_patch(
                mpl.Circle(target[:2], radius, color="tab:green" if ok else "tab:red", alpha=0.35)
            )
            if not ok:  # marked by more than its colour (a grey print, a colour-blind reader)
                ax.plot(*target[:2], "x", color="tab:red", markersize=12, markeredgewidth=1.5)
            ax.text(target[0], target[1], printable(label), ha="center", va="center", fontsize=8)
            end = result.rollouts[label][-1]
            ax.plot(end[0], end[1], "k.", markersize=3)
            clearance = result.clearance_at(label)
            if clearance is not None and not clearance.collision_free:
                ax.plot(
                    clearance.point[0],
                    clearance.point[1],
                    "x",
                    color="darkred",
                    markersize=7,
                    markeredgewidth=2,
                )
        if scene is not None:
            title = (
                f"{name}: task success {result.task_successes}/{len(targets)}, "
                f"{result.collision_free}/{len(result.checked)} collision-free (x = hit)"
            )
        else:
            title = f"{name}: {result.successes}/{len(targets)} within {scenario.success_threshold:g} {scenario.units}"
        ax.set_title(title, fontsize=9)
        ax.set_xlim(targets[:, 0].min() - pad, targets[:, 0].max() + pad)
        ax.set_ylim(targets[:, 1].min() - pad, targets[:, 1].max() + pad)
        ax.set_aspect("equal")
        ax.set_xlabel(f"x [{scenario.units}]")
        ax.set_ylabel(f"y [{scenario.units}]")
        ax.grid(True, alpha=0.3)
    for ax in axes.ravel()[len(names) :]:
        ax.axis("off")
    fig.suptitle(
        f"{printable(scenario.name)}: {'task ' if scene is not None else ''}success per target "
        f"(green) and failure (red)"
    )
    fig.tight_layout()
    return _save(fig, path)


def plot_error_vs_distance(path, report) -> Path:
    """End-point error (and approach error) against the distance from the demonstrated target.
    Errors of a cell in m or cm are drawn in mm (its threshold 1.75 mm, not 0.00175 m on an axis
    whose ticks read 0), the distance in the cell's unit; the threshold's value is in the legend."""
    _check_report(report)
    mpl = _matplotlib()
    scenario = report.scenario
    from .._units import UNITS

    units = scenario.units
    scale = UNITS[units] / 1e-3 if units in UNITS else 1.0  # errors in mm for a length unit
    error_unit = "mm" if units in UNITS else (units or "units")
    origin = scenario.targets[scenario.demonstrated]
    distance = {
        label: float(np.linalg.norm(target - origin)) for label, target in scenario.targets.items()
    }
    order = sorted(distance, key=distance.get)
    has_approach = any(r.approach_errors is not None for r in report.methods.values())
    fig, axes = mpl.subplots(
        1,
        2 if has_approach else 1,
        figsize=(12 if has_approach else 6.5, 4.8),
        dpi=100,
        squeeze=False,
    )
    panels = [("errors", "end-point error")] + (
        [("approach_errors", "approach error")] if has_approach else []
    )
    for ax, (attribute, title) in zip(axes[0], panels):
        for name, result in report.methods.items():
            values = getattr(result, attribute)
            if values is None:
                continue
            ax.plot(
                [distance[label] for label in order],
                [scale * values[label] for label in order],
                "o-",
                color=_METHOD_COLOURS.get(name),
                label=name,
                markersize=4,
            )
        threshold = scale * scenario.success_threshold
        ax.axhline(
            threshold,
            color="k",
            linestyle="--",
            linewidth=1,
            label=f"threshold {threshold:g} {error_unit}",
        )
        _readable_symlog(ax)
        ax.set_xlabel(f"distance from the demonstrated target [{scenario.units}]")
        ax.set_ylabel(f"{title} [{error_unit}]")
        ax.grid(True, alpha=0.3)
        ax.set_title(title, fontsize=10)
    axes[0][0].legend(fontsize=8)
    fig.suptitle(f"{printable(scenario.name)}: error against distance (symlog scale)")
    fig.tight_layout()
    return _save(fig, path)


def _readable_symlog(ax) -> None:
    """A symlog error axis with plain-number ticks (0, 0.5, 1, 2, 5, 10, ...): the default puts
    powers of ten only, and none between 0 and 1, where the successes lie."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

    ax.set_yscale("symlog", linthresh=1.0, linscale=1.5)
    ax.set_ylim(bottom=0.0)
    top = ax.get_ylim()[1]
    decades = [m * 10.0**e for e in range(0, 9) for m in (1, 2, 5)]  # 1, 2, 5, ... 5e8
    ticks = [t for t in (0, 0.25, 0.5, 0.75, *decades) if t <= top * 1.05]
    ax.yaxis.set_major_locator(FixedLocator(ticks))
    ax.yaxis.set_minor_locator(NullLocator())
    ax.yaxis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))


def plot_scenario_3d(path, report) -> Path:
    """3-D view (paper Fig. 17 / 19 analogue): the demonstration, its segmentation points and
    extended demonstration(s), every rollout the evaluation judged, one colour per method (a
    motion that breaks the contract dashed, where it comes closest to a part or into it marked
    ×), the targets, and the scene's parts as solids."""
    _check_report(report)
    mpl = _matplotlib()
    scenario = report.scenario
    # A pose scenario's paths are (T, 7): the positions are its first three columns (drawn as
    # they were, x, y against z, qx, ... made a 2-D plot with every entry in the legend four times).
    demo = scenario.demonstration[:, :3]
    n_dims = demo.shape[1]
    fig = mpl.figure(figsize=(9.0, 7.4), dpi=100)
    ax = _axes_for(fig, n_dims, 1, 1, 1)
    if scenario.scene is not None and n_dims == 3:
        _draw_solids(ax, scenario.scene.solids)
    _draw(ax, demo, color="0.2", linewidth=3, label="demonstration")
    for index, extension in enumerate(report.extensions):
        if len(extension.segmentation_points):
            _draw(
                ax,
                extension.demonstration[extension.segmentation_points][:, :3],
                "^",
                color="k",
                markersize=6,
                linestyle="none",
                label="segmentation points" if index == 0 else None,
            )
        _draw(
            ax,
            extension.complete[:, :3],
            color="goldenrod",
            linewidth=2.5,
            alpha=0.8,
            label="extended demonstration" if index == 0 else None,
        )
    for trajectory in scenario.demonstrations.values():
        _draw(ax, trajectory[:, :3], color="goldenrod", linewidth=2.0, alpha=0.6)
    for name, result in report.methods.items():
        colour = _METHOD_COLOURS.get(name, "tab:green")
        failed = [label for label in result.rollouts if not result.task_success_at(label)]
        ax.plot(
            [],
            [],
            color=colour,
            linewidth=1.2,
            label=f"{name}: {len(result.rollouts) - len(failed)} of {len(result.rollouts)} within the contract",
        )
        for label, trajectory in result.rollouts.items():
            bad = label in failed
            _draw(
                ax,
                trajectory[:, :3],
                "--" if bad else "-",
                color=colour,
                linewidth=1.0 if bad else 0.8,
                alpha=0.9 if bad else 0.6,
            )
            clearance = result.clearance_at(label)
            if (
                bad
                and clearance is not None
                and clearance.point is not None
                and not clearance.clear
            ):
                _draw(
                    ax,
                    np.asarray(clearance.point, dtype=float)[None, :3],
                    "X",
                    color=colour,
                    markersize=8,
                    markeredgecolor="black",
                    markeredgewidth=0.5,
                    linestyle="none",
                )
    if any(
        not result.task_success_at(label)
        for result in report.methods.values()
        for label in result.rollouts
    ):
        ax.plot(
            [], [], "--", color="0.3", label="breaks the contract (dashed; × closest to a part)"
        )
    _draw(
        ax,
        scenario.target_array[:, :3],
        "o",
        color="tab:green",
        markersize=4,
        linestyle="none",
        label="targets",
    )
    _finish(ax, n_dims, scenario.units, f"{scenario.name}")
    ax.legend(fontsize=7, loc="upper left")
    return _save(fig, path)


def _draw_solids(ax, solids) -> None:
    """The scene's parts as shaded solids (their triangle meshes, light and translucent, so the
    motions past them stay visible)."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    from .viewer import solid_mesh

    for index, solid in enumerate(solids):
        vertices, faces = solid_mesh(
            solid.kind, solid.centre, solid.rotation, solid.params, sides=16
        )
        mesh = Poly3DCollection(
            vertices[faces], facecolor="lightsteelblue", edgecolor="none", alpha=0.35
        )
        ax.add_collection3d(mesh)
        if index == 0:
            ax.plot([], [], "s", color="lightsteelblue", label="scene parts")
    if solids:  # add_collection3d does not widen the axes: take the parts' extent in
        corners = np.array([s.lower for s in solids] + [s.upper for s in solids], dtype=float)
        ax.auto_scale_xyz(corners[:, 0], corners[:, 1], corners[:, 2], had_data=True)


def _check_report(report) -> None:
    """``report`` must be an evaluation Report (a TypeError naming it otherwise)."""
    from .._checks import check_members

    check_members(
        report, ("scenario", "methods"), "report", "a bidmp evaluation Report (bidmp.evaluate)"
    )
