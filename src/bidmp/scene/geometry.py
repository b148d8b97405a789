"""Scene geometry: the parts of a work cell, the tool, and the tool's clearance along a motion.

A :class:`Scene` holds labelled parts (boxes, cylinders, hex nuts with studs, plates, battery
cells) and a :class:`Tool`: a cylinder of ``radius`` hanging upward from the trajectory point
(the centre of a socket's mouth) over ``length``. For a trajectory, :meth:`Scene.clearance` gives
the smallest signed distance between the swept tool and every part except those excluded (the
target, which enters the socket), with the label of the part it was to; negative is a collision
(the value is then the penetration depth). :meth:`Scene.checker` is the collision callback of the
roadmap (:func:`bidmp.roadmap.gaussian_prm`): tool placements and straight tool moves.

The distances come from coal (the maintained successor of FCL), in the ``collision`` extra:
``pip install 'bidmp[collision]'``. Measured against closed forms (tests/test_geometry.py), coal
with a tightened GJK tolerance is within 1e-8 of the exact clearance; python-fcl, whose GJK
tolerance cannot be set from Python, was up to 2e-3 off. Only lower bounds for culling are
computed here (the exact distance from the vertical tool cylinder to each part's axis-aligned
bounding box, vectorised): a pair is sent to coal only when its bound could beat the best
distance found so far, so a trajectory needs a few dozen coal calls, not one per sample and part.

Scene data (``Scene.from_dict``, the ``"scene"`` key of a scenario), lengths in the scenario's
unit, angles in degrees::

    {"tool": {"radius": 12.5, "length": 100},
     "targets": "all" | [labels],       # targets the geometry applies to (default all)
     "targets_on_parts": true,          # each of them must lie on the part with its label
     "parts": [
        {"type": "plate", "label": "plate", "at": [x, y, z_top], "size": [sx, sy, thickness]},
        {"type": "nut", "label": "3", "at": [x, y, z_base], "across_flats": 13, "height": 6.5,
         "stud": {"radius": 4, "above": 10}, "yaw": 0},
        {"type": "box" | "cell", "label": "B1", "at": [x, y, z_base], "size": [sx, sy, sz], "yaw": 0},
        {"type": "cylinder", "label": "post", "at": [x, y, z_base], "radius": r, "height": h},
        {"type": "nut", "at_targets": "all" | [labels], "offset": [dx, dy, dz], ...}]}

``at`` is the centre of a part's bottom face (a plate's top face). ``at_targets`` places one part
on each named target (at the target plus ``offset``) labelled like the target. A nut's stud is a
cylinder from the nut's base to ``above`` over its top, labelled ``"<nut>/stud"``; ``yaw`` 0 puts
a corner of the hexagon on +x. ``"rotation": [rx, ry, rz]`` (degrees, extrinsic x-y-z) turns a
part fully instead of ``yaw`` (a tilted pack); "bottom", "top" and ``offset`` are then in the
part's own frame.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass
from numbers import Real

import numpy as np

from .._checks import as_trajectory, check_real, get_limits, numerically_guarded, require_extra, short_token
from .._trajectory import continuous_quaternions

__all__ = ["Tool", "Part", "Solid", "Scene", "Clearance", "SceneChecker", "PART_TYPES"]

logger = logging.getLogger(__name__)

PART_TYPES = ("box", "cell", "cylinder", "nut", "plate")
_PART_KEYS = {
    "box": {"size", "yaw"}, "cell": {"size", "yaw"}, "plate": {"size", "yaw"},
    "cylinder": {"radius", "height"}, "nut": {"across_flats", "height", "stud", "yaw"},

}
_COMMON_KEYS = {"type", "label", "at", "at_targets", "offset", "rotation"}
_SCENE_KEYS = {"tool", "parts", "targets", "targets_on_parts"}
_GJK_TOLERANCE = 1e-12  # coal's default (1e-6 relative) leaves clearances ~1e-4 off; see the module docstring
_EPA_TOLERANCE = 1e-6  # penetration depths (coal's default): tighter, its EPA stops early on cylinders and over-reports
_OVERLAP_TOLERANCE = 1e-6  # parts may touch (a nut on its plate), not interpenetrate beyond this
_DEFAULT_STEP = 0.2  # trajectory checked at most this far apart (scene units)
_CHUNK = 8192  # samples per block of lower bounds (memory: _CHUNK x parts doubles)
_MAX_ADVANCE_STEPS = 10_000  # conservative advancement along one straight tool move


class SceneError(ValueError):
    """Malformed scene data; the message names the key."""


def _coal():
    return require_extra("coal", "collision", "scene geometry checks")


@dataclass(frozen=True)
class Tool:
    """A cylindrical tool hanging from the trajectory point (lengths in the scene's unit).

    Parameters
    ----------
    radius : float
        Outer radius (a Ø25 mm socket: 12.5).
    length : float
        From the trajectory point (the mouth) upward to the flange.
    """

    radius: float
    length: float

    def __post_init__(self):
        for name in ("radius", "length"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(value) or value <= 0:
                raise SceneError(f"tool.{name} must be a positive number, got {short_token(value, 20)}")
            if value > get_limits().max_abs_value:
                raise SceneError(f"tool.{name} = {value:g} exceeds the limit max_abs_value")

    def to_dict(self) -> dict:
        return {"radius": self.radius, "length": self.length}


@dataclass(frozen=True)
class Solid:
    """One convex primitive of a part: ``kind`` in box/cylinder/convex, pose by centre and rotation."""

    label: str  # what a hit reports: the part's label, or "<nut>/stud"
    part: str  # the part it belongs to (excluded together)
    kind: str
    centre: np.ndarray  # (3,)
    rotation: np.ndarray  # (3, 3): the solid's frame in the scene
    params: tuple  # box: (sx, sy, sz); cylinder: (radius, height); convex: vertices (n, 3) in the solid frame
    lower: np.ndarray  # axis-aligned bounding box
    upper: np.ndarray


@dataclass(frozen=True)
class Part:
    """A labelled part as given in the scene data (``spec``) and its solids."""

    label: str
    type: str
    spec: dict
    solids: tuple


def _rotation_z(yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _bounds(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    return points.min(axis=0), points.max(axis=0)


def _box_solid(label, part, centre, size, rotation) -> Solid:
    half = np.asarray(size, dtype=float) / 2.0
    corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)]) * half
    return Solid(label, part, "box", centre, rotation, tuple(float(v) for v in size), *_bounds(corners @ rotation.T + centre))


def _cylinder_extent(axis: np.ndarray, radius: float, half_height: float) -> np.ndarray:
    """Half-extents of the axis-aligned box around a cylinder with unit ``axis``."""
    return np.abs(axis) * half_height + radius * np.sqrt(np.clip(1.0 - axis**2, 0.0, 1.0))


def _cylinder_solid(label, part, centre, radius, height, rotation) -> Solid:
    extent = _cylinder_extent(rotation[:, 2], radius, height / 2.0)
    return Solid(label, part, "cylinder", centre, rotation, (float(radius), float(height)), centre - extent, centre + extent)


def _hex_solid(label, part, centre, across_flats, height, rotation) -> Solid:
    corner = across_flats / math.sqrt(3.0)  # circumradius of the hexagon
    angles = np.deg2rad(np.arange(6) * 60.0)
    ring = np.column_stack([corner * np.cos(angles), corner * np.sin(angles), np.zeros(6)])
    vertices = np.vstack([ring + [0, 0, -height / 2.0], ring + [0, 0, height / 2.0]])
    return Solid(label, part, "convex", centre, rotation, (vertices,), *_bounds(vertices @ rotation.T + centre))


# ---------------------------------------------------------------------------------------------
# Parsing
# ---------------------------------------------------------------------------------------------
def _fail(key: str, message: str):
    raise SceneError(f"{key}: {message}")


def _number(value, key, *, positive=True) -> float:
    if isinstance(value, bool) or not isinstance(value, Real) or not math.isfinite(value):
        _fail(key, f"expected a number, got {short_token(value, 20)}")
    if positive and value <= 0:
        _fail(key, f"must be > 0, got {value:g}")
    if abs(value) > get_limits().max_abs_value:
        _fail(key, f"{value:g} exceeds the limit max_abs_value = {get_limits().max_abs_value:g}")
    return float(value)


def _vector(value, key, n=3, positive=False) -> np.ndarray:
    if not isinstance(value, list) or len(value) != n:
        _fail(key, f"expected a list of {n} numbers, got {short_token(value, 30)}")
    return np.array([_number(v, f"{key}[{i}]", positive=positive) for i, v in enumerate(value)])


def _part_rotation(spec: dict, key: str) -> np.ndarray:
    """A part's orientation: ``"rotation": [rx, ry, rz]`` (degrees, extrinsic x-y-z) or ``"yaw"``."""
    if "rotation" in spec and "yaw" in spec:
        _fail(key, 'give either "rotation" [rx, ry, rz] or "yaw", not both')
    if "rotation" in spec:
        from scipy.spatial.transform import Rotation

        return Rotation.from_euler("xyz", _vector(spec["rotation"], f"{key}.rotation"), degrees=True).as_matrix()
    return _rotation_z(math.radians(_number(spec.get("yaw", 0.0), f"{key}.yaw", positive=False)))


def _part_solids(label: str, kind: str, at: np.ndarray, spec: dict, key: str, rotation: np.ndarray) -> tuple:
    up = rotation[:, 2]  # the part's own z axis: "bottom" and "top" are along it
    if kind in ("box", "cell"):
        size = _vector(spec.get("size"), f"{key}.size", positive=True)
        return (_box_solid(label, label, at + up * size[2] / 2.0, size, rotation),)
    if kind == "plate":
        size = _vector(spec.get("size"), f"{key}.size", positive=True)
        return (_box_solid(label, label, at - up * size[2] / 2.0, size, rotation),)
    if kind == "cylinder":
        radius = _number(spec.get("radius"), f"{key}.radius")
        height = _number(spec.get("height"), f"{key}.height")
        return (_cylinder_solid(label, label, at + up * height / 2.0, radius, height, rotation),)
    # nut
    across = _number(spec.get("across_flats"), f"{key}.across_flats")
    height = _number(spec.get("height"), f"{key}.height")
    solids = [_hex_solid(label, label, at + up * height / 2.0, across, height, rotation)]
    stud = spec.get("stud")
    if stud is not None:
        if not isinstance(stud, dict) or set(stud) - {"radius", "above"} or not {"radius", "above"} <= set(stud):
            _fail(f"{key}.stud", 'expected {"radius": r, "above": h} (the stud sticks out h over the nut)')
        radius = _number(stud["radius"], f"{key}.stud.radius")
        above = _number(stud["above"], f"{key}.stud.above")
        if radius >= across / 2.0:
            _fail(f"{key}.stud.radius", f"{radius:g} does not fit inside the nut ({across:g} across flats)")
        total = height + above
        solids.append(_cylinder_solid(f"{label}/stud", label, at + up * total / 2.0, radius, total, rotation))
    return tuple(solids)


def _parse_parts(items, targets: dict | None) -> list[Part]:
    if not isinstance(items, list) or not items:
        _fail("scene.parts", "expected a non-empty list of parts")
    parts: list[Part] = []
    for index, item in enumerate(items):
        key = f"scene.parts[{index}]"
        if not isinstance(item, dict):
            _fail(key, "expected an object")
        kind = item.get("type")
        if kind not in PART_TYPES:
            _fail(f"{key}.type", f"unknown part type {short_token(kind, 20)} (known: {', '.join(PART_TYPES)})")
        rotation = _part_rotation(item, key)
        unknown = sorted(set(item) - _COMMON_KEYS - _PART_KEYS[kind])
        if unknown:
            _fail(f"{key}.{short_token(unknown[0], 20)[1:-1]}",
                  f"unknown key for a {kind} (known: {', '.join(sorted(_COMMON_KEYS | _PART_KEYS[kind]))})")
        if "at_targets" in item:
            if "at" in item or "label" in item:
                _fail(key, "give either at_targets (one part per target, labelled like it) or at and label")
            if targets is None:
                _fail(f"{key}.at_targets", "needs the scenario's targets")
            names = item["at_targets"]
            if names == "all":
                names = list(targets)
            if not isinstance(names, list) or not names or not all(isinstance(n, str) for n in names):
                _fail(f"{key}.at_targets", 'expected "all" or a list of target labels')
            for name in names:
                if name not in targets:
                    _fail(f"{key}.at_targets", f"{short_token(name, 20)} is not a target label")
            offset = rotation @ _vector(item.get("offset", [0, 0, 0]), f"{key}.offset")  # in the part's frame
            placements = [(name, np.asarray(targets[name], dtype=float)[:3] + offset) for name in names]
        else:
            if "offset" in item:
                _fail(f"{key}.offset", "only with at_targets")
            label = item.get("label")
            if not isinstance(label, str) or not label:
                _fail(f"{key}.label", "expected a non-empty string")
            placements = [(label, _vector(item.get("at"), f"{key}.at"))]
        spec = {k: v for k, v in item.items() if k not in _COMMON_KEYS}
        for label, at in placements:
            extra = {"rotation": item["rotation"]} if "rotation" in item else {}
            parts.append(Part(label, kind, {"type": kind, "label": label, "at": at.tolist(), **extra, **spec},
                              _part_solids(label, kind, at, spec, key, rotation)))
    seen = set()
    for part in parts:
        if part.label in seen:
            _fail("scene.parts", f"two parts are labelled {short_token(part.label, 20)}")
        seen.add(part.label)
    return parts


# ---------------------------------------------------------------------------------------------
# Distances
# ---------------------------------------------------------------------------------------------
def _cylinder_box_bounds(points: np.ndarray, radius: float, length: float, lower: np.ndarray,
                         upper: np.ndarray) -> np.ndarray:
    """Exact distance from the vertical tool cylinder at each point to each axis-aligned box,
    (m, k): a lower bound of the distance to whatever the box bounds (0 when they overlap)."""
    gap_xy = np.maximum(np.maximum(lower[None, :, :2] - points[:, None, :2], points[:, None, :2] - upper[None, :, :2]), 0.0)
    lateral = np.maximum(np.sqrt(np.einsum("mkj,mkj->mk", gap_xy, gap_xy)) - radius, 0.0)
    vertical = np.maximum(np.maximum(lower[None, :, 2] - (points[:, None, 2] + length), points[:, None, 2] - upper[None, :, 2]), 0.0)
    return np.hypot(lateral, vertical)


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

    @property
    def collision_free(self) -> bool:
        return not self.distance < 0.0

    @property
    def collision_part(self) -> str | None:
        """The part hit, or None when the motion is collision-free."""
        return None if self.collision_free else self.part


class _Distances:
    """coal objects of the tool and the solids, and one reusable request."""

    def __init__(self, solids: tuple, tool: Tool):
        coal = _coal()
        self.coal = coal
        self.request = coal.DistanceRequest()
        self.request.gjk_tolerance = _GJK_TOLERANCE
        self.request.gjk_max_iterations = 1000
        self.request.epa_tolerance = _EPA_TOLERANCE
        self.result = coal.DistanceResult()
        self.tool = coal.Cylinder(tool.radius, tool.length)
        self.tool_offset = np.array([0.0, 0.0, tool.length / 2.0])
        self.shapes = []
        for solid in solids:
            if solid.kind == "box":
                shape = coal.Box(*solid.params)
            elif solid.kind == "cylinder":
                shape = coal.Cylinder(*solid.params)
            else:
                vertices = coal.StdVec_Vec3s()
                for vertex in solid.params[0]:
                    vertices.append(np.asarray(vertex, dtype=float))
                shape = coal.Convex.convexHull(vertices, False, "")
            self.shapes.append((shape, coal.Transform3s(np.asarray(solid.rotation, dtype=float), np.asarray(solid.centre, dtype=float))))
        self.identity = np.eye(3)

    def tool_to(self, point: np.ndarray, index: int, rotation: np.ndarray | None = None) -> float:
        """Signed distance from the tool at ``point`` to solid ``index``; ``rotation`` (3, 3) is
        the tool frame (its z axis the approach direction; default pointing down)."""
        shape, pose = self.shapes[index]
        self.result.clear()
        if rotation is None:
            tool_pose = self.coal.Transform3s(self.identity, np.asarray(point, dtype=float) + self.tool_offset)
        else:  # the body extends from the mouth against the approach direction
            centre = np.asarray(point, dtype=float) - rotation[:, 2] * self.tool_offset[2]
            tool_pose = self.coal.Transform3s(np.asarray(rotation, dtype=float), centre)
        return self._checked(float(self.coal.distance(self.tool, tool_pose, shape, pose, self.request, self.result)))

    def _checked(self, distance: float) -> float:
        # EPA that does not converge reports -DBL_MAX; a contact is certain then, its depth is not.
        if not math.isfinite(distance) or distance < -1e100:
            raise ValueError("coal could not compute a penetration depth (EPA did not converge)")
        return distance

    def between(self, first: int, second: int) -> float:
        a, pose_a = self.shapes[first]
        b, pose_b = self.shapes[second]
        self.result.clear()
        return self._checked(float(self.coal.distance(a, pose_a, b, pose_b, self.request, self.result)))


def _densify(points: np.ndarray, step: float, segments: np.ndarray | None = None, weights: bool = False):
    """Points along the polyline through ``points`` no more than ``step`` apart: of every segment
    (``segments`` None), or of the segments whose indices are given (each with both its ends).
    ``weights``: also return each point's segment index and fraction along it (to interpolate
    anything else given at ``points`` the same way)."""
    if points.shape[0] == 1 or (segments is not None and segments.size == 0):
        dense = points.copy() if points.shape[0] == 1 else points[:0]
        return (dense, np.zeros(len(dense), dtype=np.int64), np.zeros(len(dense))) if weights else dense
    if segments is None:
        segments = np.arange(points.shape[0] - 1)
    starts, ends = points[segments], points[segments + 1]
    pieces = np.maximum(np.ceil(np.linalg.norm(ends - starts, axis=1) / step).astype(np.int64), 1) + 1
    total = int(pieces.sum())
    if total > get_limits().max_samples * 4:
        raise ValueError(f"the trajectory needs {total:,} checks at steps of {step:g}; use a larger step")
    which = np.repeat(np.arange(segments.size), pieces)
    first = np.concatenate([[0], np.cumsum(pieces)[:-1]])
    fraction = (np.arange(total) - np.repeat(first, pieces)) / np.repeat(pieces - 1, pieces)
    dense = starts[which] + fraction[:, None] * (ends[which] - starts[which])
    return (dense, segments[which], fraction) if weights else dense


def _box_distance(lower_a: np.ndarray, upper_a: np.ndarray, lower_b: np.ndarray, upper_b: np.ndarray) -> np.ndarray:
    """Distance between axis-aligned boxes, broadcast over leading axes."""
    gap = np.maximum(np.maximum(lower_b - upper_a, lower_a - upper_b), 0.0)
    return np.sqrt(np.sum(gap * gap, axis=-1))


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

    def __init__(self, parts, tool: Tool, targets=None, targets_on_parts: bool = True):
        self.parts = tuple(parts)
        self.tool = tool
        self.targets = None if targets is None else list(targets)
        self.targets_on_parts = bool(targets_on_parts)
        self.solids = tuple(solid for part in self.parts for solid in part.solids)
        self._lower = np.array([s.lower for s in self.solids]).reshape(-1, 3)
        self._upper = np.array([s.upper for s in self.solids]).reshape(-1, 3)
        self._owner = np.array([s.part for s in self.solids], dtype=object)
        self._distances = None

    # -- construction ------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data, targets: dict | None = None) -> Scene:
        """Build and validate a scene from its JSON data; ``targets`` ({label: point}) resolves
        ``at_targets`` and is checked against ``targets_on_parts``. Raises :class:`SceneError`
        (a ``ValueError``) naming the key for malformed data, overlapping parts, a target not on
        its part or a tool of zero size."""
        if not isinstance(data, dict):
            _fail("scene", "expected an object with tool and parts")
        unknown = sorted(set(data) - _SCENE_KEYS)
        if unknown:
            _fail(f"scene.{short_token(unknown[0], 20)[1:-1]}", f"unknown key (known: {', '.join(sorted(_SCENE_KEYS))})")
        tool_data = data.get("tool")
        if not isinstance(tool_data, dict) or set(tool_data) != {"radius", "length"}:
            _fail("scene.tool", 'expected {"radius": r, "length": l} (a cylinder hanging from the trajectory point)')
        tool = Tool(*(_number(tool_data[k], f"scene.tool.{k}") for k in ("radius", "length")))
        parts = _parse_parts(data.get("parts"), targets)
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
        scene = cls(parts, tool, chosen, on_parts)
        scene.check_overlaps()
        if targets is not None and on_parts:
            scene.check_targets(targets)
        return scene

    def to_dict(self) -> dict:
        out = {"tool": self.tool.to_dict(), "parts": [dict(part.spec) for part in self.parts],
               "targets_on_parts": self.targets_on_parts}
        if self.targets is not None:
            out["targets"] = list(self.targets)
        return out

    @property
    def labels(self) -> list[str]:
        return [part.label for part in self.parts]

    def part(self, label: str) -> Part:
        for part in self.parts:
            if part.label == label:
                return part
        raise KeyError(f"no part labelled {label!r}")

    def applies_to(self, label: str) -> bool:
        """Whether target ``label`` is checked against this scene."""
        return self.targets is None or label in self.targets

    def bounds(self, part: str) -> tuple[np.ndarray, np.ndarray]:
        """Axis-aligned bounding box (lower, upper) of a part's solids."""
        mask = self._owner == part
        return self._lower[mask].min(axis=0), self._upper[mask].max(axis=0)

    def target_parts(self, label: str, point) -> list[str]:
        """The parts that enter the tool at target ``label`` (excepted from its clearance): the
        part labelled like it, else whatever the tool takes into its mouth at ``point``."""
        return [label] if label in self.labels else self.parts_at(point)

    def parts_at(self, point) -> list[str]:
        """Labels of the parts the tool would take into its mouth at ``point``: those whose
        bounding box is within the tool radius of the point."""
        point = np.asarray(point, dtype=float)[:3]
        gap = np.maximum(np.maximum(self._lower - point, point - self._upper), 0.0)
        near = np.linalg.norm(gap, axis=1) <= self.tool.radius
        return list(dict.fromkeys(self._owner[near]))

    # -- validation ---------------------------------------------------------------------------
    def check_overlaps(self) -> None:
        """Raise when solids of two different parts interpenetrate (touching is allowed)."""
        gap = np.maximum(np.maximum(self._lower[:, None] - self._upper[None], self._lower[None] - self._upper[:, None]), 0.0)
        close = np.argwhere(np.triu(np.all(gap == 0.0, axis=2), 1))
        for first, second in close:
            if self._owner[first] == self._owner[second]:
                continue
            depth = self._engine().between(int(first), int(second))
            if depth < -_OVERLAP_TOLERANCE:
                _fail("scene.parts", f"parts {self.solids[first].label!r} and {self.solids[second].label!r} overlap "
                                     f"by {-depth:.3g}; parts may touch but not interpenetrate")

    def check_targets(self, targets: dict) -> None:
        """Raise when a target the scene applies to has no part with its label, or does not lie
        on it (more than the tool radius from the part's bounding box)."""
        for label, point in targets.items():
            point = np.asarray(point, dtype=float)[:3]  # a pose target: its position
            if not self.applies_to(label):
                continue
            if label not in self.labels:
                _fail("scene", f"target {short_token(label, 20)} has no part labelled like it (targets_on_parts is "
                               f"true; set it false, or list the targets the scene applies to in scene.targets)")
            lower, upper = self.bounds(label)
            gap = np.linalg.norm(np.maximum(np.maximum(lower - point, np.asarray(point) - upper), 0.0))
            if gap > self.tool.radius:
                _fail("scene", f"target {short_token(label, 20)} at {np.round(point, 3).tolist()} is not on part "
                               f"{short_token(label, 20)} (its box spans {np.round(lower, 3).tolist()} to "
                               f"{np.round(upper, 3).tolist()}, {gap:.3g} away)")

    # -- distances ----------------------------------------------------------------------------
    def _engine(self) -> _Distances:
        if self._distances is None:
            self._distances = _Distances(self.solids, self.tool)
        return self._distances

    def _selected(self, exclude) -> np.ndarray:
        exclude = set([exclude] if isinstance(exclude, str) else (exclude or ()))
        unknown = exclude - set(self._owner.tolist())
        if unknown:
            raise ValueError(f"exclude names {sorted(unknown)[0]!r}, which is not a part of the scene")
        return np.flatnonzero([owner not in exclude for owner in self._owner])

    def _minimum(self, samples: np.ndarray, chosen: np.ndarray, bounds_of, exact, best: float = math.inf,
                 part: str | None = None, point=None) -> Clearance:
        """Branch and bound over (sample, part) pairs: ``bounds_of(rows)`` bounds the distances of
        ``samples[rows]`` to the chosen parts from below, (m, k); ``exact(row, solid)`` is coal's
        distance. Pairs are evaluated in ascending bound until no bound can beat the best."""
        for start in range(0, samples.shape[0], _CHUNK):
            block = np.arange(start, min(start + _CHUNK, samples.shape[0]))
            bounds = bounds_of(block)
            if best == math.inf:  # seed the bound with the most promising pair
                row, col = divmod(int(np.argmin(bounds)), bounds.shape[1])
                best, part, point = exact(block[row], int(chosen[col])), self.solids[chosen[col]].label, samples[block[row]]
            # The bounds are >= 0, so a pair whose bound is 0 may penetrate to any depth: while the
            # best is a collision, every overlapping pair is evaluated to find the deepest one.
            rows, cols = np.nonzero((bounds < best) | (bounds <= 0.0))
            for at in np.argsort(bounds[rows, cols], kind="stable"):
                row, col = rows[at], cols[at]
                if bounds[row, col] > 0.0 and bounds[row, col] >= best:
                    break  # every remaining pair is bounded below by at least the best so far
                distance = exact(block[row], int(chosen[col]))
                if distance < best:
                    best, part, point = distance, self.solids[chosen[col]].label, samples[block[row]]
        return Clearance(float(best), part, None if point is None else np.array(point))

    def _clearance_oriented(self, points: np.ndarray, quaternions, chosen: np.ndarray, step: float) -> Clearance:
        """:meth:`clearance` for a tool whose orientation changes along the motion."""
        from scipy.spatial.transform import Rotation

        q = np.asarray(quaternions, dtype=float)
        if q.shape != (points.shape[0], 4) or not np.all(np.isfinite(q)) or np.any(np.linalg.norm(q, axis=1) < 1e-9):
            raise ValueError(f"orientations must be {points.shape[0]} finite, non-zero quaternions (x, y, z, w)")
        q = continuous_quaternions(q / np.linalg.norm(q, axis=1, keepdims=True))
        dense, segment, fraction = _densify(points, step, weights=True)
        if points.shape[0] > 1:  # nlerp between samples at most ``step`` apart
            dense_q = q[segment] + fraction[:, None] * (q[segment + 1] - q[segment])
            dense_q /= np.linalg.norm(dense_q, axis=1, keepdims=True)
        else:
            dense_q = q
        rotations = Rotation.from_quat(dense_q).as_matrix()
        axes = rotations[:, :, 2]
        centres = dense - axes * self.tool.length / 2.0
        extent = _cylinder_extent(axes, self.tool.radius, self.tool.length / 2.0)
        lower, upper = self._lower[chosen], self._upper[chosen]
        engine = self._engine()
        return self._minimum(
            dense, chosen,
            lambda rows: _box_distance((centres[rows] - extent[rows])[:, None], (centres[rows] + extent[rows])[:, None],
                                       lower[None], upper[None]),
            lambda row, solid: engine.tool_to(dense[row], solid, rotations[row]))

    @numerically_guarded
    def clearance(self, trajectory, exclude=(), step: float = _DEFAULT_STEP, orientations=None) -> Clearance:
        """Smallest signed distance between the tool and the parts along ``trajectory``.

        Parameters
        ----------
        trajectory : array (n, 3)
            Tool-centre points; the tool moves in straight lines between them.
        exclude : str or iterable of str
            Part labels not checked (the target: it enters the socket).
        step : float, default 0.2
            The tool is placed at least every ``step`` along the path (scene unit).
        orientations : array (n, 4), optional
            The tool frame at each point (quaternions x, y, z, w; the frame's z axis is the
            approach direction, the tool's body extends against it). Default: pointing down.

        Returns
        -------
        Clearance
            The exact minimum over those placements (coal, 1e-8), with the part and point.
        """
        points = as_trajectory(trajectory, "trajectory", min_points=1, allow_static=True)
        if points.shape[1] != 3:
            raise ValueError(f"trajectory must have 3 columns (x, y, z), got {points.shape[1]}")
        step = check_real(step, "step", positive=True)
        chosen = self._selected(exclude)
        if chosen.size == 0:
            return Clearance(math.inf, None, None)
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
        at_samples = _cylinder_box_bounds(points, radius, length, whole_lower[None], whole_upper[None])[:, 0]
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
        return self._minimum(dense, chosen, lambda rows: _cylinder_box_bounds(dense[rows], radius, length, lower, upper),
                             lambda row, solid: engine.tool_to(dense[row], solid), best, best_part, best_point)

    def checker(self, exclude=()) -> SceneChecker:
        """The roadmap's collision callback for this scene (parts in ``exclude`` ignored)."""
        return SceneChecker(self, self._selected(exclude))


class SceneChecker:
    """Collision callback for :func:`bidmp.roadmap.gaussian_prm`: ``checker(points)`` says which
    tool placements are free, :meth:`segments_free` which straight tool moves are."""

    def __init__(self, scene: Scene, chosen: np.ndarray):
        self.scene = scene
        self.chosen = chosen

    def __call__(self, points) -> np.ndarray:
        points = np.asarray(points, dtype=float).reshape(-1, 3)
        free = np.ones(points.shape[0], dtype=bool)
        if self.chosen.size == 0:
            return free
        scene = self.scene
        engine = scene._engine()
        lower, upper = scene._lower[self.chosen], scene._upper[self.chosen]
        radius, length = scene.tool.radius, scene.tool.length
        whole = _cylinder_box_bounds(points, radius, length, lower.min(axis=0)[None], upper.max(axis=0)[None])[:, 0]
        near = np.flatnonzero(whole <= 0.0)
        for start in range(0, near.size, _CHUNK):
            rows = near[start : start + _CHUNK]
            bounds = _cylinder_box_bounds(points[rows], radius, length, lower, upper)
            for row, col in zip(*np.nonzero(bounds <= 0.0)):
                index = rows[row]
                if free[index] and engine.tool_to(points[index], int(self.chosen[col])) < 0.0:
                    free[index] = False
        return free

    def segments_free(self, a, b) -> np.ndarray:
        """Whether the tool moving straight from ``a[i]`` to ``b[i]`` touches no part, (M,) bool.

        Conservative advancement: the distance to a part changes by at most the distance moved,
        so the tool may advance by its current clearance without missing a contact."""
        a = np.asarray(a, dtype=float).reshape(-1, 3)
        b = np.asarray(b, dtype=float).reshape(-1, 3)
        free = np.ones(a.shape[0], dtype=bool)
        if self.chosen.size == 0 or a.shape[0] == 0:
            return free
        scene = self.scene
        radius, length = scene.tool.radius, scene.tool.length
        lo = np.minimum(a, b) - [radius, radius, 0.0]
        hi = np.maximum(a, b) + [radius, radius, length]
        lower, upper = scene._lower[self.chosen], scene._upper[self.chosen]
        # The swept tool's box against the box around all parts first, then part by part.
        near = np.flatnonzero(np.all((hi >= lower.min(axis=0)) & (lo <= upper.max(axis=0)), axis=1))
        touching = np.all((hi[near, None] >= lower[None]) & (lo[near, None] <= upper[None]), axis=2)
        candidates = [(near[i], j) for i, j in zip(*np.nonzero(touching))]
        engine = scene._engine()
        for row, col in candidates:
            if free[row] and not self._move_free(engine, a[row], b[row], int(self.chosen[col])):
                free[row] = False
        return free

    @staticmethod
    def _move_free(engine: _Distances, a: np.ndarray, b: np.ndarray, index: int) -> bool:
        length = float(np.linalg.norm(b - a))
        travelled = 0.0
        resolution = 1e-9 * max(length, 1.0)
        for _ in range(_MAX_ADVANCE_STEPS):
            distance = engine.tool_to(a + (travelled / length) * (b - a) if length > 0 else a, index)
            if distance < 0.0:
                return False
            if travelled >= length:
                return True
            travelled = min(travelled + max(distance, resolution), length)  # touching is allowed
        return False  # grazing for too long: treated as a contact (conservative)

