"""``bidmp reproduce``, ``bidmp lasa`` and ``bidmp benchmark``: the paper's results, the bundled
LASA data and the LASA benchmark."""

from __future__ import annotations

import argparse
import json

from .common import (
    EXIT_OK,
    MAX_SEEDS,
    Parser,
    output_folder,
    overwrite_option,
    shown_written,
)

__all__ = ["add_commands", "lasa_demo"]


def _cmd_reproduce(args: argparse.Namespace) -> int:
    from functools import partial
    from pathlib import Path

    from tqdm import tqdm

    from ..experiments import reproduce

    out = Path(args.out)
    if not 1 <= args.seeds <= MAX_SEEDS:
        raise ValueError(f"--seeds must be 1-{MAX_SEEDS}, got {args.seeds}")
    # the folder is checked and held first: a refusal comes before the work, not after it
    with output_folder(out, args.overwrite) as run:
        if args.what == "table4":
            with tqdm(
                total=len(reproduce.TABLE4_SCENARIOS), desc="table4", unit="scenario", disable=None
            ) as bar:
                result = reproduce.run_table4(
                    progress=lambda name: (bar.set_postfix_str(name), bar.update(1))
                )
        elif args.what == "figures":
            result = reproduce.run_figures(
                progress=partial(tqdm, desc="figures", unit="shape", disable=None)
            )
        else:
            result = reproduce.run_table5(
                args.seeds, progress=partial(tqdm, desc="table5", unit="case", disable=None)
            )
        print(result.summary())
        written = reproduce.write_results(result, args.what, run.path)
    print(f"\nwrote {shown_written(run, written)}")
    return EXIT_OK


# ---------------------------------------------------------------------------------------------
# Command handlers
# ---------------------------------------------------------------------------------------------
def _cmd_lasa(args: argparse.Namespace) -> int:
    from ..demonstrations.datasets import lasa, lasa_names

    if args.lasa_command == "list":
        for name in lasa_names():
            print(name)
        return EXIT_OK
    from ..io.trajectories import save_trajectory

    demos = lasa(args.name)
    if not 0 <= args.demo < demos.shape[0]:
        raise ValueError(f"--demo must be 0-{demos.shape[0] - 1}, got {args.demo}")
    path = save_trajectory(demos[args.demo], args.output)
    print(
        f"wrote {args.name} demonstration {args.demo} ({demos.shape[1]} x {demos.shape[2]}) to {path}"
    )
    return EXIT_OK


def lasa_demo(shape: str, out, overwrite: bool = False) -> int:
    """``bidmp demo --lasa SHAPE``: the fit-and-generalise example, its JSON and figure one run
    in folder ``out``."""
    from ..experiments.reproduce import lasa_generalisation
    from ..io.atomic import atomic_write
    from ..plotting.trajectories import plot_generalisation

    with output_folder(out, overwrite) as run:
        result = lasa_generalisation(shape)
        print("bidmp demo --lasa: " + result.summary())
        with atomic_write(run.path / "lasa_generalisation.json", "w") as handle:
            json.dump(result.to_dict(), handle, indent=2)
        figure = plot_generalisation(run.path / "lasa_generalisation.png", result)
    print(f"wrote {run.shown(run.path / 'lasa_generalisation.json')} and {run.shown(figure)}")
    return EXIT_OK


def _cmd_benchmark(args: argparse.Namespace) -> int:
    if args.benchmark_command == "clfd":
        return _cmd_clfd(args)
    from pathlib import Path

    from tqdm import tqdm

    from ..experiments import check_lasa_options, lasa

    shapes = (
        None if args.shapes is None else [s.strip() for s in args.shapes.split(",") if s.strip()]
    )
    methods = (
        None if args.methods is None else [m.strip() for m in args.methods.split(",") if m.strip()]
    )
    # before starting a cluster
    shapes_checked, _, indices = check_lasa_options(shapes, methods, args.demos, args.every)
    if args.workers is not None and not 1 <= args.workers <= 256:
        raise ValueError(f"--workers must be 1-256, got {args.workers}")
    # The cells go into a partial folder beside --out that a failed or killed run leaves for
    # --resume; the finished run (its cells, table and figures) is then swapped in whole.
    with (
        output_folder(Path(args.out), args.overwrite, partial=True, resume=args.resume) as run,
        tqdm(
            total=len(shapes_checked) * len(indices), desc="LASA", unit="cell", disable=None
        ) as bar,
    ):
        if args.resume:
            _resume_cells(run)
        result = lasa(
            run.path,
            shapes=shapes,
            methods=methods,
            demos=args.demos,
            every=args.every,
            workers=args.workers,
            scheduler=args.scheduler,
            resume=args.resume,
            output_format=args.format,
            progress=lambda key: bar.update(1),
        )
        _drop_other_cells(run, result)
        summary = (run.path / "lasa.md").read_text()
    print(
        f"LASA benchmark: {len(result.computed)} cells computed, {len(result.resumed)} resumed, "
        f"{result.workers} worker(s), {result.wall_s:.1f} s"
    )
    print(summary)
    print(f"wrote {shown_written(run, result.written)}")
    return EXIT_OK


def _resume_cells(run) -> None:
    """--resume: the partial run's own files but its cells are dropped (the table and figures
    are written again), and the finished cells of the run in --out that the partial run lacks
    are taken into it (the benchmark checks each one it reads)."""
    import shutil

    for entry in run.path.iterdir():
        if entry.name == "cells":
            continue
        if entry.is_dir():
            shutil.rmtree(entry)
        else:
            entry.unlink()
    finished = run.final / "cells"
    if not finished.is_dir():
        return
    (run.path / "cells").mkdir(exist_ok=True)
    for cell in finished.glob("*.json"):
        if not (run.path / "cells" / cell.name).exists():
            from ..io.atomic import atomic_write

            with atomic_write(run.path / "cells" / cell.name, "wb") as handle:
                handle.write(cell.read_bytes())


def _drop_other_cells(run, result) -> None:
    """The cells a resumed partial run held that this run did not use (other shapes, another
    protocol) are not part of it."""
    keep = {f"{key}.json" for key in [*result.computed, *result.resumed]}
    for cell in (run.path / "cells").glob("*"):
        if cell.name not in keep:
            cell.unlink()


def _cmd_clfd(args: argparse.Namespace) -> int:
    from ..experiments.clfd import METHODS, run_clfd, write_clfd

    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    unknown = [m for m in methods if m not in METHODS]
    if unknown or not methods:
        raise ValueError(
            f"--methods: unknown method {unknown[0] if unknown else '(none given)'!r:.40} "
            f"(known: {', '.join(METHODS)})"
        )
    n_available = 26 if args.dataset == "lasa" else 9
    if args.tasks is not None and not 1 <= args.tasks <= n_available:
        raise ValueError(f"--tasks must be 1-{n_available} on {args.dataset}, got {args.tasks}")
    if not 1 <= args.seeds <= 100:
        raise ValueError(f"--seeds must be 1-100, got {args.seeds}")
    if not 1 <= args.workers <= 256:
        raise ValueError(f"--workers must be 1-256, got {args.workers}")
    with output_folder(args.out, args.overwrite) as run:
        result = run_clfd(
            args.dataset,
            methods,
            n_tasks=args.tasks,
            seeds=range(args.seeds),
            workers=args.workers,
        )
        written = write_clfd(result, run.path)
    print(result.markdown())
    print(f"wrote {shown_written(run, written)}")
    return EXIT_OK


def _reproduce_parser(commands) -> None:
    """``bidmp reproduce table4|table5|figures``."""
    reproduce = commands.add_parser(
        "reproduce",
        help="reproduce a table of the paper",
        description="Reproduce the paper's comparisons. table4: the three case studies (nut "
        "unscrewing, cell removal before/after the second extension, pick-and-place with "
        "three operators). table5: G-PRM vs classic PRM similarity "
        "per iteration over many seeds (LASA shapes and the battery approach path). "
        "figures: Bi-DMP on LASA shapes, three new targets each (Fig. 11), "
        "with reproduction errors and forgetting.",
    )
    reproduce.add_argument("what", choices=("table4", "table5", "figures"), help="which result")
    reproduce.add_argument(
        "--out",
        default="bidmp-out",
        help="output folder (default ./bidmp-out): one run, replaced whole by the next",
    )
    overwrite_option(reproduce)
    reproduce.add_argument("--seeds", type=int, default=20, help="number of seeds (default 20)")
    reproduce.set_defaults(handler=_cmd_reproduce)


def _lasa_parser(commands) -> None:
    """``bidmp lasa list|export``."""
    lasa = commands.add_parser(
        "lasa",
        help="the bundled LASA handwriting data",
        description="List or export the LASA handwriting shapes.",
    )
    lasa_commands = lasa.add_subparsers(
        dest="lasa_command", metavar="{list,export}", required=True, parser_class=Parser
    )
    lasa_commands.add_parser("list", help="list the shape names")
    export = lasa_commands.add_parser("export", help="write one demonstration of a shape")
    export.add_argument("name", metavar="NAME", help="shape name, e.g. Sshape")
    export.add_argument(
        "--demo", type=int, default=0, help="which of the 7 demonstrations (0-6, default 0)"
    )
    export.add_argument(
        "-o", "--output", required=True, metavar="OUT", help="file to write (.csv or .npy)"
    )
    lasa.set_defaults(handler=_cmd_lasa)


def _benchmark_parser(commands) -> None:
    """``bidmp benchmark lasa``."""
    benchmark = commands.add_parser(
        "benchmark",
        help="the full LASA benchmark with the standard metrics, on Dask",
        description="Sweep every LASA shape x demonstration with every method (reproduction, "
        "near and far goals): RMSE, DTW, swept area, Fréchet, end-point error, "
        "times. Runs on an embedded Dask LocalCluster (one worker per core) or on "
        "--scheduler ADDRESS. Needs bidmp[benchmark].",
    )
    bench_commands = benchmark.add_subparsers(
        dest="benchmark_command", metavar="{lasa,clfd}", required=True, parser_class=Parser
    )
    bench = bench_commands.add_parser("lasa", help="the LASA handwriting benchmark")
    bench.add_argument("--shapes", default=None, help="comma-separated shapes (default all 30)")
    bench.add_argument(
        "--methods",
        default=None,
        help="comma-separated methods (default dmp-paper,dmp-robot,bidmp,gmm,tpgmm,mp-dmp)",
    )
    bench.add_argument(
        "--demos",
        choices=("all", "first3"),
        default="all",
        help="all 7 demonstrations or the first 3",
    )
    bench.add_argument(
        "--every",
        type=int,
        default=1,
        metavar="K",
        help="use every K-th sample (papers use 1 or 10)",
    )
    bench.add_argument(
        "--workers",
        type=int,
        default=None,
        help="worker processes of the embedded Dask cluster (default: one per core); 1 runs the cells "
        "serially in this process, without Dask",
    )
    bench.add_argument(
        "--scheduler",
        default=None,
        metavar="ADDRESS",
        help="run on an existing Dask scheduler (tcp://host:8786)",
    )
    bench.add_argument(
        "--resume",
        action="store_true",
        help="skip the cells a previous run into --out finished, or an interrupted one left "
        "(in .OUT.bidmp-partial beside it)",
    )
    bench.add_argument(
        "--format",
        choices=("parquet", "csv"),
        default="parquet",
        help="results table format (default parquet)",
    )
    bench.add_argument(
        "--out",
        default="bidmp-lasa",
        help="output folder (default ./bidmp-lasa): one run, replaced whole by the next",
    )
    overwrite_option(bench)
    clfd = bench_commands.add_parser(
        "clfd",
        help="continual learning from demonstration: the CLFD protocol (Auddy et al.)",
        description="Learn the tasks one after the other (lasa: 26 shapes, 7 demonstrations "
        "each; robottasks: RoboTasks9's 9 pose tasks, 9 demonstrations each) and after each "
        "evaluate every task seen, reproduced from each demonstration's start: DTW, Fréchet, "
        "swept-area (lasa) and orientation (robottasks) errors, the accuracy matrices, ACC, BWT, "
        "REM, MS, TE, FS, CL_score and CL_stability as the protocol defines them. Writes "
        "clfd.json, clfd.md and their figures (clfd_robottasks* for robottasks).",
    )
    clfd.add_argument(
        "--dataset", choices=("lasa", "robottasks"), default="lasa", help="the tasks (lasa)"
    )
    clfd.add_argument(
        "--methods",
        default="dmp-library,bidmp-continual",
        help="comma-separated methods: dmp-library, finetune, bidmp-library, promp-library, "
        "bidmp-continual (default dmp-library,bidmp-continual)",
    )
    clfd.add_argument(
        "--tasks", type=int, default=None, help="only the first N tasks (default all)"
    )
    clfd.add_argument(
        "--seeds",
        type=int,
        default=1,
        help="seeds 0..N-1 of the methods that draw at random (bidmp-library, "
        "bidmp-continual): one cell each (default 1)",
    )
    clfd.add_argument(
        "--workers",
        type=int,
        default=1,
        help="run the cells (method x seed) on an embedded Dask cluster of N processes; 1 "
        "(default), or a single cell: one after the other here",
    )
    clfd.add_argument(
        "--out",
        default="bidmp-clfd",
        help="output folder (default ./bidmp-clfd): one run, replaced whole by the next",
    )
    overwrite_option(clfd)
    benchmark.set_defaults(handler=_cmd_benchmark)


def add_commands(commands) -> None:
    """The reproduce, lasa and benchmark commands of ``bidmp``'s parser."""
    _reproduce_parser(commands)
    _lasa_parser(commands)
    _benchmark_parser(commands)
