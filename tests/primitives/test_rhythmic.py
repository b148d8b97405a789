"""Rhythmic DMPs: learned from recordings they were not tuned on, checked against the signal that
made the recording, closed forms and properties (periodicity, continuity), not against themselves."""

from __future__ import annotations

import math

import numpy as np
import pytest
from sklearn.base import clone

import bidmp
from bidmp.primitives import (
    AdaptiveOscillator,
    RhythmicDMP,
    RhythmicPhase,
    VonMisesBasis,
    estimate_frequency,
    harmonic_fit,
)

AMPLITUDE = 20.0  # mm


def _signal(phase: np.ndarray, scale: float = 1.0) -> np.ndarray:
    """A sum of sines in 3-D about (100, 100, 100) mm (the recording's clean motion)."""
    return 100.0 + scale * np.column_stack(
        [
            AMPLITUDE * np.sin(phase) + 0.3 * AMPLITUDE * np.sin(2 * phase + 0.5),
            0.6 * AMPLITUDE * np.cos(phase) + 0.2 * AMPLITUDE * np.sin(3 * phase),
            0.25 * AMPLITUDE * np.sin(phase + 1.0),
        ]
    )


def _recording(rng, frequency=0.8, periods=6, rate=250.0, noise=0.3, idle=1.0, ramp=0.6):
    """A logger's recording: jittered epoch stamps at ``rate``, idle ends, the rhythm ramping in
    and out, Gaussian noise (mm). Returns (t, y, clean, time from the first stamp)."""
    duration = periods / frequency + 2 * idle
    t = np.cumsum(rng.uniform(0.6, 1.4, int(duration * rate)) / rate) + 1.7e9
    s = t - t[0]
    envelope = np.clip((s - idle) / ramp, 0, 1) * np.clip((s[-1] - idle - s) / ramp, 0, 1)
    envelope = envelope**2 * (3 - 2 * envelope)
    clean = 100.0 + envelope[:, None] * (_signal(2 * np.pi * frequency * s) - 100.0)
    return t, clean + rng.normal(0.0, noise, clean.shape), clean, s


@pytest.mark.parametrize(
    ("seed", "frequency", "rate"), [(1, 0.8, 250.0), (2, 1.7, 100.0), (3, 0.45, 1000.0)]
)
def test_a_noisy_jittered_recording_is_learned_to_its_frequency_and_shape(seed, frequency, rate):
    """Frequency within 0.5 % (and within 5 standard errors of the estimate's own), reproduction
    RMSE within 2 % of the amplitude over the whole steady part; 100-1000 Hz stamps."""
    rng = np.random.default_rng(seed)
    t, y, clean, s = _recording(rng, frequency=frequency, rate=rate)
    model = RhythmicDMP().fit(y, t, units="mm")
    estimate = model.estimate_
    assert abs(model.frequency_ - frequency) <= 0.005 * frequency
    assert abs(model.frequency_ - frequency) <= 5 * estimate.uncertainty + 1e-6 * frequency
    assert estimate.periods >= 3
    # The transients are cut: the steady part starts past the middle of the ramp in and ends
    # before the middle of the ramp out (idle 1 s, ramp 0.6 s); the RMSE below, over the whole
    # kept part against the ramped clean signal, shows what is left of them.
    assert estimate.start >= 1.3
    assert estimate.end <= s[-1] - 1.3
    keep = (s >= estimate.start) & (s <= estimate.end)
    motion = model.trajectory(cycles=estimate.periods, dt=0.001)
    reproduced = np.column_stack(
        [np.interp(s[keep] - estimate.start, motion.t, column) for column in motion.y.T]
    )
    rmse = np.sqrt(np.mean(np.sum((reproduced - clean[keep]) ** 2, axis=1)))
    assert rmse <= 0.02 * AMPLITUDE, rmse
    # The period-to-period spread of a steady rhythm is the noise's share only.
    assert estimate.spread < 0.02


def test_the_spread_reports_periods_that_differ():
    """A recording whose every other period is 20 % larger reports a spread near the closed form
    (the RMS of ±10 % of the mean period's shape), the steady recording one near 0."""
    rng = np.random.default_rng(7)
    frequency, n = 1.0, 8 * 400
    t = np.arange(n) / 400.0
    phase = 2 * np.pi * frequency * t
    alternating = np.where(np.floor(t * frequency) % 2 == 0, 1.1, 0.9)
    y = 100.0 + alternating[:, None] * (_signal(phase) - 100.0)
    y += rng.normal(0.0, 0.01, y.shape)
    estimate = estimate_frequency(y, t, trim=False)
    mean_curve = _signal(np.linspace(0, 2 * np.pi, 256, endpoint=False)) - 100.0
    expected = 0.1 * np.sqrt(np.mean(mean_curve**2)) / (0.5 * np.ptp(mean_curve, axis=0).max())
    assert estimate.spread == pytest.approx(expected, rel=0.1)


def test_harmonic_fit_recovers_the_coefficients_of_a_known_series():
    """Closed form: y = 3 + 2 cos ωt - sin 2ωt sampled at jittered stamps."""
    rng = np.random.default_rng(4)
    t = np.cumsum(rng.uniform(0.002, 0.006, 2000))
    omega = 2 * np.pi * 1.3
    local = t - t[0]
    y = (3 + 2 * np.cos(omega * local) - np.sin(2 * omega * local))[:, None]
    a0, a, b = harmonic_fit(y, t, 1.3, 3)
    np.testing.assert_allclose(a0, [3.0], atol=1e-9)
    np.testing.assert_allclose(a[:, 0], [2.0, 0.0, 0.0], atol=1e-9)
    np.testing.assert_allclose(b[:, 0], [0.0, -1.0, 0.0], atol=1e-9)


def test_the_fundamental_is_found_when_a_harmonic_is_stronger():
    t = np.arange(4000) / 500.0
    phase = 2 * np.pi * 0.6 * t
    y = np.column_stack([0.4 * np.sin(phase) + np.sin(2 * phase)])
    assert estimate_frequency(y, t).frequency == pytest.approx(0.6, rel=1e-4)


def test_the_cycle_start_is_on_the_limit_cycle():
    """Property: started at ``cycle_start``, one period later the motion is where it started (the
    periodic solution), at other settings too."""
    rng = np.random.default_rng(5)
    t, y, *_ = _recording(rng)
    model = RhythmicDMP(n_kernels=30).fit(y, t)
    for frequency, amplitude in ((None, 1.0), (1.3, 0.5)):
        f = model.frequency_ if frequency is None else frequency
        dt = 1.0 / (f * 800)  # one period is 800 steps exactly
        motion = model.trajectory(cycles=1.0, dt=dt, frequency=frequency, amplitude=amplitude)
        assert motion.y.shape[0] == 801
        np.testing.assert_allclose(motion.y[-1], motion.y[0], atol=1e-9 * AMPLITUDE)
        np.testing.assert_allclose(motion.yd[-1], motion.yd[0], atol=1e-8 * AMPLITUDE * f)
        # Velocities are the positions' rate: compare with central differences.
        central = (motion.y[2:] - motion.y[:-2]) / (2 * dt)
        np.testing.assert_allclose(motion.yd[1:-1], central, atol=1e-3 * np.abs(central).max())


def test_the_amplitude_scales_the_oscillation_about_the_anchor():
    rng = np.random.default_rng(6)
    t, y, *_ = _recording(rng)
    model = RhythmicDMP().fit(y, t)
    anchor = model.anchor_ + [5.0, -3.0, 1.0]
    base = model.trajectory(cycles=2, anchor=anchor).y
    scaled = model.trajectory(cycles=2, amplitude=1.5, anchor=anchor).y
    np.testing.assert_allclose(scaled - anchor, 1.5 * (base - anchor), atol=1e-9 * AMPLITUDE)


def test_the_stepper_equals_the_trajectory_at_fixed_settings():
    rng = np.random.default_rng(8)
    t, y, *_ = _recording(rng)
    model = RhythmicDMP().fit(y, t)
    motion = model.trajectory(cycles=2, dt=0.001)
    stepper = model.stepper()
    stepped = np.array([stepper.step(0.001) for _ in range(motion.y.shape[0])])
    extent = np.ptp(motion.y, axis=0).max()
    np.testing.assert_allclose(stepped[:, 0], motion.y, atol=1e-9 * extent)
    np.testing.assert_allclose(stepped[:, 1], motion.yd, atol=1e-7 * extent)
    np.testing.assert_allclose(stepped[:, 2], motion.ydd, atol=1e-5 * extent)


def test_frequency_and_amplitude_changed_while_running_are_smooth():
    """0.8 -> 1.2 Hz and amplitude x1.5 mid-motion at 1 kHz: the peak jerk across the change is at
    most 1.2x the steady state's at the new setting, and no acceleration step: the largest change
    of acceleration per step across the change is at most the steady state's."""
    rng = np.random.default_rng(9)
    t, y, *_ = _recording(rng)
    model = RhythmicDMP().fit(y, t)
    dt = 0.001
    stepper = model.stepper(frequency=0.8)
    samples = []
    for i in range(int(12.0 / dt)):
        if i == int(2.0 / dt):
            stepper.set_frequency(1.2)
            stepper.set_amplitude(1.5)
        samples.append(stepper.step(dt)[2])
    acceleration = np.array(samples)
    jerk = np.linalg.norm(np.diff(acceleration, axis=0), axis=1) / dt
    steady = jerk[-int(2.5 / dt) :].max()  # the last 3 periods at 1.2 Hz
    across = jerk[int(1.5 / dt) : int(8.0 / dt)].max()
    assert across <= 1.2 * steady, across / steady
    assert stepper.frequency == pytest.approx(1.2, rel=1e-6)
    # A jump in a setting without the filter would show as a spike: the step in the command's
    # acceleration at the change is of the order of one sample's steady change.
    change = int(2.0 / dt)
    assert np.abs(acceleration[change + 1] - acceleration[change]).max() <= steady * dt * 1.2


def test_from_rest_into_the_rhythm_and_back_to_rest_at_the_anchor():
    """A discrete -> rhythmic -> discrete sequence: the run starts and ends at rest at the anchor
    (zero velocity and acceleration at both ends), runs at least the cycles asked, and its peak
    excursion reaches the steady rhythm's."""
    rng = np.random.default_rng(10)
    t, y, *_ = _recording(rng)
    model = RhythmicDMP().fit(y, t, units="mm")
    motion = model.run(4, dt=0.002)
    anchor = model.anchor_
    np.testing.assert_allclose(motion.y[0], anchor, atol=1e-12)
    assert np.abs(motion.yd[0]).max() == 0.0
    assert np.abs(motion.ydd[0]).max() <= 1e-9
    assert np.abs(motion.y[-1] - anchor).max() <= 1e-3 * AMPLITUDE * 1.1
    assert np.abs(motion.yd[-1]).max() * (1 / model.frequency_) <= 1e-3 * AMPLITUDE * 1.1
    steady = model.trajectory(cycles=1).y
    assert np.abs(motion.y - anchor).max() >= 0.9 * np.abs(steady - anchor).max()
    assert motion.t[-1] >= 4 / model.frequency_
    jerk = np.linalg.norm(np.diff(motion.ydd, axis=0), axis=1) / 0.002
    steady_motion = model.trajectory(cycles=2, dt=0.002)
    steady_jerk = np.linalg.norm(np.diff(steady_motion.ydd, axis=0), axis=1) / 0.002
    assert jerk.max() <= 1.2 * steady_jerk.max()


@pytest.mark.parametrize("guess", [0.8, 1.2])
def test_an_adaptive_oscillator_locks_onto_a_drifting_frequency_within_5_periods(guess):
    """A signal whose frequency drifts 10 % (1.0 -> 1.1 Hz over 20 s), the oscillator started 20 %
    off: within 2 % of the true frequency from period 5 on, to the end."""
    dt = 0.004
    n = int(20.0 / dt)
    t = np.arange(n) * dt
    frequency = 1.0 + 0.1 * t / 20.0
    phase = 2 * np.pi * np.cumsum(frequency) * dt
    y = 60.0 + 20.0 * (np.sin(phase) + 0.3 * np.sin(2 * phase + 0.5))
    oscillator = AdaptiveOscillator(guess, 1)
    estimates = np.empty(n)
    for i in range(n):
        oscillator.update([y[i]], dt)
        estimates[i] = oscillator.frequency
    cycles = np.cumsum(frequency) * dt
    late = cycles >= 5.0
    assert np.all(np.abs(estimates[late] - frequency[late]) <= 0.02 * frequency[late])
    # What it learned is a rhythmic DMP that reproduces the last period's shape.
    model = oscillator.to_dmp()
    motion = model.trajectory(cycles=1, dt=dt)
    assert np.ptp(motion.y[:, 0]) == pytest.approx(np.ptp(y[-int(1 / 1.1 / dt) :]), rel=0.1)


def test_components_and_conventions():
    """Structure guard: the phase wraps at 2π, the basis is periodic and normalised, the estimator
    clones (scikit-learn), and bad input is refused naming the argument."""
    phase = RhythmicPhase().grid(10, 1.0, 1.0)
    assert np.all((phase >= 0) & (phase < 2 * np.pi))
    basis = VonMisesBasis(12)
    centres, widths = basis.place(RhythmicPhase(), 100, 0.01)
    rows = basis.rows(np.array([0.3, 0.3 + 2 * np.pi, -0.3]), centres, widths)
    np.testing.assert_allclose(rows[0], rows[1], atol=1e-12)
    np.testing.assert_allclose(rows.sum(axis=1), 1.0)
    model = RhythmicDMP(n_kernels=20)
    assert clone(model).get_params() == model.get_params()
    with pytest.raises(ValueError, match="n_kernels"):
        RhythmicDMP(n_kernels=1).fit(np.zeros((50, 1)) + np.arange(50)[:, None], np.arange(50.0))
    with pytest.raises(ValueError, match="periods"):
        t = np.arange(300) / 100.0
        RhythmicDMP().fit(np.sin(2 * np.pi * 0.5 * t)[:, None], t)
    t, y, *_ = _recording(np.random.default_rng(0))
    fitted = RhythmicDMP(n_kernels=20).fit(y, t)
    with pytest.raises(ValueError, match="frequency"):
        fitted.stepper(frequency=-1.0)
    with pytest.raises(ValueError, match="anchor"):
        fitted.trajectory(anchor=[1.0, 2.0])


def test_is_not_fitted():
    from bidmp import NotFittedError

    with pytest.raises(NotFittedError):
        RhythmicDMP().trajectory()
    assert math.isfinite(RhythmicDMP().alpha)


def _pose_recording(rng, frequency=0.7, periods=6, rate=250.0, noise_deg=0.3):
    """A wrist rocking about a tilted orientation (rotation vectors up to 0.6 rad) while the tool
    circles: jittered stamps, noise on both parts (0.3 mm, 0.3 degrees)."""
    from scipy.spatial.transform import Rotation

    duration = periods / frequency
    t = np.cumsum(rng.uniform(0.6, 1.4, int(duration * rate)) / rate)
    phase = 2 * np.pi * frequency * t
    rocking = np.column_stack(
        [0.5 * np.sin(phase), 0.2 * np.sin(2 * phase + 0.4), 0.3 * np.sin(phase + 1.0)]
    )
    base = Rotation.from_euler("xyz", [0.3, -0.2, 1.0])
    clean = (Rotation.from_rotvec(rocking) * base).as_quat()
    noise = Rotation.from_rotvec(rng.normal(0.0, np.radians(noise_deg), rocking.shape))
    measured = (noise * Rotation.from_quat(clean)).as_quat()
    positions = _signal(phase)[:, :3]
    measured_positions = positions + rng.normal(0.0, 0.3, positions.shape)
    return t, np.hstack([measured_positions, measured]), clean, positions


def test_an_orientation_rhythm_is_learned_on_the_log_map():
    """Frequency within 0.5 %, orientation RMSE within 2 % of the rocking's amplitude (0.6 rad),
    positions within 2 % of theirs; the angular velocity equals the quaternions' own rate."""
    from bidmp.primitives import RhythmicPoseDMP, angle_between

    rng = np.random.default_rng(12)
    t, poses, clean_q, clean_p = _pose_recording(rng)
    model = RhythmicPoseDMP().fit(poses, t, units="mm")
    assert abs(model.frequency_ - 0.7) <= 0.005 * 0.7
    estimate = model.estimate_
    s = t - t[0]
    keep = (s >= estimate.start) & (s <= estimate.end)
    motion = model.trajectory(cycles=estimate.periods, dt=0.001)
    index = np.clip(np.round((s[keep] - estimate.start) / 0.001).astype(int), 0, len(motion.t) - 1)
    angles = angle_between(motion.q[index], clean_q[keep])
    assert np.sqrt(np.mean(angles**2)) <= 0.02 * 0.6
    position_error = np.linalg.norm(motion.y[index] - clean_p[keep], axis=1)
    assert np.sqrt(np.mean(position_error**2)) <= 0.02 * AMPLITUDE
    # ω against the quaternions' finite-difference rate: 2 (q̇ ⊗ q⁻¹), world frame.
    from scipy.spatial.transform import Rotation

    rotations = Rotation.from_quat(motion.q)
    relative = rotations[2:] * rotations[:-2].inv()
    rate = relative.as_rotvec() / (2 * 0.001)
    np.testing.assert_allclose(motion.omega[1:-1], rate, atol=1e-3 * np.abs(rate).max())


def test_rhythmic_models_survive_their_files(tmp_path):
    """A saved and loaded model rolls out the same motion (not pickles: bidmp.io model files)."""
    from bidmp.io import load_model, save_model
    from bidmp.primitives import RhythmicPoseDMP

    rng = np.random.default_rng(13)
    t, y, *_ = _recording(rng)
    model = RhythmicDMP(n_kernels=30).fit(y, t, units="mm")
    loaded = load_model(save_model(model, tmp_path / "rhythm"))
    np.testing.assert_array_equal(loaded.rollout(2, amplitude=1.3), model.rollout(2, amplitude=1.3))
    assert loaded.estimate_.periods == model.estimate_.periods and loaded.units_ == "mm"
    t, poses, *_ = _pose_recording(rng)
    pose_model = RhythmicPoseDMP(n_kernels=30).fit(poses, t)
    loaded = load_model(save_model(pose_model, tmp_path / "pose"))
    np.testing.assert_array_equal(loaded.trajectory(1).q, pose_model.trajectory(1).q)


@pytest.mark.parametrize(
    ("setting", "value", "name"),
    [
        ("frequency", 5e-324, "frequency"),
        ("frequency", 0.0, "frequency"),
        ("alpha", 5e-324, "alpha"),
    ],
)
def test_a_denormal_rate_or_gain_is_refused_by_name(setting, value, name):
    """A denormal frequency divided by zero (a ZeroDivisionError), a denormal spring made the
    period's transition singular (a LinAlgError): each is a ValueError naming the argument."""
    t = np.linspace(0.0, 4.0, 400)
    y = np.column_stack([np.sin(2 * np.pi * 1.3 * t), np.cos(2 * np.pi * 1.3 * t)])
    with pytest.raises(ValueError, match=rf"^{name} must be >= "):
        if setting == "frequency":
            RhythmicDMP().fit(y, t).trajectory(frequency=value)
        else:
            RhythmicDMP(alpha=value).fit(y, t)


def _small_rhythm(anchor: float = 0.0, amplitude: float = 20.0) -> RhythmicDMP:
    t = np.arange(400) / 100.0
    y = anchor + amplitude * np.column_stack(
        [np.sin(2 * np.pi * t), 0.5 * np.cos(4 * np.pi * t + 0.3)]
    )
    return RhythmicDMP(n_kernels=12).fit(y, t)


@pytest.mark.parametrize("settle", [1e-300, 5e-324, 1e-12])
def test_a_settle_below_the_rounding_is_refused_naming_its_smallest_value(settle):
    """A tiny settle never came true: the settling ran to the step limit (two million stepped
    samples, minutes). Under a small step limit the old code returned without a word."""
    model = _small_rhythm()
    with bidmp.set_limits(max_steps=20_000), pytest.raises(ValueError) as caught:
        model.run(2.0, dt=0.01, settle=settle)
    message = str(caught.value)
    assert message.startswith("settle must be >= 1e-09") and "\n" not in message


def test_a_rest_the_floats_cannot_resolve_is_refused_after_a_bounded_settling():
    """An anchor 1e9 times the amplitude: float64 resolves the rest only to a few 1e-6 of the
    amplitude, so settle = 1e-7 can never come true. The settling stops at its own bound (the
    filter's and spring's decay by settle: a few hundred samples, not the step limit) and says
    how near it came."""
    model = _small_rhythm(anchor=1e6, amplitude=1e-3)
    with bidmp.set_limits(max_steps=200_000), pytest.raises(ValueError) as caught:
        model.run(1.0, dt=0.01, settle=1e-7)
    message = str(caught.value)
    assert message.startswith("settle: ") and "give settle >= " in message
    floor = float(message.rsplit(">= ", 1)[1])
    # what it names is enough: the run then settles
    motion = model.run(1.0, dt=0.01, settle=floor)
    assert len(motion.t) < 3_000


@pytest.mark.parametrize("transition", [1e-300, 5e-324, 1e-9])
def test_a_transition_far_below_the_step_is_a_jump_of_the_settings(transition):
    """A time constant far below the step: the filter's output is its target after one step (the
    limit of the exact step as T -> 0), finite; inf times 0 made it NaN before. The run starts
    at the anchor, runs its cycles and settles there in bounded time."""
    model = _small_rhythm()
    with bidmp.set_limits(max_steps=20_000):
        motion = model.run(2.0, dt=0.01, transition=transition)
    assert np.all(np.isfinite(motion.y)) and np.all(np.isfinite(motion.ydd))
    assert len(motion.t) < 20 / (model.frequency_ * 0.01)
    np.testing.assert_allclose(motion.y[0], model.anchor_, atol=1e-12)
    assert np.abs(motion.y[-1] - model.anchor_).max() <= 1e-3 * model.amplitude_.max() * 1.01
    # the peak reaches the steady rhythm's at once: the amplitude jumped to 1
    steady = model.trajectory(cycles=1, dt=0.01).y
    assert np.abs(motion.y - model.anchor_).max() >= 0.95 * np.abs(steady - model.anchor_).max()


@pytest.mark.parametrize("seed", range(4))
def test_the_settling_bound_holds_for_settings_it_was_not_tuned_on(seed):
    """The bound on the settling (the filter's and the spring's decay by settle, a period at rest)
    is never what ends a run that can settle: random frequency, spring, transition, settle,
    step and amplitude each settle at the anchor within settle, at rest."""
    rng = np.random.default_rng(seed)
    frequency = float(rng.uniform(0.3, 3.0))
    t = np.arange(int(8 / frequency * 100)) / 100.0
    y = 50 + np.column_stack(
        [20 * np.sin(2 * np.pi * frequency * t), 10 * np.cos(4 * np.pi * frequency * t + 1)]
    )
    model = RhythmicDMP(n_kernels=12, alpha=float(rng.uniform(5.0, 100.0))).fit(y, t)
    settle = float(10 ** rng.uniform(-9, -0.5))
    amplitude = float(rng.uniform(0.2, 1.0))
    motion = model.run(
        float(rng.uniform(0.3, 3.0)),
        dt=float(rng.choice([0.001, 0.01])),
        transition=float(10 ** rng.uniform(-3, 0.3)),
        settle=settle,
        amplitude=amplitude,
    )
    scale = float(model.amplitude_.max()) * amplitude
    assert np.abs(motion.y[-1] - model.anchor_).max() <= settle * scale
    assert np.abs(motion.yd[-1]).max() / model.frequency_ <= settle * scale
