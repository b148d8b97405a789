"""One motion interface for every point-to-point kind: the same call, the same meaning.

The checks read the motion independently of the kinds' own machinery: where it starts and ends,
where it is at a via-point's time (interpolated from the samples), and its speed by finite
differences of the positions (not the kinds' own velocities).
"""

from __future__ import annotations

import inspect

import numpy as np
import pytest

import bidmp
from bidmp import BiDMP, CartesianBiDMP, MotionLimits
from bidmp.demonstrations import minimum_jerk
from bidmp.primitives import (
    DMP,
    CartesianDMP,
    MotionPrimitive,
    MultiDMP,
    ProbabilisticPrimitive,
    ProDMP,
    ProMP,
)

KEYWORDS = ("start", "start_velocity", "duration", "dt", "via", "limits")


def demonstrations(seed: int, n: int = 5, samples: int = 301):
    """``n`` demonstrations (mm), 3 s each: a minimum-jerk time law along a quadratic Bézier
    curve whose middle control point varies (a smooth motion that never stops midway)."""
    rng = np.random.default_rng(seed)
    start, end = rng.uniform(-50, 50, 3), rng.uniform(100, 200, 3)
    middle = 0.5 * (start + end) + rng.uniform(-30, 30, 3)
    tau = np.linspace(0.0, 1.0, samples)
    s = (10 * tau**3 - 15 * tau**4 + 6 * tau**5)[:, None]
    demos = []
    for _ in range(n):
        bend = middle + rng.normal(0.0, 4.0, 3)
        demos.append((1 - s) ** 2 * start + 2 * (1 - s) * s * bend + s**2 * end)
    return np.linspace(0.0, 3.0, samples), demos


def fitted_kinds(seed: int):
    t, demos = demonstrations(seed)
    dmp = DMP(n_kernels=30).fit(demos[0], t)
    promp = ProMP(n_basis=20).fit(demos, [t] * len(demos), units="mm")
    prodmp = ProDMP(n_basis=15).fit(demos, [t] * len(demos), units="mm")
    return t, demos, {"DMP": dmp, "ProMP": promp, "ProDMP": prodmp}


def at(motion, when: float) -> np.ndarray:
    """The motion's position at ``when`` s, linearly between its samples."""
    return np.array([np.interp(when, motion.t, column) for column in motion.y.T])


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_three_kinds_take_one_call_and_mean_the_same(seed):
    """DMP, ProDMP and ProMP fitted on the same demonstrations: ``trajectory(goal=g, start=s,
    via=[(t, p)], dt=0.01)`` starts at s, passes p at t and ends at g (0.5 mm)."""
    _, demos, kinds = fitted_kinds(seed)
    rng = np.random.default_rng(100 + seed)
    start = demos[0][0] + rng.uniform(-10, 10, 3)
    goal = demos[0][-1] + rng.uniform(-15, 15, 3)
    when = 1.2  # a whole number of 10 ms steps: a sample
    point = at_mean(demos, when / 3.0) + rng.uniform(-8, 8, 3)
    for name, model in kinds.items():
        motion = model.trajectory(goal=goal, start=start, via=[(when, point)], dt=0.01)
        assert np.allclose(np.diff(motion.t), 0.01), name
        assert np.linalg.norm(motion.y[0] - start) <= 0.5, name
        assert np.linalg.norm(at(motion, when) - point) <= 0.5, name
        assert np.linalg.norm(motion.y[-1] - goal) <= 0.5, name
        # ... and with several via-points, each passed
        later = (2.0, at_mean(demos, 2.0 / 3.0) + rng.uniform(-5, 5, 3))
        motion = model.trajectory(goal=goal, start=start, via=[(when, point), later], dt=0.01)
        for t, p in ((when, point), later):
            assert np.linalg.norm(at(motion, t) - p) <= 0.5, (name, t)
        assert np.linalg.norm(motion.y[-1] - goal) <= 0.5, name


def at_mean(demos, share: float) -> np.ndarray:
    """The demonstrations' mean position at ``share`` of their samples."""
    index = int(round(share * (len(demos[0]) - 1)))
    return np.mean([demo[index] for demo in demos], axis=0)


@pytest.mark.parametrize("seed", [0, 3])
def test_motion_limits_cap_the_speed_of_every_kind(seed):
    """``limits=MotionLimits(max_velocity=v)``: the speed read from the positions by finite
    differences stays within v (to the difference's own error), and the motion is slowed, not
    cut: it still ends at its goal."""
    _, demos, kinds = fitted_kinds(seed)
    goal = demos[0][-1] + 5.0
    for name, model in kinds.items():
        free = model.trajectory(goal=goal, dt=0.005)
        free_speed = np.max(np.linalg.norm(np.diff(free.y, axis=0), axis=1) / 0.005)
        cap = 0.5 * free_speed
        capped = model.trajectory(goal=goal, dt=0.005, limits=MotionLimits(max_velocity=cap))
        speed = np.linalg.norm(np.diff(capped.y, axis=0), axis=1) / np.diff(capped.t)
        assert speed.max() <= cap * 1.01, name
        assert speed.max() >= cap * 0.9, name  # the cap binds: the shortest duration within it
        assert capped.duration >= 1.8 * free.duration, name
        assert np.linalg.norm(capped.y[-1] - goal) <= 0.5, name
        # the dict form is the same limits
        same = model.trajectory(goal=goal, dt=0.005, limits={"max_velocity": cap})
        np.testing.assert_allclose(same.y, capped.y, rtol=0, atol=1e-9)


def test_a_via_point_that_a_cap_breaks_is_refused_not_moved():
    _, demos, kinds = fitted_kinds(4)
    for name, model in kinds.items():
        free = model.trajectory(dt=0.01)
        cap = 0.3 * np.max(np.linalg.norm(free.yd, axis=1))
        with pytest.raises(ValueError, match="via"):
            model.trajectory(
                via=[(1.5, at(free, 1.5))], dt=0.01, limits=MotionLimits(max_velocity=cap)
            )
        assert name


def test_a_probabilistic_kind_answers_its_conditioned_mean():
    """The probabilistic kinds' trajectory is the mean of the model conditioned on the same
    points (their spread there is 0: they pass them exactly)."""
    _, demos, kinds = fitted_kinds(5)
    goal, when = demos[1][-1] + 3.0, 1.5
    point = at_mean(demos, 0.5) + 2.0
    for name in ("ProMP", "ProDMP"):
        model = kinds[name]
        assert isinstance(model, ProbabilisticPrimitive)
        conditioned = model.conditioned(goal=goal, via=[(when, point)])
        spread = conditioned.std(times=[when, model.duration_])
        assert np.all(spread <= 1e-5), name
        assert np.all(model.std(times=[when]) > 1e-3), name


@pytest.mark.parametrize("cls", [DMP, CartesianDMP, BiDMP, CartesianBiDMP, ProMP, ProDMP, MultiDMP])
def test_every_point_to_point_kind_spells_the_call_alike(cls):
    parameters = inspect.signature(cls.trajectory).parameters
    names = list(parameters)
    assert names[:2] == ["self", "goal"] and parameters["goal"].default is None
    for keyword in KEYWORDS:
        assert keyword in parameters, (cls.__name__, keyword)
        assert parameters[keyword].kind is inspect.Parameter.KEYWORD_ONLY
        assert parameters[keyword].default in (None, ()), (cls.__name__, keyword)


def test_the_fitted_kinds_are_motion_primitives_and_take_an_empty_via():
    t, demos, kinds = fitted_kinds(6)
    kinds["MultiDMP"] = MultiDMP(DMP(n_kernels=20)).fit(demos[:3], [t] * 3)
    kinds["BiDMP"] = BiDMP(DMP(n_kernels=20)).fit(demos[0])
    for name, model in kinds.items():
        assert isinstance(model, MotionPrimitive), name
        plain = model.trajectory(dt=0.01)
        empty = model.trajectory(dt=0.01, via=())
        np.testing.assert_array_equal(plain.y, empty.y, err_msg=name)


def test_a_pose_kind_refuses_a_start_velocity_in_one_line():
    t = np.linspace(0.0, 2.0, 201)
    position = minimum_jerk([[0, 0, 0], [100, 50, 20]], 201)
    angle = np.linspace(0.0, 0.8, 201)
    quaternion = np.column_stack(
        [np.zeros(201), np.zeros(201), np.sin(angle / 2), np.cos(angle / 2)]
    )
    model = CartesianDMP(DMP(n_kernels=20)).fit(np.hstack([position, quaternion]), t)
    with pytest.raises(
        ValueError, match=r"^start_velocity: a CartesianDMP's motion starts at rest"
    ):
        model.trajectory(start_velocity=np.ones(6))


@pytest.mark.parametrize(
    "kwargs, error, match",
    [
        ({}, ValueError, "at least one of max_velocity"),
        ({"max_velocity": -1.0}, ValueError, "positive and finite"),
        ({"max_velocity": np.nan}, ValueError, "positive and finite"),
        ({"max_velocity": "fast"}, TypeError, "max_velocity"),
        ({"max_velocity": [1.0, 2.0]}, ValueError, "norm='axis'"),
        ({"max_velocity": 1.0, "norm": "l2"}, ValueError, "norm must be"),
        ({"max_velocity": 1.0, "fastest": 1}, TypeError, "fastest"),
        ({"max_velocity": True}, TypeError, "max_velocity"),
    ],
)
def test_motion_limits_refuse_what_is_not_a_cap(kwargs, error, match):
    with pytest.raises(error, match=match):
        MotionLimits(**kwargs)


def test_motion_limits_round_trip_their_file_form():
    limits = MotionLimits(max_velocity=[1.0, 2.0, 3.0], max_jerk=50.0, norm="axis", fastest=True)
    assert MotionLimits.from_dict(limits.as_dict()) == limits
    with pytest.raises(ValueError, match="unknown key"):
        MotionLimits.from_dict({"max_speed": 1.0})
    assert bidmp.MotionLimits is MotionLimits
