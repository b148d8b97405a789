"""Robot-ready motion: costs measured against each other and against movement_primitives in one run.

    make bench            # or: .venv/bin/python benchmarks/bench_timing.py [--repeats N]

On a shared kinesthetic recording (operator1_nut3.csv: 8.2 s at ~250 Hz with idle ends and noise):

1. ``bidmp.prepare`` + ``DMP.fit`` (robot protocol), target <= 20 ms;
2. ``DMP.trajectory()`` (positions, velocities, accelerations, 1.1x the duration) against
   ``DMP.rollout()`` on the same grid, target ratio <= 1.5;
3. movement_primitives' DMP on the same prepared recording: fit + open loop (its fastest step
   function) to the same new goal, with the end-point error of both.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings

import numpy as np
from _timing import interleaved_times, median_time

import bidmp
from bidmp.io import read_trajectory

RECORDING = bidmp.demonstrations.recording_path("operator1_nut3")
SHIFT = np.array([150.0, 25.0, 0.0]) * 150.0 / np.hypot(150.0, 25.0)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=41)
    args = parser.parse_args(argv)
    y, t = read_trajectory(RECORDING)
    prepared, _ = bidmp.prepare(y, t)
    dmp = bidmp.DMP().fit(prepared.y, prepared.t)
    goal = dmp.goal_ + SHIFT
    print(
        f"recording {os.path.basename(RECORDING)}: {y.shape[0]} samples over {t[-1] - t[0]:.2f} s; "
        f"prepared: {prepared.y.shape[0]} samples over {prepared.duration:.2f} s"
    )

    prepare_fit = median_time(lambda: bidmp.DMP().fit(*_prepared(y, t)), args.repeats)
    print(f"  prepare + fit                       {1e3 * prepare_fit:8.3f} ms   (target <= 20 ms)")
    rollout = median_time(lambda: dmp.rollout(goal), args.repeats * 5)
    trajectory = median_time(lambda: dmp.trajectory(goal), args.repeats * 5)
    print(f"  rollout()                           {1e3 * rollout:8.3f} ms")
    print(
        f"  trajectory() with derivatives       {1e3 * trajectory:8.3f} ms   ratio "
        f"{trajectory / rollout:.2f} (target <= 1.5)"
    )
    ours = dmp.trajectory(goal)
    print(
        f"  bidmp: end-point error {np.linalg.norm(ours.y[-1] - goal):.4f} mm after {ours.duration:.2f} s, "
        f"initial acceleration change from the demonstrated goal "
        f"{np.linalg.norm(ours.ydd[0] - dmp.trajectory().ydd[0]):.2e} mm/s^2"
    )

    try:
        from movement_primitives.dmp import DMP as MPDMP
    except ImportError:
        print("  movement_primitives is not installed: pip install movement-primitives")
        return 0
    stamps = prepared.t

    def theirs(step_function):
        mp = MPDMP(
            n_dims=3,
            execution_time=stamps[-1],
            dt=stamps[1] - stamps[0],
            n_weights_per_dim=bidmp.DMP().n_kernels_value,
        )
        mp.imitate(stamps, prepared.y)
        mp.configure(start_y=prepared.y[0], goal_y=goal)
        return mp.open_loop(step_function=step_function)

    best = None
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for step_function in ("euler-cython", "rk4-cython", "euler"):
            try:
                seconds = median_time(lambda: theirs(step_function), max(args.repeats // 4, 5))
            except Exception:  # noqa: BLE001 - a step function this build lacks
                continue
            if best is None or seconds < best[1]:
                best = (step_function, seconds)
    _, positions = theirs(best[0])
    # The three sides interleaved round by round: the defaults a user meets (robot protocol, a
    # timed trajectory with its derivatives), the paper's protocol (normalised time, positions),
    # and the peer's fit + open loop with its fastest step function.
    sides = {
        "bidmp defaults: fit + trajectory": lambda: (
            bidmp.DMP().fit(prepared.y, prepared.t).trajectory(goal)
        ),
        "bidmp paper protocol: fit + rollout": lambda: (
            bidmp.DMP(protocol="paper").fit(prepared.y).rollout(goal)
        ),
        f"movement_primitives fit + open loop ({best[0]})": lambda: theirs(best[0]),
    }
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        times = interleaved_times(sides, args.repeats)
    peer = times[f"movement_primitives fit + open loop ({best[0]})"]
    for name, seconds in times.items():
        ratio = "" if seconds == peer else f"   movement_primitives / this {peer / seconds:5.1f}x"
        print(f"  {name:45s} {1e3 * seconds:8.3f} ms{ratio}")
    print(
        f"  movement_primitives: end-point error {np.linalg.norm(positions[-1] - goal):.4f} mm "
        f"after {prepared.t[-1]:.2f} s"
    )
    return 0


def _prepared(y, t):
    prepared, _ = bidmp.prepare(y, t)
    return prepared.y, prepared.t


if __name__ == "__main__":
    sys.exit(main())
