"""One API shape (issue 20): rollout/trajectory/stepper(goal=None, *, ...) keyword-only past the
goal on every estimator, the old positional spellings still working for now with a
DeprecationWarning, generate() kept as a deprecated alias. Structural checks: they guard the
interface, the numbers come from the estimators' own tests."""

import inspect

import numpy as np
import pytest

import bidmp
from bidmp.baselines import TPGMM, GMMRegressor
from bidmp.datasets import minimum_jerk

DEMO = minimum_jerk(np.array([[0.0, 0.0, 50.0], [40.0, 10.0, 20.0], [100.0, 20.0, 0.0]]), n_steps=120)


@pytest.fixture(scope="module")
def models():
    dmp = bidmp.DMP().fit(DMP_DEMO := DEMO, np.linspace(0.0, 1.2, len(DMP_DEMO)))
    bi = bidmp.BiDMP(dmp, increments=(5,))
    bi.learn(DEMO + np.linspace(0.0, 1.0, len(DEMO))[:, None] * [30.0, 0.0, 0.0])
    return {"dmp": dmp, "bidmp": bi}


@pytest.mark.parametrize("cls", [bidmp.DMP, bidmp.BiDMP, bidmp.CartesianDMP, bidmp.CartesianBiDMP, TPGMM, GMMRegressor])
def test_everything_past_the_goal_is_keyword_only(cls):
    for name in ("rollout", "trajectory", "stepper"):
        method = getattr(cls, name, None)
        if method is None:
            continue
        parameters = list(inspect.signature(method).parameters.values())[1:]
        assert parameters[0].name == "goal" and parameters[0].default is None, (cls.__name__, name)
        assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in parameters[1:]), (cls.__name__, name)


def test_positional_start_still_works_with_a_deprecation_warning(models):
    dmp, goal, start = models["dmp"], DEMO[-1] + 10.0, DEMO[0] - 5.0
    with pytest.warns(DeprecationWarning, match=r"pass start by keyword"):
        old = dmp.rollout(goal, start)
    np.testing.assert_array_equal(old, dmp.rollout(goal, start=start))
    with pytest.warns(DeprecationWarning, match=r"pass start, duration by keyword"):
        old = dmp.trajectory(goal, start, 2.0)
    np.testing.assert_array_equal(old.y, dmp.trajectory(goal, start=start, duration=2.0).y)
    with pytest.warns(DeprecationWarning, match=r"pass skill by keyword"):
        old = models["bidmp"].rollout(goal, "latest")
    np.testing.assert_array_equal(old, models["bidmp"].rollout(goal, skill="latest"))
    with pytest.raises(TypeError, match="multiple values for argument 'start'"):
        dmp.rollout(goal, start, start=start)
    with pytest.raises(TypeError, match="positional arguments"):
        dmp.rollout(goal, start, 10, None, "extra")


def test_generate_is_a_deprecated_alias_of_rollout():
    tpgmm = TPGMM(n_components=4, n_copies=2).fit(DEMO)
    with pytest.warns(DeprecationWarning, match=r"use rollout\(\)"):
        mean, covariances = tpgmm.generate(DEMO[0], DEMO[-1] + 5.0)
    np.testing.assert_array_equal(mean, tpgmm.rollout(DEMO[-1] + 5.0, start=DEMO[0]))
    assert covariances.shape == (len(DEMO), 3, 3)
    np.testing.assert_array_equal(tpgmm.rollout(), tpgmm.rollout(DEMO[-1], start=DEMO[0]))  # the defaults
    gmm = GMMRegressor(n_components=4, n_copies=2).fit(DEMO)
    with pytest.warns(DeprecationWarning, match=r"use rollout\(\)"):
        mean, _ = gmm.generate()
    np.testing.assert_array_equal(mean, gmm.rollout())
    with pytest.raises(ValueError, match="goal: GMMRegressor reproduces its demonstration"):
        gmm.rollout(DEMO[-1])
