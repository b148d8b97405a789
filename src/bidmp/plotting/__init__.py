"""Figures (matplotlib ``Figure`` objects written to files; the global backend is never switched).

Layer 3 (the application): imports the math and ``bidmp.io``; never ``cli``.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "plot_trajectories": "figures",
    "plot_generalisation": "figures",
    "plot_segmentation": "figures",
    "plot_extension": "figures",
    "plot_prm_comparison": "figures",
    "plot_incremental": "figures",
    "plot_targets_top_view": "figures",
    "plot_error_vs_distance": "figures",
    "plot_scenario_3d": "figures",
}
__all__ = list(_EXPORTS)
# what the flat module bidmp.plotting of bidmp <= 0.4 held, for code written against it
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals(), fallback=("figures",))
