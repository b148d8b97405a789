"""Basis rows stored as a band: each row's columns that matter, and where they start.

A row of a DMP's basis is a handful of kernels around the phase (13 of 100 for the robot
protocol are above 1e-16 of the row's peak; the rest are down to 1e-20) so a product with the
whole rows moves and multiplies zeros: the rows are 0.9 MB at T = 1000, N = 100, and a fit or a
rollout reading them from a cold cache costs more than the arithmetic. Kept as a band, the
products read about an eighth of that. What is dropped is below ``1e-16`` of each row's peak: a
product changes by less than its own rounding (the forcing term to ~1e-14 of its size).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .._kernels import band_of as _band_edges
from .._kernels import band_product, band_transposed_product

__all__ = []

# Entries below this share of their row's largest are dropped (a double's rounding is 1.1e-16).
_BAND_FLOOR = 1e-16
# A band as wide as this share of the columns is no gain: the rows stay dense.
_BAND_MAX_SHARE = 0.5


@dataclass(frozen=True)
class _Band:
    """Rows (n, N) kept as ``values`` (n, w): row ``i``'s columns ``first[i] … first[i] + w - 1``.

    Attributes
    ----------
    values : array, shape (n, w)
    first : array of int64, shape (n,)
    n_columns : int
        N, the rows' full width.
    """

    values: np.ndarray
    first: np.ndarray
    n_columns: int

    def product(self, weights: np.ndarray) -> np.ndarray:
        """``rows @ weights`` for ``weights`` (N, D): (n, D)."""
        return band_product(self.values, self.first, np.ascontiguousarray(weights, dtype=float))

    def transposed_product(self, target: np.ndarray) -> np.ndarray:
        """``rowsᵀ @ target`` for ``target`` (n, D): (N, D)."""
        return band_transposed_product(
            self.values, self.first, np.ascontiguousarray(target, dtype=float), self.n_columns
        )

    def head(self, n_rows: int) -> _Band:
        """The first ``n_rows`` rows (a shorter grid is a prefix of a longer one)."""
        return _Band(self.values[:n_rows], self.first[:n_rows], self.n_columns)


def _band_of(rows: np.ndarray) -> _Band | None:
    """``rows`` (n, N) as a :class:`_Band`, or None when their band would be no narrower than
    half the columns (a basis of one's own whose functions overlap everywhere; a row with a NaN
    spans its columns from the first to the last NaN)."""
    rows = np.ascontiguousarray(rows, dtype=float)
    n_rows, n_columns = rows.shape
    if n_rows == 0 or n_columns == 0:
        return None
    first, last = _band_edges(rows, _BAND_FLOOR)
    width = int((last - first).max()) + 1
    if width > _BAND_MAX_SHARE * n_columns:
        return None
    first = np.minimum(first, n_columns - width).astype(np.int64)
    values = np.ascontiguousarray(
        rows[np.arange(n_rows)[:, None], first[:, None] + np.arange(width)]
    )
    values.flags.writeable = False
    first.flags.writeable = False
    return _Band(values, first, n_columns)
