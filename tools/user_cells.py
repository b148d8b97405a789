"""Users' cells end to end: the built-in nut task with two 68 mm posts in the way, and a battery module
with a 90 mm cable duct between the demonstrated nut and the far ones (tests/data), the duct module in
mm, cm and m. Every target through the evaluation (the plain DMP, and Bi-DMP with its repairs), on the
simulated arm (Bi-DMP's motions) and in the whole job; one Markdown table (make readme copies it to
docs/results/user_cells.md).

    .venv/bin/python tools/user_cells.py [--out FILE]
"""

from __future__ import annotations

import argparse
import collections
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests"))
sys.path.insert(0, str(ROOT / "tests" / "tasks"))
from test_user_cells import spec  # noqa: E402  (the cells and their unit conversion, as the tests use them)

from bidmp import sim  # noqa: E402
from bidmp.tasks import evaluate, scenarios  # noqa: E402

CELLS = (
    ("two_posts.json", "mm"),
    ("duct_module.json", "mm"),
    ("duct_module.json", "cm"),
    ("duct_module.json", "m"),
)


def row(name: str, units: str) -> list[str]:
    scenario = scenarios.from_dict(spec(name, units))
    n = len(scenario.labels)
    report = evaluate(scenario, ["dmp", "bidmp"])
    dmp, bidmp = report.methods["dmp"], report.methods["bidmp"]
    hows = collections.Counter(
        bidmp.repaired_at(label) for label in bidmp.repairs if bidmp.repaired_at(label)
    )
    repaired = ", ".join(f"{how} {count}" for how, count in sorted(hows.items())) or "-"
    ran = sim.simulate(scenario, ["bidmp"], workers=2).methods["bidmp"]
    job = sim.run_job(scenario)
    return [
        scenario.name,
        units,
        f"{dmp.task_successes}/{n}",
        f"{bidmp.task_successes}/{n}",
        repaired,
        f"{ran.task_successes}/{n}",
        f"{ran.contacts}",
        f"{ran.within_limits}/{n}",
        f"{job.removed}/{n}",
        f"{sum(t.within_limits for t in job.targets)}/{n}",
    ]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=None, help="write the Markdown table here too")
    args = parser.parse_args()
    header = [
        "cell",
        "units",
        "evaluate: dmp",
        "evaluate: bidmp",
        "repaired (how)",
        "sim: bidmp",
        "contacts",
        "within limits",
        "job: removed",
        "job: within limits",
    ]
    rows = [row(name, units) for name, units in CELLS]
    table = (
        "\n".join(
            ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
            + ["| " + " | ".join(cells) + " |" for cells in rows]
        )
        + "\n"
    )
    print(table)
    if args.out:
        Path(args.out).write_text(table)


if __name__ == "__main__":
    main()
