"""A part the job moves in the MuJoCo world: seated → threading (a nut turned up its stud, placed
every recorded step) → held (a free body welded to the tool's mouth, its mass on the arm) →
released (the weld gone: it falls) → at rest (static again where it lies). A change of kind is a
change of the model: MuJoCo's model spec edited and recompiled with the state carried over."""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from ..backend import _part_args, _solid_height
from ..pybullet.parts import _turned
from .world import CONTACT_SLACK, MOVING_GROUP, PART_GROUP, _quaternion_wxyz

__all__ = []

# The weld's stiffness (MuJoCo's solref: time constant s, damping ratio): two physics steps,
# MuJoCo's stiffest stable setting: the part sits within micrometres of where it was taken.
_WELD = (2e-3, 1.0)


class _MovablePart:
    """One part of the scene (a nut or a cell) that the job moves; poses in scene units."""

    def __init__(self, cell, label: str, mass: float):
        self.solid, mass = _part_args(cell.scene, label, mass)
        self.cell, self.label, self.mass = cell, label, mass
        self.name = next(name for name, (solid, _) in cell._part_bodies.items() if solid == label)
        self.centre0 = np.asarray(self.solid.centre, dtype=float)
        self.rotation0 = Rotation.from_matrix(self.solid.rotation)
        self._quaternion0 = tuple(self.rotation0.as_quat().tolist())
        self.axis = self.solid.rotation[:, 2]
        self._centre0, self._axis = self.centre0.tolist(), self.axis.tolist()
        self.height = _solid_height(self.solid)
        self.state, self.rise, self.weld = "seated", 0.0, None
        self.trace: list[tuple[float, float, float]] = []

    def _body(self):
        return self.cell.m.body(self.name)

    def pose(self) -> tuple[np.ndarray, Rotation]:
        d, body = self.cell.d, self._body()
        if body.mocapid[0] >= 0:
            centre, (w, x, y, z) = d.mocap_pos[body.mocapid[0]], d.mocap_quat[body.mocapid[0]]
        else:
            centre, (w, x, y, z) = d.xpos[body.id], d.xquat[body.id]
        return np.asarray(centre) / self.cell.unit, Rotation.from_quat([x, y, z, w])

    def _place(self, centre_m, quaternion) -> None:
        """Put the part (in place) at ``centre_m`` (m) turned by ``quaternion`` (x, y, z, w)."""
        mocap = self._body().mocapid[0]
        x, y, z, w = quaternion
        self.cell.d.mocap_pos[mocap] = centre_m
        self.cell.d.mocap_quat[mocap] = (w, x, y, z)

    def thread(self, rise: float, pitch: float, t: float) -> None:
        """On the thread: risen ``rise`` along its axis, turned ``rise / pitch`` turns (loosening
        only: :meth:`bidmp.sim.pybullet.parts._MovablePart.thread`)."""
        self.state, self.rise = "threading", max(self.rise, float(rise))
        angle = 2.0 * math.pi * self.rise / pitch
        unit, rise = self.cell.unit, self.rise
        self._place(
            [(centre + axis * rise) * unit for centre, axis in zip(self._centre0, self._axis)],
            _turned(self._quaternion0, [axis * angle for axis in self._axis]),
        )
        self.trace.append((self.rise, angle, t))

    def hold(self) -> None:
        """Held by the tool from now on: a body with the part's mass welded to the tool's mouth
        where it is, carried by the arm under physics; its contacts are its own."""
        cell = self.cell
        self._make_dynamic()
        mujoco, m, d = cell.mj, cell.m, cell.d
        mujoco.mj_kinematics(m, d)
        body = self._body()
        tcp_rotation = d.xmat[cell._tcp_body].reshape(3, 3)
        part_rotation = d.xmat[body.id].reshape(3, 3)
        # the tool's mouth in the part's frame: MuJoCo's weld keeps body2's pose relative to body1
        relative_position = part_rotation.T @ (d.xpos[cell._tcp_body] - d.xpos[body.id])
        relative = _quaternion_wxyz(part_rotation.T @ tcp_rotation)
        self.weld = cell.spec.add_equality(
            type=mujoco.mjtEq.mjEQ_WELD,
            name1=self.name,
            name2="tcp",
            objtype=mujoco.mjtObj.mjOBJ_BODY,
            solref=list(_WELD),
            data=[0.0, 0.0, 0.0, *relative_position, *relative, 1.0, 0.0],
        )
        cell._compile(keep=True)
        self.state = "held"

    def contacts(self, found: dict, ignore=()) -> None:
        """Add the part's contacts with the scene's parts (not those in ``ignore``) to ``found``."""
        cell = self.cell
        d = cell.d
        if not d.ncon:
            return
        body = self._body()
        own = set(range(body.geomadr[0], body.geomadr[0] + body.geomnum[0]))
        geoms, dists = d.contact.geom, d.contact.dist
        for k in np.flatnonzero(dists < -CONTACT_SLACK).tolist():
            g1, g2 = int(geoms[k, 0]), int(geoms[k, 1])
            other = g2 if g1 in own else g1 if g2 in own else None
            label = cell._geom_label.get(other)
            if label is not None and cell._geom_owner.get(other) not in ignore:
                found[label] = max(found.get(label, 0.0), -float(dists[k]) / cell.unit)

    def release(self) -> None:
        """Let go: the weld removed, the part falls under gravity."""
        cell = self.cell
        self._make_dynamic()
        if self.weld is not None:
            cell.spec.delete(self.weld)
            self.weld = None
            cell._compile(keep=True)
        self.state = "released"

    def rest(self) -> None:
        """A released part that has come to rest: static where it lies."""
        cell = self.cell
        centre, rotation = self.pose()
        body = cell.spec.body(self.name)
        for joint in list(body.joints):
            cell.spec.delete(joint)
        body.mocap = True
        body.pos = (centre * cell.unit).tolist()
        body.quat = _quaternion_wxyz(rotation.as_matrix())
        for geom in body.geoms:
            geom.contype, geom.conaffinity = PART_GROUP
        # static again where it lies (the arm touches it), but no longer one of the scene's parts
        cell._compile(keep=True)
        mocap = self._body().mocapid[0]
        cell.d.mocap_pos[mocap] = centre * cell.unit
        cell.d.mocap_quat[mocap] = body.quat
        self.state = "at rest"

    def _make_dynamic(self) -> None:
        """The part as a free body with its mass where it is (no longer one of the scene's parts
        in place); no contact with the arm (it sits inside the tool's solid)."""
        cell = self.cell
        if self.state in ("held", "released"):
            return
        centre, rotation = self.pose()
        body = cell.spec.body(self.name)
        body.mocap = False
        body.pos = (centre * cell.unit).tolist()
        body.quat = _quaternion_wxyz(rotation.as_matrix())
        body.add_freejoint()
        for geom in body.geoms:
            geom.contype, geom.conaffinity = MOVING_GROUP
            geom.mass = self.mass
        cell._part_bodies.pop(self.name, None)
        # (recompiled, the new free joint starts at its body's pose: where the part stood)
        cell._compile(keep=True)
