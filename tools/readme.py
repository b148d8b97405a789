"""Keep the README's result tables equal to the committed outputs of the commands that make them.

A generated block in README.md looks like::

    <!-- generated: docs/results/table4.md -->
    ...the file's content...
    <!-- end generated -->

``python tools/readme.py`` copies each file's content into its block (``make readme`` first
regenerates the files with ``bidmp reproduce ...``); ``--check`` exits 1 if any block differs.
"""

from __future__ import annotations

import re
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
BLOCK = re.compile(
    r"(<!-- generated: (?P<path>\S+) -->\n)(?P<body>.*?)(<!-- end generated -->)", re.DOTALL
)


def blocks(text: str) -> list[tuple[str, str]]:
    """(path, body) of every generated block in ``text``."""
    return [(match["path"], match["body"]) for match in BLOCK.finditer(text)]


def render(text: str) -> str:
    """``text`` with every generated block replaced by its file's current content."""

    def replace(match):
        content = (ROOT / match["path"]).read_text(encoding="utf-8")
        return match.group(1) + content.rstrip("\n") + "\n" + match.group(4)

    return BLOCK.sub(replace, text)


def main(argv: list[str]) -> int:
    text = README.read_text(encoding="utf-8")
    rendered = render(text)
    if "--check" in argv:
        if rendered != text:
            print("README.md differs from docs/results: run 'make readme'", file=sys.stderr)
            return 1
        return 0
    if rendered != text:
        README.write_text(rendered, encoding="utf-8")
        print(f"updated {README}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
