"""Extended demonstrations (paper §3): 1D-SEG segmentation at curvature extrema
(``segmentation``), Fréchet similarity (``similarity``), the G-PRM / classic PRM roadmaps
(``roadmap``) and the extended demonstration that keeps the nearest segment's shape and the
final approach (``extend``).

Layer 1 (the math): imports ``bidmp.primitives`` and the package root's private helpers; a scene
enters only as a collision callback, so nothing here imports ``bidmp.scene``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .extend import (
        APPROACHES,
        ExtendedDemonstration,
        ExtensionOptions,
        check_extension_options,
        extend_demonstration,
        extend_pose_demonstration,
        final_approach,
    )
    from .roadmap import (
        NoFreeRouteError,
        RoadmapOptions,
        RoadmapResult,
        classic_prm,
        gaussian_prm,
        template,
    )
    from .segmentation import Piece, Segmentation, choose_piece, curvature, segment
    from .similarity import (
        dtw_distance,
        frechet_distance,
        frechet_distance_reference,
        frechet_similarity,
        polyline_length,
    )
__getattr__, __dir__ = exports(__name__, __file__, globals())
