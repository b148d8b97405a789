"""Bi-DMP: incremental forcing term, skill library, forgetting, persistence."""

import numpy as np
import pytest

import bidmp
from bidmp import DMP, BiDMP, extend_demonstration, forgetting
from bidmp._trajectory import resample_time
from bidmp.demonstrations import lasa, minimum_jerk
from bidmp.experiments import BATTERY_APPROACH_VIA, BATTERY_EXTENSION_TARGET


def relative_rmse(a, b):
    return np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1))) / np.linalg.norm(np.ptp(b, axis=0))


@pytest.fixture(scope="module")
def battery():
    demo = minimum_jerk(BATTERY_APPROACH_VIA, 200)
    dmp = DMP(protocol="paper", alpha=100.0).fit(demo)
    extension = extend_demonstration(demo, BATTERY_EXTENSION_TARGET, seed=0)
    return demo, dmp, extension


def test_learned_demonstration_is_reproduced_at_its_goal(battery):
    demo, dmp, extension = battery
    model = BiDMP(dmp).learn(extension.complete, duration=extension.duration_for(dmp))
    assert model.n_skills == 2
    rollout = model.rollout(BATTERY_EXTENSION_TARGET)
    assert (
        abs(len(rollout) - len(extension.complete)) <= 1
    )  # the skill lasts as long as its demonstration
    assert relative_rmse(rollout, resample_time(extension.complete, len(rollout))) < 0.01
    # ... which the plain DMP cannot do.
    assert (
        relative_rmse(
            dmp.rollout(BATTERY_EXTENSION_TARGET), resample_time(extension.complete, dmp.n_steps_)
        )
        > 0.05
    )


@pytest.mark.parametrize("name", ["Sshape", "WShape"])
def test_lasa_extension_reproduced(name):
    demo = lasa(name)[0]
    dmp = DMP(protocol="paper").fit(demo)
    extension = extend_demonstration(demo, demo[-1] + [12.0, -9.0], seed=1)
    # The transfer takes as long as it needs: the skill lasts as long as the extension.
    model = BiDMP(dmp).learn(extension.complete, duration=extension.duration_for(dmp))
    rollout = model.rollout(extension.complete[-1])
    assert abs(len(rollout) - len(extension.complete)) <= 1
    assert relative_rmse(rollout, resample_time(extension.complete, len(rollout))) < 0.01


def test_skill_zero_is_the_plain_dmp_bit_for_bit(battery):
    demo, dmp, extension = battery
    model = BiDMP(dmp).learn(extension.complete)
    goals = [demo[-1], [60.0, 50.0, 0.0], [180.0, 0.0, 0.0]]
    for goal in goals:
        np.testing.assert_array_equal(model.rollout(goal, skill=0), dmp.rollout(goal))
    np.testing.assert_array_equal(model.rollout(demo[-1]), dmp.rollout())  # nearest picks skill 0


def test_zero_forcing_increment_leaves_the_dmp_unchanged(battery):
    demo, dmp, _ = battery
    model = BiDMP(dmp).learn_increment(np.zeros((dmp.n_steps_, 3)), goal=[150.0, 25.0, 0.0])
    for goal in ([150.0, 25.0, 0.0], [30.0, 50.0, 0.0]):
        np.testing.assert_allclose(
            model.rollout(goal, skill=1), dmp.rollout(goal), rtol=0, atol=1e-12
        )
    np.testing.assert_allclose(
        model.forcing_term(dmp.phase()), dmp.forcing_term(dmp.phase()), atol=1e-12
    )


def three_operator_demonstrations(n_steps=200):
    """Pick-and-place by three operators: same task, different height and reach (seeded)."""
    demonstrations = []
    for index, (height, reach) in enumerate([(150.0, 300.0), (190.0, 340.0), (120.0, 260.0)]):
        via = [[0.0, 0.0, 0.0], [0.4 * reach, 20.0, height], [reach, 60.0, 30.0]]
        demonstrations.append(minimum_jerk(via, n_steps, noise=0.5, seed=index))
    return demonstrations


def test_forgetting_nearest_is_zero_latest_forgets():
    """An architecture guard: skill p uses the blocks up to p only, so "nearest" cannot forget
    by construction. It guards the skill library's structure; whether learning is faithful is
    the test after it."""
    demonstrations = three_operator_demonstrations()
    dmp = DMP(protocol="paper", alpha=40.0).fit(demonstrations[0])
    nearest = forgetting(dmp, demonstrations[1:], skill="nearest")
    latest = forgetting(dmp, demonstrations[1:], skill="latest")
    np.testing.assert_allclose(nearest.forgetting, 0.0, atol=1e-9)
    assert np.all(latest.forgetting[:-1] > 1.0)  # mm: the earlier skills are overwritten
    assert latest.forgetting[-1] == pytest.approx(0.0, abs=1e-9)
    # Every learned skill is reproduced when it is learned.
    extent = np.linalg.norm(np.ptp(demonstrations[1], axis=0))
    assert np.all(np.diag(nearest.errors)[1:] < 0.01 * extent)


@pytest.mark.parametrize("protocol, params", [("paper", {"alpha": 40.0}), ("robot", {})])
def test_every_skill_reproduces_its_demonstration_as_well_as_a_dmp_fitted_on_it(protocol, params):
    """Learning is faithful: after all demonstrations are learned, each skill reproduces its own
    demonstration at least as well (5 % margin) as a DMP fitted from scratch on it alone."""
    from bidmp._trajectory import rmse

    demonstrations = three_operator_demonstrations()
    t = np.arange(200) / 100.0
    model = BiDMP(DMP(protocol=protocol, **params).fit(demonstrations[0], t))
    for demonstration in demonstrations[1:]:
        model.learn(demonstration)
    for skill, demonstration in enumerate(demonstrations):
        learned = model.rollout(demonstration[-1], skill=skill, start=demonstration[0])[:200]
        scratch = DMP(protocol=protocol, **params).fit(demonstration, t).rollout()[:200]
        assert rmse(learned, demonstration) <= 1.05 * rmse(scratch, demonstration), skill
        assert model.select_skill(demonstration[-1]) == skill  # "nearest" finds it


def test_several_demonstrations_stack_blocks(battery):
    demo, dmp, extension = battery
    second = extend_demonstration(extension.complete, [60.0, 100.0, -20.0], seed=3)
    model = BiDMP(dmp).learn(extension.complete, duration=extension.duration_for(dmp))
    model.learn(second.complete, duration=second.duration_for(dmp))
    assert model.n_skills == 3 and len(model.blocks_) == 2
    for goal, learned in (([60.0, 100.0, -20.0], second), (BATTERY_EXTENSION_TARGET, extension)):
        rollout = model.rollout(goal)
        assert relative_rmse(rollout, resample_time(learned.complete, len(rollout))) < 0.01
    assert model.select_skill([60.0, 100.0, -20.0]) == 2 and model.select_skill(demo[-1]) == 0
    assert model.select_skill(demo[-1], "latest") == 2 and model.select_skill(demo[-1], 1) == 1


def test_same_seed_same_model(battery):
    _, dmp, extension = battery
    first = BiDMP(dmp, seed=4).learn(extension.complete).rollout(BATTERY_EXTENSION_TARGET)
    again = BiDMP(dmp, seed=4).learn(extension.complete).rollout(BATTERY_EXTENSION_TARGET)
    np.testing.assert_array_equal(first, again)


def test_save_load_reproduces_rollouts_bit_for_bit(tmp_path, battery):
    demo, dmp, extension = battery
    model = BiDMP(dmp, increments=(10, 15)).learn(extension.complete)
    loaded = bidmp.load(bidmp.save(model, tmp_path / "bidmp.npz"))
    assert isinstance(loaded, BiDMP) and loaded.n_skills == 2 and loaded.increments == (10, 15)
    for goal in (BATTERY_EXTENSION_TARGET, demo[-1], [90.0, 50.0, 0.0]):
        for skill in ("nearest", "latest", 0, 1):
            np.testing.assert_array_equal(
                loaded.rollout(goal, skill=skill), model.rollout(goal, skill=skill)
            )


@pytest.mark.parametrize(
    "call, error, match",
    [
        (
            lambda m: m.learn(np.zeros((50, 2)) + np.arange(50)[:, None]),
            ValueError,
            "y_dn has D = 2",
        ),
        (lambda m: m.learn(np.full((50, 3), np.nan)), ValueError, "NaN"),
        (lambda m: m.learn(np.ones((2, 3))), ValueError, "at least 3 points"),
        (
            lambda m: m.rollout([1.0, 2.0, 3.0], skill="favourite"),
            ValueError,
            "skill must be 'nearest', 'latest'",
        ),
        (
            lambda m: m.rollout([1.0, 2.0, 3.0], skill=5),
            ValueError,
            "skill must be between 0 and 1",
        ),
        (lambda m: m.rollout([1.0, 2.0]), ValueError, "goal must have 3"),
        (
            lambda m: BiDMP(DMP(protocol="paper")).learn(np.ones((5, 3))),
            bidmp.NotFittedError,
            "not fitted",
        ),
        (lambda m: BiDMP(DMP(protocol="paper")).rollout(), bidmp.NotFittedError, "not fitted"),
        (lambda m: BiDMP("dmp").fit(np.eye(3)), TypeError, "dmp must be a bidmp.DMP"),
        (
            lambda m: BiDMP(m.dmp_, increments=(0,)).learn(np.eye(3)),
            ValueError,
            "increments must be >= 1",
        ),
    ],
)
def test_bad_input(battery, call, error, match):
    _, dmp, extension = battery
    model = BiDMP(dmp).learn(extension.complete)
    with pytest.raises(error, match=match):
        call(model)


def test_resample_time_keeps_ends_and_uniform_sampling():
    y = np.column_stack([np.linspace(0.0, 1.0, 7), np.linspace(2.0, 3.0, 7) ** 2])
    out = resample_time(y, 13)
    assert out.shape == (13, 2)
    np.testing.assert_array_equal(out[[0, -1]], y[[0, -1]])
    np.testing.assert_allclose(out[:, 0], np.linspace(0.0, 1.0, 13))


# --- convergence: the increment vanishes with the phase ----------------------------------------
def test_every_skill_rolled_out_ten_times_longer_reaches_its_goal(battery):
    demo, dmp, extension = battery
    model = BiDMP(dmp).learn(extension.complete)
    second = extend_demonstration(extension.complete, [60.0, 50.0, 0.0], seed=3)
    model.learn(second.complete)
    long = 10 * dmp.n_steps_
    plain = np.linalg.norm(dmp.rollout(n_steps=long)[-1] - demo[-1])
    for skill in range(model.n_skills):
        for goal in (model.skill_goals_[skill], model.skill_goals_[skill] + [20.0, -10.0, 5.0]):
            error = np.linalg.norm(model.rollout(goal, skill=skill, n_steps=long)[-1] - goal)
            assert error <= 0.01, (skill, goal, error)  # mm
    assert plain <= 0.01
    # Longer still, the Bi-DMP keeps converging like the plain DMP (no drift past the horizon).
    goal = model.skill_goals_[1]
    assert np.linalg.norm(model.rollout(goal, skill=1, n_steps=40 * dmp.n_steps_)[-1] - goal) < 1e-6


def test_increment_vanishes_with_the_phase_and_is_held_below_the_trained_range(battery):
    _, dmp, extension = battery
    model = BiDMP(dmp).learn(extension.complete)
    phase = np.array([1.0, 0.6, model.phase_min_, 0.2, 1e-3, 0.0])
    increment = model.forcing_term(phase) - dmp.forcing_term(phase)
    np.testing.assert_array_equal(increment[-1], 0.0)
    # Below the trained range the BLS input is held: increment = phase · BLS(φ(phase_min)).
    held = model.blocks_[0].predict(dmp.basis([model.phase_min_]))[0]
    np.testing.assert_allclose(increment[3:], phase[3:, None] * held[None], rtol=1e-10, atol=1e-12)
    assert np.abs(increment[-2]).max() < 1e-2 * np.abs(increment[:3]).max()


def test_output_weights_stay_moderate(battery):
    _, dmp, extension = battery
    model = BiDMP(dmp).learn(extension.complete)
    increment = model.forcing_term(dmp.phase()) - dmp.forcing_term(dmp.phase())
    target_scale = np.abs(increment / dmp.phase()[:, None]).max()
    weights = max(np.abs(block.output_weights_).max() for block in model.blocks_)
    assert weights < 10 * target_scale  # was 450× with reg = 1e-8 (7.5e5 on the nut task)


# --- estimator conventions ------------------------------------------------------------------------
def test_estimator_conventions_and_clone(battery):
    from sklearn.base import clone

    demo, dmp, extension = battery
    model = BiDMP(dmp, n_enhance=60, increments=(10,))
    params = model.get_params(deep=True)
    assert params["dmp__alpha"] == 100.0 and params["n_enhance"] == 60  # the DMP's parameters too
    assert not hasattr(model, "blocks_") and not hasattr(model, "dmp_")
    copy = clone(model)
    assert copy.get_params()["dmp__alpha"] == 100.0 and copy.dmp is not dmp
    assert not hasattr(copy.dmp, "weights_")  # clone drops learned state, as in scikit-learn
    with pytest.raises(bidmp.NotFittedError, match="not fitted"):
        copy.learn(extension.complete)
    copy.fit(demo).learn(extension.complete)  # fit() fits a copy of the DMP on the demonstration
    model.learn(extension.complete)
    np.testing.assert_array_equal(copy.rollout(), model.rollout())
    assert not hasattr(copy.dmp, "weights_")  # the parameter itself is never fitted
    model.set_params(dmp__alpha=100.0, reg=1e-4)
    assert "BiDMP(" in repr(model)
