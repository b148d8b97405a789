"""Scene geometry: parts and the tool from a scenario's ``scene`` block (``parts``), exact
clearances through coal (``distances``, ``clearance``), and the roadmap's collision checker
(``checker``).

Layer 1 (the math): imports the package root's private helpers only; coal is an extra
(``bidmp[collision]``), imported when a distance is first needed.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .checker import PoseChecker, SceneChecker
    from .clearance import Clearance, Scene
    from .fields import random_field
    from .parts import PART_TYPES, Part, SceneError, Solid, Tool
    from .proximity import Proximity
__getattr__, __dir__ = exports(__name__, __file__, globals())
