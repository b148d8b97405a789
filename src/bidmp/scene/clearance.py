"""The scene and the tool's clearance along a motion.

A :class:`Scene` holds labelled parts (boxes, cylinders, hex nuts with studs, plates, battery
cells) and a :class:`~bidmp.scene.parts.Tool`: a cylinder of ``radius`` hanging upward from the
trajectory point (the centre of a socket's mouth) over ``length``. For a trajectory,
:meth:`Scene.clearance` gives the smallest signed distance between the swept tool and every part
except those excluded (the target, which enters the socket), with the label of the part it was
to; negative is a collision (the value is then the penetration depth). :meth:`Scene.checker` is
the collision callback of the roadmap (:class:`~bidmp.scene.checker.SceneChecker`).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from .._checks import (
    _as_float_array,
    _check_magnitude,
    as_point,
    as_trajectory,
    as_vector,
    check_bool,
    check_real,
    numerically_guarded,
    short_token,
)
from .._norms import row_norms, unit_rows
from .._trajectory import continuous_quaternions
from .._units import check_units
from .checker import PoseChecker, SceneChecker
from .distances import _CHUNK, _box_distance, _cylinder_box_bounds, _densify, _Distances
from .parts import Part, Solid, Tool, _cylinder_extent, _fail, _number, _parse_parts

__all__ = ["Scene", "Clearance"]

logger = logging.getLogger(__name__)

_SCENE_KEYS = {"tool", "parts", "targets", "targets_on_parts", "margin", "standoff"}
DEFAULT_MARGIN_MM = 3.0  # a scenario's clearance margin when it states none (in its units), at most the tool's radius
_MM = {"mm": 1.0, "cm": 0.1, "m": 1e-3}


_OVERLAP_TOLERANCE = 1e-6  # parts may touch (a nut on its plate), not interpenetrate beyond this


# The trajectory is checked at most this fraction of the tool's length apart: 0.2 mm for the
# built-ins' 100 mm socket, 0.2 mm too when a scene is in metres (a step in scene units was 200 mm
# there, and a random cell in metres found a 7 µm dip into a post between two placements).
_STEP_SHARE = 0.002


def _solid_frames(solids) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Each solid's centre (k, 3), rotation (k, 3, 3) and its box in its own frame (lower and
    upper corners, (k, 3) each): the shape itself for a box, the tight box of a cylinder (coal's,
    centred, along z) and of a convex hull's vertices."""
    lower, upper = [], []
    for solid in solids:
        if solid.kind == "box":
            half = np.asarray(solid.params, dtype=float) / 2.0
        elif solid.kind == "cylinder":
            radius, height = solid.params
            half = np.array([radius, radius, height / 2.0])
        else:
            vertices = np.asarray(solid.params[0], dtype=float)
            lower.append(vertices.min(axis=0))
            upper.append(vertices.max(axis=0))
            continue
        lower.append(-half)
        upper.append(half)
    count = len(solids)
    return (
        np.array([s.centre for s in solids], dtype=float).reshape(count, 3),
        np.array([s.rotation for s in solids], dtype=float).reshape(count, 3, 3),
        np.array(lower, dtype=float).reshape(count, 3),
        np.array(upper, dtype=float).reshape(count, 3),
    )


@dataclass(frozen=True)
class Clearance:
    """Smallest signed distance between the swept tool and the scene's parts along a motion.

    Attributes
    ----------
    distance : float
        In the scene's unit; negative = the tool penetrates a part by that much; ``inf`` when no
        part is checked.
    part : str or None
        Label of the part (solid) it is to, e.g. ``"4"``, ``"4/stud"``, ``"plate"``.
    point : array (3,) or None
        Trajectory point (tool-centre point) where it occurs.
    """

    distance: float
    part: str | None
    point: np.ndarray | None
    margin: float = 0.0  # the scene's clearance margin (scene units)

    @property
    def collision_free(self) -> bool:
        return not self.distance < 0.0

    @property
    def clear(self) -> bool:
        """Collision-free and, when the scene has a margin, no closer to a part than it."""
        return self.collision_free if self.margin <= 0.0 else not self.distance < self.margin

    @property
    def collision_part(self) -> str | None:
        """The part hit, or None when the motion is collision-free."""
        return None if self.collision_free else self.part


def _scene_options(
    data: dict, tool: Tool, targets: dict | None, units: str | None, part_labels
) -> tuple:
    """A scene's ``targets`` (None: all), ``targets_on_parts``, ``margin`` (default 3 mm in
    ``units`` when they are known, else 0) and ``standoff``, validated."""
    chosen = data.get("targets", "all")
    if chosen == "all":
        chosen = None
    elif not isinstance(chosen, list) or not all(isinstance(t, str) for t in chosen):
        _fail("scene.targets", 'expected "all" or a list of target labels')
    elif targets is not None:
        for name in chosen:
            if name not in targets:
                _fail("scene.targets", f"{short_token(name, 20)} is not a target label")
    on_parts = data.get("targets_on_parts", True)
    if not isinstance(on_parts, bool):
        _fail("scene.targets_on_parts", "expected true or false")
    default = 0.0 if units is None else min(DEFAULT_MARGIN_MM * _MM.get(units, 1.0), tool.radius)
    margin = _number(data.get("margin", default), "scene.margin", positive=False)
    if not 0.0 <= margin <= tool.radius:
        _fail(
            "scene.margin",
            f"expected a clearance in [0, the tool's radius {tool.radius:g}], got {margin:g}",
        )
    standoff = data.get("standoff", {})
    if not isinstance(standoff, dict):
        _fail("scene.standoff", 'expected {"part label": the closest the tool may come to it, ...}')
    standoff = {
        str(label): _number(value, f"scene.standoff.{short_token(label, 20)[1:-1]}", positive=False)
        for label, value in standoff.items()
    }
    for label, value in standoff.items():
        if label not in part_labels:
            _fail(f"scene.standoff.{short_token(label, 20)[1:-1]}", "is not the label of a part")
        if not 0.0 <= value <= margin:
            _fail(
                f"scene.standoff.{short_token(label, 20)[1:-1]}",
                f"expected a clearance in [0, the margin {margin:g}], got {value:g}",
            )
    return chosen, on_parts, margin, standoff


class Scene:
    """Parts and a tool; clearance of motions (see the module docstring for the data format).

    Parameters
    ----------
    parts : sequence of Part
        Usually built by :meth:`from_dict`.
    tool : Tool
    targets : list of str or None
        Target labels the geometry applies to (None: every target of the scenario).
    targets_on_parts : bool
        Whether each of those targets must lie on the part with its label.
    """

    def __init__(
        self,
        parts,
        tool: Tool,
        targets=None,
        targets_on_parts: bool = True,
        margin: float = 0.0,
        standoff: dict | None = None,
    ):
        # margin: what every planned and checked motion keeps (scene units); standoff: the parts it
        # may come closer to, by design.
        self.parts, self.tool, self.targets, self.targets_on_parts, self.margin, self.standoff = (
            _init_args(parts, tool, targets, targets_on_parts, margin, standoff)
        )
        self.solids = tuple(solid for part in self.parts for solid in part.solids)
        self._lower = np.array([s.lower for s in self.solids]).reshape(-1, 3)
        self._upper = np.array([s.upper for s in self.solids]).reshape(-1, 3)
        self._owner = np.array([s.part for s in self.solids], dtype=object)
        self._frames = _solid_frames(self.solids)
        self._distances = None

    # -- construction ------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data, targets: dict | None = None, units: str | None = None) -> Scene:
        """Build and validate a scene from its JSON data; ``targets`` ({label: point}) resolves
        ``at_targets`` and is checked against ``targets_on_parts``. Raises :class:`SceneError`
        (a ``ValueError``) naming the key for malformed data, overlapping parts, a target not on
        its part or a tool of zero size."""
        if not isinstance(data, dict):
            _fail("scene", f"data must be an object with tool and parts, got {type(data).__name__}")
        units = None if units is None else check_units(units)
        if targets is not None and (
            not isinstance(targets, dict) or not all(isinstance(k, str) for k in targets)
        ):
            raise TypeError(
                f"targets must be a dict of target label -> point, got {type(targets).__name__}"
            )
        unknown = sorted(set(data) - _SCENE_KEYS)
        if unknown:
            _fail(
                f"scene.{short_token(unknown[0], 20)[1:-1]}",
                f"unknown key (known: {', '.join(sorted(_SCENE_KEYS))})",
            )
        tool_data = data.get("tool")
        if not isinstance(tool_data, dict) or set(tool_data) != {"radius", "length"}:
            _fail(
                "scene.tool",
                'expected {"radius": r, "length": l} (a cylinder hanging from the trajectory point)',
            )
        tool = Tool(*(_number(tool_data[k], f"scene.tool.{k}") for k in ("radius", "length")))
        parts = _parse_parts(data.get("parts"), targets)
        scene = cls(
            parts, tool, *_scene_options(data, tool, targets, units, {part.label for part in parts})
        )
        scene.check_overlaps()
        if targets is not None and scene.targets_on_parts:
            scene.check_targets(targets)
        return scene

    def to_dict(self) -> dict:
        out = {
            "tool": self.tool.to_dict(),
            "parts": [dict(part.spec) for part in self.parts],
            "targets_on_parts": self.targets_on_parts,
            "margin": self.margin,
        }
        if self.targets is not None:
            out["targets"] = list(self.targets)
        if self.standoff:
            out["standoff"] = dict(self.standoff)
        return out

    def with_parts(self, parts, targets: dict | None = None) -> Scene:
        """The same scene with more parts: ``parts`` as a scenario file writes them (a list of part
        objects, ``at_targets`` resolved against ``targets``), checked like the scene's own (their
        keys, their overlaps). The tool, margin, stand-offs and targets are kept.

        Raises
        ------
        SceneError
            Naming the part and key that is wrong, or the two parts that overlap.
        """
        if not isinstance(parts, (list, tuple)):
            raise TypeError(f"parts must be a list of part objects, got {type(parts).__name__}")
        added = _parse_parts(list(parts), targets) if parts else []
        labels = {part.label for part in self.parts}
        clash = next((part.label for part in added if part.label in labels), None)
        if clash is not None:
            _fail("scene.parts", f"label {short_token(clash, 30)} is already a part of the scene")
        scene = Scene(
            (*self.parts, *added),
            self.tool,
            self.targets,
            self.targets_on_parts,
            self.margin,
            self.standoff,
        )
        scene.check_overlaps()
        return scene

    def with_tool(self, tool: Tool) -> Scene:
        """The same parts, margin and stand-offs with another ``tool`` (a part carried under the
        tool's mouth: its height and the radius round its footprint); the margin is kept up to the
        new tool's radius."""
        if not isinstance(tool, Tool):
            raise TypeError(f"tool must be a bidmp.Tool, got {type(tool).__name__}")
        return Scene(
            self.parts,
            tool,
            self.targets,
            self.targets_on_parts,
            min(self.margin, tool.radius),
            {k: min(v, tool.radius) for k, v in self.standoff.items()},
        )

    @property
    def labels(self) -> list[str]:
        return [part.label for part in self.parts]

    def part(self, label: str) -> Part:
        """The part labelled ``label`` (a ``ValueError`` naming the labels when there is none)."""
        return _labelled(self.parts, label)

    def applies_to(self, label: str) -> bool:
        """Whether target ``label`` is checked against this scene."""
        label = _label(label, "label")
        return self.targets is None or label in self.targets

    def bounds(self, part: str) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounding box (lower, upper) of a part's solids."""
        mask = self._owner == _labelled(self.parts, part).label
        return self._lower[mask].min(axis=0), self._upper[mask].max(axis=0)

    def target_parts(self, label: str, point) -> list[str]:
        """The parts that enter the tool at target ``label`` (excepted from its clearance): the
        part labelled like it, else whatever the tool takes into its mouth at ``point``."""
        label, at = _label(label, "label"), self.parts_at(point)  # both checked, whichever answers
        return [label] if label in self.labels else at

    def near(self, trajectory, part: str, distance: float) -> np.ndarray:
        """Which points of ``trajectory`` (n, 3) put the tool (pointing down) within ``distance`` of
        part ``part``'s bounding boxes: a superset of the points within ``distance`` of the part
        itself (the box is no smaller than what it bounds). (n,) bool."""
        points = as_trajectory(trajectory, "trajectory", min_points=1, allow_static=True)
        if points.shape[1] != 3:
            raise ValueError(f"trajectory must have 3 columns (x, y, z), got {points.shape[1]}")
        distance = check_real(distance, "distance", nonnegative=True)
        mask = self._owner == _labelled(self.parts, part).label
        bounds = _cylinder_box_bounds(
            points, self.tool.radius, self.tool.length, self._lower[mask], self._upper[mask]
        )
        return np.min(bounds, axis=1) <= distance

    def parts_at(self, point) -> list[str]:
        """Labels of the parts the tool would take into its mouth at ``point``: those whose
        bounding box is within the tool radius of the point."""
        point = _position(point)
        gap = np.maximum(np.maximum(self._lower - point, point - self._upper), 0.0)
        near = np.linalg.norm(gap, axis=1) <= self.tool.radius
        return list(dict.fromkeys(self._owner[near]))

    # -- validation ---------------------------------------------------------------------------
    def check_overlaps(self) -> None:
        """Raise when solids of two different parts interpenetrate (touching is allowed)."""
        gap = np.maximum(
            np.maximum(
                self._lower[:, None] - self._upper[None], self._lower[None] - self._upper[:, None]
            ),
            0.0,
        )
        close = np.argwhere(np.triu(np.all(gap == 0.0, axis=2), 1))
        for first, second in close:
            if self._owner[first] == self._owner[second]:
                continue
            depth = self._engine().between(int(first), int(second))
            if depth < -_OVERLAP_TOLERANCE:
                _fail(
                    "scene.parts",
                    f"parts {self.solids[first].label!r} and {self.solids[second].label!r} overlap "
                    f"by {-depth:.3g}; parts may touch but not interpenetrate",
                )

    def check_targets(self, targets: dict) -> None:
        """Raise when a target the scene applies to has no part with its label, or does not lie
        on it (more than the tool radius from the part's bounding box)."""
        if not isinstance(targets, dict):
            raise TypeError(
                f"targets must be a dict of label -> point, got {type(targets).__name__}"
            )
        for label, point in targets.items():
            if not isinstance(label, str):
                raise TypeError(
                    f"targets: a target's label must be a string, got {type(label).__name__}"
                )
            point = as_vector(point, f"targets[{short_token(label, 20)}]")
            if point.shape[0] < 3:
                raise ValueError(
                    f"targets[{short_token(label, 20)}] must be a point (3,) or a pose (7,), "
                    f"got {point.shape[0]} values"
                )
            point = _position(point[:3])  # a pose target: its position
            if not self.applies_to(label):
                continue
            if label not in self.labels:
                _fail(
                    "scene",
                    f"target {short_token(label, 20)} has no part labelled like it (targets_on_parts is "
                    f"true; set it false, or list the targets the scene applies to in scene.targets)",
                )
            lower, upper = self.bounds(label)
            gap = np.linalg.norm(
                np.maximum(np.maximum(lower - point, np.asarray(point) - upper), 0.0)
            )
            if gap > self.tool.radius:
                _fail(
                    "scene",
                    f"target {short_token(label, 20)} at {np.round(point, 3).tolist()} is not on part "
                    f"{short_token(label, 20)} (its box spans {np.round(lower, 3).tolist()} to "
                    f"{np.round(upper, 3).tolist()}, {gap:.3g} away)",
                )

    # -- distances ----------------------------------------------------------------------------
    def _engine(self) -> _Distances:
        if self._distances is None:
            self._distances = _Distances(self.solids, self.tool)
        return self._distances

    def _selected(self, exclude) -> np.ndarray:
        exclude = {
            _label(name, "exclude")
            for name in ([exclude] if isinstance(exclude, str) else _names(exclude, "exclude"))
        }
        unknown = exclude - set(self._owner.tolist())
        if unknown:
            raise ValueError(
                f"exclude names {short_token(sorted(unknown)[0])}, which is not a part of the scene"
            )
        return np.flatnonzero([owner not in exclude for owner in self._owner])

    def _minimum(
        self,
        samples: np.ndarray,
        chosen: np.ndarray,
        bounds_of,
        exact,
        best: float = math.inf,
        part: str | None = None,
        point=None,
    ) -> Clearance:
        """Branch and bound over (sample, part) pairs: ``bounds_of(rows)`` bounds the distances of
        ``samples[rows]`` to the chosen parts from below, (m, k); ``exact(row, solid)`` is coal's
        distance. Pairs are evaluated in ascending bound until no bound can beat the best."""
        for start in range(0, samples.shape[0], _CHUNK):
            block = np.arange(start, min(start + _CHUNK, samples.shape[0]))
            bounds = bounds_of(block)
            if best == math.inf:  # seed the bound with the most promising pair
                row, col = divmod(int(np.argmin(bounds)), bounds.shape[1])
                best, part, point = (
                    exact(block[row], int(chosen[col])),
                    self.solids[chosen[col]].label,
                    samples[block[row]],
                )
            # The bounds are >= 0, so a pair whose bound is 0 may penetrate to any depth: while the
            # best is a collision, every overlapping pair is evaluated to find the deepest one.
            rows, cols = np.nonzero((bounds < best) | (bounds <= 0.0))
            for at in np.argsort(bounds[rows, cols], kind="stable"):
                row, col = rows[at], cols[at]
                if bounds[row, col] > 0.0 and bounds[row, col] >= best:
                    break  # every remaining pair is bounded below by at least the best so far
                distance = exact(block[row], int(chosen[col]))
                if distance < best:
                    best, part, point = (
                        distance,
                        self.solids[chosen[col]].label,
                        samples[block[row]],
                    )
        return Clearance(float(best), part, None if point is None else np.array(point), self.margin)

    def _clearance_oriented(
        self, points: np.ndarray, quaternions, chosen: np.ndarray, step: float
    ) -> Clearance:
        """:meth:`clearance` for a tool whose orientation changes along the motion."""
        q = _as_float_array(quaternions, "orientations")
        if (
            q.shape != (points.shape[0], 4)
            or not np.all(np.isfinite(q))
            or np.any(row_norms(q) < 1e-9)
        ):
            raise ValueError(
                f"orientations must be {points.shape[0]} finite, non-zero quaternions (x, y, z, w)"
            )
        q = continuous_quaternions(unit_rows(q))  # (scaled first: 1e300 components normalise)
        sweep = _sweep(points, q, math.hypot(self.tool.length, self.tool.radius))
        dense, segment, fraction = _densify(points, step, weights=True, lengths=sweep)
        if points.shape[0] > 1:  # nlerp between samples at most ``step`` apart
            dense_q = q[segment] + fraction[:, None] * (q[segment + 1] - q[segment])
            dense_q /= np.linalg.norm(dense_q, axis=1, keepdims=True)
        else:
            dense_q = q
        rotations = Rotation.from_quat(dense_q).as_matrix()
        axes = rotations[:, :, 2]
        centres = dense - axes * self.tool.length / 2.0
        engine = self._engine()
        return self._minimum(
            dense,
            chosen,
            lambda rows: self._oriented_bounds(centres[rows], axes[rows], chosen),
            lambda row, solid: engine.tool_to(dense[row], solid, rotations[row]),
        )

    def _oriented_bounds(self, centres: np.ndarray, axes: np.ndarray, chosen: np.ndarray):
        """Lower bounds (m, k) of the distances from the tool (its body's ``centres`` (m, 3), unit
        ``axes`` (m, 3)) to the solids ``chosen``: the distance between the tool's box and each
        solid's box, both taken in the solid's own frame. In the world frame a tilted plate's box
        holds every tool placed near it (bound 0, so every such pair went to coal); in its own
        frame the box is the plate itself."""
        centre, rotation, lower, upper = (part[chosen] for part in self._frames)
        # R^T (c - centre) and R^T a for every solid and placement, (k, m, 3): as row vectors,
        # c R - centre R, one matrix product per solid (an einsum over (m, k, 3) took twice as
        # long, and this runs on every placement of every repaired motion)
        local = centres @ rotation - centre[:, None, :] @ rotation
        extent = _cylinder_extent(axes @ rotation, self.tool.radius, self.tool.length / 2.0)
        # _box_distance's gaps from the boxes' centres and half-sizes (its corners: 1.4x slower)
        middle, half = (lower + upper) / 2.0, (upper - lower) / 2.0
        gap = np.maximum(np.abs(local - middle[:, None]) - extent - half[:, None], 0.0)
        return np.sqrt(np.einsum("kmi,kmi->km", gap, gap)).T

    @numerically_guarded
    def clearance(
        self, trajectory, exclude=(), step: float | None = None, orientations=None
    ) -> Clearance:
        """Smallest signed distance between the tool and the parts along ``trajectory``.

        Parameters
        ----------
        trajectory : array (n, 3)
            Tool-centre points; the tool moves in straight lines between them.
        exclude : str or iterable of str
            Part labels not checked (the target: it enters the socket).
        step : float, optional
            The tool is placed at least every ``step`` along the path (scene unit); default 0.2 %
            of the tool's length (0.2 mm for a 100 mm tool, in any unit). Between two placements
            the tool can come closer than at either by at most ``step / 2`` (the distance is
            1-Lipschitz in the tool's position).
        orientations : array (n, 4), optional
            The tool frame at each point (quaternions x, y, z, w; the frame's z axis is the
            approach direction, the tool's body extends against it). Default: pointing down. A
            turning tool is placed so that none of its points moves more than ``step`` between two.

        Returns
        -------
        Clearance
            The exact minimum over those placements (coal, 1e-8), with the part and point.
        """
        points = as_trajectory(trajectory, "trajectory", min_points=1, allow_static=True)
        if points.shape[1] != 3:
            raise ValueError(f"trajectory must have 3 columns (x, y, z), got {points.shape[1]}")
        step = _STEP_SHARE * self.tool.length if step is None else _checked_step(step, self.tool)
        chosen = self._selected(exclude)
        if chosen.size == 0:
            return Clearance(math.inf, None, None, self.margin)
        if not any(self._owner[index] in self.standoff for index in chosen):
            return self._clearance(points, chosen, step, orientations)
        return _nearest_to_its_clearance(self, points, chosen, step, orientations)

    def _clearance(
        self, points: np.ndarray, chosen: np.ndarray, step: float, orientations
    ) -> Clearance:
        """:meth:`clearance` over the solids ``chosen`` (validated points and step)."""
        if orientations is not None:
            return self._clearance_oriented(points, orientations, chosen, step)
        lower, upper = self._lower[chosen], self._upper[chosen]
        engine = self._engine()
        radius, length = self.tool.radius, self.tool.length
        # Culling: the box around every checked part bounds each sample's distance from below,
        # and the exact distance of the most promising pair bounds the minimum from above. Only
        # the segments whose swept tool box could come closer than that are densified and
        # bounded part by part; most of a motion is far from everything.
        whole_lower, whole_upper = lower.min(axis=0), upper.max(axis=0)
        at_samples = _cylinder_box_bounds(
            points, radius, length, whole_lower[None], whole_upper[None]
        )[:, 0]
        row = int(np.argmin(at_samples))
        first = _cylinder_box_bounds(points[row : row + 1], radius, length, lower, upper)[0]
        col = int(np.argmin(first))
        best = engine.tool_to(points[row], int(chosen[col]))
        best_part, best_point = self.solids[chosen[col]].label, points[row]
        if points.shape[0] > 1:
            swept_lower = np.minimum(points[:-1], points[1:]) - [radius, radius, 0.0]
            swept_upper = np.maximum(points[:-1], points[1:]) + [radius, radius, length]
            near = _box_distance(swept_lower, swept_upper, whole_lower, whole_upper)
            dense = _densify(points, step, np.flatnonzero((near < best) | (near <= 0.0)))
        else:
            dense = points
        return self._minimum(
            dense,
            chosen,
            lambda rows: _cylinder_box_bounds(dense[rows], radius, length, lower, upper),
            lambda row, solid: engine.tool_to(dense[row], solid),
            best,
            best_part,
            best_point,
        )

    @numerically_guarded
    def body_clearance(
        self, solid, trajectory, offset, exclude=(), step: float | None = None
    ) -> Clearance:
        """Smallest signed distance between a body carried along ``trajectory`` and the parts: a
        solid (one of a part the tool holds, :class:`~bidmp.scene.parts.Solid`), its centre
        ``offset`` (3,) from the trajectory point and its orientation as it is, at least every
        ``step`` (default as :meth:`clearance`); the parts in ``exclude`` (the carried part's own,
        those it is lifted off) not checked."""
        points = as_trajectory(trajectory, "trajectory", min_points=1, allow_static=True)
        if points.shape[1] != 3:
            raise ValueError(f"trajectory must have 3 columns (x, y, z), got {points.shape[1]}")
        if not isinstance(solid, Solid):
            raise TypeError(
                f"solid must be a bidmp.scene.Solid (one of a part's solids), got {type(solid).__name__}"
            )
        offset = as_point(offset, 3, "offset")
        step = _STEP_SHARE * self.tool.length if step is None else _checked_step(step, self.tool)
        chosen = self._selected(exclude)
        if chosen.size == 0:
            return Clearance(math.inf, None, None, self.margin)
        engine = self._engine()
        shape = engine.shape_of(solid)
        half = (
            np.asarray(solid.upper) - np.asarray(solid.lower)
        ) / 2.0  # the body's box round its centre
        centres = _densify(points, step) + offset
        lower, upper = self._lower[chosen], self._upper[chosen]
        return self._minimum(
            centres - offset,
            chosen,
            lambda rows: _box_distance(
                (centres[rows] - half)[:, None],
                (centres[rows] + half)[:, None],
                lower[None],
                upper[None],
            ),
            lambda row, index: engine.body_to(shape, solid.rotation, centres[row], index),
        )

    def pose_checker(self, exclude=(), margin: float | None = None) -> PoseChecker:
        """Whether the tool at one pose keeps every part's clearance (:class:`PoseChecker`): the
        parts in ``exclude`` ignored, ``margin`` (scene units; default the scene's) kept from the
        others, a part's stand-off from it."""
        return PoseChecker(self, self._selected(exclude), self.margin if margin is None else margin)

    def checker(self, exclude=(), margin: float | None = None) -> SceneChecker:
        """The roadmap's collision callback for this scene (parts in ``exclude`` ignored): a
        placement or move closer than ``margin`` (scene units; default the scene's) to a part
        is not free."""
        return SceneChecker(
            self, self._selected(exclude), self.margin if margin is None else margin
        )


def _init_args(parts, tool, targets, targets_on_parts, margin, standoff) -> tuple:
    """:class:`Scene`'s arguments validated (as :meth:`Scene.from_dict` builds them)."""
    if not isinstance(parts, (list, tuple)) or not all(isinstance(part, Part) for part in parts):
        raise TypeError("parts must be a list of bidmp.scene.Part (Scene.from_dict builds them)")
    if not isinstance(tool, Tool):
        raise TypeError(f"tool must be a bidmp.Tool, got {type(tool).__name__}")
    if targets is not None:
        targets = [_label(label, "targets") for label in _names(targets, "targets")]
    margin = check_real(margin, "margin", nonnegative=True, maximum=tool.radius)
    if standoff is not None and not isinstance(standoff, dict):
        raise TypeError(
            f"standoff must be a dict of part label -> clearance, got {type(standoff).__name__}"
        )
    standoff = {
        _label(k, "standoff"): check_real(v, "standoff", nonnegative=True)
        for k, v in (standoff or {}).items()
    }
    return (
        tuple(parts),
        tool,
        targets,
        check_bool(targets_on_parts, "targets_on_parts"),
        margin,
        standoff,
    )


def _label(value, name: str) -> str:
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a part label (a string), got {type(value).__name__}")
    return value


def _names(value, name: str) -> list:
    """Labels: None, or a list, tuple or set of strings (not an array)."""
    if value is None:
        return []
    if not isinstance(value, (list, tuple, set, frozenset)):
        raise TypeError(
            f"{name} must be a part label or a list of them, got {type(value).__name__}"
        )
    return list(value)


def _labelled(parts, label) -> Part:
    for part in parts:
        if part.label == _label(label, "label"):
            return part
    raise ValueError(
        f"label: no part labelled {short_token(label)}; parts: {', '.join(p.label for p in parts)[:200]}"
    )


def _checked_step(step, tool: Tool) -> float:
    """A placement step (scene units): positive, at least a millionth of the tool's length (finer
    steps only multiply the placements, and their count overflows)."""
    return check_real(step, "step", minimum=1e-6 * tool.length)


def _sweep(points: np.ndarray, quaternions: np.ndarray, reach: float) -> np.ndarray:
    """How far any point of a tool within ``reach`` of its tip moves along each segment: at most
    |Δp| + reach · Δθ. A turning tool moves its far end more than its tip, so its placements are
    spaced by this, not by |Δp| alone."""
    turn = 2.0 * np.arccos(
        np.clip(np.abs(np.sum(quaternions[1:] * quaternions[:-1], axis=1)), 0.0, 1.0)
    )
    return np.linalg.norm(np.diff(points, axis=0), axis=1) + reach * turn


def _nearest_to_its_clearance(
    scene: Scene, points: np.ndarray, chosen: np.ndarray, step: float, orientations
) -> Clearance:
    """:meth:`Scene.clearance` with stand-offs: the parts that have one are checked against it, the
    rest against the margin, and the result is the group that comes nearest its own clearance (a
    plate at its stand-off must not hide a nut inside the margin)."""
    owner, standoff = scene._owner, scene.standoff
    groups = [[i for i in chosen if owner[i] not in standoff]] + [
        [i for i in chosen if owner[i] == label] for label in standoff
    ]
    results = []
    for group in groups:
        if group:
            found = scene._clearance(points, np.array(group), step, orientations)
            allowed = scene.margin if group is groups[0] else standoff[owner[group[0]]]
            results.append(Clearance(found.distance, found.part, found.point, allowed))
    return min(results, key=lambda c: c.distance - c.margin)


def _position(point) -> np.ndarray:
    """The (x, y, z) of a point or a pose (7,), checked: real, finite, within the value limit."""
    array = _as_float_array(point, "point").reshape(-1)
    if array.shape[0] not in (3, 7) or not np.all(np.isfinite(array[:3])):
        raise ValueError(f"point must be a finite (x, y, z) or pose, got shape {np.shape(point)}")
    _check_magnitude(array[:3], "point")
    return array[:3]
