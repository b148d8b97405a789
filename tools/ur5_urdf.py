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


def _segment(tail: tuple, radius: float, mass: float) -> str:
    """A link's cylinder from its origin to the next joint's, ``tail`` = (x, y, z), with an inertial."""
    x, y, z = tail
    length = math.sqrt(x * x + y * y + z * z)
    if y == 0.0:  # in the link's xz plane: a pitch alone turns the cylinder's z onto it
        centre, turn = f"{x / 2:.6f} 0 {z / 2:.6f}", f"0 {math.atan2(x, z):.6f} 0"
    else:
        centre = f"{x / 2:.6f} {y / 2:.6f} {z / 2:.6f}"
        turn = f"0 {math.atan2(math.hypot(x, y), z):.6f} {math.atan2(y, x):.6f}"
    shape = (
        f'<origin xyz="{centre}" rpy="{turn}"/><geometry><cylinder radius="{radius}" '
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
# A user's industrial arm with an offset wrist and an elbow offset, as its maker publishes it: ABB's
# IRB 1200-7/0.7 (product specification 3HAC046982; the classic DH table of ARTE's model of it:
# d1 399 mm, a2 350 mm, a3 42 mm, d4 351 mm, d6 82 mm; theta offsets -90 deg on axis 2 and 180 deg
# on axis 6), its axis ranges (+-170, -100/+135, -200/+70, +-270, +-130, +-400 deg) and speeds
# (288, 240, 297, 400, 405, 600 deg/s); masses and radii to a few kilograms and millimetres.
IRB1200 = {
    "name": "irb1200",
    "dh": (
        (0.399, 0.0, -math.pi / 2),
        (0.0, 0.35, 0.0),
        (0.0, 0.042, -math.pi / 2),
        (0.351, 0.0, math.pi / 2),
        (0.0, 0.0, -math.pi / 2),
        (0.082, 0.0, 0.0),
    ),
    "offsets": (0.0, -math.pi / 2, 0.0, 0.0, 0.0, math.pi),
    "masses": (12.0, 10.0, 6.0, 3.0, 1.5, 0.5),
    "radii": (0.07, 0.06, 0.055, 0.045, 0.04, 0.032),
    "effort": (150.0, 150.0, 100.0, 40.0, 40.0, 30.0),
    "lower": tuple(math.radians(v) for v in (-170, -100, -200, -270, -130, -400)),
    "upper": tuple(math.radians(v) for v in (170, 135, 70, 270, 130, 400)),
    "speeds": tuple(math.radians(v) for v in (288, 240, 297, 400, 405, 600)),
}
ARMS = {"ur5": UR5, "tm5-like": TM5_LIKE, "irb1200": IRB1200}


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
    n = len(arm["dh"])
    offsets = arm.get("offsets", (0.0,) * n)
    lower = arm.get("lower", tuple(-r for r in arm.get("ranges", ())))
    upper = arm.get("upper", arm.get("ranges"))
    for index, ((d, a, alpha), offset, mass, radius, effort, low, high, speed) in enumerate(
        zip(
            arm["dh"],
            offsets,
            arm["masses"],
            arm["radii"],
            arm["effort"],
            lower,
            upper,
            arm["speeds"],
        ),
        start=1,
    ):
        name = f"link{index}"
        lines.append(
            f'  <joint name="joint{index}" type="revolute"><parent link="{parent}"/><child link="{name}"/>'
            f'<origin xyz="{origin[0]}" rpy="{origin[1]}"/><axis xyz="0 0 1"/>'
            f'<limit lower="{low:.6f}" upper="{high:.6f}" velocity="{speed:.6f}" effort="{effort}"/></joint>'
        )
        # A theta offset turns the link's own frame about the joint's axis: Rz(q + offset) =
        # Rz(q) Rz(offset), so the next joint's origin is the DH tail turned by it.
        if offset == 0.0:
            tail = (a, 0.0, d)
            origin = (f"{a} 0 {d}", f"{alpha:.10f} 0 0")
        else:
            # (the products' rounding dust below a picometre written as 0)
            tail = tuple(
                0.0 if abs(v) < 1e-12 else v + 0.0
                for v in (a * math.cos(offset), a * math.sin(offset), d)
            )
            origin = (f"{tail[0]:.10g} {tail[1]:.10g} {d}", f"{alpha:.10f} 0 {offset:.10f}")
        lines.append(f'  <link name="{name}">\n{_segment(tail, radius, mass)}  </link>')
        parent = name
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
