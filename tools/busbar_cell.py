"""Write the user's kind of cell of the route acceptance (tests/data/irb1200/busbar.json): an ABB
IRB 1200 known only from its URDF (tests/data/irb1200/irb1200.urdf, written by tools/ur5_urdf.py
from ABB's published table), in metres, with no rest pose; 2 x 3 M8 nuts (columns A and B, rows 1
to 3) on a busbar plate tilted 25 degrees toward the arm, a post between the columns, a flat
demonstrated nut D beside it, and the bin where a tool pointing down puts the arm's wrist at its
singularity (joint 5 within 1.2 degrees of zero): the drop there is reached by tilting the tool.

    .venv/bin/python tools/busbar_cell.py [--out FILE]
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path

import numpy as np
from scipy.spatial.transform import Rotation

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "tests" / "data" / "irb1200" / "busbar.json"
TILT = 25.0  # degrees, about x: the plate's nuts lean toward the arm
PLATE_TOP = np.array([0.16, 0.10, 0.04])  # m: the busbar plate's top face, at its centre
PITCH = (0.05, 0.05)  # m between the columns and between the rows
SINK = 0.002  # m: the socket's mouth above a nut's base when it has engaged
# (deg, deg/s): ABB's axis ranges and speeds of the IRB 1200-7/0.7
LOWER = (-170, -100, -200, -270, -130, -400)
UPPER = (170, 135, 70, 270, 130, 400)
SPEEDS = (288, 240, 297, 400, 405, 600)
BIN = (
    0.30,
    -0.25,
    0.0,
)  # m: the bin's floor centre, where the wrist is singular for a tool pointing down


def cell() -> dict:
    down = Rotation.from_euler("x", 180.0, degrees=True)
    tilt = Rotation.from_euler("x", TILT, degrees=True)
    nut = {"across_flats": 0.013, "height": 0.0065, "stud": {"radius": 0.004, "above": 0.010}}
    targets = {"D": [0.0, 0.0, 0.0, *down.as_quat().tolist()]}
    parts = [
        {"type": "plate", "label": "pad", "at": [0.0, 0.0, -SINK], "size": [0.08, 0.08, 0.005]},
        {
            "type": "box",
            "label": "busbar",
            "at": (PLATE_TOP - tilt.apply([0.0, 0.0, 0.005])).round(9).tolist(),
            "size": [0.10, 0.16, 0.005],
            "rotation": [TILT, 0.0, 0.0],
        },
        {"type": "nut", "label": "D", "at": [0.0, 0.0, -SINK], **nut},
    ]
    for column, x in zip("AB", (-PITCH[0] / 2, PITCH[0] / 2)):
        for row, y in zip("123", (-PITCH[1], 0.0, PITCH[1])):
            seat = PLATE_TOP + tilt.apply([x, y, 0.0])
            mouth = seat + tilt.apply([0.0, 0.0, SINK])
            label = f"{column}{row}"
            targets[label] = [*mouth.round(9).tolist(), *(tilt * down).as_quat().round(12).tolist()]
            parts.append(
                {
                    "type": "nut",
                    "label": label,
                    "at": seat.round(9).tolist(),
                    "rotation": [TILT, 0.0, 0.0],
                    **nut,
                }
            )
    # a vertical post between the columns, on a boss that clears the tilted face
    foot = PLATE_TOP + [0.0, 0.0, 0.006 * math.tan(math.radians(TILT)) + 1e-4]
    parts.append(
        {
            "type": "cylinder",
            "label": "busbar_post",
            "at": foot.round(9).tolist(),
            "radius": 0.006,
            "height": 0.07,
        }
    )
    deg = math.pi / 180.0
    limits = {
        "lower": [v * deg for v in LOWER],
        "upper": [v * deg for v in UPPER],
        "velocity": [v * deg for v in SPEEDS],
        "acceleration": [5 * v * deg for v in SPEEDS],  # not published: 5x the speed per second
        "jerk": [500 * v * deg for v in SPEEDS],  # not published: 500x
    }
    hover = [0.0, 0.0, 0.04, *down.as_quat().tolist()]
    return {
        "name": "busbar-irb1200",
        "description": (
            "A user's kind of cell: an ABB IRB 1200 from its URDF (metres, no rest pose), 2 x 3 nuts on "
            "a busbar plate tilted 25 degrees with a post between the columns, a flat demonstrated "
            "nut, the bin where the wrist is singular for a tool pointing down."
        ),
        "units": "m",
        "targets": targets,
        "demonstrated": "D",
        "demonstration": {
            "minimum_jerk": {
                "via": [[-0.08, -0.12, 0.20, *down.as_quat().tolist()], hover, targets["D"]],
                "n_steps": 200,
            }
        },
        "success_threshold": 0.00175,
        "approach_height": 0.0285,
        "robot": {"urdf": "irb1200.urdf", "flange": "flange", "limits": limits},
        "scene": {
            "tool": {"radius": 0.0125, "length": 0.10},
            "margin": 0.003,
            "standoff": {"pad": 0.001, "busbar": 0.001},
            "parts": parts,
        },
        "job": {
            "steps": ["approach", "engage", "unscrew", "retract", "drop"],
            "order": "shortest",
            "bin": {"at": list(BIN), "size": [0.07, 0.07, 0.04]},
            "pitch": 0.00125,
            "spindle_speed": 10,
        },
        "methods": ["dmp", "bidmp"],
        "seed": 0,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(OUT), help=f"the scenario file (default {OUT})")
    args = parser.parse_args()
    Path(args.out).write_text(json.dumps(cell(), indent=1) + "\n")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
