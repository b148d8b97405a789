"""Shared fixtures: smooth demonstrations that start and end at rest, and a fresh interpreter's
imports."""

import ast
import subprocess
import sys

import numpy as np
import pytest


def minimum_jerk(start, end, n_steps):
    """Minimum-jerk straight line from start to end (rest to rest), shape (n_steps, D)."""
    s = np.linspace(0.0, 1.0, n_steps)[:, None]
    blend = 10 * s**3 - 15 * s**4 + 6 * s**5
    return np.asarray(start, float) + blend * (np.asarray(end, float) - np.asarray(start, float))


def curved_demo(n_steps=300, n_dims=3, seed=0):
    """A curved rest-to-rest demonstration: a minimum-jerk line plus a smooth bump per axis."""
    rng = np.random.default_rng(seed)
    start = rng.uniform(-1, 1, n_dims)
    end = rng.uniform(-1, 1, n_dims)
    line = minimum_jerk(start, end, n_steps)
    s = np.linspace(0.0, 1.0, n_steps)[:, None]
    bump = np.sin(np.pi * s) ** 4 * np.sin(2 * np.pi * s * rng.uniform(0.5, 1.5, n_dims))
    return line + 0.4 * bump


@pytest.fixture
def demo3d():
    return curved_demo(300, 3)


@pytest.fixture
def demo2d():
    return curved_demo(400, 2, seed=1)


def _loaded_after(code: str, modules: tuple[str, ...]) -> list[str]:
    """Which of ``modules`` a new interpreter has imported after running ``code`` (sorted)."""
    script = f"{code}\nimport sys\nprint(sorted(m for m in {modules!r} if m in sys.modules))"
    result = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    )
    return ast.literal_eval(result.stdout.strip().splitlines()[-1])


@pytest.fixture
def loaded_after():
    """``loaded_after(code, modules)``: the modules of ``modules`` that ``code`` imports when run
    in a new interpreter (what a command's start-up pays for)."""
    return _loaded_after


class _Peak:
    """The peak memory (MB, tracemalloc: NumPy reports its buffers) allocated inside a block."""

    megabytes = 0.0

    def __enter__(self):
        import tracemalloc

        tracemalloc.start()
        return self

    def __exit__(self, *exc):
        import tracemalloc

        _, peak = tracemalloc.get_traced_memory()
        tracemalloc.stop()
        self.megabytes = peak / 2**20
        return False


@pytest.fixture
def peak_memory():
    """``with peak_memory() as peak: ...; peak.megabytes``: what a block allocated at most. Shows
    that a refusal came before the work (the work would allocate far more), without a clock."""
    return _Peak
