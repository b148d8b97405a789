"""JointLimits naming its FCI table: what the contract asks (JointLimits.reflex), and the table
names it accepts."""

from __future__ import annotations

import numpy as np
import pytest

from bidmp.sim.robots import FR3, PANDA, JointLimits

HOME = np.array([0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785])


def test_the_franka_arms_name_their_tables_and_others_none():
    assert PANDA.fci == "panda" and FR3.fci == "fr3"
    plain = JointLimits(PANDA.lower, PANDA.upper, PANDA.velocity, PANDA.acceleration)
    assert plain.jerk is None and plain.fci is None
    jump = np.repeat(HOME[None], 50, axis=0)
    jump[25:, 3] += 1e-4  # a 0.1 mrad jump: 100 rad/s² in one cycle
    assert plain.reflex(jump) == ""  # no table: nothing asked
    assert PANDA.reflex(jump).startswith("joint_motion_generator_velocity_discontinuity: joint 4")
    assert FR3.reflex(jump).startswith("joint_motion_generator_velocity_discontinuity: joint 4")
    assert FR3.reflex(np.repeat(HOME[None], 50, axis=0)) == ""


@pytest.mark.parametrize("fci", ["ur5", "Panda", ""])
def test_an_unknown_table_is_refused(fci):
    with pytest.raises(ValueError, match="JointLimits.fci must be 'panda' or 'fr3'"):
        JointLimits(PANDA.lower, PANDA.upper, PANDA.velocity, PANDA.acceleration, fci=fci)


def test_a_table_needs_seven_joints():
    six = [slice(0, 6)]
    with pytest.raises(ValueError, match="on a 7-joint arm"):
        JointLimits(
            *(tuple(np.asarray(v)[tuple(six)]) for v in (PANDA.lower, PANDA.upper, PANDA.velocity)),
            tuple(np.asarray(PANDA.acceleration)[:6]),
            fci="panda",
        )


def test_a_stated_jerk_is_checked_like_the_rest():
    with pytest.raises(ValueError, match="JointLimits.jerk"):
        JointLimits(PANDA.lower, PANDA.upper, PANDA.velocity, PANDA.acceleration, (-1.0,) * 7)
    limits = JointLimits(PANDA.lower, PANDA.upper, PANDA.velocity, PANDA.acceleration, [1] * 7)
    assert limits.jerk == (1.0,) * 7 and all(isinstance(v, float) for v in limits.jerk)
