"""Compare produced results with the committed ones by value, not by bytes.

A faster computation that is equivalent moves the last bits of a float, and with them, now and
then, the last printed digit of a table. So:

* JSON: the same structure, the same strings, integers and booleans; floats equal to a relative
  1e-9 (absolute 1e-12 near zero);
* text (Markdown tables, reports): the same words; a number printed with a decimal point or an
  exponent may differ by one unit in its last printed place (or a relative 1e-9); a number
  printed as an integer — a count, a target's label — must be equal (a count one off is a
  result, not rounding).

    python tools/compare_results.py PRODUCED COMMITTED     # two files, or two folders

exits 1 listing every difference (the first 20 per file), 0 if all agree.
"""

from __future__ import annotations

import json
import math
import re
import sys
from pathlib import Path

REL = 1e-9
ABS = 1e-12
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")


def _decimal(token: str) -> bool:
    return "." in token or "e" in token.lower()


def _last_place(token: str) -> float:
    """One unit in the last printed place of a decimal ``token`` (``0.039`` -> 0.001)."""
    mantissa, _, exponent = token.lower().partition("e")
    decimals = len(mantissa.partition(".")[2])
    return 10.0 ** (-decimals + (int(exponent) if exponent else 0))


def _close(a: float, b: float) -> bool:
    return a == b or abs(a - b) <= max(REL * max(abs(a), abs(b)), ABS)


def compare_text(produced: str, committed: str, where: str = "") -> list[str]:
    """Differences between two texts (module docstring), each a line naming its place."""
    differences = []
    for number, (line_a, line_b) in enumerate(
        zip(produced.splitlines(), committed.splitlines()), start=1
    ):
        words_a, words_b = NUMBER.split(line_a), NUMBER.split(line_b)
        numbers_a, numbers_b = NUMBER.findall(line_a), NUMBER.findall(line_b)
        if words_a != words_b or len(numbers_a) != len(numbers_b):
            differences.append(f"{where}:{number}: text differs: {line_a!r} / {line_b!r}")
            continue
        for a, b in zip(numbers_a, numbers_b):
            if a == b:
                continue
            if not (_decimal(a) and _decimal(b)):
                differences.append(f"{where}:{number}: {a} / {b} (integers must be equal)")
                continue
            x, y = float(a), float(b)
            if _close(x, y) or abs(x - y) <= max(_last_place(a), _last_place(b)) * (1 + 1e-9):
                continue
            differences.append(f"{where}:{number}: {a} / {b}")
    lines_a, lines_b = len(produced.splitlines()), len(committed.splitlines())
    if lines_a != lines_b:
        differences.append(f"{where}: {lines_a} lines / {lines_b} lines")
    return differences


def compare_json(produced, committed, where: str = "$") -> list[str]:
    """Differences between two JSON values (module docstring), each naming its path."""
    if isinstance(committed, dict):
        if not isinstance(produced, dict) or set(produced) != set(committed):
            return [f"{where}: keys differ"]
        return [
            d for k in committed for d in compare_json(produced[k], committed[k], f"{where}.{k}")
        ]
    if isinstance(committed, list):
        if not isinstance(produced, list) or len(produced) != len(committed):
            return [f"{where}: lengths differ"]
        return [
            d
            for i, (a, b) in enumerate(zip(produced, committed))
            for d in compare_json(a, b, f"{where}[{i}]")
        ]
    if isinstance(committed, float) or isinstance(produced, float):
        if isinstance(produced, bool) or isinstance(committed, bool):
            return [] if produced == committed else [f"{where}: {produced} / {committed}"]
        if not isinstance(produced, (int, float)) or not isinstance(committed, (int, float)):
            return [f"{where}: {produced!r} / {committed!r}"]
        a, b = float(produced), float(committed)
        same = (math.isnan(a) and math.isnan(b)) or _close(a, b)
        return [] if same else [f"{where}: {produced} / {committed}"]
    return [] if produced == committed else [f"{where}: {produced!r} / {committed!r}"]


def compare_files(produced: Path, committed: Path) -> list[str]:
    """Differences between two files: JSON by value, anything else as text."""
    if produced.suffix == ".json":
        return compare_json(
            json.loads(produced.read_text(encoding="utf-8")),
            json.loads(committed.read_text(encoding="utf-8")),
            f"{committed.name}: $",
        )
    return compare_text(
        produced.read_text(encoding="utf-8"), committed.read_text(encoding="utf-8"), committed.name
    )


def main(argv: list[str]) -> int:
    if len(argv) != 2:
        print(__doc__.strip().splitlines()[-3], file=sys.stderr)
        return 2
    produced, committed = map(Path, argv)
    pairs = (
        [
            (produced / p.name, p)
            for p in sorted(committed.iterdir())
            if (produced / p.name).is_file()
        ]
        if committed.is_dir()
        else [(produced, committed)]
    )
    failed = False
    for a, b in pairs:
        if b.suffix not in (".md", ".json", ".txt", ".csv"):
            continue
        differences = compare_files(a, b)
        for line in differences[:20]:
            print(line)
        failed |= bool(differences)
        if not differences:
            print(f"{b.name}: equal by value")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
