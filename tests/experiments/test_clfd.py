"""The CLFD protocol's metrics against closed forms and plain implementations of their
definitions, and the protocol's runner on the first tasks (the 26-task run is make clfd's)."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bidmp.experiments.clfd import (
    DMPLibrary,
    accuracy_matrix,
    clfd_tasks,
    continual_metrics,
    orientation_error,
    run_clfd,
    swept_error_area,
)
from bidmp.extension.similarity import dtw_distance


def test_the_swept_area_between_parallel_lines_is_length_times_gap():
    x = np.linspace(0.0, 7.0, 50)
    a = np.column_stack([x, np.zeros_like(x)])
    assert swept_error_area(a, a + [0.0, 3.0]) == pytest.approx(21.0, rel=1e-12)
    assert swept_error_area(a, a) == 0.0


def test_the_swept_area_of_convex_quadrilaterals_is_the_shoelace_sum():
    """Random curves whose corresponding points are offset upwards (every quadrilateral simple
    and convex): the plain shoelace formula of each quadrilateral, summed in a loop."""
    rng = np.random.default_rng(4)
    x = np.cumsum(rng.uniform(0.5, 1.0, 40))
    a = np.column_stack([x, rng.normal(0, 0.1, 40)])
    b = a + np.column_stack([np.zeros(40), rng.uniform(1.0, 2.0, 40)])
    total = 0.0
    for i in range(39):
        quad = [a[i], a[i + 1], b[i + 1], b[i]]
        total += 0.5 * abs(
            sum(p[0] * q[1] - q[0] * p[1] for p, q in zip(quad, quad[1:] + quad[:1]))
        )
    assert swept_error_area(a, b) == pytest.approx(total, rel=1e-12)


def test_the_orientation_error_is_the_angle_between_the_orientations():
    """Rotations by θ(t) about random axes: the mean of θ, whichever sign each quaternion has."""
    rng = np.random.default_rng(2)
    true = Rotation.random(100, random_state=3)
    theta = rng.uniform(0.0, 3.0, 100)
    axes = rng.normal(size=(100, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    predicted = Rotation.from_rotvec(axes * theta[:, None]) * true
    wxyz = lambda r: np.roll(r.as_quat(), 1, axis=1)  # noqa: E731 - SciPy's x,y,z,w to w,x,y,z
    flipped = wxyz(predicted) * rng.choice([-1.0, 1.0], (100, 1))
    assert orientation_error(wxyz(true), flipped) == pytest.approx(theta.mean(), rel=1e-9)


def plain_dtw(a: np.ndarray, b: np.ndarray) -> float:
    """The full table, as the protocol defines DTW."""
    n, m = len(a), len(b)
    table = np.full((n + 1, m + 1), np.inf)
    table[0, 0] = 0.0
    for i in range(1, n + 1):
        for j in range(1, m + 1):
            cost = np.linalg.norm(a[i - 1] - b[j - 1])
            table[i, j] = cost + min(table[i - 1, j], table[i, j - 1], table[i - 1, j - 1])
    return float(table[n, m])


def test_dtw_is_the_protocols_unnormalised_warping_cost():
    rng = np.random.default_rng(8)
    for _ in range(5):
        a, b = rng.normal(size=(30, 2)), rng.normal(size=(23, 2))
        assert dtw_distance(a, b) == pytest.approx(plain_dtw(a, b), rel=1e-12)


def test_the_continual_metrics_of_a_small_matrix_by_hand():
    """Three tasks: A = [[1], [0.5, 1], [1, 0.5, 0.5]]. ACC = 4.5 / 6; BWT = mean(0.5-1, 1-1,
    0.5-1) = -1/3; REM = 2/3; sizes 1, 2, 3: MS = (1 + 1/2 + 1/3) / 3; times 2, 1, 4: TE =
    min(1, (1 + 2 + 0.5) / 3) = 1; FS against a largest model of 6: 1 - 3/6."""
    nan = np.nan
    matrix = np.array([[1.0, nan, nan], [0.5, 1.0, nan], [1.0, 0.5, 0.5]])
    figures = continual_metrics(matrix, [1, 2, 3], [2.0, 1.0, 4.0], largest_size=6)
    assert figures["ACC"] == pytest.approx(0.75)
    assert figures["BWT"] == pytest.approx(-1 / 3)
    assert figures["REM"] == pytest.approx(2 / 3)
    assert figures["MS"] == pytest.approx((1 + 1 / 2 + 1 / 3) / 3)
    assert figures["TE"] == 1.0 and figures["FS"] == pytest.approx(0.5)
    parts = [0.75, 2 / 3, (1 + 1 / 2 + 1 / 3) / 3, 1.0, 0.5]
    assert figures["CL_score"] == pytest.approx(np.mean(parts))
    assert figures["CL_stability"] == pytest.approx(1 - np.std(parts, ddof=1))


def test_a_library_growing_by_one_block_per_task_scores_the_harmonic_mean():
    n = 26
    figures = continual_metrics(np.tril(np.ones((n, n))), np.arange(1, n + 1), np.ones(n))
    assert figures["MS"] == pytest.approx(sum(1 / k for k in range(1, n + 1)) / n)  # 0.148
    assert figures["ACC"] == 1.0 and figures["BWT"] == 0.0 and figures["REM"] == 1.0


def test_the_accuracy_matrix_counts_errors_within_the_threshold():
    errors = [[np.array([1.0, 3.0])], [np.array([1.0, 1.0]), np.array([2.0, 5.0])]]
    matrix = accuracy_matrix(errors, 2.0)
    assert matrix[0, 0] == 0.5 and matrix[1, 0] == 1.0 and matrix[1, 1] == 0.5
    assert np.isnan(matrix[0, 1])


def test_the_vendored_lasa_tasks_in_the_protocols_order():
    tasks = clfd_tasks("lasa")
    assert len(tasks) == 26 and tasks[0].positions.shape == (7, 1000, 2)
    assert tasks[0].times.shape == (7, 1000)
    assert len({task.name for task in tasks}) == 26


def test_learning_a_task_leaves_every_earlier_reproduction_unchanged():
    """REM = 1 as the library claims it: task 0's reproductions bit for bit after tasks 1-3."""
    tasks = clfd_tasks("lasa")[:4]
    library = DMPLibrary()
    library.learn(tasks[0])
    t = tasks[0].times[0]
    before = library.reproduce(0, tasks[0].positions[:, 0], t)
    for task in tasks[1:]:
        library.learn(task)
    assert np.array_equal(library.reproduce(0, tasks[0].positions[:, 0], t), before)


def test_the_protocol_on_three_tasks():
    result = run_clfd("lasa", ["dmp-library"], n_tasks=3)
    row = result.rows["dmp-library"]
    assert row.matrices["dtw"].shape == (3, 3) and np.isnan(row.matrices["dtw"][0, 2])
    assert row.metrics["dtw"]["REM"] == 1.0
    assert row.metrics["dtw"]["MS"] == pytest.approx((1 + 1 / 2 + 1 / 3) / 3)
    assert len(row.mean_dtw_seen) == 3 and row.sizes[2] == 3 * row.sizes[0]
    text = result.markdown()
    assert "| dmp-library |" in text


def test_a_bad_dataset_or_method_is_refused_by_name():
    with pytest.raises(ValueError, match="dataset"):
        clfd_tasks("lasa2")
    with pytest.raises(ValueError, match="methods"):
        run_clfd("lasa", ["nope"], n_tasks=1)


def test_the_continual_bls_is_the_ridge_fit_on_every_task_seen():
    """Its output weights, updated from the accumulated normal equations, equal a ridge fit
    computed here from all the tasks' nodes and targets at once (to 1e-9)."""
    from bidmp.experiments.clfd import ContinualBLS
    from bidmp.primitives import DMP

    tasks = clfd_tasks("lasa")[:4]
    model = ContinualBLS()
    rows, targets = [], []
    for index, task in enumerate(tasks):
        model.learn(task)
        dmp = DMP(protocol="paper", n_kernels=50).fit(task.positions.mean(axis=0), task.times[0])
        targets.append(np.concatenate([dmp.weights_.ravel(), task.positions[:, -1].mean(axis=0)]))
        code = np.zeros(model.capacity)
        code[index] = 1.0
        rows.append(np.tanh(model._projection @ code + model._bias))
    H, Y = np.array(rows), np.array(targets)
    gram = H.T @ H
    expected = np.linalg.solve(
        gram + 1e-10 * np.trace(gram) / H.shape[1] * np.eye(H.shape[1]), H.T @ Y
    )
    # (the weights' component outside the tasks' nodes is the ridge's alone: compare what they
    # give, every task's DMP)
    given, wanted = H @ model._weights, H @ expected
    assert np.max(np.abs(given - wanted)) <= 1e-9 * np.abs(wanted).max()


def test_the_continual_bls_keeps_its_size_and_its_earlier_tasks():
    """A fixed size (MS = 1), and task 0's reproduction after three more tasks within 1e-6 of
    its extent of what it was (its REM = 1 claim; not bit for bit: the ridge's share moves)."""
    from bidmp.experiments.clfd import ContinualBLS

    tasks = clfd_tasks("lasa")[:4]
    model = ContinualBLS()
    model.learn(tasks[0])
    size = model.n_parameters
    t = tasks[0].times[0]
    before = model.reproduce(0, tasks[0].positions[:, 0], t)
    for task in tasks[1:]:
        model.learn(task)
        assert model.n_parameters == size
    after = model.reproduce(0, tasks[0].positions[:, 0], t)
    extent = np.ptp(tasks[0].positions.reshape(-1, 2), axis=0).max()
    assert np.max(np.abs(after - before)) <= 1e-6 * extent


def test_finetune_forgets_and_the_promp_library_does_not():
    """The protocol's bounds: one DMP refitted on each task reproduces task 0 differently after
    task 1 (its accuracy there falls), at a constant size; the ProMP library's task 0 is bit for
    bit what it was."""
    from bidmp.experiments.clfd import FineTune, ProMPLibrary

    tasks = clfd_tasks("lasa")[:2]
    t, starts = tasks[0].times[0], tasks[0].positions[:, 0]
    for method, forgets in ((FineTune(), True), (ProMPLibrary(), False)):
        method.learn(tasks[0])
        before, size = method.reproduce(0, starts, t), method.n_parameters
        method.learn(tasks[1])
        after = method.reproduce(0, starts, t)
        assert (not np.array_equal(after, before)) is forgets, method.name
        assert (method.n_parameters == size) is forgets, method.name
    result = run_clfd("lasa", ["finetune"], n_tasks=2)
    assert result.rows["finetune"].metrics["dtw"]["BWT"] < 0.0


def test_the_figures_are_written(tmp_path):
    from matplotlib.image import imread

    written = [p for p in run_and_write(tmp_path) if p.suffix == ".png"]
    assert sorted(p.name for p in written) == ["clfd_accuracy.png", "clfd_dtw.png"]
    for path in written:
        pixels = imread(path)
        assert pixels.shape[0] > 100 and pixels.shape[1] > 100 and np.ptp(pixels) > 0.5


def run_and_write(folder):
    from bidmp.experiments.clfd import write_clfd

    return write_clfd(run_clfd("lasa", ["dmp-library", "promp-library"], n_tasks=2), folder)
