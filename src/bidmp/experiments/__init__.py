"""Experiments: the paper's tables and figures (``reproduce``: ``table4``, ``table5``,
``incremental``, ``generalisation``), the LASA benchmark on Dask
(``lasa``) and the continual-learning protocol of the field (``clfd``).

Layer 3 (the application): imports the math, ``demonstrations``, ``io``, ``tasks`` and
``plotting``; never ``cli``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .avoidance import AvoidanceCase, random_case
    from .benchmark import BenchmarkResult, check_lasa_options, lasa, summary_markdown, summary_rows
    from .clfd import (
        CAPACITY_NODES,
        CLFD_THRESHOLDS,
        BiDMPLibrary,
        CapacityResult,
        CapacityRow,
        ClfdMethod,
        ClfdResult,
        ClfdRow,
        ClfdTask,
        ContinualBLS,
        DMPLibrary,
        FineTune,
        MapLibrary,
        ProMPLibrary,
        TangentChart,
        accuracy_matrix,
        capacity_sweep,
        clfd_tasks,
        continual_metrics,
        demonstration_errors,
        orientation_error,
        run_clfd,
        swept_error_area,
        write_capacity,
        write_clfd,
    )
    from .lasa_cells import CASES, LASA_METHODS, METRICS, cell_key, run_cell
    from .reproduce import (
        BATTERY_APPROACH_VIA,
        BATTERY_EXTENSION_TARGET,
        FIGURE_SHAPES,
        LASA_TARGET_OFFSETS,
        MAX_SEEDS,
        PAPER_NUT_ERRORS,
        PAPER_TABLE4,
        TABLE4_SCENARIOS,
        TASK_SCENARIOS,
        Figures,
        GeneralisationResult,
        IncrementalResult,
        PRMComparison,
        Table4,
        Table5,
        compare_prm,
        lasa_generalisation,
        lasa_incremental,
        run_figures,
        run_table4,
        run_table5,
        table5_cases,
        write_results,
    )
__getattr__, __dir__ = exports(__name__, __file__, globals())
