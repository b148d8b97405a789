"""G-PRM and classic PRM."""

import numpy as np
import pytest

from bidmp._trajectory import resample_arclength
from bidmp.demonstrations import minimum_jerk
from bidmp.experiments import compare_prm, table5_cases
from bidmp.extension import (
    NoFreeRouteError,
    RoadmapOptions,
    classic_prm,
    frechet_similarity,
    gaussian_prm,
    template,
)
from bidmp.extension.roadmap import _shortest_path as shortest_path


@pytest.fixture
def arc_piece():
    theta = np.linspace(0.0, np.pi / 2, 80)
    return np.column_stack([np.cos(theta), np.sin(theta)]) * 10.0  # from (10, 0) to (0, 10)


@pytest.mark.parametrize("method", [gaussian_prm, classic_prm])
def test_path_starts_at_seg_and_ends_at_the_new_target_exactly(method, arc_piece):
    target = np.array([-4.0, 14.0])
    result = method(arc_piece, target, seed=3)
    assert np.array_equal(result.path[0], arc_piece[0])
    assert np.array_equal(result.path[-1], target)
    assert result.history.shape == (10,)
    assert result.similarity == result.history.max()


@pytest.mark.parametrize("scaling", ["axis", "similarity"])
def test_template_ends_at_new_target_and_is_finite_on_degenerate_axes(scaling):
    descent = minimum_jerk([[0.0, 0.0, 40.0], [0.0, 0.0, 0.0]], 50)  # vertical: x and y degenerate
    piece = resample_arclength(descent, 100)
    new_target = np.array([150.0, 25.0, 0.0])
    shape = template(piece, new_target, scaling)
    assert np.all(np.isfinite(shape))
    assert np.array_equal(shape[0], piece[0]) and np.array_equal(shape[-1], new_target)
    if scaling == "axis":  # ramp on x, y; z scaled by 1: the descent profile is kept
        np.testing.assert_allclose(shape[:, 2], piece[:, 2], atol=1e-12)


def test_axis_template_is_the_piece_when_the_target_is_tar(arc_piece):
    np.testing.assert_allclose(template(arc_piece, arc_piece[-1], "axis"), arc_piece, atol=1e-12)
    np.testing.assert_allclose(
        template(arc_piece, arc_piece[-1], "similarity"), arc_piece, atol=1e-12
    )


def test_similarity_template_is_a_scaled_rotation(arc_piece):
    new_target = np.array([20.0, -10.0])
    shape = template(arc_piece, new_target, "similarity")
    scale = np.linalg.norm(new_target - arc_piece[0]) / np.linalg.norm(arc_piece[-1] - arc_piece[0])
    original = np.linalg.norm(arc_piece[:, None] - arc_piece[None], axis=-1)
    mapped = np.linalg.norm(shape[:, None] - shape[None], axis=-1)
    np.testing.assert_allclose(mapped, scale * original, atol=1e-9)  # all distances scale alike
    antiparallel = template(arc_piece, arc_piece[0] - (arc_piece[-1] - arc_piece[0]), "similarity")
    assert np.all(np.isfinite(antiparallel))


@pytest.mark.parametrize(
    "schedule, rho", [("geometric", 0.9), ("harmonic", 0.9), ("geometric", 0.7)]
)
def test_bias_update_follows_eq8_when_the_noise_vanishes(arc_piece, schedule, rho):
    """With sigma -> 0 and n_tar = tar the path is the biased line itself, so the gap 1 - s to
    the template shrinks exactly as Eq. 8 says: gap <- gap (1 - gap eta_it)."""
    result = gaussian_prm(
        arc_piece,
        arc_piece[-1],
        RoadmapOptions(sigma_rel=1e-9, schedule=schedule, rho=rho),
        seed=0,
    )
    gap = 1.0 - result.history
    eta = rho ** np.arange(1, 10) if schedule == "geometric" else rho / np.arange(1, 10)
    predicted = gap[:-1] * (1.0 - gap[:-1] * eta)
    np.testing.assert_allclose(gap[1:], predicted, rtol=0.02)
    assert np.all(np.diff(result.history) > 0)
    # Eq. 8 shrinks its own steps ((1 - s) eta): with the defaults a quarter circle plateaus near
    # 0.92, short of the 0.95 hoped for, after 10 iterations (noted in the README).
    if (schedule, rho) == ("geometric", 0.9):
        assert 0.85 < result.history[-1] < 0.95


def test_same_seed_same_result_other_seed_other_result(arc_piece):
    target = np.array([-5.0, 12.0])
    first = gaussian_prm(arc_piece, target, seed=11)
    again = gaussian_prm(arc_piece, target, seed=11)
    other = gaussian_prm(arc_piece, target, seed=12)
    assert np.array_equal(first.path, again.path) and np.array_equal(first.history, again.history)
    assert not np.array_equal(first.path, other.path)
    generator = gaussian_prm(arc_piece, target, seed=np.random.default_rng(11))
    assert np.array_equal(generator.path, first.path)


def test_gprm_improves_on_its_first_iteration_and_beats_classic_prm_over_20_seeds():
    """Paper Table 5 on the `bidmp reproduce table5` cases: per case the final (best-of) G-PRM
    similarity beats its first iteration and classic PRM's best-of; over the cases the first
    G-PRM iteration beats classic PRM's mean."""
    firsts, prm_means = [], []
    for name, (y, target, _) in table5_cases().items():
        comparison = compare_prm(y, target, name=name, n_seeds=20)
        final, first = comparison.gprm.max(axis=1).mean(), comparison.gprm[:, 0].mean()
        assert final > first, name
        assert final > comparison.prm.max(axis=1).mean(), name
        firsts.append(first)
        prm_means.append(comparison.prm.mean())
    assert np.mean(firsts) > np.mean(prm_means)


def test_collision_callback_keeps_the_path_out_of_an_obstacle():
    piece = np.linspace([0.0, 0.0], [10.0, 0.0], 50)
    target = np.array([20.0, 0.0])
    centre, radius = np.array([10.0, 0.0]), 2.0  # a disc on the straight line seg -> target

    def is_free(points):
        return np.linalg.norm(points - centre, axis=1) > radius

    result = gaussian_prm(piece, target, RoadmapOptions(sigma_rel=0.15), is_free=is_free, seed=0)
    assert np.all(is_free(result.path))
    free_run = gaussian_prm(piece, target, RoadmapOptions(sigma_rel=0.15), seed=0)
    assert not np.all(is_free(free_run.path))  # without the callback the path goes through it
    with pytest.raises(ValueError, match="inside an obstacle"):
        gaussian_prm(piece, centre + [0.5, 0.0], is_free=is_free)


def test_a_wall_that_blocks_every_route_is_an_error_never_a_path_through_it():
    nodes = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0], [3.0, 0.0]])
    assert shortest_path(nodes, 1).tolist() == [0, 1, 2, 3]
    wall = lambda points: np.abs(points[:, 0] - 1.5) > 0.4  # noqa: E731 - a wall at x = 1.5
    assert shortest_path(nodes, 1, is_free=wall) is None
    with pytest.raises(NoFreeRouteError, match="no collision-free route"):
        gaussian_prm(
            np.linspace([0.0, 0.0], [1.0, 0.0], 10),
            [3.0, 0.0],
            RoadmapOptions(n_samples=20),
            is_free=wall,
            seed=0,
        )


def test_unreachable_target_without_a_callback_falls_back_to_the_sample_chain():
    # Far apart samples and one neighbour: the kNN graph is disconnected, nothing is in the way.
    result = gaussian_prm(
        np.linspace([0.0, 0.0], [1.0, 0.0], 10),
        [3.0, 0.0],
        RoadmapOptions(n_samples=2, n_neighbours=1, sigma_rel=5.0),
        seed=0,
    )
    assert np.array_equal(result.path[0], [0.0, 0.0]) and np.array_equal(
        result.path[-1], [3.0, 0.0]
    )


@pytest.mark.parametrize(
    "kwargs, error, match",
    [
        ({"new_target": [1.0, 2.0, 3.0]}, ValueError, "new_target must have 2"),
        ({"new_target": [np.nan, 2.0]}, ValueError, "NaN"),
        ({"n_samples": 1}, ValueError, "n_samples must be >= 2"),
        ({"scaling": "stretch"}, ValueError, "scaling must be one of"),
        ({"compare": "other"}, ValueError, "compare must be one of"),
        ({"n_iter": 0}, ValueError, "n_iter must be >= 1"),
        ({"new_target": [10.0, 0.0]}, ValueError, "coincides with the start"),
    ],
)
def test_bad_input(arc_piece, kwargs, error, match):
    target = kwargs.pop("new_target", [0.0, 15.0])
    with pytest.raises(error, match=match):
        gaussian_prm(arc_piece, target, RoadmapOptions(**kwargs))


def test_options_are_one_checked_object():
    """The options are checked when made, once; both roadmaps refuse anything else by name."""
    options = RoadmapOptions(n_iter=3)
    assert options.replace(sigma_rel=0.1) == RoadmapOptions(n_iter=3, sigma_rel=0.1)
    with pytest.raises(ValueError, match="sigma_rel"):
        options.replace(sigma_rel=-1.0)
    piece = np.linspace([0.0, 0.0], [1.0, 0.0], 10)
    for roadmap in (gaussian_prm, classic_prm):
        with pytest.raises(TypeError, match="options must be a bidmp.extension.RoadmapOptions"):
            roadmap(piece, [3.0, 0.0], {"n_iter": 3})


def test_paper_scaling_and_raw_comparison_run(arc_piece):
    target = np.array([-4.0, 14.0])
    for options in (
        {"scaling": "paper"},
        {"compare": "raw"},
        {"schedule": "harmonic"},
        {"select": "last"},
    ):
        result = gaussian_prm(arc_piece, target, RoadmapOptions(**options), seed=1)
        assert 0.0 <= result.similarity <= 1.0 and np.array_equal(result.path[-1], target)
    raw = gaussian_prm(arc_piece, target, RoadmapOptions(compare="raw"), seed=1)
    # Against Tra_imi itself the end-point gap caps the score below the template's.
    assert (
        raw.history.max()
        < frechet_similarity(
            template(resample_arclength(arc_piece, 100), target), resample_arclength(arc_piece, 100)
        )
        + 0.2
    )
    assert gaussian_prm(arc_piece, target, RoadmapOptions(select="last"), seed=1).iteration == 9
