"""The rhythmic stepper's limits: a setting whose steady rhythm exceeds them is refused, and a
change is slowed until it keeps them (the checks that guard the robot; ``make mutation`` plants
bugs in them and these tests must catch each)."""

from __future__ import annotations

import numpy as np
import pytest
from test_rhythmic import _recording

from bidmp.primitives import RhythmicDMP


def test_limits_refuse_a_setting_and_set_the_transition():
    """With caps 3 % over the new setting's steady peaks, a change 0.8 -> 1.2 Hz, x1.5 and the
    anchor moved 150 mm stays within them on the whole command (velocity, acceleration, jerk by differences), the
    transition lengthened by the limits; a setting whose steady rhythm exceeds them is refused."""
    rng = np.random.default_rng(14)
    t, y, *_ = _recording(rng)
    model = RhythmicDMP().fit(y, t)
    dt = 0.002
    fast = model.trajectory(cycles=2, dt=dt, frequency=1.2, amplitude=1.5)
    jerk = np.linalg.norm(np.diff(fast.ydd, axis=0), axis=1) / dt
    limits = {
        "max_velocity": 1.03 * fast.peak_speed(),
        "max_acceleration": 1.03 * fast.peak_acceleration(),
        "max_jerk": 1.03 * jerk.max(),
    }
    free = model.stepper(frequency=0.8)
    stepper = model.stepper(frequency=0.8, limits=limits)
    samples = []
    for i in range(int(40.0 / dt)):
        if i == int(1.0 / dt):
            for each in (stepper, free):
                each.set_frequency(1.2)
                each.set_amplitude(1.5)
                each.set_anchor(model.anchor_ + [150.0, 0.0, 0.0])  # the centre moves too
            assert stepper.time_constant > free.time_constant
        samples.append(stepper.step(dt))
    velocity = np.array([s[1] for s in samples])
    acceleration = np.array([s[2] for s in samples])
    assert np.linalg.norm(velocity, axis=1).max() <= limits["max_velocity"]
    assert np.linalg.norm(acceleration, axis=1).max() <= limits["max_acceleration"]
    assert (np.linalg.norm(np.diff(acceleration, axis=0), axis=1) / dt).max() <= limits["max_jerk"]
    with pytest.raises(ValueError, match="frequency: at 2 Hz .* over max_velocity"):
        stepper.set_frequency(2.0)


def test_the_limits_are_checked_by_name_and_each_cap_alone_refuses():
    rng = np.random.default_rng(15)
    t, y, *_ = _recording(rng)
    model = RhythmicDMP().fit(y, t)
    fast = model.trajectory(cycles=1, dt=0.001, frequency=1.0)
    jerk = (np.linalg.norm(np.diff(fast.ydd, axis=0), axis=1) / 0.001).max()
    peaks = {
        "max_velocity": fast.peak_speed(),
        "max_acceleration": fast.peak_acceleration(),
        "max_jerk": jerk,
    }
    for key, peak in peaks.items():  # each cap alone, just under the 1 Hz rhythm's own peak
        stepper = model.stepper(frequency=0.5, limits={key: 0.97 * peak})
        with pytest.raises(ValueError, match=key):
            stepper.set_frequency(1.0)
        # just over it: accepted
        model.stepper(frequency=0.5, limits={key: 1.05 * peak}).set_frequency(1.0)
    with pytest.raises(ValueError, match="unknown key"):
        model.stepper(limits={"max_speed": 1.0})
    with pytest.raises(ValueError, match="max_velocity"):
        model.stepper(limits={"max_velocity": -1.0})
    with pytest.raises(ValueError, match="the start's settings"):
        model.stepper(limits={"max_velocity": 0.5 * peaks["max_velocity"]}, frequency=1.0)
