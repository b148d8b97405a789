"""Experiments: the paper's tables and figures (``reproduce``) and the LASA benchmark on Dask
(``lasa``).

Layer 3 (the application): imports the math, ``demonstrations``, ``io``, ``tasks`` and
``plotting``; never ``cli``.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "GeneralisationResult": "reproduce",
    "lasa_generalisation": "reproduce",
    "PRMComparison": "reproduce",
    "Table5": "reproduce",
    "table5_cases": "reproduce",
    "compare_prm": "reproduce",
    "run_table5": "reproduce",
    "IncrementalResult": "reproduce",
    "Figures": "reproduce",
    "lasa_incremental": "reproduce",
    "run_figures": "reproduce",
    "Table4": "reproduce",
    "run_table4": "reproduce",
    "write_results": "reproduce",
    "LASA_METHODS": "lasa",
    "CASES": "lasa",
    "METRICS": "lasa",
    "run_cell": "lasa",
    "lasa": "lasa",
    "BenchmarkResult": "lasa",
    "summary_rows": "lasa",
    "cell_key": "lasa",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
