"""The methods that learn from several demonstrations in the registry: in evaluate (one
demonstration and its noisy copies), in a LASA cell (the shape's seven), and the Task's checks."""

from __future__ import annotations

import numpy as np
import pytest

from bidmp.experiments.lasa_cells import run_cell
from bidmp.tasks import evaluate, scenarios
from bidmp.tasks.methods import Task, get, names


def test_they_are_registered_and_run_in_the_lasa_benchmark_by_default():
    assert {"promp", "dmp-multi"} <= set(names(lasa=True))


def test_they_reach_every_nut_in_evaluate():
    report = evaluate(scenarios.load("nut-unscrewing"), ["promp", "dmp-multi"], geometry=False)
    for name in ("promp", "dmp-multi"):
        result = report.methods[name]
        assert result.successes == 14, (name, result.errors)


def test_a_lasa_cell_learns_from_the_shapes_seven():
    """The ProMP passes the cell's start and goal exactly (conditioned, zero variance); its
    reproduction is the seven's mean, not the cell's one: farther from it than a DMP of it."""
    cell = run_cell("Sshape", 3, methods=("dmp-paper", "promp", "dmp-multi"))
    rows = {(row["method"], row["case"]): row for row in cell["rows"]}
    for case in ("reproduction", "near", "far"):
        assert rows[("promp", case)]["endpoint_error"] < 1e-9
        assert rows[("dmp-multi", case)]["endpoint_error"] < 1e-3
    assert rows[("promp", "reproduction")]["rmse"] > rows[("dmp-paper", "reproduction")]["rmse"]


def test_a_task_checks_its_further_demonstrations():
    y = np.column_stack([np.linspace(0, 1, 20), np.linspace(0, 2, 20)])
    with pytest.raises(ValueError, match="demonstrations\\[0\\] has D = 3"):
        Task(y, y[-1:], demonstrations=(np.ones((20, 3)) * np.arange(20)[:, None],))
    with pytest.raises(TypeError, match="demonstrations"):
        Task(y, y[-1:], demonstrations=y)
    task = Task(y, y[-1:])
    assert len(task.all_demonstrations()) == 6  # the demonstration and 5 noisy copies
    model, _ = get("promp").fit(task)
    np.testing.assert_allclose(get("promp").rollout(model, y[-1] + 0.5)[-1], y[-1] + 0.5)
