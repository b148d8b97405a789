"""Unit quaternions and rotation vectors for pose skills.

Quaternions are ``(x, y, z, w)``, scalar last, as in SciPy and PyBullet; angles in radians.

The orientation DMP runs on rotation vectors ``e = Log(q ⊗ g⁻¹)``. SciPy's ``as_rotvec`` returns
the principal value (angle in [0, π]), which wraps: a 270° turn about the tool axis comes back as
90° the other way, and a 360° turn as none at all. :func:`continuous_log` instead picks, sample
by sample, the equivalent rotation vector ``(θ + 2πk) n`` nearest its neighbour, so a
demonstration of several turns (a nut run off its stud) keeps its whole angle.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from .._checks import _as_bounded_array, _check_magnitude, check_limit
from .._kernels import quaternion_exp, quaternion_log
from .._norms import tamed_rows
from .._trajectory import continuous_quaternions

__all__ = [
    "as_quaternions",
    "principal_log",
    "continuous_log",
    "angle_between",
    "orientation_from_log",
]

# a quaternion further than this from unit length is normalised, with a warning
_NORM_TOLERANCE = 1e-6
# below this angle (rad) a rotation's axis is noise: the neighbour's axis is kept
_AXIS_FLOOR = 1e-6
_TWO_PI = 2.0 * math.pi


def as_quaternions(q, name: str = "q") -> np.ndarray:
    """Validate quaternions ``(n, 4)`` (x, y, z, w): finite, not zero; non-unit ones are
    normalised with a warning; signs made continuous. ``name``: the argument's name in messages."""
    if not isinstance(name, str) or not name or len(name) > 100:
        raise TypeError(
            f"name must be the argument's name (a short string), got {type(name).__name__}"
        )
    if isinstance(q, (str, bytes)):
        raise TypeError(f"{name} must be an array of numbers, got a string")
    # None, complex, objects and oversized arrays refused, naming the argument
    array = _as_bounded_array(q, name, 2)
    if array.ndim == 1:
        array = array[None]
    if array.ndim != 2 or array.shape[1] != 4 or array.shape[0] == 0:
        raise ValueError(f"{name} must have shape (n, 4) (qx, qy, qz, qw), got {np.shape(q)}")
    check_limit(array.shape[0], "max_samples", f"{name}: the number of quaternions")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} contains NaN or inf")
    # Scaled by the largest component first, so that 1e200 and 1e-200 quaternions normalise too.
    largest = np.max(np.abs(array), axis=1, keepdims=True)
    if np.any(largest < 1e-300):
        raise ValueError(
            f"{name}: row {int(np.argmax(largest[:, 0] < 1e-300))} is a zero quaternion, which is no rotation"
        )
    scaled = array / largest
    norms = np.linalg.norm(scaled, axis=1) * largest[:, 0]
    if np.any(norms < 1e-9):
        raise ValueError(
            f"{name}: row {int(np.argmax(norms < 1e-9))} is a zero quaternion, which is no rotation"
        )
    off = np.abs(norms - 1.0) > _NORM_TOLERANCE
    if np.any(off):
        warnings.warn(
            f"{name}: {int(off.sum())} quaternion(s) were not of unit length (up to "
            f"{np.max(np.abs(norms - 1)):.3g} off) and were normalised",
            UserWarning,
            stacklevel=3,
        )
    return continuous_quaternions(scaled / np.linalg.norm(scaled, axis=1, keepdims=True))


def _quaternion_rows(q, name: str) -> np.ndarray:
    """Quaternions (n, 4) or one (4,) checked at the boundary: real, finite, not zero. Their values
    are left as given (SciPy normalises them), so a checked call computes what an unchecked one did."""
    array = np.atleast_2d(_as_bounded_array(q, name, 2))
    if array.ndim != 2 or array.shape[1] != 4 or array.shape[0] == 0:
        raise ValueError(
            f"{name} must have shape (n, 4) or (4,) (qx, qy, qz, qw), got {np.shape(q)}"
        )
    check_limit(array.shape[0], "max_samples", f"{name}: the number of quaternions")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} contains NaN or inf")
    # A row of 1e300 components overflows its norm to inf, one of 1e-300 underflows it to 0: such
    # rows are scaled by the power of two of their largest component (exact; the rotation is the
    # same). The others are left as given, bit for bit.
    array = tamed_rows(array)
    if np.any(np.linalg.norm(array, axis=1) == 0.0):
        raise ValueError(f"{name} contains a zero quaternion (no rotation has one)")
    return array


def _vector_rows(r, name: str) -> np.ndarray:
    """Rotation vectors (n, 3) or one (3,) (rad) checked at the boundary: real and finite."""
    array = np.atleast_2d(_as_bounded_array(r, name, 2))
    if array.ndim != 2 or array.shape[1] != 3 or array.shape[0] == 0:
        raise ValueError(
            f"{name} must have shape (n, 3) or (3,) (rotation vectors, rad), got {np.shape(r)}"
        )
    check_limit(array.shape[0], "max_samples", f"{name}: the number of rotation vectors")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} contains NaN or inf")
    _check_magnitude(array, name)  # rotations of 1e300 rad overflow the Jacobian's products
    return array


def principal_log(q, goal) -> np.ndarray:
    """Rotation vectors ``Log(q ⊗ goal⁻¹)`` (n, 3) with angles in [0, π] (SciPy's ``as_rotvec``)."""
    return _principal_log(q, goal, "q", "goal")


def _principal_log(q, goal, q_name: str, goal_name: str) -> np.ndarray:
    q, goal = _quaternion_rows(q, q_name), _quaternion_rows(goal, goal_name)
    if goal.shape[0] not in (1, q.shape[0]):
        raise ValueError(
            f"{goal_name} has {goal.shape[0]} quaternions; give one, or one per row of {q_name} ({q.shape[0]})"
        )
    # (Rotation.from_quat(q) * Rotation.from_quat(goal).inv()).as_rotvec(), SciPy's arithmetic
    # in one compiled loop (Rotation's array dispatch costs 0.3 ms a product).
    return quaternion_log(q, goal)


def _angles_and_axes(vectors: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    angles = np.linalg.norm(vectors, axis=1)
    axes = np.divide(
        vectors, angles[:, None], out=np.zeros_like(vectors), where=angles[:, None] > _AXIS_FLOOR
    )
    return angles, axes


def continuous_log(q, goal) -> np.ndarray:
    """Rotation vectors ``Log(q ⊗ goal⁻¹)`` (n, 3), continuous along the sequence.

    The last sample keeps its principal value (0 when ``q[-1]`` is the goal); going back from
    it, every sample takes the equivalent ``(θ + 2πk) n`` nearest the one after it. Where a
    rotation is within 1e-6 rad of a whole number of turns its axis is undefined, and the axis
    of the sample after it is kept. Sequential by nature; a scalar loop (about 1 µs a sample).
    """
    principal = principal_log(q, goal)
    if (
        principal.shape[0] < 2
        or np.max(np.linalg.norm(np.diff(principal, axis=0), axis=1)) < 0.5 * math.pi
    ):
        return principal  # no jump anywhere: the principal values are already continuous
    angles, axes = _angles_and_axes(principal)
    n = angles.shape[0]
    signed = [0.0] * n
    out_axes = axes.tolist()
    angle_list = angles.tolist()
    signed[-1] = angle_list[-1]
    for index in range(n - 2, -1, -1):
        after = out_axes[index + 1]
        if angle_list[index] <= _AXIS_FLOOR:
            out_axes[index] = after
        axis = out_axes[index]
        alignment = axis[0] * after[0] + axis[1] * after[1] + axis[2] * after[2]
        wanted = signed[index + 1] * alignment  # the neighbour's vector projected on this axis
        signed[index] = angle_list[index] + _TWO_PI * math.floor(
            (wanted - angle_list[index]) / _TWO_PI + 0.5
        )
    return np.asarray(signed)[:, None] * np.asarray(out_axes)


def _nearest_turn(q, goal, reference: np.ndarray) -> np.ndarray:
    """``Log(q ⊗ goal⁻¹)`` for one quaternion ``q`` (4,), as the equivalent rotation vector nearest
    ``reference`` (3,): a start pose away from the demonstrated one turns to the goal the same way
    (and as many times) as the demonstration did."""
    reference = _vector_rows(reference, "reference")[0]
    angles, axes = _angles_and_axes(principal_log(_quaternion_rows(q, "q")[:1], goal))
    axis = axes[0]
    if angles[0] <= _AXIS_FLOOR:
        norm = float(np.linalg.norm(reference))
        if norm <= _AXIS_FLOOR:
            return angles[0] * axis
        axis = reference / norm
    wanted = float(axis @ reference)
    return (angles[0] + _TWO_PI * round((wanted - angles[0]) / _TWO_PI)) * axis


def angle_between(q, p) -> np.ndarray:
    """The angle (rad, in [0, π]) of the rotation between orientations ``q`` and ``p`` (n,)."""
    return np.linalg.norm(_principal_log(q, p, "q", "p"), axis=-1)


def _skew(v: np.ndarray) -> np.ndarray:
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2], out[..., 1, 2] = -v[..., 2], v[..., 1], -v[..., 0]
    out[..., 1, 0], out[..., 2, 0], out[..., 2, 1] = v[..., 2], -v[..., 1], v[..., 0]
    return out


def _left_jacobian(r: np.ndarray) -> np.ndarray:
    """Left Jacobian of SO(3), (n, 3, 3): ``ω = J_l(r) ṙ`` for ``R = Exp(r) G`` (world-frame ω).
    Valid for rotation vectors of any length (several turns)."""
    r = _vector_rows(r, "r")
    theta = np.linalg.norm(r, axis=1)
    small = theta < 1e-6
    safe = np.where(small, 1.0, theta)
    a = np.where(small, 0.5 - theta**2 / 24.0, (1.0 - np.cos(safe)) / safe**2)
    b = np.where(small, 1.0 / 6.0 - theta**2 / 120.0, (safe - np.sin(safe)) / safe**3)
    k = _skew(r)
    return np.eye(3) + a[:, None, None] * k + b[:, None, None] * (k @ k)


def orientation_from_log(error: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """Unit quaternions ``Exp(e) ⊗ goal`` (n, 4), signs continuous."""
    error, goal = _vector_rows(error, "error"), _quaternion_rows(goal, "goal")
    if goal.shape[0] not in (1, error.shape[0]):
        raise ValueError(
            f"goal has {goal.shape[0]} quaternions; give one, or one per row of error ({error.shape[0]})"
        )
    # (Rotation.from_rotvec(error) * Rotation.from_quat(goal)).as_quat(), SciPy's arithmetic in
    # one compiled loop.
    q = quaternion_exp(error, goal)
    return continuous_quaternions(q / np.linalg.norm(q, axis=1, keepdims=True))
