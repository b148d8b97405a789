"""The LASA benchmark: metrics against independent references, Dask runs that agree
with the serial one, survive a killed worker and resume, and bad input that fails fast."""

import functools
import json
import pathlib
import sys

import numpy as np
import pytest

from bidmp.cli import main
from bidmp.experiments import benchmark, lasa_cells
from bidmp.extension import dtw_distance
from bidmp.tasks import swept_area

# Only what runs on Dask or writes Parquet needs the benchmark extra; the metrics do not.
needs_dask = pytest.mark.skipif(
    __import__("importlib").util.find_spec("distributed") is None,
    reason="the benchmark extra (dask[distributed]) is not installed",
)
needs_parquet = pytest.mark.skipif(
    __import__("importlib").util.find_spec("pyarrow") is None,
    reason="the benchmark extra (pyarrow) is not installed",
)

SMALL = {
    "shapes": ["Sshape", "WShape"],
    "demos": "first3",
    "every": 10,
    "methods": ["dmp-paper", "bidmp"],
}
TIMING = set(lasa_cells.TIMES)


def plain_dtw(a, b):
    """The textbook recursion, memoised: D(i, j) = d(i, j) + min(D(i-1, j), D(i, j-1), D(i-1, j-1))."""
    sys.setrecursionlimit(10_000)

    @functools.cache
    def cost(i, j):
        here = float(np.linalg.norm(a[i] - b[j]))
        if i == 0 and j == 0:
            return here
        if i == 0:
            return here + cost(0, j - 1)
        if j == 0:
            return here + cost(i - 1, 0)
        return here + min(cost(i - 1, j), cost(i, j - 1), cost(i - 1, j - 1))

    return cost(len(a) - 1, len(b) - 1)


def test_dtw_against_the_plain_recursion():
    rng = np.random.default_rng(0)
    for n, m, d in [(1, 1, 2), (1, 6, 2), (9, 4, 3), (40, 33, 2)]:
        a, b = rng.normal(size=(n, d)), rng.normal(size=(m, d))
        assert dtw_distance(a, b) == pytest.approx(plain_dtw(a, b), rel=1e-12)
    line = np.column_stack([np.arange(5.0), np.zeros(5)])
    assert dtw_distance(line, line) == 0.0


def test_swept_area_against_hand_computed_polygons():
    reference = np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]])
    assert swept_area(reference + [0.0, 1.0], reference) == pytest.approx(2.0)  # two unit squares
    # One step: reference (0,0)->(2,0), trajectory (0,1)->(2,3): a trapezoid of heights 1 and 3.
    assert swept_area(
        np.array([[0.0, 1.0], [2.0, 3.0]]), np.array([[0.0, 0.0], [2.0, 0.0]])
    ) == pytest.approx(4.0)
    assert swept_area(reference, reference) == 0.0


def table(rows):
    return [{k: v for k, v in row.items() if k not in TIMING} for row in rows]


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    pytest.importorskip("pyarrow")  # the table is written as Parquet
    return benchmark.lasa(tmp_path_factory.mktemp("serial"), synchronous=True, **SMALL)


@needs_dask
@needs_parquet
def test_serial_and_two_workers_give_identical_tables(serial, tmp_path):
    parallel = benchmark.lasa(tmp_path, workers=2, **SMALL)
    assert parallel.workers == 2
    assert table(parallel.rows) == table(serial.rows)
    assert len(serial.rows) == 2 * 3 * 2 * 3  # cells x methods x cases
    import pyarrow.parquet as pq

    stored = pq.read_table(tmp_path / "lasa.parquet").to_pylist()
    assert table(stored) == table(parallel.rows)
    assert {"demos", "every"} <= set(stored[0]) and stored[0]["every"] == 10


def _worker_environment(_):
    import os

    return {name: os.environ.get(name) for name in ("MALLOC_TRIM_THRESHOLD_", "OMP_NUM_THREADS")}


@needs_dask
def test_workers_keep_glibc_adaptive_malloc_and_this_process_its_environment():
    """Dask's nannies set MALLOC_TRIM_THRESHOLD_=65536 in their workers, which turns off glibc's
    adaptive mmap threshold (the cells' fits ran 1.6-2x slower there); bidmp's cluster
    starts them without it, and leaves no variable of theirs in this process."""
    import os

    from bidmp.experiments.benchmark import _client

    before = dict(os.environ)
    client, cluster = _client(None, 1)
    try:
        seen = client.submit(_worker_environment, 0, pure=False).result()
    finally:
        client.close()
        cluster.close()
    assert seen["MALLOC_TRIM_THRESHOLD_"] is None
    assert seen["OMP_NUM_THREADS"] == "1"  # Dask's single-threaded BLAS in workers is kept
    assert dict(os.environ) == before


def test_a_cell_gives_the_same_floats_whatever_the_thread_pools():
    """run_cell limits BLAS and OpenMP to one thread itself, as Dask's workers do: the serial path
    and the workers then agree to the last bit (2 threads sum in another order: without the limit
    the robot protocol's metrics on this cell differ in the last digits)."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=2):
        two = lasa_cells.run_cell("Angle", 0, ["dmp-robot"], 10)
    with threadpool_limits(limits=1):
        one = lasa_cells.run_cell("Angle", 0, ["dmp-robot"], 10)
    assert table(two["rows"]) == table(one["rows"])


@needs_dask
@needs_parquet
def test_a_worker_killed_mid_run_still_gives_the_complete_table(serial, tmp_path):
    marker = tmp_path / "kill-one-worker"
    marker.write_text("the first cell to see this file kills its worker process")
    result = benchmark.lasa(tmp_path / "out", workers=2, _kill_once=str(marker), **SMALL)
    assert not marker.exists()  # a worker did die
    assert table(result.rows) == table(serial.rows)


def test_an_interrupted_run_resumes_with_only_the_missing_cells(serial, tmp_path):
    first = benchmark.lasa(tmp_path, synchronous=True, **SMALL)
    assert len(first.computed) == 6 and not first.resumed
    # An interruption: two cells never finished, one was cut off mid-write.
    (tmp_path / "cells" / "WShape__1.json").unlink()
    (tmp_path / "cells" / "Sshape__2.json").unlink()
    cut = tmp_path / "cells" / "WShape__2.json"
    cut.write_text(cut.read_text()[:50])
    again = benchmark.lasa(tmp_path, synchronous=True, resume=True, **SMALL)
    assert sorted(again.computed) == ["Sshape__2", "WShape__1", "WShape__2"]
    assert len(again.resumed) == 3
    assert table(again.rows) == table(serial.rows)
    # Another protocol is never mistaken for this one.
    other = benchmark.lasa(tmp_path, synchronous=True, resume=True, **{**SMALL, "every": 20})
    assert len(other.computed) == 6


@pytest.mark.parametrize(
    "argv, match",
    [
        (["--shapes", "Sshape,Nope"], "unknown LASA shape 'Nope'"),
        (["--methods", "dmp-paper,magic"], "unknown method 'magic'"),
        pytest.param(
            ["--scheduler", "tcp://127.0.0.1:9"],
            "cannot reach the Dask scheduler at tcp://127.0.0.1:9 within 0.3 s",
            marks=needs_dask,
        ),
    ],
)
def test_bad_input_is_one_line_and_leaves_nothing(argv, match, tmp_path, capsys, monkeypatch):
    from bidmp.experiments import _lasa_dask

    # Dask retries a refused connection until the timeout: a shorter one here (the message says it)
    monkeypatch.setattr(_lasa_dask, "CONNECT_TIMEOUT_S", 0.3)
    code = main(
        [
            "benchmark",
            "lasa",
            "--shapes",
            "Sshape",
            "--every",
            "10",
            "--out",
            str(tmp_path / "o"),
            *argv,
        ]
    )
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2
    assert match in err[-1] and sum("error" in line for line in err) == 1
    assert not list((tmp_path / "o").glob("cells/*.json"))  # nothing --resume would trust


def test_csv_output_and_the_summary(serial, tmp_path):
    result = benchmark.lasa(tmp_path, synchronous=True, output_format="csv", **SMALL)
    lines = (tmp_path / "lasa.csv").read_text().splitlines()
    assert lines[0].startswith("shape,demo,method,case,seed") and len(lines) == 1 + len(result.rows)
    summary = (tmp_path / "lasa.md").read_text()
    assert "median (IQR)" in summary and "| bidmp |" in summary
    header, rows = benchmark.summary_rows(result.rows, "endpoint_error")
    values = [
        r["endpoint_error"] for r in result.rows if r["method"] == "bidmp" and r["case"] == "far"
    ]
    assert rows[[r[0] for r in rows].index("bidmp")][3].startswith(f"{np.median(values):.3g}")
    cell = json.loads((tmp_path / "cells" / "Sshape__0.json").read_text())
    assert cell["protocol"]["every"] == 10 and cell["rows"][0]["seed"] == lasa_cells._cell_seed(
        "Sshape", 0
    )


def test_the_committed_lasa_summary_is_its_table_and_its_cells_recompute():
    """docs/results/lasa.md (the README's LASA tables, from `make lasa`) is the
    summary of the committed per-cell table docs/results/lasa.parquet, and a fresh run of two of
    its cells gives the same rows (every metric; the times aside)."""
    pq = pytest.importorskip("pyarrow.parquet")
    pytest.importorskip("movement_primitives")  # the committed table has the mp-dmp rows
    root = pathlib.Path(__file__).resolve().parents[2] / "docs" / "results"
    rows = pq.read_table(root / "lasa.parquet").to_pylist()
    protocol = {"demos": rows[0]["demos"], "every": rows[0]["every"]}
    assert (
        benchmark.summary_markdown(rows, protocol).strip() == (root / "lasa.md").read_text().strip()
    )
    methods = list(dict.fromkeys(row["method"] for row in rows))
    for shape, demo in (("Sshape", 0), ("WShape", 4)):
        fresh = lasa_cells.run_cell(shape, demo, methods, protocol["every"])["rows"]
        committed = [row for row in rows if row["shape"] == shape and row["demo"] == demo]
        assert len(fresh) == len(committed)
        for new, old in zip(fresh, committed):
            for name in lasa_cells.METRICS:
                assert new[name] == pytest.approx(old[name], rel=1e-6, abs=1e-9), (
                    shape,
                    demo,
                    new["method"],
                    name,
                )


def test_resume_recomputes_an_edited_a_foreign_or_a_broken_cell_and_says_so(
    serial, tmp_path, caplog
):
    """--resume trusted cell files; an edited value was merged as is and a missing key
    ended in an internal error. Each is now recomputed, with a warning naming the cell."""
    import json
    import logging

    benchmark.lasa(tmp_path, synchronous=True, **SMALL)
    cells = tmp_path / "cells"
    edited = json.loads((cells / "Sshape__0.json").read_text())
    edited["rows"][0]["rmse"] = 0.0  # a better number than the method earned
    (cells / "Sshape__0.json").write_text(json.dumps(edited))
    broken = json.loads((cells / "Sshape__1.json").read_text())
    del broken["rows"][0]["frechet"]
    (cells / "Sshape__1.json").write_text(json.dumps(broken))
    (cells / "WShape__0.json").write_text(
        (cells / "WShape__1.json").read_text()
    )  # another cell's file
    with caplog.at_level(logging.WARNING, logger="bidmp.experiments.benchmark"):
        again = benchmark.lasa(tmp_path, synchronous=True, resume=True, **SMALL)
    assert sorted(again.computed) == ["Sshape__0", "Sshape__1", "WShape__0"]
    assert table(again.rows) == table(serial.rows)
    said = caplog.text
    assert (
        "Sshape__0 was changed after it was written" in said
        and "WShape__0 holds cell 'WShape__1'" in said
    )
    assert "Sshape__1" in said
