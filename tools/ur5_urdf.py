"""Write the UR5-class arm's URDF (src/bidmp/data/robots/ur5_dh.urdf) from the published numbers.

Universal Robots publishes the UR5's kinematics as classic Denavit-Hartenberg parameters (d, a, alpha
per joint; "DH parameters for calculations of kinematics and dynamics", UR support site), its joint
ranges (+-360 deg every joint), speeds (180 deg/s every joint), link masses and joint torques (150 N m
for the base, shoulder and elbow, 28 N m for the wrists). The links here are cylinders along the DH
segments, with the radii of the real arm's tubes and housings to a few millimetres: enough for the
simulator's contacts, not a visual model.

Classic DH: frame i = frame i-1 . Rz(theta_i) Tz(d_i) Tx(a_i) Rx(alpha_i). A URDF joint rotates
about its own z at its origin, so joint i sits at frame i-1 and joint i+1's origin is the DH tail
(a_i, 0, d_i) with roll alpha_i in link i's frame; the flange is frame 6.

Run ``python tools/ur5_urdf.py`` to write it again; tests/sim/test_robots.py checks PyBullet's forward
kinematics of the file against the DH product computed independently.
"""

from __future__ import annotations

import math
from pathlib import Path

# (d, a, alpha) per joint, metres and radians: the UR5 (CB3) table.
DH = (
    (0.089159, 0.0, math.pi / 2),
    (0.0, -0.425, 0.0),
    (0.0, -0.39225, 0.0),
    (0.10915, 0.0, math.pi / 2),
    (0.09465, 0.0, -math.pi / 2),
    (0.0823, 0.0, 0.0),
)
MASSES = (3.7, 8.393, 2.275, 1.219, 1.219, 0.1879)  # kg, shoulder ... wrist 3
RADII = (0.06, 0.054, 0.04, 0.045, 0.045, 0.04)  # m: the tube or housing round each DH segment
EFFORT = (150.0, 150.0, 150.0, 28.0, 28.0, 28.0)  # N m
SPEED = math.pi  # rad/s, every joint
RANGE = 2.0 * math.pi  # rad, every joint both ways
OUT = Path(__file__).resolve().parents[1] / "src" / "bidmp" / "data" / "robots" / "ur5_dh.urdf"


def _segment(d: float, a: float, radius: float, mass: float) -> str:
    """A link's cylinder from its origin to the next joint's, (a, 0, d), with an inertial."""
    length = math.hypot(a, d)
    pitch = math.atan2(a, d)  # turns the cylinder's z onto (a, 0, d)
    centre = f"{a / 2:.6f} 0 {d / 2:.6f}"
    shape = (
        f'<origin xyz="{centre}" rpy="0 {pitch:.6f} 0"/><geometry><cylinder radius="{radius}" '
        f'length="{max(length, 0.02):.6f}"/></geometry>'
    )
    inertia = mass * radius**2 / 2.0
    return (
        f'    <inertial><origin xyz="{centre}"/><mass value="{mass}"/><inertia ixx="{inertia:.6g}" ixy="0" '
        f'ixz="0" iyy="{inertia:.6g}" iyz="0" izz="{inertia:.6g}"/></inertial>\n'
        f'    <visual>{shape}<material name="ur"><color rgba="0.6 0.65 0.7 1"/></material></visual>\n'
        f"    <collision>{shape}</collision>\n"
    )


# A user's kind of six-axis arm that is not built in, for the tests of an arm bidmp knows only
# from its URDF (tests/data/tm5_like/): Techman's TM5-700 numbers as its maker publishes them
# (d1 145.2 mm, a2 329 mm, a3 311.5 mm, d4 122.3 mm, d5 106 mm, d6 113.15 mm; joints +-270,
# +-180, +-155, +-180, +-180, +-270 deg at 180, 180, 180, 225, 225, 225 deg/s), written in the
# UR5's DH form but with the upper arm's lengths positive: its zero pose reaches the other way.
TM5_LIKE = {
    "name": "tm5_like",
    "dh": (
        (0.1452, 0.0, math.pi / 2),
        (0.0, 0.329, 0.0),
        (0.0, 0.3115, 0.0),
        (0.1223, 0.0, math.pi / 2),
        (0.106, 0.0, -math.pi / 2),
        (0.11315, 0.0, 0.0),
    ),
    "masses": (4.0, 7.0, 2.3, 1.3, 1.3, 0.3),
    "radii": (0.06, 0.055, 0.045, 0.045, 0.045, 0.04),
    "effort": (157.0, 157.0, 157.0, 43.0, 43.0, 43.0),
    "ranges": tuple(math.radians(v) for v in (270, 180, 155, 180, 180, 270)),
    "speeds": tuple(math.radians(v) for v in (180, 180, 180, 225, 225, 225)),
}
UR5 = {
    "name": "ur5_dh",
    "dh": DH,
    "masses": MASSES,
    "radii": RADII,
    "effort": EFFORT,
    "ranges": (RANGE,) * 6,
    "speeds": (SPEED,) * 6,
}
ARMS = {"ur5": UR5, "tm5-like": TM5_LIKE}


def urdf(arm: dict = UR5) -> str:
    where = (
        "the UR5's published DH parameters and limits"
        if arm is UR5
        else f"the published DH parameters and limits of the arm {arm['name']} is modelled on"
    )
    lines = [
        '<?xml version="1.0"?>',
        f"<!-- Written by tools/ur5_urdf.py from {where}. -->",
        f'<robot name="{arm["name"]}">',
        '  <link name="base_link">',
        '    <inertial><mass value="4.0"/>'
        '<inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>',
        '    <visual><origin xyz="0 0 -0.025"/><geometry><cylinder radius="0.075" length="0.05"/></geometry></visual>',
        '    <collision><origin xyz="0 0 -0.025"/><geometry>'
        '<cylinder radius="0.075" length="0.05"/></geometry></collision>',
        "  </link>",
    ]
    parent, origin = "base_link", ("0 0 0", "0 0 0")
    for index, ((d, a, alpha), mass, radius, effort, reach, speed) in enumerate(
        zip(arm["dh"], arm["masses"], arm["radii"], arm["effort"], arm["ranges"], arm["speeds"]),
        start=1,
    ):
        name = f"link{index}"
        lines.append(
            f'  <joint name="joint{index}" type="revolute"><parent link="{parent}"/><child link="{name}"/>'
            f'<origin xyz="{origin[0]}" rpy="{origin[1]}"/><axis xyz="0 0 1"/>'
            f'<limit lower="{-reach:.6f}" upper="{reach:.6f}" velocity="{speed:.6f}" effort="{effort}"/></joint>'
        )
        lines.append(f'  <link name="{name}">\n{_segment(d, a, radius, mass)}  </link>')
        parent, origin = name, (f"{a} 0 {d}", f"{alpha:.10f} 0 0")
    lines.append(
        f'  <joint name="flange_joint" type="fixed"><parent link="{parent}"/><child link="flange"/>'
        f'<origin xyz="{origin[0]}" rpy="{origin[1]}"/></joint>'
    )
    lines.append(
        '  <link name="flange"><inertial><mass value="0.01"/><inertia ixx="1e-6" ixy="0" ixz="0" iyy="1e-6" '
        'iyz="0" izz="1e-6"/></inertial></link>'
    )
    lines.append("</robot>")
    return "\n".join(lines) + "\n"


if __name__ == "__main__":
    import argparse

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--arm", choices=sorted(ARMS), default="ur5")
    parser.add_argument("--out", default=None, help=f"the file (default, for the UR5: {OUT})")
    args = parser.parse_args()
    out = Path(args.out) if args.out else OUT
    if args.out is None and args.arm != "ur5":
        parser.error("--out is needed for an arm other than the built-in UR5")
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(urdf(ARMS[args.arm]))
    print(f"wrote {out}")
