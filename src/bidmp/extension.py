"""Extended demonstrations: segment → pick the piece → G-PRM → complete demonstration (SPEC §2–5).

``extend_demonstration(y, new_target)`` returns the complete extended demonstration

    y_dn = prefix ⊕ Tra_gen(seg → n_tar)

resampled to the demonstration's T samples. Tra_gen is the G-PRM path, smoothed (it is a
polyline) with its ends pinned. It is timed with a cubic arc-length profile that starts at the
demonstration's speed at seg, so position and speed are continuous at the junction, and that
ends at rest at the new target.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np
from scipy.signal import savgol_filter

from ._checks import as_point, as_trajectory, check_choice, check_int, check_real, numerically_guarded
from ._trajectory import arclength, interp_columns, path_extent, resample_time
from .roadmap import CollisionCallback, check_options, gaussian_prm
from .segmentation import Piece, choose_piece, segment

__all__ = ["ExtendedDemonstration", "extend_demonstration", "time_path", "check_extension_options"]

logger = logging.getLogger(__name__)

@dataclass
class ExtendedDemonstration:
    """Result of :func:`extend_demonstration` (lengths in the demonstration's unit).

    Attributes
    ----------
    complete : array (T, D)
        The extended demonstration y_dn: starts at the demonstration's start, ends exactly at the
        new target, T samples uniform in time.
    tra_imi : array (n, D)
        The demonstrated piece that was imitated (seg → tar), original samples.
    tra_gen : array (k, D)
        The generated path (seg → new target), smoothed, k = ``n_compare`` points.
    seg_index : int
        Index of seg in the demonstration.
    similarity_history : array (n_iter,)
        G-PRM similarity per iteration (empty when G-PRM was skipped).
    """

    complete: np.ndarray
    tra_imi: np.ndarray
    tra_gen: np.ndarray
    seg_index: int
    similarity_history: np.ndarray
    demonstration: np.ndarray
    new_target: np.ndarray
    segmentation_points: np.ndarray
    piece: Piece
    similarity: float = float("nan")
    template: np.ndarray | None = None
    samples: np.ndarray | None = None

    @property
    def prefix(self) -> np.ndarray:
        """The demonstration before seg, (seg_index, D)."""
        return self.demonstration[: self.seg_index]


def _smooth_path(path: np.ndarray) -> np.ndarray:
    """Savitzky–Golay smoothing of a polyline with its two ends kept exactly."""
    n_points = path.shape[0]
    window = min(11, n_points - (1 - n_points % 2))
    if window < 5:
        return path.copy()
    smooth = savgol_filter(path, window, 3, axis=0, mode="interp")
    lam = np.linspace(0.0, 1.0, n_points)[:, None]
    smooth += (1.0 - lam) * (path[0] - smooth[0]) + lam * (path[-1] - smooth[-1])
    return smooth


def time_path(path: np.ndarray, start_speed: float, mean_speed: float, dt: float) -> tuple[np.ndarray, float]:
    """Time a geometric path: a cubic arc-length profile from ``start_speed`` to rest.

    ``s(u) = L (3u² − 2u³) + a (u − 2u² + u³)`` on ``u ∈ [0, 1]`` with ``a = start_speed · D``;
    ``D = L / mean_speed``, shortened if needed so that ``a ≤ 3L`` (then ``s`` never runs back).

    Returns
    -------
    (positions, duration) : positions sampled every ``dt`` from u = 0 (excluded) to u = 1
    (included), shape (n, D), and the duration D.
    """
    s = arclength(path)
    length = s[-1]
    if length <= 0.0:
        return path[-1:].copy(), dt
    duration = length / max(mean_speed, 1e-300)
    if start_speed > 0.0:
        duration = min(duration, 3.0 * length / start_speed)
    n_steps = max(int(round(duration / dt)), 1)
    check_int(n_steps, "the generated transfer's samples (its length at the demonstrated piece's speed)",
              limit="max_steps")
    u = np.arange(1, n_steps + 1) / n_steps
    a = start_speed * duration
    arc = length * (3 * u**2 - 2 * u**3) + a * (u - 2 * u**2 + u**3)
    positions = interp_columns(arc, s, path)
    positions[-1] = path[-1]
    return positions, n_steps * dt


def check_extension_options(*, eps_frac: float = 0.1, method: str = "persistence", seed=0, **roadmap_options) -> None:
    """Validate the options of :func:`extend_demonstration` without running it (what ``bidmp
    scenario check`` runs on a scenario's ``"extension"`` key); raise naming the first bad one."""
    eps_frac = check_real(eps_frac, "eps_frac")
    if not 0.0 < eps_frac < 1.0:
        raise ValueError(f"eps_frac must lie in (0, 1), got {eps_frac}")
    check_choice(method, "method", ("persistence", "paper"))
    roadmap_options.pop("is_free", None)
    check_options(seed=seed, **roadmap_options)


@numerically_guarded
def extend_demonstration(
    y,
    new_target,
    *,
    seed: int | np.random.Generator | None = 0,
    eps_frac: float = 0.1,
    method: str = "persistence",
    n_samples: int = 300,
    sigma_rel: float = 0.03,
    n_neighbours: int = 8,
    n_compare: int = 100,
    n_iter: int = 10,
    rho: float = 0.9,
    schedule: str = "geometric",
    scaling: str = "axis",
    compare: str = "template",
    select: str = "best",
    denom: str = "sqrt2",
    is_free: CollisionCallback | None = None,
) -> ExtendedDemonstration:
    """Grow an extended demonstration from ``y`` to ``new_target`` (1D-SEG + G-PRM).

    Parameters
    ----------
    y : array (T, D), D = 2 or 3
        The demonstration, uniform in time.
    new_target : array (D,)
    seed : int or numpy.random.Generator
        Seed of the G-PRM sampling: same seed, same result.
    eps_frac, method
        Segmentation options, see :func:`bidmp.segment`.
    n_samples, sigma_rel, n_neighbours, n_compare, n_iter, rho, schedule, scaling, compare, select, denom, is_free
        G-PRM options, see :func:`bidmp.roadmap.gaussian_prm` (same defaults).

    Returns
    -------
    ExtendedDemonstration
    """
    y = as_trajectory(y, "y", min_points=10)
    target = as_point(new_target, y.shape[1], "new_target")
    check_extension_options(
        eps_frac=eps_frac, method=method, seed=seed, n_samples=n_samples, sigma_rel=sigma_rel, n_neighbours=n_neighbours,
        n_compare=n_compare, n_iter=n_iter, rho=rho, schedule=schedule, scaling=scaling, compare=compare, select=select,
        denom=denom,
    )
    n_steps = y.shape[0]
    dt = 1.0 / n_steps

    points = segment(y, eps_frac=eps_frac, method=method).points
    piece = choose_piece(y, points, target)
    tra_imi = y[piece.start : piece.end + 1]
    seg = y[piece.start]
    roadmap_options = {
        "n_samples": n_samples, "sigma_rel": sigma_rel, "n_neighbours": n_neighbours, "n_compare": n_compare,
        "n_iter": n_iter, "rho": rho, "schedule": schedule, "scaling": scaling, "compare": compare,
        "select": select, "denom": denom, "is_free": is_free,
    }

    extent = path_extent(y)
    if np.linalg.norm(target - seg) <= 1e-9 * extent:
        logger.info("new target coincides with seg: G-PRM skipped")
        tra_gen = np.vstack([seg, target])
        history = np.empty(0)
        result = None
    else:
        result = gaussian_prm(tra_imi, target, seed=seed, **roadmap_options)
        tra_gen = _smooth_path(result.path)
        history = result.history

    prefix = y[: piece.start + 1]  # includes seg
    start_speed = float(np.linalg.norm(y[piece.start] - y[piece.start - 1]) / dt) if piece.start > 0 else 0.0
    imi_duration = max(piece.end - piece.start, 1) * dt
    mean_speed = arclength(tra_imi)[-1] / imi_duration
    if mean_speed <= 0.0:
        mean_speed = arclength(y)[-1]  # the piece does not move: use the demonstration's mean speed
    timed, _ = time_path(tra_gen, start_speed, mean_speed, dt)
    complete = resample_time(np.vstack([prefix, timed]), n_steps)
    complete[-1] = target
    logger.debug("extended demonstration: piece %d (samples %d-%d), %d G-PRM iterations",
                 piece.index, piece.start, piece.end, len(history))
    return ExtendedDemonstration(
        complete=complete, tra_imi=tra_imi.copy(), tra_gen=tra_gen, seg_index=piece.start,
        similarity_history=np.asarray(history), demonstration=y, new_target=target,
        segmentation_points=points, piece=piece,
        similarity=float("nan") if result is None else result.similarity,
        template=None if result is None else result.template,
        samples=None if result is None else result.samples,
    )
