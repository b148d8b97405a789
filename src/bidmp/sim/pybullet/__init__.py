"""The PyBullet backend: a Franka Panda from ``pybullet_data`` carrying the scenario's tool, in a
headless world of the scene's parts.

* ``world`` — pybullet imported quietly, the URDF with the tool, the parts as bodies;
* ``robot`` — the Panda's limits, placement and checks;
* ``ik``, ``plan``, ``execute``, ``render`` — one job each, functions of a cell;
* ``cell`` — :class:`PandaCell`, the world's state and the backend protocol's methods.

Needs the ``sim`` extra: ``pip install 'bidmp[sim]'``.
"""

from __future__ import annotations

from ..._lazy import exports

_EXPORTS = {"PandaCell": "cell", "PANDA": "robot", "robot_placement": "robot"}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
