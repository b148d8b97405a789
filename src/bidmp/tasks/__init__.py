"""Tasks: scenario files (``scenarios``), the methods registry (``methods``), evaluation of every
method on every target (``evaluation``), the metrics it reports (``metrics``) and the motion
contract every motion is judged by (``contract``).

Layer 2 (data and tasks): imports the math and ``bidmp.io``; never ``sim``, ``experiments``,
``plotting`` at import time (figures are drawn on request) or ``cli``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .contract import CommandPeaks, Contract, Verdict, command_peaks, mm
    from .evaluation import CONVERGED_GAIN, evaluate
    from .jobs import JobSpec, RockSpec, parse_job, tour
    from .metrics import (
        approach_error,
        axis_deviation,
        endpoint_error,
        final_approach_mask,
        path_difference,
        path_extent,
        rmse,
        swept_area,
    )
    from .options import BiDMPOptions, DMPOptions, ExtensionStage, RobotOptions
    from .repair import REPAIRS, Attempt, Repaired, Repairer, carried_clearance, carried_depth
    from .report import MethodResult, Report, write_report
    from .scenarios import (
        METHODS,
        Scenario,
        ScenarioError,
        builtin_names,
        builtin_text,
        check_robot,
        from_dict,
        load,
        resolve,
    )
__getattr__, __dir__ = exports(__name__, __file__, globals())
