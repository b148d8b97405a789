"""``bidmp view`` and the ``--view`` of ``bidmp demo`` and ``bidmp sim``: the 3-D viewer's files."""

from __future__ import annotations

import argparse
from pathlib import Path

from .common import EXIT_OK

LAYERS = "view_layers.npz"
PAGE = "view.html"


def write_view_files(out: Path, report=None, sim_result=None, extra_solids=()) -> list[Path]:
    """Store the layers of an evaluation (and a simulation's arm motions, added to the layers
    already in ``out``; ``extra_solids``: a job's own parts) and write the HTML viewer; returns
    the files written."""
    from ..plotting.viewer import (
        add_robot_motions,
        layers_from_report,
        load_layers,
        save_layers,
        solid_layer,
        write_view,
    )

    out = Path(out)
    if report is not None:
        layers = layers_from_report(report)
    else:
        layers = load_layers(out / LAYERS)
    layers.solids += [solid_layer(solid) for solid in extra_solids]
    if sim_result is not None:
        add_robot_motions(layers, sim_result)
    return [save_layers(out / LAYERS, layers), write_view(out / PAGE, layers)]


def _cmd_view(args: argparse.Namespace) -> int:
    from ..plotting.viewer import load_layers, write_view

    folder = Path(args.results)
    if not (folder / LAYERS).is_file():
        raise ValueError(
            f"{folder} holds no {LAYERS}: run 'bidmp demo --view --out {folder}' or "
            f"'bidmp sim --view --out {folder}' first"
        )
    page = write_view(
        Path(args.output) if args.output else folder / PAGE, load_layers(folder / LAYERS)
    )
    if not args.output:
        from ..io.runs import update_manifest

        # the page is the run's own (written with --view): its manifest lists it as it is now
        update_manifest(folder, PAGE)
    print(f"wrote {page} (open it in a browser: drag to turn, slider for the robot's motion)")
    return EXIT_OK


def add_commands(commands) -> None:
    """``bidmp view RESULTS_DIR``."""
    view = commands.add_parser(
        "view",
        help="the 3-D viewer of a results folder (one offline HTML file)",
        description="Write RESULTS_DIR/view.html from the layers 'bidmp demo --view' or 'bidmp sim "
        "--view' stored there: demonstration, segmentation points, extended "
        "demonstrations, rollouts per method, scene parts and the simulated robot's "
        "motion on a time slider. One self-contained file (plotly.js inside): opens "
        "offline in any browser. Needs bidmp[view].",
    )
    view.add_argument(
        "results", metavar="RESULTS_DIR", help="a folder written by bidmp demo/sim with --view"
    )
    view.add_argument(
        "-o",
        "--output",
        default=None,
        metavar="HTML",
        help="where to write (default RESULTS_DIR/view.html)",
    )
    view.set_defaults(handler=_cmd_view)
