"""Cells that look like users' cells, nobody tuned bidmp for: a nut module drawn at random (one or two
rows of M6-M10 nuts on studs, a pitch, a socket, a margin) in millimetres, centimetres or metres, with
posts, bosses, cable ducts up to 130 mm and tilted brackets in the way, one of the four built-in arms
(6 and 7 joints) standing in front, and the bin on either side.

The property, for every target of every cell: the evaluation's plain DMP and Bi-DMP, and (on a sample
of the cells) the simulator's motion and the job's cycle, either meet the motion contract by a check
written here — the end, a monotone final descent along the nut's axis, the whole tool's clearance from
every part but the target's own by the margin (the plate by its stand-off), and on the arm the 1 kHz
joint commands within its limits — or fail with a reason in one sentence. No run raises.

The checks are independent oracles, not the library's code: the tool is an upright cylinder on each
point of the path (sampled at most 1 % of its radius apart), the upright parts are boxes, cylinders and
hexagonal prisms whose distance from it is closed form (a 2-D distance and a height interval); a tilted
bracket's distance is taken from points on the tool's surface, which can only overstate it (so the
check cannot raise a false alarm). The commands' velocity, acceleration and jerk are differences
computed here with the arm's rest held before and after.
"""

import os

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bidmp.demonstrations import minimum_jerk
from bidmp.tasks import evaluate, scenarios

pytest.importorskip("pybullet")

N_CELLS = int(os.environ.get("BIDMP_RANDOM_CELLS", "20"))  # `make random-cells`: 300
EVERY = (
    1 if N_CELLS >= 100 else 5
)  # cells whose motions also run on the simulated arm and in the job
ARMS = ("panda", "iiwa", "xarm6", "ur5")
UNITS = {"mm": 1.0, "cm": 0.1, "m": 1e-3}
# the contract's allowed rise inside the final approach, in mm (stated, not imported)
RISE_MM = 0.15


# ---------------------------------------------------------------------------------------------
# The cells
# ---------------------------------------------------------------------------------------------
def user_cell(seed: int) -> dict:
    """A scenario dict for seed ``seed`` (the same cell for the same seed)."""
    rng = np.random.default_rng(seed)
    units = str(rng.choice(list(UNITS)))
    rows, cols, pitch = int(rng.integers(1, 3)), int(rng.integers(2, 5)), float(rng.uniform(40, 60))
    across, nut_height = float(rng.uniform(10, 14)), float(rng.uniform(5, 8))
    stud = {"radius": float(rng.uniform(2.5, across / 2 - 1.5)), "above": float(rng.uniform(6, 12))}
    sink = float(
        rng.uniform(1.6, 3.0)
    )  # the target (the socket's mouth) this far above the nut's base
    targets = {f"r{r}c{c}": [c * pitch, r * pitch, 0.0] for r in range(rows) for c in range(cols)}
    tool = {"radius": float(rng.uniform(9, 13)), "length": float(rng.uniform(90, 130))}
    margin = float(rng.uniform(1.2, 3.0))
    approach = float(rng.uniform(20, 30))
    home = np.zeros(3)
    start = home + [rng.uniform(-120, -60), rng.uniform(-130, -80), rng.uniform(150, 230)]
    hover = home + [0.0, 0.0, rng.uniform(approach + 10, 60)]
    demo = minimum_jerk(np.array([start, hover, home]), int(rng.integers(150, 400)))
    width, depth = (cols - 1) * pitch, (rows - 1) * pitch
    parts = [
        {
            "type": "plate",
            "label": "plate",
            "at": [width / 2, depth / 2, -sink],
            "size": [width + 160, depth + 140, 5.0],
        },
        {
            "type": "nut",
            "at_targets": "all",
            "offset": [0.0, 0.0, -sink],
            "across_flats": across,
            "height": nut_height,
            "stud": stud,
        },
    ]
    # Obstacles between the demonstrated nut and the far ones, a socket and the margin off every nut.
    keep = tool["radius"] + margin + across / np.sqrt(3.0) + 4.0
    taken = []
    for index in range(int(rng.integers(0, 4))):
        kind = str(rng.choice(["post", "boss", "duct", "bracket"]))
        for _ in range(60):
            spot = np.array(
                [
                    rng.uniform(0.2, 1.0) * max(width, pitch) - 0.1 * pitch,
                    rng.uniform(-0.5, 1.5) * max(depth, pitch / 2),
                    0.0,
                ]
            )
            if kind in ("post", "boss"):
                radius = float(rng.uniform(3, 8) if kind == "post" else rng.uniform(6, 14))
                half = np.array([radius, radius])
            else:
                size = [
                    float(rng.uniform(10, 20)),
                    float(rng.uniform(40, 140)),
                    float(rng.uniform(40, 130)) if kind == "duct" else 4.0,
                ]
                if kind == "bracket":
                    size = [float(rng.uniform(25, 45)), float(rng.uniform(25, 45)), 4.0]
                if rng.uniform() < 0.5:
                    size[0], size[1] = size[1], size[0]
                half = (
                    np.hypot(size[0], size[1]) / 2 * np.ones(2)
                    if kind == "bracket"
                    else np.array(size[:2]) / 2
                )
            nearest = min(
                max(np.max(np.abs(spot[:2] - t[:2]) - half), 0.0)
                for t in map(np.array, targets.values())
            )
            apart = all(
                np.max(np.abs(spot[:2] - other[0]) - half - other[1])
                > 2 * tool["radius"] + 2 * margin
                for other in taken
            )
            if nearest > keep and apart:
                break
        else:
            continue
        taken.append((spot[:2], half))
        label = f"{kind}{index}"
        if kind in ("post", "boss"):
            height = float(rng.uniform(50, 130) if kind == "post" else rng.uniform(8, 20))
            parts.append(
                {
                    "type": "cylinder",
                    "label": label,
                    "at": [*spot[:2], -sink],
                    "radius": radius,
                    "height": height,
                }
            )
        elif kind == "duct":
            parts.append({"type": "box", "label": label, "at": [*spot[:2], -sink], "size": size})
        else:  # a bracket on a stand, tilted 5-20 degrees about x or y
            lift = float(rng.uniform(15, 50))
            tilt = [
                float(rng.uniform(5, 20)) if axis == int(rng.integers(0, 2)) else 0.0
                for axis in range(2)
            ] + [0.0]
            parts.append(
                {
                    "type": "box",
                    "label": label,
                    "at": [*spot[:2], -sink + lift],
                    "size": size,
                    "rotation": tilt,
                }
            )
    side = -1.0 if rng.uniform() < 0.5 else 1.0
    bin_x = width / 2 + side * (width / 2 + rng.uniform(90, 130))
    job = {
        "steps": ["approach", "engage", "unscrew", "retract", "drop"],
        "order": "listed",
        "pitch": float(rng.uniform(1.0, 1.5)),
        "bin": {"at": [bin_x, depth / 2, -sink], "size": [70.0, 70.0, 40.0]},
    }
    f = UNITS[units]
    scale = lambda values: (np.asarray(values, dtype=float) * f).tolist()  # noqa: E731
    for part in parts:
        for key in ("at", "size", "offset"):
            if key in part:
                part[key] = scale(part[key])
        for key in ("radius", "height", "across_flats"):
            if key in part:
                part[key] = float(part[key] * f)
        if "stud" in part:
            part["stud"] = {key: value * f for key, value in part["stud"].items()}
    job["pitch"] *= f
    job["bin"] = {key: scale(value) for key, value in job["bin"].items()}
    return {
        "name": f"user-cell-{seed}",
        "units": units,
        "targets": {label: scale(point) for label, point in targets.items()},
        "demonstrated": "r0c0",
        "demonstration": {"points": scale(demo)},
        "success_threshold": 1.75 * f,
        "approach_height": approach * f,
        "methods": ["dmp", "bidmp"],
        "seed": seed,
        "dmp": {"protocol": str(rng.choice(["robot", "paper"]))},
        "robot": {"model": str(rng.choice(ARMS))},
        "scene": {
            "tool": {key: value * f for key, value in tool.items()},
            "margin": margin * f,
            "standoff": {"plate": 1.0 * f},
            "parts": parts,
        },
        "job": job,
    }


# ---------------------------------------------------------------------------------------------
# The independent checks
# ---------------------------------------------------------------------------------------------
def _solids(spec: dict, scene_extra=()) -> list:
    """(label, owner, kind, data) of every part, from the dict itself: "box" (lower, upper), "cylinder"
    (centre x, y, radius, z from, z to), "hex" (corners (6, 2), z from, z to), "oriented" (centre,
    rotation, half sizes)."""
    out = []
    for part in list(spec["scene"]["parts"]) + list(scene_extra):
        if part.get("at_targets"):
            for label, target in spec["targets"].items():
                base = np.add(target, part["offset"])
                circum = part["across_flats"] / np.sqrt(3.0)
                angles = np.radians(np.arange(6) * 60.0)
                corners = base[:2] + circum * np.column_stack([np.cos(angles), np.sin(angles)])
                out.append((label, label, "hex", (corners, base[2], base[2] + part["height"])))
                stud = part["stud"]
                out.append(
                    (
                        f"{label}/stud",
                        label,
                        "cylinder",
                        (
                            base[0],
                            base[1],
                            stud["radius"],
                            base[2],
                            base[2] + part["height"] + stud["above"],
                        ),
                    )
                )
            continue
        at = np.asarray(part["at"], dtype=float)
        if part["type"] == "cylinder":
            out.append(
                (
                    part["label"],
                    part["label"],
                    "cylinder",
                    (at[0], at[1], part["radius"], at[2], at[2] + part["height"]),
                )
            )
            continue
        size = np.asarray(part["size"], dtype=float)
        if "rotation" in part:
            rotation = Rotation.from_euler("xyz", part["rotation"], degrees=True).as_matrix()
            centre = at + rotation[:, 2] * size[2] / 2
            out.append((part["label"], part["label"], "oriented", (centre, rotation, size / 2)))
            continue
        bottom = at[2] - size[2] if part["type"] == "plate" else at[2]
        lower = np.array([at[0] - size[0] / 2, at[1] - size[1] / 2, bottom])
        out.append((part["label"], part["label"], "box", (lower, lower + size)))
    return out


def _segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """2-D distance from points (n, 2) to the segment a-b."""
    ab = b - a
    t = np.clip(((points - a) @ ab) / (ab @ ab), 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def _flat_distance(xy: np.ndarray, kind: str, data) -> np.ndarray:
    """Signed 2-D distance from the tool's axis (points (n, 2)) to a part's footprint (negative inside)."""
    if kind == "box":
        lower, upper = data
        gap = np.maximum(lower[:2] - xy, xy - upper[:2])
        return np.where(
            np.all(gap <= 0, axis=1), gap.max(axis=1), np.linalg.norm(np.maximum(gap, 0.0), axis=1)
        )
    if kind == "cylinder":
        return np.linalg.norm(xy - np.array(data[:2]), axis=1) - data[2]
    corners = data[0]
    edges = np.min(
        [_segment_distance(xy, corners[k], corners[(k + 1) % 6]) for k in range(6)], axis=0
    )
    centre = corners.mean(axis=0)
    inside = (
        np.linalg.norm(xy - centre, axis=1)
        <= np.sqrt(3.0) / 2 * np.linalg.norm(corners[0] - centre) - 1e-12
    )
    return np.where(inside, -edges, edges)


def _z_range(kind: str, data) -> tuple:
    if kind == "box":
        return data[0][2], data[1][2]
    return (data[3], data[4]) if kind == "cylinder" else (data[1], data[2])


def dense(path: np.ndarray, step: float) -> np.ndarray:
    """The polyline ``path`` (n, 3) with points at most ``step`` apart."""
    pieces = np.maximum(np.ceil(np.linalg.norm(np.diff(path, axis=0), axis=1) / step), 1).astype(
        int
    )
    which = np.repeat(np.arange(len(pieces)), pieces)
    share = (np.arange(which.size) - np.repeat(np.cumsum(pieces) - pieces, pieces)) / np.repeat(
        pieces, pieces
    )
    return np.vstack([path[which] + share[:, None] * (path[which + 1] - path[which]), path[-1:]])


def clearance(path: np.ndarray, spec: dict, exclude: set, extra=()) -> dict:
    """Owner -> the smallest distance from the upright tool along ``path`` to it (closed form for the
    upright parts; an overstatement, from points on the tool's surface, for a tilted one)."""
    radius, length = spec["scene"]["tool"]["radius"], spec["scene"]["tool"]["length"]
    points = dense(np.asarray(path, dtype=float), 0.01 * radius)
    found = {}
    for _label, owner, kind, data in _solids(spec, extra):
        if owner in exclude:
            continue
        if kind == "oriented":
            centre, rotation, half = data
            # Only where the tool's box comes within a radius of the bracket's box (else it is further
            # than the margin from it); there, points on the tool's surface.
            reach = np.abs(rotation) @ half
            gap = np.maximum(
                np.maximum(
                    centre - reach - (points + [radius, radius, length]),
                    (points - [radius, radius, 0.0]) - (centre + reach),
                ),
                0.0,
            )
            near = points[np.linalg.norm(gap, axis=1) <= radius]
            if near.shape[0] == 0:
                found[owner] = min(
                    found.get(owner, np.inf), float(np.linalg.norm(gap, axis=1).min())
                )
                continue
            angles = np.linspace(0, 2 * np.pi, 48, endpoint=False)
            rim = np.column_stack([radius * np.cos(angles), radius * np.sin(angles)])
            heights = np.linspace(0.0, length, 24)
            surface = np.array(
                [[x, y, h] for x, y in rim for h in heights] + [[0, 0, h] for h in heights]
            )
            best = np.inf
            for chunk in np.array_split(near, max(1, len(near) // 500)):
                local = (
                    (chunk[:, None, :] + surface[None]) - centre
                ) @ rotation  # into the bracket's frame
                gap = np.abs(local) - half
                outside = np.linalg.norm(np.maximum(gap, 0.0), axis=2)
                signed = np.where(np.all(gap <= 0, axis=2), gap.max(axis=2), outside)
                best = min(best, float(signed.min()))
            distance = best
        else:
            flat = _flat_distance(points[:, :2], kind, data) - radius
            low, high = _z_range(kind, data)
            vertical = np.maximum(low - (points[:, 2] + length), points[:, 2] - high)
            signed = np.where(
                (flat <= 0) & (vertical <= 0),
                np.maximum(flat, vertical),
                np.hypot(np.maximum(flat, 0.0), np.maximum(vertical, 0.0)),
            )
            distance = float(signed.min())
        found[owner] = min(found.get(owner, np.inf), distance)
    return found


def check_clear(path, spec, exclude, context, extra=()):
    """Every part but ``exclude`` kept at its margin (the plate: its stand-off), to the half step
    between the placements the library checks (0.1 % of the tool's length)."""
    slack = 0.001 * spec["scene"]["tool"]["length"] * (1 + 1e-9)
    for owner, distance in clearance(path, spec, exclude, extra).items():
        floor = spec["scene"]["standoff"].get(owner, spec["scene"]["margin"])
        assert distance >= floor - slack, (*context, "clearance", owner, distance, floor)


def check_end_and_descent(path, target, spec, context, slack: float = 0.0):
    """The end within the threshold; from the last entry into the band over the target, the path stays
    within the threshold of the nut's (vertical) axis and never rises by more than 0.15 mm."""
    f = UNITS[spec["units"]]
    threshold, height = spec["success_threshold"], spec["approach_height"]
    path, target = np.asarray(path, dtype=float), np.asarray(target, dtype=float)
    assert np.linalg.norm(path[-1] - target) <= threshold * (1 + 1e-9), (*context, "end")
    above = np.flatnonzero(path[:, 2] - target[2] >= height)
    assert above.size and above[-1] < len(path) - 1, (*context, "no entry from above")
    band = path[above[-1] + 1 :]
    assert (
        np.linalg.norm(band[:, :2] - target[:2], axis=1).max() <= threshold * (1 + 1e-9) + slack
    ), (*context, "lateral")
    heights = band[:, 2]
    assert np.max(heights - np.minimum.accumulate(heights)) <= RISE_MM * f * (1 + 1e-9), (
        *context,
        "rise",
    )


def check_commands(commands, limits, context):
    """The 1 kHz joint commands, the first and the last held three samples: every velocity, acceleration
    and jerk within the arm's limits, and the first and last command's acceleration at most 5 % of it."""
    q = np.asarray(commands, dtype=float)
    padded = np.concatenate([np.repeat(q[:1], 3, axis=0), q, np.repeat(q[-1:], 3, axis=0)])
    for order, limit in ((1, limits.velocity), (2, limits.acceleration), (3, limits.jerk)):
        if limit is None:
            continue
        rate = np.diff(padded, n=order, axis=0) / 1e-3**order
        assert np.all(np.abs(rate) <= np.asarray(limit) * (1 + 1e-9)), (*context, "limit", order)
    ends = np.abs(np.stack([q[1] - q[0], q[-2] - q[-1]])) / 1e-6
    assert np.all(ends <= 0.05 * np.asarray(limits.acceleration)), (*context, "not from rest")


def one_sentence(reason: str, context) -> None:
    assert reason and "\n" not in reason and len(reason) < 600, (*context, "reason", reason)


# ---------------------------------------------------------------------------------------------
# The property
# ---------------------------------------------------------------------------------------------
def _evaluated(spec: dict, seed: int):
    try:
        scenario = scenarios.from_dict(spec)
    except (
        scenarios.ScenarioError
    ) as exc:  # parts drawn overlapping, a target off its part: refused, named
        assert "overlap" in str(exc) or "not on part" in str(exc), str(exc)
        return None, None
    report = evaluate(scenario, ["dmp", "bidmp"])
    for name, result in report.methods.items():
        for label, rollout in result.rollouts.items():
            context = (seed, "evaluate", name, label)
            if result.task_success_at(label):
                target = spec["targets"][label]
                check_end_and_descent(rollout, target, spec, context)
                check_clear(rollout, spec, {label}, context)
            else:
                one_sentence(result.reason_at(label), context)
    return scenario, report


def _simulated(scenario, spec, seed, label):
    from bidmp import sim

    result = sim.simulate(scenario, ["bidmp"], targets=[label], workers=1, record=True)
    target = result.methods["bidmp"].targets[label]
    context = (seed, "sim", spec["robot"]["model"], label)
    if target.commands is not None:  # whatever its verdict, what ran never broke the margin
        check_clear(target.path, spec, {label}, context)
        check_commands(target.commands, result.limits, context)
    if not target.task_success(spec["success_threshold"]):
        one_sentence(target.reason, context)
        return
    # The measured tool: the arm's tracking wobble stays within the contract's own tolerances.
    check_end_and_descent(target.path, spec["targets"][label], spec, context)
    check_clear(target.path, spec, {label}, context)
    check_commands(target.commands, result.limits, context)


def _job(scenario, spec, seed, labels):
    """The job over ``labels`` in turn: every motion that ran — of a removed part, of a failed
    one, and of the next target after a failure (which starts where the failed one left the
    tool) — clear of every part by the margin and within the limits; a removed part's approach
    ends on its axis; a part not removed says why in one sentence."""
    from bidmp import sim
    from bidmp.sim.job import _job_parts

    report = sim.run_job(scenario, targets=labels, record=True)
    bin_parts = _job_parts(scenario, labels)
    limits = sim.robot_model(scenario.robot, scenario.base_dir).limits
    for record in report.targets:
        label = record.label
        context = (seed, "job", spec["robot"]["model"], label)
        if not record.removed:
            one_sentence(record.reason, context)
        for phase in record.phases:
            if phase.path is None:  # the engage check, or a motion refused before it ran
                continue
            phase_context = (*context, phase.name)
            if phase.name == "approach" and record.removed:
                check_end_and_descent(phase.path, spec["targets"][label], spec, phase_context)
            check_clear(phase.path, spec, {label}, phase_context, extra=bin_parts)
            check_commands(phase.commands, limits, phase_context)


@pytest.mark.parametrize("chunk", range(4))
def test_every_target_of_a_random_user_cell_meets_the_contract_or_says_why(chunk):
    """Independent oracle: closed-form geometry and differences of the commands written here (module
    docstring). A target that fails must say why in one sentence; nothing may raise."""
    seeds = range(chunk * N_CELLS // 4, (chunk + 1) * N_CELLS // 4)
    ran = 0
    for seed in seeds:
        spec = user_cell(seed)
        scenario, report = _evaluated(spec, seed)
        if scenario is None:
            continue
        ran += 1
        if seed % EVERY:
            continue
        labels = scenario.labels
        far = labels[-1]
        _simulated(scenario, spec, seed, far)
        first = seed % len(labels)
        _job(scenario, spec, seed, list(dict.fromkeys([labels[first], labels[first - 1]])))
    assert ran > 0


def test_the_checks_can_fail():
    """Structure guard for the oracles above: a path through a nut, a path that rises in the band,
    commands that jump, each refused."""
    spec = user_cell(3)
    target = np.asarray(spec["targets"]["r0c0"])
    f = UNITS[spec["units"]]
    down = target + np.outer(np.linspace(1.0, 0.0, 40), [0.0, 0.0, 2 * spec["approach_height"]])
    neighbour = np.asarray(list(spec["targets"].values())[1])
    with pytest.raises(AssertionError, match="clearance"):
        check_clear(np.vstack([down, neighbour]), spec, {"r0c0"}, ("probe",))
    bump = np.vstack(
        [down[:-1], target - [0.0, 0.0, 0.2 * f], target]
    )  # 0.2 mm below, then back up
    check_end_and_descent(
        np.vstack([down[:-1], target - [0.0, 0.0, 0.1 * f], target]), target, spec, ("probe",)
    )
    with pytest.raises(AssertionError, match="rise"):
        check_end_and_descent(bump, target, spec, ("probe",))
    from bidmp.sim import PANDA

    steady = np.zeros((50, 7))
    jump = steady.copy()
    jump[25:, 0] = 0.01
    check_commands(steady, PANDA, ("probe",))
    with pytest.raises(AssertionError, match="limit"):
        check_commands(jump, PANDA, ("probe",))
