"""A DMP from several demonstrations: its spread against the demonstrations' own, its mean against
a DMP of the mean demonstration, sampling against the exact variance."""

from __future__ import annotations

import numpy as np
import pytest
from sklearn.base import clone

from bidmp import DMP
from bidmp.primitives import MultiDMP

T = 400


def _demos(n=7):
    s = np.linspace(0.0, 1.0, T)
    base = np.column_stack([100 * s, 30 * np.sin(np.pi * s)])
    bump = np.column_stack([0 * s, 10 * np.sin(np.pi * s) ** 2])
    return base, bump, [base + k * bump for k in np.linspace(-1.5, 1.5, n)]


@pytest.fixture(scope="module")
def model():
    _, _, demos = _demos()
    return MultiDMP().fit(demos, [np.linspace(0.0, 2.0, T)] * len(demos), units="mm")


def test_the_spread_is_the_demonstrations_own(model):
    """Where the demonstrations differ (a bump of random size in y), the model's exact standard
    deviation equals theirs (sample std, ddof 1) to 2 %; where they agree (x) it is ~0."""
    _, _, demos = _demos()
    spread = np.std(np.stack(demos), axis=0, ddof=1)
    std = model.std()
    middle = slice(T // 4, 3 * T // 4)
    np.testing.assert_allclose(std[middle, 1], spread[middle, 1], rtol=0.02)
    assert std[:, 0].max() < 1e-3 * spread[:, 1].max()


def test_the_mean_is_the_mean_demonstrations_dmp(model):
    """Property: the forcing target is affine in the demonstration, so the mean of the weights
    is the weights of the mean demonstration (the same grid and goal system)."""
    base, _, _ = _demos()
    single = DMP().fit(base, np.linspace(0.0, 2.0, T), units="mm")
    np.testing.assert_allclose(model.rollout(), single.rollout(), atol=1e-6 * np.ptp(base))


def test_samples_have_the_exact_variance_and_follow_the_seed(model):
    samples = model.sample(300, seed=4)
    std = model.std()
    middle = slice(T // 4, 3 * T // 4)
    np.testing.assert_allclose(samples.std(axis=0, ddof=1)[middle, 1], std[middle, 1], rtol=0.12)
    np.testing.assert_array_equal(model.sample(2, seed=8), model.sample(2, seed=8))
    # a new goal: the spread travels with the motion (the forcing enters alike)
    moved = model.std(goal=model.dmp_.goal_ + [20.0, -10.0])
    np.testing.assert_allclose(moved, std, atol=1e-9 * std.max())


def test_conventions_and_refusals():
    assert clone(MultiDMP(cov_reg=1e-4)).get_params()["cov_reg"] == 1e-4
    with pytest.raises(TypeError, match="dmp"):
        MultiDMP(dmp="robot").fit(_demos()[2])
    with pytest.raises(ValueError, match="demonstrations\\[1\\]"):
        MultiDMP().fit([np.ones((20, 2)) * np.arange(20)[:, None], np.ones((20, 3))])


def test_a_multi_dmp_survives_its_file(model, tmp_path):
    from bidmp.io import load_model, save_model

    loaded = load_model(save_model(model, tmp_path / "multi"))
    goal = model.dmp_.goal_ + [5.0, 5.0]
    np.testing.assert_array_equal(loaded.rollout(goal), model.rollout(goal))
    np.testing.assert_array_equal(loaded.std(goal), model.std(goal))
