"""The protocol's errors and figures: per demonstration the DTW (Euclidean point distances
accumulated along the optimal warping path, not normalised), the discrete Fréchet distance, the
swept error area (2-D) and the orientation error; the accuracy matrix of one error against its
threshold; and from it ACC, BWT, REM, MS, TE, FS, CL_score and CL_stability."""

from __future__ import annotations

import numpy as np

from ..._checks import (
    _as_bounded_array,
    _check_finite,
    _check_magnitude,
    as_trajectory,
    as_vector,
    check_choice,
    check_real,
)
from ..._norms import row_norms, unit_rows
from ...extension.similarity import dtw_distance, frechet_distance
from ...tasks.metrics import swept_area

__all__ = [
    "CLFD_THRESHOLDS",
    "accuracy_matrix",
    "continual_metrics",
    "demonstration_errors",
    "orientation_error",
    "swept_error_area",
]

# The protocol's thresholds per data set. LASA's are the protocol's (raw LASA units).
# RoboTasks9 has no published thresholds: its are the published best's medians (position DTW
# 1.8e3, orientation 0.045 rad), so its accuracy is the share of demonstrations reproduced at
# least as well as the published best's median one; its Fréchet distance is reported without
# one (None).
CLFD_THRESHOLDS = {
    "lasa": {"dtw": 2191.0, "frechet": 5.0, "area": 70.0},
    "robottasks": {"dtw": 1.8e3, "frechet": None, "orientation": 0.045},
}


def demonstration_errors(reproduced: np.ndarray, demonstrations: np.ndarray, metrics) -> dict:
    """Per demonstration, each of ``metrics`` ("dtw", "frechet", "area", "orientation") between
    ``reproduced`` (M, T, D [+ 4]) and ``demonstrations`` of the same shape: the position
    metrics on the first D columns, the orientation error on the last 4 (w, x, y, z). Returns
    metric -> (M,)."""
    reproduced = _as_bounded_array(reproduced, "reproduced", max_ndim=3)
    demonstrations = _as_bounded_array(demonstrations, "demonstrations", max_ndim=3)
    if reproduced.ndim != 3 or reproduced.shape != demonstrations.shape:
        raise ValueError(
            "reproduced and demonstrations must be (M, T, D) of one shape, got "
            f"{reproduced.shape} and {demonstrations.shape}"
        )
    for name, array in (("reproduced", reproduced), ("demonstrations", demonstrations)):
        _check_finite(array, name)
        _check_magnitude(array, name)  # (named here, not as the distances' a and b)
    if not isinstance(metrics, (list, tuple, dict)) or not metrics or len(metrics) > 4:
        raise TypeError("metrics must be a sequence of metric names (at most 4)")
    for metric in metrics:
        check_choice(metric, "metrics", ("dtw", "frechet", "area", "orientation"))
    pose = "orientation" in metrics
    if pose and reproduced.shape[2] < 5:
        raise ValueError("an orientation error needs poses: positions, then w, x, y, z (D + 4)")
    errors = {}
    for metric in metrics:
        values = []
        for r, d in zip(reproduced, demonstrations):
            if metric == "orientation":
                values.append(orientation_error(d[:, -4:], r[:, -4:]))
                continue
            r, d = (r[:, :-4], d[:, :-4]) if pose else (r, d)
            if metric == "dtw":
                values.append(dtw_distance(r, d))
            elif metric == "frechet":
                values.append(frechet_distance(r, d))
            else:
                values.append(swept_error_area(r, d))
        errors[metric] = np.array(values)
    return errors


def swept_error_area(trajectory, reference) -> float:
    """The swept error area between a ``trajectory`` and its ``reference`` (T, 2) of
    corresponding points: the sum over i of the shoelace area of the quadrilateral r_i, r_{i+1},
    y_{i+1}, y_i, absolute per quadrilateral — the LASA benchmark's
    :func:`bidmp.tasks.metrics.swept_area`, one definition for both."""
    return swept_area(trajectory, reference)


def orientation_error(true, predicted) -> float:
    """The protocol's orientation error: ‖2 · log(q_true ⊗ q̄_predicted)‖ averaged over time, of
    unit quaternions (T, 4) in **w, x, y, z** order (rad; the shorter way round)."""
    true = as_trajectory(true, "true", min_points=1, allow_static=True)
    predicted = as_trajectory(predicted, "predicted", min_points=1, allow_static=True)
    if true.shape != predicted.shape or true.shape[1] != 4:
        raise ValueError(
            f"true and predicted must be quaternions (T, 4) of equal length, got {true.shape} and "
            f"{predicted.shape}"
        )
    for name, quaternions in (("true", true), ("predicted", predicted)):
        zero = row_norms(quaternions) == 0.0  # (scaled first: a row of 1e-300 is a direction)
        if np.any(zero):
            raise ValueError(
                f"{name}: row {int(np.argmax(zero))} is a zero quaternion, which is no rotation"
            )
    true, predicted = unit_rows(true), unit_rows(predicted)
    # the real part of q_true ⊗ conj(q_pred) is their dot product; the angle of the relative
    # rotation is 2 acos(|w|), which is ‖2 log(·)‖ taken the shorter way
    w = np.clip(np.abs(np.sum(true * predicted, axis=1)), 0.0, 1.0)
    return float(np.mean(2.0 * np.arccos(w)))


def accuracy_matrix(errors: list[list[np.ndarray]], threshold: float) -> np.ndarray:
    """(N, N): entry (i, j), j ≤ i, the fraction of task j's errors ``errors[i][j]`` (one per
    demonstration) within ``threshold``; NaN above the diagonal."""
    threshold = check_real(threshold, "threshold")
    if not isinstance(errors, (list, tuple)) or not 1 <= len(errors) <= 1000:
        raise TypeError("errors must be a list (one per task learned) of lists of error arrays")
    n = len(errors)
    matrix = np.full((n, n), np.nan)
    for i, row in enumerate(errors):
        if not isinstance(row, (list, tuple)) or len(row) != i + 1:
            raise ValueError(f"errors[{i}] must hold the errors of tasks 0-{i} ({i + 1} arrays)")
        for j in range(i + 1):
            values = as_vector(row[j], f"errors[{i}][{j}]")
            matrix[i, j] = float(np.mean(values <= threshold))
    return matrix


def continual_metrics(
    matrix: np.ndarray, sizes, times, largest_size: float | None = None
) -> dict[str, float]:
    """ACC, BWT, REM, MS, TE, FS, CL_score and CL_stability (module docstring) of a
    lower-triangular accuracy ``matrix`` (N, N), the model's ``sizes`` (N,) after each task
    (parameters) and its training ``times`` (N,) per task (s); ``largest_size``: the largest
    model compared (default this one's last)."""
    matrix = _as_bounded_array(matrix, "matrix", max_ndim=2)
    n = matrix.shape[0] if matrix.ndim == 2 else 0
    if matrix.ndim != 2 or n == 0 or matrix.shape != (n, n):
        raise ValueError(f"matrix must be a square accuracy matrix (N, N), got {matrix.shape}")
    sizes = as_vector(sizes, "sizes", length=n, positive=True)
    times = as_vector(times, "times", length=n)
    if np.any(times < 0):
        raise ValueError("times must be >= 0 (seconds per task)")
    lower = np.tril_indices(n)
    if not np.all((matrix[lower] >= 0.0) & (matrix[lower] <= 1.0)):
        raise ValueError("matrix must hold accuracies in [0, 1] on and below its diagonal")
    if largest_size is not None:
        largest_size = check_real(largest_size, "largest_size", positive=True)
        if largest_size < sizes[-1]:  # FS = 1 - size / largest compared, in [0, 1]
            raise ValueError(
                f"largest_size must be at least the model's own size {sizes[-1]:g} (the largest "
                f"model compared), got {largest_size:g}"
            )
    acc = float(np.sum(matrix[lower]) / (n * (n + 1) / 2))
    below = np.tril_indices(n, -1)
    bwt = float(np.mean(matrix[below] - np.diag(matrix)[below[1]])) if n > 1 else 0.0
    rem = 1.0 - abs(min(bwt, 0.0))
    ms = float(min(1.0, np.mean(sizes[0] / sizes)))
    te = float(min(1.0, np.mean(times[0] / np.maximum(times, 1e-12))))
    fs = 1.0 - float(sizes[-1]) / float(largest_size if largest_size is not None else sizes[-1])
    parts = np.array([acc, rem, ms, te, fs])
    return {
        "ACC": acc,
        "BWT": bwt,
        "REM": rem,
        "MS": ms,
        "TE": te,
        "FS": fs,
        "CL_score": float(np.mean(parts)),
        "CL_stability": float(1.0 - np.std(parts, ddof=1)),
    }
