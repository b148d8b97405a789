"""Obstacle avoidance against movement_primitives on the same random fields.

    .venv/bin/python benchmarks/bench_avoidance.py [--fields N] [--out DIR]
    make avoidance        # 50 fields, writes docs/results/avoidance.md and docs/avoidance.png

Each field (bidmp.experiments.random_case, bidmp.scene.random_field: 1-4 tall posts and boxes
across the line from start to goal,
a free path by construction) gets a random demonstration (mm or m, 2-5 s); both libraries learn
it and roll it out at 1 kHz with their avoidance: bidmp ``SceneAvoidance`` on the parts' exact
geometry, movement_primitives' ``CouplingTermObstacleAvoidance3D`` (Hoffmann et al. 2009, its
defaults) with one point obstacle at each part's centre, summed. Measured on what each returns:
the exact clearance to the parts (coal, for both), the goal error, the path length over the plain
motion's, the peak jerk (third differences of the positions, the same estimator for both) and the
time per rollout (the two sides interleaved field by field). A field counts as a success when the
motion keeps the margin and ends within 1 mm of its goal; bidmp's misses are raised
(AvoidanceError), movement_primitives' are silent.

Then speed: a coupled 1 kHz rollout of the nut task's demonstration (4 s, robot protocol) on the
nut scene, as a multiple of real time (one core); and a trajectory through two via-points against
a plain ``trajectory()`` at 1 kHz (the ratio).
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

from bidmp import DMP
from bidmp.experiments import random_case
from bidmp.primitives import AvoidanceError, SceneAvoidance
from bidmp.tasks import scenarios

DT = 0.001


class _PointObstacles:
    """movement_primitives' 3-D avoidance term, one per obstacle point, summed."""

    def __init__(self, points):
        from movement_primitives.dmp import CouplingTermObstacleAvoidance3D

        self.terms = [CouplingTermObstacleAvoidance3D(point) for point in points]

    def coupling(self, y, yd):
        accelerations = [term.coupling(y, yd)[1] for term in self.terms]
        return np.zeros_like(y), np.sum(accelerations, axis=0)


def run_bidmp(demonstration, t, scene):
    dmp = DMP().fit(demonstration, t)
    start = time.perf_counter()
    try:
        y, reported = dmp.trajectory(dt=DT, coupling=[SceneAvoidance(scene)]).y, False
    except AvoidanceError as error:
        y, reported = error.trajectory.y, True
    return y, time.perf_counter() - start, reported, dmp.trajectory(dt=DT).y


def run_peer(demonstration, t, scene):
    from movement_primitives.dmp import DMP as PeerDMP

    peer = PeerDMP(n_dims=3, execution_time=float(t[-1]), dt=DT, n_weights_per_dim=50)
    peer.imitate(t, demonstration)
    peer.configure(start_y=demonstration[0], goal_y=demonstration[-1])
    centres = [solid.centre for solid in scene.solids]
    start = time.perf_counter()
    _, y = peer.open_loop(run_t=1.1 * float(t[-1]), coupling_term=_PointObstacles(centres))
    return y, time.perf_counter() - start


def measure(y, plain, goal, scene, unit) -> dict:
    clearance = scene.clearance(y).distance
    jerk = np.diff(y, 3, axis=0) / DT**3
    return {
        "clear": clearance >= scene.margin,
        "clearance": clearance / unit,
        "margin": scene.margin / unit,
        "goal": float(np.linalg.norm(y[-1] - goal)) / unit,
        "length": float(
            np.sum(np.linalg.norm(np.diff(y, axis=0), axis=1))
            / np.sum(np.linalg.norm(np.diff(plain, axis=0), axis=1))
        ),
        "jerk": float(np.max(np.linalg.norm(jerk, axis=1))) / unit,
    }


def fields_table(n_fields: int, figure: Path | None) -> str:
    rows = {
        "bidmp SceneAvoidance": [],
        "movement_primitives CouplingTermObstacleAvoidance3D": [],
        "plain DMP, no avoidance (reference)": [],
    }
    times = {name: [] for name in rows}
    reported, shown = 0, None
    for seed in range(n_fields):
        demonstration, t, scene, unit = random_case(seed)
        ours, our_time, was_reported, plain = run_bidmp(demonstration, t, scene)
        theirs, their_time = run_peer(demonstration, t, scene)
        reported += was_reported
        for name, y, seconds in (
            ("bidmp SceneAvoidance", ours, our_time),
            ("movement_primitives CouplingTermObstacleAvoidance3D", theirs, their_time),
        ):
            rows[name].append(measure(y, plain, demonstration[-1], scene, unit))
            times[name].append(seconds)
        rows["plain DMP, no avoidance (reference)"].append(
            measure(plain, plain, demonstration[-1], scene, unit)
        )
        times["plain DMP, no avoidance (reference)"].append(float("nan"))
        if (
            shown is None
            and rows["bidmp SceneAvoidance"][-1]["clear"]
            and not rows["movement_primitives CouplingTermObstacleAvoidance3D"][-1]["clear"]
            and unit == 1.0
        ):
            shown = (seed, demonstration, plain, ours, theirs, scene)
    if figure is not None and shown is not None:
        _figure(figure, *shown)
    lines = [
        f"{n_fields} random fields (`python benchmarks/bench_avoidance.py --fields {n_fields}`), 1 kHz; "
        f"medians over the fields, lengths and jerk in mm (fields in m converted).",
        "",
        "| method | keeps the margin | within 1 mm of the goal | both | min clearance − margin (mm, median) | "
        "goal error (mm, median) | path length / plain | peak jerk (m/s³, median) | ms per rollout |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name, measured in rows.items():
        clear = sum(m["clear"] for m in measured)
        near = sum(m["goal"] <= 1.0 for m in measured)
        both = sum(m["clear"] and m["goal"] <= 1.0 for m in measured)
        lines.append(
            f"| {name} | {clear}/{n_fields} | {near}/{n_fields} | {both}/{n_fields} | "
            f"{statistics.median(m['clearance'] - m['margin'] for m in measured):.1f} | "
            f"{statistics.median(m['goal'] for m in measured):.3g} | "
            f"{statistics.median(m['length'] for m in measured):.3f} | "
            f"{statistics.median(m['jerk'] for m in measured) / 1e3:.1f} | "
            + (
                "- |"
                if np.isnan(times[name][0])
                else f"{1e3 * statistics.median(times[name]):.0f} |"
            )
        )
    lines += [
        "",
        f"bidmp reported {reported} of its "
        f"{n_fields - sum(m['clear'] and m['goal'] <= 1.0 for m in rows['bidmp SceneAvoidance'])} "
        f"misses as AvoidanceError; movement_primitives reports none (it has no geometry to check).",
    ]
    return "\n".join(lines) + "\n"


def _figure(path: Path, seed, demonstration, plain, ours, theirs, scene) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Circle, Polygon

    figure, axis = plt.subplots(figsize=(6.5, 6.5), layout="constrained")
    keep = scene.tool.radius + scene.margin  # how far the tool's axis must stay from a part
    for part in scene.to_dict()["parts"]:
        centre = np.asarray(part["at"][:2])
        if part["type"] == "cylinder":
            axis.add_patch(Circle(centre, part["radius"], color="0.6"))
            axis.add_patch(Circle(centre, part["radius"] + keep, fill=False, ls=":", color="0.3"))
        else:
            yaw = np.radians(part.get("yaw", 0.0))
            half = np.asarray(part["size"][:2]) / 2
            rotation = np.array([[np.cos(yaw), -np.sin(yaw)], [np.sin(yaw), np.cos(yaw)]])
            corners = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * half
            axis.add_patch(Polygon(centre + corners @ rotation.T, color="0.6"))
            angles = np.linspace(0, 2 * np.pi, 73)
            ring = np.concatenate(
                [
                    corner + keep * np.column_stack([np.cos(a), np.sin(a)])
                    for corner, a in zip(corners, np.split(angles[:-1] - np.pi, 4))
                ]
            )
            hull = ring[np.argsort(np.arctan2(ring[:, 1], ring[:, 0]))]
            axis.add_patch(Polygon(centre + hull @ rotation.T, fill=False, ls=":", color="0.3"))
    axis.plot(*plain[:, :2].T, color="0.3", ls="--", label="plain DMP: goes through the parts")
    axis.plot(
        *ours[:, :2].T, color="C0", lw=2, label="bidmp SceneAvoidance: the parts' exact geometry"
    )
    axis.plot(
        *theirs[:, :2].T,
        color="C3",
        label="movement_primitives: a point obstacle at each part's centre",
    )
    axis.plot(*demonstration[0, :2], "ko")
    axis.annotate("start", demonstration[0, :2], xytext=(6, 0), textcoords="offset points")
    axis.plot(*demonstration[-1, :2], "k*", ms=10)
    axis.annotate("goal", demonstration[-1, :2], xytext=(6, -10), textcoords="offset points")
    axis.set(xlabel="x (mm)", ylabel="y (mm)", aspect="equal")
    axis.set_title(
        f"Random field {seed}: {len(scene.parts)} tall parts the demonstration never saw\n"
        f"(grey; dotted: where the {2 * scene.tool.radius:.0f} mm tool's axis keeps the {scene.margin:.1f} mm margin)",
        fontsize=10,
    )
    axis.legend(loc="upper center", bbox_to_anchor=(0.5, -0.1), fontsize=9)
    path.parent.mkdir(parents=True, exist_ok=True)
    figure.savefig(path, dpi=110)
    plt.close(figure)


def speed_lines(repeats: int) -> str:
    scenario = scenarios.load("nut-unscrewing")
    demonstration = scenario.demonstration
    dmp = DMP().fit(demonstration, np.linspace(0, 4, len(demonstration)))
    target = np.asarray(scenario.targets["13"])
    rollouts = []
    for _ in range(repeats):
        start = time.perf_counter()
        trajectory = dmp.trajectory(
            target, dt=DT, coupling=[SceneAvoidance(scenario.scene, target="13")]
        )
        rollouts.append((time.perf_counter() - start, trajectory.t[-1]))
    seconds, motion = statistics.median(r[0] for r in rollouts), rollouts[0][1]
    via = [
        (1.5, dmp.trajectory(target, dt=DT).y[1500] + [10.0, 0, 5.0]),
        (2.5, dmp.trajectory(target, dt=DT).y[2500] + [0, 8.0, 0]),
    ]
    plain_times, via_times = [], []
    for _ in range(repeats * 5):  # interleaved
        start = time.perf_counter()
        dmp.trajectory(target, dt=DT)
        plain_times.append(time.perf_counter() - start)
        start = time.perf_counter()
        dmp.trajectory(target, dt=DT, via=via)
        via_times.append(time.perf_counter() - start)
    ratio = statistics.median(via_times) / statistics.median(plain_times)
    return (
        f"Nut scene, robot-protocol DMP, 4 s motion ({motion:.2f} s with its settling) at 1 kHz with SceneAvoidance: "
        f"{motion / seconds:.1f}x faster than real time (one core, median of {repeats}).\n"
        f"Two via-points: {ratio:.2f}x a plain trajectory() at 1 kHz (median of {repeats * 5}, interleaved).\n"
    )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--fields", type=int, default=50)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument(
        "--out",
        type=Path,
        help="write avoidance.md here and avoidance.png beside the README's figures",
    )
    args = parser.parse_args()
    text = (
        fields_table(args.fields, None if args.out is None else args.out.parent / "avoidance.png")
        + "\n"
        + speed_lines(args.repeats)
    )
    print(text)
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        (args.out / "avoidance.md").write_text(text, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
