"""Scene parts and the tool: what a scenario's ``"scene"`` block describes, parsed and checked.

Scene data (``Scene.from_dict``, the ``"scene"`` key of a scenario), lengths in the scenario's
unit, angles in degrees::

    {"tool": {"radius": 12.5, "length": 100},
     "targets": "all" | [labels],       # targets the geometry applies to (default all)
     "targets_on_parts": true,          # each of them must lie on the part with its label
     "margin": 0,                       # clearance kept from every part but the target's
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

from .._checks import as_point, as_rotation, get_limits, short_token

__all__ = ["PART_TYPES", "SceneError", "Tool", "Solid", "Part"]

logger = logging.getLogger(__name__)

PART_TYPES = ("box", "cell", "cylinder", "nut", "plate")


_PART_KEYS = {
    "box": {"size", "yaw"},
    "cell": {"size", "yaw"},
    "plate": {"size", "yaw"},
    "cylinder": {"radius", "height"},
    "nut": {"across_flats", "height", "stud", "yaw"},
}


_COMMON_KEYS = {"type", "label", "at", "at_targets", "offset", "rotation"}


class SceneError(ValueError):
    """Malformed scene data; the message names the key."""


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
            if (
                isinstance(value, bool)
                or not isinstance(value, Real)
                or not _finite(value)
                or value <= 0
            ):
                raise SceneError(
                    f"tool.{name} must be a positive number, got {short_token(value, 20)}"
                )
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

    def moved(self, centre, rotation) -> Solid:
        """The same solid with its centre at ``centre`` (3,) and turned to ``rotation`` (3, 3): a
        part the tool carries, where it is now."""
        centre, rotation = as_point(centre, 3, "centre"), as_rotation(rotation, "rotation")
        if self.kind == "box":
            half = np.asarray(self.params, dtype=float) / 2.0
            extent = np.abs(rotation) @ half
        elif self.kind == "cylinder":
            extent = _cylinder_extent(rotation[:, 2], self.params[0], self.params[1] / 2.0)
        else:
            vertices = np.asarray(self.params[0], dtype=float) @ rotation.T
            extent = np.max(np.abs(vertices), axis=0)
        return Solid(
            self.label,
            self.part,
            self.kind,
            centre,
            rotation,
            self.params,
            centre - extent,
            centre + extent,
        )


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
    return Solid(
        label,
        part,
        "box",
        centre,
        rotation,
        tuple(float(v) for v in size),
        *_bounds(corners @ rotation.T + centre),
    )


def _cylinder_extent(axis: np.ndarray, radius: float, half_height: float) -> np.ndarray:
    """Half-extents of the axis-aligned box around a cylinder with unit ``axis``."""
    return np.abs(axis) * half_height + radius * np.sqrt(np.clip(1.0 - axis**2, 0.0, 1.0))


def _cylinder_solid(label, part, centre, radius, height, rotation) -> Solid:
    extent = _cylinder_extent(rotation[:, 2], radius, height / 2.0)
    return Solid(
        label,
        part,
        "cylinder",
        centre,
        rotation,
        (float(radius), float(height)),
        centre - extent,
        centre + extent,
    )


def _hex_solid(label, part, centre, across_flats, height, rotation) -> Solid:
    corner = across_flats / math.sqrt(3.0)  # circumradius of the hexagon
    angles = np.deg2rad(np.arange(6) * 60.0)
    ring = np.column_stack([corner * np.cos(angles), corner * np.sin(angles), np.zeros(6)])
    vertices = np.vstack([ring + [0, 0, -height / 2.0], ring + [0, 0, height / 2.0]])
    return Solid(
        label,
        part,
        "convex",
        centre,
        rotation,
        (vertices,),
        *_bounds(vertices @ rotation.T + centre),
    )


# ---------------------------------------------------------------------------------------------
# Parsing
# ---------------------------------------------------------------------------------------------
def _fail(key: str, message: str):
    raise SceneError(f"{key}: {message}")


def _finite(value) -> bool:
    """Whether a real number is finite as a float (an integer of 400 digits is not)."""
    try:
        return math.isfinite(float(value))
    except OverflowError:
        return False


def _number(value, key, *, positive=True) -> float:
    if isinstance(value, bool) or not isinstance(value, Real) or not _finite(value):
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

        return Rotation.from_euler(
            "xyz", _vector(spec["rotation"], f"{key}.rotation"), degrees=True
        ).as_matrix()
    return _rotation_z(math.radians(_number(spec.get("yaw", 0.0), f"{key}.yaw", positive=False)))


def _part_solids(
    label: str, kind: str, at: np.ndarray, spec: dict, key: str, rotation: np.ndarray
) -> tuple:
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
        if (
            not isinstance(stud, dict)
            or set(stud) - {"radius", "above"}
            or not {"radius", "above"} <= set(stud)
        ):
            _fail(
                f"{key}.stud",
                'expected {"radius": r, "above": h} (the stud sticks out h over the nut)',
            )
        radius = _number(stud["radius"], f"{key}.stud.radius")
        above = _number(stud["above"], f"{key}.stud.above")
        if radius >= across / 2.0:
            _fail(
                f"{key}.stud.radius",
                f"{radius:g} does not fit inside the nut ({across:g} across flats)",
            )
        total = height + above
        solids.append(
            _cylinder_solid(f"{label}/stud", label, at + up * total / 2.0, radius, total, rotation)
        )
    return tuple(solids)


def _parse_parts(items, targets: dict | None) -> list[Part]:  # noqa: C901 - one branch per documented option or part kind, each a line
    if not isinstance(items, list) or not items:
        _fail("scene.parts", "expected a non-empty list of parts")
    parts: list[Part] = []
    for index, item in enumerate(items):
        key = f"scene.parts[{index}]"
        if not isinstance(item, dict):
            _fail(key, "expected an object")
        kind = item.get("type")
        if kind not in PART_TYPES:
            _fail(
                f"{key}.type",
                f"unknown part type {short_token(kind, 20)} (known: {', '.join(PART_TYPES)})",
            )
        rotation = _part_rotation(item, key)
        unknown = sorted(set(item) - _COMMON_KEYS - _PART_KEYS[kind])
        if unknown:
            _fail(
                f"{key}.{short_token(unknown[0], 20)[1:-1]}",
                f"unknown key for a {kind} (known: {', '.join(sorted(_COMMON_KEYS | _PART_KEYS[kind]))})",
            )
        if "at_targets" in item:
            if "at" in item or "label" in item:
                _fail(
                    key,
                    "give either at_targets (one part per target, labelled like it) or at and label",
                )
            if targets is None:
                _fail(f"{key}.at_targets", "needs the scenario's targets")
            names = item["at_targets"]
            if names == "all":
                names = list(targets)
            if (
                not isinstance(names, list)
                or not names
                or not all(isinstance(n, str) for n in names)
            ):
                _fail(f"{key}.at_targets", 'expected "all" or a list of target labels')
            for name in names:
                if name not in targets:
                    _fail(f"{key}.at_targets", f"{short_token(name, 20)} is not a target label")
            # in the part's frame
            offset = rotation @ _vector(item.get("offset", [0, 0, 0]), f"{key}.offset")
            placements = [
                (name, np.asarray(targets[name], dtype=float)[:3] + offset) for name in names
            ]
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
            parts.append(
                Part(
                    label,
                    kind,
                    {"type": kind, "label": label, "at": at.tolist(), **extra, **spec},
                    _part_solids(label, kind, at, spec, key, rotation),
                )
            )
    seen = set()
    for part in parts:
        if part.label in seen:
            _fail("scene.parts", f"two parts are labelled {short_token(part.label, 20)}")
        seen.add(part.label)
    return parts
