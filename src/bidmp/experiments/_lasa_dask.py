"""The LASA sweep on Dask: the embedded cluster (without the glibc setting that slowed its workers)
or an existing scheduler, one task per cell, each cell written as it finishes."""

from __future__ import annotations

import logging
import os

from .._checks import require_extra

__all__ = []

# How long an existing scheduler has to answer (Dask retries a refused connection until then).
CONNECT_TIMEOUT_S = 3.0


def _client(scheduler: str | None, workers: int):
    require_extra("distributed", "benchmark", "the LASA benchmark on Dask")
    from distributed import Client, LocalCluster

    if scheduler is not None:
        try:
            return Client(scheduler, timeout=f"{CONNECT_TIMEOUT_S:g}s"), None
        except (OSError, TimeoutError) as exc:
            raise ValueError(
                f"cannot reach the Dask scheduler at {scheduler} within {CONNECT_TIMEOUT_S:g} s "
                f"({type(exc).__name__})"
            ) from None
    import dask

    # Dask's nannies set MALLOC_TRIM_THRESHOLD_=65536 in every worker. Setting any of glibc's malloc
    # thresholds switches off its adaptive mmap threshold, so every array above 128 KiB is mapped
    # and unmapped afresh: the GMM and TP-GMM fits ran 1.6-2x slower with 30x the kernel time. The
    # nannies also leave their variables in this process's environment; it is restored after.
    saved = dict(os.environ)
    with dask.config.set({"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None}):
        cluster = LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            # a free port of its own: None still meant the shared default 8787, and a second
            # cluster starting beside the first (two test workers) was refused with a warning
            dashboard_address=":0",
            silence_logs=logging.ERROR,
        )
    os.environ.clear()
    os.environ.update(saved)
    return Client(cluster), cluster


def _run_on_dask(todo, sweep: tuple, cluster: tuple, kill_once, done, progress) -> int:
    """The cells ``todo`` of ``sweep`` = (methods, every, results folder, protocol) on a Dask
    ``cluster`` = (workers, scheduler address or None: an embedded one), each written as it
    finishes and added to ``done``; returns the number of workers."""
    methods, every, out, protocol = sweep
    workers, scheduler = cluster
    n_workers = workers or (os.cpu_count() or 1)
    client, cluster = _client(scheduler, n_workers)
    try:
        from distributed import as_completed

        n_running = len(client.scheduler_info().get("workers", {})) or n_workers
        from ..tasks import methods as registry
        from .lasa_cells import _write_cell, cell_key, run_cell

        objects = [registry.get(name) for name in methods]
        futures = [
            client.submit(
                run_cell,
                shape,
                demo,
                objects,
                every,
                kill_once,
                key=f"bidmp-lasa-{cell_key(shape, demo)}",
                pure=False,
                retries=2,
            )
            for shape, demo in todo
        ]
        for future in as_completed(futures):
            cell = future.result()
            _write_cell(out, protocol, cell)
            done[cell["key"]] = cell
            if progress is not None:
                progress(cell["key"])
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
    return n_running
