"""limits where the robot moves — the 1 kHz commands checked against velocity,
acceleration and jerk limits from rest to rest (closed forms) and the closed loop's jerk-limited
command generator on random targets (the simulated nut task's commands: tests/sim/test_sim.py)."""

import numpy as np
import pytest

from bidmp.sim.backend import LIMIT_MARGIN, SIM_STEP, JointLimits
from bidmp.sim.limits import _command_peaks, _RateLimiter

LIMITS = JointLimits(
    lower=(-3.0,) * 7,
    upper=(3.0,) * 7,
    velocity=(2.0,) * 7,
    acceleration=(10.0,) * 7,
    jerk=(5000.0,) * 7,
)


def quintic(amplitude: float, duration: float) -> np.ndarray:
    """A rest-to-rest minimum-jerk move of every joint, sampled every millisecond."""
    s = np.arange(0.0, duration + SIM_STEP / 2, SIM_STEP) / duration
    return np.outer(amplitude * (10 * s**3 - 15 * s**4 + 6 * s**5), np.ones(7))


def test_the_command_peaks_are_the_closed_forms_of_a_minimum_jerk_move():
    amplitude, duration = 0.8, 1.2
    peaks = _command_peaks(quintic(amplitude, duration), LIMITS)
    assert peaks.velocity == pytest.approx(1.875 * amplitude / duration / 2.0, rel=1e-3)
    assert peaks.acceleration == pytest.approx(5.7735 * amplitude / duration**2 / 10.0, rel=2e-3)
    assert peaks.jerk == pytest.approx(60 * amplitude / duration**3 / 5000.0, rel=2e-2)
    assert peaks.within


def test_a_move_that_starts_or_stops_with_an_acceleration_is_out_of_limits():
    """A clamped cubic (3s² − 2s³) starts and stops at zero velocity but with an acceleration of
    6A/T² (what a position interface refuses), although its velocity, acceleration and own jerk
    (12A/T³) are within the limits. Differenced from rest, as the interface does, its first
    command accelerates at (c₁ − c₀)/dt² = 3A/T², and the jump shows as that per millisecond in
    the jerk. The minimum-jerk move of the same size starts at rest."""
    amplitude, duration = 0.8, 1.2
    s = np.arange(0.0, duration + SIM_STEP / 2, SIM_STEP) / duration
    cubic = np.outer(amplitude * (3 * s**2 - 2 * s**3), np.ones(7))
    peaks = _command_peaks(cubic, LIMITS)
    assert (
        peaks.velocity < 1
        and peaks.acceleration < 1
        and 12 * amplitude / duration**3 < 0.01 * 5000.0
    )
    assert peaks.ends == pytest.approx(3 * amplitude / duration**2 / 10.0, rel=1e-2)
    assert peaks.jerk == pytest.approx(3 * amplitude / duration**2 / SIM_STEP / 5000.0, rel=2e-2)
    assert not peaks.within
    assert _command_peaks(quintic(amplitude, duration), LIMITS).ends < 0.01


@pytest.mark.parametrize("seed", range(4))
def test_the_rate_limiter_keeps_every_command_within_the_limits_and_comes_to_rest(seed):
    """Random 100 Hz targets — a smooth motion, a jump, a joint that stands still while its
    target runs on — through the 1 kHz generator: every command within the jerk and acceleration
    limits (velocity within 2 % of its margin), and at rest on a target that stops."""
    rng = np.random.default_rng(seed)
    n = 300
    t = np.arange(n) * 0.01
    targets = np.sin(np.outer(t, rng.uniform(0.5, 3.0, 7)) + rng.uniform(0, 6, 7)) * rng.uniform(
        0.1, 1.0, 7
    )
    targets[150:] += rng.uniform(-0.3, 0.3, 7)  # a jump
    targets[200:] = targets[200]  # then it stops
    limiter = _RateLimiter(targets[0], LIMITS, LIMIT_MARGIN)
    commands = []
    for previous, target in zip(np.vstack([targets[:1], targets[:-1]]), targets):
        for step in range(1, 11):
            commands.append(
                limiter(previous + step / 10 * (target - previous), (target - previous) / 0.01)
            )
    for _ in range(1000):  # a second of settling on the last target
        commands.append(limiter(targets[-1], np.zeros(7)))
    commands = np.array(commands)
    peaks = _command_peaks(commands, LIMITS)
    assert peaks.jerk <= LIMIT_MARGIN + 1e-9 and peaks.acceleration <= LIMIT_MARGIN + 1e-9
    assert peaks.velocity <= 1.02 * LIMIT_MARGIN
    np.testing.assert_allclose(commands[-1], targets[-1], atol=1e-6)
    assert np.max(np.abs(limiter.velocity)) < 1e-5 and np.max(np.abs(limiter.acceleration)) < 1e-3
