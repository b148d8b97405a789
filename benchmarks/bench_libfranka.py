"""bidmp's FCI judge (:func:`bidmp.sim.fci.judge_commands`) against libfranka: generated FR3 command
streams (tests/fci_streams.py: smooth moves, planted steps in position, velocity, acceleration
and jerk, DMPs from rest, moves to the ends of the ranges, each sized around its threshold)
judged by bidmp and streamed through pylibfranka to franka-sim with the motion limits enforced.
Needs the side environment (make franka).

    .venv/bin/python benchmarks/bench_libfranka.py [--streams 240] [--seed 2026] [--out DIR]

Prints, and with --out writes DIR/libfranka.md: per kind of stream, how many each side accepted
and on how many they agree; every disagreement listed with both verdicts. Also times bidmp's
judge on a 10 s motion (``bidmp verify``'s speed target: 50 ms).
"""

from __future__ import annotations

import argparse
import collections
import os
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))

from fci_streams import streams  # noqa: E402

from bidmp.sim.fci import judge_commands  # noqa: E402
from bidmp.sim.libfranka import stream_fr3  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--streams", type=int, default=240)
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()
    generated = streams(args.streams, args.seed)
    verdicts = [judge_commands(q, "fr3") for _, q in generated]
    start = time.perf_counter()
    outcomes = stream_fr3([q for _, q in generated])
    elapsed = time.perf_counter() - start
    table = collections.defaultdict(lambda: [0, 0, 0, 0])
    disagreements = []
    same_reflex = 0
    for index, ((kind, q), verdict, outcome) in enumerate(zip(generated, verdicts, outcomes)):
        row = table[kind]
        row[0] += 1
        row[1] += verdict.ok
        row[2] += outcome.accepted
        row[3] += verdict.ok == outcome.accepted
        if not verdict.ok and not outcome.accepted and verdict.reflex in outcome.reflexes:
            same_reflex += 1
        if verdict.ok != outcome.accepted:
            disagreements.append(
                f"| {index} | {kind} | {len(q)} | "
                f"{'accepted' if verdict.ok else verdict.reason()} | "
                f"{'accepted' if outcome.accepted else outcome.reason()} |"
            )
    rejected_both = sum(not v.ok and not o.accepted for v, o in zip(verdicts, outcomes))
    samples = sum(len(q) for _, q in generated)
    lines = [
        "# bidmp's FCI judge against libfranka",
        "",
        f"{len(generated)} generated FR3 streams (seed {args.seed}, {samples} commands, "
        f"{samples / 1000:.0f} s at 1 kHz), each judged by `bidmp.sim.fci.judge_commands` and "
        f"streamed through pylibfranka 0.21.3 to franka-sim 1.1.7 (motion limits enforced) in "
        f"{elapsed:.0f} s. Produced by `make franka-agreement` "
        f"(`benchmarks/bench_libfranka.py --out docs/results`).",
        "",
        "| kind | streams | bidmp accepted | libfranka accepted | agree |",
        "|---|---:|---:|---:|---:|",
    ]
    for kind, (count, ours, theirs, agree) in table.items():
        lines.append(f"| {kind} | {count} | {ours} | {theirs} | {agree} |")
    total_agree = sum(row[3] for row in table.values())
    lines += [
        f"| all | {len(generated)} | {sum(v.ok for v in verdicts)} | "
        f"{sum(o.accepted for o in outcomes)} | {total_agree} |",
        "",
        f"Of the {rejected_both} streams both rejected, libfranka named bidmp's reflex among its "
        f"own on {same_reflex}. Streamed again because the client had missed a 1 ms cycle just "
        f"before a reflex (the machine's load, not the motion): "
        f"{sum(o.retries > 0 for o in outcomes)} streams, {sum(o.retries for o in outcomes)} times.",
        "",
    ]
    if disagreements:
        lines += [
            "## Disagreements",
            "",
            "| stream | kind | commands | bidmp | libfranka |",
            "|---:|---|---:|---|---|",
            *disagreements,
            "",
        ]
    else:
        lines += ["No disagreement.", ""]
    text = "\n".join(lines)
    print(text)
    if args.out is not None:
        args.out.mkdir(parents=True, exist_ok=True)
        with tempfile.NamedTemporaryFile("w", dir=args.out, delete=False, suffix=".tmp") as handle:
            handle.write(text)
        os.replace(handle.name, args.out / "libfranka.md")


if __name__ == "__main__":
    main()
