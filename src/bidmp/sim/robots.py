"""The robots the simulator models, whatever its backend: a :class:`RobotModel` (URDF, tool flange, joint limits,
motor efforts, rest pose) for any serial arm of six or more joints — built in: the Franka Panda (the
default) and the KUKA LBR iiwa 7 R800 of ``pybullet_data`` (7 joints), UFACTORY's xArm6 of
``pybullet_data`` and a UR5-class arm written from Universal Robots' published DH parameters (6
joints) — or one a scenario names by its own URDF; where a robot stands in a scenario; the checks on
points and joint seeds."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .._checks import (
    as_point,
    as_vector,
    check_bool,
    check_limit,
    check_path,
    check_real,
    short_token,
    shown_path,
)
from .backend import JointLimits, SimError
from .fci import FCI_LIMITS

__all__ = [
    "PANDA",
    "FR3",
    "IIWA",
    "XARM6",
    "UR5",
    "RobotModel",
    "ROBOT_MODELS",
    "ROBOT_NAMES",
    "robot_model",
    "robot_placement",
]

# m: the Cartesian path is subdivided so that IK points are at most this far apart
MAX_SAMPLE_SPACING = 5e-3
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
    fci="panda",
)

_EFFORT = [87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0]  # N m
GAIN = 1.0  # PyBullet's position and velocity gains, every joint: the stiffest its motors allow

# KUKA LBR iiwa 7 R800: axis ranges and speeds from KUKA's datasheet (±170/120/170/120/170/120/175°;
# 98, 98, 100, 130, 140, 180, 180 °/s). KUKA publishes no joint acceleration or jerk limits; these
# are assumed, 5x and 500x the speed limit per second (the Panda's own ratios are 3.4-7.7x and
# 1700-3800x), and named as assumptions wherever they are reported.
_DEG = np.pi / 180.0
_IIWA_SPEED = tuple(round(v * _DEG, 4) for v in (98.0, 98.0, 100.0, 130.0, 140.0, 180.0, 180.0))
IIWA = JointLimits(
    lower=tuple(round(-v * _DEG, 4) for v in (170.0, 120.0, 170.0, 120.0, 170.0, 120.0, 175.0)),
    upper=tuple(round(v * _DEG, 4) for v in (170.0, 120.0, 170.0, 120.0, 170.0, 120.0, 175.0)),
    velocity=_IIWA_SPEED,
    acceleration=tuple(round(5.0 * v, 3) for v in _IIWA_SPEED),
    jerk=tuple(round(500.0 * v, 1) for v in _IIWA_SPEED),
)


# UFACTORY xArm6: joint ranges from UFACTORY's SDK (its JOINT_LIMITS for the xArm6), 180 deg/s every
# joint (the xArm's datasheet). UFACTORY publishes no joint acceleration or jerk limits: assumed as
# for the iiwa, 5x and 500x the speed per second, and named as assumptions wherever reported.
_XARM_SPEED = (math.pi,) * 6
XARM6 = JointLimits(
    lower=(-2 * math.pi, -2.059488, -3.92699, -2 * math.pi, -1.692969, -2 * math.pi),
    upper=(2 * math.pi, 2.094395, 0.191986, 2 * math.pi, math.pi, 2 * math.pi),
    velocity=_XARM_SPEED,
    acceleration=tuple(round(5.0 * v, 4) for v in _XARM_SPEED),
    jerk=tuple(round(500.0 * v, 1) for v in _XARM_SPEED),
)
# A UR5-class arm: +-360 deg and 180 deg/s every joint (Universal Robots' UR5 datasheet); acceleration
# and jerk are not published: assumed like the xArm6's.
UR5 = JointLimits(
    lower=(-2 * math.pi,) * 6,
    upper=(2 * math.pi,) * 6,
    velocity=_XARM_SPEED,
    acceleration=XARM6.acceleration,
    jerk=XARM6.jerk,
)


# The Franka Research 3: its FCI's tables (bidmp.sim.fci.FCI_LIMITS["fr3"], sources named there):
# the ranges and top speeds its URDF gives libfranka, 10 rad/s² and 5000 rad/s³ every joint. (Its
# velocity limits also fall towards each stop: the FCI's own judge, bidmp.sim.fci, checks those.)
_FR3_FCI = FCI_LIMITS["fr3"]
FR3 = JointLimits(
    _FR3_FCI.lower,
    _FR3_FCI.upper,
    _FR3_FCI.velocity,
    _FR3_FCI.acceleration,
    _FR3_FCI.jerk,
    fci="fr3",
)
# The arms whose acceleration and jerk limits are assumptions (reports say so).
ASSUMED_LIMITS = {"iiwa", "xarm6", "ur5"}


@dataclass(frozen=True)
class RobotModel:
    """A serial arm of six or more joints for the PyBullet backend.

    Parameters
    ----------
    name : str
    urdf : str
        The URDF: a path, or one relative to ``pybullet_data``'s folder.
    flange : str
        The link the tool is mounted on (the scenario's tool hangs from it along its z axis).
    limits : JointLimits
        Position (rad), velocity (rad/s), acceleration (rad/s²) and jerk (rad/s³) limits, one value
        per joint from the base to the flange.
    rest : tuple of float
        The joints (rad) the arm starts from and IK is seeded with: the tool pointing down.
    effort : tuple of float
        Motor torques (N m) of PyBullet's position control.
    cut_at : str, optional
        A joint of the URDF from which on its text is dropped (the Panda's own hand).
    standoff : float
        Where the robot stands by default: this far (m) short of the work's nearest point.
    """

    name: str
    urdf: str
    flange: str
    limits: JointLimits
    rest: tuple
    effort: tuple
    cut_at: str | None = None
    standoff: float = 0.33
    # Whether ``rest`` was given (the built-in arms, a scenario's "robot": {"rest": ...}); a URDF
    # arm without one starts where it can work: bidmp.sim solves it from the demonstration's start.
    rest_given: bool = True

    def __post_init__(self) -> None:
        for name in ("name", "urdf", "flange"):
            value = getattr(self, name)
            if not isinstance(value, str) or not value or len(value) > 4096:
                raise TypeError(f"{name} must be a non-empty string, got {short_token(value, 30)}")
        if not isinstance(self.limits, JointLimits):
            raise TypeError(
                f"limits must be bidmp.sim.JointLimits, got {type(self.limits).__name__}"
            )
        n = self.limits.n_joints
        for name, positive in (("rest", False), ("effort", True)):
            object.__setattr__(
                self,
                name,
                tuple(as_vector(getattr(self, name), name, length=n, positive=positive).tolist()),
            )
        if self.cut_at is not None and (not isinstance(self.cut_at, str) or not self.cut_at):
            raise TypeError(
                f"cut_at must be a joint name or None, got {short_token(self.cut_at, 30)}"
            )
        object.__setattr__(
            self, "standoff", check_real(self.standoff, "standoff", positive=True, maximum=2.0)
        )
        object.__setattr__(self, "rest_given", check_bool(self.rest_given, "rest_given"))

    @property
    def n_joints(self) -> int:
        return self.limits.n_joints

    def to_dict(self) -> dict:
        return {"name": self.name, "urdf": self.urdf, "flange": self.flange}


PANDA_MODEL = RobotModel(
    "panda",
    "franka_panda/panda.urdf",
    "panda_link8",
    PANDA,
    _REST,
    tuple(_EFFORT),
    cut_at="panda_hand_joint",
)
# The iiwa stands further back than the Panda: its shoulder is 0.34 m up (the Panda's 0.33 m) and
# it does not reach points close in front of its base with the tool pointing down (the nut task's
# start, 0.33 m away: 47 mm short; from 0.43 m every point of the task within 5 µm).
IIWA_MODEL = RobotModel(
    "iiwa",
    "kuka_iiwa/model.urdf",
    "lbr_iiwa_link_7",
    IIWA,
    (0.0, 0.5, 0.0, -1.4, 0.0, 1.2, 0.0),
    (176.0, 176.0, 110.0, 110.0, 110.0, 40.0, 40.0),
    standoff=0.43,
)
# The xArm6's reach (0.7 m) and its shoulder 0.27 m up put it closer to the work than the Panda; the
# UR5's forearm offsets keep its wrist 0.11 m beside the tool, so it stands a little further back.
XARM6_MODEL = RobotModel(
    "xarm6",
    "xarm/xarm6_robot.urdf",
    "link6",
    XARM6,
    (0.0, -0.3, -1.2, 0.0, 1.5, 0.0),
    (50.0, 50.0, 32.0, 32.0, 32.0, 20.0),
    standoff=0.3,
)
UR5_MODEL = RobotModel(
    "ur5",
    str(Path(__file__).resolve().parents[1] / "data" / "robots" / "ur5_dh.urdf"),
    "flange",
    UR5,
    (math.pi, -math.pi / 2, math.pi / 2, -math.pi / 2, -math.pi / 2, 0.0),
    (150.0, 150.0, 150.0, 28.0, 28.0, 28.0),
    standoff=0.38,
)
# The FR3 shares the Panda's kinematics (its DH parameters) and stands where the Panda does; its
# URDF (tools/fr3_urdf.py) carries its own ranges: joint 6 turns to 4.52 rad, the Panda's to 3.75.
FR3_MODEL = RobotModel(
    "fr3",
    str(Path(__file__).resolve().parents[1] / "data" / "robots" / "fr3.urdf"),
    "fr3_link8",
    FR3,
    _REST,
    tuple(_EFFORT),
)
ROBOT_MODELS = {
    "panda": PANDA_MODEL,
    "fr3": FR3_MODEL,
    "iiwa": IIWA_MODEL,
    "xarm6": XARM6_MODEL,
    "ur5": UR5_MODEL,
}
ROBOT_NAMES = {
    "panda": "Franka Panda",
    "fr3": "Franka Research 3",
    "iiwa": "KUKA LBR iiwa 7 R800",
    "xarm6": "UFACTORY xArm6",
    "ur5": "UR5-class arm (DH model)",
}


def robot_model(spec, base_dir=None) -> RobotModel:
    """The arm a scenario's ``"robot"`` key names: ``"model"`` (one of :data:`ROBOT_MODELS`, default
    ``"panda"``), or its own ``"urdf"`` (inside the scenario's folder ``base_dir``, or shipped by
    ``pybullet_data``) with ``"flange"`` and ``"limits"`` ({"lower", "upper", "velocity",
    "acceleration", "jerk"}, one value per joint, rad) and optionally ``"rest"`` (one per joint, rad)
    and ``"effort"`` (one per joint, N m). The key is checked as a scenario file's is; the URDF must
    be a regular ``.urdf`` file within the file size limit. ``spec``: a scenario's
    :class:`~bidmp.tasks.RobotOptions`, or the key's dict, or None (the Panda)."""
    from ..tasks.options import RobotOptions
    from ..tasks.scenarios import check_robot

    if isinstance(spec, RobotOptions):  # a scenario's, checked when it loaded: its file form
        spec = spec.flat
    if spec is not None and not isinstance(spec, dict):
        raise TypeError(
            f'spec must be a scenario\'s "robot" (a bidmp.tasks.RobotOptions or its dict) or None, '
            f"got {type(spec).__name__}"
        )
    folder = "." if base_dir is None else check_path(base_dir, "base_dir")
    # Scenarios resolve their URDF when they load: here it may be absolute (the folder rule was applied then).
    spec = check_robot(spec, folder)
    if "urdf" not in spec:
        return ROBOT_MODELS[spec.get("model", "panda")]
    path = Path(spec["urdf"])
    if not path.is_absolute():
        local = Path(folder) / path
        if local.exists():
            path = local
        else:  # a model PyBullet ships (the sim extra)
            import pybullet_data

            path = Path(pybullet_data.getDataPath()) / path
    if not path.is_file():
        raise ValueError(
            f"robot.urdf {shown_path(spec['urdf'])}: no such regular file (a path in the scenario's "
            f"folder, or a model shipped by pybullet_data such as kuka_iiwa/model.urdf)"
        )
    check_limit(path.stat().st_size, "max_file_bytes", f"the size of {shown_path(path)} in bytes")
    links = _check_urdf_tree(path)
    if spec["flange"] not in links:
        raise ValueError(
            f"robot.urdf {shown_path(path)}: no link {shown_path(spec['flange'], 30)!r} to mount "
            f"the tool on (robot.flange; its links: {', '.join(sorted(links)[:12]) or 'none'})"
        )
    limits = JointLimits(**spec["limits"])
    middle = tuple(0.5 * (low + high) for low, high in zip(limits.lower, limits.upper))
    return RobotModel(
        path.stem,
        str(path),
        spec["flange"],
        limits,
        tuple(spec.get("rest", middle)),
        tuple(spec.get("effort", (100.0,) * limits.n_joints)),
        rest_given="rest" in spec,
    )


_URDF_EXTENT_M = 1e3  # m (and rad): no arm's joint or part is placed this far; more is a mistake


def _check_urdf_tree(path) -> set:
    """The link names of the URDF at ``path``, after checking it is one robot PyBullet can load
    without surprises: unique link and joint names, every joint's parent and child links present,
    each link the child of at most one joint, one root and no loop, finite origins within
    1000 (m or rad), and every mesh file inside the URDF's folder and within the file size limit
    (a loop, a missing parent or a NaN origin reached PyBullet, whose own error names none of
    them; a mesh link to a system file was followed). A ``ValueError`` says which and where."""
    import xml.etree.ElementTree as ElementTree

    path = Path(path)
    where = f"robot.urdf {shown_path(path)}"
    text = path.read_bytes()  # (its size checked by the caller: read once, whole)
    if b"<!DOCTYPE" in text or b"<!ENTITY" in text:  # entities that expand or read other files
        raise ValueError(f"{where}: declares a DOCTYPE or entities, which a URDF has no use for")
    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError as exc:
        raise ValueError(f"{where}: not well-formed XML ({exc})") from None
    except RecursionError:
        raise ValueError(f"{where}: its elements nest too deep to read") from None
    if root.tag != "robot":
        raise ValueError(f"{where}: its root element is <{root.tag}>, not <robot>")
    _check_depth(root, where)
    links = _unique_names(root, "link", where)
    _unique_names(root, "joint", where)
    _one_tree(links, _parents(root, links, where), where)
    for joint in root.findall("joint"):
        _check_joint(joint, where)
    for inertial in root.iter("inertial"):
        _check_numbers(inertial.find("mass"), ("value",), where, "a <mass>", nonnegative=True)
        _check_numbers(
            inertial.find("inertia"),
            ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"),
            where,
            "an <inertia>",
        )
    for link in root.findall("link"):  # (the joints' origins: checked with their joints)
        for origin in link.iter("origin"):
            _check_origin_element(origin, where, f"link {shown_path(link.get('name'), 30)!r}")
        for mesh in link.iter("mesh"):
            if mesh.get("filename"):
                _check_mesh(path, mesh.get("filename"), where)
    return set(links)


_URDF_DEPTH = 64  # a URDF nests a few levels (robot, link, visual, geometry, mesh); PyBullet's
# parser recurses per level: 100 000 nested elements would overflow its stack
_JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")


def _check_depth(root, where: str) -> None:
    """Refuse elements nested deeper than :data:`_URDF_DEPTH` (iteratively: no recursion here)."""
    stack = [(root, 1)]
    while stack:
        element, depth = stack.pop()
        if depth > _URDF_DEPTH:
            raise ValueError(f"{where}: elements nest deeper than {_URDF_DEPTH} levels")
        stack.extend((child, depth + 1) for child in element)


def _check_joint(joint, where: str) -> None:
    """A joint's type known to URDF, its axis a finite non-zero direction, its limits numbers."""
    name = f"joint {shown_path(joint.get('name'), 30)!r}"
    kind = joint.get("type")
    if kind not in _JOINT_TYPES:
        raise ValueError(
            f"{where}: {name} has type {shown_path(str(kind), 20)!r}; URDF's are {', '.join(_JOINT_TYPES)}"
        )
    axis = joint.find("axis")
    if axis is not None and kind != "fixed":
        values = _numbers(axis.get("xyz", "1 0 0"), where, f"{name}'s axis")
        # (a NaN or inf component fails the comparison: no direction either)
        if len(values) != 3 or not 1e-9 < math.hypot(*values) < 1e9:
            raise ValueError(f"{where}: {name}'s axis {axis.get('xyz')!r} is no direction")
    _check_numbers(
        joint.find("limit"), ("lower", "upper", "velocity", "effort"), where, f"{name}'s limit"
    )


def _numbers(text: str, where: str, what: str) -> list:
    """The numbers of a URDF attribute's text (not yet checked finite: each caller says what
    they must be)."""
    try:
        return [float(v) for v in text.split()]
    except ValueError:
        raise ValueError(f"{where}: {what} {shown_path(text, 30)!r} is not numbers") from None


def _check_numbers(element, keys: tuple, where: str, what: str, nonnegative: bool = False) -> None:
    """The attributes ``keys`` of ``element`` (when present) finite numbers (and >= 0)."""
    if element is None:
        return
    for key in keys:
        text = element.get(key)
        if text is None:
            continue
        values = _numbers(text, where, f"{what}'s {key}")
        if len(values) != 1 or not math.isfinite(values[0]):
            raise ValueError(
                f"{where}: {what}'s {key} {shown_path(text, 30)!r} must be one finite number"
            )
        if nonnegative and values[0] < 0:
            raise ValueError(f"{where}: {what}'s {key} {text!r} must be >= 0")


def _unique_names(root, kind: str, where: str) -> list:
    """The names of the URDF's ``kind`` elements, each present and used once."""
    names, seen = [element.get("name") for element in root.findall(kind)], set()
    for name in names:
        if name is None:
            raise ValueError(f"{where}: a <{kind}> has no name")
        if name in seen:
            raise ValueError(f"{where}: two {kind}s are named {shown_path(name, 30)!r}")
        seen.add(name)
    return names


def _parents(root, links: list, where: str) -> dict:
    """link -> its parent link, from the joints (each naming links of the file; a link the child
    of one joint at most)."""
    parent_of = {}
    for joint in root.findall("joint"):
        name = joint.get("name")
        ends = {end: joint.find(end) for end in ("parent", "child")}
        for end, element in ends.items():
            link = None if element is None else element.get("link")
            if link not in links:
                raise ValueError(
                    f"{where}: joint {shown_path(name, 30)!r} names {end} link "
                    f"{shown_path(str(link), 30)!r}, which is not a <link> of the file"
                )
        child = ends["child"].get("link")
        if child in parent_of:
            raise ValueError(f"{where}: link {shown_path(child, 30)} is the child of two joints")
        parent_of[child] = ends["parent"].get("link")
        origin = joint.find("origin")
        if origin is not None:
            _check_origin_element(origin, where, f"joint {shown_path(name, 30)!r}")
    return parent_of


def _one_tree(links: list, parent_of: dict, where: str) -> None:
    """One root, and every chain of parents ends there (no loop). (No link at all: the flange's
    check says so.)"""
    roots = [link for link in links if link not in parent_of]
    if not links:
        return
    if len(roots) != 1:
        raise ValueError(
            f"{where}: {len(roots)} links have no parent joint "
            f"({', '.join(roots[:6]) or 'none: the joints make a loop'}); a robot has one root"
        )
    for link in links:
        seen, at = set(), link
        while at in parent_of:
            if at in seen:
                raise ValueError(
                    f"{where}: the joints make a loop through link {shown_path(at, 30)}"
                )
            seen.add(at)
            at = parent_of[at]


def _check_origin_element(origin, where: str, what: str) -> None:
    for key in ("xyz", "rpy"):
        text = origin.get(key)
        if text is None:
            continue
        values = _numbers(text, where, f"{what}'s {key}")
        if len(values) != 3 or not all(
            math.isfinite(v) and abs(v) <= _URDF_EXTENT_M for v in values
        ):
            raise ValueError(
                f"{where}: {what}'s {key} {shown_path(text, 40)!r} must be 3 finite numbers within "
                f"±{_URDF_EXTENT_M:g} (m or rad)"
            )


def _check_mesh(urdf: Path, filename: str, where: str) -> None:
    """A mesh the URDF names: a file in the URDF's own folder (links followed), within the size
    limit; a ``package://`` name is left to PyBullet (it finds none outside its search path)."""
    if filename.startswith("package://"):
        return
    name = filename[len("file://") :] if filename.startswith("file://") else filename
    folder = urdf.resolve().parent
    mesh = (folder / name).resolve()
    if not mesh.is_relative_to(folder):
        raise ValueError(
            f"{where}: mesh {shown_path(filename, 40)} lies outside the URDF's folder "
            f"(meshes are read from beside it only)"
        )
    if mesh.exists():
        if not mesh.is_file():
            raise ValueError(f"{where}: mesh {shown_path(filename, 40)} is not a regular file")
        check_limit(
            mesh.stat().st_size, "max_file_bytes", f"the size of mesh {shown_path(mesh)} in bytes"
        )


def _unit_of(units: str) -> float:
    if not isinstance(units, str) or units not in _UNITS:
        raise ValueError(
            f"units: the simulator needs lengths in m, cm or mm, got {short_token(units)}"
        )
    return _UNITS[units]


def _unit_name(unit: float) -> str:
    return {1.0: "m", 1e-2: "cm", 1e-3: "mm"}[unit]


def robot_placement(scenario) -> tuple[np.ndarray, float]:
    """The robot's base (scenario units) and yaw (degrees): the scenario's ``"robot"`` key, or in
    front of the work: the arm's standoff (the Panda 330 mm, the iiwa 430 mm) short of the nearest
    point in y, centred in x, at the lowest target's height, facing +y."""
    if not all(
        hasattr(scenario, name) for name in ("robot", "target_array", "demonstration", "units")
    ):
        raise TypeError(
            f"scenario must be a bidmp scenario (bidmp.tasks.load), got {type(scenario).__name__}"
        )
    robot = scenario.robot
    robot = robot.flat if hasattr(robot, "flat") else (robot or {})
    if "base" in robot:
        return np.asarray(robot["base"], dtype=float), float(robot.get("yaw", 90.0))
    points = np.vstack([scenario.target_array, scenario.demonstration])
    unit = _unit_of(scenario.units)
    standoff = robot_model(robot, getattr(scenario, "base_dir", None)).standoff
    base = np.array(
        [
            0.5 * (points[:, 0].min() + points[:, 0].max()),
            points[:, 1].min() - standoff / unit,
            scenario.target_array[:, 2].min(),
        ]
    )
    return base, float(robot.get("yaw", 90.0))


_REACH_M = 2.0  # m from the base: far beyond a cobot's ~0.8-0.9 m, so a path past it is a mistake


def _reachable(point_m: np.ndarray, base_m: np.ndarray, name: str) -> np.ndarray:
    """Refuse a point (m) further than any cobot reaches from its base (a unit mistake, or a
    path that IK would chase for ever)."""
    distance = float(np.linalg.norm(point_m - base_m))
    if not distance <= _REACH_M:
        raise SimError(
            f"{name}: a point {distance:.3g} m from the robot's base, beyond the arm's reach "
            f"(the Panda's is 0.855 m); check the units and the base"
        )
    return point_m


def _working_rest(cell, point_m: np.ndarray, n_seeds: int = 32) -> np.ndarray | None:
    """Joints (rad) that put the tool's mouth at ``point_m`` (m) pointing down, within the limits
    and as far inside them as the solutions found allow: the start pose of an arm given without
    one (its ranges' middle is often a stretched or singular pose from which the demonstration's
    start cannot be solved). IK is started from the ranges' middle and from ``n_seeds`` seeded
    draws within the limits (each joint within half a turn of the middle: the same seeds every
    call); among the solutions that reach the point, the one whose nearest limit is farthest (as
    a fraction of that joint's range) wins. None when no seed reaches it."""
    limits = cell.limits
    lower, upper = np.asarray(limits.lower, float), np.asarray(limits.upper, float)
    middle = 0.5 * (lower + upper)
    half = np.minimum(0.5 * (upper - lower), np.pi)
    draws = np.random.default_rng(0).uniform(-1.0, 1.0, (n_seeds, len(lower)))
    best, best_room = None, -np.inf
    for seed in np.vstack([middle, middle + draws * half]):
        try:
            q, error = cell.solve_ik(point_m, seed)
        except SimError:
            continue
        q = np.asarray(q, dtype=float)
        if error > IK_TOLERANCE or np.any(q < lower - 1e-9) or np.any(q > upper + 1e-9):
            continue
        room = float(np.min(np.minimum(q - lower, upper - q) / (upper - lower)))
        if room > best_room:
            best, best_room = q, room
    return best


def _joint_seed(seed, limits: JointLimits = PANDA) -> np.ndarray:
    """Finite joint angles (rad), one per joint of the robot, within its limits, to start IK from."""
    q = as_point(seed, limits.n_joints, "seed")
    outside = (q < np.array(limits.lower) - 1e-6) | (q > np.array(limits.upper) + 1e-6)
    if outside.any():
        joint = int(np.argmax(outside))
        raise ValueError(
            f"seed: joint {joint + 1} at {q[joint]:.4g} rad is outside its limits "
            f"[{limits.lower[joint]}, {limits.upper[joint]}]"
        )
    return q
