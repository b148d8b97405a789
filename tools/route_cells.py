"""The route property on random users' cells that stress the arm's routes (tests/sim/route_oracle.py):
every target an oracle of the test's own says has a route (plain RRT with 20 times the pipeline's
budget, its own IK and seeds) must be a task success on the simulated arm and removed in the job,
no motion that ran may break the contract by the test's own checks, and no reason may call a target
"unreachable" where the oracle's inverse kinematics reaches it. One Markdown table per run (make
routes: BIDMP_ROUTE_CELLS cells, default 40) and every failure with the oracle's view; the exit
status is 1 when the property fails.

    .venv/bin/python tools/route_cells.py [--cells N] [--first SEED] [--workers 2] [--out FILE]
"""

from __future__ import annotations

import argparse
import collections
import os
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "sim"))
# the cells, the oracle and the checks, as the tests use them
from route_oracle import ORACLE_CHECKS, run_cell  # noqa: E402

OUT = ROOT / "docs" / "results" / "route_cells.md"


def one(seed: int):
    """Cell ``seed`` through the oracle, bidmp demo, sim and job (in its own folder)."""
    with tempfile.TemporaryDirectory() as folder:
        began = time.perf_counter()
        outcome = run_cell(seed, folder)
        outcome.facts.folder = None  # (a path of this process's)
        return outcome, time.perf_counter() - began


def _count(rows, key) -> str:
    ran = [row for row in rows if getattr(row, key) is not None]
    return f"{sum(bool(getattr(row, key)) for row in ran)}/{len(ran)}"


def _hows(rows) -> str:
    """How the targets were solved: the evaluation's repairs, the simulator's and the job's use
    of the arm's own route, counted."""
    counts = collections.Counter()
    for row in rows:
        if row.demo and row.demo_how:
            counts[f"demo {row.demo_how}"] += 1
        if row.sim and "arm route" in row.sim_how:
            counts["sim arm route"] += 1
        if row.job and "route" in row.job_how:
            counts["job arm route"] += 1
    return ", ".join(f"{how} {n}" for how, n in sorted(counts.items())) or "-"


def table(outcomes) -> str:
    head = (
        "| cell | arm | units | grid | tilted | bin | targets | with a route (oracle) | owed: sim / job "
        "| solved: demo | sim | job | refusals executed | unreachable with a solution | how |"
    )
    lines = [head, "|" + "---|" * 15]
    totals = collections.Counter()
    for outcome in outcomes:
        facts, rows = outcome.facts, list(outcome.rows.values())
        labels = list(outcome.rows)
        routed = sum(row.decision.approach for row in rows)
        owed_sim = [label for label in labels if outcome.owed(label, "sim")]
        owed_job = [label for label in labels if outcome.owed(label, "job")]
        solved = {
            key: sum(bool(getattr(outcome.rows[label], key)) for label in owed)
            for key, owed in (("sim", owed_sim), ("job", owed_job))
        }
        lines.append(
            f"| {facts.seed} | {facts.arm} | {facts.units} | {facts.grid[0]} x {facts.grid[1]} "
            f"| {len(facts.tilted)} ({facts.tilt or '-'}) | {facts.bin} | {len(rows)} | {routed} "
            f"| {len(owed_sim)} / {len(owed_job)} | {_count(rows, 'demo')} "
            f"| {_count(rows, 'sim')} ({solved['sim']}/{len(owed_sim)} owed) "
            f"| {_count(rows, 'job')} ({solved['job']}/{len(owed_job)} owed) "
            f"| {len(outcome.refused)} | {len(outcome.unreachable)} | {_hows(rows)} |"
        )
        totals.update(
            targets=len(rows),
            routed=routed,
            owed_sim=len(owed_sim),
            owed_job=len(owed_job),
            demo=sum(bool(row.demo) for row in rows),
            sim=sum(bool(row.sim) for row in rows),
            job=sum(bool(row.job) for row in rows),
            sim_owed=solved["sim"],
            job_owed=solved["job"],
            refused=len(outcome.refused),
            unreachable=len(outcome.unreachable),
        )
    t = totals
    lines.append(
        f"| **all** | | | | | | {t['targets']} | {t['routed']} | {t['owed_sim']} / {t['owed_job']} "
        f"| {t['demo']}/{t['targets']} | {t['sim']}/{t['targets']} ({t['sim_owed']}/{t['owed_sim']} owed) "
        f"| {t['job']}/{t['targets']} ({t['job_owed']}/{t['owed_job']} owed) | {t['refused']} "
        f"| {t['unreachable']} | |"
    )
    return "\n".join(lines)


def failures(outcomes) -> str:
    """Every breach of the property, one line each, with the oracle's view."""
    lines = []
    for outcome in outcomes:
        seed, arm = outcome.facts.seed, outcome.facts.arm
        for label, where, reason in outcome.unsolved():
            decision = outcome.rows[label].decision
            lines.append(
                f"- cell {seed} ({arm}) {label}, {where}: not solved though the oracle found a route "
                f"({decision.checks} configurations tested): {reason}"
            )
        for where, label, what in outcome.refused:
            lines.append(
                f"- cell {seed} ({arm}) {label}, {where}: ran and broke the contract: {what}"
            )
        for where, label, reason in outcome.unreachable:
            lines.append(
                f"- cell {seed} ({arm}) {label}, {where}: called unreachable though the oracle's "
                f"IK reaches it: {reason}"
            )
    return "\n".join(lines)


def report(outcomes, seeds, command: str, planned: int) -> str:
    """The Markdown of the cells run so far (``planned``: how many the run was asked for)."""
    done = sorted(outcome.facts.seed for outcome in outcomes)
    ran = f"{len(outcomes)} of {planned}" if len(outcomes) < planned else f"{len(outcomes)}"
    text = (
        f"{ran} random users' cells (seeds {', '.join(map(str, done)) or '-'}; "
        f"tests/sim/route_oracle.py), written by `{command}`. *With a route*: the oracle's plain RRT "
        f"({ORACLE_CHECKS} configurations) joins the arm's start to the top of the target's final "
        "approach, the approach down its axis free. *Owed*: with a route, and for the simulator "
        "every motion's start (the demonstration's) joined to the arm's, for the job its retract "
        "free and every drop over the bin routed too; *solved*: task successes (in brackets: of "
        "those owed).\n\n" + table(outcomes) + "\n"
    )
    text += (
        "\nSeconds per cell (oracle, demo, sim, job): "
        + ", ".join(
            f"{o.facts.seed}: "
            + "/".join(f"{o.seconds.get(k, 0.0):.0f}" for k in ("oracle", "demo", "sim", "job"))
            for o in outcomes
        )
        + "\n"
    )
    broken = failures(outcomes)
    text += "\n" + (f"Failures:\n\n{broken}\n" if broken else "No failures.\n")
    return text


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cells", type=int, default=int(os.environ.get("BIDMP_ROUTE_CELLS", "40")))
    parser.add_argument("--first", type=int, default=0, help="the first cell's seed")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", default=str(OUT), help=f"the Markdown table (default {OUT})")
    args = parser.parse_args()
    if not 1 <= args.cells <= 10_000 or not 0 <= args.first <= 10**6:
        parser.error("--cells must be 1 to 10000 and --first 0 to 1000000")
    if not 1 <= args.workers <= 64:
        parser.error("--workers must be 1 to 64")
    from bidmp.io import atomic_write

    seeds = range(args.first, args.first + args.cells)
    command = (
        f"python tools/route_cells.py --cells {args.cells} --first {args.first} "
        f"--workers {args.workers}"
    )
    outcomes = []
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    with ProcessPoolExecutor(max_workers=args.workers) as pool:
        for future in as_completed([pool.submit(one, seed) for seed in seeds]):
            outcome, seconds = future.result()
            outcomes.append(outcome)
            print(
                f"cell {outcome.facts.seed} ({outcome.facts.arm}): {len(outcome.rows)} targets, "
                f"{len(outcome.unsolved())} unsolved, {len(outcome.refused)} refused, "
                f"{len(outcome.unreachable)} unreachable with a solution, {seconds:.0f} s "
                f"{ {k: round(v) for k, v in outcome.seconds.items()} }",
                flush=True,
            )
            # written after every cell: a run cut short leaves the cells it finished
            with atomic_write(args.out, "w") as handle:
                handle.write(report(outcomes, seeds, command, args.cells))
    text = report(outcomes, seeds, command, args.cells)
    print(text)
    return 1 if failures(outcomes) else 0


if __name__ == "__main__":
    sys.exit(main())
