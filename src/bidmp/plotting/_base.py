"""What every figure shares: matplotlib without ``pyplot``, 2-D or 3-D axes, atomic PNG writes.

Figures are built as :class:`matplotlib.figure.Figure` objects, never through ``pyplot``: nothing
is shown, no global figure registry fills up, and the process-wide backend is left alone, so a
notebook user keeps theirs."""

from __future__ import annotations

import io as _io
import os
from pathlib import Path

import numpy as np

from .._checks import check_path, printable
from ..io.atomic import atomic_write


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
    path = check_path(path)
    with atomic_write(path, "wb") as handle:
        handle.write(buffer.getvalue())
    return path


def _axes_for(fig, n_dims: int, *grid):
    return fig.add_subplot(*grid, projection="3d" if n_dims == 3 else None)


def _draw(ax, points: np.ndarray, *args, **kwargs):
    points = np.asarray(points, dtype=float).reshape(-1, points.shape[-1])
    return ax.plot(*(points[:, i] for i in range(points.shape[1])), *args, **kwargs)


def _text(value, name: str, longest: int) -> str:
    """A label for a figure: a string of at most ``longest`` characters (matplotlib lays out any
    length, and runs out of memory on a file read by mistake)."""
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a string, got {type(value).__name__}")
    if len(value) > longest:
        raise ValueError(f"{name} is {len(value):,} characters long; at most {longest}")
    # A control code has no glyph in any font (a file name may carry terminal escapes); a line
    # break is the one that lays out, as the figures' own two-line titles use it.
    return "\n".join(printable(line) for line in value.split("\n"))


def _sequence(value, name: str) -> list:
    """A list or tuple of items (a single array or None is not a sequence of them)."""
    if not isinstance(value, (list, tuple)):
        raise TypeError(f"{name} must be a list or tuple, got {type(value).__name__}")
    return list(value)


def _label_axes(ax, n_dims: int, units: str) -> None:
    """Axis names with the unit; 1-D against the sample index, 2-D at equal scale."""
    units = _text(units, "units", 20)
    suffix = f" [{units}]" if units else ""
    if n_dims == 1:
        ax.set_xlabel("sample")
        ax.set_ylabel("x" + suffix)
        return
    ax.set_xlabel("x" + suffix)
    ax.set_ylabel("y" + suffix)
    if n_dims == 3:
        ax.set_zlabel("z" + suffix)
        from matplotlib.ticker import MaxNLocator

        # 3-D tick labels crowd into each other beyond ~6
        for axis in (
            ax.xaxis,
            ax.yaxis,
            ax.zaxis,
        ):
            axis.set_major_locator(MaxNLocator(6))
        _equal_3d(ax)
    else:
        ax.set_aspect("equal", adjustable="datalim")


def _equal_3d(ax) -> None:
    """One scale on all three axes (as 2-D plots have): a cube around what is drawn. Matplotlib
    stretches each 3-D axis to its own data, so micrometre noise along one axis is drawn as large
    as a 300 mm move along another."""
    limits = np.array([ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d()])
    centre = limits.mean(axis=1)
    half = max(float(np.max(limits[:, 1] - limits[:, 0])) / 2.0, 1e-12)
    ax.set_xlim3d(centre[0] - half, centre[0] + half)
    ax.set_ylim3d(centre[1] - half, centre[1] + half)
    ax.set_zlim3d(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1.0, 1.0, 1.0))


def _finish(ax, n_dims: int, units: str, title: str = "") -> None:
    _label_axes(ax, n_dims, units)
    ax.grid(True, alpha=0.3)
    title = _text(title, "title", 300)
    if title:
        ax.set_title(title, fontsize=10)
