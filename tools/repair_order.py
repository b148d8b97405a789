"""Why the repairs are tried in the order they are: each repair alone on every motion that breaks the
contract, on random users' cells (the generator of ``tests/tasks/test_random_user_cells.py``: nut modules
in mm, cm and m with posts, bosses, ducts and tilted brackets) and on the two users' cells of the
tests (two posts, the duct module). Per repair: how many of the broken motions it alone makes keep the
contract, and its median time per motion; then the order :data:`bidmp.tasks.repair.REPAIRS` on the
same motions. Motions that miss their end or engagement go to the extension in any order (a lift or a
steer does not bring a motion onto its target), so they are counted apart.

    .venv/bin/python tools/repair_order.py [--cells 40] [--first-seed 0] [--out FILE]

``--out`` writes the table as Markdown too (make readme: docs/results/repair_order.md).
"""

from __future__ import annotations

import argparse
import json
import logging
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tests" / "tasks"))
from test_random_user_cells import user_cell  # noqa: E402  (the random cells as the tests draw them)

from bidmp.tasks import evaluate, scenarios  # noqa: E402
from bidmp.tasks.contract import Contract  # noqa: E402
from bidmp.tasks.repair import REPAIRS, Repairer  # noqa: E402


def broken_motions(spec: dict):
    """``(scenario, model, label, motion, verdict)`` of each Bi-DMP motion of ``spec`` that breaks the
    contract, unrepaired, whose final approach is not blocked."""
    try:
        scenario = scenarios.from_dict(spec)
    except scenarios.ScenarioError:  # a drawn cell the scenario refuses (parts overlapping)
        return
    report = evaluate(scenario, ["bidmp"], repair=False)
    result, model = report.methods["bidmp"], report.fitted["bidmp"]
    for label in scenario.labels:
        verdict = result.verdicts[label]
        if not verdict.ok:
            yield scenario, model, label, result.rollouts[label], verdict


def repairer(scenario, order) -> Repairer:
    return Repairer(
        Contract.of(scenario),
        scenario.demonstration,
        extension=scenario.extension,
        seed=scenario.seed,
        bidmp=scenario.bidmp,
        order=order,
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=40, help="random cells drawn (default 40)")
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--out", type=Path, help="write the Markdown table here too")
    args = parser.parse_args()
    specs = [user_cell(seed) for seed in range(args.first_seed, args.first_seed + args.cells)]
    specs += [
        json.loads((ROOT / "tests" / "data" / name).read_text())
        for name in ("two_posts.json", "duct_module.json")
    ]
    orders = [(how,) for how in REPAIRS if how != "margin"] + [REPAIRS]
    logging.basicConfig(level=logging.ERROR)  # a repair that finds no route says so at WARNING
    kinds = ("too close", "off target")
    counts = {(order, kind): [0, []] for order in orders for kind in kinds}
    seen = dict.fromkeys(kinds, 0)
    blocked = 0
    for spec in specs:
        for scenario, model, label, motion, verdict in broken_motions(spec):
            scene = scenario.scene
            exclude = scene.target_parts(label, scenario.targets[label])
            axis = scenario.target_axis(label)
            if repairer(scenario, REPAIRS).blocked(scenario.targets[label], axis, exclude):
                blocked += 1
                continue
            kind = kinds[0] if set(verdict.failed) <= {"clearance"} else kinds[1]
            seen[kind] += 1
            for order in orders:
                if kind == kinds[1] and "extend" not in order:
                    continue  # skipped by design: nothing but an extension brings a motion onto its target
                started = time.perf_counter()
                fixed = repairer(scenario, order).repair(
                    model,
                    scenario.targets[label],
                    label,
                    axis=axis,
                    exclude=exclude,
                    motion=motion,
                    verdict=verdict,
                )
                counts[order, kind][1].append(time.perf_counter() - started)
                counts[order, kind][0] += bool(fixed.how)
    lines = [
        f"{len(specs)} cells; broken motions: {seen['too close']} only too close to a part, "
        f"{seen['off target']} missing the end or the engagement; {blocked} refused at once (final approach "
        "blocked)",
        "",
        "| repairs | motion broken by | kept within the contract | median s per motion | mean s per motion |",
        "|---|---|---|---|---|",
    ]
    for (order, kind), (ok, seconds) in counts.items():
        if seconds:
            lines.append(
                f"| {' -> '.join(order)} | {kind} | {ok}/{seen[kind]} | {statistics.median(seconds):.3f} | "
                f"{statistics.fmean(seconds):.3f} |"
            )
    text = "\n".join(lines) + "\n"
    print(text, end="")
    if args.out is not None:
        partial = args.out.with_name(args.out.name + ".partial")
        partial.write_text(text, encoding="utf-8")
        partial.replace(args.out)  # atomically


if __name__ == "__main__":
    main()
