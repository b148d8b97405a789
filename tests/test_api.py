"""One API shape: rollout/trajectory/stepper(goal=None, *, ...) keyword-only past the goal on
every estimator; nothing else (no positional spellings, no generate()). Structural checks: they
guard the interface, the numbers come from the estimators' own tests."""

import inspect

import numpy as np
import pytest

import bidmp
from bidmp.baselines import TPGMM, GMMRegressor
from bidmp.demonstrations import minimum_jerk

DEMO = minimum_jerk(
    np.array([[0.0, 0.0, 50.0], [40.0, 10.0, 20.0], [100.0, 20.0, 0.0]]), n_steps=120
)


@pytest.fixture(scope="module")
def models():
    dmp = bidmp.DMP().fit(DMP_DEMO := DEMO, np.linspace(0.0, 1.2, len(DMP_DEMO)))
    bi = bidmp.BiDMP(dmp, increments=(5,))
    bi.learn(DEMO + np.linspace(0.0, 1.0, len(DEMO))[:, None] * [30.0, 0.0, 0.0])
    return {"dmp": dmp, "bidmp": bi}


@pytest.mark.parametrize(
    "cls", [bidmp.DMP, bidmp.BiDMP, bidmp.CartesianDMP, bidmp.CartesianBiDMP, TPGMM, GMMRegressor]
)
def test_everything_past_the_goal_is_keyword_only(cls):
    for name in ("rollout", "trajectory", "stepper"):
        method = getattr(cls, name, None)
        if method is None:
            continue
        parameters = list(inspect.signature(method).parameters.values())[1:]
        assert parameters[0].name == "goal" and parameters[0].default is None, (cls.__name__, name)
        assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in parameters[1:]), (
            cls.__name__,
            name,
        )


def test_arguments_past_the_goal_by_position_are_refused(models):
    """bidmp 0.6 has one API: the start, duration, skill … by keyword (0.5 still took them by
    position with a warning)."""
    dmp, goal, start = models["dmp"], DEMO[-1] + 10.0, DEMO[0] - 5.0
    for call in (
        lambda: dmp.rollout(goal, start),
        lambda: dmp.trajectory(goal, start, 2.0),
        lambda: models["bidmp"].rollout(goal, "latest"),
    ):
        with pytest.raises(TypeError, match="positional argument"):
            call()
    np.testing.assert_array_equal(
        dmp.rollout(goal, start=start), dmp.rollout(goal=goal, start=start)
    )


def test_the_baselines_roll_out_with_their_covariances_and_generate_is_gone():
    tpgmm = TPGMM(n_components=4, n_copies=2).fit(DEMO)
    mean, covariances = tpgmm.rollout(DEMO[-1] + 5.0, start=DEMO[0], return_covariance=True)
    assert covariances.shape == (len(DEMO), 3, 3) and mean.shape == DEMO.shape
    np.testing.assert_array_equal(
        tpgmm.rollout(), tpgmm.rollout(DEMO[-1], start=DEMO[0])
    )  # the defaults
    gmm = GMMRegressor(n_components=4, n_copies=2).fit(DEMO)
    assert not hasattr(gmm, "generate") and not hasattr(tpgmm, "generate")
    with pytest.raises(ValueError, match="goal: GMMRegressor reproduces its demonstration"):
        gmm.rollout(DEMO[-1])
