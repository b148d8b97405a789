"""An arm's inverse kinematics without a task: joint goals for a joint-space DMP, and a Cartesian
motion turned into joint positions sample by sample (what a ``JointTrajectory`` carries).

Points are in the world's frame, in ``units``, the robot's base at ``base`` turned by ``yaw``
about z (defaults: the origin and 0, so that x is forward from the base); the tool points down
(z of the flange towards -z) unless orientations are given. Uses the
PyBullet backend's arm models (``"panda"``, ``"iiwa"`` or a :class:`RobotModel`).
"""

from __future__ import annotations

import numpy as np

from .._checks import _as_bounded_array, as_points, check_choice, check_limit, check_real
from .backend import SimError

__all__ = ["inverse_kinematics", "joint_names"]


def _arm(robot, units: str, tool_length: float, base=(0.0, 0.0, 0.0), yaw: float = 0.0):
    from ..scene import Scene, Tool
    from .pybullet.cell import RobotCell
    from .robots import ROBOT_MODELS, RobotModel

    if isinstance(robot, str):
        if robot not in ROBOT_MODELS:
            raise ValueError(
                f"robot must be one of {', '.join(ROBOT_MODELS)} (or a RobotModel), got {robot[:20]!r}"
            )
        robot = ROBOT_MODELS[robot]
    if not isinstance(robot, RobotModel):
        raise TypeError(f"robot must be a name or a RobotModel, got {type(robot).__name__}")
    # A tool up to 10 m long (no arm carries a longer one), in the points' units.
    length = check_real(
        tool_length,
        "tool_length",
        nonnegative=True,
        maximum={"m": 10.0, "cm": 1e3, "mm": 1e4}[units],
    )
    # No parts: the cell needs only the tool (its mouth is the point IK places).
    scene = Scene([], Tool(radius=0.01 if units == "m" else 10.0, length=max(length, 1e-6)))
    return RobotCell(scene, units, base, yaw, robot)


def _seed(seed, n_joints: int) -> np.ndarray:
    from .._checks import as_point

    return as_point(seed, n_joints, "seed")


def joint_names(robot="panda") -> list[str]:
    """The names of the arm's driven joints, base to flange, as in its URDF."""
    with _arm(robot, "m", 0.0) as cell:
        return list(cell.joint_names)


def inverse_kinematics(  # noqa: PLR0913 - the public call spells its options out, as users pass them
    points,
    robot="panda",
    *,
    units: str = "m",
    tool_length: float = 0.0,
    seed=None,
    orientations=None,
    base=(0.0, 0.0, 0.0),
    yaw: float = 0.0,
) -> np.ndarray:
    """Joint positions (n, J) rad (J the arm's joints) that put the tool's mouth on each of
    ``points`` (n, 3), each solved from the previous one (the first from ``seed``, default the
    arm's rest pose).

    Parameters
    ----------
    points : array (n, 3) or (3,)
        In ``units`` ("m", "cm" or "mm").
    robot : {"panda", "fr3", "iiwa", "xarm6", "ur5"} or RobotModel
    tool_length : float
        From the flange to the tool's mouth, in ``units`` (0: the flange itself).
    seed : array (J,), optional
    orientations : array (n, 4), optional
        The tool frame's quaternions (x, y, z, w); default pointing down.
    base, yaw : array (3,), float
        Where the robot stands (``units``) and its turn about z (degrees; 90: facing +y).

    Raises
    ------
    SimError
        A point the arm does not reach (within 0.05 mm) or that needs a joint beyond its limits,
        named by its index.
    """
    from .robots import IK_TOLERANCE

    units = check_choice(units, "units", ("m", "cm", "mm"))
    array = _as_bounded_array(points, "points", 2)
    single = array.ndim == 1
    path = as_points(array[None] if single else array, 3, "points")
    check_limit(
        path.shape[0],
        "max_samples",
        "points: the number of points (each an inverse kinematics solve)",
    )
    if orientations is not None:
        from ..primitives.so3 import as_quaternions

        orientations = as_quaternions(orientations, "orientations")
        if len(orientations) != len(path):
            raise ValueError(
                f"orientations must be one quaternion per point ({len(path)}), got {len(orientations)}"
            )
    from .._checks import as_point

    base = as_point(base, 3, "base")
    yaw = check_real(yaw, "yaw")
    with _arm(robot, units, tool_length, base, yaw) as cell:
        lower, upper = np.array(cell.limits.lower), np.array(cell.limits.upper)
        # A seed is only where the search starts: one outside this arm's limits (another arm's
        # recording) starts from the nearest joints within them.
        q = (
            np.array(cell.model.rest, dtype=float)
            if seed is None
            else np.clip(_seed(seed, cell.n_joints), lower, upper)
        )
        joints = np.empty((len(path), cell.n_joints))
        for index, point in enumerate(path):
            turn = None if orientations is None else orientations[index]
            start = q
            q, error = cell.solve_ik(point * cell.unit, start, turn)
            # a seed far off: the rest pose
            if error > IK_TOLERANCE and index == 0 and seed is not None:
                q, error = cell.solve_ik(
                    point * cell.unit, np.array(cell.model.rest, dtype=float), turn
                )
            if error > IK_TOLERANCE or np.any(q < lower - 1e-9) or np.any(q > upper + 1e-9):
                raise SimError(
                    f"points[{index}] {np.round(point, 4).tolist()} {units} is out of the {cell.model.name}'s "
                    f"reach from its base (inverse kinematics leaves {error / cell.unit:.3g} {units})"
                )
            joints[index] = q
    return joints[0] if single else joints
