"""The paper's experiments: Tables 1, 2 and 4 (battery case studies, :mod:`.table4`), Table 5
(G-PRM vs classic PRM, :mod:`.table5`), Fig. 11 (Bi-DMP on LASA shapes, :mod:`.incremental`), and
the LASA fit-and-generalise example (:mod:`.generalisation`).

Each ``run_*`` function returns a result object with ``to_dict()`` (JSON), ``summary()`` (the
text the CLI prints) and ``markdown()`` (deterministic tables, no run times: the README embeds
them, and a test checks the README against them). :func:`write_results` writes JSON, Markdown and
figures into a folder.
"""

from __future__ import annotations

import json
import os
from pathlib import Path

from ..io.atomic import atomic_write
from ..tasks.evaluation import write_report

# The paper's results, importable from one place (bidmp.experiments lists them from here).
from .generalisation import (  # noqa: F401
    GeneralisationResult,
    lasa_generalisation,
)
from .incremental import (  # noqa: F401
    FIGURE_SHAPES,
    LASA_TARGET_OFFSETS,
    Figures,
    IncrementalResult,
    lasa_incremental,
    run_figures,
)
from .table4 import (  # noqa: F401
    PAPER_NUT_ERRORS,
    PAPER_TABLE4,
    TABLE4_SCENARIOS,
    TASK_SCENARIOS,
    Table4,
    run_table4,
)
from .table5 import (  # noqa: F401
    BATTERY_APPROACH_VIA,
    BATTERY_EXTENSION_TARGET,
    MAX_SEEDS,
    PRMComparison,
    Table5,
    compare_prm,
    run_table5,
    table5_cases,
)

__all__ = [
    "GeneralisationResult",
    "lasa_generalisation",
    "LASA_TARGET_OFFSETS",
    "FIGURE_SHAPES",
    "IncrementalResult",
    "lasa_incremental",
    "Figures",
    "run_figures",
    "TABLE4_SCENARIOS",
    "TASK_SCENARIOS",
    "PAPER_TABLE4",
    "PAPER_NUT_ERRORS",
    "Table4",
    "run_table4",
    "MAX_SEEDS",
    "BATTERY_APPROACH_VIA",
    "BATTERY_EXTENSION_TARGET",
    "table5_cases",
    "PRMComparison",
    "compare_prm",
    "Table5",
    "run_table5",
    "write_results",
]


def _write_json(path: Path, data) -> None:
    with atomic_write(path, "w") as handle:
        json.dump(data, handle, indent=2)


def _write_text(path: Path, text: str) -> None:
    with atomic_write(path, "w") as handle:
        handle.write(text if text.endswith("\n") else text + "\n")


# ---------------------------------------------------------------------------------------------
# Writing results
# ---------------------------------------------------------------------------------------------
def write_results(result, name: str, out: str | os.PathLike) -> list[Path]:
    """Write a reproduction result into folder ``out``: ``NAME.json``, ``NAME.md`` and its
    figures (per-scenario folders with ``results.json`` and figures for Table 4)."""
    from .. import plotting
    from .._checks import check_kind, short_token

    check_kind(
        result,
        (Table4, Table5, Figures, GeneralisationResult),
        "result",
        "a reproduction result (Table4, Table5, Figures or GeneralisationResult)",
    )
    if not isinstance(name, str) or not name or "/" in name or "\\" in name:
        raise ValueError(f"name must be a file name without a folder, got {short_token(name, 30)}")
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    written = [out / f"{name}.json", out / f"{name}.md"]
    _write_json(written[0], result.to_dict())
    # a generalisation result has a plain-text summary, the tables a Markdown one
    markdown = (
        f"```\n{result.summary()}\n```\n"
        if isinstance(result, GeneralisationResult)
        else result.markdown()
    )
    _write_text(written[1], markdown)
    if isinstance(result, Table4):
        if result.keep:
            written.append(out / "tasks.md")
            _write_text(written[-1], result.task_markdown())
        for scenario_name, report in result.reports.items():
            written += write_report(report, out / scenario_name)
    elif isinstance(result, Figures):
        written.append(plotting.plot_incremental(out / "bidmp_lasa.png", result.results))
    elif isinstance(result, Table5):
        written.append(plotting.plot_prm_comparison(out / f"{name}.png", result.comparisons))
    elif isinstance(result, GeneralisationResult):
        written.append(plotting.plot_generalisation(out / f"{name}.png", result))
    return written
