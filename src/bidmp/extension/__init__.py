"""Extended demonstrations (paper §3): 1D-SEG segmentation at curvature extrema
(``segmentation``), Fréchet similarity (``similarity``), the G-PRM / classic PRM roadmaps
(``roadmap``) and the extended demonstration that keeps the nearest segment's shape and the
final approach (``extend``).

Layer 1 (the math): imports ``bidmp.primitives`` and the package root's private helpers; a scene
enters only as a collision callback, so nothing here imports ``bidmp.scene``.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "ExtendedDemonstration": "extend",
    "extend_demonstration": "extend",
    "check_extension_options": "extend",
    "extend_pose_demonstration": "extend",
    "final_approach": "extend",
    "APPROACHES": "extend",
    "curvature": "segmentation",
    "segment": "segmentation",
    "Segmentation": "segmentation",
    "Piece": "segmentation",
    "choose_piece": "segmentation",
    "frechet_distance": "similarity",
    "frechet_distance_reference": "similarity",
    "frechet_similarity": "similarity",
    "polyline_length": "similarity",
    "dtw_distance": "similarity",
    "NoFreeRouteError": "roadmap",
    "RoadmapResult": "roadmap",
    "RoadmapOptions": "roadmap",
    "template": "roadmap",
    "gaussian_prm": "roadmap",
    "classic_prm": "roadmap",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
