"""The Franka Panda as the PyBullet backend models it: joint limits, motor efforts and gains, the
rest pose, where it stands in a scenario, and the checks on points and joint seeds."""

from __future__ import annotations

import numpy as np

from ..._checks import as_point
from ..backend import JointLimits, SimError

__all__ = ["PANDA", "robot_placement"]

MAX_SAMPLE_SPACING = 5e-3  # m: the Cartesian path is subdivided so that IK points are at most this far apart
IK_TOLERANCE = 5e-5  # m: a sample whose IK leaves more than this (0.05 mm) is unreachable
IK_ACCURACY = 5e-6  # m: IK stops refining below this (tracking errors are ~100x larger)
_UNITS = {"m": 1.0, "cm": 1e-2, "mm": 1e-3}
_DOWN = (1.0, 0.0, 0.0, 0.0)  # quaternion (x, y, z, w): the flange's z axis pointing down
_REST = (0.0, -0.3, 0.0, -2.2, 0.0, 2.0, 0.785)

# Franka Emika Panda, from Franka's published robot and interface specifications.
PANDA = JointLimits(
    lower=(-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973),
    upper=(2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973),
    velocity=(2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100),
    acceleration=(15.0, 7.5, 10.0, 12.5, 15.0, 20.0, 20.0),
    jerk=(7500.0, 3750.0, 5000.0, 6250.0, 7500.0, 10000.0, 10000.0),  # Franka's datasheet, rad/s³
)

_EFFORT = [87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0]  # N m
_GAINS = [1.0] * 7  # PyBullet's position and velocity gains: the stiffest its motors allow


def _unit_of(units: str) -> float:
    if units not in _UNITS:
        raise ValueError(f"the simulator needs lengths in m, cm or mm; the scenario's units are {units!r}")
    return _UNITS[units]


def _unit_name(unit: float) -> str:
    return {1.0: "m", 1e-2: "cm", 1e-3: "mm"}[unit]


def robot_placement(scenario) -> tuple[np.ndarray, float]:
    """The robot's base (scenario units) and yaw (degrees): the scenario's ``"robot"`` key, or in
    front of the work: 330 mm short of the nearest point in y, centred in x, at the lowest
    target's height, facing +y."""
    if not all(hasattr(scenario, name) for name in ("robot", "target_array", "demonstration", "units")):
        raise TypeError(f"scenario must be a bidmp scenario (bidmp.scenarios.load), got {type(scenario).__name__}")
    robot = scenario.robot or {}
    if "base" in robot:
        return np.asarray(robot["base"], dtype=float), float(robot.get("yaw", 90.0))
    points = np.vstack([scenario.target_array, scenario.demonstration])
    unit = _unit_of(scenario.units)
    base = np.array([0.5 * (points[:, 0].min() + points[:, 0].max()), points[:, 1].min() - 0.33 / unit,
                     scenario.target_array[:, 2].min()])
    return base, float(robot.get("yaw", 90.0))


_REACH_M = 2.0  # m from the base: far beyond the Panda's 0.855 m, so a path past it is a mistake


def _reachable(point_m: np.ndarray, base_m: np.ndarray, name: str) -> np.ndarray:
    """Refuse a point (m) further than any Panda reaches from its base (a unit mistake, or a
    path that IK would chase for ever)."""
    distance = float(np.linalg.norm(point_m - base_m))
    if not distance <= _REACH_M:
        raise SimError(f"{name}: a point {distance:.3g} m from the robot's base, beyond the Panda's reach "
                       f"(0.855 m); check the units and the base")
    return point_m


def _joint_seed(seed) -> np.ndarray:
    """Seven finite joint angles (rad) within the Panda's limits, to start IK from."""
    q = as_point(seed, 7, "seed")
    outside = (q < np.array(PANDA.lower) - 1e-6) | (q > np.array(PANDA.upper) + 1e-6)
    if outside.any():
        joint = int(np.argmax(outside))
        raise ValueError(f"seed: joint {joint + 1} at {q[joint]:.4g} rad is outside its limits "
                         f"[{PANDA.lower[joint]}, {PANDA.upper[joint]}]")
    return q
