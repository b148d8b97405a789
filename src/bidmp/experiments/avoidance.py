"""Random avoidance cases: a demonstration and a field of parts across it, the same for
the tests (tests/primitives/test_avoidance.py), the benchmark against movement_primitives
(benchmarks/bench_avoidance.py) and anyone who wants to try a coupling term on cells nobody tuned.

Layer 3: a demonstration (``bidmp.demonstrations``) beside a field (``bidmp.scene.random_field``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._checks import check_int
from ..demonstrations.datasets import minimum_jerk
from ..scene.clearance import Scene
from ..scene.fields import random_field

__all__ = ["AvoidanceCase", "random_case"]


class AvoidanceCase(NamedTuple):
    """One drawn case: ``demonstration`` (n, 3) and its times ``t`` (n,) s, the ``scene`` of parts
    across it, and the length ``unit`` (1.0: millimetres, 1e-3: metres)."""

    demonstration: np.ndarray
    t: np.ndarray
    scene: Scene
    unit: float


def random_case(seed: int) -> AvoidanceCase:
    """A random minimum-jerk demonstration (200-400 mm from start to goal with a bend, 150-600
    samples over 2-5 s, in mm or m) and a random field across it (tool radius 6-14 mm, margin
    1-5 mm): the same case for the same ``seed``."""
    rng = np.random.default_rng(check_int(seed, "seed", minimum=0))
    unit = float(rng.choice([1.0, 1e-3]))
    start = rng.uniform(-100, 100, 3) + [0, 0, 80]
    heading, reach = rng.uniform(0, 2 * np.pi), rng.uniform(200, 400)
    goal = start + np.array(
        [np.cos(heading) * reach, np.sin(heading) * reach, rng.uniform(-30, 30)]
    )
    middle = (start + goal) / 2 + np.append(rng.uniform(-20, 20, 2), rng.uniform(0, 40))
    n, duration = int(rng.integers(150, 600)), float(rng.uniform(2, 5))
    demonstration = minimum_jerk(np.array([start, middle, goal]) * unit, n)
    tool = {"radius": rng.uniform(6, 14) * unit, "length": 100 * unit}
    scene = random_field(
        rng, demonstration[0], demonstration[-1], tool, margin=rng.uniform(1, 5) * unit
    )
    return AvoidanceCase(demonstration, np.linspace(0, duration, n), scene, unit)
