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


def interleaved_times(functions: dict, rounds: int) -> dict:
    """Median wall time (s) of each of ``functions`` (name -> callable), the sides interleaved:
    every round calls each once in turn, so a noisy stretch of the machine hits them all alike.
    One untimed warm-up call each first."""
    for function in functions.values():
        function()
    samples = {name: [] for name in functions}
    for _ in range(rounds):
        for name, function in functions.items():
            start = time.perf_counter()
            function()
            samples[name].append(time.perf_counter() - start)
    return {name: statistics.median(values) for name, values in samples.items()}
