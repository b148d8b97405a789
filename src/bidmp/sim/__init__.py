"""Simulation: the simulator backend protocol and its PyBullet Franka Panda implementation, the
simulated task runs and their reports.

Layer 3 (the application): imports the math, ``demonstrations``, ``io`` and ``tasks``; never
``cli``. PyBullet is an extra (``bidmp[sim]``), imported when a cell is built.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "PANDA": "panda",
    "JointLimits": "panda",
    "Hold": "panda",
    "PandaCell": "panda",
    "MotionPlan": "panda",
    "Execution": "panda",
    "SimTarget": "panda",
    "SimMethod": "panda",
    "SimReport": "panda",
    "SimError": "panda",
    "simulate": "panda",
    "robot_placement": "panda",
    "write_sim_report": "panda",
}
__all__ = list(_EXPORTS)
# what the flat module bidmp.sim of bidmp <= 0.4 held, for code written against it
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals(), fallback=("panda",))
