"""Small trajectory helpers used across the library, in one place.

Arc length, resampling (by time or by arc length), column-wise interpolation, RMSE and extent.
Arrays are float64 of shape (T, D); lengths are in the trajectory's own unit.
"""

from __future__ import annotations

import numpy as np

from ._checks import numerically_guarded
from ._kernels import arclength as _arclength
from ._kernels import interp_columns as _interp_columns
from ._savgol import savgol_filter

# NumPy sums a row of this many squares or more pairwise (in blocks of eight), not in order: such
# rows stay with NumPy, so an arc length is the same to the bit either way.
_PAIRWISE_COLUMNS = 8

__all__ = [
    "arclength",
    "savgol_filter",
    "interp_columns",
    "resample_arclength",
    "resample_time",
    "rmse",
    "path_extent",
    "continuous_quaternions",
]


def arclength(y: np.ndarray) -> np.ndarray:
    """Cumulative arc length at each sample, shape (T,), starting at 0 (``y`` (T, D))."""
    y = np.asarray(y, dtype=np.float64)
    if y.ndim == 2 and y.shape[0] > 0 and 0 < y.shape[1] < _PAIRWISE_COLUMNS:
        return _arclength(y)  # one compiled pass; a fit measures two paths (24 µs each in NumPy)
    steps = np.linalg.norm(np.diff(y, axis=0), axis=1)
    return np.concatenate([[0.0], np.cumsum(steps)])


def interp_columns(x_new: np.ndarray, x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Piecewise-linear interpolation of every column of ``y`` (n, D) from ``x`` (n,) to
    ``x_new`` (m,); returns (m, D). ``x`` must be increasing. ``np.interp`` of each column, to the
    bit, in one compiled scan."""
    return _interp_columns(
        np.asarray(x_new, dtype=np.float64),
        np.asarray(x, dtype=np.float64),
        np.asarray(y, dtype=np.float64),
    )


def resample_arclength(y, n_points: int) -> np.ndarray:
    """Resample a polyline to ``n_points`` points equally spaced in arc length (ends kept exactly).

    Repeated points (zero-length steps) are skipped, so a robot that paused is not a problem.
    """
    y = np.asarray(y, dtype=np.float64)
    s = arclength(y)
    moving = np.concatenate([[True], np.diff(s) > 0])
    y, s = y[moving], s[moving]
    if s[-1] <= 0.0:
        return np.repeat(y[:1], n_points, axis=0)
    out = interp_columns(np.linspace(0.0, s[-1], n_points), s, y)
    out[0], out[-1] = y[0], y[-1]
    return out


def resample_time(y, n_samples: int) -> np.ndarray:
    """Resample a trajectory that is uniform in time to ``n_samples`` uniform samples (ends kept)."""
    y = np.asarray(y, dtype=np.float64)
    if y.shape[0] == n_samples:
        return y.copy()
    out = interp_columns(np.linspace(0.0, 1.0, n_samples), np.linspace(0.0, 1.0, y.shape[0]), y)
    out[0], out[-1] = y[0], y[-1]
    return out


@numerically_guarded
def rmse(a, b) -> float:
    """Root-mean-square Euclidean distance between two trajectories of equal shape (T, D)."""
    from ._checks import as_trajectory

    # sizes, types and finiteness checked by name
    a = as_trajectory(a, "a", min_points=1, allow_static=True)
    b = as_trajectory(b, "b", min_points=1, allow_static=True)
    if a.shape != b.shape:
        raise ValueError(
            f"a has shape {a.shape} but b has {b.shape}: rmse compares trajectories of equal shape"
        )
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=-1))))


@numerically_guarded
def path_extent(y) -> float:
    """Diagonal of the axis-aligned bounding box of a trajectory (same unit as ``y``)."""
    from ._checks import as_trajectory

    y = as_trajectory(y, "y", min_points=1, allow_static=True)  # sizes bounded before any work
    return float(np.linalg.norm(np.ptp(y, axis=0)))


def continuous_quaternions(q: np.ndarray) -> np.ndarray:
    """Flip signs so that neighbouring quaternions (n, 4) lie in the same hemisphere (``q`` and
    ``-q`` are the same rotation; a recording that jumps between them would make ``Log`` jump,
    and interpolating across a flip would pass through zero)."""
    q = np.array(q, dtype=float)
    if q.shape[0] > 1:
        flips = np.cumsum(np.einsum("ij,ij->i", q[1:], q[:-1]) < 0.0) % 2
        q[1:][flips == 1] *= -1.0
    return q
