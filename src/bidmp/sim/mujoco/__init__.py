"""The MuJoCo backend: the PyBullet backend's arms (the same URDFs with the scenario's tool, the
user's too) and the scene's parts in a MuJoCo world, driven by the same 1 kHz joint position and
velocity control and running the same contract, writing the same outputs.

* ``world`` — mujoco imported, the URDF compiled to a MuJoCo model with the parts as bodies;
* ``execute`` — the 1 kHz loops (open and closed loop), contacts and records;
* ``parts`` — a part the job moves (the nut on its thread, held, released, at rest);
* ``cell`` — :class:`MujocoCell`, the backend protocol's methods.

The arm's plans (inverse kinematics, timing) are the PyBullet backend's, on its kinematic copy of
the same URDF: both engines are sent the very same joint commands, so that what differs between
them is the physics. Needs the ``mujoco`` and ``sim`` extras: ``pip install 'bidmp[sim,mujoco]'``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from ..._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .cell import MujocoCell
__getattr__, __dir__ = exports(__name__, __file__, globals())
