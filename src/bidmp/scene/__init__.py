"""Scene geometry: parts and the tool from a scenario's ``scene`` block, exact clearances through
coal (with a margin), and the roadmap's collision checker.

Layer 1 (the math): imports the package root's private helpers only; coal is an extra
(``bidmp[collision]``), imported when a distance is first needed.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "Tool": "geometry",
    "Part": "geometry",
    "Solid": "geometry",
    "Scene": "geometry",
    "Clearance": "geometry",
    "SceneChecker": "geometry",
    "PART_TYPES": "geometry",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
