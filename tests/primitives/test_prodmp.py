"""The ProDMP against independent references: the goal basis' closed form, the weights' basis as
the system's Green's function convolved with the forcing (SciPy's adaptive quadrature), the
system's equation by finite differences, exact boundary conditions and via-points, and the
convergence to the goal. (Batched rollouts against single ones guard structure: the same code's
two paths.)"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import quad
from sklearn.base import clone

from bidmp.demonstrations import minimum_jerk
from bidmp.primitives.prodmp import ProDMP, prodmp_basis


def demo(n: int = 601, duration: float = 3.0, offset=(0.0, 0.0, 0.0)):
    t = np.linspace(0.0, duration, n)
    y = minimum_jerk([[0.0, 0.0, 0.0], [30.0, -20.0, 10.0], [50.0, 10.0, 40.0]], n)
    return t, y + np.asarray(offset)


def test_the_goal_basis_is_the_closed_form_step_response():
    basis = prodmp_basis(8, tau=2.0, alpha=20.0, dt=0.004)
    s = np.arange(basis.position.shape[0]) * basis.scaled_step
    closed = 1.0 - (1.0 + 10.0 * s) * np.exp(-10.0 * s)
    assert np.max(np.abs(basis.position[:, -1] - closed)) <= 1e-12
    assert np.max(np.abs(basis.velocity[:, -1] - 100.0 * s * np.exp(-10.0 * s))) <= 1e-10


@pytest.mark.parametrize("index", [0, 4, 9])
def test_the_weight_basis_is_the_greens_function_of_the_forcing(index):
    """Φ_i(s) = ∫₀ˢ (s - r) e^(-α (s - r) / 2) x(r) φ_i(r) dr, by SciPy's adaptive quadrature;
    the trapezoid's error falls at least 8-fold when its step is 4-fold finer (it is about
    h² (α/2)² / 12 of the basis' peak, with h = dt / tau: 1.3e-5 at h = 0.001)."""
    errors = []
    for dt in (0.004, 0.001):
        basis = prodmp_basis(10, tau=1.0, dt=dt)
        worst = 0.0
        for s_value in (0.2, 0.55, 1.0, 2.0):

            def integrand(r, s_value=s_value):
                forcing = basis.forcing(np.array([r]))[0, index] * np.exp(-3.0 * r)
                return (s_value - r) * np.exp(-12.5 * (s_value - r)) * forcing

            reference = quad(integrand, 0.0, s_value, limit=400, epsabs=1e-15)[0]
            value = basis._read(basis.position, np.array([s_value]))[0, index]
            worst = max(worst, abs(value - reference))
        errors.append(worst / np.abs(basis.position[:, index]).max())
    assert errors[1] <= 3e-5 and errors[1] <= errors[0] / 8.0


@pytest.mark.parametrize("alpha_phase", [1e-6, 0.05, 3.0])
def test_the_forcing_basis_is_a_softmax_even_where_every_kernel_underflows(alpha_phase):
    """Independent reference: SciPy's softmax of the kernels' exponents (log-sum-exp). A slow phase
    leaves late samples so far from every kernel that each one underflows to 0; the basis there is
    still the normalised one (it was 0/0), and the precomputed basis stays finite."""
    from scipy.special import softmax

    basis = prodmp_basis(8, alpha_phase=alpha_phase, dt=0.01)
    times = np.linspace(0.0, 5.9, 300)
    phase = basis.phase(times)[:, None]
    exponent = -0.5 * (phase - basis.centres[None, :]) ** 2 * basis.widths[None, :]
    np.testing.assert_allclose(basis.forcing(times), softmax(exponent, axis=1), rtol=0, atol=1e-12)
    assert np.all(np.isfinite(basis.position)) and np.all(np.isfinite(basis.velocity))


def test_a_trajectory_keeps_its_boundary_and_obeys_its_equation():
    """From any start and start velocity: y(0) and ẏ(0) exactly; the velocity is the positions'
    derivative and the acceleration the velocity's (central differences, fine grid); the
    acceleration is what the spring, the damper and the forcing give."""
    t, y = demo()
    model = ProDMP(n_basis=12, dt=0.0005).fit(y, [t])
    rng = np.random.default_rng(3)
    for _ in range(3):
        start, velocity = rng.normal(0, 20, 3), rng.normal(0, 30, 3)
        times = np.linspace(0.0, 3.0, 3001)
        motion = model.trajectory(start, start_velocity=velocity, times=times)
        assert np.allclose(motion.y[0], start, atol=1e-9)
        assert np.allclose(motion.yd[0], velocity, atol=1e-7)
        extent = np.ptp(motion.y, axis=0).max()
        numeric_velocity = np.gradient(motion.y, times, axis=0)[2:-2]
        assert np.max(np.abs(numeric_velocity - motion.yd[2:-2])) <= 2e-3 * extent / 0.1
        numeric_acceleration = np.gradient(motion.yd, times, axis=0)[2:-2]
        scale = np.abs(motion.ydd).max()
        assert np.max(np.abs(numeric_acceleration - motion.ydd[2:-2])) <= 0.01 * scale


def test_it_reproduces_its_demonstration_and_ends_at_the_goal():
    t, y = demo()
    model = ProDMP(n_basis=20).fit(y, [t])
    motion = model.trajectory(y[0], times=t)
    extent = np.ptp(y, axis=0).max()
    assert np.max(np.abs(motion.y - y)) <= 1e-3 * extent
    goal = np.array([80.0, -15.0, 5.0])
    late = model.trajectory(y[0], goal, times=np.array([0.0, 5.0 * 3.0]))
    assert np.allclose(late.y[-1], goal, atol=1e-4 * extent)


def test_batched_rollouts_are_the_single_trajectories():
    """(Structure: the batch path and the single path of the same code.)"""
    t, y = demo()
    model = ProDMP().fit(y, [t])
    rng = np.random.default_rng(5)
    starts, goals = rng.normal(0, 10, (6, 3)), rng.normal(40, 10, (6, 3))
    batch = model.rollouts(starts, goals, times=t)
    for b in range(6):
        single = model.trajectory(starts[b], goals[b], times=t).y
        assert np.allclose(batch[b], single, rtol=0, atol=1e-10)


def test_conditioning_passes_the_via_point_and_keeps_the_start():
    """Several demonstrations that rise by as much on the way as at their end: the conditioned
    mean passes a via-point (to 1e-6 of the extent) and still starts where it is told;
    conditioned on a goal 10 higher it ends there and passes about 7 higher half-way (the
    demonstrations' sin(pi/4) of it), where only replacing the goal passes about 10 higher."""
    rng = np.random.default_rng(7)
    demos, times = [], []
    for _ in range(8):
        t, y = demo()
        lift = rng.normal(0.0, 8.0)
        y = y + lift * np.sin(0.5 * np.pi * t / 3.0)[:, None] * np.array([0.0, 0.0, 1.0])
        demos.append(y)
        times.append(t)
    model = ProDMP(n_basis=15, cov_reg=1e-6).fit(demos, times)
    start = demos[0][0]
    via = model.trajectory(start, times=[1.5]).y[0] + [0.0, 0.0, 6.0]
    conditioned = model.condition([1.5], via[None], 0.0, start=start)
    passed = conditioned.trajectory(start, times=[0.0, 1.5])
    assert np.allclose(passed.y[1], via, atol=1e-6 * 60.0)
    assert np.allclose(passed.y[0], start, atol=1e-9)
    goal = model.weight_mean_.reshape(3, -1)[:, -1]
    goals = np.array([goal, goal + [0.0, 0.0, 10.0]])
    moved = model.rollouts(start[None], goals, times=[1.5, 15.0], conditioned=True)
    assert np.allclose(moved[:, -1], goals, atol=1e-4)  # the goal is the attractor, 5 tau on
    assert 5.0 < moved[1, 0, 2] - moved[0, 0, 2] < 9.0
    replaced = model.rollouts(start[None], goals, times=[1.5])
    assert replaced[1, 0, 2] - replaced[0, 0, 2] > 9.5


def test_the_goal_for_an_end_ends_there():
    t, y = demo()
    model = ProDMP().fit(y, [t])
    end = y[-1] + [5.0, -4.0, 3.0]
    attractor = model.goal_for_end(end, y[0])
    assert np.allclose(model.trajectory(y[0], attractor, times=[0.0, 3.0]).y[-1], end, atol=1e-9)


def test_it_is_a_scikit_learn_estimator_and_refuses_bad_input_by_name():
    model = ProDMP(n_basis=7, alpha=20.0)
    assert clone(model).get_params()["n_basis"] == 7
    t, y = demo()
    with pytest.raises(ValueError, match="n_basis"):
        ProDMP(n_basis=0).fit(y, [t])
    with pytest.raises(ValueError, match="length_factor"):
        ProDMP(length_factor=8.0).fit(y, [t])
    with pytest.raises(ValueError, match="times"):
        ProDMP().fit(y, [t[::-1]])
    fitted = ProDMP().fit(y, [t])
    with pytest.raises(ValueError, match="beyond"):
        fitted.trajectory(y[0], times=[0.0, 30.0])
    with pytest.raises(ValueError, match="one per rollout"):
        fitted.rollouts(np.zeros((2, 3)), np.zeros((3, 3)))


def test_a_model_file_gives_the_same_motions(tmp_path):
    from bidmp.io import load_model, save_model

    t, y = demo()
    model = ProDMP(n_basis=12, alpha_phase=2.0).fit([y, y + 1.0], [t, t], units="mm")
    loaded = load_model(save_model(model, tmp_path / "prodmp"))
    assert isinstance(loaded, ProDMP) and loaded.units_ == "mm"
    times = np.linspace(0.0, 3.0, 50)
    for a, b in ((model.trajectory(times=times), loaded.trajectory(times=times)),):
        assert np.array_equal(a.y, b.y) and np.array_equal(a.yd, b.yd)


def test_the_default_start_is_the_mean_start_point_in_every_call():
    """A start with three different coordinates: conditioning kept only its first (every
    coordinate of the conditioned model's start was 5.03), goal_for_end read it so (the end
    4e-4 off), and rollouts() without starts refused itself."""
    t, y = demo(offset=(5.0, -3.0, 2.0))
    model = ProDMP(n_basis=8).fit([y, y * 1.05, y * 0.97], [t] * 3)
    conditioned = model.condition([1.5], y[300][None], 0.0)
    np.testing.assert_array_equal(conditioned.start_, model.start_)
    np.testing.assert_allclose(conditioned.rollout()[0], model.start_, rtol=0, atol=1e-12)
    wanted = y[-1] + np.array([1.0, -2.0, 0.5])
    end = model.rollout(goal=model.goal_for_end(wanted))[-1]
    np.testing.assert_allclose(end, wanted, rtol=0, atol=1e-9 * np.abs(wanted).max())
    np.testing.assert_array_equal(model.rollouts()[0], model.rollout())


@pytest.mark.parametrize(
    "call, error, match",
    [
        (lambda m, y: m.condition([0.0], y[[10]], 0.0), ValueError, "times must be > 0"),
        (
            lambda m, y: m.condition([1.0, 1.0], y[[10, 20]], 0.0),
            ValueError,
            "times: the via-point 0 .at 1 s. and the via-point 1",
        ),
        (lambda m, y: m.rollout(start=y[:2]), ValueError, "start must be one point"),
        (
            lambda m, y: m.condition([1.0], y[[10]], 0.0, start=y[:2]),
            ValueError,
            "start must be one",
        ),
        (lambda m, y: m.rollout(n_steps=2**40), ValueError, "n_steps .* exceeds the limit"),
        (
            lambda m, y: m.rollouts(goals=y[-1:], conditioned="yes"),
            TypeError,
            "conditioned must be",
        ),
        (
            lambda m, y: m.rollouts(starts=y[:4], goals=y[-3:]),
            ValueError,
            r"got starts \(4, 3\), start_velocities \(1, 3\), goals \(3, 3\)",
        ),
        (
            lambda m, y: m.rollouts(goals=np.broadcast_to(y[-1], (2_000_000, 3))),
            ValueError,
            "the rollouts .2000000 starts or goals",
        ),
    ],
)
def test_a_bad_request_is_refused_by_name(call, error, match):
    """What the surface sweep found: each was a raw NumPy error, a LinAlgError or 8 TiB asked for."""
    t, y = demo()
    model = ProDMP(n_basis=8).fit([y, y * 1.05, y * 0.97], [t] * 3)
    with pytest.raises(error, match=match):
        call(model, y)


def test_start_velocities_are_one_or_one_per_rollout_and_say_the_shape_otherwise():
    """Two start velocities from the one mean start are two rollouts (each the single
    trajectory); three velocities for two starts are refused naming every argument's shape, not
    in NumPy's broadcast words."""
    t, y = demo()
    model = ProDMP(n_basis=8).fit([y, y * 1.05, y * 0.97], [t] * 3)
    velocities = np.array([[10.0, -5.0, 2.0], [-3.0, 0.0, 8.0]])
    batch = model.rollouts(start_velocities=velocities, times=t)
    for b in range(2):
        single = model.trajectory(start_velocity=velocities[b], times=t).y
        np.testing.assert_allclose(batch[b], single, rtol=0, atol=1e-10)
    with pytest.raises(ValueError) as caught:
        model.rollouts(starts=y[:2], start_velocities=np.ones((3, 3)))
    message = str(caught.value)
    assert "\n" not in message and "broadcast" not in message
    assert "shape (1, 3) or (B, 3)" in message and "start_velocities (3, 3)" in message
    with pytest.raises(ValueError, match=r"^start_velocity must be one point \(3,\)"):
        model.trajectory(start_velocity=velocities)


def test_a_via_point_given_twice_is_once_and_two_at_one_time_conflict():
    t, y = demo()
    model = ProDMP(n_basis=8).fit([y, y * 1.05, y * 0.97], [t] * 3)
    start, via = y[0], y[300] + [1.0, -2.0, 3.0]
    twice = model.condition([1.5, 1.5], np.stack([via, via]), 0.0, start=start)
    once = model.condition([1.5], via[None], 0.0, start=start)
    np.testing.assert_allclose(twice.weight_mean_, once.weight_mean_, rtol=1e-7, atol=1e-7)
    with pytest.raises(
        ValueError, match=r"^times: the via-point 0 \(at 1.5 s\) and the via-point 1"
    ):
        model.condition([1.5, 1.5], np.stack([via, via + 1.0]), 0.0, start=start)


def test_conditioned_on_the_goal_at_rest_it_ends_there_still_and_stays():
    """condition(times, values, rest=[T], goal=g) with the end among the points: the motion
    passes the via-points, ends at g at T with velocity and acceleration 0 (finite differences
    of its positions, an independent judge), its goal weight is g, and after T it stays near g
    (the attractor; the forcing still fades)."""
    t, y = demo()
    rng = np.random.default_rng(11)
    demos = [y + rng.normal(0.0, 3.0, 3) * np.sin(np.pi * t / 3.0)[:, None] for _ in range(5)]
    model = ProDMP(n_basis=12).fit(demos, [t] * 5)
    goal, via = y[-1] + [6.0, -4.0, 5.0], y[200] + [3.0, 2.0, -2.0]
    end = model.duration_
    conditioned = model.condition(
        [1.0, end], np.stack([via, goal]), 0.0, start=y[0], rest=[end], goal=goal
    )
    np.testing.assert_allclose(conditioned.weight_mean_.reshape(3, -1)[:, -1], goal, atol=1e-9)
    h = 1e-4
    near = conditioned.trajectory(y[0], times=[1.0, end - 2 * h, end - h, end]).y
    np.testing.assert_allclose(near[0], via, atol=1e-6)
    near = near[1:]
    np.testing.assert_allclose(near[2], goal, atol=1e-6)
    slope = (3 * near[2] - 4 * near[1] + near[0]) / (2 * h)
    curvature = (near[2] - 2 * near[1] + near[0]) / h**2
    # (the basis is read linearly between its grid points: differences within one are exact)
    assert np.abs(slope).max() <= 1e-3 and np.abs(curvature).max() <= 1.0
    later = conditioned.trajectory(y[0], times=np.linspace(end, 2 * end, 50)).y
    assert np.abs(later - goal).max() <= 0.5  # (the forcing fades: 0.13 mm over tau more)
