"""Timing helper shared by the benchmark scripts."""

import statistics
import time


def median_time(function, repeats: int) -> float:
    """Median wall time (s) of ``repeats`` calls, after one untimed warm-up call."""
    function()  # warm-up (imports, caches, JIT)
    samples = []
    for _ in range(repeats):
        start = time.perf_counter()
        function()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples)
