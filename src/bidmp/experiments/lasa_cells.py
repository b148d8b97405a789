"""One cell of the LASA benchmark: a (shape, demonstration) pair, every method fitted on it and
rolled out to the demonstration's goal and to a near and a far shifted goal, the metrics of
each (see :mod:`bidmp.experiments.benchmark`), and the cell's file: written once, atomically,
with a digest of its content, and read back only when its protocol and digest match."""

from __future__ import annotations

import json
import logging
import os
import time
import zlib
from pathlib import Path

import numpy as np

from .._checks import check_int, short_token

__all__ = ["LASA_METHODS", "CASES", "METRICS", "run_cell", "cell_key"]

logger = logging.getLogger(__name__)

# The built-in methods the benchmark runs by default (registry.names(lasa=True) lists them, and any
# method registered with lasa = True after them).
LASA_METHODS = ("dmp-paper", "dmp-robot", "bidmp", "gmm", "tpgmm", "mp-dmp", "promp", "dmp-multi")


# goal shift as a fraction of the shape's extent
CASES = (
    ("reproduction", 0.0),
    ("near", 0.1),
    ("far", 0.6),
)


METRICS = ("rmse", "dtw", "dtw_per_sample", "swept_area", "frechet", "endpoint_error")


TIMES = ("fit_s", "rollout_s")


FORMAT = 3  # of the cell files (2: the robot protocol; 3: a content digest); another is recomputed


def cell_key(shape: str, demo: int) -> str:
    """The name of one benchmark cell (a LASA shape and a demonstration index), as in its file."""
    if not isinstance(shape, str) or not shape or len(shape) > 100:
        raise TypeError(f"shape must be a LASA shape's name, got {short_token(shape, 20)}")
    return f"{shape}__{check_int(demo, 'demo', minimum=0, maximum=10_000)}"


def _cell_seed(shape: str, demo: int) -> int:
    return zlib.crc32(cell_key(shape, demo).encode())


def _methods_available(methods) -> list[str]:
    """The methods whose optional package is installed (the others are skipped with a note)."""
    from ..tasks import methods as registry

    out = []
    for name in methods:
        method = registry.get(name)
        if not method.available():
            logger.info("%s is not installed: %s skipped", method.requires, name)
            continue
        out.append(name)
    return out


def _reference(demo: np.ndarray, offset: np.ndarray) -> np.ndarray:
    """The demonstration with the goal offset blended in over time (starts unchanged)."""
    blend = np.linspace(0.0, 1.0, demo.shape[0])[:, None]
    return demo + blend * offset


def _metrics(rollout: np.ndarray, reference: np.ndarray, goal: np.ndarray) -> dict:
    from .._trajectory import resample_time, rmse
    from ..extension.similarity import dtw_distance, frechet_distance
    from ..tasks.metrics import swept_area

    aligned = resample_time(rollout, reference.shape[0])
    dtw = dtw_distance(aligned, reference)
    return {
        "rmse": rmse(aligned, reference),
        "dtw": dtw,
        "dtw_per_sample": dtw / reference.shape[0],
        "swept_area": swept_area(aligned, reference),
        "frechet": frechet_distance(aligned, reference),
        "endpoint_error": float(np.linalg.norm(rollout[-1] - goal)),
    }


def _timed(function):
    start = time.perf_counter()
    value = function()
    return value, time.perf_counter() - start


def run_cell(
    shape: str, demo: int, methods=LASA_METHODS, every: int = 1, _kill_once: str | None = None
) -> dict:
    """All methods on one (shape, demonstration): ``{"key", "rows": [...], "rollouts": {...}}``.

    ``methods`` are names in the methods registry (:mod:`bidmp.tasks.methods`) or method objects
    (what a Dask worker is sent, so that a method registered in this process runs there too).

    ``rollouts`` keeps the reproductions (for the per-shape figure). ``_kill_once`` is for
    tests: if that file exists, it is removed and this worker process kills itself.
    """
    cell_key(shape, demo)  # the shape a name, the demonstration an index: checked before work
    every = check_int(every, "every", minimum=1, maximum=1000)
    if isinstance(methods, (str, bytes)) or not isinstance(methods, (list, tuple)):
        raise TypeError(
            f"methods must be a list of method names or objects, got {short_token(methods, 20)}"
        )
    if _kill_once is not None and os.path.exists(_kill_once):
        os.remove(_kill_once)
        os.kill(os.getpid(), 9)
    import sklearn.mixture  # noqa: F401  (its OpenMP pool loaded, so that the limit below holds it)

    from .._threads import one_thread

    # One BLAS/OpenMP thread, as in a Dask worker (whose nanny sets OMP_NUM_THREADS=1 and the
    # like): the serial path and the workers then give the same floats (2 threads summed in
    # another order, 1 ulp off), and small matrices gain nothing from threads anyway.
    with one_thread():
        return _run_cell(shape, demo, methods, every)


def _run_cell(shape: str, demo: int, methods, every: int) -> dict:
    from ..demonstrations.datasets import lasa as lasa_data
    from ..tasks import methods as registry
    from ..tasks.methods import Method, Task
    from ..tasks.metrics import path_extent

    shape_demos = lasa_data(shape)
    if demo >= len(shape_demos):
        raise ValueError(
            f"demo must be a demonstration of {shape} (0 to {len(shape_demos) - 1}), got {demo}"
        )
    y = shape_demos[demo][::every]
    # the shape's other demonstrations, for the methods that learn from several
    others = tuple(d[::every] for index, d in enumerate(shape_demos) if index != demo)
    seed = _cell_seed(shape, demo)
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0.0, 2.0 * np.pi)
    direction = np.array([np.cos(angle), np.sin(angle)])
    extent = path_extent(y)
    cases = [(name, y[-1] + fraction * extent * direction) for name, fraction in CASES]
    rows, rollouts = [], {}

    def record(method, case, goal, rollout, fit_s, rollout_s, end=None):
        reference = _reference(y, goal - y[-1])
        metrics = _metrics(rollout, reference, goal)
        if end is not None:  # where the motion comes to rest, after the time-aligned part
            metrics["endpoint_error"] = float(np.linalg.norm(end - goal))
        rows.append(
            {
                "shape": shape,
                "demo": demo,
                "method": method,
                "case": case,
                "seed": seed,
                "goal_x": float(goal[0]),
                "goal_y": float(goal[1]),
                **metrics,
                "fit_s": fit_s,
                "rollout_s": rollout_s,
            }
        )
        if case == "reproduction":
            rollouts[method] = np.asarray(rollout[:: max(1, len(rollout) // 200)]).round(4).tolist()

    # The task of the cell: the paper's DMP (the LASA literature's), a Bi-DMP grown to each goal.
    task = Task(
        y,
        np.array([goal for _, goal in cases]),
        seed=seed,
        dmp={"protocol": "paper"},
        demonstrations=others,
    )
    for name in methods:
        method = name if isinstance(name, Method) else registry.get(name)
        model, fit_s = method.fit(task)  # seconds to learn, shared models (the DMP) included
        for case, goal in cases:
            rollout, seconds = _timed(
                lambda goal=goal, method=method, model=model: method.rollout(model, goal)
            )
            if method.settles:
                # The first T samples are the motion's time (the robot protocol then rests at the
                # goal for 10 % longer): what is time-aligned with the demonstration.
                record(method.name, case, goal, rollout[: len(y)], fit_s, seconds, end=rollout[-1])
            else:
                record(method.name, case, goal, rollout, fit_s, seconds)
    return {"key": cell_key(shape, demo), "rows": rows, "rollouts": rollouts}


def _cell_path(out: Path, key: str) -> Path:
    return out / "cells" / f"{key}.json"


def _digest(result: dict) -> str:
    """A cell's content hash: what it computed, in canonical JSON (floats round-trip exactly)."""
    import hashlib

    content = json.dumps(
        {"rows": result["rows"], "rollouts": result.get("rollouts", {})}, sort_keys=True
    )
    return hashlib.sha256(content.encode()).hexdigest()


_ROW_KEYS = frozenset(
    ("shape", "demo", "method", "case", "seed", "goal_x", "goal_y", *METRICS, *TIMES)
)


def _cell_problem(data, shape: str, demo: int, protocol: dict) -> str | None:
    """Why a cell file cannot be resumed from (None: it can)."""
    if not isinstance(data, dict) or data.get("format") != FORMAT:
        return f"not a cell file of format {FORMAT}"
    if data.get("protocol") != protocol:
        return "computed with another protocol"
    if data.get("key") != cell_key(shape, demo):
        return f"holds cell {str(data.get('key'))[:40]!r}"
    rows = data.get("rows")
    if not isinstance(rows, list) or not rows or not isinstance(data.get("rollouts", {}), dict):
        return "has no rows"
    if data.get("digest") != _digest(data):
        return "was changed after it was written (its digest does not match)"
    expected = {(method, case) for method in protocol["methods"] for case, _ in CASES}
    seen = []
    for row in rows:
        if (
            not isinstance(row, dict)
            or set(row) != _ROW_KEYS
            or (row["shape"], row["demo"]) != (shape, demo)
        ):
            return "has a malformed row"
        seen.append((row["method"], row["case"]))
    if sorted(seen, key=str) != sorted(expected, key=str):
        return "does not hold one row per method and case"
    return None


def _load_cell(path: Path, protocol: dict, shape: str, demo: int) -> dict | None:
    """A finished cell file, if it holds this protocol's results for (shape, demo) unchanged; else
    None (it is recomputed), and a cell file that exists but is unusable is said so."""
    from ..io.strict_json import load_json

    if not path.exists():
        return None
    try:
        data = load_json(path.read_bytes(), str(path))
    except (OSError, ValueError) as exc:
        problem = f"is not readable JSON ({str(exc)[:80]})"
    else:
        problem = _cell_problem(data, shape, demo, protocol)
    if problem is None:
        return data
    logger.warning("LASA cell %s %s: recomputed", cell_key(shape, demo), problem)
    return None


def _write_cell(out: Path, protocol: dict, result: dict) -> None:
    from ..io.atomic import atomic_write

    path = _cell_path(out, result["key"])
    path.parent.mkdir(parents=True, exist_ok=True)
    with atomic_write(path, "w") as handle:
        json.dump(
            {"format": FORMAT, "protocol": protocol, **result, "digest": _digest(result)}, handle
        )
