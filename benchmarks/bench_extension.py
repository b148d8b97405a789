"""Extended-demonstration speed: Fréchet against similaritymeasures and frechetdist, G-PRM, and
the whole extend_demonstration chain, timed in one run (ratios, not seconds).

    make bench            # runs every script in benchmarks/
    .venv/bin/python benchmarks/bench_extension.py [--repeats N]

Targets (issue #3): Fréchet >= 100x faster than similaritymeasures at 1000 x 1000 (JIT compile
excluded and reported separately); extend_demonstration with defaults <= 50 ms on a 200-point
3-D demonstration.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile

import numpy as np
from _timing import median_time

from bidmp import extend_demonstration, frechet_distance
from bidmp.demonstrations import minimum_jerk
from bidmp.experiments import BATTERY_APPROACH_VIA, BATTERY_EXTENSION_TARGET
from bidmp.extension import classic_prm, frechet_distance_reference, gaussian_prm


def jit_compile_seconds() -> float:
    """Import + first call in a fresh process with an empty numba cache (compile from scratch)."""
    code = (
        "import time, numpy as np; t = time.perf_counter(); from bidmp import frechet_distance; "
        "frechet_distance(np.zeros((3, 2)), np.ones((4, 2))); print(time.perf_counter() - t)"
    )
    with tempfile.TemporaryDirectory() as cache:
        env = {**os.environ, "NUMBA_CACHE_DIR": cache}
        cold = float(
            subprocess.run(
                [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
            ).stdout
        )
        warm = float(
            subprocess.run(
                [sys.executable, "-c", code], env=env, capture_output=True, text=True, check=True
            ).stdout
        )
    return cold, warm


def bench_frechet(size: int, repeats: int) -> None:
    rng = np.random.default_rng(size)
    a = rng.normal(size=(size, 3)).cumsum(axis=0)
    b = rng.normal(size=(size + size // 7, 3)).cumsum(axis=0)
    ours = median_time(lambda: frechet_distance(a, b), repeats)
    print(f"\n  Fréchet {size} x {size + size // 7}, D = 3 (median of {repeats})")
    print(f"    {'bidmp (numba kernel)':40s} {ours * 1e3:10.3f} ms")
    peers = {"bidmp NumPy reference": lambda: frechet_distance_reference(a, b)}
    try:
        import similaritymeasures

        peers["similaritymeasures.frechet_dist"] = lambda: similaritymeasures.frechet_dist(a, b)
    except ImportError:  # pragma: no cover
        print("    similaritymeasures not installed: skipped")
    try:
        from frechetdist import frdist

        peers["frechetdist.frdist (equal lengths)"] = lambda: frdist(a[:size], b[:size])
    except ImportError:  # pragma: no cover
        print("    frechetdist not installed: skipped")
    for name, function in peers.items():
        try:
            seconds = median_time(function, max(1, repeats // 10))
        except RecursionError:
            print(f"    {name:40s}     fails (RecursionError)")
            continue
        print(f"    {name:40s} {seconds * 1e3:10.3f} ms   bidmp is {seconds / ours:8.1f}x faster")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=21)
    args = parser.parse_args()

    cold, warm = jit_compile_seconds()
    print(
        f"numba Fréchet kernel: first call in a fresh environment {cold:.2f} s (compile), "
        f"from the on-disk cache {warm:.2f} s (import + load)"
    )
    for size in (200, 1000):
        bench_frechet(size, args.repeats)

    demo = minimum_jerk(BATTERY_APPROACH_VIA, 200)
    target = np.array(BATTERY_EXTENSION_TARGET)
    result = extend_demonstration(demo, target, seed=0)
    piece = result.tra_imi
    print(
        f"\n  battery approach path: 200 samples, 3-D, extension to {BATTERY_EXTENSION_TARGET} "
        f"(median of {args.repeats})"
    )
    rows = {
        "G-PRM, 10 iterations, 300 samples": lambda: gaussian_prm(piece, target, seed=1),
        "classic PRM, 10 iterations, 300 samples": lambda: classic_prm(piece, target, seed=1),
        "extend_demonstration (defaults)": lambda: extend_demonstration(demo, target, seed=1),
    }
    for name, function in rows.items():
        print(f"    {name:40s} {median_time(function, args.repeats) * 1e3:10.2f} ms")
    print("    target: extend_demonstration <= 50 ms")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
