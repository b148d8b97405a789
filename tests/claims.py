"""The machinery of tests/test_claims.py: the prose as paragraphs, the numbers in it that stand next
to a result, and the committed results read by value.

A page is read as paragraphs (blank-line separated; code blocks, HTML comments and the generated
blocks of tools/readme.py taken out), each with its lines joined by single spaces (a table keeps
one row a line), so a claim's text matches however the prose is wrapped.

A number stands next to a result (:func:`result_numbers`) when it is in

* a sentence (or table row) naming a measure of a committed result (:data:`MEASURES`),
* a table whose header names one,
* a paragraph that cites a committed result file (``results/...``, a result file's name) or comes
  right after a generated table (the prose that reads the table), and the list or table such a
  paragraph introduces (it ends in a colon),

and it has a decimal point or three or more digits (small whole numbers there are counts and
settings — 26 tasks, 7 demonstrations — far more often than measurements; a claim may still tie
one). Numbers inside inline code, years and issue numbers are not claims.
"""

from __future__ import annotations

import functools
import json
import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
RESULTS = ROOT / "docs" / "results"

# A number as the prose prints it: a sign (- or −), digits with an optional thousands separator
# (a space or a comma before three digits), a decimal part. Not a part of a word, a version, a
# path or an exponent (1e-8), nor the denominator of a fraction (8/14).
NUMBER = r"[−-]?\d+(?:[ ,]\d{3})*(?:\.\d+)?"
NUMBER_IN_PROSE = re.compile(rf"(?<![\w.\-−^]){NUMBER}(?![\w]|\.\d|,\d{{3}})")

# The measures of the committed results: a sentence naming one makes its numbers claims
MEASURES = re.compile(
    r"\b(?:CL_score|CL_stability|ACC|BWT|REM|DTW|MS|FS|TE)\b|success rate|forgetting|"
    r"per nut|per box|in the bin|cells removed|stored map|numbers? kept|RMSE"
)
# A paragraph citing a committed result file
CITES = re.compile(
    r"results/\w|(?<!guides/)(?<!\()\b(?:table4|table5|figures|tasks|sim|job|job_cells|job_xarm6|job_ur5|clfd|"
    r"clfd_robottasks|clfd_capacity|lasa|libfranka|user_cells|repair_order|robot|avoidance)"
    r"\.(?:md|json)\b|sim_results\.json|job_results\.json"
)
NOT_CLAIMS = re.compile(r"\bissue \d+|\b(?:19|20)\d\d\b(?!\.\d)")


def current_changelog() -> str:
    """CHANGELOG.md's current version's section (from its first '## ' heading to the next)."""
    text = (ROOT / "CHANGELOG.md").read_text(encoding="utf-8")
    headings = [m.start() for m in re.finditer(r"^## ", text, re.MULTILINE)]
    end = headings[1] if len(headings) > 1 else len(text)
    return text[headings[0] : end]


@functools.cache
def pages() -> dict[str, str]:
    """The prose checked: the README, every guide and the CHANGELOG's current section, by path."""
    paths = [ROOT / "README.md", *sorted((ROOT / "docs" / "guides").glob("*.md"))]
    texts = {p.relative_to(ROOT).as_posix(): p.read_text(encoding="utf-8") for p in paths}
    texts["CHANGELOG.md"] = current_changelog()
    return texts


GENERATED = re.compile(r"<!-- generated: \S+ -->\n.*?<!-- end generated -->", re.DOTALL)
FENCE = re.compile(r"^```.*?^```[^\n]*$", re.DOTALL | re.MULTILINE)
COMMENT = re.compile(r"<!--.*?-->", re.DOTALL)
AFTER_TABLE = "\x00"
LIST_ITEM = re.compile(
    r"(?:[-*+]|\d+\.) "
)  # marks a generated table's place: the next paragraph reads it


@dataclass
class Paragraph:
    text: str  # lines joined by single spaces (a table: one row a line)
    table: bool
    after_table: bool  # right after a generated table
    item: bool  # an item of a list


def paragraphs(page: str) -> list[Paragraph]:
    page = GENERATED.sub(f"\n\n{AFTER_TABLE}\n\n", page)
    page = FENCE.sub("\n\n", page)
    page = COMMENT.sub("", page)
    out, after = [], False
    for block in re.split(r"\n[ \t]*\n", page):
        lines = [line.strip() for line in block.splitlines() if line.strip()]
        if not lines:
            continue
        if lines == [AFTER_TABLE]:
            after = True
            continue
        if all(line.startswith("|") for line in lines):
            out.append(Paragraph("\n".join(lines), True, after, False))
        else:  # a list's items are paragraphs of their own
            items: list[list[str]] = []
            for line in lines:
                if not items or LIST_ITEM.match(line):
                    items.append([])
                items[-1].append(line)
            for index, item in enumerate(items):
                listed = bool(LIST_ITEM.match(item[0]))
                text = " ".join(" ".join(item).split())
                out.append(Paragraph(text, False, after and not index, listed))
        after = False
    return out


@functools.cache
def normalised(page: str) -> str:
    """The page's prose as :func:`paragraphs` reads it, paragraphs separated by blank lines."""
    return "\n\n".join(p.text for p in paragraphs(page))


def _sentences(text: str) -> list[tuple[int, str]]:
    """(offset, sentence) of a prose paragraph: split after . ; : before a capital or a mark."""
    out, start = [], 0
    for match in re.finditer(r"(?<=[.;:])\s+(?=[A-Z*(`\[])", text):
        out.append((start, text[start : match.start()]))
        start = match.end()
    out.append((start, text[start:]))
    return out


def _code_spans(text: str) -> list[tuple[int, int]]:
    return [m.span() for m in re.finditer(r"`[^`]*`", text)]


def result_numbers(page: str) -> list[tuple[int, int, str, str]]:
    """(start, end, number, its sentence) of every number standing next to a result in
    :func:`normalised` ``page`` (module docstring)."""
    found, offset, introduced = [], 0, False
    for paragraph in paragraphs(page):
        text = paragraph.text
        # a cited paragraph ending in ":" passes its citation to the list or table it introduces
        introduced = introduced and (paragraph.item or paragraph.table)
        cited = paragraph.after_table or introduced or bool(CITES.search(text))
        if paragraph.table:
            rows = text.split("\n")
            whole = cited or bool(MEASURES.search(rows[0]))
            units, position = [], 0
            for row in rows:
                units.append((position, row, whole or bool(MEASURES.search(row))))
                position += len(row) + 1
        else:
            units = [(o, s, cited or bool(MEASURES.search(s))) for o, s in _sentences(text)]
        for start, unit, in_context in units:
            if not in_context:
                continue
            skip = _code_spans(unit) + [m.span() for m in NOT_CLAIMS.finditer(unit)]
            for match in NUMBER_IN_PROSE.finditer(unit):
                a, b = match.span()
                if any(s <= a < e for s, e in skip):
                    continue
                digits = re.sub(r"\D", "", match.group())
                if a and unit[a - 1] == "/" and "." not in match.group():
                    continue  # the denominator of a count (8/14); 0.96/2.71 is two numbers
                if "." in match.group() or len(digits) >= 3:
                    found.append((offset + start + a, offset + start + b, match.group(), unit))
        if cited and not paragraph.table and not paragraph.item and text.endswith(":"):
            introduced = True
        offset += len(text) + 2
    return found


# -- numbers as printed, and the committed results ------------------------------------------------


def parse_number(text: str) -> tuple[float, int]:
    """(value, decimals printed) of a number as the prose prints it."""
    plain = text.replace("−", "-").replace(" ", "").replace(",", "")
    decimals = len(plain.split(".")[1]) if "." in plain else 0
    return float(plain), decimals


def same_at_precision(printed: str, value: float) -> bool:
    """``printed`` is ``value`` rounded to the decimals printed (0.994 is 0.99390..., 663 is
    663.1; -0.000 is 0.000)."""
    number, decimals = parse_number(printed)
    if not math.isfinite(value):
        return False
    return float(f"{value:.{decimals}f}") == number


@dataclass(frozen=True)
class Source:
    """Where a claimed number comes from: ``what`` names the file and the field; ``read`` gives
    its value. The prose prints it (``bound`` False) or a bound it keeps (True: "at most")."""

    what: str
    read: Callable[[], float]
    bound: bool = False

    def at_most(self) -> Source:
        """The same source, the prose giving a bound it stays within ("within 1.2×")."""
        return Source(f"{self.what} (at most)", self.read, True)

    def holds(self, printed: str, value: float) -> bool:
        if self.bound:
            number, decimals = parse_number(printed)
            return float(f"{value:.{decimals}f}") <= number
        return same_at_precision(printed, value)


@functools.cache
def _json(name: str):
    return json.loads((RESULTS / name).read_text(encoding="utf-8"))


def J(name: str, *path, scale: float = 1.0) -> Source:  # noqa: N802 - a short name in a long table
    """A field of a committed JSON result: ``J("clfd.json", "methods", "finetune", ...)``; an
    int in ``path`` indexes a list; ``scale`` multiplies (a percentage: 100)."""

    def read():
        value = _json(name)
        for key in path:
            value = value[key]
        return float(value) * scale

    return Source(
        f"{name}: {'/'.join(map(str, path))}" + (f" × {scale:g}" if scale != 1 else ""), read
    )


def markdown_tables(name: str) -> list[list[list[str]]]:
    """The tables of a committed Markdown result: rows of cells (the header first, the rule
    left out)."""
    tables, current = [], []
    for line in (RESULTS / name).read_text(encoding="utf-8").splitlines():
        if line.startswith("|"):
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if not all(re.fullmatch(r":?-+:?", c) for c in cells):
                current.append(cells)
        elif current:
            tables.append(current)
            current = []
    if current:
        tables.append(current)
    return tables


def M(name: str, row, column: str, index: int = 0) -> Source:  # noqa: N802
    """The ``index``-th number in the cell of a committed Markdown table: the row whose first cell
    is ``row`` (a tuple: whose first cells are), the column headed ``column`` (the first table
    that has both)."""
    first = (row,) if isinstance(row, str) else tuple(row)

    def read():
        for table in markdown_tables(name):
            header = table[0]
            if column not in header:
                continue
            for cells in table[1:]:
                if tuple(cells[: len(first)]) == first:
                    numbers = re.findall(NUMBER, cells[header.index(column)])
                    return parse_number(numbers[index])[0]
        raise KeyError(f"{name} has no cell ({row!r}, {column!r})")

    return Source(f"{name}: row {row!r}, column {column!r}" + (f" #{index}" if index else ""), read)


def X(name: str, pattern: str, scale: float = 1.0) -> Source:  # noqa: N802
    """The number a committed Markdown result's prose gives in ``pattern``'s first group
    (times ``scale``)."""

    def read():
        match = re.search(pattern, (RESULTS / name).read_text(encoding="utf-8"))
        if match is None:
            raise KeyError(f"{name} has no text matching {pattern!r}")
        return parse_number(match.group(1))[0] * scale

    return Source(f"{name}: {pattern!r}" + (f" × {scale:g}" if scale != 1 else ""), read)


def D(what: str, read: Callable[[], float]) -> Source:  # noqa: N802
    """A number derived from committed results: ``what`` says how (the files and fields)."""
    return Source(what, read)


@dataclass(frozen=True)
class Claim:
    """``text`` on ``page`` (normalised: one space between words), each claimed number written
    as ``{}``, tied to its ``sources`` in order."""

    page: str
    text: str
    sources: tuple

    def pattern(self) -> re.Pattern:
        parts = self.text.split("{}")
        body = f"({NUMBER})".join(re.escape(part) for part in parts)
        return re.compile(body)


def claim(page: str, text: str, *sources: Source) -> Claim:
    if text.count("{}") != len(sources):
        raise ValueError(f"{page}: {text!r} has {text.count('{}')} numbers, {len(sources)} sources")
    return Claim(page, text, sources)


@dataclass(frozen=True)
class NotResult:
    """Numbers on ``page`` in ``text`` (each ``{}``) that stand next to a result but are not
    one, and why (``reason``)."""

    page: str
    text: str
    reason: str

    def pattern(self) -> re.Pattern:
        return Claim(self.page, self.text, ()).pattern()
