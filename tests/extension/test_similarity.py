"""Discrete Fréchet distance and Fre_sim, against similaritymeasures and properties."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from bidmp import frechet_distance, frechet_similarity
from bidmp.extension import frechet_distance_reference, polyline_length, similarity
from bidmp.extension.similarity import _frechet_compiled


def test_spec_reference_case():
    p = [[1, 1], [2, 1], [2, 2]]
    q = [[2, 2], [0, 1], [2, 4]]
    assert frechet_distance(p, q) == 2.0
    assert frechet_distance_reference(np.array(p, float), np.array(q, float)) == 2.0


def test_equals_similaritymeasures_on_random_unequal_curves():
    similaritymeasures = pytest.importorskip("similaritymeasures")  # only this test needs it
    rng = np.random.default_rng(42)
    for trial in range(60):
        n_dims = (1, 2, 3)[trial % 3]
        a = rng.normal(size=(rng.integers(1, 60), n_dims)).cumsum(axis=0)
        b = rng.normal(size=(rng.integers(1, 60), n_dims)).cumsum(axis=0)
        expected = similaritymeasures.frechet_dist(a, b)
        assert frechet_distance(a, b) == pytest.approx(expected, rel=1e-12, abs=1e-12)
        assert frechet_distance_reference(a, b) == pytest.approx(expected, rel=1e-12, abs=1e-12)
        assert _frechet_compiled(a, b) == pytest.approx(expected, rel=1e-12, abs=1e-12)


def test_the_compiled_kernel_and_the_numpy_version_give_the_same_bits():
    """Which one answers must not change a result (G-PRM keeps the best-scoring path): random
    curves of 1 to 120 points in 1 to 3 dimensions, of any scale, and curves with ties."""
    rng = np.random.default_rng(11)
    for trial in range(200):
        n_dims = int(rng.integers(1, 4))
        scale = 10.0 ** rng.uniform(-3, 3)
        a = scale * rng.normal(size=(int(rng.integers(1, 121)), n_dims)).cumsum(axis=0)
        b = scale * rng.normal(size=(int(rng.integers(1, 121)), n_dims)).cumsum(axis=0)
        if trial % 10 == 0:  # exact ties: points on a grid
            a, b = np.round(a / scale), np.round(b / scale)
        assert _frechet_compiled(a, b) == frechet_distance_reference(a, b), trial


def test_numba_is_loaded_only_for_work_that_repays_it(monkeypatch):
    """A process's first NUMPY_BUDGET_CELLS cells are the NumPy version's (no numba: ~0.3 s of
    a command's life); past them the compiled kernel answers, with the same numbers."""
    monkeypatch.setattr(similarity, "_kernel_state", {})
    monkeypatch.setattr(similarity, "_numpy_cells", [0])
    rng = np.random.default_rng(3)
    a, b = rng.normal(size=(100, 3)).cumsum(axis=0), rng.normal(size=(100, 3)).cumsum(axis=0)
    first = frechet_distance(a, b)
    assert "Fréchet" not in similarity._kernel_state and similarity._numpy_cells[0] == 10_000
    budget = int(similarity.NUMPY_BUDGET_CELLS)
    similarity._numpy_cells[0] = budget - 10_000
    assert frechet_distance(a, b) == first  # the budget's last cells: still NumPy
    assert "Fréchet" not in similarity._kernel_state and similarity._numpy_cells[0] == budget
    assert frechet_distance(a, b) == first  # over the budget: compiled
    assert similarity._kernel_state.get("Fréchet") is not None
    assert similarity._numpy_cells[0] == budget


def test_the_numpy_version_refuses_a_table_over_its_size_in_cells():
    """A Python loop over anti-diagonals is a reference, not a tool: over REFERENCE_MAX_CELLS
    (rows times rows, whatever the dimension) it says to use frechet_distance."""
    rows = int(similarity.REFERENCE_MAX_CELLS) // 1_000 + 1
    with pytest.raises(ValueError, match="use frechet_distance"):
        frechet_distance_reference(np.zeros((rows, 2)), np.zeros((1_000, 2)))
    with pytest.raises(ValueError, match="use frechet_distance"):
        frechet_distance_reference(np.zeros((1_000, 2)), np.zeros((rows, 2)))


curves = st.integers(1, 25).flatmap(
    lambda n: arrays(np.float64, (n, 2), elements=st.floats(-100, 100, allow_nan=False, width=32))
)


@settings(max_examples=60, deadline=None)
@given(curves, curves, curves)
def test_metric_properties(a, b, c):
    d_ab = frechet_distance(a, b)
    assert d_ab == pytest.approx(frechet_distance(b, a), rel=1e-12, abs=1e-12)
    assert d_ab >= np.linalg.norm(a[0] - b[0]) - 1e-9
    assert d_ab >= np.linalg.norm(a[-1] - b[-1]) - 1e-9
    assert frechet_distance(a, a) == 0.0
    assert d_ab <= frechet_distance(a, c) + frechet_distance(c, b) + 1e-9


def test_large_curves_are_fine():
    rng = np.random.default_rng(0)
    a = rng.normal(size=(3000, 3)).cumsum(axis=0)
    b = a[::-1].copy()
    assert np.isfinite(frechet_distance(a, b))  # no recursion limit, no n x m matrix


def test_similarity_definition_and_options():
    a = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    b = a + [0.0, 0.5]
    assert frechet_similarity(a, a) == 1.0
    # Fré = 0.5, len = 2 for both: 1 - 0.5 / (2 / sqrt 2) and 1 - 0.5 / (2 / 2)
    assert frechet_similarity(a, b) == pytest.approx(1 - 0.5 / (2 / np.sqrt(2)))
    assert frechet_similarity(a, b, denom="2") == pytest.approx(0.5)
    assert frechet_similarity(a, a + [0.0, 100.0]) == 0.0  # clipped at 0
    assert polyline_length(a) == 2.0


@pytest.mark.parametrize(
    "call, error, match",
    [
        (
            lambda: frechet_distance(np.zeros((3, 2)), np.zeros((3, 3))),
            ValueError,
            "same dimension",
        ),
        (lambda: frechet_distance([[0.0, np.nan]], [[0.0, 0.0]]), ValueError, "NaN"),
        (
            lambda: frechet_distance(np.zeros((0, 2)), np.zeros((3, 2))),
            ValueError,
            "at least 1 point",
        ),
        (
            lambda: frechet_similarity([[0.0, 0.0]], [[1.0, 1.0], [2.0, 2.0]]),
            ValueError,
            "non-zero length",
        ),
        (lambda: frechet_similarity(np.eye(2), np.eye(2), denom="3"), ValueError, "denom"),
    ],
)
def test_bad_input(call, error, match):
    with pytest.raises(error, match=match):
        call()
