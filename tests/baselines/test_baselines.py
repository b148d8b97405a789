"""GMM/GMR and TP-GMM baselines, against closed forms and properties."""

import numpy as np
import pytest

from bidmp.baselines import TPGMM, GMMRegressor, augment
from bidmp.baselines.gmm import _gmr
from bidmp.demonstrations import minimum_jerk


@pytest.fixture(scope="module")
def approach():
    return minimum_jerk([[-80, -120, 200], [0, 0, 40], [0, 0, 0]], 200)


def test_gmr_with_one_component_is_the_conditional_gaussian():
    rng = np.random.default_rng(0)
    L = rng.normal(size=(4, 4))
    sigma = L @ L.T + 4 * np.eye(4)
    mu = rng.normal(size=4)
    t = np.array([-1.0, 0.3, 2.0])
    mean, cov = _gmr(np.ones(1), mu[None], sigma[None], t)
    gain = sigma[1:, :1] / sigma[0, 0]
    np.testing.assert_allclose(mean, mu[1:] + (t[:, None] - mu[0]) * gain[:, 0], atol=1e-12)
    np.testing.assert_allclose(
        cov, np.broadcast_to(sigma[1:, 1:] - gain @ sigma[:1, 1:], (3, 3, 3)), atol=1e-12
    )


def test_gmr_follows_the_responsible_component():
    means = np.array([[0.0, 10.0], [1.0, -10.0]])
    covs = np.array([np.eye(2) * 0.01, np.eye(2) * 0.01])
    mean, _ = _gmr(np.array([0.5, 0.5]), means, covs, np.array([0.0, 1.0]))
    np.testing.assert_allclose(mean[:, 0], [10.0, -10.0], atol=1e-6)


def test_augment_keeps_ends_and_adds_copies(approach):
    copies = augment(approach, n_copies=4, noise=1.5, seed=3)
    assert copies.shape == (5, 200, 3)
    np.testing.assert_array_equal(copies[0], approach)
    np.testing.assert_allclose(
        copies[:, [0, -1]], np.broadcast_to(approach[[0, -1]], (5, 2, 3)), atol=1e-12
    )
    assert 0.5 < np.std(copies[1:] - approach) < 3.0


def test_gmm_reproduces_its_demonstration_but_cannot_move(approach):
    mean, cov = GMMRegressor().fit(approach).rollout(return_covariance=True)
    assert mean.shape == (200, 3) and cov.shape == (200, 3, 3)
    assert np.linalg.norm(mean[-1] - approach[-1]) < 1.75
    assert np.sqrt(np.mean(np.sum((mean - approach) ** 2, axis=1))) < 3.0


def test_tpgmm_is_translation_equivariant_and_halfway_with_one_demonstration(approach):
    model = TPGMM().fit(approach)
    start, target = approach[0], approach[-1]
    base, _ = model.rollout(target, start=start, return_covariance=True)
    assert np.linalg.norm(base[-1] - target) < 1.75
    shift = np.array([25.0, -40.0, 10.0])
    moved, _ = model.rollout(target + shift, start=start + shift, return_covariance=True)
    np.testing.assert_allclose(moved, base + shift, atol=1e-8)
    # One demonstration: both frames are equally sure, so the product lands halfway.
    new_target = target + np.array([100.0, 0.0, 0.0])
    end = model.rollout(new_target, start=start)[-1]
    assert 0.35 < np.linalg.norm(end - new_target) / 100.0 < 0.65
