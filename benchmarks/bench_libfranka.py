"""bidmp's FCI judge (:func:`bidmp.sim.fci.judge_commands`) against libfranka at the limits:
threshold families of FR3 command streams (tests/fci_streams.py) on all seven joints, one for
every limit kind (position range, flat and position-based velocity, acceleration, jerk), each
bisected by bidmp's judge to a pair within 0.5 % of its threshold (one just inside, one just
outside), both judged by bidmp and streamed through pylibfranka to franka-sim with the motion
limits enforced. Needs the side environment (make franka).

    .venv/bin/python benchmarks/bench_libfranka.py [--per 5] [--joints 1,...,7] [--seed 2026]
        [--out DIR]

Prints, and with --out writes DIR/libfranka.md: agreement per kind, per joint and per (kind,
joint), and every disagreement with both verdicts. A stream agrees when both sides accept it, or
both reject it and libfranka names bidmp's reflex among its own.
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

from fci_streams import LIMIT_KINDS, REFLEXES, bisect, families, inside  # noqa: E402

from bidmp.sim.fci import judge_commands  # noqa: E402
from bidmp.sim.libfranka import stream_fr3  # noqa: E402

REL = 0.005  # the pair's factors at most this far apart: each within 0.5 % of the threshold


def _bidmp_inside(kind: str, q) -> bool:
    verdict = judge_commands(q, "fr3")
    return inside(kind, verdict.ok, (verdict.reflex,))


def pairs(per: int, seed: int, joints=range(1, 8), kinds=LIMIT_KINDS) -> list[dict]:
    """For each family (``per`` of each kind and joint, from ``seed``): its just-inside and
    just-outside streams by bidmp's judge, with their factors."""
    out = []
    for family in families(per, seed, joints=joints, kinds=kinds):
        low, high = bisect(lambda q, k=family.kind: _bidmp_inside(k, q), family, rel=REL)
        for side, factor in (("inside", low), ("outside", high)):
            out.append({"family": family, "side": side, "factor": factor, "q": family.at(factor)})
    return out


def agree(verdict, outcome) -> bool:
    """Both accept, or both reject with libfranka naming bidmp's reflex among its own."""
    if verdict.ok or outcome.accepted:
        return verdict.ok == outcome.accepted
    return verdict.reflex in outcome.reflexes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--per", type=int, default=5, help="families per (kind, joint)")
    parser.add_argument("--joints", default="1,2,3,4,5,6,7", help="of the FR3, 1-7")
    parser.add_argument("--seed", type=int, default=2026)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()
    if args.per < 1:
        parser.error("--per must be at least 1")
    try:
        joints = sorted({int(joint) for joint in args.joints.split(",")})
    except ValueError:
        parser.error(f"--joints must be joint numbers 1-7 separated by commas, got {args.joints!r}")
    if not joints or joints[0] < 1 or joints[-1] > 7:
        parser.error(f"--joints must be joint numbers 1-7, got {args.joints!r}")
    generated = pairs(args.per, args.seed, joints=joints)
    verdicts = [judge_commands(row["q"], "fr3") for row in generated]
    start = time.perf_counter()
    outcomes = stream_fr3([row["q"] for row in generated])
    elapsed = time.perf_counter() - start

    by_kind = collections.defaultdict(lambda: collections.Counter())
    by_cell = collections.Counter()
    cell_count = collections.Counter()
    disagreements, approach = [], 0
    for index, (row, verdict, outcome) in enumerate(zip(generated, verdicts, outcomes)):
        family = row["family"]
        kind, joint, side = family.kind, family.joint, row["side"]
        counts = by_kind[kind]
        counts["streams"] += 1
        counts[f"bidmp {side}"] += inside(kind, verdict.ok, (verdict.reflex,)) == (side == "inside")
        counts[f"libfranka {side}"] += inside(kind, outcome.accepted, outcome.reflexes) == (
            side == "inside"
        )
        # the kind's own reflex, on the family's joint, past the threshold (the construction's
        # claim, checked against bidmp)
        counts["own reflex"] += side == "inside" or (
            verdict.reflex == REFLEXES[kind] and verdict.joint == joint
        )
        same = agree(verdict, outcome)
        counts["agree"] += same
        cell_count[kind, joint] += 1
        by_cell[kind, joint] += same
        approach += outcome.phase == "approach"
        if not same:
            disagreements.append(
                f"| {index} | {kind} | {joint} | {side} ({row['factor']:.4f}) | "
                f"{family.label} | {'accepted' if verdict.ok else verdict.reason()} | "
                f"{'accepted' if outcome.accepted else outcome.reason()} |"
            )
    total = len(generated)
    samples = sum(row["q"].shape[0] for row in generated)
    width = max(generated[i + 1]["factor"] / generated[i]["factor"] - 1 for i in range(0, total, 2))
    where = (
        "each of the 7 joints"
        if joints == list(range(1, 8))
        else "joint " + ", ".join(map(str, joints))
    )
    lines = [
        "# bidmp's FCI judge against libfranka, at the limits",
        "",
        f"{total} FR3 streams (seed {args.seed}, {samples} commands, {samples / 1000:.0f} s at "
        f"1 kHz): {total // 2} threshold families (`tests/fci_streams.py`), {args.per} for each "
        f"of the 5 limit kinds on {where}, each bisected by bidmp's judge to a pair "
        f"of streams whose factors are at most {width * 100:.2f} % apart (so each within 0.5 % "
        f"of the threshold): one just inside, one just outside. Each judged by "
        f"`bidmp.sim.fci.judge_commands` and streamed through pylibfranka 0.21.3 to franka-sim "
        f"1.1.7 (motion limits enforced) in {elapsed:.0f} s. Produced by "
        f"`make franka-agreement` (`benchmarks/bench_libfranka.py --out docs/results`).",
        "",
        "A stream agrees when both sides accept it, or both reject it and libfranka names "
        "bidmp's reflex among its own. A range stream lands on the stop in one jump (nothing "
        "else reaches an FR3's stop: its velocity limit falls to zero short of it), which both "
        "sides reject: inside the stop for the jump (a velocity discontinuity), past it for the "
        "range. Its threshold is where the reflex changes.",
        "",
        "| kind | streams | bidmp: inside / outside as built | libfranka: inside / outside "
        "as built | bidmp's reflex is the kind's, on its joint | agree |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for kind in LIMIT_KINDS:
        c = by_kind[kind]
        lines.append(
            f"| {kind} | {c['streams']} | {c['bidmp inside']} / {c['bidmp outside']} | "
            f"{c['libfranka inside']} / {c['libfranka outside']} | {c['own reflex']} | "
            f"{c['agree']} |"
        )
    agreed = sum(c["agree"] for c in by_kind.values())
    lines += [f"| all | {total} | | | | {agreed} |", "", "Agreement per joint and kind:", ""]
    lines.append("| kind | " + " | ".join(f"joint {j}" for j in range(1, 8)) + " |")
    lines.append("|---|" + "---:|" * 7)
    for kind in LIMIT_KINDS:
        cells = " | ".join(f"{by_cell[kind, j]}/{cell_count[kind, j]}" for j in range(1, 8))
        lines.append(f"| {kind} | {cells} |")
    per_joint = " | ".join(
        f"{sum(by_cell[k, j] for k in LIMIT_KINDS)}/{sum(cell_count[k, j] for k in LIMIT_KINDS)}"
        for j in range(1, 8)
    )
    lines += [
        f"| all | {per_joint} |",
        "",
        f"Rejected in the approach (the slow move to a stream's first command, not the stream): "
        f"{approach}. Streamed again because the client had missed a 1 ms cycle just before a "
        f"reflex (the machine's load, not the motion): {sum(o.retries > 0 for o in outcomes)} "
        f"streams, {sum(o.retries for o in outcomes)} times.",
        "",
    ]
    if disagreements:
        lines += [
            "## Disagreements",
            "",
            "| stream | kind | joint | side (factor) | family | bidmp | libfranka |",
            "|---:|---|---:|---|---|---|---|",
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
