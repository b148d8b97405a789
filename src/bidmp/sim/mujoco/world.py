"""The MuJoCo world: mujoco imported (with a headless renderer), the arm's URDF with the scenario's
tool compiled to a MuJoCo model, and the scene's parts as bodies of it.

How the URDF is compiled, and why (each a difference from MuJoCo's defaults for a URDF):

* ``fusestatic="false"``: a link on a fixed joint stays a body of its own. MuJoCo fuses such links
  into their parent by default, and drops the inertia of a massless one as it does: the Panda's
  ``panda_link8`` (mass 0, inertia 0.1 kg m² in pybullet_data's URDF) went, and the arm's inverse
  dynamics differed from pinocchio's by up to 3.3 N m (gravity torques alike, to 3e-14); unfused,
  by 6e-14 N m. The tool's mouth (link ``tcp``) would go with the fusing too.
* the links' inertial parameters are the URDF's as written (a link without any: from its
  geometry, MuJoCo's ``inertiafromgeom="auto"``), the numbers pinocchio and PyBullet (with
  ``URDF_USE_INERTIA_FROM_FILE``) read.
* ``balanceinertia="true"``: an inertia tensor that is not physical (the xArm6's ``link2`` and
  ``link3`` break A + B >= C) is made so, as MuJoCo requires to load it; pinocchio takes it as
  written and PyBullet sets it to zero: the engines' inverse dynamics differ on that arm by the
  repair (``docs/results/engines.md``).
* ``discardvisual="true"``: the links' visual meshes are not loaded (pictures draw the collision
  shapes); contacts are the collision shapes', as in PyBullet.
* no self-collision (each link's ``conaffinity`` 0), as PyBullet loads a URDF; the parts in place
  touch the arm and what falls, not each other.
"""

from __future__ import annotations

import os
import re

import numpy as np

from ..._checks import require_extra

__all__ = [
    "ARM_GROUP",
    "PART_GROUP",
    "MOVING_GROUP",
    "CONTACT_SOLREF",
    "CONTACT_SLACK",
    "FALL_SUBSTEPS",
]

# contype / conaffinity bits: a contact needs one side's contype in the other's conaffinity.
ARM_GROUP = (1, 0)  # the arm's links: touch the parts, not each other
PART_GROUP = (2, 1)  # a part in place (static): touched by the arm and by what falls
MOVING_GROUP = (1, 2)  # a part held or falling: touches the parts in place, not the arm
_OFF = (0, 0)
# The parts' contacts (MuJoCo's solref: time constant s, damping ratio): two physics steps of the
# finest stepping (a falling part's), MuJoCo's stiffest stable setting (at 1 ms steps it holds
# it at 2 ms). Its default (20 ms) let a nut dropped 80 mm sink through the bin's 1.4 mm floor;
# Bullet's contacts are rigid.
CONTACT_SOLREF = (5e-4, 1.0)
# MuJoCo's contacts are soft: a body resting on another sinks into it by micrometres (its weight
# against the contact's stiffness; a part held on the table by the tool's weld 1 µm). Such a
# penetration is a body at rest, not a touch: contacts are reported from this depth (m).
CONTACT_SLACK = 1e-5
FALL_SUBSTEPS = 4  # physics steps per 1 ms while a released part falls (it moves < 0.7 mm a step)

_COMPILER = (
    '<mujoco><compiler discardvisual="true" fusestatic="false" balanceinertia="true" '
    'strippath="false" angle="radian"/></mujoco>'
)


def _mujoco_module():
    """Import mujoco, or say in one line how to install it. Pictures are drawn off-screen through
    EGL unless ``MUJOCO_GL`` says otherwise (MuJoCo's default, GLFW, needs a display)."""
    os.environ.setdefault("MUJOCO_GL", "egl")
    return require_extra("mujoco", "mujoco", "the MuJoCo backend (--backend mujoco)")


def _arm_spec(mujoco, urdf_text: str):
    """A MuJoCo model spec of the arm with its tool (the text of
    :func:`bidmp.sim.pybullet.world._tool_urdf`), compiled as the module docstring says."""
    text = re.sub(r"(<robot\b[^>]*>)", r"\1" + _COMPILER, urdf_text, count=1)
    try:
        return mujoco.MjSpec.from_string(text)
    except ValueError as exc:
        raise ValueError(
            f"robot URDF: MuJoCo cannot read it ({str(exc).splitlines()[0]})"
        ) from None


def _solid_geom(mujoco, body, unit: float, solid, name: str):
    """A geom for one solid of the scene on ``body`` (at the body's frame), in metres: a box, a
    cylinder, or a nut's convex hull (a mesh of its vertices, added to the spec as ``name``)."""
    if solid.kind == "box":
        geom = body.add_geom(
            type=mujoco.mjtGeom.mjGEOM_BOX, size=[0.5 * v * unit for v in solid.params]
        )
    elif solid.kind == "cylinder":
        geom = body.add_geom(
            type=mujoco.mjtGeom.mjGEOM_CYLINDER,
            size=[solid.params[0] * unit, 0.5 * solid.params[1] * unit, 0.0],
        )
    else:
        geom = body.add_geom(type=mujoco.mjtGeom.mjGEOM_MESH, meshname=name)
    geom.name = name
    geom.rgba = _colour(solid, unit)
    return geom


def _colour(solid, unit: float) -> list:
    from ..pybullet.world import _colour as colour

    return colour(solid, unit)


def _quaternion_wxyz(rotation) -> list:
    """A rotation matrix (3, 3) as MuJoCo's quaternion (w, x, y, z)."""
    from scipy.spatial.transform import Rotation

    x, y, z, w = Rotation.from_matrix(np.asarray(rotation, dtype=float)).as_quat()
    return [w, x, y, z]


def _add_part_body(mujoco, spec, unit: float, solid, name: str, moving: bool = False):
    """The body of one solid of the scene: static where it stands (a mocap body: the world holds
    it, the job moves it on its thread), or free (``moving``: held or falling) with the solid's
    mass spread as a uniform solid's. Returns the body."""
    if solid.kind == "convex":
        spec.add_mesh(name=name, uservert=(np.asarray(solid.params[0]) * unit).ravel().tolist())
    body = spec.worldbody.add_body(
        name=name,
        pos=(np.asarray(solid.centre) * unit).tolist(),
        quat=_quaternion_wxyz(solid.rotation),
        mocap=not moving,
    )
    geom = _solid_geom(mujoco, body, unit, solid, name)
    geom.contype, geom.conaffinity = MOVING_GROUP if moving else PART_GROUP
    geom.solref = list(CONTACT_SOLREF)
    return body
