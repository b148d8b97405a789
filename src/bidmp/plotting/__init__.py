"""Figures per domain (matplotlib ``Figure`` objects written to PNG files; the global backend is never
switched): ``trajectories``, ``extension``, ``incremental``, ``tasks``, ``benchmark``,
``clfd``; ``_base`` holds what they
share. ``viewer`` writes the 3-D viewer (one offline HTML file, plotly: the ``view`` extra).

Layer 2 (data out, beside ``io``): imports the math and ``bidmp.io``; never ``tasks``, ``sim`` or
``cli`` (a report is passed in and read by its attributes).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .benchmark import plot_lasa_benchmark
    from .clfd import plot_clfd, plot_clfd_capacity
    from .extension import plot_extension, plot_prm_comparison, plot_segmentation
    from .incremental import plot_incremental
    from .tasks import plot_error_vs_distance, plot_scenario_3d, plot_targets_top_view
    from .trajectories import (
        plot_distribution,
        plot_generalisation,
        plot_recordings,
        plot_rhythm,
        plot_rollout,
        plot_trajectories,
    )
    from .viewer import (
        ViewLayers,
        add_robot_motions,
        layers_from_report,
        load_layers,
        save_layers,
        solid_layer,
        solid_mesh,
        view_figure,
        write_view,
    )
__getattr__, __dir__ = exports(__name__, __file__, globals())
