"""bidmp-continual's capacity against the plain library of its start maps: what it keeps (a closed
form counted here), what it gives back (least squares computed here by NumPy's lstsq), the sweep
on a few tasks, and the committed sweep (make clfd-capacity) against the committed protocol (make
clfd), two runs that must agree."""

import json
from pathlib import Path

import numpy as np
import pytest

from bidmp.experiments.clfd import (
    CAPACITY_NODES,
    ContinualBLS,
    MapLibrary,
    capacity_sweep,
    clfd_tasks,
    write_capacity,
)

RESULTS = Path(__file__).resolve().parents[2] / "docs" / "results"


def _map_size(n_basis: int, dims: int) -> int:
    """A ProMP start map's numbers: μ (n_basis · D), K (n_basis · D × D), s̄ (D)."""
    return n_basis * dims + n_basis * dims * dims + dims


@pytest.fixture(scope="module")
def tasks():
    """The first five LASA tasks on every 10th sample (their maps are the same size: the basis
    does not depend on the samples)."""
    from bidmp.experiments.clfd import ClfdTask

    return [
        ClfdTask(t.name, t.positions[:, ::10], t.times[:, ::10]) for t in clfd_tasks("lasa")[:5]
    ]


@pytest.mark.parametrize("nodes", [1, 3, 5, 9])
def test_every_number_kept_is_counted(tasks, nodes):
    """R (nodes × capacity), b, W (nodes × a map), A (nodes × nodes), B (nodes × a map); the
    library: one map per task."""
    model, library = ContinualBLS(n_nodes=nodes, capacity=7, n_basis=12), MapLibrary(n_basis=12)
    for count, task in enumerate(tasks[:3], start=1):
        model.learn(task)
        library.learn(task)
        size = _map_size(12, 2)
        assert model.numbers_kept == {
            "projection": nodes * 7,
            "bias": nodes,
            "weights": nodes * size,
            "normal_equations": nodes * nodes + nodes * size,
        }
        assert model.n_parameters == nodes * 7 + nodes + nodes * size
        assert library.n_parameters == count * size


@pytest.mark.parametrize("nodes", [2, 3, 4, 5, 8])
def test_the_maps_it_gives_are_the_least_squares_fit_of_the_maps_taught(tasks, nodes):
    """Five tasks: with at least five nodes every map comes back (to 1e-6 of its norm: the
    ridge's share); with
    fewer, the maps given are NumPy's least-squares fit of the taught maps on the tasks' nodes
    (to 1e-6), and some are off by more than 1 %."""
    model = ContinualBLS(n_nodes=nodes, n_basis=12, seed=3)
    for task in tasks:
        model.learn(task)
    taught = np.array([model.task_target(task) for task in tasks])
    given = np.array([model.task_map(i) for i in range(len(tasks))])
    nodes_of = np.tanh(model._projection[:, : len(tasks)].T + model._bias)  # (tasks, nodes)
    fit = nodes_of @ np.linalg.lstsq(nodes_of, taught, rcond=None)[0]
    scale = np.linalg.norm(taught, axis=1, keepdims=True)
    off = np.linalg.norm(given - taught, axis=1) / scale[:, 0]
    if nodes >= len(tasks):
        assert off.max() <= 1e-6
    else:
        assert np.max(np.abs(given - fit) / scale) <= 1e-6
        assert off.max() > 0.01


def test_the_library_gives_back_the_maps_taught_and_reproduces_as_the_memory(tasks):
    library, memory = MapLibrary(n_basis=12), ContinualBLS(n_nodes=8, n_basis=12)
    for task in tasks:
        library.learn(task)
        memory.learn(task)
    for index, task in enumerate(tasks):
        np.testing.assert_array_equal(library.task_map(index), library.task_target(task))
        starts, t = task.poses[:, 0], task.times[0]
        extent = np.ptp(task.positions.reshape(-1, 2), axis=0).max()
        a, b = library.reproduce(index, starts, t), memory.reproduce(index, starts, t)
        assert np.max(np.abs(a - b)) <= 1e-6 * extent


def test_the_sweep_on_three_tasks(tmp_path):
    """Fewer nodes than tasks forget (BWT < 0, ACC below the library's); as many give the
    library's figures; the files are written and say the same."""
    result = capacity_sweep(nodes=(2, 3), seeds=(0,), n_tasks=3)
    library = result.library
    few, enough = result.by_nodes()[2][0], result.by_nodes()[3][0]
    assert library.kept == 3 * _map_size(100, 2) and library.bwt == 0.0
    assert enough.bwt == pytest.approx(0.0, abs=1e-12) and enough.acc == library.acc
    assert enough.mean_dtw == pytest.approx(library.mean_dtw, rel=1e-6)
    assert few.bwt < 0 and few.acc < library.acc and np.median(few.map_errors) > 0.01
    assert enough.kept == 3 * 26 + 3 + 2 * 3 * _map_size(100, 2) + 3 * 3
    written = write_capacity(result, tmp_path)
    assert [p.name for p in written] == [
        "clfd_capacity.json",
        "clfd_capacity.md",
        "clfd_capacity.png",
    ]
    saved = json.loads(written[0].read_text())
    assert [r["nodes"] for r in saved["rows"]] == [2, 3, None]
    assert f"| bidmp-continual | 2 | 1 | {few.acc:.3f} |" in written[1].read_text()
    assert written[2].stat().st_size > 10_000


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(nodes=5), "nodes"),
        (dict(nodes=(0,)), "nodes"),
        (dict(seeds=(1.5,)), "seeds"),
        (dict(nodes=(), seeds=(0,)), "nodes"),
        (dict(n_tasks=27), "n_tasks"),
        (dict(workers=0), "workers"),
    ],
)
def test_the_sweep_refuses_bad_options_by_name(kwargs, name):
    with pytest.raises((ValueError, TypeError), match=name):
        capacity_sweep(**kwargs)


def _committed(name: str):
    return json.loads((RESULTS / name).read_text())


def test_the_committed_sweep_is_the_committed_protocol():
    """make clfd-capacity's committed rows against make clfd's (another run): the 64-node row is
    bidmp-continual's row (ACC, BWT, mean DTW); the map library reproduces as the ProMP library
    (its ACC, its mean DTW to 1e-6); every row's numbers are the closed form; the maps come back
    with as many nodes as tasks and not with fewer, where the memory forgets."""
    sweep, protocol = _committed("clfd_capacity.json"), _committed("clfd.json")["methods"]
    tasks, size = len(sweep["tasks"]), _map_size(100, 2)
    assert tasks == 26 and sweep["map_size"] == size
    rows = sweep["rows"]
    assert sorted({r["nodes"] for r in rows if r["nodes"]}) == list(CAPACITY_NODES)
    default = next(r for r in rows if r["nodes"] == 64 and r["seed"] == 0)
    continual = protocol["bidmp-continual"]
    assert default["ACC"] == pytest.approx(continual["metrics"]["dtw"]["ACC"], abs=1e-12)
    assert default["BWT"] == pytest.approx(continual["metrics"]["dtw"]["BWT"], abs=1e-12)
    assert default["mean_dtw"] == pytest.approx(continual["mean_dtw_over_tasks_seen"][-1], rel=1e-9)
    library = next(r for r in rows if r["method"] == "map-library")
    promp = protocol["promp-library"]
    assert library["ACC"] == pytest.approx(promp["metrics"]["dtw"]["ACC"], abs=1e-12)
    assert library["mean_dtw"] == pytest.approx(promp["mean_dtw_over_tasks_seen"][-1], rel=1e-6)
    assert library["kept"] == tasks * size
    for row in rows:
        if row["method"] == "map-library":
            continue
        n = row["nodes"]
        assert row["numbers"] == {
            "projection": n * tasks,
            "bias": n,
            "weights": n * size,
            "normal_equations": n * n + n * size,
        }
        assert row["kept"] == n * tasks + n + 2 * n * size + n * n
        if n >= tasks:  # the ridge's share: 2.2e-6 at exactly as many nodes as tasks (square)
            assert row["map_error_max"] <= 1e-5 and row["BWT"] >= -1e-12
        else:
            assert row["map_error_median"] > 0.01 and row["BWT"] < 0
        if row["map_error_max"] <= 1e-5:  # a memory that gives every map back is larger than them
            assert row["reproduced_from"] > library["kept"]
