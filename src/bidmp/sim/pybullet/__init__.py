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

from ..._lazy import exports

_EXPORTS = {
    "RobotCell": "cell",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
