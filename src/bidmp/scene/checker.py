"""The roadmap's collision checker: tool placements and straight tool moves against the scene
(:func:`bidmp.extension.roadmap.gaussian_prm` calls it)."""

from __future__ import annotations

import logging
import math
from typing import TYPE_CHECKING

import numpy as np

from .._checks import (
    as_indices,
    as_point,
    as_points,
    as_rotation,
    check_limit,
    check_real,
    checks_input,
)
from .distances import _CHUNK, _MAX_ADVANCE_STEPS, _cylinder_box_bounds, _Distances

if TYPE_CHECKING:  # pragma: no cover
    from .clearance import Scene

__all__ = ["SceneChecker"]

logger = logging.getLogger(__name__)


class SceneChecker:
    """Collision callback for :func:`bidmp.extension.roadmap.gaussian_prm`: ``checker(points)`` says which
    tool placements are free, :meth:`segments_free` which straight tool moves are."""

    def __init__(self, scene: Scene, chosen: np.ndarray, margin: float = 0.0):
        # By what it has, not its class: the scene's module builds its checkers from this one.
        if not all(hasattr(scene, name) for name in ("solids", "tool", "_engine")):
            raise TypeError(f"scene must be a bidmp.Scene, got {type(scene).__name__}")
        self.scene = scene
        self.chosen = (
            as_indices(chosen, "chosen", len(scene.solids) - 1)
            if len(scene.solids)
            else np.zeros(0, np.int64)
        )
        # a placement or move closer than this to a part is not free
        self.margin = check_real(margin, "margin", nonnegative=True)

    def __call__(self, points) -> np.ndarray:
        points = as_points(points, 3, "points")
        check_limit(points.shape[0], "max_samples", "points: the number of tool placements")
        free = np.ones(points.shape[0], dtype=bool)
        if self.chosen.size == 0:
            return free
        scene = self.scene
        engine = scene._engine()
        lower, upper = scene._lower[self.chosen], scene._upper[self.chosen]
        radius, length = scene.tool.radius, scene.tool.length
        margin = self.margin
        whole = _cylinder_box_bounds(
            points, radius, length, lower.min(axis=0)[None], upper.max(axis=0)[None]
        )[:, 0]
        near = np.flatnonzero(whole <= margin)
        for start in range(0, near.size, _CHUNK):
            rows = near[start : start + _CHUNK]
            bounds = _cylinder_box_bounds(points[rows], radius, length, lower, upper)
            for row, col in zip(*np.nonzero(bounds <= margin)):
                index = rows[row]
                if free[index] and engine.tool_to(points[index], int(self.chosen[col])) < margin:
                    free[index] = False
        return free

    def segments_free(self, a, b) -> np.ndarray:
        """Whether the tool moving straight from ``a[i]`` to ``b[i]`` touches no part, (M,) bool.

        Conservative advancement: the distance to a part changes by at most the distance moved,
        so the tool may advance by its current clearance without missing a contact."""
        a, b = as_points(a, 3, "a"), as_points(b, 3, "b")
        if a.shape != b.shape:
            raise ValueError(
                f"a has {a.shape[0]} start points but b has {b.shape[0]} end points: one move each"
            )
        check_limit(a.shape[0], "max_samples", "a: the number of moves")
        free = np.ones(a.shape[0], dtype=bool)
        if self.chosen.size == 0:  # (as_points refuses no moves at all)
            return free
        scene = self.scene
        radius, length = scene.tool.radius, scene.tool.length
        grow = self.margin  # the swept tool's box, grown by the margin
        lo = np.minimum(a, b) - [radius + grow, radius + grow, grow]
        hi = np.maximum(a, b) + [radius + grow, radius + grow, length + grow]
        lower, upper = scene._lower[self.chosen], scene._upper[self.chosen]
        # The swept tool's box against the box around all parts first, then part by part.
        near = np.flatnonzero(np.all((hi >= lower.min(axis=0)) & (lo <= upper.max(axis=0)), axis=1))
        touching = np.all((hi[near, None] >= lower[None]) & (lo[near, None] <= upper[None]), axis=2)
        candidates = [(near[i], j) for i, j in zip(*np.nonzero(touching))]
        engine = scene._engine()
        for row, col in candidates:
            if free[row] and not self._move_free(
                engine, a[row], b[row], int(self.chosen[col]), self.margin
            ):
                free[row] = False
        return free

    @staticmethod
    def _move_free(
        engine: _Distances, a: np.ndarray, b: np.ndarray, index: int, margin: float = 0.0
    ) -> bool:
        length = float(np.linalg.norm(b - a))
        travelled = 0.0
        resolution = 1e-9 * max(length, 1.0)
        for _ in range(_MAX_ADVANCE_STEPS):
            distance = engine.tool_to(
                a + (travelled / length) * (b - a) if length > 0 else a, index
            )
            if distance < margin:
                return False
            if travelled >= length:
                return True
            # The distance changes by at most the distance moved: advance by what is left above the margin.
            # touching the margin is allowed
            travelled = min(travelled + max(distance - margin, resolution), length)
        return False  # grazing for too long: treated as a contact (conservative)


class PoseChecker:
    """Whether the tool, placed at a pose, keeps every part's own clearance: the ``margin`` (a
    planning margin, or the scene's), a part's stand-off where the scene states one (the plate the
    nuts stand on). What a planner asks of the tool at each configuration it tests
    (:func:`bidmp.planning.tool_route`): one placement at a time, a tool that may tilt.

    The parts' boxes in their own frames bound the distances from below (the clearance's own
    bounds); coal is asked only for the parts whose bound is within their clearance.
    """

    def __init__(self, scene: Scene, chosen: np.ndarray, margin: float):
        if not all(hasattr(scene, name) for name in ("solids", "tool", "_engine", "standoff")):
            raise TypeError(f"scene must be a bidmp.Scene, got {type(scene).__name__}")
        self.scene = scene
        self.chosen = (
            as_indices(chosen, "chosen", len(scene.solids) - 1)
            if len(scene.solids)
            else np.zeros(0, np.int64)
        )
        self.margin = check_real(margin, "margin", nonnegative=True)
        owners = scene._owner[self.chosen] if self.chosen.size else []
        # each solid's clearance: its part's stand-off, else the margin
        self.required = np.array(
            [min(scene.standoff.get(owner, self.margin), self.margin) for owner in owners],
            dtype=float,
        )
        self._down = np.array([0.0, 0.0, -1.0])

    def free(self, point, rotation=None, check_input: bool = True) -> bool:
        """Whether the tool's mouth at ``point`` (3,), its frame ``rotation`` (3, 3; its z axis the
        approach direction; default pointing down), keeps every part's clearance.
        ``check_input=False``: the arguments taken as given (a planner's, at every test)."""
        return self.slack(point, rotation, far=0.0, check_input=check_input) >= 0.0

    def nearest(self, point, rotation=None) -> str:
        """The label of the part (solid) the tool at ``point`` (its frame ``rotation``) comes
        nearest its clearance of ("" with no part checked)."""
        point = as_point(point, 3, "point")
        rotation = None if rotation is None else as_rotation(rotation, "rotation")
        if self.chosen.size == 0:
            return ""
        engine = self.scene._engine()
        slacks = [
            engine.tool_to(point, int(index), rotation) - required
            for index, required in zip(self.chosen, self.required)
        ]
        return self.scene.solids[int(self.chosen[int(np.argmin(slacks))])].label

    def slack(
        self, point, rotation=None, far: float | None = None, check_input: bool = True
    ) -> float:
        """How far the tool at ``point`` (its frame ``rotation``, as :meth:`free`) is from coming
        within any part's clearance (scene units; negative: it is within it by that much; ``inf``
        with no part checked). A lower bound where every part is more than ``far`` beyond its
        clearance (default the tool's radius): the parts' boxes say so without coal."""
        if checks_input(check_input):
            point = as_point(point, 3, "point")
            rotation = None if rotation is None else as_rotation(rotation, "rotation")
            far = None if far is None else check_real(far, "far", nonnegative=True)
        if self.chosen.size == 0:
            return math.inf
        scene = self.scene
        point = np.asarray(point, dtype=float)
        axis = self._down if rotation is None else np.asarray(rotation, dtype=float)[:, 2]
        centre = point - axis * (scene.tool.length / 2.0)
        gaps = scene._oriented_bounds(centre[None], axis[None], self.chosen)[0]
        # A gap bounds the part's signed distance from below only while the boxes are apart:
        # boxes that overlap bound nothing (the tool may be in the part by any depth).
        bounds = np.where(gaps > 0.0, gaps - self.required, -math.inf)
        order = np.argsort(bounds, kind="stable")
        far = scene.tool.radius if far is None else far
        if bounds[order[0]] > far:
            return float(bounds[order[0]])
        engine = scene._engine()
        best = math.inf
        for col in order:
            if bounds[col] >= best:
                break  # every remaining part is bounded below by at least the best so far
            best = min(
                best, engine.tool_to(point, int(self.chosen[col]), rotation) - self.required[col]
            )
            if best < 0.0 and far == 0.0:
                break  # (a yes-or-no question: one part within its clearance answers it)
        return float(best)
