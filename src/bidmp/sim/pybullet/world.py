"""The PyBullet world: pybullet imported quietly, the Panda's URDF with the scenario's tool, and the
scene's parts as static bodies."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from ..._checks import check_limit, require_extra, short_token, shown_path

__all__ = ["SOLVER_ITERATIONS"]

SOLVER_ITERATIONS = 20


def _pybullet_module():
    """Import pybullet without its banner (it writes one line from C to the process's stderr on
    import; a library must not)."""
    import sys

    module = sys.modules.get("pybullet")
    if module is not None:
        return module
    for stream in (sys.stdout, sys.stderr):
        # None: a caller redirected it away (contextlib.redirect_stdout(None))
        if stream is not None:
            stream.flush()
    saved = [os.dup(1), os.dup(2)]
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 1)
            os.dup2(null.fileno(), 2)
            try:
                return require_extra("pybullet", "sim", "the simulator (bidmp sim)")
            finally:
                os.dup2(saved[0], 1)
                os.dup2(saved[1], 2)
    finally:
        for fd in saved:
            os.close(fd)


_MESHES = (".stl", ".obj", ".dae")


def _mesh(folder: Path, name: str, urdf: Path) -> Path:
    """A URDF's mesh file, made absolute: a regular .stl, .obj or .dae file inside the URDF's folder
    (a URDF is data: it may not make the simulator read files elsewhere)."""
    import os

    resolved = Path(os.path.realpath(folder / name))
    inside = os.path.commonpath([os.path.realpath(folder), resolved]) == os.path.realpath(folder)
    if not inside or resolved.suffix.lower() not in _MESHES or not resolved.is_file():
        raise ValueError(
            f"robot URDF {shown_path(urdf)}: mesh {short_token(name, 40)} must be a .stl, .obj or .dae "
            f"file inside the URDF's folder"
        )
    check_limit(
        resolved.stat().st_size,
        "max_file_bytes",
        f"the size of mesh {shown_path(resolved)} in bytes",
    )
    return resolved


def _kinematic_urdf(text: str) -> str:
    """The URDF ``text`` without its links' visual and collision geometry, for the planning copy
    of the arm: inverse and forward kinematics read the joints' axes and frames only (the same
    bits with or without the geometry, tested), and parsing the meshes was most of the time of
    loading that copy. Text that ElementTree cannot read is returned whole."""
    import xml.etree.ElementTree as ElementTree

    try:
        root = ElementTree.fromstring(text)
    except ElementTree.ParseError:
        return text
    for link in root.iter("link"):
        for tag in ("visual", "collision"):
            for element in link.findall(tag):
                link.remove(element)
    return ElementTree.tostring(root, encoding="unicode")


def _tool_urdf(model, tool_radius: float, tool_length: float) -> str:
    """The URDF of ``model`` (a :class:`~bidmp.sim.robots.RobotModel`) carrying a
    cylindrical tool (metres) on its flange: link ``tool`` on the flange, link ``tcp`` at the
    tool's mouth. The Panda's own hand is cut away (``model.cut_at``). Mesh paths are made
    absolute, since the text is loaded from another folder."""
    import re

    import pybullet_data

    path = Path(model.urdf)
    if not path.is_absolute():
        path = Path(pybullet_data.getDataPath()) / path
    if not path.is_file():
        raise ValueError(
            f"robot URDF {shown_path(model.urdf)}: no such regular file (a path in the scenario's folder, "
            f"or a model shipped by pybullet_data such as kuka_iiwa/model.urdf)"
        )
    check_limit(path.stat().st_size, "max_file_bytes", f"the size of {shown_path(path)} in bytes")
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(
            f"robot URDF {shown_path(path)} cannot be read as text ({type(exc).__name__})"
        ) from None
    folder = path.parent
    cut = (
        text.find(f'<joint name="{model.cut_at}"')
        if model.cut_at is not None
        else text.rfind("</robot>")
    )
    if "<robot" not in text or cut < 0:
        raise ValueError(
            f"robot URDF {shown_path(path)} is not a URDF with the joint the hand is cut at"
            if model.cut_at is not None and "<robot" in text
            else f"{shown_path(path)} is not a URDF robot"
        )
    text = text[:cut]
    if f'<link name="{model.flange}"' not in text:
        raise ValueError(f"robot URDF {model.urdf!r} has no link {model.flange!r} (the flange)")
    inertia = 'ixx="1e-4" ixy="0" ixz="0" iyy="1e-4" iyz="0" izz="1e-4"'
    tool = (
        f'  <joint name="tool_joint" type="fixed"><parent link="{model.flange}"/><child link="tool"/>'
        f'<origin rpy="0 0 0" xyz="0 0 {tool_length / 2}"/></joint>\n'
        f'  <link name="tool"><inertial><origin xyz="0 0 0"/><mass value="0.3"/><inertia {inertia}/></inertial>'
        f'<visual><geometry><cylinder radius="{tool_radius}" length="{tool_length}"/></geometry>'
        f'<material name="socket"><color rgba="0.25 0.25 0.28 1"/></material></visual>'
        f'<collision><geometry><cylinder radius="{tool_radius}" '
        f'length="{tool_length}"/></geometry></collision></link>\n'
        f'  <joint name="tcp_joint" type="fixed"><parent link="tool"/><child link="tcp"/>'
        f'<origin rpy="0 0 0" xyz="0 0 {tool_length / 2}"/></joint>\n'
        f'  <link name="tcp"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/>'
        f"</inertial></link>\n</robot>\n"
    )

    def absolute(match):
        name = match.group(2)
        if name.startswith("package://"):
            name = name[len("package://") :]
        return f'{match.group(1)}{_mesh(folder, name, path)}"'

    return re.sub(r'(<mesh\b[^>]*?\sfilename=")([^"]+)"', absolute, text + tool)


# Bullet grows a convex hull by its collision margin (PyBullet's default for a mesh: 1 mm), so a
# 0.88 mm near miss of a nut was a "contact". Boxes and cylinders keep their margin inside.
HULL_MARGIN = 1e-3  # m


def _inset_prism(vertices: np.ndarray, margin: float) -> np.ndarray:
    """The vertices (local frame, centred, axis z) of a prism moved in by ``margin`` on every face,
    so that the hull grown by Bullet's margin has the solid's own faces again (its edges rounded)."""
    from scipy.spatial import ConvexHull

    planes = ConvexHull(vertices).equations  # n·x + d = 0, n outward
    sides = planes[np.abs(planes[:, 2]) < 1e-9]
    inradius = float(np.min(-sides[:, 3]))
    half_height = float(np.max(vertices[:, 2]))
    scale = np.array(
        [
            (inradius - margin) / inradius,
            (inradius - margin) / inradius,
            (half_height - margin) / half_height,
        ]
    )
    return vertices * scale


# -- world -----------------------------------------------------------------------------
def _add_solid(p, client: int, unit: float, solid, mass: float = 0.0) -> int:
    """A body for one solid of the scene (box, cylinder, or a nut's convex hull), in metres: static,
    or dynamic with ``mass`` (kg)."""
    if solid.kind == "box":
        half = [0.5 * v * unit for v in solid.params]
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
        visual = p.createVisualShape(
            p.GEOM_BOX, halfExtents=half, rgbaColor=_colour(solid, unit), physicsClientId=client
        )
    elif solid.kind == "cylinder":
        radius, height = solid.params[0] * unit, solid.params[1] * unit
        shape = p.createCollisionShape(
            p.GEOM_CYLINDER, radius=radius, height=height, physicsClientId=client
        )
        visual = p.createVisualShape(
            p.GEOM_CYLINDER,
            radius=radius,
            length=height,
            rgbaColor=_colour(solid, unit),
            physicsClientId=client,
        )
    else:  # the hex nut: its convex hull
        vertices = (_inset_prism(np.asarray(solid.params[0]) * unit, HULL_MARGIN)).tolist()
        shape = p.createCollisionShape(p.GEOM_MESH, vertices=vertices, physicsClientId=client)
        extent = np.ptp(np.asarray(solid.params[0]), axis=0) * unit
        visual = p.createVisualShape(
            p.GEOM_CYLINDER,
            radius=0.5 * extent[0],
            length=extent[2],
            rgbaColor=_colour(solid, unit),
            physicsClientId=client,
        )
    from scipy.spatial.transform import Rotation

    orientation = Rotation.from_matrix(solid.rotation).as_quat().tolist()
    return p.createMultiBody(
        float(mass),
        shape,
        visual,
        (np.asarray(solid.centre) * unit).tolist(),
        orientation,
        physicsClientId=client,
    )


def _colour(solid, unit: float) -> list:
    """A part's colour in the pictures: studs dark, nuts light, posts and other cylinders steel,
    boxes by their height in metres (thin plates pale, tall parts such as cells blue)."""
    if solid.label.endswith("/stud"):
        return [0.35, 0.35, 0.38, 1.0]
    if solid.kind == "convex":
        return [0.75, 0.75, 0.7, 1.0]
    if solid.kind == "cylinder":
        return [0.5, 0.52, 0.56, 1.0]
    return [0.55, 0.62, 0.72, 1.0] if solid.params[2] * unit < 0.02 else [0.35, 0.5, 0.8, 1.0]
