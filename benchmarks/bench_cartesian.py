"""Pose DMPs: bidmp's CartesianDMP vs movement_primitives' CartesianDMP, timed in one run (issue #13).

    make bench            # runs every script in benchmarks/
    .venv/bin/python benchmarks/bench_cartesian.py [--repeats N]

Both learn the same pose demonstration (T = 1000 samples over 2 s, 50 weights per dimension)
and generate the reproduction: bidmp fit + trajectory() (positions, quaternions, velocities,
angular velocities and accelerations) against movement_primitives' imitate + open_loop with its
fastest step functions (Cython Euler for positions, Cython quaternion steps), integrated at
the demonstration's own step. Target: ratio >= 10x. The reproductions' orientation error to
the demonstration is printed beside the times.
"""

from __future__ import annotations

import argparse

import numpy as np
from _timing import median_time
from scipy.spatial.transform import Rotation

from bidmp.demonstrations import minimum_jerk
from bidmp.primitives import DMP, CartesianDMP, angle_between


def demonstration(n_steps: int = 1000):
    positions = minimum_jerk([[0.0, 0.0, 0.0], [0.1, 0.05, 0.08], [0.2, 0.0, 0.0]], n_steps=n_steps)
    s = np.linspace(0.0, 1.0, n_steps)
    s = 10 * s**3 - 15 * s**4 + 6 * s**5
    rotations = Rotation.from_rotvec(np.outer(s, [0.3, -0.8, 1.2])) * Rotation.from_euler(
        "x", 180, degrees=True
    )
    return np.linspace(0.0, 2.0, n_steps), np.hstack([positions, rotations.as_quat()])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=21)
    args = parser.parse_args()
    from movement_primitives.dmp import CartesianDMP as PeerCartesianDMP

    t, poses = demonstration()
    dt = t[1] - t[0]
    scalar_first = np.hstack([poses[:, :3], poses[:, [6, 3, 4, 5]]])

    def ours():
        return (
            CartesianDMP(DMP(alpha=25.0, beta=6.25, n_kernels=50)).fit(poses, t).trajectory(dt=dt)
        )

    def peer():
        dmp = PeerCartesianDMP(execution_time=2.0, dt=dt, n_weights_per_dim=50, int_dt=dt)
        dmp.imitate(t, scalar_first)
        dmp.configure(start_y=scalar_first[0], goal_y=scalar_first[-1])
        return dmp.open_loop(step_function="euler-cython", quaternion_step_function="cython")[1]

    ours_s = median_time(ours, args.repeats)
    peer_s = median_time(peer, args.repeats)
    mine, theirs = ours(), peer()
    n = min(len(poses), len(mine.t))
    ours_error = np.degrees(angle_between(mine.q[:n], poses[:n, 3:]).max())
    peer_error = np.degrees(
        angle_between(theirs[: len(poses), [4, 5, 6, 3]], poses[: len(theirs), 3:]).max()
    )
    print(f"pose DMP, T = {len(poses)}, 50 weights per dimension (median of {args.repeats} runs)")
    print(
        f"  bidmp CartesianDMP fit + trajectory:            {ours_s * 1e3:7.2f} ms   (max "
        f"orientation error {ours_error:.3f} deg)"
    )
    print(
        f"  movement_primitives imitate + open_loop (cython): {peer_s * 1e3:7.2f} ms   (max "
        f"orientation error {peer_error:.3f} deg)"
    )
    print(f"  ratio: {peer_s / ours_s:.1f}x   (target >= 10x)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
