"""The PyBullet backend: a serial arm of six or more joints (the Franka Panda, the KUKA iiwa and the
xArm6 from ``pybullet_data``, a UR5-class arm from its DH parameters, or a scenario's own URDF)
carrying the scenario's tool, in a headless world of the scene's parts.

* ``world`` — pybullet imported quietly, the URDF with the tool, the parts as bodies;
* the arms' models and limits, placement and checks are :mod:`bidmp.sim.robots` (any backend's);
* ``ik``, ``plan``, ``execute``, ``render`` — one job each, functions of a cell;
* ``cell`` — :class:`RobotCell`, the world's state and the backend protocol's methods.

Needs the ``sim`` extra: ``pip install 'bidmp[sim]'``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .cell import RobotCell
__getattr__, __dir__ = exports(__name__, __file__, globals())
