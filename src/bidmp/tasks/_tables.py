"""Plain-text and Markdown tables for reports (the CLI prints them, the README embeds them)."""

from __future__ import annotations

from collections.abc import Sequence

__all__ = ["text_table", "markdown_table"]


def text_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """Right-aligned columns separated by two spaces, with a dashed rule under the header."""
    widths = [max(len(str(cell)) for cell in column) for column in zip(header, *rows)]
    line = "  ".join(f"{{:>{w}}}" for w in widths)
    out = [line.format(*header), "  ".join("-" * w for w in widths)]
    out.extend(line.format(*row) for row in rows)
    return "\n".join(out)


def markdown_table(header: Sequence[str], rows: Sequence[Sequence[str]]) -> str:
    """A GitHub-flavoured Markdown table."""
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out.extend("| " + " | ".join(str(cell) for cell in row) + " |" for row in rows)
    return "\n".join(out)
