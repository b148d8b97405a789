"""Exact distances between the tool and the parts through coal (the maintained successor of FCL),
in the ``collision`` extra (``pip install 'bidmp[collision]'``), and the vectorised lower bounds
that decide which pairs coal is asked about.

Measured against closed forms (tests/scene/test_geometry.py), coal with a tightened GJK tolerance is
within 1e-8 of the exact clearance; python-fcl, whose GJK tolerance cannot be set from Python,
was up to 2e-3 off. Only lower bounds for culling are computed here (the exact distance from the
vertical tool cylinder to each part's axis-aligned bounding box, vectorised): a pair is sent to
coal only when its bound could beat the best distance found so far, so a trajectory needs a few
dozen coal calls, not one per sample and part.
"""

from __future__ import annotations

import logging
import math

import numpy as np

from .._checks import get_limits, require_extra
from .parts import Tool

logger = logging.getLogger(__name__)

# coal's default (1e-6 relative) leaves clearances ~1e-4 off; see the module docstring
_GJK_TOLERANCE = 1e-12


_EPA_TOLERANCE = 1e-6  # penetration depths (coal's default): tighter, its EPA stops early on cylinders and over-reports


_CHUNK = 8192  # samples per block of lower bounds (memory: _CHUNK x parts doubles)


_MAX_ADVANCE_STEPS = 10_000  # conservative advancement along one straight tool move


def _coal():
    return require_extra("coal", "collision", "scene geometry checks")


# ---------------------------------------------------------------------------------------------
# Distances
# ---------------------------------------------------------------------------------------------
def _cylinder_box_bounds(
    points: np.ndarray, radius: float, length: float, lower: np.ndarray, upper: np.ndarray
) -> np.ndarray:
    """Exact distance from the vertical tool cylinder at each point to each axis-aligned box,
    (m, k): a lower bound of the distance to whatever the box bounds (0 when they overlap)."""
    gap_xy = np.maximum(
        np.maximum(
            lower[None, :, :2] - points[:, None, :2], points[:, None, :2] - upper[None, :, :2]
        ),
        0.0,
    )
    lateral = np.maximum(np.sqrt(np.einsum("mkj,mkj->mk", gap_xy, gap_xy)) - radius, 0.0)
    vertical = np.maximum(
        np.maximum(
            lower[None, :, 2] - (points[:, None, 2] + length),
            points[:, None, 2] - upper[None, :, 2],
        ),
        0.0,
    )
    return np.hypot(lateral, vertical)


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
        self.shapes = [
            (
                self.shape_of(solid),
                coal.Transform3s(
                    np.asarray(solid.rotation, dtype=float), np.asarray(solid.centre, dtype=float)
                ),
            )
            for solid in solids
        ]
        self.identity = np.eye(3)

    def tool_to(self, point: np.ndarray, index: int, rotation: np.ndarray | None = None) -> float:
        """Signed distance from the tool at ``point`` to solid ``index``; ``rotation`` (3, 3) is
        the tool frame (its z axis the approach direction; default pointing down)."""
        shape, pose = self.shapes[index]
        self.result.clear()
        if rotation is None:
            tool_pose = self.coal.Transform3s(
                self.identity, np.asarray(point, dtype=float) + self.tool_offset
            )
        else:  # the body extends from the mouth against the approach direction
            centre = np.asarray(point, dtype=float) - rotation[:, 2] * self.tool_offset[2]
            tool_pose = self.coal.Transform3s(np.asarray(rotation, dtype=float), centre)
        return self._distance(self.tool, tool_pose, shape, pose)

    def _distance(self, a, pose_a, b, pose_b) -> float:
        """coal's signed distance, never an abort and never a wrong separation. GJK at the tight
        tolerance can end on a degenerate simplex when flat faces are parallel (a vertical tool
        beside a vertical post): coal then runs EPA on shapes that do not touch and reports
        -DBL_MAX, or (two vertical cylinders) returns the distance between "nearest points" that
        lie off the shapes: 1.96 for 16.90, 3.93 for 12.50 (tests/scene/test_geometry.py), and
        Nesterov-accelerated GJK repeats the second. So an answer is kept only when it is finite
        and, for a separation, both nearest points lie on their shapes that far apart; otherwise the query is
        repeated with Nesterov-accelerated GJK, then at looser tolerances (1e-10, 1e-9, coal's
        default 1e-6 relative), each within 1e-8 of the closed form where it passes. If none
        passes, the pair is answered conservatively (0: touching, so nothing is ever reported
        clearer than it is) and logged."""
        for (
            request
        ) in self._requests():  # into self.result: a caller reads the nearest points there
            self.result.clear()
            distance = float(self.coal.distance(a, pose_a, b, pose_b, request, self.result))
            if (
                math.isfinite(distance)
                and distance > -1e100
                and (distance <= 0.0 or self._witnessed(a, pose_a, b, pose_b, distance))
            ):
                return distance
        logger.warning(
            "coal could not compute a distance (GJK/EPA did not converge); the pair is taken as touching"
        )
        return 0.0

    def _witnessed(self, a, pose_a, b, pose_b, distance: float) -> bool:
        """Whether a separation ``distance`` is borne out by the nearest points in ``self.result``:
        each on its shape, and that far apart. Plain floats: it runs after every query of a
        conservative advancement (a route's edges ask hundreds of thousands), where NumPy's calls on
        three numbers cost more than coal's own answer."""
        first = self.result.getNearestPoint1().tolist()
        second = self.result.getNearestPoint2().tolist()
        apart = math.dist(first, second)
        return (
            abs(apart - distance) <= _ON_SHAPE * max(distance, 1.0)
            and _on_shape(a, pose_a, first)
            and _on_shape(b, pose_b, second)
        )

    def _requests(self) -> list:
        """The requests :meth:`_distance` tries in turn, built once."""
        if getattr(self, "_fallbacks", None) is None:
            coal = self.coal
            accelerated = coal.DistanceRequest()
            accelerated.gjk_tolerance, accelerated.gjk_max_iterations = _GJK_TOLERANCE, 1000
            accelerated.epa_tolerance, accelerated.gjk_variant = (
                _EPA_TOLERANCE,
                coal.GJKVariant.NesterovAcceleration,
            )
            looser = []
            for tolerance in (1e-10, 1e-9, None):
                request = coal.DistanceRequest()
                if tolerance is not None:
                    request.gjk_tolerance, request.gjk_max_iterations = tolerance, 1000
                request.epa_tolerance = _EPA_TOLERANCE
                looser.append(request)
            self._fallbacks = [self.request, accelerated, *looser]
        return self._fallbacks

    def shape_of(self, solid):
        """The coal shape of ``solid`` in its own frame (box, cylinder or convex hull of its vertices)."""
        coal = self.coal
        if solid.kind == "box":
            shape = coal.Box(*solid.params)
        elif solid.kind == "cylinder":
            shape = coal.Cylinder(*solid.params)
        else:
            vertices = coal.StdVec_Vec3s()
            for vertex in solid.params[0]:
                vertices.append(np.asarray(vertex, dtype=float))
            shape = coal.Convex.convexHull(vertices, False, "")
        return shape

    def body_to(self, shape, rotation: np.ndarray, centre: np.ndarray, index: int) -> float:
        """Signed distance from a moving body (``shape`` at ``centre``, turned by ``rotation``) to solid ``index``."""
        other, pose = self.shapes[index]
        return self._distance(
            shape,
            self.coal.Transform3s(
                np.asarray(rotation, dtype=float), np.asarray(centre, dtype=float)
            ),
            other,
            pose,
        )

    def between(self, first: int, second: int) -> float:
        a, pose_a = self.shapes[first]
        b, pose_b = self.shapes[second]
        return self._distance(a, pose_a, b, pose_b)


_ON_SHAPE = 1e-6  # relative to the shape's size: a nearest point this far outside it is not on it


def _on_shape(shape, pose, point) -> bool:
    """Whether ``point`` (world frame, three floats) lies in ``shape`` at ``pose`` (to
    :data:`_ON_SHAPE`): boxes and cylinders checked, other shapes taken as given."""
    # R^T (p - t), in plain floats (see _Distances._witnessed)
    tx, ty, tz = pose.getTranslation().tolist()
    (r00, r01, r02), (r10, r11, r12), (r20, r21, r22) = pose.getRotation().tolist()
    dx, dy, dz = point[0] - tx, point[1] - ty, point[2] - tz
    x = dx * r00 + dy * r10 + dz * r20
    y = dx * r01 + dy * r11 + dz * r21
    z = dx * r02 + dy * r12 + dz * r22
    half = getattr(shape, "halfSide", None)
    if half is not None:
        hx, hy, hz = half.tolist()
        slack = _ON_SHAPE * max(hx, hy, hz)
        return abs(x) <= hx + slack and abs(y) <= hy + slack and abs(z) <= hz + slack
    length = getattr(shape, "halfLength", None)
    if length is not None:
        slack = _ON_SHAPE * max(shape.radius, length)
        return math.hypot(x, y) <= shape.radius + slack and abs(z) <= length + slack
    return True


def _densify(
    points: np.ndarray,
    step: float,
    segments: np.ndarray | None = None,
    weights: bool = False,
    lengths: np.ndarray | None = None,
):
    """Points along the polyline through ``points`` no more than ``step`` apart: of every segment
    (``segments`` None), or of the segments whose indices are given (each with both its ends).
    ``weights``: also return each point's segment index and fraction along it (to interpolate
    anything else given at ``points`` the same way). ``lengths`` (one per segment of ``points``):
    how far each segment moves what is placed along it, when that is more than its chord (a tool
    that turns as it goes), in place of the chord."""
    if points.shape[0] == 1 or (segments is not None and segments.size == 0):
        dense = points.copy() if points.shape[0] == 1 else points[:0]
        return (
            (dense, np.zeros(len(dense), dtype=np.int64), np.zeros(len(dense)))
            if weights
            else dense
        )
    if segments is None:
        segments = np.arange(points.shape[0] - 1)
    starts, ends = points[segments], points[segments + 1]
    moved = np.linalg.norm(ends - starts, axis=1) if lengths is None else lengths[segments]
    pieces = np.maximum(np.ceil(moved / step).astype(np.int64), 1) + 1
    total = int(pieces.sum())
    if total > get_limits().max_samples * 4:
        raise ValueError(
            f"the trajectory needs {total:,} checks at steps of {step:g}; use a larger step"
        )
    which = np.repeat(np.arange(segments.size), pieces)
    first = np.concatenate([[0], np.cumsum(pieces)[:-1]])
    fraction = (np.arange(total) - np.repeat(first, pieces)) / np.repeat(pieces - 1, pieces)
    dense = starts[which] + fraction[:, None] * (ends[which] - starts[which])
    return (dense, segments[which], fraction) if weights else dense


def _box_distance(
    lower_a: np.ndarray, upper_a: np.ndarray, lower_b: np.ndarray, upper_b: np.ndarray
) -> np.ndarray:
    """Distance between axis-aligned boxes, broadcast over leading axes."""
    gap = np.maximum(np.maximum(lower_b - upper_a, lower_a - upper_b), 0.0)
    return np.sqrt(np.sum(gap * gap, axis=-1))
