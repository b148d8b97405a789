"""Input validation shared by every public entry point.

Every check raises ``TypeError`` (wrong kind of object) or ``ValueError`` (right kind, bad value)
with a message that names the argument and says what was wrong, so that the CLI can show it as a
one-line error.
"""

from __future__ import annotations

from collections.abc import Iterable
from numbers import Integral, Real

import numpy as np

__all__ = [
    "NotFittedError",
    "as_trajectory",
    "as_point",
    "as_points",
    "check_int",
    "check_real",
    "check_choice",
    "check_fitted",
]


class NotFittedError(ValueError, AttributeError):
    """Raised when a model is used before ``fit`` (same contract as scikit-learn's)."""


def _as_float_array(value, name: str) -> np.ndarray:
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{name} must be an array of numbers, got a string")
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise TypeError(f"{name} must be an array of numbers ({exc})") from None
    return array


def _check_finite(array: np.ndarray, name: str) -> None:
    if not np.all(np.isfinite(array)):
        bad = np.argwhere(~np.isfinite(array))[0]
        kind = "NaN" if np.isnan(array[tuple(bad)]) else "inf"
        where = f"row {bad[0]}" if array.ndim == 2 else f"index {tuple(int(b) for b in bad)}"
        raise ValueError(f"{name} contains {kind} (first at {where})")


def as_trajectory(y, name: str = "y", min_points: int = 3, allow_static: bool = False) -> np.ndarray:
    """Validate a trajectory and return it as a C-contiguous float64 array of shape (T, D).

    Raises
    ------
    TypeError
        If ``y`` is not numeric.
    ValueError
        If ``y`` is not 2-D, has fewer than ``min_points`` samples, contains NaN/inf, or all its
        points are identical (there is no motion to learn; allowed with ``allow_static``).
    """
    array = _as_float_array(y, name)
    if array.ndim != 2:
        hint = " (for a 1-D signal use shape (T, 1))" if array.ndim == 1 else ""
        raise ValueError(f"{name} must have shape (T, D), got an array with {array.ndim} dimension(s){hint}")
    n_points, n_dims = array.shape
    if n_dims < 1:
        raise ValueError(f"{name} must have at least one column (D >= 1), got shape {array.shape}")
    if n_points < min_points:
        raise ValueError(f"{name} needs at least {min_points} points, got {n_points}")
    _check_finite(array, name)
    if not allow_static and not np.any(array != array[0]):
        raise ValueError(f"{name} is degenerate: all {n_points} points are identical")
    return np.ascontiguousarray(array)


def as_point(p, n_dims: int, name: str = "point") -> np.ndarray:
    """Validate one point of dimension ``n_dims`` and return it as a float64 array (n_dims,)."""
    array = _as_float_array(p, name)
    if array.ndim == 0:
        array = array.reshape(1)
    if array.ndim != 1 or array.shape[0] != n_dims:
        raise ValueError(f"{name} must have {n_dims} coordinate(s) to match the model, got shape {array.shape}")
    _check_finite(array, name)
    return array


def as_points(points, n_dims: int, name: str = "points") -> np.ndarray:
    """Validate a set of points and return them as a float64 array (G, n_dims)."""
    array = _as_float_array(points, name)
    if array.ndim == 1 and array.shape[0] == n_dims:
        array = array.reshape(1, n_dims)
    if array.ndim != 2 or array.shape[1] != n_dims:
        raise ValueError(f"{name} must have shape (G, {n_dims}) to match the model, got shape {array.shape}")
    if array.shape[0] == 0:
        raise ValueError(f"{name} is empty")
    _check_finite(array, name)
    return np.ascontiguousarray(array)


def check_int(value, name: str, minimum: int | None = None) -> int:
    """Return ``value`` as an ``int`` after checking it is an integer >= ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, Integral):
        raise TypeError(f"{name} must be an integer, got {type(value).__name__} {value!r}")
    if minimum is not None and value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {value}")
    return int(value)


def check_real(value, name: str, *, positive: bool = False, nonnegative: bool = False) -> float:
    """Return ``value`` as a finite ``float`` (optionally > 0 or >= 0)."""
    if isinstance(value, bool) or not isinstance(value, Real):
        raise TypeError(f"{name} must be a number, got {type(value).__name__} {value!r}")
    value = float(value)
    if not np.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value}")
    if positive and value <= 0:
        raise ValueError(f"{name} must be > 0, got {value}")
    if nonnegative and value < 0:
        raise ValueError(f"{name} must be >= 0, got {value}")
    return value


def check_choice(value, name: str, choices: Iterable[str]) -> str:
    """Check that ``value`` is one of ``choices`` (strings)."""
    choices = tuple(choices)
    if not isinstance(value, str) or value not in choices:
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}; got {value!r}")
    return value


def check_fitted(model, attribute: str) -> None:
    """Raise :class:`NotFittedError` if ``model`` lacks the learned ``attribute``."""
    if getattr(model, attribute, None) is None:
        raise NotFittedError(f"this {type(model).__name__} is not fitted yet: call fit() first")
