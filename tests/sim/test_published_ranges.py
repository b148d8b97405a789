"""Each built-in arm's joint ranges and speeds pinned to its maker's published table, typed here
in the maker's own units (degrees and degrees per second where the maker publishes those), not
read from the library. A range typed wrong in the library (a sign, a swapped pair, degrees left
as radians, one joint's value on another) lets the planner send a joint where the arm stops
with a fault, or judge a motion safe that is not: this fails first.

Sources (the numbers as published; the library's comments name the same):
- Franka Emika Panda (FER): Franka's "Robot and interface specifications" (FCI documentation),
  the joint-space limits q_min/q_max (rad), dq_max (rad/s), ddq_max (rad/s²), dddq_max (rad/s³).
- KUKA LBR iiwa 7 R800: KUKA's specification, axis ranges ±170, ±120, ±170, ±120, ±170, ±120,
  ±175 degrees and speeds 98, 98, 100, 130, 140, 180, 180 deg/s.
- UFACTORY xArm 6: the user manual's joint ranges J1 ±360, J2 -118..120, J3 -225..11, J4 ±360,
  J5 -97..180, J6 ±360 degrees; maximum joint speed 180 deg/s.
- Universal Robots UR5 (CB3): technical specifications, every joint ±360 degrees at 180 deg/s.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from bidmp import sim

DEG = math.pi / 180.0

PUBLISHED = {
    "panda": {
        "lower": [-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973],
        "upper": [2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973],
        "velocity": [2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100],
        "acceleration": [15, 7.5, 10, 12.5, 15, 20, 20],
        "jerk": [7500, 3750, 5000, 6250, 7500, 10000, 10000],
        "unit": 1.0,
    },
    "fr3": {  # the FR3's URDF as served to libfranka >= 0.10; libfranka >= 0.10's rates
        "lower": [-2.7501, -1.7918, -2.9065, -3.0481, -2.8101, 0.54092, -3.0196],
        "upper": [2.7501, 1.7918, 2.9065, -0.1458, 2.8101, 4.5205, 3.0196],
        "velocity": [2.62, 2.62, 2.62, 2.62, 5.26, 4.18, 5.26],
        "acceleration": [10] * 7,
        "jerk": [5000] * 7,
        "unit": 1.0,
    },
    "iiwa": {
        "lower": [-170, -120, -170, -120, -170, -120, -175],
        "upper": [170, 120, 170, 120, 170, 120, 175],
        "velocity": [98, 98, 100, 130, 140, 180, 180],
        "unit": DEG,
    },
    "xarm6": {
        "lower": [-360, -118, -225, -360, -97, -360],
        "upper": [360, 120, 11, 360, 180, 360],
        "velocity": [180] * 6,
        "unit": DEG,
    },
    "ur5": {
        "lower": [-360] * 6,
        "upper": [360] * 6,
        "velocity": [180] * 6,
        "unit": DEG,
    },
}


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_each_built_in_arm_has_its_makers_published_ranges_and_speeds(name):
    table = PUBLISHED[name]
    limits = sim.ROBOT_MODELS[name].limits
    unit = table["unit"]
    for key in ("lower", "upper", "velocity", "acceleration", "jerk"):
        if key not in table:
            continue
        published = np.asarray(table[key], dtype=float) * (
            1.0 if key in ("acceleration", "jerk") else unit
        )
        ours = np.asarray(getattr(limits, key), dtype=float)
        assert ours.shape == published.shape, (name, key)
        # The library rounds degrees to 1e-4 rad; the maker's radians are given to 1e-4.
        np.testing.assert_allclose(ours, published, atol=1.5e-4, rtol=0, err_msg=f"{name} {key}")
    assert limits.n_joints == len(table["lower"])


@pytest.mark.parametrize("name", sorted(PUBLISHED))
def test_each_arm_unpublished_limits_are_said_to_be_assumed_and_below_what_it_can_do(name):
    """Where a maker publishes no acceleration or jerk limits, the library's are assumptions: the
    report must say so (the arm is in the assumed set), and they must be positive per joint."""
    limits = sim.ROBOT_MODELS[name].limits
    published = {"acceleration", "jerk"} <= set(PUBLISHED[name])
    assert (name in sim.robots.ASSUMED_LIMITS) != published, name
    assert all(v > 0 for v in limits.acceleration) and all(v > 0 for v in limits.jerk)
