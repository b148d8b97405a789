"""How long the guarded paths take: the work the tests check for its answer, timed here (a test with a
clock fails on a loaded machine). A million-sample recording segmented, a million-sample noisy
minimum-jerk demonstration, and refusals that must come before the work (a BLS too large, a
rollout block of 14.9 GiB).

    .venv/bin/python benchmarks/bench_robustness.py [--repeats 3] [--smoke]

Prints the median of each (seconds) beside its target.
"""

from __future__ import annotations

import argparse

import numpy as np
from _timing import median_time

import bidmp


def refused(function) -> None:
    try:
        function()
    except ValueError:
        return
    raise AssertionError("expected a refusal")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--smoke", action="store_true", help="a tenth of the sizes, one run (CI)")
    args = parser.parse_args()
    repeats, n = (1, 100_000) if args.smoke else (args.repeats, 1_000_000)
    t = np.linspace(0.0, 1.0, n)
    y = np.column_stack([np.sin(6.0 * t), np.cos(4.0 * t), t]) * 100.0
    dmp = bidmp.DMP(protocol="paper").fit(
        bidmp.demonstrations.minimum_jerk([[0, 0], [50, 20], [100, 0]], 1000)
    )
    cases = [
        (f"segment {n:,} samples", lambda: bidmp.segment(y), 5.0),
        (
            f"minimum_jerk {n:,} samples, noisy",
            lambda: bidmp.demonstrations.minimum_jerk([[0, 0, 0], [100, 50, 20]], n, noise=1.0),
            5.0,
        ),
        (
            "BLS too large: refused",
            lambda: refused(
                lambda: bidmp.BLS(n_enhance=2500).fit(np.zeros((20_000, 3)), np.zeros(20_000))
            ),
            2.0,
        ),
        (
            "rollout block of 14.9 GiB: refused",
            lambda: refused(lambda: dmp.rollout_many(np.zeros((1_000_000, 2)))),
            2.0,
        ),
    ]
    print(f"{'case':40s} {'median s':>9s} {'target s':>9s}")
    for name, function, target in cases:
        seconds = median_time(function, repeats)
        print(f"{name:40s} {seconds:9.3f} {target:9.1f}{'' if seconds <= target else '  OVER'}")


if __name__ == "__main__":
    main()
