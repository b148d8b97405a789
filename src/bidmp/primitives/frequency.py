"""The frequency of a periodic recording: a spectral peak refined by a least-squares harmonic
series over every kept sample at its own stamp (jitter needs no resampling), with its standard
error, the transients cut and the period-to-period spread; and the harmonic series' values and
derivatives in phase (what the rhythmic DMP learns its forcing target from).

Layer 1: NumPy and SciPy's scalar minimiser only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import SLOWEST_HZ, as_trajectory, check_bool, check_int, check_real
from .timing import check_timestamps

__all__ = ["FrequencyEstimate", "estimate_frequency", "harmonic_fit"]

_ENVELOPE_SHARE = 0.9  # of the steady envelope: below it a stretch is a transient
_MAX_HARMONICS = 15


@dataclass(frozen=True)
class FrequencyEstimate:
    """The frequency of a periodic recording and what it was estimated on.

    Attributes
    ----------
    frequency : float
        Hz.
    uncertainty : float
        One standard error of ``frequency`` (Hz), from the curvature of the harmonic fit's
        residual at its minimum (the Gauss-Newton variance ``2 σ² / RSS''``).
    n_harmonics : int
        Harmonics of the series fitted (chosen by BIC unless given).
    start, end : float
        The steady part kept (s from the recording's first stamp): whole periods, transients cut.
    periods : int
        Whole periods in the kept part.
    spread : float
        Period-to-period spread: the RMS difference of each period's own harmonic series from
        the mean period, over the mean period's amplitude (half its largest peak-to-peak).
    amplitude : array (D,)
        Half the mean period's peak-to-peak per dimension (units).
    series : array (2K + 1, D) or None
        The mean period's harmonic series over the kept part, phase 0 at ``start``:
        ``[a_0, a_1 … a_K, b_1 … b_K]`` of ``a_0 + Σ a_k cos kφ + b_k sin kφ`` (None when read
        from a model file, which keeps the learned weights instead).
    """

    frequency: float
    uncertainty: float
    n_harmonics: int
    start: float
    end: float
    periods: int
    spread: float
    amplitude: np.ndarray
    series: np.ndarray | None = None


def _design(t: np.ndarray, omega: float, n_harmonics: int) -> np.ndarray:
    """[1, cos(kωt), sin(kωt)] for k = 1..K, shape (T, 2K + 1)."""
    angles = np.outer(t, omega * np.arange(1, n_harmonics + 1))
    return np.column_stack([np.ones_like(t), np.cos(angles), np.sin(angles)])


def _residual(t: np.ndarray, y: np.ndarray, omega: float, n_harmonics: int) -> float:
    """The least-squares residual of the harmonic series; normal equations (the harmonics of two
    periods or more are nearly orthogonal: a well-conditioned Gram matrix), 5x faster than an
    SVD, and the search calls it some 40 times."""
    design = _design(t, omega, n_harmonics)
    gram = design.T @ design
    coefficients = np.linalg.solve(gram, design.T @ y)
    return float(np.sum((y - design @ coefficients) ** 2))


def harmonic_fit(
    y, t, frequency: float, n_harmonics: int
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Least-squares harmonic series of ``y`` (T, D) at stamps ``t`` (s) for a known frequency (Hz):
    ``y ≈ a_0 + Σ_k a_k cos(k ω t) + b_k sin(k ω t)``.

    Returns
    -------
    (a_0 (D,), a (K, D), b (K, D))
    """
    y = as_trajectory(y, "y", min_points=3, allow_static=True)
    t = check_timestamps(t, y.shape[0])
    frequency = check_real(frequency, "frequency", minimum=SLOWEST_HZ, maximum=1e3)
    n_harmonics = check_int(n_harmonics, "n_harmonics", minimum=1, maximum=_MAX_HARMONICS * 4)
    coefficients = np.linalg.lstsq(
        _design(t - t[0], 2.0 * math.pi * frequency, n_harmonics), y, rcond=None
    )[0]
    return coefficients[0], coefficients[1 : n_harmonics + 1], coefficients[n_harmonics + 1 :]


def _coarse_frequency(y: np.ndarray, t: np.ndarray) -> float:
    """The spectral peak (Hz) of the mean-free recording on a uniform grid, Hann window, zero
    padded 8x, refined by a parabola through the log power of the peak and its neighbours; a
    peak whose half or third also stands out (a strong harmonic) gives way to it."""
    n = y.shape[0]
    step = (t[-1] - t[0]) / (n - 1)
    uniform = np.linspace(t[0], t[-1], n)
    resampled = np.column_stack([np.interp(uniform, t, column) for column in y.T])
    resampled -= resampled.mean(axis=0)
    window = np.hanning(n)[:, None]
    size = 8 * (1 << int(math.ceil(math.log2(n))))
    power = np.sum(np.abs(np.fft.rfft(resampled * window, n=size, axis=0)) ** 2, axis=1)
    frequencies = np.fft.rfftfreq(size, step)
    lowest = 2.0 / (t[-1] - t[0])  # two periods at least
    power[frequencies < lowest] = 0.0
    peak = int(np.argmax(power))

    def refined(index: int) -> float:
        if 0 < index < power.shape[0] - 1 and min(power[index - 1 : index + 2]) > 0.0:
            left, mid, right = np.log(power[index - 1 : index + 2])
            curvature = left - 2.0 * mid + right
            if curvature < 0.0:
                return float(
                    frequencies[index] + 0.5 * (left - right) / curvature * (frequencies[1])
                )
        return float(frequencies[index])

    best = refined(peak)
    for divisor in (3, 2):  # the fundamental may be weaker than a harmonic
        candidate = best / divisor
        if candidate < lowest:
            continue
        index = int(round(candidate / frequencies[1]))
        lo, hi = max(index - 4, 1), min(index + 5, power.shape[0])
        local = lo + int(np.argmax(power[lo:hi]))
        if power[local] > 0.1 * power[peak]:
            return refined(local)
    return best


def _steady_part(y: np.ndarray, t: np.ndarray, frequency: float) -> tuple[int, int]:
    """Indices [first, last) of the longest stretch whose one-period RMS envelope is at least
    9/10 of the steady level (the median envelope over the middle half of the recording)."""
    period = 1.0 / frequency
    centred = y - np.median(y, axis=0)
    energy = np.sum(centred**2, axis=1)
    cumulative = np.concatenate([[0.0], np.cumsum(energy * np.gradient(t))])
    half = 0.5 * period
    lo = np.searchsorted(t, t - half)
    hi = np.searchsorted(t, t + half)
    span = t[np.minimum(hi, len(t) - 1)] - t[lo]
    envelope = np.sqrt((cumulative[hi] - cumulative[lo]) / np.maximum(span, 1e-300))
    n = len(t)
    steady = np.median(envelope[n // 4 : 3 * n // 4])
    # A window that reaches past either end has no full period: not steady.
    inside = (t - t[0] >= half) & (t[-1] - t >= half)
    good = inside & (envelope >= _ENVELOPE_SHARE * steady)
    if not good.any():
        return 0, n
    # The longest run of good samples.
    edges = np.flatnonzero(np.diff(np.concatenate([[0], good.astype(np.int8), [0]])))
    starts, ends = edges[::2], edges[1::2]
    longest = int(np.argmax(ends - starts))
    return int(starts[longest]), int(ends[longest])


def _choose_harmonics(t: np.ndarray, y: np.ndarray, omega: float) -> int:
    """The number of harmonics with the least BIC (Gaussian residual, every dimension)."""
    n, d = y.shape
    best, best_bic = 1, math.inf
    for k in range(1, _MAX_HARMONICS + 1):
        if n <= 2 * k + 2:
            break
        rss = _residual(t, y, omega, k)
        bic = n * d * math.log(max(rss, 1e-300) / (n * d)) + (2 * k + 1) * d * math.log(n * d)
        if bic < best_bic:
            best, best_bic = k, bic
    return best


def estimate_frequency(
    y, t, *, n_harmonics: int | None = None, trim: bool = True
) -> FrequencyEstimate:
    """The frequency of a periodic recording of several periods, its standard error, the steady
    part and the period-to-period spread.

    A spectral peak (Hann window, zero padding, parabolic refinement) gives the first estimate;
    the transients are cut (``trim``: where the one-period RMS envelope is below 9/10 of the
    steady level); the frequency is refined by minimising the residual of a least-squares
    harmonic series over all the kept samples at their own stamps (jitter needs no resampling),
    searched within one spectral bin, and the kept part is cut to whole periods.

    Parameters
    ----------
    y : array-like, shape (T, D)
        The recording (any unit), at least 2 periods.
    t : array-like, shape (T,)
        Strictly increasing stamps (s), jittered or not.
    n_harmonics : int, optional
        Harmonics of the series; default chosen by BIC (1 to 15).
    trim : bool
        Cut the transients at both ends.

    Returns
    -------
    FrequencyEstimate
    """
    from scipy.optimize import minimize_scalar

    y = as_trajectory(y, "y", min_points=8)
    t = check_timestamps(t, y.shape[0])
    trim = check_bool(trim, "trim")
    if n_harmonics is not None:
        n_harmonics = check_int(n_harmonics, "n_harmonics", minimum=1, maximum=_MAX_HARMONICS * 4)
    t = t - t[0]
    coarse = _coarse_frequency(y, t)
    if not coarse > 0.0:
        raise ValueError("y: no periodic component found (the spectrum has no peak)")
    first, last = _steady_part(y, t, coarse) if trim else (0, len(t))
    kept_t, kept_y = t[first:last], y[first:last]
    if (kept_t[-1] - kept_t[0]) * coarse < 2.0:
        raise ValueError(
            f"y: the steady part holds {(kept_t[-1] - kept_t[0]) * coarse:.2f} periods of "
            f"{coarse:.4g} Hz; at least 2 are needed"
        )
    origin = kept_t[0]
    local = kept_t - origin
    omega0 = 2.0 * math.pi * coarse
    harmonics = n_harmonics or _choose_harmonics(local, kept_y, omega0)
    resolution = 2.0 * math.pi / (local[-1] - local[0])
    result = minimize_scalar(
        lambda omega: _residual(local, kept_y, omega, harmonics),
        bounds=(max(omega0 - resolution, 0.5 * omega0), omega0 + resolution),
        method="bounded",
        options={"xatol": 1e-10 * omega0},
    )
    omega = float(result.x)
    # Whole periods from the kept part's start.
    periods = int(math.floor((local[-1] - local[0]) * omega / (2.0 * math.pi) + 1e-9))
    end = 2.0 * math.pi * periods / omega
    whole = local <= end + 1e-12
    local, kept_y = local[whole], kept_y[whole]
    rss = _residual(local, kept_y, omega, harmonics)
    h = 1e-4 * resolution
    curvature = (
        _residual(local, kept_y, omega + h, harmonics)
        - 2.0 * rss
        + _residual(local, kept_y, omega - h, harmonics)
    ) / (h * h)
    n_params = (2 * harmonics + 1) * kept_y.shape[1] + 1
    sigma2 = rss / max(kept_y.size - n_params, 1)
    uncertainty = math.sqrt(2.0 * sigma2 / curvature) if curvature > 0.0 else math.inf
    spread, amplitude, series = _period_spread(local, kept_y, omega, harmonics, periods)
    return FrequencyEstimate(
        frequency=omega / (2.0 * math.pi),
        uncertainty=uncertainty / (2.0 * math.pi),
        n_harmonics=harmonics,
        start=float(origin),
        end=float(origin + end),
        periods=periods,
        spread=spread,
        amplitude=amplitude,
        series=series,
    )


def _series(coefficients: np.ndarray, phase: np.ndarray, harmonics: int, order: int = 0):
    """The harmonic series (L, D) at phases (rad), or its ``order``-th derivative in phase."""
    k = np.arange(1, harmonics + 1)
    angles = np.outer(phase, k)
    a, b = coefficients[1 : harmonics + 1], coefficients[harmonics + 1 :]
    scale = k.astype(float) ** order
    # d/dφ of (cos, sin) cycles through (-sin, cos), (-cos, -sin), (sin, -cos)
    cos_term = [np.cos, lambda x: -np.sin(x), lambda x: -np.cos(x), np.sin][order % 4](angles)
    sin_term = [np.sin, np.cos, lambda x: -np.sin(x), lambda x: -np.cos(x)][order % 4](angles)
    value = (cos_term * scale) @ a + (sin_term * scale) @ b
    if order == 0:
        value = value + coefficients[0]
    return value


def _period_spread(t, y, omega, harmonics, periods) -> tuple[float, np.ndarray, np.ndarray]:
    """(spread, amplitude (D,), the mean period's series (2K + 1, D)) of the kept samples."""
    design = _design(t, omega, harmonics)
    mean = np.linalg.lstsq(design, y, rcond=None)[0]
    grid = np.linspace(0.0, 2.0 * math.pi, 256, endpoint=False)
    mean_curve = _series(mean, grid, harmonics)
    amplitude = 0.5 * np.ptp(mean_curve, axis=0)
    differences = []
    period = 2.0 * math.pi / omega
    for p in range(periods):
        inside = (t >= p * period) & (t < (p + 1) * period)
        if np.count_nonzero(inside) <= 2 * harmonics + 1:
            continue
        own = np.linalg.lstsq(design[inside], y[inside], rcond=None)[0]
        differences.append(_series(own, grid, harmonics) - mean_curve)
    if not differences:
        return 0.0, amplitude, mean
    rms = math.sqrt(float(np.mean(np.square(differences))))
    return rms / max(float(amplitude.max()), 1e-300), amplitude, mean


def _with_frequency(estimate: FrequencyEstimate, y, t, frequency: float) -> FrequencyEstimate:
    """The estimate's steady part re-cut to whole periods of a given frequency."""
    omega = 2.0 * math.pi * frequency
    span = estimate.end - estimate.start
    periods = max(int(math.floor(span * frequency + 1e-9)), 1)
    local = t - t[0]
    keep = (local >= estimate.start) & (local <= estimate.start + periods / frequency)
    spread, amplitude, series = _period_spread(
        local[keep] - estimate.start, y[keep], omega, estimate.n_harmonics, periods
    )
    return FrequencyEstimate(
        frequency=frequency,
        uncertainty=0.0,
        n_harmonics=estimate.n_harmonics,
        start=estimate.start,
        end=estimate.start + periods / frequency,
        periods=periods,
        spread=spread,
        amplitude=amplitude,
        series=series,
    )
