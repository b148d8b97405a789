"""Random users' cells that stress the arm's routes, an oracle of which targets have one, and the
checks of what the arm did — written here, not taken from the pipeline.

**The cells** (:func:`route_cell`): a grid of 2-3 x 2-4 nuts on a plate, in some cells the columns
farthest from the demonstrated nut on a face tilted 10-30 degrees (then every target is a pose);
tall posts placed by the arm's own links (under the forearm of a configuration that reaches a
target: the links must go round them), a shorter post between the demonstrated nut and a column
(the targets behind it), the bin either where the tool pointing down puts the wrist at its
singularity (found by a scan of this module's inverse kinematics: two of the wrist's axes within a
few degrees of parallel) or at an easy place beside the work; five arms (the Panda, the FR3, the
xArm6, the UR5 and a URDF arm with no rest pose: the ABB IRB 1200 or the TM5-like arm of
tests/data, copied beside the scenario); mm, cm or m. The same seed gives the same cell.

**The oracle** (:class:`RouteOracle`), independent of the pipeline's planner and seed: a target
has a route when a configuration of the arm at the top of its final approach (1.1 approach heights
up the target's axis) is joined to the start (the rest pose; an arm given without one: the
solution at the demonstration's start, tool pointing down, farthest inside its limits, the rule
bidmp documents) by :func:`bidmp.planning.plan_route` with plain RRT (not the pipeline's
RRT-Connect), a seed of the oracle's own and 20 times the pipeline's budget of configurations
tested, and the arm follows the approach straight down the axis (inverse kinematics every 2 mm,
each joint step free). The free space is the tool kept the scene's margin plus the 0.5 mm bidmp
allows for the arm's tracking (stated here, not imported), a part's stand-off instead of the
margin, and the links that 0.5 mm (the contract asks them only not to touch), from every part of
the job's scene (the bin too) but the target's own nut. The
goal configurations come from an inverse kinematics of this module: SciPy's bounded least squares
on pinocchio's forward kinematics (the tool's mouth and axis, its turn about the axis free), from
96 seeds of its own. The IK oracle: whether any solution within the limits puts the tool's mouth
on the target along its axis.

**The checks** of every motion that ran, in the simulator and in the job: the tool (a cylinder on
the measured mouth, its frame the forward kinematics of the 1 kHz commands) clear of every part but
the target's own (and the nuts already taken away) by the margin (a stand-off where declared),
from points of the tool's surface against each part in closed form (boxes, cylinders, hexagonal
prisms in their own frames; along each of 48 lines of the tool's side the distance is convex,
minimised by golden section), which can only overstate the distance: it shows a violation, it
cannot raise a false alarm. The commands' velocity, acceleration and jerk by differences taken
here, their positions within the joints' ranges; a task success's end, its descent down the
target's axis (rising at most 0.15 mm) and, for a pose, the tool's axis within 2 degrees of it.
"""

from __future__ import annotations

import math
import shutil
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

from bidmp.demonstrations import minimum_jerk

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "data"
UNITS = {"mm": 1.0, "cm": 0.1, "m": 1e-3}  # scene units per mm
ARMS = ("panda", "fr3", "xarm6", "ur5", "urdf")
DOWN = Rotation.from_euler("x", 180.0, degrees=True)  # the tool pointing down
# The URDF arms: their file, flange, axis ranges (+-deg or (lower, upper)) and speeds (deg/s)
URDF_ARMS = {
    "irb1200": (
        DATA / "irb1200" / "irb1200.urdf",
        ((-170, 170), (-100, 135), (-200, 70), (-270, 270), (-130, 130), (-400, 400)),
        (288, 240, 297, 400, 405, 600),
    ),
    "tm5_like": (
        DATA / "tm5_like" / "tm5_like.urdf",
        ((-270, 270), (-180, 180), (-155, 155), (-180, 180), (-180, 180), (-270, 270)),
        (180, 180, 180, 225, 225, 225),
    ),
}
# mm: how far short of the grid's first row each arm stands (its shoulder height and reach)
STANDOFF_MM = {
    "panda": 330.0,
    "fr3": 330.0,
    "xarm6": 300.0,
    "ur5": 380.0,
    "irb1200": 300.0,
    "tm5_like": 330.0,
}
# bidmp plans its repairs and the arm's routes this much wider than the margin (the simulated
# arm's tool strays up to 0.3 mm from its command): the oracle's routes keep it too; the contract
# asks the links only not to touch, so they keep this much from the parts, the tool the margin too
ALLOWANCE_MM = 0.5
PIPELINE_CHECKS = 40_000  # the arm's route's budget in bidmp.sim.routes (stated, not imported)
ORACLE_CHECKS = 20 * PIPELINE_CHECKS
ORACLE_SEED = 7_654_321  # the oracle's RRT and IK seeds: none of the cells' (0 to a few hundred)
IK_SEEDS = 96
IK_POSITION = 1e-5  # m: a solution puts the mouth this close (the pipeline accepts 5e-5)
IK_AXIS = 1e-4  # rad between the tool's axis and the one asked for
RISE_MM = 0.15  # the contract's allowed rise inside the final approach, in mm (stated)
ALIGNMENT_DEG = 2.0  # the contract's alignment threshold for a pose (the scenarios' default)
TOP = 1.1  # the oracle's final approach starts this many approach heights up the target's axis
WRIST_SINGULAR_DEG = 3.0  # a bin "at the singularity": its wrist axes within this of parallel


# ---------------------------------------------------------------------------------------------
# The arm's kinematics and an inverse kinematics of the test's own
# ---------------------------------------------------------------------------------------------
def _pin():
    import pinocchio

    return pinocchio


class Kinematics:
    """The arm standing at ``base`` (m) turned ``yaw`` degrees, with the tool: forward kinematics
    from pinocchio's model of its URDF (``bidmp.sim.arm_geometry.ArmGeometry``, checked against
    PyBullet's and a published DH table by test_arm_routes.py), an inverse kinematics of its own
    (SciPy's bounded least squares, the limits as bounds), the wrist's axes."""

    def __init__(self, robot, tool_radius_m: float, tool_length_m: float, base_m, yaw: float):
        from bidmp.sim.arm_geometry import ArmGeometry

        self.robot = robot
        self.geometry = ArmGeometry(robot, tool_radius_m, tool_length_m, base_m, yaw)
        self.model = self.geometry.model
        self.data = self.model.createData()
        self.tcp = self.geometry.tcp
        self.turn = self.geometry.rotation
        self.base = np.asarray(base_m, dtype=float)
        self.lower = np.asarray(robot.limits.lower, dtype=float)
        self.upper = np.asarray(robot.limits.upper, dtype=float)
        n = self.lower.size
        self.wrist = (3, 5) if n == 6 else (4, 6)

    def pose(self, q) -> tuple[np.ndarray, np.ndarray]:
        """The tool's mouth (m) and frame (3, 3) in the world at joints ``q``."""
        pin = _pin()
        pin.framesForwardKinematics(self.model, self.data, np.asarray(q, dtype=float))
        placed = self.data.oMf[self.tcp]
        return self.turn @ placed.translation + self.base, self.turn @ placed.rotation

    def poses(self, joints) -> tuple[np.ndarray, np.ndarray]:
        """Mouths (n, 3) and frames (n, 3, 3) at joints (n, J)."""
        out = [self.pose(q) for q in np.asarray(joints, dtype=float)]
        return np.array([p for p, _ in out]), np.array([r for _, r in out])

    def origins(self, q) -> np.ndarray:
        """The joints' origins (J, 3) m in the world, base to flange."""
        pin = _pin()
        pin.forwardKinematics(self.model, self.data, np.asarray(q, dtype=float))
        return np.array(
            [
                self.turn @ self.data.oMi[j].translation + self.base
                for j in range(1, self.model.njoints)
            ]
        )

    def wrist_angle(self, q) -> float:
        """Degrees between the wrist's outer two axes (joints 4 and 6 of a 6-axis arm, 5 and 7 of a
        7-axis one): zero where the wrist is singular."""
        pin = _pin()
        pin.computeJointJacobians(self.model, self.data, np.asarray(q, dtype=float))
        a, b = (self.data.J[3:, k] for k in self.wrist)
        cosine = abs(float(a @ b)) / (np.linalg.norm(a) * np.linalg.norm(b))
        return float(np.degrees(np.arccos(min(cosine, 1.0))))

    def solve(self, point_m, axis, q0) -> tuple[np.ndarray, float, float]:
        """Joints within the limits putting the mouth at ``point_m`` with the tool's z axis along
        ``axis`` (its turn free), from ``q0``: (q, position error m, axis error rad).

        Levenberg-Marquardt (Marquardt's scaling, the damping raised on a step that does not
        lower the squared error and lowered on one that does) on the mouth's position and the
        tool's axis (0.1 m per unit of its difference), each step projected onto the joints'
        ranges: the test's own, not the pipeline's damped least squares."""
        target = self.turn.T @ (np.asarray(point_m, dtype=float) - self.base)
        wanted = self.turn.T @ (np.asarray(axis, dtype=float) / np.linalg.norm(axis))
        q = np.clip(np.asarray(q0, dtype=float), self.lower, self.upper)
        residual, jacobian = self._residual(q, target, wanted)
        cost, damping = float(residual @ residual), 1e-3
        for _ in range(300):
            if cost < 1e-20:
                break
            normal = jacobian.T @ jacobian
            gradient = jacobian.T @ residual
            step = np.linalg.solve(normal + damping * np.diag(np.diag(normal) + 1e-9), -gradient)
            trial = np.clip(q + step, self.lower, self.upper)
            trial_residual, trial_jacobian = self._residual(trial, target, wanted)
            trial_cost = float(trial_residual @ trial_residual)
            if trial_cost < cost:
                q, residual, jacobian, cost = trial, trial_residual, trial_jacobian, trial_cost
                damping = max(damping * 0.3, 1e-12)
            else:
                damping *= 10.0
                if damping > 1e10:
                    break
        position, rotation = self.pose(q)
        error = float(np.linalg.norm(position - np.asarray(point_m, dtype=float)))
        turn = float(np.arccos(np.clip(rotation[:, 2] @ (self.turn @ wanted), -1.0, 1.0)))
        return q, error, turn

    def _residual(self, q, target, wanted) -> tuple[np.ndarray, np.ndarray]:
        """The position and axis residual (6,) in the base's frame and its Jacobian (6, J)."""
        pin = _pin()
        model, data, tcp = self.model, self.data, self.tcp
        full = pin.computeFrameJacobian(model, data, q, tcp, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        pin.updateFramePlacements(model, data)
        frame = data.oMf[tcp]
        z = frame.rotation[:, 2]
        skew = np.array([[0.0, -z[2], z[1]], [z[2], 0.0, -z[0]], [-z[1], z[0], 0.0]])
        weight = 0.1  # m per unit of the axis' difference
        residual = np.concatenate([frame.translation - target, weight * (z - wanted)])
        return residual, np.vstack([full[:3], -weight * skew @ full[3:]])

    def seeds(self, first=(), count: int = IK_SEEDS, seed: int = ORACLE_SEED) -> np.ndarray:
        """Where the inverse kinematics starts: ``first`` (rows), the ranges' middle, then seeded
        draws (each joint within half a turn of its range's middle)."""
        middle = 0.5 * (self.lower + self.upper)
        half = np.minimum(0.5 * (self.upper - self.lower), np.pi)
        draws = np.random.default_rng(seed).uniform(-1.0, 1.0, (count, self.lower.size))
        rows = [np.asarray(q, dtype=float) for q in first] + [middle]
        return np.vstack([*rows, middle + draws * half])[:count]

    def solutions(self, point_m, axis, seeds, enough: int = 1, accept=None) -> list:
        """Distinct solutions (at least 0.05 rad apart in some joint) from ``seeds``, up to
        ``enough``, each passing ``accept(q)`` if given."""
        found = []
        for seed in seeds:
            q, error, turn = self.solve(point_m, axis, seed)
            if error > IK_POSITION or turn > IK_AXIS:
                continue
            if any(np.max(np.abs(q - other)) < 0.05 for other in found):
                continue
            if accept is not None and not accept(q):
                continue
            found.append(q)
            if len(found) >= enough:
                break
        return found

    def working_rest(self, point_m) -> np.ndarray | None:
        """The start of an arm given without a rest pose, by the rule bidmp documents: joints that
        put the mouth at ``point_m`` pointing down, the one farthest inside its limits (as a
        share of each joint's range) among the solutions found."""
        solutions = self.solutions(point_m, [0.0, 0.0, -1.0], self.seeds(), enough=IK_SEEDS)
        if not solutions:
            return None
        room = [
            float(np.min(np.minimum(q - self.lower, self.upper - q) / (self.upper - self.lower)))
            for q in solutions
        ]
        return solutions[int(np.argmax(room))]


def robot_of(spec: dict, folder):
    """The scenario's arm (a bidmp RobotModel), its URDF found in ``folder``."""
    from bidmp.sim import robot_model

    return robot_model(spec["robot"], folder)


def kinematics_of(spec: dict, folder) -> Kinematics:
    """The scenario's arm where it stands, with its tool, in metres."""
    f = UNITS[spec["units"]]
    metre = 1e-3 / f  # m per scene unit
    tool = spec["scene"]["tool"]
    return Kinematics(
        robot_of(spec, folder),
        tool["radius"] * metre,
        tool["length"] * metre,
        np.asarray(spec["robot"]["base"], dtype=float) * metre,
        float(spec["robot"]["yaw"]),
    )


def start_joints(kinematics: Kinematics, spec: dict, first=None) -> np.ndarray | None:
    """Where the arm starts: its rest pose, or (a URDF arm given without one) the documented rule
    at the demonstration's start (``first``, scene units; default the first of its points)."""
    robot = kinematics.robot
    if robot.rest_given:
        return np.asarray(robot.rest, dtype=float)
    metre = 1e-3 / UNITS[spec["units"]]
    first = spec["demonstration"]["points"][0] if first is None else first
    return kinematics.working_rest(np.asarray(first[:3], dtype=float) * metre)


# ---------------------------------------------------------------------------------------------
# The cells
# ---------------------------------------------------------------------------------------------
@dataclass
class CellFacts:
    """What a drawn cell holds, for the report: its arm, units, grid, the targets on the tilted
    face and its tilt, the posts (placed by the links, or between the demonstration and a
    column) and the targets behind the latter, where the bin is (``"wrist 0.4 deg"``: the tool
    pointing down there puts the wrist's axes that near parallel; ``"easy"``)."""

    seed: int
    arm: str
    units: str
    grid: tuple
    tilted: list
    tilt: str
    posts: dict
    behind: list
    bin: str
    folder: Path  # where the arm's URDF is (a URDF arm), for the generator's own checks


def route_cell(seed: int) -> tuple[dict, dict]:
    """The scenario dict of cell ``seed`` and the files to copy beside it (name -> source path):
    the same cell for the same seed (module docstring)."""
    spec, files, _ = draw_cell(seed)
    return spec, files


def draw_cell(seed: int) -> tuple[dict, dict, CellFacts]:
    """:func:`route_cell` and the cell's :class:`CellFacts`. A draw whose parts overlap, whose
    arm's start touches a post or the bin, or whose bin the arm cannot drop into pointing down,
    is drawn again from the same generator (so the same seed still gives the same cell)."""
    rng = np.random.default_rng(seed)
    kind = ARMS[seed % len(ARMS)]
    arm = kind if kind != "urdf" else ("irb1200", "tm5_like")[(seed // len(ARMS)) % 2]
    units = str(rng.choice(list(UNITS)))
    for _ in range(50):
        drawn = _draw(rng, seed, arm)
        if drawn is not None:
            spec, files, facts = drawn
            facts.units = units
            return _in_units(spec, units), files, facts
    raise RuntimeError(f"cell {seed}: no valid draw in 50 tries")


def _urdf_robot(arm: str, folder_name: bool) -> dict:
    path, ranges, speeds = URDF_ARMS[arm]
    deg = math.pi / 180.0
    return {
        "urdf": path.name if folder_name else str(path),
        "flange": "flange",
        "limits": {
            "lower": [low * deg for low, _ in ranges],
            "upper": [high * deg for _, high in ranges],
            "velocity": [v * deg for v in speeds],
            "acceleration": [5 * v * deg for v in speeds],  # not published: 5x the speed per s
            "jerk": [500 * v * deg for v in speeds],  # not published: 500x
        },
    }


def _draw(rng, seed: int, arm: str):  # noqa: C901, PLR0915 - one cell, drawn part by part
    """One draw of the cell in mm (None when it is not valid)."""
    rows, cols = int(rng.integers(2, 4)), int(rng.integers(2, 5))
    pitch = float(rng.uniform(42, 55))
    across, nut_height = float(rng.uniform(10, 14)), float(rng.uniform(5, 8))
    stud = {"radius": float(rng.uniform(2.5, across / 2 - 1.5)), "above": float(rng.uniform(6, 12))}
    sink = float(rng.uniform(1.6, 3.0))
    tool = {"radius": float(rng.uniform(9, 13)), "length": float(rng.uniform(90, 130))}
    margin = float(rng.uniform(1.2, 3.0))
    approach = float(rng.uniform(20, 30))
    tilted_count = int(rng.integers(1, min(2, cols - 1) + 1)) if rng.uniform() < 0.7 else 0
    about = str(rng.choice(["x", "y"]))
    angle = float(rng.uniform(10, 30) * rng.choice([-1.0, 1.0]))
    side = float(
        rng.choice([-1.0, 1.0])
    )  # the demonstrated nut left (-1) or right (+1) of the grid
    base = np.array([rng.uniform(-150, 150), rng.uniform(-150, 150), rng.uniform(-80, 0) - sink])
    standoff = STANDOFF_MM[arm] + float(rng.uniform(0, 40))
    shift = float(rng.uniform(-60, 60))
    circum = across / math.sqrt(3.0)
    keep = tool["radius"] + margin + circum + 4.0  # a post's surface this far from a nut's axis
    plate_top = -sink
    # the grid: columns along x, rows along y (away from the arm); the tilted columns are those
    # farthest from the demonstrated nut, 25 mm further out
    xs = base[0] + shift + (np.arange(cols) - (cols - 1) / 2.0) * pitch
    ys = base[1] + standoff + np.arange(rows) * pitch
    order = np.arange(cols) if side > 0 else np.arange(cols)[::-1]  # nearest the demo last
    tilted_cols = set(order[:tilted_count].tolist())
    xs = xs + np.array([-side * 25.0 if c in tilted_cols else 0.0 for c in range(cols)])
    flat_cols = [c for c in range(cols) if c not in tilted_cols]
    demo_x = (xs[flat_cols].max() if side > 0 else xs[flat_cols].min()) + side * rng.uniform(
        80, 120
    )
    demo_y = float(ys[int(rng.integers(rows))])
    down = DOWN.as_quat().tolist()
    pose = tilted_count > 0
    targets, nuts = {"demo": [demo_x, demo_y, 0.0]}, [("demo", [demo_x, demo_y, plate_top], None)]
    tilt = Rotation.from_euler("xyz", [angle, 0, 0] if about == "x" else [0, angle, 0], True)
    turn = tilt.as_euler("xyz", degrees=True).tolist()
    parts = []
    if pose:
        face_cols = sorted(tilted_cols)
        centre = np.array([xs[face_cols].mean(), ys.mean(), 0.0])
        size = [(len(face_cols) - 1) * pitch + 50.0, (rows - 1) * pitch + 50.0, 5.0]
        corners = np.array(
            [
                [sx * size[0] / 2, sy * size[1] / 2, z]
                for sx in (-1, 1)
                for sy in (-1, 1)
                for z in (0, -5)
            ]
        )
        centre[2] = plate_top + 3.0 - tilt.apply(corners)[:, 2].min() + rng.uniform(0, 15)
        parts.append(
            {
                "type": "box",
                "label": "face",
                "at": (centre - tilt.apply([0, 0, 5.0])).tolist(),
                "size": size,
                "rotation": turn,
            }
        )
    for c in range(cols):
        for r in range(rows):
            label = f"c{c + 1}r{r + 1}"
            if c in tilted_cols:
                seat = centre + tilt.apply([xs[c] - centre[0], ys[r] - centre[1], 0.0])
                targets[label] = (seat + tilt.apply([0, 0, sink])).tolist()
                nuts.append((label, seat.tolist(), turn))
            else:
                targets[label] = [float(xs[c]), float(ys[r]), 0.0]
                nuts.append((label, [float(xs[c]), float(ys[r]), plate_top], None))
    flat_x = [demo_x, *xs[flat_cols]]
    plate_lower = np.array([min(flat_x) - 50, ys.min() - 50])
    plate_upper = np.array([max(flat_x) + 50, ys.max() + 50])
    parts.insert(
        0,
        {
            "type": "plate",
            "label": "plate",
            "at": [*((plate_lower + plate_upper) / 2).tolist(), plate_top],
            "size": [*(plate_upper - plate_lower).tolist(), 5.0],
        },
    )
    nut = {"across_flats": across, "height": nut_height, "stud": stud}
    for label, at, rotation in nuts:
        parts.append(
            {
                "type": "nut",
                "label": label,
                "at": at,
                **nut,
                **({"rotation": rotation} if rotation else {}),
            }
        )
    axes = {
        label: (
            tilt.apply([0, 0, 1.0])
            if (pose and label in _tilted_labels(tilted_cols, rows))
            else np.array([0, 0, 1.0])
        )
        for label in targets
    }
    nut_xy = np.array([np.asarray(point)[:2] for point in targets.values()])

    def on_plate(xy) -> bool:
        return bool(np.all(xy >= plate_lower) and np.all(xy <= plate_upper))

    def clear_of_nuts(xy, radius) -> bool:
        return bool(np.all(np.linalg.norm(nut_xy - xy, axis=1) >= keep + radius))

    # a post between the demonstrated nut and a column (the targets behind it), 60-130 mm tall
    posts, behind = {}, []
    column = int(rng.choice(flat_cols))
    row = int(np.argmin(np.abs(ys - demo_y)))
    radius = float(rng.uniform(4, 8))
    for share in rng.uniform(0.3, 0.7, 10):
        xy = np.array([demo_x, demo_y]) + share * (
            np.array([xs[column], ys[row]]) - [demo_x, demo_y]
        )
        xy[1] += rng.uniform(-0.3, 0.3) * pitch
        if clear_of_nuts(xy, radius):
            parts.append(
                {
                    "type": "cylinder",
                    "label": "post0",
                    "at": [*xy.tolist(), plate_top],
                    "radius": radius,
                    "height": float(rng.uniform(60, 130)),
                }
            )
            posts["post0"] = "between"
            behind = [
                f"c{c + 1}r{r + 1}"
                for c in range(cols)
                if (xs[c] - xy[0]) * -side > 0
                for r in range(rows)
            ]
            break
    folder = URDF_ARMS[arm][0].parent if arm in URDF_ARMS else DATA
    robot = {"model": arm} if arm not in URDF_ARMS else _urdf_robot(arm, folder_name=True)
    robot.update({"base": base.tolist(), "yaw": 90.0})
    start = np.array(
        [demo_x + rng.uniform(-60, 60), demo_y - rng.uniform(80, 130), rng.uniform(150, 230)]
    )
    hover = np.array([demo_x, demo_y, approach + rng.uniform(10, 40)])
    demo = minimum_jerk(np.array([start, hover, targets["demo"]]), int(rng.integers(150, 400)))
    if pose:
        targets = {
            label: [
                *point,
                *(
                    (tilt * DOWN).as_quat().tolist()
                    if label in _tilted_labels(tilted_cols, rows)
                    else down
                ),
            ]
            for label, point in targets.items()
        }
        demo = np.hstack([demo, np.tile(down, (demo.shape[0], 1))])
    spec = {
        "name": f"route-cell-{seed}",
        "units": "mm",
        "targets": targets,
        "demonstrated": "demo",
        "demonstration": {"points": demo.tolist()},
        "success_threshold": 1.75,
        "approach_height": approach,
        "methods": ["bidmp"],
        "seed": seed,
        "robot": robot,
        "scene": {
            "tool": tool,
            "margin": margin,
            "standoff": {"plate": 1.0, **({"face": 1.0} if pose else {})},
            "parts": parts,
        },
        "job": {
            "steps": ["approach", "engage", "unscrew", "retract", "drop"],
            "order": str(rng.choice(["listed", "shortest"])),
            "pitch": float(rng.uniform(1.0, 1.5)),
            "bin": {"at": [0.0, 0.0, plate_top], "size": [70.0, 70.0, 40.0]},
        },
    }
    kinematics = kinematics_of(spec, folder)
    first = start_joints(kinematics, spec)
    if first is None:
        return None
    # tall posts by the elbow of configurations that reach targets (1 or 2): under it (that
    # configuration blocked) or 100-170 mm beside it (the links' way round it narrowed)
    labels = [label for label in targets if label != "demo"]
    elbow = 2 if kinematics.lower.size == 6 else 3  # joint 3 of a 6-axis arm, 4 of a 7-axis one
    for index in range(1, int(rng.integers(1, 3)) + 1):
        label = str(rng.choice(labels))
        top = (np.asarray(targets[label][:3]) + axes[label] * TOP * approach) * 1e-3
        reached = kinematics.solutions(top, -axes[label], kinematics.seeds([first], 8, seed))
        if not reached:
            continue
        origins = kinematics.origins(reached[0]) * 1e3
        radius = float(rng.uniform(10, 18))
        for _ in range(12):
            point = origins[elbow] + rng.uniform(0.0, 0.35) * (origins[elbow + 2] - origins[elbow])
            out = point[:2] - base[:2]
            across = np.array([-out[1], out[0]]) / max(np.linalg.norm(out), 1e-9)
            beside = 0.0 if rng.uniform() < 0.5 else rng.choice([-1.0, 1.0]) * rng.uniform(100, 170)
            xy = point[:2] + beside * across
            if np.linalg.norm(xy - base[:2]) < 120.0 + radius or not clear_of_nuts(xy, radius + 25):
                continue
            if np.linalg.norm(xy - start[:2]) < tool["radius"] + radius + margin + 10.0:
                continue
            bottom = plate_top if on_plate(xy) else float(base[2])
            parts.append(
                {
                    "type": "cylinder",
                    "label": f"post{index}",
                    "at": [*xy.tolist(), bottom],
                    "radius": radius,
                    "height": float(point[2] + rng.uniform(20, 60) - bottom),
                }
            )
            posts[f"post{index}"] = f"{'beside' if beside else 'under'} the elbow ({label})"
            break
    bin_at, where = _place_bin(rng, spec, kinematics, first, base)
    if bin_at is None:
        return None
    spec["job"]["bin"]["at"] = bin_at
    if not _valid(spec, folder, kinematics, first):
        return None
    files = {URDF_ARMS[arm][0].name: URDF_ARMS[arm][0]} if arm in URDF_ARMS else {}
    facts = CellFacts(
        seed,
        arm,
        "mm",
        (rows, cols),
        sorted(_tilted_labels(tilted_cols, rows)),
        f"{abs(angle):.0f} deg about {about}" if pose else "",
        posts,
        behind,
        where,
        folder,
    )
    return spec, files, facts


def _tilted_labels(columns, rows: int) -> set:
    return {f"c{c + 1}r{r + 1}" for c in columns for r in range(rows)}


def _drop_height(spec: dict) -> float:
    """mm over the bin's bottom where the job lets a part go: its floor (2 % of its inner width
    thick), its height and the job's 40 mm clearance (as bidmp.tasks.jobs documents them)."""
    size = spec["job"]["bin"]["size"]
    return max(0.02 * min(size[:2]), 1e-3 * max(size)) + size[2] + 40.0


def _place_bin(rng, spec: dict, kinematics: Kinematics, first, base):
    """The bin's bottom centre (mm) and how it stands: where the tool pointing down over it puts
    the wrist nearest its singularity (a Franka arm, the xArm6, the IRB 1200, in some cells: at
    about the height of the arm's base, the bin sunk below the plate if need be), or an easy place
    on the plate's level (the wrist far from it). The arm reaches the bin's centre and 20 mm off
    it either way pointing down from the solution it takes from its start. None when no scanned
    place will do."""
    singular_wrist = kinematics.robot.name in ("panda", "fr3", "xarm6", "irb1200")
    want_singular = singular_wrist and rng.uniform() < 0.6
    height = _drop_height(spec)
    plate_top = spec["scene"]["parts"][0]["at"][2]
    keep = np.array(
        [np.asarray(p[:3])[:2] for p in spec["targets"].values()]
        + [p["at"][:2] for p in spec["scene"]["parts"] if p["type"] == "cylinder"]
    )
    face = [p for p in spec["scene"]["parts"] if p.get("label") == "face"]
    start = np.asarray(spec["demonstration"]["points"][0][:3])
    down = [0.0, 0.0, -1.0]
    levels = base[2] + np.array([-30.0, 0.0, 30.0]) if want_singular else [plate_top + height]
    candidates = []
    for level in levels:
        for radius in np.linspace(200.0, 480.0, 8):
            for turn in np.radians(np.arange(0.0, 360.0, 15.0)):
                xy = base[:2] + radius * np.array([np.cos(turn), np.sin(turn)])
                if np.min(np.linalg.norm(keep - xy, axis=1)) < 95.0:
                    continue
                if np.linalg.norm(start[:2] - xy) < 80.0:
                    continue
                if face and np.linalg.norm(np.asarray(face[0]["at"][:2]) - xy) < 40.0 + max(
                    face[0]["size"][:2]
                ):
                    continue
                centre = np.array([*xy, level]) * 1e-3
                q, error, turned = kinematics.solve(centre, down, first)
                if error > IK_POSITION or turned > IK_AXIS:
                    continue
                candidates.append((kinematics.wrist_angle(q), xy, level, q))
    if want_singular:
        candidates.sort(key=lambda c: c[0])
    else:
        candidates = [c for c in candidates if c[0] > 25.0]
        candidates = [candidates[k] for k in rng.permutation(len(candidates))]
    for angle, xy, level, q in candidates[:20]:
        centre = np.array([*xy, level]) * 1e-3
        corners = [centre + np.array([dx, dy, 0.0]) * 1e-3 for dx in (-20, 20) for dy in (-20, 20)]
        if all(kinematics.solutions(c, down, [q]) for c in corners):
            where = f"wrist {angle:.1f} deg" if want_singular else "easy"
            return [*xy.tolist(), float(level - height)], where
    return None, ""


def _valid(spec: dict, folder, kinematics: Kinematics, first) -> bool:
    """The cell loads (no parts overlap), the arm's start keeps the margin from every part of the
    job's scene (the bin too), and some joints put the tool at the demonstration's start clear
    of them (every simulated motion starts there)."""
    from bidmp.tasks import scenarios

    try:
        scenario = scenarios.from_dict(spec, base_dir=str(folder))
    except scenarios.ScenarioError:
        return False
    scene = job_scene(scenario)
    space = kinematics.geometry.space(
        scene, 1e-3, exclude=[], margin=_margin_m(spec), links=ALLOWANCE_MM * 1e-3
    )
    if space.slack(first) < 0.0:
        return False
    begin = np.asarray(spec["demonstration"]["points"][0][:3], dtype=float) * 1e-3
    seeds = kinematics.seeds([first], 24, spec["seed"])
    return bool(
        kinematics.solutions(begin, [0.0, 0.0, -1.0], seeds, accept=lambda q: space.slack(q) >= 0)
    )


def job_scene(scenario):
    """The scene the job works in: the scenario's parts and the bin (as the job builds it)."""
    from bidmp.sim.job import _job_parts

    return scenario.scene.with_parts(_job_parts(scenario, scenario.labels), scenario.targets)


def _margin_m(spec: dict) -> float:
    """The oracle's margin (m): the scene's plus the tracking allowance."""
    return (spec["scene"]["margin"] / UNITS[spec["units"]] + ALLOWANCE_MM) * 1e-3


def _in_units(spec: dict, units: str) -> dict:
    """``spec`` (mm) with every length in ``units``."""
    f = UNITS[units]
    out = json_copy(spec)
    scale = lambda values: (np.asarray(values, dtype=float) * f).tolist()  # noqa: E731
    out["units"] = units
    out["targets"] = {k: [*scale(v[:3]), *v[3:]] for k, v in spec["targets"].items()}
    out["demonstration"] = {
        "points": [[*scale(p[:3]), *p[3:]] for p in spec["demonstration"]["points"]]
    }
    out["success_threshold"] *= f
    out["approach_height"] *= f
    out["robot"]["base"] = scale(spec["robot"]["base"])
    scene = out["scene"]
    scene["tool"] = {k: v * f for k, v in spec["scene"]["tool"].items()}
    scene["margin"] *= f
    scene["standoff"] = {k: v * f for k, v in spec["scene"]["standoff"].items()}
    for part in scene["parts"]:
        for key in ("at", "size"):
            if key in part:
                part[key] = scale(part[key])
        for key in ("radius", "height", "across_flats"):
            if key in part:
                part[key] = part[key] * f
        if "stud" in part:
            part["stud"] = {k: v * f for k, v in part["stud"].items()}
    out["job"]["pitch"] *= f
    out["job"]["bin"] = {k: scale(v) for k, v in spec["job"]["bin"].items()}
    return out


def json_copy(data):
    import json

    return json.loads(json.dumps(data))


def write_cell(seed: int, folder) -> tuple[Path, CellFacts]:
    """Cell ``seed`` written into ``folder`` with its files: the scenario file's path and the
    cell's facts."""
    import json

    spec, files, facts = draw_cell(seed)
    folder = Path(folder)
    for name, source in files.items():
        shutil.copy(source, folder / name)
    path = folder / f"{spec['name']}.json"
    path.write_text(json.dumps(spec))
    return path, facts


# ---------------------------------------------------------------------------------------------
# The oracle
# ---------------------------------------------------------------------------------------------
@dataclass
class Decision:
    """The oracle's word on one target: whether a solution within the limits puts the tool on it
    along its axis (``ik``); whether a route from the start reaches the top of its final approach
    with the approach down its axis free (``approach``: the route the brief of the property asks
    about); whether the straight line on up the axis to where the job's retract ends is free too
    (``retract``); why not (``why``), the configurations the searches tested and their seconds."""

    label: str
    ik: bool
    approach: bool
    retract: bool = False
    why: str = ""
    checks: int = 0
    seconds: float = 0.0


@dataclass
class Leg:
    """A route of the cell's own: from the start to a configuration at the demonstration's start
    (where every simulated motion begins), or to each point the job drops a part at."""

    ok: bool
    why: str = ""
    checks: int = 0


class RouteOracle:
    """Which targets of a cell have a route (module docstring): ``decide(label)``; the cell's own
    legs: ``start_leg()`` (the demonstration's start joined to the start), ``bin_leg()`` (every
    drop point over the bin joined to it, the tool pointing down or tilted up to 30 degrees)."""

    def __init__(self, spec: dict, folder):
        from bidmp.tasks import scenarios

        self.spec = spec
        self.scenario = scenarios.from_dict(spec, base_dir=str(folder))
        self.kinematics = kinematics_of(spec, folder)
        self.metre = 1e-3 / UNITS[spec["units"]]
        self.scene = job_scene(self.scenario)
        self.start = start_joints(self.kinematics, spec, self.scenario.demonstration[0])
        self.margin = _margin_m(spec)
        self.seeds = self.kinematics.seeds([] if self.start is None else [self.start])

    def axis(self, label: str) -> np.ndarray:
        """The target's axis, out of it."""
        target = self.spec["targets"][label]
        if len(target) < 7:
            return np.array([0.0, 0.0, 1.0])
        return -Rotation.from_quat(target[3:7]).apply([0.0, 0.0, 1.0])

    def reachable(self, label: str) -> bool:
        """The IK oracle: a solution within the limits with the mouth on the target along its axis."""
        point = np.asarray(self.spec["targets"][label][:3], dtype=float) * self.metre
        return bool(self.kinematics.solutions(point, -self.axis(label), self.seeds))

    def space(self, exclude=()):
        return self.kinematics.geometry.space(
            self.scene,
            self.metre,
            exclude=list(exclude),
            margin=self.margin,
            links=ALLOWANCE_MM * 1e-3,
        )

    def _plan(self, space, goals, start=None):
        """(route or None, why, checks): the oracle's search from ``start`` (default the arm's)
        to any of ``goals``."""
        from bidmp.planning import NoRouteError, plan_route

        start = self.start if start is None else start
        if start is None:
            return None, "no start: the arm cannot reach the demonstration's start", 0
        if space.slack(start) < 0.0:
            return None, "the start is not free", 0
        try:
            route = plan_route(
                space,
                start,
                np.array(goals),
                seed=ORACLE_SEED,
                max_checks=ORACLE_CHECKS,
                time_limit=3600.0,
                planner="rrt",
                shorten="none",
            )
        except NoRouteError as exc:
            return None, str(exc), 0
        return route, "", route.checks

    def _line(self, space, q, points, axis) -> bool:
        """Whether the arm follows the straight ``points`` (m) from joints ``q`` (its tool along
        ``-axis``): the inverse kinematics at every point from the one before, the joints
        halfway between two keeping the mouth within 0.1 mm of the line and the tool's axis
        within a degree of it (a step that does not is split, down to 1/16 of it: near a
        wrist's singularity the joints turn fast but still follow the line), every joint step
        free."""
        from bidmp.planning import segment_free

        joints = [q]
        for a, b in zip(points[:-1], points[1:]):
            steps = self._follow(joints[-1], a, b, axis, points[0], 4)
            if steps is None:
                return False
            joints += steps
        return all(segment_free(space, a, b) for a, b in zip(joints[:-1], joints[1:]))

    def _follow(self, q, a, b, axis, origin, depth: int):
        """The joints (a list) that take the mouth from ``a`` (at joints ``q``) to ``b`` along
        the line through ``origin`` down ``axis``, split in halves where needed; None where
        the arm cannot."""
        step, error, turned = self.kinematics.solve(b, -axis, q)
        if error > IK_POSITION or turned > IK_AXIS:
            return None
        mouth, frame = self.kinematics.pose(0.5 * (step + q))
        offset = mouth - origin
        across = np.linalg.norm(offset - np.dot(offset, axis) * axis)
        if across <= 1e-4 and frame[:, 2] @ -axis >= math.cos(math.radians(1.0)):
            return [step]
        if depth == 0:
            return None
        middle = 0.5 * (a + b)
        first = self._follow(q, a, middle, axis, origin, depth - 1)
        if first is None:
            return None
        second = self._follow(first[-1], middle, b, axis, origin, depth - 1)
        return None if second is None else first + second

    def _points(self, a, b) -> np.ndarray:
        """Points (m) every 2 mm or closer from ``a`` to ``b`` (scene units)."""
        count = max(int(np.ceil(np.linalg.norm(b - a) * self.metre / 2e-3)), 1) + 1
        return np.linspace(a, b, count) * self.metre

    def decide(self, label: str) -> Decision:
        """The target's :class:`Decision`."""
        began = time.perf_counter()
        ik = self.reachable(label)
        space = self.space([label])
        axis = self.axis(label)
        target = np.asarray(self.spec["targets"][label][:3], dtype=float)
        height = self.spec["approach_height"]
        top = target + axis * TOP * height
        nut = next(p for p in self.spec["scene"]["parts"] if p.get("label") == label)
        f = UNITS[self.spec["units"]]
        # the job turns the nut off its stud (its height and the stud's, and 0.5 mm), then
        # retracts 40 mm (bidmp.tasks.jobs' defaults, stated here)
        lift = nut["height"] + nut["stud"]["above"] + 0.5 * f + 40.0 * f
        end = target + axis * max(lift, TOP * height)
        descent, ascent = self._points(top, target), self._points(top, end)
        tops = self.kinematics.solutions(descent[0], -axis, self.seeds, enough=12)
        free = [q for q in tops if space.slack(q) >= 0.0]
        if not free:
            why = (
                "no joints within the limits put the tool at the approach's top"
                if not tops
                else "the arm at the approach's top would come within the margin of "
                + space.nearest(tops[0])[0]
            )
            return Decision(label, ik, False, why=why, seconds=time.perf_counter() - began)
        goals = [q for q in free if self._line(space, q, descent, axis)]
        if not goals:
            why = "the arm cannot follow the final approach down the axis clear of the parts"
            return Decision(label, ik, False, why=why, seconds=time.perf_counter() - began)
        route, why, checks = self._plan(space, goals)
        if route is None:
            return Decision(label, ik, False, why=why, seconds=time.perf_counter() - began)
        retract = self._line(space, goals[route.goal], ascent, axis)
        if not retract:
            lifted = [q for q in goals if self._line(space, q, ascent, axis)]
            if lifted:
                again, _, more = self._plan(space, lifted)
                retract, checks = again is not None, checks + more
        why = "" if retract else "the job's retract up the axis is not free"
        return Decision(label, ik, True, retract, why, checks, time.perf_counter() - began)

    def start_leg(self) -> Leg:
        """A route from the start to a free configuration with the tool at the demonstration's
        start pointing down (where every simulated motion begins)."""
        first = np.asarray(self.scenario.demonstration[0][:3], dtype=float) * self.metre
        space = self.space()
        goals = self.kinematics.solutions(
            first, [0.0, 0.0, -1.0], self.seeds, enough=12, accept=lambda q: space.slack(q) >= 0
        )
        if not goals:
            return Leg(False, "no free joints put the tool at the demonstration's start")
        route, why, checks = self._plan(space, goals)
        return Leg(route is not None, why, checks)

    def bin_leg(self) -> Leg:
        """Routes from the start to every point the job lets a part go at (a grid over the bin's
        floor, as bidmp.sim.job spreads them: one every two tool radii, the job's clearance over
        the bin's rim), the tool pointing down or tilted up to 30 degrees."""
        spec, f = self.spec, UNITS[self.spec["units"]]
        size = np.asarray(spec["job"]["bin"]["size"], dtype=float)
        wall = max(0.02 * size[:2].min(), 1e-3 * size.max())
        floor = np.asarray(spec["job"]["bin"]["at"], dtype=float) + [0.0, 0.0, wall]
        span = 2.0 * spec["scene"]["tool"]["radius"]
        counts = np.maximum(np.floor(size[:2] / span).astype(int), 1)
        frames = [np.array([0.0, 0.0, -1.0])]
        for tilt in (15.0, 30.0):
            for turn in np.radians(np.arange(0.0, 360.0, 45.0)):
                lean = math.sin(math.radians(tilt))
                frames.append(
                    np.array(
                        [
                            lean * math.cos(turn),
                            lean * math.sin(turn),
                            -math.cos(math.radians(tilt)),
                        ]
                    )
                )
        space = self.space()
        checks, over = 0, None
        for i in range(counts[0]):
            for j in range(counts[1]):
                offset = (np.array([i, j]) + 0.5) / counts * size[:2] - size[:2] / 2
                point = (floor + [*offset, size[2] + 40.0 * f]) * self.metre
                goals = []
                for frame in frames:
                    goals += self.kinematics.solutions(
                        point,
                        frame,
                        self.seeds[:12],
                        enough=2,
                        accept=lambda q: space.slack(q) >= 0,
                    )
                    if len(goals) >= 8:
                        break
                if not goals:
                    return Leg(
                        False, f"no free joints drop at {np.round(point, 4).tolist()} m", checks
                    )
                # the first drop from the start, the others from it (a route there and back)
                route, why, more = self._plan(space, goals, over)
                checks += more
                if route is None:
                    return Leg(
                        False,
                        f"no route to the drop at {np.round(point, 4).tolist()} m: {why}",
                        checks,
                    )
                over = goals[route.goal] if over is None else over
        return Leg(True, "", checks)


# ---------------------------------------------------------------------------------------------
# The checks of what the arm did
# ---------------------------------------------------------------------------------------------
GOLDEN = (math.sqrt(5.0) - 1.0) / 2.0


def solids(spec: dict, extra=()) -> list:
    """Every part of ``spec`` (and ``extra`` part dicts) as (owner, kind, centre, rotation (3, 3),
    dims): "box" (half sizes), "cylinder" (radius, half height), "hex" (circumradius, half
    height; a corner on its own +x), read from the dict as the scenario files document them."""
    out = []
    for part in list(spec["scene"]["parts"]) + list(extra):
        turn = (
            Rotation.from_euler("xyz", part["rotation"], degrees=True).as_matrix()
            if "rotation" in part
            else Rotation.from_euler("z", part.get("yaw", 0.0), degrees=True).as_matrix()
        )
        up, at, label = turn[:, 2], np.asarray(part["at"], dtype=float), part["label"]
        if part["type"] in ("box", "plate", "cell"):
            size = np.asarray(part["size"], dtype=float)
            sign = -1.0 if part["type"] == "plate" else 1.0
            out.append((label, "box", at + sign * up * size[2] / 2, turn, size / 2))
        elif part["type"] == "cylinder":
            height = part["height"]
            out.append(
                (label, "cylinder", at + up * height / 2, turn, (part["radius"], height / 2))
            )
        else:
            height = part["height"]
            circum = part["across_flats"] / math.sqrt(3.0)
            out.append((label, "hex", at + up * height / 2, turn, (circum, height / 2)))
            stud = part.get("stud")
            if stud:
                total = height + stud["above"]
                out.append(
                    (label, "cylinder", at + up * total / 2, turn, (stud["radius"], total / 2))
                )
    return out


def _hex_flat(xy: np.ndarray, circum: float) -> np.ndarray:
    """Signed 2-D distance from points (..., 2) to a regular hexagon (circumradius, a corner on
    +x): inside, the nearest edge's line; outside, the nearest edge."""
    angles = np.radians(np.arange(6) * 60.0)
    corners = circum * np.column_stack([np.cos(angles), np.sin(angles)])
    normals = np.column_stack([np.cos(angles + np.pi / 6), np.sin(angles + np.pi / 6)])
    apothem = circum * math.sqrt(3.0) / 2.0
    inside = np.max(xy @ normals.T - apothem, axis=-1)
    best = np.full(xy.shape[:-1], np.inf)
    for k in range(6):
        a, b = corners[k], corners[(k + 1) % 6]
        t = np.clip(((xy - a) @ (b - a)) / ((b - a) @ (b - a)), 0.0, 1.0)
        best = np.minimum(best, np.linalg.norm(xy - (a + t[..., None] * (b - a)), axis=-1))
    return np.where(inside <= 0.0, inside, best)


def signed_distance(points: np.ndarray, solid) -> np.ndarray:
    """Signed distance (negative inside) from points (..., 3) to a solid of :func:`solids`."""
    _, kind, centre, turn, dims = solid
    local = (points - centre) @ turn
    if kind == "box":
        gap = np.abs(local) - dims
        return np.linalg.norm(np.maximum(gap, 0.0), axis=-1) + np.minimum(gap.max(axis=-1), 0.0)
    if kind == "cylinder":
        flat = np.linalg.norm(local[..., :2], axis=-1) - dims[0]
    else:
        flat = _hex_flat(local[..., :2], dims[0])
    vertical = np.abs(local[..., 2]) - dims[1]
    both = np.stack([flat, vertical], axis=-1)
    return np.linalg.norm(np.maximum(both, 0.0), axis=-1) + np.minimum(both.max(axis=-1), 0.0)


def _line_minimum(starts: np.ndarray, direction: np.ndarray, length: float, solid) -> np.ndarray:
    """The least signed distance along the segments from ``starts`` (..., 3) a ``length`` along
    ``direction`` (..., 3): convex along a line (a convex part), golden section to 1e-9 of the
    length, and the ends."""
    low = np.zeros(starts.shape[:-1])
    high = np.full(starts.shape[:-1], length)
    value = lambda s: signed_distance(starts + s[..., None] * direction, solid)  # noqa: E731
    for _ in range(44):
        a, b = high - GOLDEN * (high - low), low + GOLDEN * (high - low)
        left = value(a) < value(b)
        high, low = np.where(left, b, high), np.where(left, low, a)
    middle = 0.5 * (low + high)
    return np.minimum.reduce([value(middle), value(np.zeros_like(low)), value(high * 0 + length)])


def densified(points: np.ndarray, frames: np.ndarray, step: float, reach: float) -> tuple:
    """The tool's placements ``points`` (n, 3), ``frames`` (n, 3, 3) with more between them, so
    that no point of the tool moves more than ``step`` from one to the next (the mouth's travel
    plus ``reach``, the tool's, times the turn)."""
    from scipy.spatial.transform import Slerp

    turns = Rotation.from_matrix(frames)
    if len(points) < 2:
        return points, frames
    angle = (turns[:-1].inv() * turns[1:]).magnitude()
    travel = np.linalg.norm(np.diff(points, axis=0), axis=1)
    pieces = np.maximum(np.ceil((travel + angle * reach) / step), 1).astype(int)
    which = np.repeat(np.arange(len(pieces)), pieces)
    share = (np.arange(which.size) - np.repeat(np.cumsum(pieces) - pieces, pieces)) / np.repeat(
        pieces, pieces
    )
    at = np.concatenate([which + share, [len(points) - 1]])
    dense = np.vstack(
        [points[which] + share[:, None] * np.diff(points, axis=0)[which], points[-1:]]
    )
    return dense, Slerp(np.arange(len(points)), turns)(at).as_matrix()


def clearance(points, frames, spec: dict, exclude, extra=()) -> dict:
    """Owner -> the least distance of the tool (mouth at ``points`` (n, 3), frames (n, 3, 3): its
    body from the mouth against its z axis) from that part, where it comes within the part's
    floor (its stand-off, else the margin) of it: from points of its surface (module docstring).
    Where a bound from below (the tool's axis as a capsule) already clears the floor, that bound."""
    radius, length = spec["scene"]["tool"]["radius"], spec["scene"]["tool"]["length"]
    margin, standoff = spec["scene"]["margin"], spec["scene"]["standoff"]
    points, frames = densified(
        np.asarray(points, dtype=float),
        np.asarray(frames, dtype=float),
        0.01 * radius,
        math.hypot(length, radius),
    )
    down = -frames[:, :, 2]  # from the mouth up the tool
    middle = points + down * length / 2
    around = np.radians(np.arange(48) * 7.5)
    ring = (
        np.cos(around)[None, :, None] * frames[:, None, :, 0]
        + np.sin(around)[None, :, None] * frames[:, None, :, 1]
    )
    found = {}
    for solid in solids(spec, extra):
        owner, kind, centre, _, dims = solid
        if owner in exclude:
            continue
        floor = standoff.get(owner, margin)
        extent = np.linalg.norm(dims) if kind == "box" else math.hypot(dims[0], dims[1])
        sphere = np.linalg.norm(middle - centre, axis=1) - math.hypot(length / 2, radius) - extent
        near = sphere < floor
        least = float(sphere[~near].min(initial=np.inf))
        if near.any():
            near = np.flatnonzero(near)
            capsule = _line_minimum(points[near], down[near], length, solid) - radius
            close = capsule < floor
            least = min(least, float(capsule[~close].min(initial=np.inf)))
            close = near[close]
            if close.size:
                side = points[close][:, None] + radius * ring[close]
                rim = _line_minimum(side, down[close][:, None].repeat(48, 1), length, solid)
                discs = [
                    signed_distance(
                        points[close][:, None]
                        + share * radius * ring[close]
                        + h * down[close][:, None],
                        solid,
                    )
                    for share in (0.0, 1 / 3, 2 / 3)
                    for h in (0.0, length)
                ]
                least = min(least, float(np.min(rim)), *(float(np.min(d)) for d in discs))
        found[owner] = min(found.get(owner, np.inf), least)
    return found


def clearance_breaches(points, frames, spec, exclude, extra=()) -> list:
    """The parts the tool came within its floor of (less the contract's half step between the
    placements it checks, 0.1 % of the tool's length): (owner, distance, floor)."""
    slack = 0.001 * spec["scene"]["tool"]["length"] * (1 + 1e-9)
    out = []
    for owner, distance in clearance(points, frames, spec, exclude, extra).items():
        floor = spec["scene"]["standoff"].get(owner, spec["scene"]["margin"])
        if distance < floor - slack:
            out.append((owner, distance, floor))
    return out


def command_breaches(commands, limits) -> list:
    """What of the arm's limits the 1 kHz ``commands`` (m, J) break, by differences taken here
    (the first and last command held three samples): positions outside the ranges; velocity,
    acceleration, jerk beyond their limits; a first or last step accelerating past 5 % of it."""
    q = np.asarray(commands, dtype=float)
    out = []
    if np.any(q < np.asarray(limits.lower) - 1e-9) or np.any(q > np.asarray(limits.upper) + 1e-9):
        out.append("position")
    padded = np.concatenate([np.repeat(q[:1], 3, axis=0), q, np.repeat(q[-1:], 3, axis=0)])
    for order, name, limit in (
        (1, "velocity", limits.velocity),
        (2, "acceleration", limits.acceleration),
        (3, "jerk", limits.jerk),
    ):
        if limit is None:
            continue
        rate = np.diff(padded, n=order, axis=0) / 1e-3**order
        if np.any(np.abs(rate) > np.asarray(limit) * (1 + 1e-9)):
            out.append(name)
    if len(q) > 1:
        ends = np.abs(np.stack([q[1] - q[0], q[-2] - q[-1]])) / 1e-6
        if np.any(ends > 0.05 * np.asarray(limits.acceleration)):
            out.append("not from rest")
    return out


def approach_breaches(points, frames, target, axis, spec) -> list:
    """What of a task success's end the path breaks: the end within the threshold; from its last
    entry into the band of the approach height up ``axis``, within the threshold of the axis,
    never rising more than 0.15 mm; a pose's tool axis within 2 degrees of the target's."""
    f = UNITS[spec["units"]]
    threshold, height = spec["success_threshold"], spec["approach_height"]
    points, target = np.asarray(points, dtype=float), np.asarray(target, dtype=float)[:3]
    out = []
    if np.linalg.norm(points[-1] - target) > threshold * (1 + 1e-9):
        out.append("end")
    along = (points - target) @ axis
    above = np.flatnonzero(along >= height)
    if not above.size or above[-1] >= len(points) - 1:
        return [*out, "no entry from above"]
    band = slice(above[-1] + 1, None)
    offsets = points[band] - target
    across = np.linalg.norm(offsets - np.outer(offsets @ axis, axis), axis=1)
    if across.max() > threshold * (1 + 1e-9):
        out.append("off the axis")
    heights = along[band]
    if np.max(heights - np.minimum.accumulate(heights)) > RISE_MM * f * (1 + 1e-9):
        out.append("rise")
    if frames is not None and len(spec["targets"]["demo"]) >= 7:
        tool = np.asarray(frames)[band][:, :, 2]
        if np.degrees(np.arccos(np.clip(tool @ -axis, -1.0, 1.0))).max() > ALIGNMENT_DEG:
            out.append("tilted")
    return out


# ---------------------------------------------------------------------------------------------
# A cell through the pipeline, judged
# ---------------------------------------------------------------------------------------------
@dataclass
class TargetRow:
    """One target: the oracle's decision, and what bidmp demo / sim / job made of it (None: not
    run there), how (the repairs, the arm's route) and why not."""

    decision: Decision
    demo: bool | None = None
    demo_how: str = ""
    sim: bool | None = None
    sim_how: str = ""
    sim_reason: str = ""
    job: bool | None = None
    job_how: str = ""
    job_reason: str = ""


@dataclass
class CellOutcome:
    """A cell's targets (label -> :class:`TargetRow`), its own legs (the demonstration's start,
    the bin: :class:`Leg`), the executed motions a check refuses (where, label, what), the
    "unreachable" reasons where the IK oracle found a solution (where, label, reason), and
    seconds per stage."""

    facts: CellFacts
    rows: dict
    start_leg: Leg
    bin_leg: Leg | None
    refused: list = field(default_factory=list)
    unreachable: list = field(default_factory=list)
    seconds: dict = field(default_factory=dict)

    def owed(self, label: str, where: str) -> bool:
        """Whether the oracle says target ``label`` can be solved ``where`` ("sim": it has a
        route and every simulated motion's start is joined to the arm's; "job": it has a route,
        its retract is free and every drop over the bin has a route)."""
        decision = self.rows[label].decision
        if where == "sim":
            return decision.approach and self.start_leg.ok
        if self.bin_leg is None:  # (no job ran: the bin's routes were not asked)
            return False
        return decision.approach and decision.retract and self.bin_leg.ok

    def unsolved(self) -> list:
        """(label, where, reason) of every target the oracle says can be solved where it ran
        and was not."""
        out = []
        for label, row in self.rows.items():
            if row.sim is False and self.owed(label, "sim"):
                out.append((label, "sim", row.sim_reason))
            if row.job is False and self.owed(label, "job"):
                out.append((label, "job", row.job_reason))
        return out


def run_cell(
    seed: int, folder, *, demo: bool = True, sim_labels=None, job_labels=None
) -> CellOutcome:
    """Cell ``seed`` written into ``folder``, its targets decided by the oracle (every one where
    the evaluation runs or a target set is all; else the ones the simulator and the job run, and
    the bin's routes only where a job runs), then bidmp's evaluation (``demo``), simulator (its
    targets ``sim_labels``, default all; ``()`` none) and job (``job_labels``) with every executed
    motion checked here."""
    import json

    from bidmp.tasks import evaluate, scenarios

    path, facts = write_cell(seed, folder)
    spec = json.loads(path.read_text())
    scenario = scenarios.load(str(path))
    began = time.perf_counter()
    oracle = RouteOracle(spec, folder)
    if demo or sim_labels is None or job_labels is None:
        decided = list(scenario.labels)
    else:
        asked = {*sim_labels, *job_labels}
        decided = [label for label in scenario.labels if label in asked]
    rows = {label: TargetRow(oracle.decide(label)) for label in decided}
    jobs = job_labels is None or len(job_labels) > 0
    outcome = CellOutcome(facts, rows, oracle.start_leg(), oracle.bin_leg() if jobs else None)
    outcome.seconds["oracle"] = time.perf_counter() - began
    if demo:
        began = time.perf_counter()
        result = evaluate(scenario, ["bidmp"]).methods["bidmp"]
        for label, row in rows.items():
            row.demo = bool(result.task_success_at(label))
            row.demo_how = result.repaired_at(label) or ""
        outcome.seconds["demo"] = time.perf_counter() - began
    judge = _Judge(spec, oracle, outcome)
    if sim_labels is None or len(sim_labels):
        began = time.perf_counter()
        judge.simulated(scenario, sim_labels)
        outcome.seconds["sim"] = time.perf_counter() - began
    if job_labels is None or len(job_labels):
        began = time.perf_counter()
        judge.job(scenario, job_labels)
        outcome.seconds["job"] = time.perf_counter() - began
    return outcome


class _Judge:
    """The checks of what the simulator and the job did, into ``outcome``."""

    def __init__(self, spec: dict, oracle: RouteOracle, outcome: CellOutcome):
        self.spec, self.oracle, self.outcome = spec, oracle, outcome
        self.kinematics = oracle.kinematics

    def frames(self, commands, count: int) -> np.ndarray:
        """The tool's frames at ``count`` samples spread over the commands' time (FK here)."""
        commands = np.asarray(commands, dtype=float)
        picked = np.round(np.linspace(0, len(commands) - 1, count)).astype(int)
        return self.kinematics.poses(commands[picked])[1]

    def motion(self, where: str, label: str, ran, success: bool, extra=()) -> None:
        """One motion that ran (``ran``: its ``path``, ``commands``, ``contacts``, ``verdict``):
        the tool's clearance, the commands' limits, a task success's approach (checks written
        here), and the physics' contacts and the pipeline's own verdict on it."""
        refused = self.outcome.refused
        frames = self.frames(ran.commands, len(ran.path))
        for owner, distance, floor in clearance_breaches(
            ran.path, frames, self.spec, {label}, extra
        ):
            refused.append((where, label, f"{distance:.4g} from {owner} (floor {floor:.3g})"))
        for what in command_breaches(ran.commands, self.kinematics.robot.limits):
            refused.append((where, label, f"commands: {what}"))
        if success:
            target = self.spec["targets"][label]
            for what in approach_breaches(
                ran.path, frames, target, self.oracle.axis(label), self.spec
            ):
                refused.append((where, label, f"approach: {what}"))
        if ran.contacts:
            refused.append((where, label, f"contacts {ran.contacts}"))
        if ran.verdict is not None and not ran.verdict.ok:
            refused.append((where, label, f"verdict: {ran.verdict.reason()}"))

    def unreachable(self, where: str, label: str, reason: str) -> None:
        if "unreachable" in reason and self.outcome.rows[label].decision.ik:
            self.outcome.unreachable.append((where, label, reason))

    def simulated(self, scenario, labels) -> None:
        from bidmp import sim

        report = sim.simulate(scenario, ["bidmp"], targets=labels, workers=1, record=True)
        for label, target in report.methods["bidmp"].targets.items():
            row = self.outcome.rows[label]
            row.sim = bool(target.task_success(scenario.success_threshold))
            row.sim_how, row.sim_reason = target.repair, target.reason
            self.unreachable("sim", label, target.reason)
            if target.commands is not None:
                self.motion("sim", label, target, row.sim)

    def job(self, scenario, labels) -> None:
        from bidmp import sim
        from bidmp.sim.job import _job_parts

        report = sim.run_job(scenario, targets=labels, record=True)
        bin_parts = _job_parts(scenario, scenario.labels)
        for record in report.targets:
            row, label = self.outcome.rows[record.label], record.label
            row.job, row.job_reason = bool(record.removed), record.reason
            row.job_how = "; ".join(
                f"{phase.name}: {phase.note}"
                for phase in record.phases
                if "route" in phase.note or "repaired" in phase.note
            )
            self.unreachable("job", label, record.reason)
            for phase in record.phases:
                if phase.path is not None:
                    success = phase.name == "approach" and record.removed
                    self.motion(f"job {phase.name}", label, phase, success, bin_parts)
