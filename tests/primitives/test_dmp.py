"""DMP: checked against a plain Euler loop, closed-form properties and movement_primitives."""

import numpy as np
import pytest
from conftest import curved_demo, minimum_jerk

from bidmp import DMP, NotFittedError
from bidmp.demonstrations import lasa
from bidmp.primitives import basis_functions, kernel_centres, kernel_widths, phase_grid
from bidmp.primitives.forcing import _forcing_target as forcing_target


def euler_reference(dmp, goal, start, n_steps, start_velocity=None):
    """Slow, literal explicit-Euler integration of Eq. 10-11 (independent of the lfilter path)."""
    goal = np.asarray(goal, float)
    start = np.asarray(start, float)
    h = dmp.dt_ / dmp.tau
    y = start.copy()
    z = dmp.tau * (
        np.zeros_like(start) if start_velocity is None else np.asarray(start_velocity, float)
    )
    phase = 1.0
    out = []
    for _ in range(n_steps):
        out.append(y.copy())
        exponent = -dmp.widths_ * (phase - dmp.centres_) ** 2
        psi = np.exp(exponent - exponent.max())  # same ratio, no 0/0 far outside the kernels
        f = phase * (psi @ dmp.weights_) / psi.sum()
        acceleration = (
            dmp.alpha_value * (dmp.beta_value * (goal - y) - z)
            + dmp.K_value * f
            - dmp.K_value * phase * (goal - start)
        )
        y, z = y + h * z, z + h * acceleration
        phase *= 1.0 - dmp.alpha_phase_value * dmp.dt_ / dmp.tau
    return np.array(out)


def rel_rmse(a, b):
    return np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1))) / np.linalg.norm(np.ptp(b, axis=0))


# --- correctness against an independent integration -----------------------------------------
@pytest.mark.parametrize(
    "params",
    [
        {},
        {"K": "pastor"},
        {"alpha": 100.0, "tau": 1.7},
        {"alpha": 40.0, "beta": 3.0, "alpha_phase": 3.0, "regression": "ridge"},
        {"K": 12.5, "n_kernels": 7, "widths": "pydmps"},
    ],
)
def test_rollout_equals_plain_euler_loop(params, demo3d):
    dmp = DMP(protocol="paper", **params).fit(demo3d)
    rng = np.random.default_rng(3)
    goal, start, velocity = rng.normal(size=(3, 3))
    for n_steps in (1, 2, 3, 50, dmp.n_steps_, 3 * dmp.n_steps_):
        fast = dmp.rollout(goal, start=start, n_steps=n_steps, start_velocity=velocity)
        slow = euler_reference(dmp, goal, start, n_steps, velocity)
        assert fast.shape == (n_steps, 3)
        np.testing.assert_allclose(fast, slow, rtol=0, atol=1e-9 * (1 + np.abs(slow).max()))


def test_default_rollout_starts_at_demo_and_uses_its_goal(demo3d):
    dmp = DMP(protocol="paper").fit(demo3d)
    y = dmp.rollout()
    assert y.shape == demo3d.shape
    np.testing.assert_array_equal(y[0], demo3d[0])
    np.testing.assert_array_equal(dmp.rollout(goal=demo3d[-1], start=demo3d[0]), y)


@pytest.mark.parametrize("name", ["Sshape", "WShape", "NShape", "GShape", "Angle", "heee"])
def test_lasa_reproduction_below_one_percent(name):
    demos = lasa(name)
    # Demonstration 0 of these shapes starts at rest: a rollout from rest reproduces it.
    assert rel_rmse(DMP(protocol="paper").fit(demos[0]).rollout(), demos[0]) < 0.01
    # Some LASA recordings start in motion; given their first velocity, all seven reproduce.
    for demo in demos:
        start_velocity = (demo[1] - demo[0]) * len(demo)
        assert (
            rel_rmse(DMP(protocol="paper").fit(demo).rollout(start_velocity=start_velocity), demo)
            < 0.01
        )


def test_ridge_fit_reproduces_better_than_lwr_on_lasa():
    demo = lasa("Sshape")[0]
    lwr = rel_rmse(DMP(protocol="paper", regression="lwr").fit(demo).rollout(), demo)
    ridge = rel_rmse(DMP(protocol="paper", regression="ridge").fit(demo).rollout(), demo)
    assert ridge < lwr < 0.01


def test_forward_differences_reproduce_almost_exactly_with_enough_kernels():
    demo = minimum_jerk([0, 0], [1, 2], 100)
    dmp = DMP(
        protocol="paper", n_kernels=100, regression="ridge", derivatives="forward", ridge=1e-12
    ).fit(demo)
    assert rel_rmse(dmp.rollout(), demo) < 1e-4


def test_works_for_any_dimension():
    for n_dims in (1, 2, 5):
        demo = curved_demo(200, n_dims, seed=n_dims)
        dmp = DMP(protocol="paper").fit(demo)
        assert dmp.rollout().shape == (200, n_dims)
        assert rel_rmse(dmp.rollout(), demo) < 0.01


# --- affine structure, rollout_many, end-point gain -------------------------------------------
def test_rollout_is_affine_in_goal_and_start(demo2d):
    dmp = DMP(protocol="paper").fit(demo2d)
    rng = np.random.default_rng(0)
    g1, g2, s1, s2 = rng.normal(size=(4, 2))
    lam = 0.3
    mixed = dmp.rollout(lam * g1 + (1 - lam) * g2, start=lam * s1 + (1 - lam) * s2)
    np.testing.assert_allclose(
        mixed, lam * dmp.rollout(g1, start=s1) + (1 - lam) * dmp.rollout(g2, start=s2), atol=1e-12
    )


@pytest.mark.parametrize("n_steps", [None, 37, 2000])
def test_rollout_many_equals_looped_rollout(demo3d, n_steps):
    dmp = DMP(protocol="paper", alpha=60.0).fit(demo3d)
    rng = np.random.default_rng(1)
    goals = rng.normal(scale=2.0, size=(25, 3))
    start = rng.normal(size=3)
    many = dmp.rollout_many(goals, start=start, n_steps=n_steps)
    looped = np.stack([dmp.rollout(g, start=start, n_steps=n_steps) for g in goals])
    assert many.shape == looped.shape
    np.testing.assert_allclose(many, looped, rtol=0, atol=1e-9)


def scalar_goal_response(alpha, beta, K, alpha_phase, tau, dt, n_steps):
    """y[n_steps-1] of the 1-D system with f = 0, y0 = 0, g = 1, integrated by a scalar loop."""
    y, z, phase = 0.0, 0.0, 1.0
    h = dt / tau
    for _ in range(n_steps - 1):
        acceleration = alpha * (beta * (1.0 - y) - z) - K * phase * 1.0
        y, z = y + h * z, z + h * acceleration
        phase *= 1.0 - alpha_phase * dt / tau
    return y


@pytest.mark.parametrize(
    "alpha, K", [(25.0, "paper"), (100.0, "paper"), (25.0, "pastor"), (50.0, 10.0)]
)
def test_endpoint_gain_matches_scalar_recursion_and_rollout(alpha, K):
    demo = curved_demo(200, 3, seed=5)
    dmp = DMP(protocol="paper", alpha=alpha, K=K).fit(demo)
    c = dmp.endpoint_gain()
    expected = abs(
        1.0 - scalar_goal_response(alpha, dmp.beta_value, dmp.K_value, 1.0, 1.0, 1 / 200, 200)
    )
    assert c == pytest.approx(expected, rel=1e-9)
    # Measured by rollouts: the change of the final error per unit goal shift.
    shift = np.array([3.0, -4.0, 12.0])
    base_error = dmp.rollout()[-1] - dmp.goal_
    moved_error = dmp.rollout(dmp.goal_ + shift)[-1] - (dmp.goal_ + shift)
    assert np.linalg.norm(moved_error - base_error) / np.linalg.norm(shift) == pytest.approx(
        c, rel=1e-8
    )


def test_endpoint_gain_spec_values_and_convergence():
    # The paper's settings: T = 200, alpha_phase = 1, K = alpha: c = 0.0695 at alpha = 25, 0.0153 at alpha = 100.
    demo = minimum_jerk([0.0], [1.0], 200)
    assert DMP(protocol="paper", alpha=25.0).fit(demo).endpoint_gain() == pytest.approx(
        0.0695, abs=5e-4
    )
    assert DMP(protocol="paper", alpha=100.0).fit(demo).endpoint_gain() == pytest.approx(
        0.0153, abs=2e-4
    )
    dmp = DMP(protocol="paper", alpha=25.0).fit(demo)
    gains = [dmp.endpoint_gain(n) for n in (200, 400, 1000, 4000)]
    assert all(a > b for a, b in zip(gains, gains[1:]))
    assert gains[-1] < 1e-4
    # A faster phase (phase(T) ~ 0.01) shrinks c too.
    assert (
        DMP(protocol="paper", alpha=25.0, alpha_phase=4.6).fit(demo).endpoint_gain()
        < 0.5 * gains[0]
    )


def test_far_goal_error_is_gain_times_shift_when_goal_reached_exactly():
    # Fit with forward differences and many kernels so the demonstrated goal is hit almost exactly.
    demo = minimum_jerk([0.0, 0.0, 0.0], [0.0, 0.0, -1.0], 200)
    dmp = DMP(
        protocol="paper",
        alpha=100.0,
        n_kernels=200,
        regression="ridge",
        derivatives="forward",
        ridge=1e-12,
    ).fit(demo)
    shift = np.array([150.0, 25.0, 0.0])
    error = np.linalg.norm(dmp.rollout(dmp.goal_ + shift)[-1] - (dmp.goal_ + shift))
    assert error == pytest.approx(dmp.endpoint_gain() * np.linalg.norm(shift), rel=1e-3)


# --- kernels and the phase grid ----------------------------------------------------------------
@pytest.mark.parametrize("n_steps", [3, 4, 10, 57, 1000, 20000])
def test_kernels_stay_inside_visited_phase_and_weights_stay_bounded(n_steps):
    demo = (
        curved_demo(n_steps, 2, seed=2) if n_steps >= 10 else minimum_jerk([0, 0], [1, 1], n_steps)
    )
    # Explicit Euler with dt = 1/T needs alpha/T < 4: for T = 3 or 4 samples alpha = 25 diverges
    # (and is refused, see test_unstable_euler_settings_are_refused), so those use alpha = 8.
    alpha = 25.0 if n_steps >= 10 else 8.0
    for fit in ("lwr", "ridge"):
        dmp = DMP(protocol="paper", regression=fit, alpha=alpha).fit(demo)
        phase = dmp.phase()
        assert phase[0] == 1.0 and phase.shape == (n_steps,)
        assert np.all(dmp.centres_ <= 1.0) and np.all(dmp.centres_ >= phase[-1] - 1e-15)
        assert np.all(np.isfinite(dmp.weights_))
        target = forcing_target(
            demo,
            phase,
            dt=dmp.dt_,
            tau=1.0,
            gains=(dmp.alpha_value, dmp.beta_value, dmp.K_value),
        )
        if (
            fit == "lwr"
        ):  # each LWR weight is a weighted mean of f*/phase: it cannot exceed their range
            assert np.abs(dmp.weights_).max() <= np.abs(target / phase[:, None]).max() * (1 + 1e-9)
        # far past the demonstration (the phase long decayed): 50 T, at most 200 000 samples
        rollout = dmp.rollout(n_steps=min(50 * n_steps, 200_000))
        assert np.all(np.isfinite(rollout))


def test_basis_rows_sum_to_phase_and_never_nan():
    centres = kernel_centres(50, 1000, 1e-3)
    widths = kernel_widths(centres)
    phase = np.array([1.0, 0.5, 0.37, 1e-3, 0.0, 5.0])
    phi = basis_functions(phase, centres, widths)
    assert np.all(np.isfinite(phi))
    np.testing.assert_allclose(phi.sum(axis=1), phase, rtol=1e-12)


@pytest.mark.parametrize("n_kernels", [1, 2, 50, 400])
@pytest.mark.parametrize("rule", ["spacing", "pydmps"])
def test_basis_matches_the_plain_formula(n_kernels, rule):
    centres = kernel_centres(n_kernels, 1000, 1e-3)
    widths = kernel_widths(centres, 1.0, rule)
    phase = np.concatenate([phase_grid(5000, 1e-3), [0.0, 0.999, 1.0]])
    psi = np.exp(-widths * (phase[:, None] - centres) ** 2)
    keep = psi.sum(axis=1) > 1e-250  # the plain formula is 0/0 beyond; checked separately above
    expected = phase[keep, None] * psi[keep] / psi[keep].sum(axis=1, keepdims=True)
    np.testing.assert_allclose(
        basis_functions(phase, centres, widths)[keep], expected, rtol=0, atol=1e-10
    )


def test_phase_grid_is_the_euler_canonical_system():
    np.testing.assert_allclose(phase_grid(5, 0.1, 2.0, 4.0), 0.8 ** np.arange(5))
    assert phase_grid(200, 1 / 200)[-1] == pytest.approx(np.exp(-1), rel=0.01)


def test_pastor_with_zero_weights_starts_with_zero_acceleration():
    demo = minimum_jerk([0.0, 0.0], [1.0, -2.0], 100)
    for K, zero_start in (("pastor", True), ("paper", False)):
        dmp = DMP(protocol="paper", K=K).fit(demo)
        dmp.weights_ = np.zeros_like(dmp.weights_)
        y = dmp.rollout(goal=[3.0, 4.0])
        second_difference = y[2] - 2 * y[1] + y[0]  # = h² · acceleration at step 0 (explicit Euler)
        if zero_start:
            np.testing.assert_allclose(second_difference, 0.0, atol=1e-15)
        else:
            assert np.linalg.norm(second_difference) > 1e-6


# --- agreement with movement_primitives ----------------------------------------------------------
def test_pastor_variant_matches_movement_primitives_smooth_scaling():
    dmp_module = pytest.importorskip("movement_primitives.dmp")
    n_steps = 500
    demo = curved_demo(n_steps, 2, seed=4)
    times = np.arange(n_steps) / n_steps  # our protocol: dt = 1/T
    theirs = dmp_module.DMP(
        n_dims=2,
        execution_time=times[-1],
        dt=1 / n_steps,
        n_weights_per_dim=50,
        smooth_scaling=True,
    )
    theirs.imitate(times, demo)
    # movement_primitives lets the phase decay to 0.01 over the movement; use the same decay.
    alpha_phase = theirs.forcing_term.alpha_z * times[-1]
    ours = DMP(protocol="paper", K="pastor", alpha_phase=alpha_phase).fit(demo)
    new_goal = demo[-1] + np.array([0.3, -0.2])
    theirs.configure(start_y=demo[0], goal_y=new_goal)
    _, their_path = theirs.open_loop(step_function="euler")
    # Kernels, phase discretisation and Euler variant differ: same path within 1 % of the extent.
    assert their_path.shape == (n_steps, 2)
    assert rel_rmse(ours.rollout(goal=new_goal), their_path) < 0.01
    # ... while the paper's K = alpha scales goal changes differently: the check can tell them apart.
    plain = DMP(protocol="paper", K="paper", alpha_phase=alpha_phase).fit(demo)
    assert rel_rmse(plain.rollout(goal=new_goal), their_path) > 2 * rel_rmse(
        ours.rollout(goal=new_goal), their_path
    )


# --- bad input --------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "y, error, match",
    [
        (np.array([[0.0, 0.0], [np.nan, 1.0], [2.0, 2.0]]), ValueError, "NaN.*row 1"),
        (np.array([[0.0, 0.0], [np.inf, 1.0], [2.0, 2.0]]), ValueError, "inf"),
        (np.linspace(0, 1, 10), ValueError, r"shape \(T, D\)"),
        (np.zeros((4, 3, 2)), ValueError, r"shape \(T, D\)"),
        (np.array([[0.0, 0.0], [1.0, 1.0]]), ValueError, "at least 3 points"),
        (np.ones((20, 3)), ValueError, "identical"),
        ([["a", "b"], ["c", "d"], ["e", "f"]], TypeError, "numbers"),
        ("not an array", TypeError, "string"),
    ],
)
def test_fit_rejects_bad_demonstrations(y, error, match):
    with pytest.raises(error, match=match):
        DMP(protocol="paper").fit(y)


def test_rollout_rejects_bad_goal_start_and_steps(demo3d):
    dmp = DMP(protocol="paper").fit(demo3d)
    with pytest.raises(ValueError, match="goal must have 3 coordinate"):
        dmp.rollout(goal=[1.0, 2.0])
    with pytest.raises(ValueError, match="start must have 3"):
        dmp.rollout(start=[1.0, 2.0, 3.0, 4.0])
    with pytest.raises(ValueError, match="goal contains NaN"):
        dmp.rollout(goal=[1.0, np.nan, 0.0])
    with pytest.raises(ValueError, match=r"goals must have shape \(G, 3\)"):
        dmp.rollout_many(np.zeros((5, 2)))
    with pytest.raises(ValueError, match="n_steps must be >= 1"):
        dmp.rollout(n_steps=0)
    with pytest.raises(TypeError, match="n_steps must be an integer"):
        dmp.rollout(n_steps=2.5)


@pytest.mark.parametrize(
    "params, match",
    [
        ({"n_kernels": 0}, "n_kernels must be >= 1"),
        ({"alpha": -1.0}, "alpha must be > 0"),
        ({"alpha": 1e-9}, "alpha must be >= 1e-06"),
        ({"alpha": 1e300}, "alpha must be <= 1e\\+06"),
        ({"n_kernels": 10**9}, "n_kernels = 1,000,000,000 exceeds the limit max_kernels"),
        ({"K": "huge"}, "K must be one of"),
        ({"regression": "gpr"}, "regression must be one of"),
        ({"tau": float("nan")}, "tau must be finite"),
        ({"widths": "wide"}, "widths must be one of"),
    ],
)
def test_bad_parameters_are_named_at_fit(params, match):
    model = DMP(protocol="paper", **params)  # scikit-learn convention: the constructor only stores
    with pytest.raises(ValueError, match=match):
        model.fit(minimum_jerk([0.0], [1.0], 20))


def test_too_fast_phase_is_rejected_at_fit():
    with pytest.raises(ValueError, match="alpha_phase"):
        DMP(protocol="paper", alpha_phase=50.0).fit(minimum_jerk([0.0], [1.0], 10))


def test_unfitted_model_says_so():
    with pytest.raises(NotFittedError, match="not fitted"):
        DMP(protocol="paper").rollout()


# --- hyperparameters after fit, temporal scaling, estimator conventions ------------------------
@pytest.mark.parametrize("how", ["attribute", "set_params"])
def test_tau_may_change_after_fit_and_equals_a_fresh_model_with_it(how, demo3d):
    """tau is an execution parameter: the weights are learned at tau = 1 whatever it is."""
    from sklearn.base import clone

    dmp = DMP(protocol="paper").fit(demo3d)
    goal = demo3d[-1] + 0.3
    before = dmp.rollout(goal)  # fills the cache with the old parameters
    if how == "attribute":
        dmp.tau = 1.6
    else:
        dmp.set_params(tau=1.6)
    fresh = clone(dmp).fit(demo3d)  # fitted from scratch with the new tau
    after = dmp.rollout(goal)
    np.testing.assert_array_equal(after, fresh.rollout(goal))
    np.testing.assert_allclose(
        after, euler_reference(dmp, goal, demo3d[0], after.shape[0]), atol=1e-9
    )
    assert after.shape != before.shape


@pytest.mark.parametrize(
    "name, value",
    [
        ("alpha", 31.0),
        ("beta", 5.0),
        ("K", "pastor"),
        ("K", 40.0),
        ("alpha_phase", 2.5),
        ("n_kernels", 20),
        ("regression", "ridge"),
        ("goal_rate", 3.0),
        ("integrator", "exact"),
        ("protocol", "robot"),
    ],
)
@pytest.mark.parametrize("how", ["attribute", "set_params"])
def test_a_learned_parameter_changed_after_fit_unfits_the_model(name, value, how, demo3d):
    """before the fix, set_params(alpha=...) kept the weights learned for the old
    gains (LASA Sshape: 0.50 % -> 44.6 % RMSE). Now the model says it must be fitted again."""
    from sklearn.utils.validation import check_is_fitted

    dmp = DMP(protocol="paper").fit(demo3d)
    if how == "attribute":
        setattr(dmp, name, value)
    else:
        dmp.set_params(**{name: value})
    for use in (
        dmp.rollout,
        dmp.trajectory,
        dmp.endpoint_gain,
        lambda: dmp.rollout_many(demo3d[-1:]),
    ):
        with pytest.raises(NotFittedError, match=f"{name} \\(fitted with .*fitted again"):
            use()
    with pytest.raises(ValueError, match="not fitted"):  # scikit-learn's own check agrees
        check_is_fitted(dmp)
    refitted = dmp.fit(demo3d)  # fitting again with the new value is the remedy
    np.testing.assert_array_equal(refitted.rollout(), DMP(**dmp.get_params()).fit(demo3d).rollout())


def test_every_parameter_but_tau_is_checked_after_fit():
    from bidmp.primitives.dmp import _RAW_PARAMS

    assert set(_RAW_PARAMS) | {"tau"} == set(
        DMP().get_params()
    )  # a new parameter must be checked too


def test_changing_alpha_after_fit_on_lasa_would_have_ruined_the_reproduction():
    """The measurement behind the refit on set_params: the old weights under new gains reproduce Sshape badly,
    a refit reproduces it well; so reusing them silently was wrong."""
    demo = lasa("Sshape")[0]
    dmp = DMP(protocol="paper").fit(demo)
    extent = np.linalg.norm(np.ptp(demo, axis=0))
    good = np.sqrt(np.mean(np.sum((dmp.rollout() - demo) ** 2, axis=1))) / extent
    stale = clone_with_weights(dmp, alpha=100.0).rollout()
    bad = np.sqrt(np.mean(np.sum((stale - demo) ** 2, axis=1))) / extent
    assert good < 0.01 and bad > 0.2
    dmp.set_params(alpha=100.0)
    with pytest.raises(NotFittedError):
        dmp.rollout()
    refit = np.sqrt(np.mean(np.sum((dmp.fit(demo).rollout() - demo) ** 2, axis=1))) / extent
    assert refit < 0.01


def clone_with_weights(dmp, **params):
    """A model with new parameters and the old learned state: what main silently did."""
    from sklearn.base import clone

    fresh = clone(dmp).set_params(**params)
    fresh.__dict__.update(
        {k: v for k, v in dmp.__dict__.items() if k.endswith("_") and not k.startswith("_")}
    )
    return fresh


def test_tau_is_temporal_scaling_same_path_slower(demo3d):
    nominal = DMP(protocol="paper").fit(demo3d)
    slow = DMP(protocol="paper", tau=2.0).fit(demo3d)
    np.testing.assert_array_equal(
        slow.weights_, nominal.weights_
    )  # learned at the demo's own time scale
    y1, y2 = nominal.rollout(), slow.rollout()
    assert y2.shape == (2 * demo3d.shape[0], 3)  # default horizon: tau · T samples of dt
    extent = np.linalg.norm(np.ptp(demo3d, axis=0))
    # Same path in twice the time: every second sample of the slow rollout is the nominal one
    # (up to the Euler step, which halves).
    assert np.sqrt(np.mean(np.sum((y2[1::2] - y1) ** 2, axis=1))) / extent < 5e-3
    speed1 = np.linalg.norm(np.diff(y1, axis=0), axis=1).max() / nominal.dt_
    speed2 = np.linalg.norm(np.diff(y2, axis=0), axis=1).max() / slow.dt_
    assert speed2 / speed1 == pytest.approx(0.5, rel=0.02)


def test_estimator_conventions(demo2d):
    from sklearn.base import clone

    dmp = DMP(protocol="paper", alpha=30.0, K="pastor", regression="ridge")
    assert "weights_" not in vars(dmp) and not hasattr(dmp, "weights_")
    assert repr(dmp) == "DMP(K='pastor', alpha=30.0, protocol='paper', regression='ridge')"
    copy = clone(dmp)
    assert copy.get_params() == dmp.get_params() and copy is not dmp
    fitted = clone(dmp).fit(demo2d)
    np.testing.assert_array_equal(clone(fitted).fit(demo2d).rollout(), fitted.rollout())
    assert not hasattr(clone(fitted), "weights_")
    assert dmp.set_params(alpha=50.0) is dmp and dmp.alpha_value == 50.0


def test_failed_fit_leaves_the_model_as_it_was(demo2d):
    dmp = DMP(protocol="paper").fit(demo2d)
    before = dmp.rollout()
    with pytest.raises(ValueError, match="y contains NaN"):
        dmp.fit(np.full((50, 2), np.nan))
    dmp.alpha = -1.0
    with pytest.raises(ValueError, match="alpha must be > 0"):
        dmp.fit(demo2d)
    dmp.alpha = 25.0
    np.testing.assert_array_equal(dmp.rollout(), before)


def test_ridge_weights_equal_an_augmented_least_squares_on_a_shared_grid():
    """Two recordings of one length share the cached grid and regression factor (read-only);
    each one's weights still equal an independent ridge solution: ``lstsq`` of ``Φ w = f``
    stacked on ``√λ w = 0`` (λ relative to the mean diagonal of ΦᵀΦ), on the model's own grid."""
    from bidmp.primitives.forcing import _cached_design

    rng = np.random.default_rng(17)
    t = np.arange(700) * 0.004  # uniform: training_trajectory resamples by index
    for case in range(2):
        y = np.cumsum(rng.normal(size=(700, 3)), axis=0) * (5.0 + case)
        hits = _cached_design.cache_info().hits
        dmp = DMP(regression="ridge", ridge=1e-6).fit(y, t)
        if case:  # the second fit on the same grid reused the first one's factor (structure)
            assert _cached_design.cache_info().hits == hits + 1
        _, phi = dmp.training_grid()
        target = dmp.forcing_target(dmp.training_trajectory(y))
        reg = 1e-6 * np.trace(phi.T @ phi) / phi.shape[1]
        stacked = np.vstack([phi, np.sqrt(reg) * np.eye(phi.shape[1])])
        padded = np.vstack([target, np.zeros((phi.shape[1], 3))])
        expected = np.linalg.lstsq(stacked, padded, rcond=None)[0]
        np.testing.assert_allclose(
            phi @ dmp.weights_, phi @ expected, atol=1e-9 * np.abs(phi @ expected).max()
        )
    with pytest.raises(ValueError, match="read-only"):
        dmp.centres_[0] = 0.5  # shared with every model on this grid: not writable
