"""DMP speed: bidmp against movement_primitives and pydmps, timed in one run (ratios, not seconds).

    make bench            # or: .venv/bin/python benchmarks/bench_dmp.py [--repeats N]

1. fit + rollout, T = 1000 samples, D = 2 and 3, 50 kernels per dimension:
   bidmp; movement_primitives with its fastest step function (Cython Euler and RK4 are both
   timed, the faster one counts); pydmps.
2. rollout_many to 10 000 goals (T = 1000, D = 3) against a Python loop of ``rollout``.

Targets (issue #2): bidmp fit + rollout >= 20x faster than movement_primitives' fastest rollout
alone; 10 000 goals in <= 0.5 s.
"""

from __future__ import annotations

import argparse
import sys
import warnings

import numpy as np
from _timing import interleaved_times, median_time

from bidmp import DMP

N_STEPS = 1000
N_KERNELS = 50


def demonstration(n_dims: int) -> np.ndarray:
    s = np.linspace(0.0, 1.0, N_STEPS)[:, None]
    blend = 10 * s**3 - 15 * s**4 + 6 * s**5
    start = np.array([-80.0, -120.0, 200.0])[:n_dims]
    end = np.array([0.0, 0.0, 0.0])[:n_dims]
    bump = 30.0 * np.sin(np.pi * s) ** 2 * np.sin(3 * np.pi * s + np.arange(n_dims))
    return start + blend * (end - start) + bump


def bench_fit_rollout(n_dims: int, repeats: int) -> dict:
    y = demonstration(n_dims)
    times = np.arange(N_STEPS) / N_STEPS
    results = {}
    results["bidmp fit+rollout"] = median_time(
        lambda: DMP(protocol="paper", n_kernels=N_KERNELS).fit(y).rollout(), repeats
    )

    try:
        from movement_primitives.dmp import DMP as MPDMP
    except ImportError:  # pragma: no cover - optional peer
        print("movement_primitives not installed: skipped", file=sys.stderr)
    else:

        def mp_fit():
            dmp = MPDMP(
                n_dims=n_dims, execution_time=times[-1], dt=1 / N_STEPS, n_weights_per_dim=N_KERNELS
            )
            dmp.imitate(times, y)
            dmp.configure(start_y=y[0], goal_y=y[-1])
            return dmp

        fitted = mp_fit()
        best_name, best_rollout = None, np.inf
        for step in ("euler-cython", "rk4-cython"):
            elapsed = median_time(lambda step=step: fitted.open_loop(step_function=step), repeats)
            if elapsed < best_rollout:
                best_name, best_rollout = step, elapsed
        results[f"movement_primitives rollout ({best_name})"] = best_rollout
        results["movement_primitives fit+rollout"] = median_time(
            lambda: mp_fit().open_loop(step_function=best_name), repeats
        )

    try:
        from pydmps.dmp_discrete import DMPs_discrete
    except ImportError:  # pragma: no cover - optional peer
        print("pydmps not installed: skipped", file=sys.stderr)
    else:

        def pydmps_fit_rollout():
            dmp = DMPs_discrete(n_dmps=n_dims, n_bfs=N_KERNELS, dt=1 / N_STEPS)
            dmp.imitate_path(y_des=y.T)
            return dmp.rollout()

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            results["pydmps fit+rollout"] = median_time(pydmps_fit_rollout, max(3, repeats // 5))
    return results


def bench_robot_protocol(rounds: int) -> dict:
    """The defaults a user meets: ``DMP().fit(y, t).trajectory()`` (the robot protocol: 100
    kernels, the exact integrator, the progress gate, rest at both ends, positions, velocities
    and accelerations in seconds) beside movement_primitives' fit + open-loop rollout with each
    Cython step function, T = 1000, D = 3, the sides interleaved."""
    y = demonstration(3)
    t = np.arange(N_STEPS) / N_STEPS
    sides = {"bidmp DMP().fit(y, t).trajectory()": lambda: DMP().fit(y, t).trajectory()}
    try:
        from movement_primitives.dmp import DMP as MPDMP
    except ImportError:  # pragma: no cover - optional peer
        print("movement_primitives not installed: skipped", file=sys.stderr)
    else:
        for step in ("euler-cython", "rk4-cython"):

            def peer(step=step):
                dmp = MPDMP(n_dims=3, execution_time=t[-1], dt=1 / N_STEPS, n_weights_per_dim=100)
                dmp.imitate(t, y)
                dmp.configure(start_y=y[0], goal_y=y[-1])
                return dmp.open_loop(step_function=step)

            sides[f"movement_primitives fit+open_loop ({step})"] = peer
    return interleaved_times(sides, rounds)


def bench_many_goals(n_goals: int, repeats: int) -> dict:
    y = demonstration(3)
    dmp = DMP(protocol="paper", n_kernels=N_KERNELS).fit(y)
    goals = y[-1] + np.random.default_rng(0).uniform(-200, 200, size=(n_goals, 3))
    many = median_time(lambda: dmp.rollout_many(goals), repeats)
    loop = median_time(lambda: [dmp.rollout(goal) for goal in goals], 1)
    # Same numbers both ways (checked here on a sample so the benchmark also guards correctness).
    sample = goals[:: max(1, n_goals // 50)]
    difference = np.abs(dmp.rollout_many(sample) - np.stack([dmp.rollout(g) for g in sample])).max()
    return {"rollout_many": many, "loop of rollout": loop, "max difference": difference}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--repeats", type=int, default=61, help="timed repetitions per measurement (median)"
    )
    parser.add_argument(
        "--goals", type=int, default=10_000, help="number of goals for rollout_many"
    )
    args = parser.parse_args()

    print(
        f"fit + rollout, T = {N_STEPS}, {N_KERNELS} kernels per dimension (median of {args.repeats})"
    )
    for n_dims in (2, 3):
        results = bench_fit_rollout(n_dims, args.repeats)
        ours = results["bidmp fit+rollout"]
        print(f"\n  D = {n_dims}")
        for name, seconds in results.items():
            ratio = (
                ""
                if name.startswith("bidmp")
                else f"   bidmp fit+rollout is {seconds / ours:7.1f}x faster"
            )
            print(f"    {name:48s} {seconds * 1e3:9.3f} ms{ratio}")

    results = bench_robot_protocol(args.repeats)
    ours = results["bidmp DMP().fit(y, t).trajectory()"]
    print(
        f"\nthe robot protocol (defaults), T = {N_STEPS}, D = 3, interleaved ({args.repeats} rounds)"
    )
    for name, seconds in results.items():
        ratio = "" if name.startswith("bidmp") else f"   bidmp is {seconds / ours:7.1f}x faster"
        print(f"    {name:48s} {seconds * 1e3:9.3f} ms{ratio}")

    results = bench_many_goals(args.goals, max(3, args.repeats // 4))
    print(f"\nrollouts to {args.goals} goals, T = {N_STEPS}, D = 3")
    print(f"    {'rollout_many':48s} {results['rollout_many']:9.3f} s   (target <= 0.5 s)")
    print(
        f"    {'loop of rollout':48s} {results['loop of rollout']:9.3f} s   "
        f"rollout_many is {results['loop of rollout'] / results['rollout_many']:.1f}x faster"
    )
    print(f"    max |rollout_many - rollout| on a sample: {results['max difference']:.2e}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
