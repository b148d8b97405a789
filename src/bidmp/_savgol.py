"""Savitzky–Golay smoothing and differentiation, SciPy's to the bit, without SciPy's signal package.

The extension smooths every extended path and differentiates a recording with Savitzky–Golay
filters. ``scipy.signal`` is 0.23 s to import on top of what a run already has (its modules parse
their docstrings for the array-API tables as they load), a tenth of ``bidmp sim --targets 1,12``,
for one function of it. The filter itself is small: the window's least-squares coefficients, one
convolution (SciPy's ``ndimage``, 25 ms to import), and at each end the polynomial fitted to the
first or last window evaluated over the half window the convolution cannot reach (``mode="interp"``).
Each step here is the same NumPy and SciPy operation in the same order as
:func:`scipy.signal.savgol_filter` (SciPy 1.17), so the numbers are its numbers to the last bit;
``tests/test_savgol.py`` holds that on random signals, windows, orders, derivatives and axes, so an
upgrade of SciPy that changes its arithmetic fails there first. Other modes than ``"interp"`` and
other dtypes than float64 are handed to SciPy itself.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

__all__ = ["savgol_filter"]


def savgol_filter(
    x,
    window_length: int,
    polyorder: int,
    deriv: int = 0,
    delta: float = 1.0,
    axis: int = -1,
    mode: str = "interp",
    **scipy_options,
) -> np.ndarray:
    """:func:`scipy.signal.savgol_filter` with the same arguments and results.

    Parameters
    ----------
    x : array_like
        The samples, filtered along ``axis``.
    window_length : int
        Samples per window (at most the length of ``x`` along ``axis`` in ``"interp"`` mode).
    polyorder : int
        Degree of the polynomial fitted in each window (less than ``window_length``).
    deriv : int
        Order of the derivative returned (0: the smoothed samples).
    delta : float
        Spacing of the samples (s, for a derivative per second).
    axis, mode
        As SciPy's.
    **scipy_options
        SciPy's other options (``cval`` for ``mode="constant"``): such a call is SciPy's.

    Returns
    -------
    numpy.ndarray, the shape of ``x``: the smoothed samples or their ``deriv``-th derivative.
    """
    array = np.asarray(x)
    if (
        mode != "interp"
        or scipy_options
        or array.dtype != np.float64
        or not _integral(window_length, polyorder, deriv, axis)
        or not -array.ndim <= axis < array.ndim
        or window_length > array.shape[axis]
        or not 0 <= polyorder < window_length
        or deriv < 0
    ):
        # Everything else, and every refusal with its own message, is SciPy's.
        from scipy.signal import savgol_filter as scipy_savgol_filter

        return scipy_savgol_filter(
            x,
            window_length,
            polyorder,
            deriv=deriv,
            delta=delta,
            axis=axis,
            mode=mode,
            **scipy_options,
        )
    from scipy.ndimage import convolve1d

    coefficients = _coefficients(window_length, polyorder, deriv, delta)
    out = convolve1d(array, coefficients, axis=axis, mode="constant")
    half = window_length // 2
    n_samples = array.shape[axis]
    fit = (polyorder, deriv, delta)
    _fit_edge(array, slice(0, window_length), slice(0, half), axis, fit, out)
    _fit_edge(
        array,
        slice(n_samples - window_length, n_samples),
        slice(n_samples - half, n_samples),
        axis,
        fit,
        out,
    )
    return out


def _integral(*values) -> bool:
    return all(
        isinstance(value, (int, np.integer)) and not isinstance(value, bool) for value in values
    )


def _lstsq(matrix: np.ndarray, rhs: np.ndarray, rcond: float):
    """SciPy's least squares (LAPACK ``gelsd``), as the filter's coefficients and edges use it."""
    from scipy.linalg import lstsq

    return lstsq(matrix, rhs, cond=rcond)


def _coefficients(window_length: int, polyorder: int, deriv: int, delta: float) -> np.ndarray:
    """The convolution's weights (window_length,): the least-squares polynomial's ``deriv``-th
    derivative at the window's centre, as a linear function of the window's samples (reversed, as
    a convolution reads them)."""
    half, odd = divmod(window_length, 2)
    centre = half if odd else half - 0.5
    if deriv > polyorder:
        return np.zeros(window_length, dtype=np.float64)
    offsets = np.flip(np.arange(-centre, window_length - centre, dtype=np.float64))
    powers = np.reshape(np.arange(polyorder + 1, dtype=np.float64), (-1, 1))
    vandermonde = offsets**powers
    unit = np.zeros(polyorder + 1, dtype=np.float64)
    unit[deriv] = float(math.factorial(deriv)) / (delta**deriv)
    rcond = np.finfo(np.float64).eps * max(vandermonde.shape[-1], vandermonde.shape[-2])
    return _lstsq(vandermonde, unit, rcond)[0]


def _polyfit(x: np.ndarray, y: np.ndarray, degree: int) -> np.ndarray:
    """Coefficients (degree + 1, K), highest power first, of the least-squares polynomials through
    the columns of ``y`` (n, K) at ``x`` (n,), with the Vandermonde matrix's columns scaled to unit
    norm (its conditioning)."""
    order = degree + 1
    rcond = x.shape[0] * np.finfo(x.dtype).eps
    powers = np.flip(np.arange(order, dtype=x.dtype))
    vandermonde = x[:, None] ** powers[None, :]
    scale = np.sqrt(np.sum(vandermonde * vandermonde, axis=0))
    vandermonde /= scale
    coefficients, _, rank, _ = _lstsq(vandermonde, y, rcond)
    coefficients = (coefficients.T / scale).T
    if rank != order:
        warnings.warn("Polyfit may be poorly conditioned", np.exceptions.RankWarning, stacklevel=3)
    return coefficients


def _polyder(coefficients: np.ndarray, order: int) -> np.ndarray:
    """The ``order``-th derivative of the polynomials in the columns of ``coefficients``."""
    if order == 0:
        return coefficients
    n_coefficients = coefficients.shape[0]
    if n_coefficients <= order:
        return np.zeros_like(coefficients[:1, ...])
    derivative = np.asarray(coefficients[:-order, ...], copy=True)
    for k in range(order):
        factors = np.arange(n_coefficients - k - 1, order - k - 1, -1, dtype=coefficients.dtype)
        derivative *= np.reshape(
            factors, (n_coefficients - order,) + (1,) * (coefficients.ndim - 1)
        )
    return derivative


def _polyval(coefficients: np.ndarray, x: np.ndarray) -> np.ndarray:
    """Horner's rule for every column of ``coefficients`` at ``x`` (m, 1): (m, K)."""
    values = np.zeros_like(x)
    for row in range(coefficients.shape[0]):
        values = values * x + coefficients[row, ...]
    return values


def _fit_edge(
    x: np.ndarray, window: slice, interp: slice, axis: int, fit: tuple, out: np.ndarray
) -> None:
    """Write into ``out`` the polynomial fitted to ``x``'s samples ``window`` along ``axis`` (its
    ``deriv``-th derivative; ``fit`` = (polyorder, deriv, delta)), evaluated at ``interp``."""
    polyorder, deriv, delta = fit
    window_start, window_stop = window.start, window.stop
    interp_start, interp_stop = interp.start, interp.stop
    taken = [slice(None)] * x.ndim
    taken[axis] = window
    edge = x[tuple(taken)]
    swapped = not (axis == 0 or axis == -x.ndim)
    if swapped:
        edge = np.swapaxes(edge, axis, 0)
    edge = np.reshape(edge, (edge.shape[0], -1))
    coefficients = _polyfit(
        np.arange(0, window_stop - window_start, dtype=x.dtype), edge, polyorder
    )
    if deriv > 0:
        coefficients = _polyder(coefficients, deriv)
    at = np.arange(
        interp_start - window_start, interp_stop - window_start, dtype=coefficients.dtype
    )
    values = _polyval(coefficients, np.reshape(at, (-1, 1))) / (delta**deriv)
    shape = list(out.shape)
    shape[0], shape[axis] = shape[axis], shape[0]
    values = np.reshape(values, (interp_stop - interp_start, *shape[1:]))
    if swapped:
        values = np.swapaxes(values, 0, axis)
    target = [slice(None)] * out.ndim
    target[axis] = slice(interp_start, interp_stop)
    out[tuple(target)] = values
