"""How fast the Bi-DMP motion to a far goal runs against the demonstration.

For each bundled recording (prepared, robot-protocol DMP) and a goal moved 200 mm sideways (x,
then y) and 300/150 mm: the extension (``approach="keep"``), the Bi-DMP skill learned from it
and its motion as the robot would run it (``trajectory``, seconds). Printed: the motion's peak
speed, acceleration and jerk over the plain DMP's motion to the demonstrated goal (central
differences), its duration, and the extension's largest distance from the straight transfer.

    .venv/bin/python tools/extension_pace.py

Runs on older trees too (``PYTHONPATH=<old tree>/src``): without ``duration_for`` the skill takes
the demonstration's time, as it did there.
"""

import numpy as np

import bidmp


def peaks(y: np.ndarray, dt: float) -> np.ndarray:
    out, derivative = [], y
    for _ in range(3):
        derivative = np.gradient(derivative, dt, axis=0)
        out.append(np.max(np.linalg.norm(derivative, axis=1)))
    return np.array(out)


def lateral(extension) -> float:
    """Largest distance of the transfer (seg -> the approach's start) from its chord, in mm."""
    path = extension.tra_gen
    a, b = path[0], path[-1]
    direction = (b - a) / np.linalg.norm(b - a)
    offsets = path - a
    return float(np.max(np.linalg.norm(offsets - np.outer(offsets @ direction, direction), axis=1)))


def main() -> None:
    from bidmp.demonstrations.datasets import recording

    print(
        "recording        shift [mm]        speed  accel  jerk   duration [s]  transfer off its chord [mm]"
    )
    for name in ("operator1_nut3", "operator2_nut5"):
        demo = bidmp.prepare(*recording(name))[0]
        dmp = bidmp.DMP().fit(demo.y, demo.t)
        reference = dmp.trajectory()
        base = peaks(reference.y, reference.t[1])
        for shift in ([200.0, 0.0, 0.0], [0.0, 200.0, 0.0], [300.0, 150.0, 0.0]):
            goal = dmp.goal_ + shift
            extension = bidmp.extend_demonstration(demo.y, goal, seed=0)
            options = (
                {"duration": extension.duration_for(dmp)}
                if hasattr(extension, "duration_for")
                else {}
            )
            motion = bidmp.BiDMP(dmp).learn(extension.complete, **options).trajectory(goal)
            ratio = peaks(motion.y, motion.t[1]) / base
            print(
                f"{name:16s} {str(shift):18s} {ratio[0]:5.2f}  {ratio[1]:5.2f}  {ratio[2]:5.2f}   "
                f"{motion.t[-1]:5.2f} (DMP {reference.t[-1]:.2f})   {lateral(extension):6.2f}"
            )


if __name__ == "__main__":
    main()
