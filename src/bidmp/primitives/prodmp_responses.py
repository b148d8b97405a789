"""The ProDMP's basis: the DMP's second-order system solved in closed form on a precomputed grid
(the homogeneous solutions that carry the boundary condition, the forced response's basis for
the weights and the goal), as MP_PyTorch precomputes it; :class:`bidmp.primitives.ProDMP` learns
and conditions weights on it (the derivation is :mod:`bidmp.primitives.prodmp`'s docstring).

Layer 1: NumPy only.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .._checks import as_vector, check_int, check_real

__all__ = ["ProDMPBasis", "prodmp_basis"]

# n_outside's bound alone (prodmp_basis checks it against n_basis: at most (n_basis - 2) // 2)
_MAX_OUTSIDE = 500


@dataclass(frozen=True)
class ProDMPBasis:
    """A ProDMP's precomputed basis (:func:`prodmp_basis` makes one).

    Attributes
    ----------
    n_basis, tau, delay, alpha, alpha_phase, bandwidth_factor, n_outside, dt, length_factor
        The settings it was computed with (tau, delay, dt in s).
    centres, widths : array (n_basis,)
        The forcing basis' centres in phase and its ``bandwidth`` (1 / width²).
    position, velocity : array (P, n_basis + 1)
        ``Φ(s)`` and ``dΦ/ds`` on the grid ``s_k = k · dt / tau``, k = 0..P-1; the last column is
        the goal's.
    y1, y2, dy1, dy2 : array (P,)
        The homogeneous solutions and their derivatives in ``s`` on the grid.
    """

    n_basis: int
    tau: float
    delay: float
    alpha: float
    alpha_phase: float
    bandwidth_factor: float
    n_outside: int
    dt: float
    length_factor: float
    centres: np.ndarray
    widths: np.ndarray
    position: np.ndarray
    velocity: np.ndarray
    y1: np.ndarray
    y2: np.ndarray
    dy1: np.ndarray
    dy2: np.ndarray

    @property
    def scaled_step(self) -> float:
        """The grid's step in scaled time, ``dt / tau``."""
        return self.dt / self.tau

    def scaled_time(self, times) -> np.ndarray:
        """``s = max((t - delay) / tau, 0)`` of ``times`` (s)."""
        times = as_vector(times, "times")
        return np.maximum((times - self.delay) / self.tau, 0.0)

    def phase(self, times) -> np.ndarray:
        """The canonical phase ``x = e^(-alpha_phase s)`` at ``times`` (s)."""
        return np.exp(-self.alpha_phase * self.scaled_time(times))

    def forcing(self, times) -> np.ndarray:
        """(T, n_basis): the normalised RBF forcing basis φ at ``times`` (s)."""
        return _rbf_rows(self.phase(times)[:, None], self.centres, self.widths)

    def _read(self, values: np.ndarray, times) -> np.ndarray:
        """``values`` (P, ...) on the grid read at ``times`` (s), linearly between grid points."""
        index = self.scaled_time(times) / self.scaled_step
        if np.any(index > values.shape[0] - 1 + 1e-9):
            raise ValueError(
                f"times reach {float(np.max(times)):.6g} s, beyond the precomputed "
                f"{self.length_factor:g} tau after the delay: raise length_factor"
            )
        low = np.clip(np.floor(index).astype(int), 0, values.shape[0] - 2)
        share = index - low
        share = share.reshape(share.shape + (1,) * (values.ndim - 1))
        return values[low] * (1.0 - share) + values[low + 1] * share

    def at(self, times) -> tuple[np.ndarray, ...]:
        """(Φ (T, N+1), dΦ/ds (T, N+1), y1, y2, dy1, dy2 (T,)) at ``times`` (s)."""
        solutions = np.column_stack([self.y1, self.y2, self.dy1, self.dy2])
        read = self._read(solutions, times)
        return (self._read(self.position, times), self._read(self.velocity, times), *read.T)

    def boundary_maps(self, times, start_time: float) -> tuple[np.ndarray, ...]:
        """The affine maps of a trajectory at ``times`` (T,) from a boundary condition at
        ``start_time``: ``(P0, V0, P1, V1, H, dH)`` with, per dimension,

            y(t)  = P0(t) y_b + V0(t) ẏ_b tau + H(t) [w; g],
            y'(t) = P1(t) y_b + V1(t) ẏ_b tau + dH(t) [w; g]   (d/ds: divide by tau for /s),

        ``P0, V0, P1, V1`` (T,), ``H, dH`` (T, N+1)."""
        start_time = check_real(start_time, "start_time", minimum=-1e6, maximum=1e6)
        phi, dphi, y1, y2, dy1, dy2 = self.at(times)
        phi_b, dphi_b, y1b, y2b, dy1b, dy2b = self.at(np.array([start_time]))
        det = y1b * dy2b - y2b * dy1b
        xi1, xi2 = (dy2b * y1 - dy1b * y2) / det, (y1b * y2 - y2b * y1) / det
        xi3, xi4 = (dy1b * y2 - dy2b * y1) / det, (y2b * y1 - y1b * y2) / det
        dxi1, dxi2 = (dy2b * dy1 - dy1b * dy2) / det, (y1b * dy2 - y2b * dy1) / det
        dxi3, dxi4 = (dy1b * dy2 - dy2b * dy1) / det, (y2b * dy1 - y1b * dy2) / det
        H = xi3[:, None] * phi_b + xi4[:, None] * dphi_b + phi
        dH = dxi3[:, None] * phi_b + dxi4[:, None] * dphi_b + dphi
        return xi1, xi2, dxi1, dxi2, H, dH


def prodmp_basis(  # noqa: PLR0913 - the basis' settings, each one MP_PyTorch's
    n_basis: int = 10,
    tau: float = 1.0,
    delay: float = 0.0,
    alpha: float = 25.0,
    alpha_phase: float = 3.0,
    bandwidth_factor: float = 3.0,
    n_outside: int = 0,
    dt: float = 0.01,
    length_factor: float = 6.0,
) -> ProDMPBasis:
    """The precomputed basis of a ProDMP (module docstring): ``n_basis`` forcing basis functions,
    time constant ``tau`` (s) and ``delay`` (s), the spring ``alpha`` (critically damped), the
    phase's decay ``alpha_phase``, the basis' ``bandwidth_factor`` and ``n_outside`` centres
    beyond each end, the grid's step ``dt`` (s) over ``length_factor`` · tau (at most 6: beyond,
    ``e^(alpha s / 2)`` overflows the cancellation)."""
    n_basis = check_int(n_basis, "n_basis", minimum=1, limit="max_kernels")
    tau = check_real(tau, "tau", positive=True, maximum=1e4)
    delay = check_real(delay, "delay", minimum=-1e4, maximum=1e4)
    alpha = check_real(alpha, "alpha", positive=True, maximum=1e3)
    alpha_phase = check_real(alpha_phase, "alpha_phase", positive=True, minimum=1e-6, maximum=1e3)
    bandwidth_factor = check_real(bandwidth_factor, "bandwidth_factor", positive=True, maximum=1e3)
    n_outside = check_int(n_outside, "n_outside", minimum=0, maximum=max(0, (n_basis - 2) // 2))
    dt = check_real(dt, "dt", positive=True)
    if dt > tau:  # a grid step longer than the motion: name both
        raise ValueError(
            f"dt = {dt:g} s is longer than tau = {tau:g} s: shorten dt or lengthen tau"
        )
    length_factor = check_real(length_factor, "length_factor", positive=True, maximum=6.0)
    # the grid's size from the step before it is made (a 5e-324 s step made tau / dt infinite)
    if length_factor * tau / dt > 2_000_000:
        raise ValueError(
            f"dt = {dt:g} s gives a grid of {length_factor * tau / dt:.3g} points over the motion: "
            f"too fine (at least {length_factor * tau / 2_000_000:.3g} s)"
        )
    steps = round(1.0 / (dt / tau))
    n_grid = int(length_factor * steps) + 1
    if n_grid > 2_000_000:
        raise ValueError(
            f"dt = {dt:g} s gives a grid of {float(n_grid):.3g} points over the motion: too fine"
        )
    if alpha * length_factor / 2.0 > 700.0:
        raise ValueError("alpha * length_factor / 2 must stay below 700 (e^x overflows)")
    centres, widths = _forcing_centres(n_basis, alpha_phase, bandwidth_factor, n_outside)
    s = np.linspace(0.0, length_factor, n_grid)
    y1 = np.exp(-0.5 * alpha * s)
    y2 = s * y1
    dy1 = -0.5 * alpha * y1
    dy2 = -0.5 * alpha * y2 + y1
    grow = np.exp(0.5 * alpha * s)
    q1 = (0.5 * alpha * s - 1.0) * grow + 1.0
    q2 = 0.5 * alpha * (grow - 1.0)
    phase = np.exp(-alpha_phase * s)[:, None]
    rows = _rbf_rows(phase, centres, widths)
    dp2 = (grow[:, None] * phase) * rows
    dp1 = s[:, None] * dp2
    p1, p2 = _cumulative_trapezoid(dp1, s), _cumulative_trapezoid(dp2, s)
    position = np.column_stack([p2 * y2[:, None] - p1 * y1[:, None], q2 * y2 - q1 * y1])
    velocity = np.column_stack([p2 * dy2[:, None] - p1 * dy1[:, None], q2 * dy2 - q1 * dy1])
    return ProDMPBasis(
        n_basis, tau, delay, alpha, alpha_phase, bandwidth_factor, n_outside, dt, length_factor,
        centres, widths, position, velocity, y1, y2, dy1, dy2,
    )  # fmt: skip


def _rbf_rows(phase: np.ndarray, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
    """(P, N): the RBF basis at ``phase`` (P, 1), normalised to sum 1 when N > 1 (one kernel is
    used as it is, as MP_PyTorch does)."""
    exponent = -0.5 * (phase - centres[None, :]) ** 2 * widths[None, :]
    rows = np.exp(exponent)
    if centres.shape[0] > 1:
        sums = rows.sum(axis=1, keepdims=True)
        # A slow phase leaves some samples far from every kernel: each underflows, and 0/0 would
        # follow. Those rows are normalised in the log domain (the same ratios).
        lost = sums[:, 0] < 1e-290
        if np.any(lost):
            shifted = np.exp(exponent[lost] - exponent[lost].max(axis=1, keepdims=True))
            rows[lost], sums[lost] = shifted, shifted.sum(axis=1, keepdims=True)
        rows /= sums
    return rows


def _forcing_centres(n_basis, alpha_phase, bandwidth_factor, n_outside):
    """(centres (N,), bandwidths (N,)) in phase: MP_PyTorch's normalised RBF placement."""
    if n_basis == 1:
        return np.array([math.exp(-alpha_phase * 0.5)]), np.array([bandwidth_factor])
    spacing = 1.0 / (n_basis - 2 * n_outside - 1)
    in_time = np.linspace(-n_outside * spacing, 1.0 + n_outside * spacing, n_basis)
    in_time = np.append(in_time, in_time[-1] + (in_time[1] - in_time[0]))
    in_phase = np.exp(-alpha_phase * in_time)
    gaps = np.diff(in_phase)
    if n_basis == 2:
        gaps[-1] *= 2.0
    return in_phase[:-1], bandwidth_factor / gaps**2


def _cumulative_trapezoid(values: np.ndarray, s: np.ndarray) -> np.ndarray:
    """(P, N): the trapezoidal integral of ``values`` (P, N) from s[0] to each s[k]."""
    steps = np.diff(s)[:, None]
    out = np.zeros_like(values)
    np.cumsum(0.5 * (values[1:] + values[:-1]) * steps, axis=0, out=out[1:])
    return out
