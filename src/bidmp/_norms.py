"""Norms and directions of rows whose components may be huge or tiny (quaternions, axes): each
row is scaled by the power of two of its largest magnitude first — exact, only the exponents
change — so that components of 1e300 do not overflow the squares to inf and of 1e-300 do not
underflow them to 0. Where neither happens the results are NumPy's, bit for bit."""

from __future__ import annotations

import numpy as np

__all__ = ["power_of_two_scaled", "tamed_rows", "row_norms", "unit_rows"]


def power_of_two_scaled(array: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``array`` (..., k) with each row divided by the power of two of its largest magnitude
    (exact: only the exponents change), and those exponents (..., 1)."""
    largest = np.max(np.abs(array), axis=-1, keepdims=True)
    exponent = np.frexp(largest)[1]
    return np.ldexp(array, -exponent), exponent


def tamed_rows(array: np.ndarray) -> np.ndarray:
    """``array`` (n, k) with each row whose largest magnitude is beyond 2^±500 (its norm would
    overflow to inf or underflow to 0) scaled by the power of two of it (exact: its direction is
    the same); the other rows as given, bit for bit (what a normalising caller such as SciPy's
    ``Rotation`` computes from them is unchanged)."""
    largest = np.max(np.abs(array), axis=1)
    extreme = (largest > 2.0**500) | (largest < 2.0**-500)
    if not np.any(extreme):
        return array
    array = np.array(array, dtype=float)
    array[extreme] = power_of_two_scaled(array[extreme])[0]
    return array


def row_norms(array: np.ndarray) -> np.ndarray:
    """The Euclidean norm of each row of finite ``array`` (..., k), its rows scaled by a power of
    two first, so that components of 1e300 do not overflow the squares and of 1e-300 do not
    underflow them to 0 (the norm of a quaternion, of a direction)."""
    scaled, exponent = power_of_two_scaled(np.asarray(array, dtype=float))
    return np.ldexp(np.linalg.norm(scaled, axis=-1), exponent[..., 0])


def unit_rows(array: np.ndarray) -> np.ndarray:
    """Each row of finite, non-zero ``array`` (..., k) divided by its norm, scaled first as
    :func:`row_norms` (bit for bit ``array / norm`` where that neither overflows nor
    underflows)."""
    scaled = power_of_two_scaled(np.asarray(array, dtype=float))[0]
    return scaled / np.linalg.norm(scaled, axis=-1, keepdims=True)
