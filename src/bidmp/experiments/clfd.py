"""Continual learning from demonstration on the field's own protocol (CLFD: Auddy, Hollenstein,
Saveriano, Rodríguez-Sánchez, Piater, Robotics and Autonomous Systems 2023).

Tasks arrive one at a time in the protocol's order (LASA: 26 shapes, 7 demonstrations each, raw
LASA units). After learning task i, every task j ≤ i is evaluated: each of its demonstrations is
reproduced from that demonstration's own start, on the first demonstration's time vector, and
compared with the demonstration by

* **DTW**: Euclidean point distances accumulated along the optimal warping path, not normalised
  (:func:`bidmp.extension.dtw_distance`);
* **discrete Fréchet** distance (:func:`bidmp.extension.frechet_distance`);
* **swept error area**: the areas of the quadrilaterals between corresponding points
  (:func:`swept_error_area`, the LASA benchmark's).

Entry (i, j) of a metric's accuracy matrix is the fraction of task j's demonstrations whose error
is within the protocol's threshold (DTW 2191, Fréchet 5.0, swept area 70.0). From the
lower-triangular matrix A of N tasks (:func:`continual_metrics`): ACC = Σ_{j≤i} A[i, j] /
(N (N + 1) / 2); BWT = the mean over j < i of A[i, j] − A[j, j]; REM = 1 − |min(BWT, 0)|; MS =
min(1, the mean over i of size(after task 0) / size(after task i)) — a library that grows by one
equal block per task scores H_N / N; TE = min(1, the mean over i of time(task 0) / time(task i));
FS = 1 − size / the largest size compared. CL_score is the mean of ACC, REM, MS, TE and FS;
CL_stability 1 − their standard deviation (ddof 1).

The methods (``METHODS``) learn a task from its demonstrations and reproduce any task seen:
``dmp-library`` keeps one DMP per task (:class:`DMPLibrary`), ``finetune`` one DMP refitted on
each (:class:`FineTune`), ``promp-library`` one ProMP per task (:class:`ProMPLibrary`);
``bidmp-continual`` is one BLS of a fixed size that gives every task's DMP from the task's code
(:class:`ContinualBLS`).
"""

from __future__ import annotations

import json
import logging
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .._checks import _as_bounded_array, as_trajectory, as_vector, check_choice, check_real
from .._progress import report
from .._trajectory import interp_columns
from ..extension.similarity import dtw_distance, frechet_distance
from ..tasks.metrics import swept_area

__all__ = [
    "CLFD_THRESHOLDS",
    "ClfdResult",
    "ClfdRow",
    "ClfdTask",
    "ContinualBLS",
    "DMPLibrary",
    "FineTune",
    "ProMPLibrary",
    "accuracy_matrix",
    "clfd_tasks",
    "continual_metrics",
    "orientation_error",
    "run_clfd",
    "swept_error_area",
    "write_clfd",
]

logger = logging.getLogger(__name__)

DATA = Path(__file__).resolve().parents[1] / "data" / "clfd"
# The protocol's thresholds on LASA (raw LASA units)
CLFD_THRESHOLDS = {"dtw": 2191.0, "frechet": 5.0, "area": 70.0}
_METRICS = ("dtw", "frechet", "area")
# The smallest of the published hypernetworks (Auddy et al.: 1.8-4.3 M parameters): the models
# compared for FS include it, as the field's tables do
PUBLISHED_HYPERNETWORK_PARAMETERS = 1_800_000
# The published best's mean DTW over the tasks seen after all 26 LASA tasks (read from the
# authors' figure, about ±5 %)
PUBLISHED_BEST_MEAN_DTW = 1.7e3


@dataclass(frozen=True)
class ClfdTask:
    """One task of the protocol: its ``name``, its demonstrations ``positions`` (M, T, D) and
    their ``times`` (M, T) in seconds."""

    name: str
    positions: np.ndarray
    times: np.ndarray


def clfd_tasks(dataset: str = "lasa") -> list[ClfdTask]:
    """The protocol's tasks in the order they are learned (``"lasa"``: the 26 LASA shapes of the
    CLFD data vendored with bidmp, MIT, ``bidmp/data/clfd/LICENSE``)."""
    check_choice(dataset, "dataset", ("lasa",))
    folder = DATA / "LASA"
    order = [line.strip() for line in (folder / "lasa_numpy_sequence_all.txt").read_text().split()]
    names = list(json.loads((folder / "lasa_names.json").read_text()))
    tasks = []
    for file_name in order:
        index = int(file_name.split("_")[1][1:])
        with np.load(folder / "lasa_numpy" / file_name) as archive:
            tasks.append(ClfdTask(names[index], archive["pos"].astype(float), archive["t"]))
    return tasks


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
    true = true / np.linalg.norm(true, axis=1, keepdims=True)
    predicted = predicted / np.linalg.norm(predicted, axis=1, keepdims=True)
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


def _task_dmp(task: ClfdTask, n_kernels: int):
    """(a paper-protocol DMP of ``n_kernels`` kernels fitted on the task's mean demonstration
    on its first time vector, the mean of the demonstrations' ends: its goal)."""
    from ..primitives import DMP

    dmp = DMP(protocol="paper", n_kernels=n_kernels).fit(task.positions.mean(axis=0), task.times[0])
    return dmp, task.positions[:, -1].mean(axis=0)


def _rollouts(dmp, goal: np.ndarray, starts: np.ndarray, t: np.ndarray) -> np.ndarray:
    """(M, T, D): ``dmp`` to ``goal`` from each of ``starts`` (M, D), on the time vector ``t``
    (its duration, its step; sampled at ``t``)."""
    duration, step = float(t[-1] - t[0]), float(t[1] - t[0])
    motions = (dmp.trajectory(goal, start=start, duration=duration, dt=step) for start in starts)
    return np.array([interp_columns(t, motion.t, motion.y) for motion in motions])


class DMPLibrary:
    """``dmp-library``: one DMP per task, fitted on the task's mean demonstration (the paper's
    protocol, ``n_kernels`` kernels, on the first demonstration's time vector) and reproduced
    from a start to the mean of the demonstrations' ends. Nothing learned later touches an
    earlier task's DMP (REM = 1 by construction); the size grows by one DMP per task."""

    name = "dmp-library"

    def __init__(self, n_kernels: int = 50):
        self.n_kernels = n_kernels
        self._skills: list = []

    def learn(self, task: ClfdTask) -> None:

        self._skills.append(_task_dmp(task, self.n_kernels))

    def reproduce(self, index: int, starts: np.ndarray, t: np.ndarray) -> np.ndarray:
        """(M, T, D): task ``index`` reproduced from each of ``starts`` (M, D) on times ``t``."""
        return _rollouts(*self._skills[index], starts, t)

    @property
    def n_parameters(self) -> int:
        """Weights, goals and starts kept: one DMP's forcing weights and goal per task."""
        return sum(dmp.weights_.size + goal.size for dmp, goal in self._skills)


class ContinualBLS:
    """``bidmp-continual``: one Broad Learning System over all tasks, of a fixed size, used as a
    hypernetwork — the task's code in, its DMP out (the forcing weights and the goal of a
    paper-protocol DMP with ``n_kernels`` kernels fitted on the task's mean demonstration; the
    protocol gives the time vector).

    The task code is one-hot over a capacity of ``capacity`` tasks; ``n_nodes`` enhancement
    nodes ``tanh(R code + b)`` (R, b drawn once from ``seed``) feed linear output weights W.
    W is the ridge solution (``ridge`` relative to the mean diagonal) of the normal equations
    accumulated task by task — ``A += HᵀH``, ``B += HᵀY`` — so after task i it is exactly the ridge
    fit on tasks 0..i (tested), and nothing of a task is kept but its share of A and B. Its size
    never changes (MS = 1). With more nodes than tasks the fit reproduces every task's DMP nearly
    exactly, so learning a task moves the earlier ones only by the ridge's share."""

    name = "bidmp-continual"

    def __init__(
        self, n_kernels: int = 50, n_nodes: int = 64, capacity: int = 26, ridge=1e-10, seed=0
    ):
        self.n_kernels, self.n_nodes, self.capacity = n_kernels, n_nodes, capacity
        self.ridge, self.seed = ridge, seed
        rng = np.random.default_rng(seed)
        self._projection = rng.normal(size=(n_nodes, capacity))
        self._bias = rng.normal(size=n_nodes)
        self._gram = None  # A (n_nodes, n_nodes) and B (n_nodes, outputs): what the update needs
        self._cross = None
        self._weights = None
        self._template = None  # a DMP of the same structure, its learned state replaced per task
        self._seen = 0

    def _nodes(self, index: int) -> np.ndarray:
        return np.tanh(self._projection[:, index] + self._bias)

    def learn(self, task: ClfdTask) -> None:

        if self._seen >= self.capacity:
            raise ValueError(f"bidmp-continual holds {self.capacity} tasks (its capacity)")
        dmp, goal = _task_dmp(task, self.n_kernels)
        target = np.concatenate([dmp.weights_.ravel(), goal])
        nodes = self._nodes(self._seen)[None]
        if self._gram is None:
            self._template = dmp
            self._gram = np.zeros((self.n_nodes, self.n_nodes))
            self._cross = np.zeros((self.n_nodes, target.size))
        self._gram += nodes.T @ nodes
        self._cross += nodes.T @ target[None]
        regularised = self._gram + self.ridge * np.trace(self._gram) / self.n_nodes * np.eye(
            self.n_nodes
        )
        self._weights = np.linalg.solve(regularised, self._cross)
        self._seen += 1

    def reproduce(self, index: int, starts: np.ndarray, t: np.ndarray) -> np.ndarray:
        """(M, T, D): task ``index``'s DMP, as the BLS gives it, from each of ``starts``."""
        import copy

        output = self._nodes(index) @ self._weights
        dims = starts.shape[1]
        dmp = copy.copy(self._template)
        dmp.weights_ = output[: self.n_kernels * dims].reshape(self.n_kernels, dims)
        return _rollouts(dmp, output[self.n_kernels * dims :], starts, t)

    @property
    def n_parameters(self) -> int:
        """The fixed network: projection, bias and output weights."""
        outputs = self.n_kernels * 2 + 2 if self._weights is None else self._weights.shape[1]
        return self._projection.size + self._bias.size + self.n_nodes * outputs


class FineTune:
    """``finetune``: one DMP, refitted on each new task's mean demonstration (the paper's
    protocol, ``n_kernels`` kernels); every task is reproduced by the latest, to the latest
    goal — forgetting by construction, the protocol's lower bound. Its size never changes."""

    name = "finetune"

    def __init__(self, n_kernels: int = 50):
        self.n_kernels = n_kernels
        self._latest = None

    def learn(self, task: ClfdTask) -> None:
        self._latest = DMPLibrary(self.n_kernels)
        self._latest.learn(task)

    def reproduce(self, index: int, starts: np.ndarray, t: np.ndarray) -> np.ndarray:
        return self._latest.reproduce(0, starts, t)

    @property
    def n_parameters(self) -> int:
        return self._latest.n_parameters


class ProMPLibrary:
    """``promp-library``: one ProMP per task (``n_basis`` basis functions, from the task's
    demonstrations), reproduced as its mean conditioned exactly on the start, on the time
    vector. Nothing learned later touches an earlier task's ProMP; one ProMP's mean and
    covariance more per task."""

    name = "promp-library"

    def __init__(self, n_basis: int = 30):
        self.n_basis = n_basis
        self._skills: list = []

    def learn(self, task: ClfdTask) -> None:
        from ..primitives import ProMP

        self._skills.append(ProMP(n_basis=self.n_basis).fit(list(task.positions)))

    def reproduce(self, index: int, starts: np.ndarray, t: np.ndarray) -> np.ndarray:
        promp = self._skills[index]
        return np.array(
            [promp.condition([0.0], start[None], 0.0).mean(n_steps=len(t)) for start in starts]
        )

    @property
    def n_parameters(self) -> int:
        """Means and covariances of the weights kept, one ProMP per task."""
        return sum(p.weight_mean_.size + p.weight_cov_.size for p in self._skills)


METHODS = {
    "dmp-library": DMPLibrary,
    "finetune": FineTune,
    "promp-library": ProMPLibrary,
    "bidmp-continual": ContinualBLS,
}


@dataclass
class ClfdRow:
    """One method's run: ``errors[metric][i][j]`` (M,) per demonstration of task j after task
    i, the accuracy matrices, the figures, sizes and training times per task, and the mean DTW
    over the tasks seen after each task."""

    method: str
    errors: dict = field(default_factory=dict)
    matrices: dict = field(default_factory=dict)
    metrics: dict = field(default_factory=dict)
    sizes: list = field(default_factory=list)
    times: list = field(default_factory=list)

    @property
    def mean_dtw_seen(self) -> list[float]:
        """After each task i, the mean over the tasks seen of their mean DTW."""
        return [float(np.mean([np.mean(e) for e in seen])) for seen in self.errors["dtw"]]

    def to_dict(self) -> dict:
        return {
            "method": self.method,
            "metrics": self.metrics,
            "accuracy_matrices": {
                name: [[None if np.isnan(v) else float(v) for v in row] for row in matrix]
                for name, matrix in self.matrices.items()
            },
            "mean_dtw_over_tasks_seen": [float(v) for v in self.mean_dtw_seen],
            "model_size": [int(v) for v in self.sizes],
            "training_time_s": [float(v) for v in self.times],
        }


@dataclass
class ClfdResult:
    """The protocol's outcome: the dataset, its task names, one :class:`ClfdRow` per method."""

    dataset: str
    tasks: list
    rows: dict

    def to_dict(self) -> dict:
        return {
            "dataset": self.dataset,
            "tasks": self.tasks,
            "thresholds": CLFD_THRESHOLDS,
            "methods": {name: row.to_dict() for name, row in self.rows.items()},
        }

    def markdown(self) -> str:
        lines = [
            f"# Continual learning from demonstration: CLFD protocol, {self.dataset} "
            f"({len(self.tasks)} tasks)",
            "",
            "Accuracy by DTW (threshold 2191); mean DTW over the tasks seen after the last task; "
            f"FS against the largest model compared, at least the published hypernetwork's "
            f"{PUBLISHED_HYPERNETWORK_PARAMETERS:,} parameters.",
            "",
            "| method | ACC | BWT | REM | MS | TE | FS | CL_score | CL_stability | mean DTW | "
            "ACC Fréchet | ACC area |",
            "|---|" + "---:|" * 11,
        ]
        for name, row in self.rows.items():
            m = row.metrics["dtw"]
            lines.append(
                f"| {name} | {m['ACC']:.3f} | {m['BWT']:.3f} | {m['REM']:.3f} | {m['MS']:.3f} | "
                f"{m['TE']:.3f} | {m['FS']:.3f} | {m['CL_score']:.3f} | {m['CL_stability']:.3f} | "
                f"{row.mean_dtw_seen[-1]:.0f} | {row.metrics['frechet']['ACC']:.3f} | "
                f"{row.metrics['area']['ACC']:.3f} |"
            )
        return "\n".join(lines) + "\n"


def run_clfd(
    dataset: str = "lasa", methods=("dmp-library",), n_tasks: int | None = None
) -> ClfdResult:
    """The protocol (module docstring) for each of ``methods`` (names of ``METHODS``) on the
    first ``n_tasks`` tasks of ``dataset`` (default all)."""
    tasks = clfd_tasks(dataset)
    if n_tasks is not None:
        tasks = tasks[: int(n_tasks)]
    rows = {}
    for name in methods:
        check_choice(name, "methods", tuple(METHODS))
        rows[name] = _run_method(METHODS[name](), tasks)
    largest = max([PUBLISHED_HYPERNETWORK_PARAMETERS] + [row.sizes[-1] for row in rows.values()])
    for row in rows.values():
        row.metrics = {
            metric: continual_metrics(row.matrices[metric], row.sizes, row.times, largest)
            for metric in _METRICS
        }
    return ClfdResult(dataset, [task.name for task in tasks], rows)


def _run_method(method, tasks: list[ClfdTask]) -> ClfdRow:
    row = ClfdRow(method.name, errors={metric: [] for metric in _METRICS})
    for i, task in enumerate(tasks):
        began = time.process_time()  # one core's time: the protocol's training time per task
        method.learn(task)
        row.times.append(time.process_time() - began)
        row.sizes.append(method.n_parameters)
        seen = {metric: [] for metric in _METRICS}
        for j, earlier in enumerate(tasks[: i + 1]):
            t = earlier.times[0]
            reproduced = method.reproduce(j, earlier.positions[:, 0], t)
            pairs = list(zip(reproduced, earlier.positions))
            seen["dtw"].append(np.array([dtw_distance(r, d) for r, d in pairs]))
            seen["frechet"].append(np.array([frechet_distance(r, d) for r, d in pairs]))
            seen["area"].append(np.array([swept_error_area(r, d) for r, d in pairs]))
        for metric in _METRICS:
            row.errors[metric].append(seen[metric])
        report(f"CLFD {method.name}", i + 1, len(tasks))
    row.matrices = {
        metric: accuracy_matrix(row.errors[metric], CLFD_THRESHOLDS[metric]) for metric in _METRICS
    }
    return row


def write_clfd(result: ClfdResult, out) -> list[Path]:
    """``clfd.json``, ``clfd.md`` and the figures (``clfd_accuracy.png``: the accuracy matrices
    as heat maps; ``clfd_dtw.png``: the mean DTW over the tasks seen against the task index,
    the published best marked) in the folder ``out`` (written atomically)."""
    from ..io.atomic import atomic_write

    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = [out / "clfd.json", out / "clfd.md"]
    for path, text in zip(
        written, (json.dumps(result.to_dict(), indent=1) + "\n", result.markdown())
    ):
        with atomic_write(path, "w") as handle:
            handle.write(text)
    from ..plotting.clfd import plot_clfd

    # the published figure is after all 26 LASA tasks: marked only on a run of them all
    reference = PUBLISHED_BEST_MEAN_DTW if len(result.tasks) == 26 else None
    return written + plot_clfd(out, result.rows, reference)
