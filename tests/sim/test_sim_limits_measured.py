"""The measured joints' judge (bidmp.sim.limits._measured_breach) against closed forms: a joint
whose velocity ramps at a known acceleration, a velocity past its limit, a disturbance window."""

from __future__ import annotations

import numpy as np
import pytest

from bidmp.sim.limits import MEASURED_VELOCITY_NOISE, _measured_breach
from bidmp.sim.robots import PANDA

STEP = 0.002  # s: the simulator records every 2 ms


def ramp(joint: int, acceleration: float, start: float, end: float, n: int = 1500) -> np.ndarray:
    """Velocities (n, 7): joint ``joint`` accelerating at ``acceleration`` rad/s² from ``start``
    to ``end`` s, then steady; the others still."""
    t = np.arange(n) * STEP
    velocities = np.zeros((n, 7))
    velocities[:, joint] = acceleration * (np.clip(t, start, end) - start)
    return velocities


@pytest.mark.parametrize("joint", range(7))
def test_an_acceleration_just_past_the_limit_is_a_breach_and_just_under_is_not(joint):
    limit = PANDA.acceleration[joint]
    assert _measured_breach(ramp(joint, 0.98 * limit, 1.0, 1.1), STEP, PANDA) == ""
    breach = _measured_breach(ramp(joint, 1.02 * limit, 1.0, 1.1), STEP, PANDA)
    assert breach.startswith(f"the measured joint {joint + 1} accelerated at")
    assert f"(limit {limit:g};" in breach


def test_a_disturbance_is_not_the_arms_own_acceleration_but_its_velocity_always_counts():
    stop = ramp(1, -40.0, 2.0, 2.005)  # a held joint stopped in 5 ms: 40 rad/s²
    assert _measured_breach(stop, STEP, PANDA)  # counted without the window
    assert _measured_breach(stop, STEP, PANDA, disturbed=(2.0, 2.5)) == ""
    # the same stop 50 ms after the window: the arm's own
    assert _measured_breach(ramp(1, -40.0, 2.56, 2.565), STEP, PANDA, disturbed=(2.0, 2.5))
    fast = ramp(0, 5.0, 0.5, 0.5 + (PANDA.velocity[0] + MEASURED_VELOCITY_NOISE + 0.01) / 5.0)
    breach = _measured_breach(fast, STEP, PANDA, disturbed=(0.0, 3.0))
    assert breach.startswith("joint_velocity_violation: the measured joint 1 moved at")


def _target(verdict, breach: str):
    from bidmp.sim.report import SimTarget

    return SimTarget(
        label="1",
        commanded_error=0.0,
        measured_error=100.0,  # (the verdict decides, not this field)
        approach_error=None,
        engaged=None,
        contacts={},
        peak_velocity=0.1,
        peak_acceleration=0.1,
        measured_peak_velocity=0.1,
        measured_peak_acceleration=0.1,
        motion_time=1.0,
        tracking_error=0.0,
        within_limits=not breach,
        verdict=verdict,
        measured_breach=breach,
    )


def test_a_measured_breach_fails_a_target_the_contract_passes():
    """The verdict the robot acts on: the contract's (on the measured tool and the commands) and
    the measured joints' both count, whichever fails; the breach is the reason."""
    from bidmp.tasks.contract import Contract

    path = np.linspace([0.0, 0.0, 50.0], [0.0, 0.0, 0.0], 200)
    verdict = Contract(1.75, 25.0, None, "mm").judge(path, np.zeros(3))
    assert verdict.ok
    breach = "the measured joint 2 accelerated at -8.21 rad/s² at 3.510 s (limit 7.5)"
    assert _target(verdict, "").task_success(1.75) and _target(verdict, "").reason == ""
    failed = _target(verdict, breach)
    assert not failed.task_success(1.75) and failed.reason == breach
    missed = Contract(1.75, 25.0, None, "mm").judge(path, np.array([0.0, 5.0, 0.0]))
    assert not missed.ok and not _target(missed, "").task_success(1.75)
    both = _target(missed, breach).reason
    assert both.startswith(missed.reason()) and both.endswith("; " + breach)


def test_a_velocity_breach_either_way_and_the_first_of_them_is_named():
    """Velocities past the limit plus 0.1 rad/s of noise allowance, negative too; the first in
    time is the one named (its time in the message); within the allowance is no breach."""
    limit = PANDA.velocity[2]
    steady = np.zeros((3000, 7))  # brought to limit + 0.05 at 1 rad/s², within the allowance
    steady[:, 2] = np.minimum(np.arange(3000) * STEP * 1.0, limit + 0.05)
    assert _measured_breach(steady, STEP, PANDA) == ""
    velocities = np.zeros((100, 7))
    velocities[60, 2] = -(limit + MEASURED_VELOCITY_NOISE + 0.01)
    velocities[70, 4] = PANDA.velocity[4] + 1.0
    breach = _measured_breach(velocities, STEP, PANDA)
    assert breach.startswith("joint_velocity_violation: the measured joint 3 moved at -2.28")
    assert "at 0.120 s" in breach


def test_the_acceleration_is_estimated_over_10_ms_not_from_one_sample_to_the_next():
    """A single 2 ms blip of 0.05 rad/s is 25 rad/s² between neighbouring samples but at most
    5 rad/s² over 10 ms windows: noise, not a breach (joint 1's limit is 15)."""
    velocities = np.zeros((100, 7))
    for at in range(40, 46):  # wherever the blip falls against the 10 ms grid
        blip = velocities.copy()
        blip[at, 0] = 0.05
        assert _measured_breach(blip, STEP, PANDA) == ""


def test_the_disturbance_window_edges():
    """Samples 2⁻⁷ s apart (one difference each, every time exact in binary): over (1.0, 2.0) a
    difference that ends at 1.0 or inside is the disturbance's; one that begins at 2.0 is the
    arm's own resumption and counts, as does one that ends before 1.0."""
    step, limit = 2.0**-7, PANDA.acceleration[0]
    jump = 1.01 * limit * step  # one difference of 1.01 x the limit: 0.12 rad/s

    def with_jump_ending_at(end: float) -> np.ndarray:
        velocities = np.zeros((400, 7))
        velocities[int(round(end / step)) :, 0] = jump
        return velocities

    last_before, first_after = 1.0 - step, 2.0 + step
    for end, counted in (
        (last_before, True),
        (1.0, False),
        (1.5, False),
        (2.0, False),
        (first_after, True),
    ):
        breach = _measured_breach(with_jump_ending_at(end), step, PANDA, disturbed=(1.0, 2.0))
        assert bool(breach) is counted, (end, breach)
        if counted:
            assert f"at {end:.3f} s" in breach


def test_no_samples_no_breach():
    assert _measured_breach(np.zeros((0, 7)), STEP, PANDA) == ""
    assert _measured_breach(np.zeros((1, 7)), STEP, PANDA) == ""


def test_a_runs_contacts_reach_the_verdict_in_the_scenes_unit():
    """The backend measures in metres; the verdict is in the scene's unit: a contact 2 mm deep
    (0.002 m) is 2.0 in a millimetre scene, and fails the motion."""
    from types import SimpleNamespace

    from bidmp.sim.report import _judged
    from bidmp.tasks.contract import Contract

    path_m = np.linspace([0.0, 0.0, 0.05], [0.0, 0.0, 0.0], 100)
    run = SimpleNamespace(
        tcp=path_m,
        tcp_orientation=None,
        commands=None,
        contacts={"post": 0.002},
        joint_velocities=np.zeros((100, 7)),
        disturbed=None,
    )
    task = SimpleNamespace(axes={}, alignment_threshold=None)
    contract = Contract(1.75, 25.0, None, "mm")
    verdict, breach = _judged(task, ("1", np.zeros(3)), run, 0.001, (PANDA, contract, ()))
    assert verdict.contacts == {"post": pytest.approx(2.0)} and not verdict.ok
    assert verdict.end_error == pytest.approx(0.0) and breach == ""
