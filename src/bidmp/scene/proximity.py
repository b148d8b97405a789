"""What is near the tool, and which way is away from it: the query a coupling term asks at every
control step (:class:`bidmp.primitives.avoidance.SceneAvoidance`).

One query per step: the vertical tool at a point against every chosen solid's bounding box (the
exact cylinder-to-box distance of :func:`bidmp.scene.distances._cylinder_box_bounds`: a lower
bound), then coal's signed distance and
nearest points for the solids whose bound is inside the radius asked about. The direction away
from a solid is the unit vector from its nearest point to the tool's (coal's normal, reversed,
when they overlap).
"""

from __future__ import annotations

import math

import numpy as np

from .._checks import as_point, check_real, checks_input
from .clearance import Scene
from .distances import _cylinder_box_bounds

__all__ = ["Proximity"]


class Proximity:
    """Signed distances and escape directions from the tool at a point to the parts near it.

    Parameters
    ----------
    scene : Scene
    exclude : iterable of str
        Part labels left out (the target and what it stands on).
    """

    def __init__(self, scene: Scene, exclude=()) -> None:
        if not isinstance(scene, Scene):
            raise TypeError(f"scene must be a bidmp.Scene, got {type(scene).__name__}")
        self.scene = scene
        self._chosen = scene._selected(exclude)
        self._lower, self._upper = scene._lower[self._chosen], scene._upper[self._chosen]
        self._engine = scene._engine() if self._chosen.size else None
        # The box around them all: a tool far from it needs no per-solid bound (most of a motion).
        self._whole = (
            (self._lower.min(axis=0).tolist(), self._upper.max(axis=0).tolist())
            if self._chosen.size
            else None
        )
        # A part's designed stand-off (a plate under the nut), inf for the parts without one.
        self.standoffs = np.array(
            [scene.standoff.get(scene._owner[index], np.inf) for index in self._chosen]
        )

    def near(
        self,
        point: np.ndarray,
        within: float,
        skip: np.ndarray | None = None,
        *,
        check_input: bool = True,
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Solids whose signed distance from the tool at ``point`` (3,) is below ``within``
        (scene units): their distances (k,), unit directions from each toward the tool (k, 3), their
        parts' stand-offs (k,; inf: none) and their indices among the chosen solids (k,). ``skip``:
        a mask over the chosen solids, those not asked about.

        ``check_input=False`` takes the arguments as given: ``point`` a float array (3,),
        ``within`` a positive float, ``skip`` None or such a mask (a coupling term that asks
        every control step checks them once; as scikit-learn's trees' ``check_input``)."""
        if checks_input(check_input):
            point = as_point(point, 3, "point")
            within = check_real(within, "within", positive=True)
            if skip is not None and (
                not isinstance(skip, np.ndarray)
                or skip.dtype != bool
                or skip.shape != self._chosen.shape
            ):
                raise ValueError(
                    f"skip must be a boolean mask over the {self._chosen.size} chosen solids"
                )
        if self._engine is None:
            return _NONE
        tool = self.scene.tool
        # _cylinder_box_bounds for the one box round every part, in floats: every control step asks
        # this, and NumPy's per-call cost would be most of it.
        x, y, z = point.tolist()
        (x0, y0, z0), (x1, y1, z1) = self._whole
        lateral = math.hypot(max(x0 - x, x - x1, 0.0), max(y0 - y, y - y1, 0.0)) - tool.radius
        vertical = max(z0 - (z + tool.length), z - z1, 0.0)
        if math.hypot(max(lateral, 0.0), vertical) >= within:
            return _NONE
        bounds = _cylinder_box_bounds(
            point[None], tool.radius, tool.length, self._lower, self._upper
        )[0]
        candidates = np.flatnonzero(bounds < within)
        if skip is not None and candidates.size:  # a mask over the chosen solids
            candidates = candidates[~skip[candidates]]
        distances, directions, owed, found = [], [], [], []
        engine = self._engine
        for index in candidates:
            distance = engine.tool_to(point, int(self._chosen[index]))
            if distance >= within:
                continue
            result = engine.result
            away = result.getNearestPoint1() - result.getNearestPoint2()
            if distance <= 0.0:
                away = -np.asarray(result.normal, dtype=float)
            size = math.sqrt(away @ away)
            # no direction from coal: away from the solid's centre
            if not (size > 1e-12 and math.isfinite(size)):
                away = point - self.scene.solids[self._chosen[index]].centre
                size = max(math.sqrt(away @ away), 1e-300)
            distances.append(distance)
            directions.append(away / size)
            owed.append(self.standoffs[index])
            found.append(index)
        if not distances:
            return _NONE
        return np.array(distances), np.array(directions), np.array(owed), np.array(found)


_NONE = (np.empty(0), np.empty((0, 3)), np.empty(0), np.empty(0, dtype=int))
