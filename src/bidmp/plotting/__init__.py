"""Figures per domain (matplotlib ``Figure`` objects written to PNG files; the global backend is never
switched): ``trajectories``, ``extension``, ``incremental``, ``tasks``; ``_base`` holds what they
share. ``viewer`` writes the 3-D viewer (one offline HTML file, plotly: the ``view`` extra).

Layer 2 (data out, beside ``io``): imports the math and ``bidmp.io``; never ``tasks``, ``sim`` or
``cli`` (a report is passed in and read by its attributes).
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "plot_trajectories": "trajectories",
    "plot_rollout": "trajectories",
    "plot_generalisation": "trajectories",
    "plot_recordings": "trajectories",
    "plot_segmentation": "extension",
    "plot_extension": "extension",
    "plot_prm_comparison": "extension",
    "plot_incremental": "incremental",
    "plot_targets_top_view": "tasks",
    "plot_error_vs_distance": "tasks",
    "plot_scenario_3d": "tasks",
    "plot_lasa_benchmark": "benchmark",
    "ViewLayers": "viewer",
    "layers_from_report": "viewer",
    "add_robot_motions": "viewer",
    "solid_layer": "viewer",
    "solid_mesh": "viewer",
    "view_figure": "viewer",
    "write_view": "viewer",
    "save_layers": "viewer",
    "load_layers": "viewer",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
