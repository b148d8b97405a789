"""Broad Learning System: incremental updates against from-scratch pinv / ridge."""

import numpy as np
import pytest

import bidmp
from bidmp import BLS
from bidmp.incremental import block_pinv_update, sparse_autoencoder
from bidmp.incremental.linalg import PINV_RCOND


def random_problem(seed=0, n_rows=300, n_inputs=5):
    rng = np.random.default_rng(seed)
    X = rng.uniform(-1, 1, (n_rows, n_inputs))
    Y = np.column_stack([np.sin(3 * X[:, 0]) + X[:, 1] ** 2, np.cos(X[:, 2] * X[:, 3])])
    return X, Y


def full_rank(rng, n_rows, n_cols):
    return rng.normal(size=(n_rows, n_cols))


def rank_deficient(rng, n_rows, n_cols, rank):
    return rng.normal(size=(n_rows, rank)) @ rng.normal(size=(rank, n_cols))


@pytest.mark.parametrize("base", ["full", "deficient"])
@pytest.mark.parametrize(
    "kind, expected_case", [("random", "full-rank"), ("span", "zero"), ("mixed", "general")]
)
def test_block_update_equals_pinv_from_scratch(base, kind, expected_case):
    rng = np.random.default_rng(7)
    A = full_rank(rng, 120, 25) if base == "full" else rank_deficient(rng, 120, 25, 15)
    A_pinv = np.linalg.pinv(A, rcond=PINV_RCOND)
    if kind == "random":
        E = rng.normal(size=(120, 6))
    elif kind == "span":
        E = A @ rng.normal(size=(25, 6))
    else:
        E = np.hstack([rng.normal(size=(120, 2)), A @ rng.normal(size=(25, 4))])
    D, Bt, case = block_pinv_update(A, A_pinv, E)
    assert case == expected_case
    updated = np.vstack([A_pinv - D @ Bt, Bt])
    reference = np.linalg.pinv(np.hstack([A, E]), rcond=PINV_RCOND)
    np.testing.assert_allclose(updated, reference, rtol=0, atol=1e-8 * np.abs(reference).max())
    Y = rng.normal(size=(120, 3))
    np.testing.assert_allclose(
        updated @ Y, reference @ Y, rtol=0, atol=1e-8 * np.abs(reference @ Y).max()
    )


def test_zero_case_uses_plus_sign_not_the_circulating_minus():
    # E inside span(A): the correct (I + DᵀD)⁻¹ gives pinv; the circulating (I − DᵀD) does not.
    rng = np.random.default_rng(1)
    A = rng.normal(size=(50, 8))
    A_pinv = np.linalg.pinv(A)
    E = A @ rng.normal(size=(8, 3))
    D = A_pinv @ E
    wrong = np.linalg.solve(np.eye(3) - D.T @ D, D.T @ A_pinv)
    _, Bt, case = block_pinv_update(A, A_pinv, E)
    reference = np.linalg.pinv(np.hstack([A, E]))[8:]
    assert case == "zero"
    np.testing.assert_allclose(Bt, reference, atol=1e-10)
    assert not np.allclose(wrong, reference, atol=1e-3)


def test_exact_ridge_update_equals_ridge_from_scratch():
    X, Y = random_problem()
    reg = 1e-3
    model = BLS(n_enhance=40, reg=reg, update="exact_ridge", seed=1).fit(X, Y)
    for n_nodes in (20, 35, 5):
        model.add_enhancement_nodes(n_nodes)
        A = model.hidden(X)
        reference = np.linalg.solve(A.T @ A + reg * np.eye(A.shape[1]), A.T @ Y)
        np.testing.assert_allclose(
            model.output_weights_, reference, rtol=0, atol=1e-8 * np.abs(reference).max()
        )


def test_pinv_update_equals_numpy_pinv_from_scratch_on_random_problems():
    """Against the independent reference, weights included (not the model's own A⁺ @ Y)."""
    X, Y = random_problem(2)
    model = BLS(n_windows=2, n_mapped=4, n_enhance=30, shrink=3.0, reg=0.0, seed=3).fit(X, Y)
    for n_nodes in (10, 10, 25):
        model.add_enhancement_nodes(n_nodes)
        A = model.hidden(X)
        reference = np.linalg.pinv(A, rcond=PINV_RCOND)
        np.testing.assert_allclose(
            model.output_weights_, reference @ Y, rtol=0, atol=1e-8 * np.abs(reference @ Y).max()
        )
        np.testing.assert_allclose(
            model.hidden_pinv_, reference, rtol=0, atol=1e-8 * np.abs(reference).max()
        )


def bidmp_hidden_problem(model):
    """The BLS inputs and targets a Bi-DMP's first block was trained on: its own matrices."""
    phase, basis = model.dmp_.training_grid()
    return model._bls_input(phase, basis), model.blocks_[0].train_targets_


@pytest.fixture(scope="module")
def nut_bidmp():
    from bidmp.tasks import evaluate

    return evaluate(bidmp.tasks.load("nut-unscrewing"), ["bidmp"]).model


def test_pinv_update_on_a_recordings_bidmp_matrices_equals_numpy_pinv():
    """9 on the project's own matrices: a Bi-DMP learned from a bundled recording."""
    y, t = bidmp.demonstrations.recording("operator1_nut3")
    prepared, _ = bidmp.prepare(y, t)
    dmp = bidmp.DMP().fit(prepared.y, prepared.t)
    model = bidmp.BiDMP(dmp).learn(
        bidmp.extend_demonstration(prepared.y, dmp.goal_ + [150.0, 25.0, 0.0], seed=0).complete
    )
    X, Y = bidmp_hidden_problem(model)
    bls = BLS(reg=0.0, seed=model.blocks_[0].seed).fit(X, Y)
    for _ in range(2):
        bls.add_enhancement_nodes(20)
        reference = np.linalg.pinv(bls.train_hidden_, rcond=PINV_RCOND) @ Y
        assert np.linalg.norm(bls.output_weights_ - reference) <= 1e-6 * np.linalg.norm(reference)


def test_pinv_update_on_the_nut_tasks_bidmp_matrices_is_refused_with_the_reason(nut_bidmp):
    """before the fix, add_enhancement_nodes(20) raised the training residual from
    322 to 27 570 (a from-scratch pinv: 307) and BiDMP(reg=0) rolled out 108 mm off. The
    pseudo-inverse of these matrices is ill-posed (shown here with NumPy alone): the update is
    refused, saying why; reg > 0 is exact on the same matrices."""
    X, Y = bidmp_hidden_problem(nut_bidmp)
    bls = BLS(reg=0.0, seed=1).fit(X, Y)
    A = np.hstack(
        [bls.train_hidden_, np.tanh(np.random.default_rng(0).normal(size=(X.shape[0], 20)))]
    )
    weights = np.linalg.pinv(A, rcond=PINV_RCOND) @ Y
    nudged = (
        np.linalg.pinv(
            A * (1.0 + 1e-15 * np.random.default_rng(1).normal(size=A.shape)), rcond=PINV_RCOND
        )
        @ Y
    )
    assert np.linalg.norm(nudged - weights) > 1e-8 * np.linalg.norm(
        weights
    )  # rounding moves NumPy's own answer
    with pytest.raises(ValueError, match="ill-posed.*decay through the rank cut.*use reg > 0"):
        bls.add_enhancement_nodes(20)
    assert bls.n_hidden_ == 200  # refused before anything changed
    with pytest.raises(ValueError, match="ill-posed"):
        bidmp.BiDMP(nut_bidmp.dmp_, reg=0.0).learn(nut_bidmp.rollout(nut_bidmp.skill_goals_[1]))
    ridge = BLS(reg=1e-4, seed=1).fit(X, Y).add_enhancement_nodes(20)
    A = ridge.train_hidden_
    reference = np.linalg.solve(A.T @ A + 1e-4 * np.eye(A.shape[1]), A.T @ Y)
    assert np.linalg.norm(ridge.output_weights_ - reference) <= 1e-6 * np.linalg.norm(reference)


@pytest.mark.parametrize(
    "params", [{}, {"reg": 0.0}, {"reg": 1e-3}, {"n_windows": 3, "n_mapped": 7}]
)
def test_training_residual_never_rises_as_nodes_are_added(params):
    X, Y = random_problem(4)
    model = BLS(n_enhance=30, seed=5, **params).fit(X, Y)
    residuals = [np.sqrt(np.mean((model.predict(X) - Y) ** 2))]
    for _ in range(4):
        model.add_enhancement_nodes(15)
        residuals.append(np.sqrt(np.mean((model.predict(X) - Y) ** 2)))
    assert all(later <= earlier * (1 + 1e-9) for earlier, later in zip(residuals, residuals[1:])), (
        residuals
    )
    assert residuals[-1] < residuals[0]


def test_same_seed_same_model_and_hidden_layer_layout():
    X, Y = random_problem(6)
    first = BLS(seed=9).fit(X, Y).add_enhancement_nodes(12)
    again = BLS(seed=9).fit(X, Y).add_enhancement_nodes(12)
    other = BLS(seed=10).fit(X, Y).add_enhancement_nodes(12)
    np.testing.assert_array_equal(first.predict(X), again.predict(X))
    assert not np.array_equal(first.predict(X), other.predict(X))
    assert first.hidden(X).shape == (300, 10 * 10 + 100 + 12)
    # Enhancement weights are orthonormal; the stored shrink factors reproduce max |pre| = shrink.
    W = first.enhancement_weights_[1]
    np.testing.assert_allclose(W.T @ W, np.eye(12), atol=1e-12)
    Z = first.hidden(X)[:, :100]
    pre = np.hstack([Z, np.full((300, 1), 0.1)]) @ W
    assert np.max(np.abs(first.enhancement_scales_[1] * pre)) == pytest.approx(0.8)


def test_sparse_autoencoder_solves_the_lasso():
    rng = np.random.default_rng(0)
    F = rng.normal(size=(200, 6))
    truth = np.array([[1.5], [0.0], [-2.0], [0.0], [0.0], [0.7]])
    target = F @ truth
    beta = sparse_autoencoder(F, target, l1=1e-3, n_iter=500)
    np.testing.assert_allclose(beta, truth, atol=1e-3)
    heavy = sparse_autoencoder(F, target, l1=200.0, n_iter=500)
    assert np.count_nonzero(np.abs(heavy) > 1e-12) < 3  # a large l1 zeroes the weak weights


def test_save_load_reproduces_predictions_and_continues_learning(tmp_path):
    X, Y = random_problem(8)
    for params in ({}, {"reg": 0.0}):
        model = BLS(n_enhance=30, seed=2, **params).fit(X, Y).add_enhancement_nodes(10)
        path = bidmp.save(model, tmp_path / "bls.npz")
        loaded = bidmp.load(path)
        np.testing.assert_array_equal(loaded.predict(X), model.predict(X))
        # Learning continues after loading (equal up to BLAS rounding, which depends on memory layout).
        np.testing.assert_allclose(
            loaded.add_enhancement_nodes(7).predict(X),
            model.add_enhancement_nodes(7).predict(X),
            atol=1e-9,
        )


@pytest.mark.parametrize(
    "call, error, match",
    [
        (lambda m, X, Y: m.add_enhancement_nodes(0), ValueError, "n must be >= 1"),
        (lambda m, X, Y: m.add_enhancement_nodes(-3), ValueError, "n must be >= 1"),
        (lambda m, X, Y: m.add_enhancement_nodes(2.5), TypeError, "n must be an integer"),
        (lambda m, X, Y: m.predict(X[:, :3]), ValueError, "X must have 5 columns"),
        (lambda m, X, Y: m.predict(np.full_like(X, np.nan)), ValueError, "NaN"),
        (lambda m, X, Y: BLS().fit(X, Y[:10]), ValueError, "Y must have shape"),
        (
            lambda m, X, Y: BLS(update="pinv", reg=1e-3).fit(X, Y),
            ValueError,
            "exact only with reg=0",
        ),
        (lambda m, X, Y: BLS(n_windows=0).fit(X, Y), ValueError, "n_windows must be >= 1"),
        (lambda m, X, Y: BLS().predict(X), bidmp.NotFittedError, "not fitted"),
    ],
)
def test_bad_input(call, error, match):
    X, Y = random_problem(0, n_rows=60)
    model = BLS(n_enhance=10).fit(X, Y)
    with pytest.raises(error, match=match):
        call(model, X, Y)


@pytest.mark.parametrize(
    "bad_fit",
    [
        lambda m, X, Y: m.fit(X, Y[:10]),  # bad data
        lambda m, X, Y: m.fit(X[:, :2], np.full_like(Y, np.nan)),
        lambda m, X, Y: m.set_params(n_windows=0).fit(X, Y),  # bad parameter
        lambda m, X, Y: m.set_params(update="pinv", reg=1e-3).fit(X, Y),
    ],
)
def test_failed_fit_leaves_predictions_unchanged(bad_fit):
    X, Y = random_problem(0, n_rows=80)
    model = BLS(n_enhance=15).fit(X, Y).add_enhancement_nodes(5)
    before = model.predict(X)
    params = model.get_params()
    with pytest.raises((ValueError, TypeError)):
        bad_fit(model, X, Y)
    model.set_params(**params)
    np.testing.assert_array_equal(model.predict(X), before)
    assert model.predict(X).shape == Y.shape
    model.add_enhancement_nodes(3)  # and it still learns
    assert model.n_hidden_ == 10 * 10 + 15 + 5 + 3


def test_estimator_conventions():
    from sklearn.base import clone

    X, Y = random_problem(1, n_rows=60)
    model = BLS(n_enhance=12, seed=4)
    assert not hasattr(model, "output_weights_") and repr(model) == "BLS(n_enhance=12, seed=4)"
    fitted = clone(model).fit(X, Y)
    again = clone(fitted)
    assert again.get_params() == model.get_params() and not hasattr(again, "output_weights_")
    np.testing.assert_array_equal(again.fit(X, Y).predict(X), fitted.predict(X))


def test_the_fast_paths_give_the_plain_computations_bits():
    """Speed paths checked against the plain computation they replace, bit for bit: the sparse
    autoencoder's ADMM with LAPACK's potrs against scipy's cho_solve, and a BLS fitted twice on
    the same inputs (the second from the remembered mapping) against one fitted with nothing
    remembered; a remembered mapping is a copy (changing one model's leaves the other's)."""
    from scipy.linalg import cho_factor, cho_solve

    from bidmp.incremental import bls as bls_module
    from bidmp.incremental.linalg import sparse_autoencoder

    rng = np.random.default_rng(7)
    F, target = rng.random((300, 12)), rng.normal(size=(300, 9))
    factor = cho_factor(F.T @ F + np.eye(12))
    z = u = np.zeros((12, 9))
    for _ in range(50):
        v = cho_solve(factor, F.T @ target + (z - u)) + u
        z = np.sign(v) * np.maximum(np.abs(v) - 1e-3, 0.0)
        u = v - z
    assert np.array_equal(sparse_autoencoder(F, target), z)

    X, Y = rng.random((200, 6)), rng.normal(size=(200, 2))
    bls_module._MAPPINGS.clear()
    first = BLS(seed=3).fit(X, Y)
    second = BLS(seed=3).fit(X, Y)  # from the remembered mapping
    bls_module._MAPPINGS.clear()
    fresh = BLS(seed=3).fit(X, Y)
    for model in (first, second):
        assert np.array_equal(model.mapping_weights_, fresh.mapping_weights_)
        assert np.array_equal(model.output_weights_, fresh.output_weights_)
    first.mapping_weights_[0, 0, 0] += 1.0
    assert not np.array_equal(first.mapping_weights_, second.mapping_weights_)
    other = BLS(seed=4).fit(X, Y)  # another seed: another mapping, not the remembered one
    assert not np.array_equal(other.mapping_weights_, fresh.mapping_weights_)
