"""Experiments: the paper's tables and figures (``reproduce``: ``table4``, ``table5``, ``incremental``, ``generalisation``) and the LASA benchmark on Dask
(``lasa``).

Layer 3 (the application): imports the math, ``demonstrations``, ``io``, ``tasks`` and
``plotting``; never ``cli``.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "AvoidanceCase": "avoidance",
    "random_case": "avoidance",
    "GeneralisationResult": "reproduce",
    "lasa_generalisation": "reproduce",
    "LASA_TARGET_OFFSETS": "reproduce",
    "FIGURE_SHAPES": "reproduce",
    "IncrementalResult": "reproduce",
    "lasa_incremental": "reproduce",
    "Figures": "reproduce",
    "run_figures": "reproduce",
    "TABLE4_SCENARIOS": "reproduce",
    "TASK_SCENARIOS": "reproduce",
    "PAPER_TABLE4": "reproduce",
    "PAPER_NUT_ERRORS": "reproduce",
    "Table4": "reproduce",
    "run_table4": "reproduce",
    "MAX_SEEDS": "reproduce",
    "BATTERY_APPROACH_VIA": "reproduce",
    "BATTERY_EXTENSION_TARGET": "reproduce",
    "table5_cases": "reproduce",
    "PRMComparison": "reproduce",
    "compare_prm": "reproduce",
    "Table5": "reproduce",
    "run_table5": "reproduce",
    "write_results": "reproduce",
    "LASA_METHODS": "lasa_cells",
    "CASES": "lasa_cells",
    "METRICS": "lasa_cells",
    "run_cell": "lasa_cells",
    "lasa": "benchmark",
    "check_lasa_options": "benchmark",
    "BenchmarkResult": "benchmark",
    "summary_rows": "benchmark",
    "cell_key": "lasa_cells",
    "summary_markdown": "benchmark",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
