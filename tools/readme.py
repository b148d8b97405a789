"""Keep the documentation's result tables equal to the committed outputs of the commands that
make them.

A generated block in README.md or a guide (docs/guides/*.md) looks like::

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


def pages() -> list[Path]:
    """The pages whose blocks are kept: the README and every guide."""
    return [README, *sorted((ROOT / "docs" / "guides").glob("*.md"))]


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


INDEX = ROOT / "docs" / "index.md"


def index_text(readme: str) -> str:
    """docs/index.md, the site's home: the README with its links made relative to docs/."""
    text = readme.replace("](docs/guides/)", "](guides/library.md)").replace("](docs/", "](")
    return text.replace("[CHANGELOG.md](CHANGELOG.md)", "`CHANGELOG.md`")


def main(argv: list[str]) -> int:
    index = index_text(README.read_text(encoding="utf-8"))
    if "--check" not in argv and (not INDEX.exists() or INDEX.read_text(encoding="utf-8") != index):
        INDEX.write_text(index, encoding="utf-8")
        print(f"updated {INDEX}")
    stale = (
        []
        if not INDEX.exists() or INDEX.read_text(encoding="utf-8") == index
        else [INDEX.relative_to(ROOT)]
    )
    for page in pages():
        text = page.read_text(encoding="utf-8")
        rendered = render(text)
        if rendered == text:
            continue
        if "--check" in argv:
            stale.append(page.relative_to(ROOT))
        else:
            page.write_text(rendered, encoding="utf-8")
            print(f"updated {page}")
    if stale:
        print(
            f"{', '.join(map(str, stale))} differ from docs/results: run 'make readme'",
            file=sys.stderr,
        )
        return 1
    return 0


if __name__ == "__main__":
    raise SystemExit(main(sys.argv[1:]))
