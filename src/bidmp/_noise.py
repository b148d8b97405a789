"""Smooth, seeded perturbations of trajectories (hand-guided wobble, augmentation)."""

from __future__ import annotations

import numpy as np

__all__ = ["perturb"]


def perturb(y, noise: float, seed: int | np.random.Generator | None = 0) -> np.ndarray:
    """A copy of trajectory ``y`` (T, D) with smooth, seeded noise of standard deviation ``noise``.

    Low-pass filtered Gaussian noise (as from a hand-guided robot), tapered to zero at both ends so
    the start and the end stay exact.
    """
    from ._checks import as_trajectory, check_real, check_seed, get_limits

    y = as_trajectory(y, "y", min_points=1, allow_static=True).copy()
    noise = check_real(noise, "noise", nonnegative=True, maximum=1e-3 * get_limits().max_abs_value)
    n_steps = y.shape[0]
    rng = check_seed(seed)
    wobble = _low_pass(rng.normal(size=y.shape), sigma=max(n_steps / 50.0, 1.0))
    wobble *= noise / max(float(wobble.std()), 1e-300)
    t = np.linspace(0.0, 1.0, n_steps)
    return y + np.sin(np.pi * t)[:, None] ** 2 * wobble


_DIRECT_FILTER_SAMPLES = 20_000


def _low_pass(noise: np.ndarray, sigma: float) -> np.ndarray:
    """Gaussian filter along axis 0 (``scipy.ndimage.gaussian_filter1d``, mode "reflect").

    Its kernel grows with the signal here (sigma = T/50), so the direct filter costs O(T²): past
    20 000 samples the same kernel and boundary are applied by FFT convolution instead (equal to
    1e-15; below the threshold the direct filter is kept so that seeded results stay bit-exact).
    """
    from scipy.ndimage import gaussian_filter1d
    from scipy.signal import fftconvolve

    if noise.shape[0] <= _DIRECT_FILTER_SAMPLES:
        return gaussian_filter1d(noise, sigma=sigma, axis=0)
    radius = int(4.0 * sigma + 0.5)  # gaussian_filter1d's default truncate = 4
    kernel = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
    kernel /= kernel.sum()
    padded = np.pad(noise, ((radius, radius), (0, 0)), mode="symmetric")  # = ndimage's "reflect"
    return fftconvolve(padded, kernel[:, None], mode="valid", axes=0)
