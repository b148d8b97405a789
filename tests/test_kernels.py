"""The compiled loops (``bidmp._kernels``) against independent references: SciPy's ``lfilter`` for
the spring's integration, SciPy's ``Rotation`` for quaternion logs and exponentials, ``np.interp``
for resampling, the NumPy expressions they replaced for the forcing target, the goal gate and share,
the rest blend, the exact state, a trajectory's rates and the held responses, NumPy's norms and
sums for the arc length and a motion's peaks, NumPy's reductions for the finite and range scans,
plain loops for the band products, plain NumPy searches for the decisions (the rest blend's
windows, a band's edges; the straight tail is checked against its plain search in
test_approach.py), and the checked path (``check_timestamps``) for the timestamps' verdict.

Each compares to the last bit (``view(np.int64)``), on random inputs at scales and lengths the
library was not tuned on: the kernels replaced NumPy expressions whose numbers the committed results
hold, so "close" would not do. These are correctness checks, not the code against itself.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.signal import lfilter
from scipy.spatial.transform import Rotation

from bidmp._kernels import (
    all_finite,
    arclength,
    band_of,
    band_product,
    band_transposed_product,
    exact_rates,
    exact_state,
    extent,
    foh_responses,
    forcing_target,
    goal_gate,
    goal_share,
    goal_share_arguments,
    interp_columns,
    motion_peaks,
    quaternion_exp,
    quaternion_log,
    rest_blend_arguments,
    rest_blended,
    rest_windows,
    second_order,
    stamp_verdict,
    strictly_decreasing,
)
from bidmp.primitives.goals import _smoothstep, _smoothstep_derivatives
from bidmp.primitives.rest import _BLEND_SHAPE, _BLEND_U, _REST_CANDIDATES


def _bits(array) -> np.ndarray:
    return np.ascontiguousarray(array, dtype=np.float64).view(np.int64)


def _random_motion(rng, n_samples: int, n_dims: int) -> np.ndarray:
    """A smooth motion with noise, or a random walk, at a random scale and offset."""
    s = np.linspace(0.0, 1.0, n_samples)
    if rng.random() < 0.3:
        y = np.cumsum(rng.normal(size=(n_samples, n_dims)), axis=0)
    else:
        frequencies = rng.uniform(0.5, 4.0, n_dims)
        y = np.sin(np.outer(s, frequencies) + rng.uniform(0, 6, n_dims)) + np.outer(
            s, rng.normal(size=n_dims)
        )
        y += rng.normal(scale=10 ** rng.uniform(-7, -2), size=y.shape)
    return y * 10 ** rng.uniform(-3, 3) + rng.uniform(-1e3, 1e3, n_dims)


def test_the_integration_loop_is_scipys_lfilter_to_the_bit():
    """``second_order`` replaced SciPy's lfilter (transposed direct form II) with its initial
    state from the first two outputs: the same bits for stable and unstable filters, any
    numerator, and the first-order-hold drive formed inside the loop."""
    rng = np.random.default_rng(3)
    for _ in range(200):
        n_signals, n_drives = int(rng.integers(1, 5)), int(rng.integers(0, 400))
        drives = rng.normal(size=(n_signals, n_drives)) * 10 ** rng.uniform(-3, 3)
        y_first, y_second = rng.normal(size=n_signals), rng.normal(size=n_signals)
        a1, a2 = rng.uniform(-2.0, 2.0), rng.uniform(-1.0, 1.0)
        b = rng.normal(size=3)
        out = second_order(drives, y_first, y_second, *b, a1, a2)
        assert out.shape == (n_signals, n_drives + 2)
        assert np.array_equal(_bits(out[:, 0]), _bits(y_first))
        assert np.array_equal(_bits(out[:, 1]), _bits(y_second))
        if n_drives:
            zi = np.stack([-a1 * y_second - a2 * y_first, -a2 * y_second], axis=1)
            expected, _ = lfilter(b, [1.0, a1, a2], drives, axis=1, zi=zi)
            assert np.array_equal(_bits(out[:, 2:]), _bits(expected))
        # the held input's drive b0 u[n+2] + b1 u[n+1] + b2 u[n], formed in the loop
        inputs = rng.normal(size=(n_signals, n_drives + 2))
        held = rng.normal(size=3)
        out = second_order(inputs, y_first, y_second, *b, a1, a2, held=held)
        drive = held[0] * inputs[:, 2:] + held[1] * inputs[:, 1:-1] + held[2] * inputs[:, :-2]
        zi = np.stack([-a1 * y_second - a2 * y_first, -a2 * y_second], axis=1)
        if n_drives:
            expected, _ = lfilter(b, [1.0, a1, a2], drive, axis=1, zi=zi)
            assert np.array_equal(_bits(out[:, 2:]), _bits(expected))


def test_the_integration_loop_refuses_fewer_than_two_samples():
    with pytest.raises(ValueError, match="2 or more"):
        second_order(
            np.zeros((1, 1)), np.zeros(1), np.zeros(1), 1.0, 0.0, 0.0, 0.1, 0.1, held=np.ones(3)
        )


@pytest.mark.parametrize("n_dims", [1, 2, 3, 6, 9])
def test_the_forcing_target_loop_is_the_numpy_expression_to_the_bit(n_dims):
    """``(tau² ÿ - α (β (g - y) - tau ẏ)) / K + G (g - y0)`` with ``np.gradient`` derivatives."""
    rng = np.random.default_rng(n_dims)
    for _ in range(40):
        n_samples = int(rng.integers(2, 1500))
        y = _random_motion(rng, n_samples, n_dims)
        gate = rng.random(n_samples)
        dt, tau = 10 ** rng.uniform(-4, -1), rng.uniform(0.3, 3.0)
        alpha, beta, K = rng.uniform(1, 100), rng.uniform(1, 30), rng.uniform(1, 1e3)
        velocity = np.gradient(y, dt, axis=0)
        acceleration = np.gradient(velocity, dt, axis=0)
        spring = alpha * (beta * (y[-1] - y) - tau * velocity)
        expected = (tau**2 * acceleration - spring) / K + gate[:, None] * (y[-1] - y[0])
        out = forcing_target(y, gate, dt, tau, tau**2, alpha, beta, K)
        assert np.array_equal(_bits(out), _bits(expected))
    with pytest.raises(ValueError, match="gate"):
        forcing_target(np.zeros((5, 2)), np.zeros(4), 0.1, 1.0, 1.0, 1.0, 1.0, 1.0)


def test_the_goal_gate_loop_is_the_numpy_expression_to_the_bit():
    """``(αβ (1 - R) - R'' - α R') / K`` with ``np.gradient`` derivatives, ``αβ / K`` first."""
    rng = np.random.default_rng(5)
    for _ in range(100):
        n_samples = int(rng.integers(2, 3000))
        share = np.sort(rng.random(n_samples)) if rng.random() < 0.5 else rng.normal(size=n_samples)
        dt = 10 ** rng.uniform(-4, -1)
        alpha, beta, K = rng.uniform(1, 100), rng.uniform(1, 30), rng.uniform(1, 1e3)
        rate = np.gradient(share, dt)
        curvature = np.gradient(rate, dt)
        expected = (alpha * beta * (1.0 - share) - curvature - alpha * rate) / K
        expected[0] = alpha * beta / K
        assert np.array_equal(_bits(goal_gate(share, dt, alpha, beta, K)), _bits(expected))


def _plain_rest_windows(y: np.ndarray, dt: float) -> tuple[float, float, float]:
    """The rest blend's windows the plain NumPy way: for each end, every candidate window's added
    acceleration against the running peak, the first that stays within 10 % of it."""
    velocity = np.gradient(y, dt, axis=0)
    acceleration = np.gradient(velocity, dt, axis=0)
    peak = float(np.max(np.linalg.norm(velocity, axis=1)))
    windows = []
    for speed_vector, forward in ((velocity[0], acceleration), (velocity[-1], acceleration[::-1])):
        speed = float(np.linalg.norm(speed_vector))
        if speed <= 1e-12 * max(peak, 1e-300):
            windows.append(0.0)
            continue
        running = np.maximum.accumulate(np.linalg.norm(forward, axis=1))
        chosen = 0.25
        for window in _REST_CANDIDATES:
            index = np.minimum((_BLEND_U * window / dt).astype(int), running.shape[0] - 1)
            added = speed * _BLEND_SHAPE / window
            if np.all(added <= 0.1 * np.maximum(running[index], 1e-300)):
                chosen = float(window)
                break
        windows.append(chosen)
    return windows[0], windows[1], peak


def test_the_rest_windows_are_the_plain_search():
    """The windows (from a fixed table) and the peak speed, on motions that start and end at speed,
    at rest, and in between, at any scale: the same as the plain search."""
    rng = np.random.default_rng(8)
    seen = set()
    for trial in range(400):
        n_samples, n_dims = int(rng.integers(3, 1500)), int(rng.integers(1, 7))
        y = _random_motion(rng, n_samples, n_dims)
        if trial % 4 == 1:  # at rest at the start: the blend window is 0 there
            y[: n_samples // 3] = y[n_samples // 3]
        dt = 1.0 / n_samples if trial % 2 else 10 ** rng.uniform(-3, 0)  # a fit's, and others
        start, end, peak, start_speed, end_speed = rest_windows(
            y, dt, _BLEND_U, _BLEND_SHAPE, _REST_CANDIDATES, 0.1, 0.25
        )
        expected = _plain_rest_windows(y, dt)
        assert (start, end, peak) == expected, trial
        assert start_speed == np.linalg.norm((y[1] - y[0]) / dt)
        assert end_speed == np.linalg.norm((y[-1] - y[-2]) / dt)
        seen.update((start == 0.0, 0.0 < start < 0.25, start == 0.25))
    assert seen == {True, False}  # every kind of answer was met (at rest, a window, the widest)
    # Short random walks on a fine step: the windows reach past the motion's end, where the
    # search reads the running peak at the last sample.
    for _ in range(300):
        n_samples, dt = int(rng.integers(3, 15)), 10 ** rng.uniform(-4, -1)
        y = np.cumsum(rng.normal(size=(n_samples, 2)), axis=0) * 10 ** rng.uniform(-3, 3)
        found = rest_windows(y, dt, _BLEND_U, _BLEND_SHAPE, _REST_CANDIDATES, 0.1, 0.25)
        assert found[:3] == _plain_rest_windows(y, dt)
    with pytest.raises(ValueError, match="3 samples"):
        rest_windows(np.zeros((2, 1)), 0.5, _BLEND_U, _BLEND_SHAPE, _REST_CANDIDATES, 0.1, 0.25)


def test_the_blend_shape_table_is_the_blends_acceleration():
    """The table the windows are searched with: ``|2 S'(u) + u S''(u)|`` on [0, 1] (a closed form
    of the blend ``u (1 - S(u))``'s second derivative, checked by finite differences here)."""
    u = _BLEND_U
    first, second = _smoothstep_derivatives(u)
    assert np.allclose(_BLEND_SHAPE, np.abs(2.0 * first + u * second))
    fine = np.linspace(0.0, 1.0, 20001)
    s7 = np.clip(fine, 0, 1) ** 4 * (35 - 84 * fine + 70 * fine**2 - 20 * fine**3)
    blend_acceleration = np.gradient(np.gradient(fine * (1.0 - s7), fine), fine)
    assert np.allclose(
        np.interp(u, fine, np.abs(blend_acceleration))[1:-1], _BLEND_SHAPE[1:-1], atol=1e-3
    )


def test_a_fit_and_its_trajectory_import_no_scipy_signal(loaded_after):
    """The spring is integrated by the compiled loop, not SciPy's lfilter: a robot-protocol fit and
    its trajectory never import SciPy's signal package (0.3 s of every command's start-up)."""
    code = (
        "import numpy as np, bidmp\n"
        "t = np.arange(200) / 200.0\n"
        "y = np.column_stack([np.sin(3 * t), t**2, np.cos(t)])\n"
        "bidmp.DMP().fit(y, t).trajectory(goal=y[-1] + 0.1)\n"
        "bidmp.DMP(protocol='paper').fit(y).rollout()"
    )
    assert loaded_after(code, ("scipy.signal",)) == []


def test_the_goal_share_loops_are_the_numpy_expression_to_the_bit():
    """``σ S((s - b) / w)``, then ``1 - (1 - σ) S((end - s) / w)`` over the last ``w``, then 1, with
    NumPy's own powers in between (its vectorised ``u**4`` is not the C library's pow)."""
    rng = np.random.default_rng(12)
    for _ in range(200):
        n_samples = int(rng.integers(2, 2000))
        dt = 1.0 / n_samples * rng.uniform(0.5, 2.0)
        progress = np.sort(rng.random(n_samples))
        n_motion = int(rng.integers(1, n_samples + 1))
        begin = rng.uniform(0.0, 0.3) * n_motion * dt
        end = (n_motion - 1) * dt
        width = max(rng.uniform(0.01, 0.3) * (end - begin), dt)
        s = np.arange(n_samples) * dt
        expected = progress * _smoothstep((s - begin) / width)
        closing = s > end - width
        expected[closing] = 1.0 - (1.0 - progress[closing]) * _smoothstep(
            (end - s[closing]) / width
        )
        expected[s >= end] = 1.0
        arguments = goal_share_arguments(n_samples, dt, begin, end, width)
        out = goal_share(progress, arguments, arguments**4, dt, end, width)
        assert np.array_equal(_bits(out), _bits(expected))
    with pytest.raises(ValueError, match="arguments and powers"):
        goal_share(np.zeros(3), np.zeros((2, 4)), np.zeros((2, 4)), 0.1, 0.2, 0.1)


def test_the_rest_blend_loops_are_the_numpy_expression_to_the_bit():
    """``y - v₀ s (1 - S(s / w₀)) + v₁ (s_T - s) (1 - S((s_T - s) / w₁))``, either end skipped at a
    window of 0."""
    rng = np.random.default_rng(13)
    for trial in range(200):
        n_samples, n_dims = int(rng.integers(3, 1500)), int(rng.integers(1, 7))
        y = _random_motion(rng, n_samples, n_dims)
        dt = 1.0 / n_samples
        widths = [rng.choice([0.0, rng.uniform(0.01, 0.25)]) for _ in range(2)]
        v0, v1 = (y[1] - y[0]) / dt, (y[-1] - y[-2]) / dt
        s = np.arange(n_samples) * dt
        expected = y.copy()
        for end, speed_vector, width in ((False, v0, widths[0]), (True, v1, widths[1])):
            if width == 0.0:
                continue
            elapsed = (s[-1] - s) if end else s
            blend = elapsed * (1.0 - _smoothstep(elapsed / width))
            expected += (1.0 if end else -1.0) * blend[:, None] * speed_vector[None, :]
        arguments = rest_blend_arguments(n_samples, dt, *widths)
        out = rest_blended(y, arguments, arguments**4, dt, v0, v1, *widths)
        assert np.array_equal(_bits(out), _bits(expected)), trial


def _numpy_exact_state(y, inputs, p, alpha, beta, tau):
    """``z`` and the acceleration of an exact rollout as NumPy expressions (the code replaced)."""
    p11, p12, now, after = p
    z = y[1:] - p11 * y[:-1]
    z -= now * inputs[:-1]
    z -= after * inputs[1:]
    z /= p12
    acceleration = inputs[:-1] - alpha * beta * y[:-1]
    acceleration -= alpha * z
    acceleration /= tau**2
    return z, acceleration


def test_the_exact_state_loop_is_the_numpy_expression_to_the_bit():
    rng = np.random.default_rng(14)
    for _ in range(100):
        n_samples, n_dims = int(rng.integers(1, 1500)), int(rng.integers(1, 7))
        y, inputs = rng.normal(size=(2, n_samples, n_dims)) * 10 ** rng.uniform(-3, 3)
        p11, p12, now, after = rng.normal(size=4)
        alpha, beta, tau = rng.uniform(1, 100), rng.uniform(1, 30), rng.uniform(0.3, 3.0)
        z, acceleration = _numpy_exact_state(y, inputs, (p11, p12, now, after), alpha, beta, tau)
        out_z, out_acceleration = exact_state(
            y, inputs, p11, p12, now, after, alpha * beta, alpha, tau**2
        )
        assert np.array_equal(_bits(out_z), _bits(z))
        assert np.array_equal(_bits(out_acceleration), _bits(acceleration))
    with pytest.raises(ValueError, match="same shape"):
        exact_state(np.zeros((3, 2)), np.zeros((3, 1)), 1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 1.0)


def _numpy_exact_rates(signals, z_first, gains, p, scales):
    """A timed trajectory's rates as NumPy expressions (the code the kernel replaced)."""
    y, forcing, gate, goal, start = signals
    K, alpha, beta, tau = gains
    inputs = K * forcing
    inputs -= np.multiply.outer(gate, K * (goal - start))
    inputs += alpha * beta * goal
    z, acceleration = _numpy_exact_state(y, inputs, p, alpha, beta, tau)
    z[0] = 0.0 if z_first is None else z_first
    acceleration[0] = (inputs[0] - alpha * beta * y[0] - alpha * z[0]) / tau**2
    return z / scales[0], acceleration / scales[1]


def test_the_exact_rates_loop_is_the_numpy_expressions_to_the_bit():
    """Random lengths, dimensions, scales, gains, starts at rest and moving."""
    rng = np.random.default_rng(15)
    for trial in range(100):
        n_samples, n_dims = int(rng.integers(2, 1500)), int(rng.integers(1, 7))
        scale = 10 ** rng.uniform(-3, 3)
        y, forcing = rng.normal(size=(2, n_samples, n_dims)) * scale
        gate = rng.uniform(0.0, 1.0, n_samples)
        goal, start = rng.normal(size=(2, n_dims)) * scale
        z_first = None if trial % 2 else rng.normal(size=n_dims) * scale
        p = rng.normal(size=4)
        alpha, beta, tau, K = rng.uniform(1, 100), rng.uniform(1, 30), rng.uniform(0.3, 3.0), 0.0
        K = alpha * beta if trial % 3 else rng.uniform(1, 1000)
        scales = rng.uniform(0.1, 10.0, 2)
        expected = _numpy_exact_rates(
            (y, forcing, gate, goal, start), z_first, (K, alpha, beta, tau), p, scales
        )
        out = exact_rates(
            y, forcing, gate, goal, start, z_first, K, alpha * beta, alpha, tau**2, *p, *scales
        )
        for got, want in zip(out, expected, strict=True):
            assert np.array_equal(_bits(got), _bits(want)), trial
    with pytest.raises(ValueError, match="exact_rates"):
        exact_rates(
            np.zeros((3, 2)), np.zeros((3, 1)), np.zeros(3), np.zeros(2), np.zeros(2), None,
            *np.ones(10),
        )  # fmt: skip


def test_the_held_responses_are_the_numpy_expressions_and_the_filter_to_the_bit():
    """foh_responses against its NumPy expressions followed by second_order (itself checked
    against SciPy's lfilter above): random signals, scales, states and steps of the spring."""
    from bidmp.primitives.integrate import _foh_step

    rng = np.random.default_rng(18)
    for trial in range(100):
        n_signals, n = int(rng.integers(1, 5)), int(rng.integers(3, 1200))
        inputs = rng.normal(size=(n, n_signals)).T * 10 ** rng.uniform(-3, 3)  # strided
        y_first, z_first = (None, None) if trial % 3 == 0 else rng.normal(size=(2, n_signals))
        transition, now, after = _foh_step(
            rng.uniform(1e-4, 0.05), rng.uniform(1, 80), rng.uniform(1, 30), rng.uniform(0.3, 3)
        )
        y0 = np.zeros(n_signals) if y_first is None else y_first
        z0 = np.zeros(n_signals) if z_first is None else z_first
        y1 = (
            transition[0, 0] * y0
            + transition[0, 1] * z0
            + now[0] * inputs[:, 0]
            + after[0] * inputs[:, 1]
        )
        (p11, p12), (p21, p22) = transition
        held = np.array(
            [after[0], now[0] - p22 * after[0] + p12 * after[1], -p22 * now[0] + p12 * now[1]]
        )
        expected = second_order(
            inputs, y0, y1, 1.0, 0.0, 0.0, -(p11 + p22), p11 * p22 - p12 * p21, held=held
        )
        out = foh_responses(inputs, y_first, z_first, transition, now, after)
        assert np.array_equal(_bits(out), _bits(expected)), trial
    with pytest.raises(ValueError, match="foh_responses"):
        foh_responses(np.zeros((2, 2)), None, None, transition, now, after)


def test_the_finite_scans_are_numpys_reductions():
    """all_finite, extent and strictly_decreasing against NumPy's isfinite, min, max and diff, with
    NaN and inf planted at random places, static and decreasing runs included."""
    rng = np.random.default_rng(16)
    for trial in range(300):
        n, d = int(rng.integers(1, 60)), int(rng.integers(1, 5))
        values = rng.normal(size=(n, d)) * 10 ** rng.uniform(-5, 5)
        if trial % 4 == 1:
            values[rng.integers(n), rng.integers(d)] = rng.choice([np.nan, np.inf, -np.inf])
        if trial % 7 == 2:
            values[:] = values[0]
        finite = bool(np.all(np.isfinite(values)))
        assert all_finite(values) is finite
        assert all_finite(values.T) is finite  # strided
        got = extent(values)
        assert got[0] is finite
        if finite:
            assert got[1:] == (values.min(), values.max(), np.abs(values - values[0]).max())
        row = np.sort(values[:, 0])[::-1] if trial % 2 else values[:, 0]
        assert strictly_decreasing(row) is bool(np.all(np.diff(row) < 0.0))


def test_the_stamp_verdict_is_the_checked_path():
    """stamp_verdict passes exactly the stamps check_timestamps takes (1 where _resampled would
    copy the samples, 2 where it resamples) and leaves every other one (0) to the checked path:
    random jittered, uniform, epoch, repeated, backward, NaN, huge and out-of-rate stamps."""
    from bidmp.primitives.timing import (
        _MAX_STAMP_S,
        MAX_RATE_HZ,
        MIN_RATE_HZ,
        _resampled,
        check_timestamps,
    )

    rng = np.random.default_rng(17)
    seen = set()
    for trial in range(600):
        n = int(rng.integers(1, 200))
        rate = 10 ** rng.uniform(-0.5, 5.5)
        if trial % 13 == 5:  # at the rate bounds, within a thousandth
            rate = rng.choice([MIN_RATE_HZ, MAX_RATE_HZ]) * (1.0 + rng.uniform(-1e-3, 1e-3))
        t = rng.uniform(-1e3, 1.7e9) * (trial % 3 == 0) + np.arange(n) / rate
        if trial % 2:  # jitter, from rounding-sized (near the uniform line) to large
            t = t + rng.uniform(0, 1, n) * 10 ** rng.uniform(-13, -0.5) / rate
        kind = trial % 11
        if kind == 1 and n > 2:
            t[rng.integers(1, n)] = t[0]  # a repeat or a step back
        elif kind == 4 and n > 2:
            k = int(rng.integers(1, n))
            t[k] = t[k - 1]  # a repeated stamp
        elif kind == 2:
            t[rng.integers(n)] = rng.choice([np.nan, np.inf])
        elif kind == 3:
            t = t + 2e12
        verdict = stamp_verdict(t, MIN_RATE_HZ, MAX_RATE_HZ, _MAX_STAMP_S)
        try:
            stamps = check_timestamps(t, n)
        except ValueError:
            assert verdict == 0, trial
            seen.add(0)
            continue
        assert verdict in (1, 2), trial
        steps = np.diff(stamps - stamps[0])
        assert (verdict == 1) == (np.ptp(steps) <= 1e-9 * np.mean(steps)), trial
        y = rng.normal(size=(n, 2))
        if verdict == 1:  # the samples as they are, as the checked path takes them
            assert np.array_equal(_resampled(y, stamps)[0], y), trial
        seen.add(verdict)
    assert seen == {0, 1, 2}


def test_the_resampling_scan_is_np_interp_to_the_bit():
    """Every column at once, on grids inside, on and beyond the knots, unsorted ones, repeated
    knots' values, infinite samples (NumPy's NaN fallbacks) and a single knot."""
    rng = np.random.default_rng(15)
    for trial in range(400):
        x = np.unique(rng.uniform(-10, 10, int(rng.integers(1, 300))))
        if trial % 3 == 0:
            x = np.unique(x.round(1))
        y = rng.normal(size=(x.shape[0], int(rng.integers(1, 5)))) * 10 ** rng.uniform(-5, 5)
        if trial % 7 == 0:
            y[rng.integers(0, x.shape[0])] = np.inf
        x_new = np.concatenate([rng.uniform(x[0] - 1, x[-1] + 1, int(rng.integers(1, 400))), x])
        if trial % 2:
            x_new = np.sort(x_new)
        if trial % 11 == 0:
            x_new[rng.integers(0, x_new.shape[0])] = np.nan
        expected = np.column_stack([np.interp(x_new, x, column) for column in y.T])
        out = interp_columns(x_new, x, y)
        assert np.array_equal(np.isnan(out), np.isnan(expected)), trial
        finite = ~np.isnan(expected)
        assert np.array_equal(_bits(out[finite]), _bits(expected[finite])), trial
    with pytest.raises(ValueError, match="rows"):
        interp_columns(np.zeros(2), np.zeros(3), np.zeros((2, 1)))


def test_the_arc_length_pass_is_numpys_norms_summed_to_the_bit():
    """Paths of one to seven dimensions (NumPy sums rows of eight or more pairwise: the library
    keeps those in NumPy), at scales from µm to km, one sample, repeated samples and infinities."""
    rng = np.random.default_rng(16)
    for trial in range(600):
        n_samples, n_dims = int(rng.integers(1, 400)), int(rng.integers(1, 8))
        y = _random_motion(rng, n_samples, n_dims)
        if trial % 5 == 0 and n_samples > 2:
            y[1] = y[0]
        if trial % 13 == 0:
            y[rng.integers(0, n_samples), rng.integers(0, n_dims)] = rng.choice([np.inf, np.nan])
        if trial % 3 == 0:
            y = np.asfortranarray(y)
        steps = np.linalg.norm(np.diff(y, axis=0), axis=1)
        expected = np.concatenate([[0.0], np.cumsum(steps)])
        out = arclength(y)
        assert np.array_equal(np.isnan(out), np.isnan(expected)), trial
        finite = ~np.isnan(expected)
        assert np.array_equal(_bits(out[finite]), _bits(expected[finite])), trial


def _numpy_peaks(points: np.ndarray, dt: float) -> np.ndarray:
    """The peaks as the extension's timing measured them in NumPy before the loop replaced it."""
    peaks = np.zeros(3)
    difference = points
    for order in range(3):
        difference = np.diff(difference, axis=0) / dt
        if difference.shape[0]:
            peaks[order] = float(np.max(np.linalg.norm(difference, axis=1)))
    return peaks


def test_the_motion_peaks_pass_is_numpys_differences_to_the_bit():
    """Peak speed, acceleration and jerk of one to seven columns, one to three hundred samples
    (too few for an order: 0), at any rate and scale, with a NaN (it wins, as in NumPy's max)."""
    rng = np.random.default_rng(23)
    for trial in range(600):
        n_samples, n_dims = int(rng.integers(1, 300)), int(rng.integers(1, 8))
        y = _random_motion(rng, n_samples, n_dims)
        if trial % 17 == 0:
            y[rng.integers(0, n_samples), rng.integers(0, n_dims)] = np.nan
        if trial % 3 == 0:
            y = np.asfortranarray(y)
        dt = 10 ** rng.uniform(-4, 0)
        expected, out = _numpy_peaks(np.asarray(y), dt), motion_peaks(y, dt)
        assert np.array_equal(np.isnan(out), np.isnan(expected)), trial
        finite = ~np.isnan(expected)
        assert np.array_equal(_bits(out[finite]), _bits(expected[finite])), trial
    assert np.array_equal(motion_peaks(np.zeros((0, 3)), 0.01), np.zeros(3))


def _rotations(rng, n_rows: int) -> np.ndarray:
    return rng.normal(size=(n_rows, 4)) * 10 ** rng.uniform(-3, 3)


def test_the_quaternion_loops_are_scipys_rotation_to_the_bit():
    """``(R(q) * R(g).inv()).as_rotvec()`` and ``(R.from_rotvec(e) * R(g)).as_quat()``: random
    rotations of any scale, one goal or one per row, small angles (the series), half turns (a
    product with w = 0 exactly, where the sign convention decides) and opposite signs."""
    rng = np.random.default_rng(16)
    identity = np.array([[0.0, 0.0, 0.0, 1.0]])
    for trial in range(300):
        n_rows = int(rng.integers(1, 300))
        q = _rotations(rng, n_rows)
        goal = _rotations(rng, 1 if trial % 2 else n_rows)
        if trial % 5 == 1:  # near the goal: the small-angle series
            goal = q[:1] + rng.normal(size=(1, 4)) * 1e-7 if trial % 2 else q * (1 + 1e-9)
        if trial % 5 == 2:  # half turns from the identity: w = 0 in the product
            q[:, 3], goal = 0.0, identity
        if trial % 5 == 3:
            q[::2] = -q[::2]
        g = goal[0] if goal.shape[0] == 1 else goal
        expected = (Rotation.from_quat(q) * Rotation.from_quat(g).inv()).as_rotvec()
        assert np.array_equal(_bits(quaternion_log(q, goal)), _bits(expected.reshape(n_rows, 3)))
        error = rng.normal(size=(n_rows, 3)) * 10 ** rng.uniform(-6, 1.5)
        expected = (Rotation.from_rotvec(error) * Rotation.from_quat(g)).as_quat()
        assert np.array_equal(
            _bits(quaternion_exp(error, goal)), _bits(expected.reshape(n_rows, 4))
        )
    with pytest.raises(ValueError, match="goal"):
        quaternion_log(np.ones((3, 4)), np.ones((2, 4)))
    with pytest.raises(ValueError, match="goal"):
        quaternion_exp(np.ones((3, 3)), np.ones((2, 4)))


def _random_band_rows(rng, n_rows: int, n_columns: int) -> np.ndarray:
    """Rows of bumps at random places and widths over a floor of tiny values, some rows zero,
    some with a NaN, at random scales."""
    columns = np.arange(n_columns)
    centres = rng.uniform(-2, n_columns + 2, size=(n_rows, 1))
    widths = rng.uniform(0.3, n_columns / 3, size=(n_rows, 1))
    rows = np.exp(-(((columns - centres) / widths) ** 2)) * 10 ** rng.uniform(-5, 5, (n_rows, 1))
    rows *= rng.choice([-1.0, 1.0], size=rows.shape)
    rows[rng.random(n_rows) < 0.1] = 0.0
    nan_rows = rng.random(n_rows) < 0.05
    rows[nan_rows, rng.integers(0, n_columns, nan_rows.sum())] = np.nan
    return rows


def test_the_band_edges_are_the_plain_search():
    rng = np.random.default_rng(23)
    for _ in range(200):
        n_rows, n_columns = int(rng.integers(1, 60)), int(rng.integers(1, 40))
        rows = _random_band_rows(rng, n_rows, n_columns)
        share = 10 ** rng.uniform(-20, -1)
        first, last = band_of(rows, share)
        for i, row in enumerate(rows):
            size = np.abs(row)
            matters = ~(size <= share * np.nanmax(size)) if np.any(size > 0) else size != size
            where = np.flatnonzero(matters)
            expected = (where[0], where[-1]) if where.size else (0, 0)
            assert (first[i], last[i]) == expected, (i, row)


def test_the_band_products_are_the_plain_loops_to_the_bit():
    rng = np.random.default_rng(29)
    for _ in range(100):
        n_rows, n_columns = int(rng.integers(1, 40)), int(rng.integers(1, 30))
        width, n_dims = int(rng.integers(1, n_columns + 1)), int(rng.integers(1, 5))
        first = rng.integers(0, n_columns - width + 1, size=n_rows).astype(np.int64)
        values = rng.normal(size=(n_rows, width)) * 10 ** rng.uniform(-3, 3)
        weights = rng.normal(size=(n_columns, n_dims)) * 10 ** rng.uniform(-3, 3)
        target = rng.normal(size=(n_rows, n_dims))
        expected = np.zeros((n_rows, n_dims))
        for i in range(n_rows):
            for k in range(n_dims):
                total = 0.0
                for j in range(width):
                    total = total + values[i, j] * weights[first[i] + j, k]
                expected[i, k] = total
        assert np.array_equal(_bits(band_product(values, first, weights)), _bits(expected))
        expected = np.zeros((n_columns, n_dims))
        for i in range(n_rows):
            for j in range(width):
                expected[first[i] + j] = expected[first[i] + j] + values[i, j] * target[i]
        assert np.array_equal(
            _bits(band_transposed_product(values, first, target, n_columns)), _bits(expected)
        )


def test_a_basis_kept_as_a_band_multiplies_as_the_whole_rows_to_their_rounding():
    """What the band drops is below 1e-16 of each row's peak: on DMP bases of other sizes, rates
    and protocols, the band's products are the dense ones within the dense products' own
    rounding (a sum of N products: N ε Σ|terms|) plus what was dropped (at most 1e-16 of the
    row's peak times the weights' sizes)."""
    from bidmp import DMP
    from bidmp.primitives.band import _band_of

    rng = np.random.default_rng(31)
    for trial in range(12):
        n_steps = int(rng.integers(50, 1500))
        settings = {"n_kernels": int(rng.integers(10, 300))}
        if trial % 3 == 0:
            settings["protocol"] = "paper"
        y = np.cumsum(rng.normal(size=(n_steps, 3)), axis=0)
        dmp = DMP(**settings).fit(y, np.arange(n_steps) / rng.uniform(10, 1000))
        _, rows = dmp.grid_basis()
        band = _band_of(rows)
        assert band is not None and band.values.shape[1] < rows.shape[1] / 2
        weights, target = dmp.weights_, rng.normal(size=(rows.shape[0], 3))
        peaks, eps = np.abs(rows).max(axis=1, keepdims=True), np.finfo(float).eps
        bound = rows.shape[1] * eps * (np.abs(rows) @ np.abs(weights))
        bound += 1e-16 * peaks * np.abs(weights).sum(axis=0)
        assert np.all(np.abs(band.product(weights) - rows @ weights) <= bound)
        bound = rows.shape[0] * eps * (np.abs(rows).T @ np.abs(target))
        bound += 1e-16 * (peaks * np.abs(target)).sum(axis=0)
        assert np.all(np.abs(band.transposed_product(target) - rows.T @ target) <= bound)
    overlapping = np.ones((20, 10))  # every function everywhere: no band
    assert _band_of(overlapping) is None


def test_every_planted_bug_of_the_kernel_mutation_tool_still_has_its_place():
    """``make mutation``'s compiled-loop mutants (tools/mutation_kernels.py) are edits of the
    source: each must still find its one place in it and change something, or the tool would
    stop planting it without saying so (a structure check, not a correctness one)."""
    from pathlib import Path

    import mutation_kernels

    source = (Path(__file__).resolve().parents[1] / "src" / "bidmp" / "_kernels.pyx").read_text(
        encoding="utf-8"
    )
    assert len(mutation_kernels.MUTANTS) >= 20
    for mutant in mutation_kernels.MUTANTS:
        assert source.count(mutant.original) == 1, mutant.loop
        assert mutant.mutated != mutant.original, mutant.loop
