"""Write the Franka Research 3's URDF (src/bidmp/data/robots/fr3.urdf) from the published numbers.

Franka publishes the FR3's kinematics as modified (Craig) Denavit-Hartenberg parameters, the same
as the Panda's (a4 = 0.0825 m, a5 = -0.0825 m, a7 = 0.088 m, d1 = 0.333 m, d3 = 0.316 m, d5 =
0.384 m, the flange d = 0.107 m; "Robot and interface specifications", Franka's documentation),
and its URDF (as the robot serves it to libfranka >= 0.10) the joint ranges and speeds that
bidmp.sim.fci.FCI_LIMITS["fr3"] holds. The links here are cylinders along the segments between
the joints, with radii near the real arm's housings: enough for the simulator's contacts, not a
visual model (pybullet_data's Panda has meshes; its URDF's joint 6 stops at 3.82 rad, where the
FR3's goes to 4.52).

Modified DH: frame i = frame i-1 . Rx(alpha_i-1) Tx(a_i-1) Rz(theta_i) Tz(d_i): joint i's URDF
origin in link i-1 is (a_i-1, -sin(alpha) d_i, cos(alpha) d_i) with roll alpha_i-1.

Run ``python tools/fr3_urdf.py`` to write it again; tests/sim/test_fr3.py checks PyBullet's forward
kinematics of the file against the DH product computed independently.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "src"))
from bidmp.sim.fci import FCI_LIMITS  # noqa: E402

# (a_{i-1}, d_i, alpha_{i-1}) per joint, metres and radians; then the flange (d only)
MDH = (
    (0.0, 0.333, 0.0),
    (0.0, 0.0, -math.pi / 2),
    (0.0, 0.316, math.pi / 2),
    (0.0825, 0.0, math.pi / 2),
    (-0.0825, 0.384, -math.pi / 2),
    (0.0, 0.0, math.pi / 2),
    (0.088, 0.0, math.pi / 2),
)
FLANGE_D = 0.107
# kg, links 1..7 (Franka's dynamic model, rounded)
MASSES = (4.97, 0.65, 3.23, 3.59, 1.23, 1.67, 0.74)
RADII = (0.065, 0.065, 0.06, 0.06, 0.055, 0.05, 0.045)  # m: the housing round each segment
EFFORT = (87.0, 87.0, 87.0, 87.0, 12.0, 12.0, 12.0)  # N m
OUT = Path(__file__).resolve().parents[1] / "src" / "bidmp" / "data" / "robots" / "fr3.urdf"


def _origin(a: float, d: float, alpha: float) -> tuple[str, str]:
    """A joint's URDF origin (xyz, rpy) in its parent link from its modified DH row."""
    return (
        f"{a:.6g} {-math.sin(alpha) * d:.6g} {math.cos(alpha) * d:.6g}",
        f"{alpha:.10f} 0 0",
    )


def _segment(tail: tuple[float, float, float], radius: float, mass: float) -> str:
    """A link's cylinder from its origin to ``tail`` (the next joint's origin in its frame)."""
    x, y, z = tail
    length = math.sqrt(x * x + y * y + z * z)
    if length < 0.02:  # a joint right on the next: a housing round the joint itself
        x, y, z, length = 0.0, 0.0, 0.0, 0.12
    # URDF's rpy turns z into (sin p cos r, -sin r, cos p cos r): onto the segment's direction
    roll = math.asin(max(-1.0, min(1.0, -y / length)))
    pitch = math.atan2(x, z)
    centre = f"{x / 2:.6f} {y / 2:.6f} {z / 2:.6f}"
    shape = (
        f'<origin xyz="{centre}" rpy="{roll:.6f} {pitch:.6f} 0"/><geometry><cylinder '
        f'radius="{radius}" length="{length:.6f}"/></geometry>'
    )
    inertia = mass * radius**2 / 2.0
    return (
        f'    <inertial><origin xyz="{centre}"/><mass value="{mass}"/><inertia ixx="{inertia:.6g}" '
        f'ixy="0" ixz="0" iyy="{inertia:.6g}" iyz="0" izz="{inertia:.6g}"/></inertial>\n'
        f'    <visual>{shape}<material name="fr3"><color rgba="0.9 0.9 0.92 1"/></material></visual>\n'
        f"    <collision>{shape}</collision>\n"
    )


def urdf() -> str:
    limits = FCI_LIMITS["fr3"]
    lines = [
        '<?xml version="1.0"?>',
        "<!-- Written by tools/fr3_urdf.py from the FR3's published kinematics and limits. -->",
        '<robot name="fr3">',
        '  <link name="fr3_link0">',
        '    <inertial><mass value="2.92"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>',
        '    <visual><origin xyz="0 0 0.07"/><geometry><cylinder radius="0.08" length="0.14"/></geometry></visual>',
        '    <collision><origin xyz="0 0 0.07"/><geometry><cylinder radius="0.08" length="0.14"/>'
        "</geometry></collision>",
        "  </link>",
    ]
    rows = [*MDH, (0.0, FLANGE_D, 0.0)]
    for index in range(1, 8):
        a, d, alpha = rows[index - 1]
        xyz, rpy = _origin(a, d, alpha)
        parent, child = f"fr3_link{index - 1}", f"fr3_link{index}"
        lines.append(
            f'  <joint name="fr3_joint{index}" type="revolute"><parent link="{parent}"/>'
            f'<child link="{child}"/><origin xyz="{xyz}" rpy="{rpy}"/><axis xyz="0 0 1"/>'
            f'<limit lower="{limits.lower[index - 1]}" upper="{limits.upper[index - 1]}" '
            f'velocity="{limits.velocity[index - 1]}" effort="{EFFORT[index - 1]}"/></joint>'
        )
        a_next, d_next, alpha_next = rows[index]
        tail = (a_next, -math.sin(alpha_next) * d_next, math.cos(alpha_next) * d_next)
        lines.append(
            f'  <link name="{child}">\n{_segment(tail, RADII[index - 1], MASSES[index - 1])}  </link>'
        )
    lines.append(
        f'  <joint name="fr3_joint8" type="fixed"><parent link="fr3_link7"/><child link="fr3_link8"/>'
        f'<origin xyz="0 0 {FLANGE_D}" rpy="0 0 0"/></joint>'
    )
    lines.append(
        '  <link name="fr3_link8"><inertial><mass value="0.01"/><inertia ixx="1e-6" ixy="0" ixz="0" '
        'iyy="1e-6" iyz="0" izz="1e-6"/></inertial></link>'
    )
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    OUT.parent.mkdir(parents=True, exist_ok=True)
    OUT.write_text(urdf())
    print(f"wrote {OUT}")
