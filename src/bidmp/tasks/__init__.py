"""Tasks: scenario files (``scenarios``), the methods registry (``methods``), evaluation of every
method on every target (``evaluation``), the metrics it reports (``metrics``) and the motion
contract every motion is judged by (``contract``).

Layer 2 (data and tasks): imports the math and ``bidmp.io``; never ``sim``, ``experiments``,
``plotting`` at import time (figures are drawn on request) or ``cli``.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "CONVERGED_GAIN": "evaluation",
    "MethodResult": "report",
    "Report": "report",
    "evaluate": "evaluation",
    "write_report": "report",
    "Scenario": "scenarios",
    "ScenarioError": "scenarios",
    "METHODS": "scenarios",
    "load": "scenarios",
    "builtin_names": "scenarios",
    "builtin_text": "scenarios",
    "from_dict": "scenarios",
    "check_robot": "scenarios",
    "rmse": "metrics",
    "path_extent": "metrics",
    "endpoint_error": "metrics",
    "approach_error": "metrics",
    "axis_deviation": "metrics",
    "path_difference": "metrics",
    "swept_area": "metrics",
    "final_approach_mask": "metrics",
    "Contract": "contract",
    "Verdict": "contract",
    "CommandPeaks": "contract",
    "command_peaks": "contract",
    "mm": "contract",
    "Repairer": "repair",
    "Repaired": "repair",
    "Attempt": "repair",
    "REPAIRS": "repair",
    "carried_clearance": "repair",
    "carried_depth": "repair",
    "JobSpec": "jobs",
    "parse_job": "jobs",
    "tour": "jobs",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
