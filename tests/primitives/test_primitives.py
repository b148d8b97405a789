"""The primitives core: the step integrator against the fast path, coupling terms
against closed forms, goal systems as objects.

Which checks show correctness and which guard structure:
- the constant push is checked against the closed-form response of a critically damped spring
  (an independent reference, not the code under test);
- the step integrator against the fast path compares two integrations that share the goal
  system and the forcing term but not their recursion (lfilter and outer products vs one
  state-space step at a time): a structural guard that also catches a wrong coupling hook;
- goal-system and coupling-term plumbing tests are structural.
"""

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bidmp
from bidmp.demonstrations import minimum_jerk, recording
from bidmp.primitives.coupling import ConstantAcceleration, PhaseStopping, _as_couplings
from bidmp.primitives.goals import DelayedGoal, PhaseGate, ProgressGate

RELATIVE = 1e-9  # of each quantity's own peak over the motion


def random_demo(rng, n_dims=3, n_steps=None):
    """A minimum-jerk demonstration through random via points (mm), at a random length."""
    n_steps = int(rng.integers(60, 400)) if n_steps is None else n_steps
    via = np.cumsum(rng.normal(scale=60.0, size=(int(rng.integers(2, 5)), n_dims)), axis=0)
    return minimum_jerk(via, n_steps=n_steps)


def assert_same_motion(fast, stepped):
    assert len(fast.t) == len(stepped.t)
    np.testing.assert_allclose(stepped.t, fast.t, rtol=0, atol=1e-12)
    for name in ("y", "yd", "ydd"):
        a, b = getattr(fast, name), getattr(stepped, name)
        peak = max(np.max(np.abs(a)), 1e-300)
        assert np.max(np.abs(a - b)) <= RELATIVE * peak, (name, np.max(np.abs(a - b)) / peak)


@pytest.mark.parametrize("protocol", ["robot", "paper"])
@pytest.mark.parametrize("seed", range(4))
def test_the_step_integrator_equals_the_fast_path_for_a_dmp(protocol, seed):
    rng = np.random.default_rng(seed)
    y = random_demo(rng)
    rate = float(rng.choice([100.0, 250.0, 500.0]))
    dmp = bidmp.DMP(protocol=protocol).fit(y, np.arange(len(y)) / rate, units="mm")
    shift = rng.normal(scale=40.0, size=3)
    queries = [
        {},
        {"goal": dmp.goal_ + shift, "start": dmp.start_ - 0.3 * shift},
        {"goal": dmp.goal_ + shift, "duration": 1.7 * dmp.duration_, "dt": 1e-3},
    ]
    for query in queries:
        assert_same_motion(dmp.trajectory(**query), dmp.trajectory(**query, coupling=[]))


def recording_bidmp():
    """(DMP, Bi-DMP with one skill, its target): operator 1's recording, a goal 134 mm away."""
    y, t = recording("operator1_nut3")
    prepared, _ = bidmp.prepare(y, t, units="mm")
    dmp = bidmp.DMP().fit(prepared.y, prepared.t, units="mm")
    target = dmp.goal_ + np.array([120.0, -60.0, 0.0])
    model = bidmp.BiDMP(dmp, increments=(10,))
    model.learn(bidmp.extend_demonstration(prepared.y, target, seed=0).complete)
    return dmp, model, target


def test_the_step_integrator_equals_the_fast_path_for_a_bidmp():
    dmp, model, target = recording_bidmp()
    for goal in (target, target + [10.0, 5.0, 0.0], dmp.goal_):
        assert_same_motion(model.trajectory(goal), model.trajectory(goal, coupling=[]))


def test_the_step_integrator_equals_the_fast_path_for_a_cartesian_dmp():
    positions = minimum_jerk(np.array([[0.0, 0, 100], [80, 20, 40], [150, 25, 0]]), n_steps=200)
    s = np.linspace(0.0, 1.0, 200)
    turn = Rotation.from_rotvec(np.outer(10 * s**3 - 15 * s**4 + 6 * s**5, [0.3, -0.8, 1.2]))
    poses = np.hstack([positions, (turn * Rotation.from_euler("x", 180, degrees=True)).as_quat()])
    model = bidmp.CartesianDMP().fit(poses, np.linspace(0.0, 2.0, 200), units="mm")
    goal = poses[-1].copy()
    goal[:3] += [30.0, -20.0, 10.0]
    goal[3:] = (Rotation.from_euler("z", 40, degrees=True) * Rotation.from_quat(goal[3:])).as_quat()
    fast, stepped = model.trajectory(goal), model.trajectory(goal, coupling=[])
    assert_same_motion(fast, stepped)
    for name, share in (("q", RELATIVE), ("omega", RELATIVE), ("omega_dot", 10 * RELATIVE)):
        # omega_dot differentiates the left Jacobian by a forward difference of step 1e-7: the
        # inputs' rounding (1e-16) comes out ~1e7 larger, at 1e-9 of the peak (the two paths sum
        # the same terms in another order).
        a, b = getattr(fast, name), getattr(stepped, name)
        assert np.max(np.abs(a - b)) <= share * max(np.max(np.abs(a)), 1.0), name


@pytest.mark.parametrize("tau", [1.0, 2.5])
def test_a_constant_push_moves_the_motion_by_the_closed_form(tau):
    """A constant acceleration a added to a critically damped spring (beta = alpha / 4) moves it by
    a (tau T)² / (αβ) (1 - (1 + ω t) e^{-ω t}), ω = α / (2 tau T), T the seconds per normalised time."""
    rng = np.random.default_rng(7)
    y = random_demo(rng, n_steps=250)
    dmp = bidmp.DMP(tau=tau).fit(y, np.arange(250) / 250.0, units="mm")
    push = np.array([2000.0, -800.0, 150.0])  # mm/s²
    free = dmp.trajectory(dt=2e-3, coupling=[])
    pushed = dmp.trajectory(dt=2e-3, coupling=[ConstantAcceleration(push)])
    params = dmp.settings()
    unit = dmp.time_unit_
    omega = params.alpha / (2.0 * tau * unit)
    shape = 1.0 - (1.0 + omega * free.t) * np.exp(-omega * free.t)
    expected = np.outer(shape, push * (tau * unit) ** 2 / (params.alpha * params.beta))
    moved = pushed.y - free.y
    assert np.max(np.abs(expected)) > 1.0  # the push moves the motion by millimetres...
    np.testing.assert_allclose(
        moved, expected, rtol=0, atol=1e-9 * np.max(np.abs(expected))
    )  # ...exactly as predicted
    # The reported acceleration includes the push: a at the first sample, where the spring is at rest.
    np.testing.assert_allclose(pushed.ydd[0] - free.ydd[0], push, rtol=1e-9)


def test_a_coupling_term_sees_the_commanded_state():
    rng = np.random.default_rng(3)
    y = random_demo(rng)
    dmp = bidmp.DMP().fit(y, np.arange(len(y)) / 200.0)
    seen = []

    def record(t, position, velocity, phase):
        seen.append((t, position.copy(), velocity.copy(), phase))
        return np.zeros_like(position)

    motion = dmp.trajectory(coupling=[record])
    assert len(seen) == len(motion.t)
    np.testing.assert_allclose([s[0] for s in seen], motion.t, atol=1e-12)
    np.testing.assert_allclose(np.array([s[1] for s in seen]), motion.y, atol=1e-12)
    np.testing.assert_allclose(np.array([s[2] for s in seen]), motion.yd, atol=1e-12)
    phases = np.array([s[3] for s in seen])
    np.testing.assert_allclose(
        phases, np.exp(-dmp.settings().alpha_phase * motion.t / dmp.time_unit_), rtol=1e-12
    )


def test_phase_stopping_is_a_coupling_term_and_a_number_still_means_its_gain():
    y = minimum_jerk(np.array([[0.0, 0.0], [50.0, 20.0], [100.0, 0.0]]), n_steps=150)
    dmp = bidmp.DMP().fit(y, np.arange(150) / 150.0)
    by_number, by_term = dmp.stepper(coupling=0.5), dmp.stepper(coupling=[PhaseStopping(0.5)])
    held = dmp.start_.copy()
    for _ in range(40):  # the robot is held at the start: both pause the same way
        a, b = by_number.step(0.01, held), by_term.step(0.01, held)
        np.testing.assert_array_equal(a[0], b[0])
    assert by_number.coupling == by_term.coupling == 0.5
    assert (
        by_number.time < 0.2
    )  # paused: 40 controller steps (0.4 s of control time), far less motion time


def test_coupling_input_is_checked():
    with pytest.raises(TypeError, match="coupling"):
        _as_couplings("push")
    with pytest.raises(TypeError, match="callable"):
        _as_couplings([1.0])
    with pytest.raises(ValueError, match="coupling"):
        _as_couplings(-1.0)
    dmp = bidmp.DMP().fit(minimum_jerk(np.array([[0.0], [1.0]]), n_steps=50))
    with pytest.raises(ValueError, match="non-finite"):
        dmp.trajectory(coupling=[lambda t, y, yd, phase: np.full_like(y, np.inf)])


def test_the_goal_systems_each_protocol_composes():
    y = minimum_jerk(np.array([[0.0, 0.0], [40.0, 10.0], [100.0, 0.0]]), n_steps=120)
    robot, paper = bidmp.DMP().fit(y), bidmp.DMP(protocol="paper").fit(y)
    delayed = bidmp.DMP(goal_rate=3.0).fit(y)
    assert isinstance(robot.goal_system(), ProgressGate)
    assert type(paper.goal_system()) is PhaseGate
    assert type(delayed.goal_system()) is DelayedGoal and delayed.goal_system().rate == 3.0
    # Each gate starts at 1 (the goal's share of the input is 0 at the start) and decays.
    for model in (robot, paper, delayed):
        gate = model.training_gate()
        assert gate[0] == pytest.approx(1.0, abs=1e-9) and gate[-1] < 0.5
    # A delayed goal at the phase's own rate is Eq. 10's phase gate.
    phase = paper.phase()
    np.testing.assert_allclose(
        DelayedGoal(1.0).on_grid(phase, paper.dt_, 1.0, False), phase, rtol=1e-12
    )


def test_rollouts_to_many_goals_as_one_matrix_product_are_the_same_numbers():
    """From GEMM_GOALS goals on, rollout_many is one matrix product: every entry is g B + free with
    exact zeros elsewhere, so it must equal the per-goal rollout to the last bit."""
    from bidmp.primitives.integrate import GEMM_GOALS

    rng = np.random.default_rng(5)
    dmp = bidmp.DMP().fit(random_demo(rng, n_steps=200))
    goals = dmp.goal_ + rng.normal(scale=50.0, size=(GEMM_GOALS + 7, 3))
    many = dmp.rollout_many(goals)
    looped = np.stack([dmp.rollout(goal) for goal in goals])
    np.testing.assert_array_equal(many, looped)
    out = np.full_like(many, np.nan)
    assert dmp.rollout_many(goals, out=out) is out
    np.testing.assert_array_equal(out, looped)


def test_a_skill_increment_is_computed_once_per_grid(monkeypatch):
    dmp, model, target = recording_bidmp()
    goals = target + np.random.default_rng(0).normal(scale=5.0, size=(6, 3))
    calls = []
    original = type(model.blocks_[0]).predict
    monkeypatch.setattr(
        type(model.blocks_[0]), "predict", lambda self, X: calls.append(len(X)) or original(self, X)
    )
    rollouts = [model.rollout(goal, skill=1) for goal in goals]
    assert len(calls) == 1  # six goals, one increment
    model.__dict__.pop("_increments")  # without the cache: the same motions
    np.testing.assert_array_equal(
        np.stack(rollouts), np.stack([model.rollout(goal, skill=1) for goal in goals])
    )
    assert len(calls) == 2
