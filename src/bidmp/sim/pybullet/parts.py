"""Parts the job takes away, in the PyBullet world: a nut on its stud's thread, a part held by
the tool, a part let go that falls under gravity; and the job's own parts (bin, rack).

**The thread** is kinematic: while the socket is engaged the nut turns about its axis and rises
by the pitch per turn, ``rise = pitch * turns``; once its bottom clears the stud's top it is off
the thread and stays in the socket. **Held** parts are bodies with their mass fixed to the tool
by a constraint (a socket's or a suction gripper's hold), carried by the arm under physics.
**Released** parts become dynamic bodies with their mass and fall under gravity,
colliding with everything else. (A full contact model of a thread — helical surfaces, friction —
would cost far more than it shows: what the job needs is where the nut is.)
"""

from __future__ import annotations

import math

import numpy as np
from scipy.spatial.transform import Rotation

from ..backend import SIM_STEP, _check_solids, _part_args, _solid_height
from .world import _add_solid

__all__ = []


def _turned(quaternion: tuple[float, ...], rotvec) -> list[float]:
    """``Rotation.from_rotvec(rotvec) * Rotation.from_quat(quaternion)`` as a quaternion
    (x, y, z, w), in scipy's own arithmetic, step by step (its small-angle series, its product,
    its normalisation): the same bits, so a released nut falls exactly as before. The thread
    asks for it at every recorded step, where the two Rotation objects cost 25 µs."""
    x, y, z = (float(value) for value in rotvec)
    angle = math.sqrt(x * x + y * y + z * z)
    if angle <= 1e-3:
        square = angle * angle
        scale = 0.5 - square / 48 + square * square / 3840
    else:
        scale = math.sin(angle / 2) / angle
    px, py, pz, pw = x * scale, y * scale, z * scale, math.cos(angle / 2)
    qx, qy, qz, qw = quaternion
    product = [
        pw * qx + qw * px + (py * qz - pz * qy),
        pw * qy + qw * py + (pz * qx - px * qz),
        pw * qz + qw * pz + (px * qy - py * qx),
        pw * qw - px * qx - py * qy - pz * qz,
    ]
    norm = math.sqrt(sum(v * v for v in product))
    return [v / norm for v in product]


class _MovablePart:
    """One part of the scene (a nut or a cell) that the job moves: ``seated`` → (``threading``) →
    ``held`` → ``released``. Poses in scene units."""

    def __init__(self, cell, label: str, mass: float):
        self.solid, mass = _part_args(cell.scene, label, mass)
        self.cell, self.label, self.mass = cell, label, mass
        self.body = next(body for body, name in cell._bodies.items() if name == label)
        self.centre0 = np.asarray(self.solid.centre, dtype=float)
        self.rotation0 = Rotation.from_matrix(self.solid.rotation)
        self._quaternion0 = tuple(self.rotation0.as_quat().tolist())
        self.axis = self.solid.rotation[:, 2]
        # The thread's pose in plain floats (the same IEEE operations as NumPy's elementwise ones,
        # without an array per step): the centre and the axis as lists.
        self._centre0, self._axis = self.centre0.tolist(), self.axis.tolist()
        self.height = _solid_height(self.solid)
        self.state, self.rise, self.constraint = "seated", 0.0, None
        self.trace: list[
            tuple[float, float, float]
        ] = []  # (rise, angle turned, time) while threading

    def set_pose(self, centre, rotation: Rotation) -> None:
        self._place((np.asarray(centre) * self.cell.unit).tolist(), rotation.as_quat().tolist())

    def _place(self, centre_m: list[float], quaternion: list[float]) -> None:
        """Put the body at ``centre_m`` (m) turned by ``quaternion`` (x, y, z, w)."""
        self.cell.p.resetBasePositionAndOrientation(
            self.body, centre_m, quaternion, physicsClientId=self.cell.client
        )

    def pose(self) -> tuple[np.ndarray, Rotation]:
        position, orientation = self.cell.p.getBasePositionAndOrientation(
            self.body, physicsClientId=self.cell.client
        )
        return np.asarray(position) / self.cell.unit, Rotation.from_quat(orientation)

    def thread(self, rise: float, pitch: float, t: float) -> None:
        """On the thread: risen ``rise`` along its axis, turned ``rise / pitch`` turns
        (counter-clockwise seen from above: a right-hand thread loosening). The spindle only
        loosens: a lag of the arm (the measured tool dips back a few micrometres) holds the nut
        where it is rather than screwing it back."""
        self.state, self.rise = "threading", max(self.rise, float(rise))
        angle = 2.0 * math.pi * self.rise / pitch
        unit, rise = self.cell.unit, self.rise
        self._place(
            [(centre + axis * rise) * unit for centre, axis in zip(self._centre0, self._axis)],
            _turned(self._quaternion0, [axis * angle for axis in self._axis]),
        )
        self.trace.append((self.rise, angle, t))

    def hold(self) -> None:
        """Held by the tool from now on: a body with the part's mass, fixed to the tool's mouth
        where it is by a constraint (the gripper's or the socket's hold), carried by the arm
        under physics; its contacts with other parts are its own (:meth:`contacts`)."""
        p, cell = self.cell.p, self.cell
        self._make_dynamic()
        tcp_position, tcp_orientation = p.getLinkState(
            cell.robot, cell.tcp, computeForwardKinematics=1, physicsClientId=cell.client
        )[4:6]
        position, orientation = p.getBasePositionAndOrientation(
            self.body, physicsClientId=cell.client
        )
        inverse = p.invertTransform(tcp_position, tcp_orientation)
        local_position, local_orientation = p.multiplyTransforms(*inverse, position, orientation)
        self.constraint = p.createConstraint(
            cell.robot,
            cell.tcp,
            self.body,
            -1,
            p.JOINT_FIXED,
            [0, 0, 0],
            local_position,
            [0, 0, 0],
            local_orientation,
            [0, 0, 0, 1],
            physicsClientId=cell.client,
        )
        p.changeConstraint(self.constraint, maxForce=500.0, physicsClientId=cell.client)
        self.state = "held"

    def contacts(self, found: dict, ignore=()) -> None:
        """Add the part's contacts with the scene's parts (not those in ``ignore``) to ``found``."""
        cell = self.cell
        for contact in cell.p.getContactPoints(bodyA=self.body, physicsClientId=cell.client):
            label = cell._bodies.get(contact[2])
            if (
                label is not None
                and contact[8] < 0.0
                and cell._owners.get(contact[2]) not in ignore
            ):
                found[label] = max(found.get(label, 0.0), -contact[8] / cell.unit)

    def release(self) -> None:
        """Let go: the constraint removed, the part falls under gravity."""
        p, cell = self.cell.p, self.cell
        if self.constraint is not None:
            p.removeConstraint(self.constraint, physicsClientId=cell.client)
            self.constraint = None
        self._make_dynamic()
        self.state = "released"

    def rest(self) -> None:
        """A released part that has come to rest: a static body where it lies (13 nuts tumbling in
        a bin on every later step made the 14-nut job run at half the speed)."""
        self._replace_body(0.0)
        self.state = "at rest"

    def _make_dynamic(self) -> None:
        """The part as a body with its mass in its place (no longer one of the scene's static
        bodies); no contact with the arm: it sits inside the tool's solid (a socket, a gripper),
        which would throw both apart."""
        p, cell = self.cell.p, self.cell
        if self.state in ("held", "released"):
            return
        cell._bodies.pop(self.body, None)
        cell._owners.pop(self.body, None)
        self._replace_body(self.mass)
        for link in range(-1, p.getNumJoints(cell.robot, physicsClientId=cell.client)):
            p.setCollisionFilterPair(
                cell.robot, self.body, link, -1, 0, physicsClientId=cell.client
            )

    def _replace_body(self, mass: float) -> None:
        """The part's body made anew where it is: dynamic with ``mass`` (kg), or static (0)."""
        p, cell = self.cell.p, self.cell
        centre, rotation = self.pose()
        p.removeBody(self.body, physicsClientId=cell.client)
        self.body = _add_solid(p, cell.client, cell.unit, self.solid, mass=mass)
        self.set_pose(centre, rotation)


def _add_job_solids(cell, solids) -> None:
    """Static bodies for the job's own parts (bin walls, ...), their contacts reported by label."""
    for solid in _check_solids(solids):
        body = _add_solid(cell.p, cell.client, cell.unit, solid)
        cell._bodies[body] = solid.label
        cell._owners[body] = solid.part


def _settle(cell, seconds: float) -> None:
    """Let the world run ``seconds`` with the arm holding where it is (a released part falls)."""
    p = cell.p
    states = p.getJointStates(cell.robot, cell.arm, physicsClientId=cell.client)
    held = [s[0] for s in states]
    p.setJointMotorControlArray(
        cell.robot,
        cell.arm,
        p.POSITION_CONTROL,
        targetPositions=held,
        targetVelocities=[0.0] * len(cell.arm),
        forces=list(cell.model.effort),
        physicsClientId=cell.client,
    )
    for _ in range(int(round(seconds / SIM_STEP))):
        p.stepSimulation(physicsClientId=cell.client)
