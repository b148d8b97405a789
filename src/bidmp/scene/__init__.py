"""Scene geometry: parts and the tool from a scenario's ``scene`` block (``parts``), exact
clearances through coal (``distances``, ``clearance``), and the roadmap's collision checker
(``checker``).

Layer 1 (the math): imports the package root's private helpers only; coal is an extra
(``bidmp[collision]``), imported when a distance is first needed.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "Scene": "clearance",
    "Clearance": "clearance",
    "SceneChecker": "checker",
    "Proximity": "proximity",
    "random_field": "fields",
    "Tool": "parts",
    "Part": "parts",
    "Solid": "parts",
    "SceneError": "parts",
    "PART_TYPES": "parts",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
