"""The PyBullet backend: a 7-joint arm (the Franka Panda or the KUKA iiwa from ``pybullet_data``,
or a scenario's own URDF) carrying the scenario's tool, in a
headless world of the scene's parts.

* ``world`` — pybullet imported quietly, the URDF with the tool, the parts as bodies;
* ``robot`` — the arms' models and limits, placement and checks;
* ``ik``, ``plan``, ``execute``, ``render`` — one job each, functions of a cell;
* ``cell`` — :class:`RobotCell` (alias ``PandaCell``), the world's state and the backend protocol's methods.

Needs the ``sim`` extra: ``pip install 'bidmp[sim]'``.
"""

from __future__ import annotations

from ..._lazy import exports

_EXPORTS = {"RobotCell": "cell", "PandaCell": "cell", "PANDA": "robot", "IIWA": "robot", "RobotModel": "robot",
            "ROBOT_MODELS": "robot", "robot_model": "robot", "robot_placement": "robot"}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
