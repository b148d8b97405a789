"""ProMPs: exact conditioning against an independent closed form and movement_primitives' ProMP,
the phase normalisation on demonstrations of other lengths and rates, sampling against the
analytic moments."""

from __future__ import annotations

import numpy as np
import pytest

from bidmp.demonstrations import lasa
from bidmp.primitives import ProMP


@pytest.fixture(scope="module")
def shape():
    return lasa("Angle")  # 7 demonstrations (7, 1000, 2), mm


@pytest.fixture(scope="module")
def promp(shape):
    return ProMP(n_basis=20).fit(list(shape))


def test_a_zero_variance_via_point_is_passed_exactly(promp, shape):
    extent = np.ptp(shape, axis=(0, 1)).max()
    points = np.array([[-12.0, 4.0], [3.0, -2.0]])
    conditioned = promp.condition([0.4, 1.0], points, 0.0)
    np.testing.assert_allclose(conditioned.mean([0.4, 1.0]), points, atol=1e-9 * extent)
    assert conditioned.var([0.4, 1.0]).max() <= 1e-9 * promp.var([0.4, 1.0]).max()
    # and elsewhere the motion keeps a spread
    assert conditioned.var([0.7]).max() > 0.0


def test_a_noisy_via_point_matches_the_information_form(promp):
    """Independent closed form: Σ' = (Σ⁻¹ + H N⁻¹ Hᵀ)⁻¹, μ' = Σ' (Σ⁻¹ μ + H N⁻¹ y)."""
    sigma2 = 0.5**2
    point = np.array([[2.0, 1.0]])
    conditioned = promp.condition([0.8], point, sigma2)
    H = promp._H(np.array([0.8]))
    precision = np.linalg.inv(promp.weight_cov_)
    cov = np.linalg.inv(precision + H @ H.T / sigma2)
    mean = cov @ (precision @ promp.weight_mean_ + H @ point.reshape(-1) / sigma2)
    np.testing.assert_allclose(
        conditioned.weight_mean_, mean, rtol=1e-6, atol=1e-8 * np.abs(mean).max()
    )
    np.testing.assert_allclose(conditioned.weight_cov_, cov, atol=1e-6 * np.abs(cov).max())
    # the posterior variance at the point is below both the prior's and the observation's
    at = conditioned.var([0.8])
    assert np.all(at < sigma2) and np.all(at < promp.var([0.8]))


def test_conditioning_equals_movement_primitives_on_the_same_distribution(promp):
    mp = pytest.importorskip("movement_primitives.promp")
    peer = mp.ProMP(n_dims=2, n_weights_per_dim=20)
    peer.from_weight_distribution(promp.weight_mean_.copy(), promp.weight_cov_.copy())
    goal = np.array([4.0, -1.0])
    theirs = peer.condition_position(goal, t=1.0, t_max=1.0)
    ours = promp.condition([1.0], goal[None], 0.0)
    T = np.linspace(0.0, 1.0, 200)
    np.testing.assert_allclose(ours.mean(T), theirs.mean_trajectory(T), atol=1e-8)
    np.testing.assert_allclose(ours.var(T), theirs.var_trajectory(T), atol=1e-8)


def test_demonstrations_of_other_lengths_and_rates_share_one_phase(shape):
    """Property: a demonstration resampled at 317 samples over 2.3 s (jittered stamps) has the
    weights of its 1000 uniform samples (the phase is each one's own normalised time)."""
    rng = np.random.default_rng(3)
    demo = shape[2]
    stamps = np.sort(np.concatenate([[0.0, 2.3], rng.uniform(0.0, 2.3, 315)]))
    resampled = np.column_stack(
        [np.interp(stamps / 2.3, np.linspace(0, 1, 1000), column) for column in demo.T]
    )
    a = ProMP(n_basis=15).fit([demo])
    b = ProMP(n_basis=15).fit([resampled], times=[stamps])
    extent = np.ptp(demo, axis=0).max()  # least squares on other samples: close, not equal
    np.testing.assert_allclose(a.mean(n_steps=300), b.mean(n_steps=300), atol=0.01 * extent)
    assert b.duration_ == pytest.approx(2.3)


def test_sampling_matches_the_moments_and_the_seed(promp):
    samples = promp.sample(4000, seed=5, n_steps=50)
    np.testing.assert_allclose(samples.mean(axis=0), promp.mean(n_steps=50), atol=0.3)
    np.testing.assert_allclose(samples.var(axis=0), promp.var(n_steps=50), rtol=0.15, atol=0.05)
    np.testing.assert_array_equal(promp.sample(3, seed=9), promp.sample(3, seed=9))


def test_velocities_are_the_positions_rate(promp):
    phase = np.linspace(0.0, 1.0, 2001)
    rate = np.gradient(promp.mean(phase), phase, axis=0) / promp.duration_
    np.testing.assert_allclose(
        promp.mean_velocity(phase)[5:-5], rate[5:-5], atol=1e-3 * np.abs(rate).max()
    )
    motion = promp.trajectory(dt=0.001)
    np.testing.assert_allclose(motion.y[-1], promp.mean([1.0])[0])


def test_bad_input_is_refused_by_name(promp):
    with pytest.raises(ValueError, match="demonstrations\\[1\\]"):
        ProMP().fit([np.zeros((10, 2)) + np.arange(10)[:, None], np.zeros((10, 3))])
    with pytest.raises(ValueError, match="phase"):
        promp.condition([1.5], [[0.0, 0.0]])
    with pytest.raises(ValueError, match="cov"):
        promp.condition([0.5], [[0.0, 0.0]], -1.0)
    with pytest.raises(TypeError, match="demonstrations"):
        ProMP().fit("nothing")


def test_a_promp_survives_its_file(promp, tmp_path):
    from bidmp.io import load_model, save_model

    loaded = load_model(save_model(promp, tmp_path / "promp"))
    np.testing.assert_array_equal(loaded.weight_cov_, promp.weight_cov_)
    goal = np.array([[1.0, 2.0]])
    np.testing.assert_array_equal(
        loaded.condition([1.0], goal).mean(), promp.condition([1.0], goal).mean()
    )


def test_conditioning_on_too_many_points_is_refused_before_it_is_built(promp, peak_memory):
    """10 million points asked for a 2.8 PiB covariance (a MemoryError); the stacked observation's
    size is checked first, and nothing of it is allocated."""
    phase = np.broadcast_to(0.5, (10**7,))
    values = np.broadcast_to(np.zeros(promp.n_dims_), (10**7, promp.n_dims_))
    with (
        peak_memory() as peak,
        pytest.raises(ValueError, match="conditioning on 10,000,000 points"),
    ):
        promp.condition(phase, values)
    assert peak.megabytes < 200.0, peak.megabytes


def _one_line(caught) -> str:
    message = str(caught.value)
    assert "\n" not in message and len(message) <= 300, message
    return message


@pytest.mark.parametrize("seed", range(3))
def test_one_point_given_twice_at_one_phase_is_that_point_once(promp, seed):
    """Two exact points at one phase with equal values read one combination of the weights twice
    (the innovation is singular: a raw LinAlgError before); they are one point. Oracle: the
    conditioning on the point once, with another point elsewhere to keep several of everything."""
    rng = np.random.default_rng(seed)
    here, there = float(rng.uniform(0.05, 0.45)), float(rng.uniform(0.55, 0.95))
    point, other = rng.normal(0.0, 10.0, (2, 2))
    twice = promp.condition([here, there, here], np.stack([point, other, point]), 0.0)
    once = promp.condition([here, there], np.stack([point, other]), 0.0)
    phases = np.linspace(0.0, 1.0, 50)
    scale = np.abs(once.mean(phases)).max()
    np.testing.assert_allclose(twice.mean(phases), once.mean(phases), atol=1e-7 * scale)
    np.testing.assert_allclose(
        twice.var(phases), once.var(phases), atol=1e-7 * promp.var(phases).max()
    )


@pytest.mark.parametrize("gap, cov", [(0.0, 0.0), (0.0, 1e-300), (1e-13, 0.0)])
def test_two_different_points_at_one_phase_are_refused_as_a_conflict(promp, gap, cov):
    """Different values at one phase (or 1e-13 of it apart) with no noise, or a tiny one, to
    reconcile them: no weights pass both. Refused naming the points, not a LinAlgError."""
    with pytest.raises(ValueError) as caught:
        promp.condition([0.2, 0.5, 0.5 + gap], [[1.0, 2.0], [3.0, 4.0], [5.0, -6.0]], cov)
    message = _one_line(caught)
    assert message.startswith("y: points 1 and 2 (both at phase 0.5) conflict"), message


def test_two_noisy_points_at_one_phase_are_their_mean_with_half_the_noise(promp):
    """Noise reconciles them: two observations of variance s at one phase are the Gaussian
    product, one observation of their mean with variance s / 2 (a closed form of its own)."""
    s = 0.7
    a, b = np.array([2.0, -1.0]), np.array([4.0, 3.0])
    both = promp.condition([0.6, 0.6], np.stack([a, b]), s)
    mean = promp.condition([0.6], ((a + b) / 2)[None], s / 2)
    np.testing.assert_allclose(both.weight_mean_, mean.weight_mean_, rtol=1e-8, atol=1e-8)
    np.testing.assert_allclose(
        both.weight_cov_, mean.weight_cov_, atol=1e-8 * np.abs(mean.weight_cov_).max()
    )


def test_more_exact_points_than_weights_pass_when_they_agree_and_are_refused_when_not():
    """Sixty exact points on 8 basis functions a dimension: a constant the basis represents
    exactly (its rows sum to 1) is passed; random values no weights pass are a conflict."""
    rng = np.random.default_rng(4)
    s = np.linspace(0.0, 1.0, 40)[:, None]
    demos = [np.hstack([s * 50 + k, np.sin(3 * s) * (5 + k)]) for k in range(4)]
    model = ProMP(n_basis=8).fit(demos)
    phases = np.linspace(0.0, 1.0, 60)
    flat = model.condition(phases, np.tile([7.0, -3.0], (60, 1)), 0.0)
    np.testing.assert_allclose(flat.mean(phases), np.tile([7.0, -3.0], (60, 1)), atol=1e-6)
    with pytest.raises(ValueError) as caught:
        model.condition(phases, rng.normal(0.0, 10.0, (60, 2)), 0.0)
    assert _one_line(caught).startswith("y: points ")


def test_condition_gaussian_names_conflicting_observations():
    from bidmp.primitives import condition_gaussian

    H = np.array([[1.0, 1.0], [0.0, 0.0], [2.0, 2.0]])
    with pytest.raises(ValueError) as caught:
        condition_gaussian(np.zeros(3), np.eye(3), H, [1.0, 2.0], np.zeros((2, 2)))
    assert _one_line(caught).startswith("y: observations 0 and 1 conflict")
    mean, cov = condition_gaussian(np.zeros(3), np.eye(3), H, [1.0, 1.0], np.zeros((2, 2)))
    once = condition_gaussian(np.zeros(3), np.eye(3), H[:, :1], [1.0], np.zeros((1, 1)))
    np.testing.assert_allclose(mean, once[0], atol=1e-12)
    np.testing.assert_allclose(cov, once[1], atol=1e-12)


def test_a_motion_conditioned_at_rest_at_both_ends_starts_and_ends_still(promp, shape):
    """rest=[0, 1]: velocity and acceleration 0 at both ends, exactly; judged by finite
    differences of the conditioned mean's positions on a fine phase grid (not the model's own
    derivatives), with a start, a via-point and a goal passed at once."""
    start, goal = shape[0][0] + [1.0, -2.0], shape[0][-1] + [3.0, 2.0]
    via = shape[0][500] + [-4.0, 5.0]
    conditioned = promp.condition(
        [0.0, 0.5, 1.0], np.stack([start, via, goal]), 0.0, rest=[0.0, 1.0]
    )
    h = 1e-4
    ends = conditioned.mean([0.0, h, 2 * h, 1.0 - 2 * h, 1.0 - h, 1.0])
    extent = np.ptp(shape, axis=(0, 1)).max()
    np.testing.assert_allclose(ends[[0, -1]], [start, goal], atol=1e-9 * extent)
    np.testing.assert_allclose(conditioned.mean([0.5])[0], via, atol=1e-9 * extent)
    for a, b, c in ((ends[0], ends[1], ends[2]), (ends[5], ends[4], ends[3])):
        slope = (-3 * a + 4 * b - c) / (2 * h)  # one-sided, second order
        curvature = (a - 2 * b + c) / h**2
        assert np.abs(slope).max() <= 1e-5 * extent and np.abs(curvature).max() <= 1e-2 * extent
    with pytest.raises(ValueError) as caught:  # a rest where it is told to move
        promp.condition([0.5, 0.5 + 1e-13], np.stack([via, via + 1.0]), 0.0, rest=[0.5])
    assert _one_line(caught).startswith("y: points 0 and 1")
