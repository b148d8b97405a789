"""The methods registry: a method registered here, in a test, runs in evaluation, the
LASA benchmark and the simulator without a line of theirs changed; the built-ins are registered
under the names every report uses; the registry refuses what it cannot hold.

The straight line is checked against what a straight line must do (end exactly at the goal, start
at the demonstration's start, stay on the segment): an independent property, not the code under
test; the name checks are structural.
"""

import numpy as np
import pytest

from bidmp.experiments import benchmark, lasa_cells
from bidmp.tasks import evaluate, scenarios
from bidmp.tasks import methods as registry
from bidmp.tasks.methods import Method, Task


class StraightLine(Method):
    """From the demonstration's start straight to the goal, in as many samples as demonstrated."""

    name = "test-line"
    lasa = False

    def fit(self, task):
        return (task.demonstration[0], task.demonstration.shape[0]), 0.0

    def rollout(self, model, goal):
        start, n_samples = model
        return start + np.linspace(0.0, 1.0, n_samples)[:, None] * (goal - start)


class LineThenDown(StraightLine):
    """Straight to 40 mm over the goal, then straight down onto it (as a socket must come)."""

    name = "test-line-down"

    def rollout(self, model, goal):
        start, n_samples = model
        over = goal + np.array([0.0, 0.0, 40.0])
        half = n_samples // 2
        first = start + np.linspace(0.0, 1.0, half)[:, None] * (over - start)
        down = over + np.linspace(0.0, 1.0, n_samples - half + 1)[1:, None] * (goal - over)
        return np.vstack([first, down])


@pytest.fixture
def line():
    method = registry.register(StraightLine())
    yield method
    registry.unregister(method.name)


def on_segment(points, start, goal):
    """Distance of each point from the segment start-goal."""
    direction = goal - start
    s = np.clip((points - start) @ direction / (direction @ direction), 0.0, 1.0)
    return np.linalg.norm(points - (start + s[:, None] * direction), axis=1)


def test_a_registered_method_runs_in_evaluate(line):
    scenario = scenarios.load("pick-and-place")
    report = evaluate(scenario, ["dmp", "test-line"], geometry=False)
    result = report.methods["test-line"]
    for label, goal in scenario.targets.items():
        rollout = result.rollouts[label]
        np.testing.assert_allclose(rollout[-1], goal, atol=1e-9)
        np.testing.assert_allclose(rollout[0], scenario.demonstration[0], atol=1e-9)
        assert np.max(on_segment(rollout, scenario.demonstration[0], goal)) <= 1e-9
        assert result.errors[label] <= 1e-9
    assert report.methods["dmp"].errors != result.errors  # the two methods really ran apart


def test_a_registered_method_runs_in_the_lasa_benchmark(line, tmp_path):
    result = benchmark.lasa(
        tmp_path,
        shapes=["Sshape"],
        methods=["test-line", "dmp-paper"],
        demos="first3",
        every=10,
        synchronous=True,
    )
    rows = [row for row in result.rows if row["method"] == "test-line"]
    assert len(rows) == 3 * len(lasa_cells.CASES)
    assert all(row["endpoint_error"] <= 1e-9 for row in rows)
    # The line is no LASA shape: it reproduces the demonstration far worse than the DMP does.
    reproduction = {
        row["method"]: row["rmse"]
        for row in result.rows
        if row["case"] == "reproduction" and row["demo"] == 0
    }
    assert reproduction["test-line"] > 10 * reproduction["dmp-paper"]
    assert "test-line" in (tmp_path / "lasa.md").read_text()


def test_a_registered_method_runs_in_the_simulator(line):
    pytest.importorskip("pybullet")
    from bidmp import sim

    # The demonstrated nut: the straight line from the demonstration's start is clear of every part
    # there (pick-and-place's line to op1 grazes op2 and op3, and how far the pushed arm then ends
    # from the target depends on the contact dynamics, not on the registry under test).
    scenario = scenarios.load("nut-unscrewing")
    label = "3"
    down = registry.register(LineThenDown())
    try:
        report = sim.simulate(scenario, ["test-line", down.name], targets=[label], workers=1)
    finally:
        registry.unregister(down.name)
    # The plain line comes down diagonally onto the nut: the contract refuses it, so it never runs.
    refused = report.methods["test-line"].targets[label]
    assert not refused.ran and "off the target's axis" in refused.error
    assert not report.methods[down.name].targets[label].contacts
    measured = report.methods[down.name].targets[label]
    assert measured.commanded_error <= 1e-6  # the line itself ends at the target...
    assert measured.measured_error <= 1.0  # ...and so does the simulated arm (mm)
    with pytest.raises(ValueError, match="test-line has none"):
        sim.simulate(scenario, ["test-line"], targets=[label], closed_loop=True, workers=1)


def test_the_built_in_methods_keep_their_names():
    assert registry.names()[:9] == [
        "dmp",
        "dmp-paper",
        "dmp-robot",
        "dmp-converged",
        "bidmp",
        "bidmp-latest",
        "gmm",
        "tpgmm",
        "mp-dmp",
    ]
    assert tuple(registry.names(lasa=True)) == lasa_cells.LASA_METHODS
    assert set(scenarios.METHODS) <= set(registry.names())
    assert registry.names(poses=True) == ["dmp", "dmp-paper", "dmp-robot", "bidmp", "bidmp-latest"]
    assert registry.names(closed_loop=True) == [
        "dmp",
        "dmp-paper",
        "dmp-robot",
        "bidmp",
        "bidmp-latest",
    ]


def test_the_registry_refuses_what_it_cannot_hold(line):
    with pytest.raises(ValueError, match="registered already"):
        registry.register(StraightLine())
    assert registry.register(line) is line  # the same object again is a no-op
    with pytest.raises(TypeError, match="Method"):
        registry.register(lambda task: None)
    nameless = StraightLine()
    nameless.name = "has space"
    with pytest.raises(ValueError, match="method.name"):
        registry.register(nameless)
    with pytest.raises(ValueError, match="unknown method 'magic'; known: dmp"):
        registry.get("magic")


def test_shared_models_are_built_once():
    demo = np.linspace([0.0, 0.0], [10.0, 5.0], 50)
    task = Task(demo, demo[-1:], seed=1)
    first, _ = task.fitted_dmp()
    again, _ = task.fitted_dmp()
    other, _ = task.fitted_dmp(protocol="paper")
    assert first is again and other is not first
    assert registry.get("dmp").fit(task)[0] is first
