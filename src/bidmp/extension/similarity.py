"""Discrete Fréchet distance and the paper's Fréchet similarity (paper Eq. 3–5).

The coupling recursion (Eiter & Mannila 1994)::

    ca[i, j] = max(min(ca[i-1, j], ca[i, j-1], ca[i-1, j-1]), d(P_i, Q_j))

is evaluated in O(n m) time and O(m) memory (one row), never as an n × m matrix and never by
recursion. The fast kernel is compiled by numba and cached on disk (the first call in a fresh
environment compiles it, about a second). SciPy and NumPy have no kernel for this recursion: its
cells depend on their left neighbour in the same row, so a row cannot be one vector operation.
:func:`frechet_distance_reference` is a plain NumPy version (one vectorised anti-diagonal at a
time) that serves as the fallback when numba is missing and as the tests' second opinion.

**Which one answers.** Loading numba and the cached kernel costs a process about 0.3 s (the
import, LLVM, and LLVM's own teardown when the process ends); the NumPy version spends that on
about a million table cells (3 ms for 100 × 100). So a process's first million cells are the NumPy
version's, and the kernel is loaded only for work that repays it: a G-PRM of a few iterations
(a command's usual extension: ten 100 × 100 tables) never loads numba. Both give the same bits:
the recursion only takes maxima and minima, the squared distances are summed in the same order,
and a correctly rounded square root is monotone, so the root of the extreme is the extreme of the
roots (tested on random curves).
"""

from __future__ import annotations

import logging

import numpy as np

from .._checks import as_trajectory, check_choice, check_limit, numerically_guarded

REFERENCE_MAX_CELLS = 1e7  # cells of frechet_distance_reference (a few seconds)
# cells the NumPy version answers in a process before the compiled kernel is loaded (module docstring)
NUMPY_BUDGET_CELLS = 1e6

__all__ = [
    "frechet_distance",
    "frechet_distance_reference",
    "frechet_similarity",
    "polyline_length",
    "dtw_distance",
]

logger = logging.getLogger(__name__)


def _frechet_rows(p: np.ndarray, q: np.ndarray) -> float:  # pragma: no cover - compiled by numba
    # The recursion only takes max/min of distances, which commute with the monotone sqrt: work
    # in squared distances and take one root at the end. (The squared distance is written out
    # in place, not as a helper, so that one function is all numba has to compile and cache.)
    n, m, n_dims = p.shape[0], q.shape[0], p.shape[1]
    row = np.empty(m)  # row[j] = ca[i, j] for the current i
    for j in range(m):
        total = 0.0
        for k in range(n_dims):
            delta = p[0, k] - q[j, k]
            total += delta * delta
        row[j] = total if j == 0 else max(row[j - 1], total)
    for i in range(1, n):
        diagonal = row[0]  # ca[i-1, j-1] for the next j
        for j in range(m):
            total = 0.0
            for k in range(n_dims):
                delta = p[i, k] - q[j, k]
                total += delta * delta
            if j == 0:
                row[0] = max(row[0], total)
                continue
            up = row[j]
            best = min(up, row[j - 1], diagonal)
            diagonal = up
            row[j] = max(best, total)
    return np.sqrt(row[m - 1])


def _dtw_rows(p: np.ndarray, q: np.ndarray) -> float:  # pragma: no cover - compiled by numba
    # D[i, j] = d(P_i, Q_j) + min(D[i-1, j], D[i, j-1], D[i-1, j-1]), one row at a time.
    n, m, n_dims = p.shape[0], q.shape[0], p.shape[1]
    row = np.empty(m)
    for i in range(n):
        diagonal = 0.0
        for j in range(m):
            total = 0.0
            for k in range(n_dims):
                delta = p[i, k] - q[j, k]
                total += delta * delta
            cost = np.sqrt(total)
            if i == 0 and j == 0:
                best = 0.0
            elif i == 0:
                best = row[j - 1]
            elif j == 0:
                best = row[0]
            else:
                best = min(row[j], row[j - 1], diagonal)
            diagonal = row[j] if i > 0 else 0.0
            row[j] = cost + best
    return row[m - 1]


_kernel_state: dict = {}


def _compiled(name: str, function):
    """The numba-compiled ``function`` (cached per process), or None without numba.

    numba caches compiled code on disk beside the package or in the user's cache folder; where
    neither is writable (a read-only install, a service user without a home) it cannot cache and
    raises at the first call. Then the kernel is compiled in memory instead, once per process.
    """
    if name not in _kernel_state:
        try:
            import numba
        # numba is a dependency; this keeps bidmp usable without it
        except ImportError:  # pragma: no cover
            _kernel_state[name] = None
            return None
        probe = (np.zeros((1, 1)), np.zeros((1, 1)))
        try:  # numba looks for a cache folder when decorating, and writes it at the first call
            kernel = numba.njit(cache=True, nogil=True)(function)
            kernel(*probe)
        except Exception as exc:  # noqa: BLE001 - numba's caching errors have no common class
            logger.info(
                "numba cannot cache the %s kernel here (%s); compiling it in memory", name, exc
            )
            kernel = numba.njit(cache=False, nogil=True)(function)
            kernel(*probe)
        _kernel_state[name] = kernel
    return _kernel_state[name]


_FRECHET = "Fréchet"  # the kernel's name in _kernel_state


def _frechet_kernel():
    return _compiled(_FRECHET, _frechet_rows)


def dtw_distance(a, b) -> float:
    """Dynamic-time-warping distance: the smallest sum of Euclidean distances over monotone
    alignments of the two curves (Sakoe & Chiba, no window), O(n m) time, O(m) memory.

    Parameters
    ----------
    a : array-like (n, D)
    b : array-like (m, D)

    Returns
    -------
    float
        In the curves' length unit (a sum over aligned pairs: divide by the alignment's length,
        or by n, for a per-sample figure).
    """
    a = as_trajectory(a, "a", min_points=1, allow_static=True)
    b = as_trajectory(b, "b", min_points=1, allow_static=True)
    if a.shape[1] != b.shape[1]:
        raise ValueError(
            f"a and b must have the same dimension, got D = {a.shape[1]} and D = {b.shape[1]}"
        )
    check_limit(
        a.shape[0] * b.shape[0],
        "max_frechet_cells",
        "the DTW table's size n x m; resample the curves",
    )
    kernel = _compiled("DTW", _dtw_rows)
    if kernel is None:  # pragma: no cover
        return float(_dtw_rows(a, b))
    return float(kernel(a, b))


def frechet_distance_reference(a: np.ndarray, b: np.ndarray) -> float:
    """Discrete Fréchet distance by anti-diagonals in NumPy (O(n + m) memory, no recursion).

    Cells on one anti-diagonal ``i + j = s`` depend only on the two previous anti-diagonals, so
    each is one vectorised step.
    """
    a = as_trajectory(a, "a", min_points=1, allow_static=True)
    b = as_trajectory(b, "b", min_points=1, allow_static=True)
    n, m = a.shape[0], b.shape[0]
    if b.shape[1] != a.shape[1]:
        raise ValueError(
            f"a and b must have the same number of columns, got {a.shape[1]} and {b.shape[1]}"
        )
    # a Python loop over anti-diagonals: a reference, not a tool
    if float(n) * m > REFERENCE_MAX_CELLS:
        raise ValueError(
            f"frechet_distance_reference: {n:,} x {m:,} cells exceed the reference's "
            f"{REFERENCE_MAX_CELLS:,.0f}; use frechet_distance"
        )
    return _frechet_anti_diagonals(a, b)


def _frechet_anti_diagonals(a: np.ndarray, b: np.ndarray) -> float:
    """:func:`frechet_distance_reference` of checked curves."""
    n, m = a.shape[0], b.shape[0]
    # previous[i] holds ca[i, s-1-i], before_previous[i] holds ca[i, s-2-i]; inf outside the grid.
    before_previous = np.full(n, np.inf)
    previous = np.full(n, np.inf)
    for s in range(n + m - 1):
        i = np.arange(max(0, s - m + 1), min(n, s + 1))
        j = s - i
        distance = np.sqrt(np.sum((a[i] - b[j]) ** 2, axis=1))
        if s == 0:
            current = np.full(n, np.inf)
            current[0] = distance[0]
        else:
            up = np.where(i >= 1, previous[np.maximum(i - 1, 0)], np.inf)  # ca[i-1, j]
            left = previous[i]  # ca[i, j-1]
            # ca[i-1, j-1]
            diagonal = np.where(i >= 1, before_previous[np.maximum(i - 1, 0)], np.inf)
            current = np.full(n, np.inf)
            current[i] = np.maximum(np.minimum(np.minimum(up, left), diagonal), distance)
        before_previous, previous = previous, current
    return float(previous[n - 1])


def frechet_distance(a, b) -> float:
    """Discrete Fréchet distance between two polylines.

    Parameters
    ----------
    a : array-like, shape (n, D)
    b : array-like, shape (m, D)
        Curves of any lengths n, m ≥ 1 in the same dimension D.

    Returns
    -------
    float
        In the curves' length unit; symmetric; at least the distance between the start points
        and between the end points.
    """
    return _frechet_distance(*_curve_pair(a, b))


def _curve_pair(a, b) -> tuple[np.ndarray, np.ndarray]:
    """Two curves checked: finite, one dimension, a Fréchet table within the limits."""
    a = as_trajectory(a, "a", min_points=1, allow_static=True)
    b = as_trajectory(b, "b", min_points=1, allow_static=True)
    if a.shape[1] != b.shape[1]:
        raise ValueError(
            f"a and b must have the same dimension, got D = {a.shape[1]} and D = {b.shape[1]}"
        )
    check_limit(
        a.shape[0] * b.shape[0],
        "max_frechet_cells",
        "the Fréchet table's size n x m; resample the curves to fewer points",
    )
    return a, b


def _frechet_distance(a: np.ndarray, b: np.ndarray) -> float:
    """:func:`frechet_distance` of checked curves (G-PRM scores every iteration with it): the NumPy
    version within the process's budget of cells, else the compiled kernel (module docstring)."""
    cells = a.shape[0] * b.shape[0]
    if _FRECHET not in _kernel_state and _numpy_cells[0] + cells <= NUMPY_BUDGET_CELLS:
        _numpy_cells[0] += cells
        return _frechet_anti_diagonals(a, b)
    return _frechet_compiled(a, b)


_numpy_cells = [0]  # cells the NumPy version has answered in this process


def _frechet_compiled(a: np.ndarray, b: np.ndarray) -> float:
    """The compiled kernel's answer for checked curves (the NumPy version's without numba)."""
    kernel = _frechet_kernel()
    if kernel is None:  # pragma: no cover
        return _frechet_anti_diagonals(a, b)
    return float(kernel(a, b))


def polyline_length(y: np.ndarray) -> float:
    """Sum of the segment lengths of a polyline (T, D)."""
    return _length(as_trajectory(y, "y", min_points=1, allow_static=True))


def _length(y: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(y, axis=0), axis=1)))


@numerically_guarded
def frechet_similarity(a, b, denom: str = "sqrt2") -> float:
    """Fréchet similarity ``max(1 - Fré(a, b) / (sqrt(len(a) len(b)) / r), 0)`` (paper Eq. 5).

    ``len`` is the polyline length; ``r = sqrt(2)`` (``denom="sqrt2"``, default) or ``r = 2``
    (``denom="2"``). It is 1 for identical curves and falls to 0 as the curves part.

    Raises
    ------
    ValueError
        If a curve has zero length (the normaliser is undefined) or ``denom`` is unknown.
    """
    check_choice(denom, "denom", ("sqrt2", "2"))
    return _frechet_similarity(*_curve_pair(a, b), denom)


def _frechet_similarity(a: np.ndarray, b: np.ndarray, denom: str) -> float:
    """:func:`frechet_similarity` of checked curves (G-PRM scores every iteration with it)."""
    distance = _frechet_distance(a, b)
    length_a, length_b = _length(a), _length(b)
    if length_a <= 0.0 or length_b <= 0.0:
        raise ValueError(
            f"a and b must be curves of non-zero length (the normaliser), got lengths {length_a:g} and {length_b:g}"
        )
    scale = np.sqrt(length_a * length_b) / (np.sqrt(2.0) if denom == "sqrt2" else 2.0)
    return float(max(1.0 - distance / scale, 0.0))
