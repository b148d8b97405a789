"""What a repair costs: a target whose motion must be repaired against a plain evaluation of a target
(the skill learned, rolled out, judged), on the users' cells of the tests (the nut task with two
posts, the duct module: the whole evaluation with and without its repairs, the difference shared
among the repaired targets), and for each repair on its own (a post across a skill's way: lift,
avoid, extend; the skill learned and its motion judged, with and without the repair).

    .venv/bin/python benchmarks/bench_repair.py [--rounds 7] [--smoke]

The two sides are interleaved, round by round, the order alternating; the median of each and their
ratio are printed (the machines are noisy: the ratio is the number). The target: at most 3x.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numpy as np

from bidmp.tasks import evaluate, scenarios

DATA = Path(__file__).resolve().parents[1] / "tests" / "data"


def cold(scenario, repair: bool):
    """One evaluation as a user runs it: the BLS's remembered mappings cleared first (within one
    evaluation the repairs' learns reuse the shared model's; across rounds a benchmark would reuse
    them all and time a warm cache no user meets)."""
    from bidmp.incremental import bls

    bls._MAPPINGS.clear()
    return evaluate(scenario, ["bidmp"], repair=repair)


def interleaved(first, second, rounds: int) -> tuple[float, float]:
    """Medians (s) of ``first`` and ``second`` timed in alternating order over ``rounds`` rounds."""
    first(), second()  # warm-up
    times = ([], [])
    for index in range(rounds):
        order = (0, 1) if index % 2 == 0 else (1, 0)
        for which in order:
            start = time.perf_counter()
            (first, second)[which]()
            times[which].append(time.perf_counter() - start)
    return statistics.median(times[0]), statistics.median(times[1])


def cells(rounds: int, smoke: bool) -> list[str]:
    """The whole evaluation of a cell with and without its repairs: a repaired target costs the plain
    cost of a target plus its share of the difference."""
    lines = []
    for name in ("two_posts.json",) if smoke else ("two_posts.json", "duct_module.json"):
        scenario = scenarios.from_dict(json.loads((DATA / name).read_text()))
        repaired = evaluate(scenario, ["bidmp"]).methods["bidmp"]
        hows = [
            repaired.repaired_at(label) for label in repaired.repairs if repaired.repaired_at(label)
        ]
        assert hows and repaired.task_successes == len(scenario.labels), name
        plain, repair = interleaved(
            lambda: cold(scenario, False), lambda: cold(scenario, True), rounds
        )
        per_target = plain / len(scenario.labels)
        cost = per_target + (repair - plain) / len(hows)
        lines.append(
            f"{name:18s} {len(hows):2d}/{len(scenario.labels):<3d} {'+'.join(sorted(set(hows))):7s} "
            f"{1e3 * per_target:9.1f} {1e3 * cost:9.1f} {cost / per_target:6.2f}x"
        )
    return lines


def each_repair(rounds: int, smoke: bool) -> list[str]:
    """A skill (the robot protocol) whose motion to a far goal passes a post: each repair alone."""
    from bidmp import DMP, Scene
    from bidmp.demonstrations import minimum_jerk
    from bidmp.tasks.contract import Contract
    from bidmp.tasks.repair import Repairer

    demo = minimum_jerk([[-100, -120, 150], [0, 0, 35], [0, 0, 0]], 300)
    t = np.linspace(0, 3, 300)
    scene = Scene.from_dict(
        {
            "tool": {"radius": 10.0, "length": 100.0},
            "margin": 3.0,
            "standoff": {"plate": 1.0},
            "parts": [
                {"type": "plate", "label": "plate", "at": [0, 0, -2], "size": [400, 400, 5]},
                {
                    "type": "cylinder",
                    "label": "post",
                    "at": [60, -33, -2],
                    "radius": 5.0,
                    "height": 80.0,
                },
            ],
        }
    )
    contract = Contract(1.75, 25.0, scene, "mm")
    goal = np.array([120.0, 0.0, 0.0])

    def plain():  # the skill learned, rolled out, judged
        dmp = DMP().fit(demo, t, units="mm")
        return contract.judge(dmp.trajectory(goal).y, goal)

    lines = []
    for how in ("lift",) if smoke else ("lift", "avoid", "extend"):

        def repaired(how=how):
            dmp = DMP().fit(demo, t, units="mm")
            return Repairer(contract, demo, order=(how,)).repair(dmp, goal, "far")

        outcome = repaired()
        base, cost = interleaved(plain, repaired, rounds)
        lines.append(
            f"{'post across a skill':18s} {'1/1':6s} {how:7s} {1e3 * base:9.1f} {1e3 * cost:9.1f} {cost / base:6.2f}x"
            f"{'' if outcome.ok else '  (not repaired: ' + outcome.reason()[:60] + ')'}"
        )
    return lines


def tilted(rounds: int, smoke: bool) -> list[str]:
    """Pose cells with tilted targets: the user's kind of cell of the tests (a nut on a 20 degree
    bracket, in metres) and random tilted plates (tests/tasks/test_random_tilted_cells.py), the
    whole evaluation with its repairs against the same evaluation without them (the target:
    repairs of tilted targets at most 3x a plain evaluation)."""
    import sys
    import tempfile

    sys.path.insert(0, str(DATA.parent / "tasks"))
    from test_random_tilted_cells import random_tilted_cell
    from test_tilted_user_cells import bracket_cell

    folder = Path(tempfile.mkdtemp())
    cases = [("bracket 20 deg, m", scenarios.load(str(bracket_cell(folder, "m", 20.0))))]
    for seed in () if smoke else range(4):
        try:
            cases.append((f"tilted plate {seed}", scenarios.from_dict(random_tilted_cell(seed)[0])))
        except scenarios.ScenarioError:  # a random layout whose parts overlap
            continue
    lines = []
    for name, scenario in cases:
        repaired = evaluate(scenario, ["bidmp"]).methods["bidmp"]
        hows = [
            repaired.repaired_at(label) for label in repaired.repairs if repaired.repaired_at(label)
        ]
        plain, repair = interleaved(
            lambda scenario=scenario: cold(scenario, False),
            lambda scenario=scenario: cold(scenario, True),
            rounds,
        )
        # as the flat cells are counted: a target's plain share, plus its share of the difference
        per_target = plain / len(scenario.labels)
        cost = per_target + (repair - plain) / max(len(hows), 1)
        lines.append(
            f"{name:18s} {len(hows):2d}/{len(scenario.labels):<3d} {'+'.join(sorted(set(hows))) or '-':7s} "
            f"{1e3 * plain:9.1f} {1e3 * repair:9.1f} {repair / plain:6.2f}x  (whole evaluation, "
            f"{repaired.task_successes}/{len(scenario.labels)} task successes; per repaired "
            f"target {1e3 * per_target:.1f} -> {1e3 * cost:.1f} ms, {cost / per_target:.2f}x)"
        )
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--smoke", action="store_true", help="one case each, two rounds (CI)")
    args = parser.parse_args()
    rounds = 2 if args.smoke else args.rounds
    print("cell               repaired repair  plain ms  repaired ms  ratio   (per target)")
    for line in (
        cells(rounds, args.smoke) + each_repair(rounds, args.smoke) + tilted(rounds, args.smoke)
    ):
        print(line)


if __name__ == "__main__":
    main()
