"""The rows of the protocol: each method learns a task from its demonstrations
(:meth:`learn`) and reproduces any task seen from given starts (:meth:`reproduce`).

A method sees poses (positions, then a w, x, y, z quaternion on a pose task) and learns curves in
the task's :class:`~bidmp.experiments.clfd.data.TangentChart`, so every primitive of positions
learns orientations on the unit sphere too. Adding a method: a class with ``name``,
``learn(task)``, ``reproduce(index, starts, t)`` and ``n_parameters`` (or subclass
:class:`ClfdMethod` and write ``_learn_curves`` and ``_reproduce_curves``), then one entry in
:data:`METHODS`.
"""

from __future__ import annotations

import copy

import numpy as np

from ..._checks import (
    _as_bounded_array,
    _check_finite,
    _check_magnitude,
    as_vector,
    check_int,
    check_real,
    check_seed,
)
from ..._trajectory import interp_columns
from .data import ClfdTask, TangentChart

__all__ = [
    "BiDMPLibrary",
    "ClfdMethod",
    "ContinualBLS",
    "DMPLibrary",
    "FineTune",
    "METHODS",
    "MapLibrary",
    "ProMPLibrary",
]

# The DMP rows' kernels. The one-DMP-per-task baseline's DTW falls monotonically with them on
# LASA (1265 at 25, 1149 at 40, 1128 at 50); 40 reproduces the figures measured outside the
# project on this protocol (mean DTW 1163, ACC 0.897) within 3 % — the count those were taken
# with is not published.
CLFD_KERNELS = 40
# The ProMP rows' basis functions: the exact conditioning on a start needs the start to be
# represented well; on RoboTasks9's orientations 30 left a median error of 0.067 rad, 100
# 0.037 (LASA's DTW: 667 at 30, 663 at 100).
CLFD_BASIS = 100
# The ProMP's covariance regulariser, relative to the mean variance: small, so conditioning on
# a start is the demonstrations' own least-norm combination starting there (the limit the
# sample covariance of a few demonstrations gives), not the mean shifted.
CLFD_COV_REG = 1e-9


def _rollouts(dmp, goal: np.ndarray, starts: np.ndarray, t: np.ndarray, increment=None):
    """(M, T, D): ``dmp`` (or a :class:`~bidmp.BiDMP` skill: ``increment`` its index) to
    ``goal`` from each of ``starts`` (M, D), on the time vector ``t`` (its duration and step;
    sampled at ``t``)."""
    duration, step = float(t[-1] - t[0]), float(t[1] - t[0])
    if increment is None:
        motions = (dmp.trajectory(goal, start=s, duration=duration, dt=step) for s in starts)
    else:
        motions = (
            dmp.trajectory(goal, skill=increment, start=s, duration=duration, dt=step)
            for s in starts
        )
    return np.array([interp_columns(t, motion.t, motion.y) for motion in motions])


def _task_dmp(curves: np.ndarray, t: np.ndarray, n_kernels: int):
    """(a paper-protocol DMP of ``n_kernels`` kernels fitted on the mean of ``curves`` (M, T,
    D) on the time vector ``t``, the mean of the curves' ends: its goal)."""
    from ...primitives import DMP

    dmp = DMP(protocol="paper", n_kernels=n_kernels).fit(curves.mean(axis=0), t)
    return dmp, curves[:, -1].mean(axis=0)


class ClfdMethod:
    """A method that learns each task's curves in the task's chart (the positions as they are,
    a pose's orientation as its logarithm at the task's first start orientation). Subclasses
    write ``_learn_curves(curves (M, T, D), t (T,))`` and ``_reproduce_curves(index, starts (M,
    D), t) -> (M, T, D)``; :meth:`_chart` gives task ``index``'s chart (by default kept, 4
    numbers per pose task)."""

    name = "method"

    def __init__(self):
        self._charts: list[TangentChart] = []
        self._widths: list[int] = []  # each task's pose columns: what its starts must have

    def learn(self, task: ClfdTask) -> None:
        """Learn ``task`` (all its demonstrations)."""
        self._record(task)
        chart = TangentChart.of_task(task)
        self._charts.append(chart)
        self._learn_curves(chart.curves(task.poses), task.times[0])

    def reproduce(self, index: int, starts: np.ndarray, t: np.ndarray) -> np.ndarray:
        """(M, T, D [+ 4]): task ``index`` reproduced from each of ``starts`` (M, D [+ 4]) on the
        time vector ``t`` (T,), s."""
        index, starts, t = self._request(index, starts, t)
        chart = self._chart(index)
        return chart.poses(self._reproduce_curves(index, chart.curves(starts), t))

    def _record(self, task) -> None:
        """Refuse what is not a task; keep its pose columns (what a start of it has)."""
        if not isinstance(task, ClfdTask):
            raise TypeError(
                f"task must be a bidmp.experiments.ClfdTask (clfd_tasks gives them), got "
                f"{type(task).__name__}"
            )
        self._widths.append(task.poses.shape[2])

    def _request(self, index, starts, t) -> tuple[int, np.ndarray, np.ndarray]:
        """``reproduce``'s arguments checked: a task learned, one start (D [+ 4]) per motion, a
        time vector of two or more increasing stamps (s)."""
        learned = len(self._widths)
        if not learned:
            raise ValueError(f"index: {self.name} has learned no task yet (call learn(task))")
        index = check_int(index, "index", minimum=0, maximum=learned - 1)
        width = self._widths[index]
        starts = _as_bounded_array(starts, "starts", 2)
        if starts.ndim != 2 or starts.shape[1] != width or starts.shape[0] == 0:
            raise ValueError(
                f"starts must be (M, {width}), one start per motion as task {index}'s poses have "
                f"them, got shape {starts.shape}"
            )
        _check_finite(starts, "starts")
        _check_magnitude(starts, "starts")
        t = as_vector(t, "t", min_length=2)
        if np.any(np.diff(t) <= 0.0):
            raise ValueError("t must increase (the time vector of the motions, s)")
        return index, starts, t

    def _chart(self, index: int) -> TangentChart:
        return self._charts[index]

    def _chart_size(self) -> int:
        return sum(0 if c.reference is None else 4 for c in self._charts)

    def _learn_curves(self, curves: np.ndarray, t: np.ndarray) -> None:
        raise NotImplementedError

    def _reproduce_curves(self, index: int, starts: np.ndarray, t: np.ndarray) -> np.ndarray:
        raise NotImplementedError


class DMPLibrary(ClfdMethod):
    """``dmp-library``: one DMP per task, fitted on the task's mean demonstration (the paper's
    protocol, ``n_kernels`` kernels, on the first demonstration's time vector) and reproduced
    from a start to the mean of the demonstrations' ends. Nothing learned later touches an
    earlier task's DMP (REM = 1 by construction); the size grows by one DMP per task."""

    name = "dmp-library"

    def __init__(self, n_kernels: int = CLFD_KERNELS):
        super().__init__()
        self.n_kernels = check_int(n_kernels, "n_kernels", minimum=2, limit="max_kernels")
        self._skills: list = []

    def _learn_curves(self, curves, t) -> None:
        self._skills.append(_task_dmp(curves, t, self.n_kernels))

    def _reproduce_curves(self, index, starts, t):
        return _rollouts(*self._skills[index], starts, t)

    @property
    def n_parameters(self) -> int:
        """One DMP's forcing weights and goal per task (and a pose task's chart)."""
        kept = sum(dmp.weights_.size + goal.size for dmp, goal in self._skills)
        return kept + self._chart_size()


class FineTune(ClfdMethod):
    """``finetune``: one DMP, refitted on each new task's mean demonstration (the paper's
    protocol, ``n_kernels`` kernels); every task is reproduced by the latest, to the latest
    goal, in the latest chart — forgetting by construction, the protocol's lower bound. Its size
    never changes."""

    name = "finetune"

    def __init__(self, n_kernels: int = CLFD_KERNELS):
        super().__init__()
        self.n_kernels = check_int(n_kernels, "n_kernels", minimum=2, limit="max_kernels")
        self._latest = None

    def learn(self, task: ClfdTask) -> None:
        self._record(task)
        self._latest = DMPLibrary(self.n_kernels)
        self._latest.learn(task)

    def reproduce(self, index, starts, t):
        index, starts, t = self._request(index, starts, t)
        latest = self._widths[-1]
        if starts.shape[1] != latest:
            raise ValueError(
                f"starts: task {index} has {starts.shape[1]} pose columns, the latest task (which "
                f"reproduces every task) {latest}"
            )
        return self._latest.reproduce(0, starts, t)

    @property
    def n_parameters(self) -> int:
        return self._latest.n_parameters


class ProMPLibrary(ClfdMethod):
    """``promp-library``: one ProMP per task (``n_basis`` basis functions, from all the task's
    demonstrations, covariance regularised by ``cov_reg``), reproduced as its mean conditioned
    exactly on the start. Nothing learned later touches an earlier task's ProMP; one ProMP's
    mean and covariance more per task."""

    name = "promp-library"

    def __init__(self, n_basis: int = CLFD_BASIS, cov_reg: float = CLFD_COV_REG):
        super().__init__()
        self.n_basis = check_int(n_basis, "n_basis", minimum=2, limit="max_kernels")
        self.cov_reg = check_real(cov_reg, "cov_reg", positive=True, maximum=1e3)
        self._skills: list = []

    def _learn_curves(self, curves, t) -> None:
        from ...primitives import ProMP

        promp = ProMP(n_basis=self.n_basis, cov_reg=self.cov_reg)
        self._skills.append(promp.fit(list(curves)))

    def _reproduce_curves(self, index, starts, t):
        promp = self._skills[index]
        return np.array(
            [promp.condition([0.0], start[None], 0.0).mean(n_steps=len(t)) for start in starts]
        )

    @property
    def n_parameters(self) -> int:
        """Means and covariances of the weights kept, one ProMP per task (and its chart)."""
        kept = sum(p.weight_mean_.size + p.weight_cov_.size for p in self._skills)
        return kept + self._chart_size()


class BiDMPLibrary(ClfdMethod):
    """``bidmp-library``: the paper's skill library as bidmp has it — one :class:`~bidmp.BiDMP`
    whose DMP (``n_kernels`` kernels, the paper's protocol) is fitted on the first task's mean
    demonstration and which learns every later task's mean demonstration as a new skill, one
    BLS block on the DMP's forcing term (its time scaled to the task's duration). A task is
    reproduced by its own skill to its training goal. Earlier skills are never touched (REM =
    1); one block per task."""

    name = "bidmp-library"

    def __init__(self, n_kernels: int = CLFD_KERNELS, seed: int = 0):
        super().__init__()
        self.n_kernels = check_int(n_kernels, "n_kernels", minimum=2, limit="max_kernels")
        self.seed = check_int(seed, "seed", minimum=0, maximum=2**32 - 1)
        self._model = None

    def _learn_curves(self, curves, t) -> None:
        from ...incremental import BiDMP

        if self._model is None:  # the first task is skill 0: the plain DMP
            self._model = BiDMP(_task_dmp(curves, t, self.n_kernels)[0], seed=self.seed)
            return
        self._model.learn(curves.mean(axis=0), duration=float(t[-1] - t[0]))

    def _reproduce_curves(self, index, starts, t):
        model = self._model
        model.n_skills  # noqa: B018 - a BiDMP holds its skills' arrays once it has started
        return _rollouts(model, model.skill_goals_[index], starts, t, increment=index)

    @property
    def n_parameters(self) -> int:
        """The DMP's weights, every skill's goal, start and time scale, and every block's
        learned arrays (mapping, enhancement and output weights)."""
        model = self._model
        model.n_skills  # noqa: B018 - a BiDMP holds its skills' arrays once it has started
        size = model.dmp_.weights_.size + model.skill_goals_.size + model.skill_starts_.size
        size += model.skill_time_scales_.size
        for block in model.blocks_:
            size += block.mapping_weights_.size + block.output_weights_.size
            size += block.mapping_min_.size + block.mapping_range_.size
            size += sum(w.size for w in block.enhancement_weights_)
        return size + self._chart_size()


def _promp_start_map(promp) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(μ (N·D,), gain K (N·D, D), the mean start H₀ᵀμ (D,)) of a fitted ProMP: its mean
    conditioned exactly on a start s is ``μ + K (s − H₀ᵀμ)`` with ``K = Σ H₀ (H₀ᵀ Σ H₀)⁻¹`` —
    the ProMP's conditioning on the start as one affine map."""
    from ...primitives.promp import promp_basis

    n_basis, dims = promp.n_basis, promp.n_dims_
    first = promp_basis([0.0], n_basis, promp.overlap)[0]
    H0 = np.kron(np.eye(dims), first[:, None])  # the weights are stacked dimension by dimension
    mean, cov = promp.weight_mean_, promp.weight_cov_
    cov_h = cov @ H0
    gain = np.linalg.solve(H0.T @ cov_h, cov_h.T).T
    return mean, gain, H0.T @ mean


class _StartMaps(ClfdMethod):
    """A method that keeps each task as one flat vector, its *start map*, and reproduces a task
    from it: ``primitive="promp"`` (default), the ProMP of :class:`ProMPLibrary` as one affine map
    from a start to the weights, ``w(s) = μ + K (s − s̄)`` (its exact conditioning on the start),
    the vector μ, K, s̄; ``"dmp"``, the forcing weights and the goal of :class:`DMPLibrary`'s DMP.
    On a pose task the chart's reference quaternion is one more part of it (normalised when
    used). Subclasses keep the vectors (``learn``) and give task ``index``'s (``_output``)."""

    def __init__(
        self, primitive: str = "promp", n_kernels: int = CLFD_KERNELS, n_basis: int = CLFD_BASIS
    ):
        super().__init__()
        from ..._checks import check_choice

        self.primitive = check_choice(primitive, "primitive", ("promp", "dmp"))
        self.n_kernels = check_int(n_kernels, "n_kernels", minimum=2, limit="max_kernels")
        self.n_basis = check_int(n_basis, "n_basis", minimum=2, limit="max_kernels")
        self._template = None  # a primitive of the same structure, its learned state replaced
        self._pose = False

    def task_target(self, task: ClfdTask) -> np.ndarray:
        """The start map of ``task`` as learned from its demonstrations: the flat vector of its
        primitive's parameters (LASA's ProMP: 602 numbers — μ 200, K 400, s̄ 2), then its chart's
        reference quaternion on a pose task."""
        if not isinstance(task, ClfdTask):
            raise TypeError(
                f"task must be a bidmp.experiments.ClfdTask (clfd_tasks gives them), got "
                f"{type(task).__name__}"
            )
        chart = TangentChart.of_task(task)
        curves, t = chart.curves(task.poses), task.times[0]
        if self.primitive == "dmp":
            dmp, goal = _task_dmp(curves, t, self.n_kernels)
            if self._template is None:
                self._template = dmp
            parts = [dmp.weights_.ravel(), goal]
        else:
            from ...primitives import ProMP

            promp = ProMP(n_basis=self.n_basis, cov_reg=CLFD_COV_REG).fit(list(curves))
            if self._template is None:
                self._template = promp
            mean, gain, start = _promp_start_map(promp)
            parts = [mean, gain.ravel(), start]
        if chart.reference is not None:
            parts.append(chart.reference)
        return np.concatenate(parts)

    def task_map(self, index: int) -> np.ndarray:
        """The start map the method gives for task ``index`` now (what it reproduces the task
        from; :meth:`task_target` is what it was taught)."""
        learned = len(self._widths)
        if not learned:
            raise ValueError(f"index: {self.name} has learned no task yet (call learn(task))")
        return self._output(check_int(index, "index", minimum=0, maximum=learned - 1)).copy()

    def _output(self, index: int) -> np.ndarray:
        raise NotImplementedError

    def _chart(self, index: int) -> TangentChart:
        if not self._pose:
            return TangentChart(None)
        reference = self._output(index)[-4:]
        return TangentChart(reference / np.linalg.norm(reference))

    def _reproduce_curves(self, index, starts, t):
        output, dims = self._output(index), starts.shape[1]
        if self.primitive == "dmp":
            dmp = copy.copy(self._template)
            dmp.weights_ = output[: self.n_kernels * dims].reshape(self.n_kernels, dims)
            goal = output[self.n_kernels * dims : (self.n_kernels + 1) * dims]
            return _rollouts(dmp, goal, starts, t)
        from ...primitives.promp import promp_basis

        size = self.n_basis * dims
        mean = output[:size]
        gain = output[size : size + size * dims].reshape(size, dims)
        mean_start = output[size + size * dims : size + size * dims + dims]
        weights = mean[None] + (starts - mean_start) @ gain.T  # (M, N·D)
        basis = promp_basis(np.linspace(0.0, 1.0, len(t)), self.n_basis, self._template.overlap)
        return np.einsum("tn,mdn->mtd", basis, weights.reshape(len(starts), dims, self.n_basis))


class MapLibrary(_StartMaps):
    """``map-library``: the plain library of the start maps :class:`ContinualBLS` learns — each
    task's vector (:meth:`task_target`) kept as it is, one per task, and the task reproduced from
    it as :class:`ContinualBLS` reproduces it. Nothing learned later touches an earlier task's
    map (REM = 1); it grows by one map per task (LASA: 602 numbers; 26 tasks, 15 652). The
    yardstick :class:`ContinualBLS` is measured against (``tools/clfd_capacity.py``)."""

    name = "map-library"

    def __init__(
        self, primitive: str = "promp", n_kernels: int = CLFD_KERNELS, n_basis: int = CLFD_BASIS
    ):
        super().__init__(primitive, n_kernels, n_basis)
        self._maps: list[np.ndarray] = []

    def learn(self, task: ClfdTask) -> None:
        target = self.task_target(task)
        self._record(task)
        self._pose = task.orientations is not None
        self._maps.append(target)

    def _output(self, index: int) -> np.ndarray:
        return self._maps[index]

    @property
    def n_parameters(self) -> int:
        """Every number kept: the maps."""
        return sum(m.size for m in self._maps)


class ContinualBLS(_StartMaps):
    """``bidmp-continual``: a ridge memory of the tasks' start maps of a fixed size — one Broad
    Learning System over all tasks, the task's code in, the task's start map out.

    The maps are :class:`MapLibrary`'s (``primitive``: ``"promp"``, default, or ``"dmp"``). The
    task code is one-hot over a capacity of ``capacity`` tasks; ``n_nodes`` enhancement nodes
    ``tanh(R code + b)`` (R, b drawn once from ``seed``) feed linear output weights W. W is the
    ridge solution (``ridge`` relative to the mean diagonal) of the normal equations accumulated
    task by task — ``A += HᵀH``, ``B += HᵀY`` — so after task i it is exactly the ridge fit on
    tasks 0..i (tested), and A and B are kept to learn the next task. With at least as many nodes
    as tasks the fit gives every task's map back (to the ridge's share): an exact memory, larger
    than the maps themselves (W alone has ``n_nodes`` rows of a map's size). With fewer, it is the
    least-squares compromise between the tasks' maps, and it forgets. Its size is fixed by
    ``n_nodes`` and ``capacity`` (MS = 1); :attr:`numbers_kept` counts every number it keeps."""

    name = "bidmp-continual"

    def __init__(  # noqa: PLR0913 - an estimator's constructor: each hyperparameter is one
        self,
        primitive: str = "promp",
        n_kernels: int = CLFD_KERNELS,
        n_basis: int = CLFD_BASIS,
        n_nodes: int = 64,
        capacity: int = 26,
        ridge: float = 1e-10,
        seed: int = 0,
    ):
        super().__init__(primitive, n_kernels, n_basis)
        self.n_nodes = check_int(n_nodes, "n_nodes", minimum=1, maximum=100_000)
        self.capacity = check_int(capacity, "capacity", minimum=1, maximum=100_000)
        self.ridge = check_real(ridge, "ridge", nonnegative=True, maximum=1.0)
        self.seed = seed
        rng = check_seed(seed)
        self._projection = rng.normal(size=(n_nodes, capacity))
        self._bias = rng.normal(size=n_nodes)
        self._gram = None  # A (n_nodes, n_nodes) and B (n_nodes, outputs): what the update needs
        self._cross = None
        self._weights = None
        self._seen = 0

    def task_nodes(self, index: int) -> np.ndarray:
        """(n_nodes,): the enhancement nodes of task ``index``'s one-hot code."""
        index = check_int(index, "index", minimum=0, maximum=self.capacity - 1)
        return np.tanh(self._projection[:, index] + self._bias)

    def learn(self, task: ClfdTask) -> None:
        if self._seen >= self.capacity:
            raise ValueError(f"bidmp-continual holds {self.capacity} tasks (its capacity)")
        target = self.task_target(task)
        self._record(task)
        if self._gram is None:
            self._pose = task.orientations is not None  # a pose task: the chart's reference too
            self._gram = np.zeros((self.n_nodes, self.n_nodes))
            self._cross = np.zeros((self.n_nodes, target.size))
        nodes = self.task_nodes(self._seen)[None]
        self._gram += nodes.T @ nodes
        self._cross += nodes.T @ target[None]
        diagonal = self.ridge * np.trace(self._gram) / self.n_nodes
        self._weights = np.linalg.solve(self._gram + diagonal * np.eye(self.n_nodes), self._cross)
        self._seen += 1

    def _output(self, index: int) -> np.ndarray:
        return self.task_nodes(index) @ self._weights

    @property
    def n_parameters(self) -> int:
        """What it reproduces from, the protocol's model size: projection, bias and output
        weights (:attr:`numbers_kept` adds the normal equations it learns with)."""
        outputs = 0 if self._weights is None else self._weights.shape[1]
        return self._projection.size + self._bias.size + self.n_nodes * outputs

    @property
    def numbers_kept(self) -> dict[str, int]:
        """Every number it keeps, by part: ``projection`` R (n_nodes × capacity), ``bias`` b
        (n_nodes), ``weights`` W (n_nodes × a map's size) and ``normal_equations`` A (n_nodes ×
        n_nodes) and B (n_nodes × a map's size), which it needs to learn another task."""
        outputs = 0 if self._weights is None else self._weights.shape[1]
        return {
            "projection": self._projection.size,
            "bias": self._bias.size,
            "weights": self.n_nodes * outputs,
            "normal_equations": 0 if self._gram is None else self._gram.size + self._cross.size,
        }


METHODS = {
    "dmp-library": DMPLibrary,
    "finetune": FineTune,
    "bidmp-library": BiDMPLibrary,
    "promp-library": ProMPLibrary,
    "bidmp-continual": ContinualBLS,
}
