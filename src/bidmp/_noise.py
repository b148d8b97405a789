"""Smooth, seeded perturbations of trajectories (hand-guided wobble, augmentation)."""

from __future__ import annotations

import numpy as np

__all__ = ["perturb"]


def perturb(y, noise: float, seed: int | np.random.Generator | None = 0) -> np.ndarray:
    """A copy of trajectory ``y`` (T, D) with smooth, seeded noise of standard deviation ``noise``.

    Low-pass filtered Gaussian noise (as from a hand-guided robot), tapered to zero at both ends so
    the start and the end stay exact.
    """
    from scipy.ndimage import gaussian_filter1d

    y = np.array(y, dtype=np.float64)
    n_steps = y.shape[0]
    rng = np.random.default_rng(seed)
    wobble = gaussian_filter1d(rng.normal(size=y.shape), sigma=max(n_steps / 50.0, 1.0), axis=0)
    wobble *= noise / max(float(wobble.std()), 1e-300)
    t = np.linspace(0.0, 1.0, n_steps)
    return y + np.sin(np.pi * t)[:, None] ** 2 * wobble
