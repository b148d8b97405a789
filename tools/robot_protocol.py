"""Measure the robot protocol against its earlier form and movement_primitives; write the table.

    .venv/bin/python tools/robot_protocol.py [--out docs/results/robot.md]

Every number in the README's "Robot-ready motion" table comes from here (``make readme`` runs
it; ``tests/test_readme.py`` reruns it and compares). "bidmp 0.3" is the robot protocol of model
format 3, still available as ``DMP(integrator="euler", regression="lwr")`` (its files load
with it): a discrete-time progress gate two samples late, explicit Euler, LWR.
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

import bidmp
from bidmp.demonstrations import kinesthetic_recording, minimum_jerk

ROOT = Path(__file__).resolve().parent.parent
NUT_VIA = [[-80.0, -120.0, 200.0], [0.0, 0.0, 40.0], [0.0, 0.0, 0.0]]
SHIFT = np.array([150.0, 25.0, 0.0]) * 150.0 / np.hypot(150.0, 25.0)
VERSIONS = {"bidmp": {}, "bidmp 0.3": {"integrator": "euler", "regression": "lwr"}}


def at_speed(via, n_samples, speed, rate=250.0):
    demo = minimum_jerk(via, n_samples)
    t = np.arange(n_samples) / rate
    first = (
        int(np.argmax(np.linalg.norm(np.gradient(demo, t, axis=0), axis=1) >= speed))
        if speed > 0
        else 0
    )
    return demo[first:], t[first:] - t[first]


def start_peaks(t, ydd):
    early = t <= 0.05 + 1e-12
    return np.linalg.norm(ydd, axis=1)[early].max(), np.linalg.norm(
        np.gradient(ydd, t, axis=0), axis=1
    )[early].max()


def start_row(name, y, t):
    """Worst ratio of the first 50 ms' peak acceleration and jerk to the demonstration's own,
    over its goal and goals 150 mm away, at 250 Hz and 1 kHz."""
    demonstrated = start_peaks(t, np.gradient(np.gradient(y, t, axis=0), t, axis=0))
    cells = [name]
    for params in VERSIONS.values():
        dmp = bidmp.DMP(**params).fit(y, t)
        worst = np.zeros(2)
        for goal in (None, dmp.goal_ + SHIFT, dmp.goal_ - SHIFT, dmp.goal_ + [0.0, 0.0, 150.0]):
            for dt in (1 / 250, 1e-3):
                motion = dmp.trajectory(goal, dt=dt)
                worst = np.maximum(
                    worst, np.array(start_peaks(motion.t, motion.ydd)) / demonstrated
                )
        cells += [f"{worst[0]:.3g}", f"{worst[1]:.3g}"]
    return cells


def rate_row():
    """A 100 Hz recording at 1 kHz and 10 kHz against its own-rate rollout (% of the extent)."""
    y, t = kinesthetic_recording(NUT_VIA, seed=21, rate_hz=100.0, duration=3.0)
    prepared, _ = bidmp.prepare(y, t)
    extent = np.linalg.norm(np.ptp(prepared.y, axis=0))
    cells = []
    for params in VERSIONS.values():
        dmp = bidmp.DMP(**params).fit(prepared.y, prepared.t)
        native = dmp.trajectory()
        worst = 0.0
        for dt in (1e-3, 1e-4):
            fast = dmp.trajectory(dt=dt)
            resampled = np.column_stack(
                [np.interp(native.t, fast.t, column) for column in fast.y.T]
            )
            worst = max(worst, float(np.max(np.linalg.norm(resampled - native.y, axis=1))))
        cells.append(f"{100 * worst / extent:.3g} % ({worst:.3g} mm)")
    return cells


def movement_primitives_rate():
    try:
        from movement_primitives.dmp import DMP as PeerDMP
    except ImportError:
        return "not installed"
    y, t = kinesthetic_recording(NUT_VIA, seed=21, rate_hz=100.0, duration=3.0)
    prepared, _ = bidmp.prepare(y, t)
    extent = np.linalg.norm(np.ptp(prepared.y, axis=0))
    runs = {}
    for dt in (prepared.t[1], 1e-3):
        peer = PeerDMP(n_dims=3, execution_time=prepared.t[-1], dt=dt, n_weights_per_dim=100)
        peer.imitate(prepared.t, prepared.y)
        runs[dt] = peer.open_loop()
    (t0, y0), (t1, y1) = runs.values()
    resampled = np.column_stack([np.interp(t0, t1, column) for column in y1.T])
    worst = float(np.max(np.linalg.norm(resampled - y0, axis=1)))
    return f"{100 * worst / extent:.3g} % ({worst:.3g} mm)"


def near_goal_rows():
    """Overshoot past a goal 1 % and 10 % along a straight recording (mm), and how far the motion
    runs backwards, for bidmp, its 0.3 form, an exponentially delayed goal and movement_primitives."""
    y, t = kinesthetic_recording([[0, 0, 0], [100, 50, 20]], seed=13, duration=3.0)
    prepared, _ = bidmp.prepare(y, t)
    start, end = prepared.y[0], prepared.y[-1]
    length = float(np.linalg.norm(end - start))
    direction = (end - start) / length
    models = {
        name: bidmp.DMP(**params).fit(prepared.y, prepared.t) for name, params in VERSIONS.items()
    }
    models["delayed goal (goal_rate = 4/T)"] = bidmp.DMP(goal_rate=4.0).fit(prepared.y, prepared.t)
    rows = []
    for fraction in (0.01, 0.1):
        goal = start + fraction * (end - start)
        cells = [f"{fraction * length:.3g} mm"]
        for model in models.values():
            along = (model.trajectory(goal).y - start) @ direction
            cells.append(
                f"{max(along.max() - fraction * length, 0.0) + 0.0:.3g} / {max(-along.min(), 0.0) + 0.0:.3g}"
            )
        cells.append(_peer_near(prepared, goal, direction, fraction * length))
        rows.append(cells)
    return rows, length


def _peer_near(prepared, goal, direction, distance):
    try:
        from movement_primitives.dmp import DMP as PeerDMP
    except ImportError:
        return "not installed"
    peer = PeerDMP(
        n_dims=3,
        execution_time=prepared.t[-1],
        dt=prepared.t[1],
        n_weights_per_dim=100,
        smooth_scaling=True,
    )
    peer.imitate(prepared.t, prepared.y)
    peer.configure(start_y=prepared.y[0], goal_y=goal)
    along = (peer.open_loop()[1] - prepared.y[0]) @ direction
    return f"{max(along.max() - distance, 0.0) + 0.0:.3g} / {max(-along.min(), 0.0) + 0.0:.3g}"


def recording_rows():
    rows = []
    for name in ("operator1_nut3", "operator2_nut5"):
        prepared, _ = bidmp.prepare(*bidmp.demonstrations.recording(name))
        cells = [name]
        for params in VERSIONS.values():
            dmp = bidmp.DMP(**params).fit(prepared.y, prepared.t)
            rms = np.sqrt(
                np.mean(np.sum((dmp.rollout()[: dmp.n_steps_] - prepared.y) ** 2, axis=1))
            )
            moved = dmp.trajectory(dmp.goal_ + SHIFT)
            cells += [f"{rms:.3g}", f"{np.linalg.norm(moved.y[-1] - dmp.goal_ - SHIFT):.2g}"]
        rows.append(cells)
    return rows


def table(header, rows):
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    return "\n".join(lines + ["| " + " | ".join(row) + " |" for row in rows])


def markdown() -> str:
    starts = [
        start_row(
            name, *(lambda p: (p.y, p.t))(bidmp.prepare(*bidmp.demonstrations.recording(name))[0])
        )
        for name in ("operator1_nut3", "operator2_nut5")
    ]
    for speed in (0.0, 1.9, 5.0):
        for via, n in (
            (NUT_VIA, 2000),
            ([[0, 0, 0], [100, 50, 20]], 1000),
            ([[0, 0, 0], [0, 0, -60]], 600),
        ):
            starts.append(
                start_row(
                    f"minimum jerk, {n / 250:g} s, from {speed:g} mm/s", *at_speed(via, n, speed)
                )
            )
    near, length = near_goal_rows()
    ours, old = rate_row()
    parts = [
        "**The first 50 ms** (`tools/robot_protocol.py`): the largest ratio of the motion's peak acceleration and jerk "
        "over its first 50 ms to the demonstration's own over the same span, for the demonstrated goal and goals moved "
        "by 150 mm, at 250 Hz and 1 kHz.",
        "",
        table(
            [
                "demonstration",
                "bidmp: acceleration",
                "bidmp: jerk",
                "bidmp 0.3: acceleration",
                "bidmp 0.3: jerk",
            ],
            starts,
        ),
        "",
        f"**Any control rate.** A 100 Hz recording rolled out at 1 kHz and 10 kHz, the largest "
        f"distance to its own-rate "
        f"rollout: bidmp {ours}; bidmp 0.3 {old}; movement_primitives at 1 kHz {movement_primitives_rate()}.",
        "",
        f"**Nearer goals** on a straight {length:.3g} mm recording: overshoot past the goal / distance run backwards "
        f"from the start (mm).",
        "",
        table(
            [
                "goal",
                *VERSIONS,
                "delayed goal (goal_rate = 4/T)",
                "movement_primitives (smooth scaling)",
            ],
            near,
        ),
        "",
        "**The shared recordings**: reproduction RMSE (mm) and the distance to a goal moved by 150 mm at rest (mm).",
        "",
        table(
            [
                "recording",
                "bidmp: RMSE",
                "bidmp: moved goal",
                "bidmp 0.3: RMSE",
                "bidmp 0.3: moved goal",
            ],
            recording_rows(),
        ),
    ]
    return "\n".join(parts) + "\n"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(ROOT / "docs" / "results" / "robot.md"))
    args = parser.parse_args(argv)
    import logging

    logging.getLogger("bidmp").setLevel(
        logging.ERROR
    )  # the demonstrations that start at speed say so
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        text = markdown()
    Path(args.out).write_text(text, encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
