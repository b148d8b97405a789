"""The FCI's Cartesian limits (bidmp.sim.fci.judge_cartesian) against closed forms: a straight
quintic move whose peak speed, acceleration and jerk are known, a turn about one axis at a known
rate, the published tables typed here."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bidmp.sim.fci import FCI_LIMITS, judge_cartesian

DT = 1e-3


def test_the_published_cartesian_tables():
    """Franka's control parameters (Panda) and libfranka >= 0.10's rate_limiting.h (FR3)."""
    panda, fr3 = FCI_LIMITS["panda"].cartesian, FCI_LIMITS["fr3"].cartesian
    assert panda.translation == (1.7, 13.0, 6500.0) and panda.rotation == (2.5, 25.0, 12500.0)
    assert panda.elbow == (2.175, 10.0, 5000.0)
    assert fr3.translation == (3.0, 9.0, 4500.0) and fr3.rotation == (2.5, 17.0, 8500.0)
    assert fr3.elbow == (1.5, 10.0, 5000.0)


def quintic_line(distance: float, duration: float) -> np.ndarray:
    """Positions (m) of a rest-to-rest quintic along a random direction: peak speed
    1.875 d / T, peak acceleration 5.7735 d / T² (closed forms)."""
    direction = np.random.default_rng(3).normal(size=3)
    direction /= np.linalg.norm(direction)
    u = np.linspace(0.0, 1.0, int(round(duration / DT)) + 1)[:, None]
    return np.array([0.4, 0.0, 0.5]) + distance * (10 * u**3 - 15 * u**4 + 6 * u**5) * direction


@pytest.mark.parametrize("robot", ["panda", "fr3"])
@pytest.mark.parametrize("share", [0.9, 1.1])
def test_a_straight_move_is_judged_by_its_peak_acceleration(robot, share):
    limits = FCI_LIMITS[robot].cartesian
    duration = 0.3
    distance = share * limits.translation[1] * duration**2 / 5.7735  # peak acceleration = share x
    assert 1.875 * distance / duration < limits.translation[0]  # the speed stays within
    verdict = judge_cartesian(quintic_line(distance, duration), robot=robot)
    if share < 1:
        assert verdict.ok, verdict.reason()
    else:
        assert verdict.reflex == "cartesian_motion_generator_velocity_discontinuity"
        assert verdict.axis == "translation" and verdict.quantity == "acceleration"
        # the first sample past the limit: over it, under the move's peak
        assert limits.translation[1] < verdict.value <= share * limits.translation[1] * 1.002
        assert verdict.bound == limits.translation[1]
        assert "the end effector's translation acceleration" in verdict.reason()


@pytest.mark.parametrize("robot", ["panda", "fr3"])
def test_a_turn_faster_than_the_rotational_limit_is_rejected(robot):
    """A turn about z at a steady 2.6 rad/s (over the 2.5 both publish), brought up smoothly
    enough that only its speed breaks a limit; the same turn at 2.4 rad/s passes."""
    for rate, ok in ((2.4, True), (2.6, False)):
        t = np.arange(0, 2.0, DT)
        ramp = np.clip(t / 1.0, 0, 1)
        speed = rate * ramp**3 * (10 - 15 * ramp + 6 * ramp**2)
        angle = np.concatenate([[0.0], np.cumsum(speed[1:]) * DT])
        speed_down = np.clip((t[-1] - t) / 1.0, 0, 1)  # and smoothly down again
        angle = np.concatenate(
            [
                angle,
                angle[-1]
                + np.cumsum(rate * (speed_down**3 * (10 - 15 * speed_down + 6 * speed_down**2)))
                * DT,
            ]
        )
        quaternions = Rotation.from_euler("z", angle[:, None]).as_quat()
        positions = np.tile([0.4, 0.0, 0.5], (len(angle), 1))
        verdict = judge_cartesian(positions, quaternions, robot)
        assert verdict.ok is ok, verdict.reason()
        if not ok:
            assert verdict.axis == "rotation" and verdict.quantity == "velocity"
            assert verdict.reflex == "cartesian_motion_generator_velocity_limits_violation"
            assert verdict.value == pytest.approx(2.5, abs=2e-3)


@pytest.mark.parametrize("robot", ["panda", "fr3"])
def test_a_stream_moving_at_its_end_jumps_to_rest_after_it(robot):
    """Brought smoothly to 20 mm/s and stopping there: held after its last command, the end
    effector stops in one cycle, an acceleration of 0.02 / dt = 20 m/s² (FR3: 9, Panda: 13)."""
    u = np.clip(np.arange(600) * DT / 0.3, 0.0, 1.0)
    speed = 0.02 * u**3 * (10 - 15 * u + 6 * u**2)
    x = np.concatenate([[0.0], np.cumsum(speed[1:]) * DT])
    positions = np.column_stack([0.4 + x, np.zeros_like(x), np.full_like(x, 0.5)])
    verdict = judge_cartesian(positions, robot=robot)
    assert not verdict.ok and verdict.after_end and verdict.sample == len(x)
    assert verdict.quantity == "acceleration" and verdict.value == pytest.approx(20.0, rel=1e-6)


@pytest.mark.parametrize(
    "positions, quaternions, match",
    [
        (np.zeros((5, 2)), None, "positions must have 3 columns"),
        (np.zeros((5, 3)), np.tile([0, 0, 0, 1.0], (4, 1)), "quaternions must be"),
        (np.full((5, 3), np.nan), None, "positions"),
    ],
)
def test_bad_streams_are_refused_by_name(positions, quaternions, match):
    with pytest.raises(ValueError, match=match):
        judge_cartesian(positions, quaternions)


def _turning(rates: np.ndarray) -> np.ndarray:
    """Quaternions (x, y, z, w) of a turn about z at ``rates`` (T,) rad/s, one per millisecond,
    from the identity at sample 0."""
    angle = np.concatenate([[0.0], np.cumsum(rates[1:]) * DT])
    return Rotation.from_euler("z", angle[:, None]).as_quat()


STILL = np.array([0.4, 0.0, 0.5])


def test_a_turn_from_its_first_command_jumps_from_rest_at_sample_one():
    """At rest before the first command (three samples of it); turning at 0.02 rad/s from the
    first: at sample 1 the angular velocity steps from 0 to 0.02, an acceleration of 20 rad/s²
    (FR3: 17)."""
    rates = np.full(300, 0.02)
    rates[-150:] = 0.0  # (then still, so the end is at rest: only the start breaks)
    quaternions = _turning(rates)
    quaternions[151:] = quaternions[150]
    verdict = judge_cartesian(np.tile(STILL, (300, 1)), quaternions, "fr3")
    assert (verdict.axis, verdict.quantity, verdict.sample) == ("rotation", "acceleration", 1)
    assert verdict.value == pytest.approx(20.0, rel=1e-6)


def test_a_turn_still_going_at_its_end_stops_after_its_last_command():
    u = np.clip(np.arange(800) * DT / 0.4, 0.0, 1.0)
    rates = 0.03 * u**3 * (10 - 15 * u + 6 * u**2)  # smoothly up to 0.03 rad/s, and still turning
    verdict = judge_cartesian(np.tile(STILL, (800, 1)), _turning(rates), "fr3")
    assert verdict.after_end and verdict.sample == 800 and verdict.quantity == "acceleration"
    assert verdict.value == pytest.approx(30.0, rel=1e-3)  # 0.03 rad/s to rest in 1 ms


def test_a_translation_jerk_alone_is_named_as_such():
    """An acceleration of 5 m/s² switched on at sample 100 (a jerk of 5 000 m/s³, over the FR3's
    4 500; the acceleration within its 9) for 20 ms, off, reversed, off: back at rest."""
    acceleration = np.zeros(400)
    acceleration[100:120], acceleration[160:180] = 5.0, -5.0
    velocity = np.cumsum(acceleration) * DT
    x = np.cumsum(velocity) * DT
    positions = STILL + x[:, None] * np.array([1.0, 0.0, 0.0])
    verdict = judge_cartesian(positions, robot="fr3")
    assert verdict.quantity == "jerk" and verdict.axis == "translation"
    assert verdict.reflex == "cartesian_motion_generator_acceleration_discontinuity"
    assert verdict.sample == 100 and verdict.value == pytest.approx(5000.0, rel=1e-6)
    assert judge_cartesian(positions, robot="panda").ok  # its jerk limit is 6 500


@pytest.mark.parametrize("rotation_first", [True, False])
def test_the_earlier_breach_is_the_verdict_whichever_axis(rotation_first):
    """A translation breaking its speed limit and a rotation breaking its own, one 100 samples
    before the other: the earlier one is named, with its sample."""
    n = 2000  # brought up over 1 s: every acceleration and jerk within its limits
    u = np.clip(np.arange(n) * DT / 1.0, 0.0, 1.0)
    ramp = u**3 * (10 - 15 * u + 6 * u**2)
    late = np.concatenate([np.zeros(100), ramp[:-100]])
    speed, turn = (3.1 * late, 2.6 * ramp) if rotation_first else (3.1 * ramp, 2.6 * late)
    x = np.concatenate([[0.0], np.cumsum(speed[1:]) * DT])
    positions = STILL + x[:, None] * np.array([0.0, 1.0, 0.0])
    first_fast = int(np.flatnonzero(np.diff(x) / DT > 3.0)[0]) + 1
    angle = np.concatenate([[0.0], np.cumsum(turn[1:]) * DT])
    first_turning = int(np.flatnonzero(np.abs(np.diff(angle)) / DT > 2.5)[0]) + 1
    verdict = judge_cartesian(positions, _turning(turn), "fr3")
    expected = ("rotation", first_turning) if rotation_first else ("translation", first_fast)
    assert (verdict.axis, verdict.sample) == expected
    assert verdict.quantity == "velocity"


def test_a_jump_at_the_last_command_is_the_commands_own_breach_not_the_holds():
    """A step of 10 µm at the very last command: the acceleration 10 m/s² there breaks the FR3's
    9 (and the hold after it breaks it again): the verdict is the last command's, sample T - 1,
    not after the end; a Cartesian verdict names no joint."""
    positions = np.tile(STILL, (200, 1))
    positions[-1, 2] += 1e-5
    verdict = judge_cartesian(positions, robot="fr3")
    assert verdict.sample == 199 and not verdict.after_end
    assert verdict.quantity == "acceleration" and verdict.joint == 0
