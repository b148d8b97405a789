"""Incremental learning (paper Eq. 15–28): the exact incremental Broad Learning System (``bls``),
the Bi-DMP skill library on a DMP's forcing term with forgetting measures (``bidmp``), and its
pose version (``cartesian``).

Layer 1 (the math): imports ``bidmp.primitives`` and the package root's private helpers only.
"""

from __future__ import annotations

from .._lazy import exports

# public name -> the module that holds it (imported on first use)
_EXPORTS = {
    "BiDMP": "bidmp",
    "ForgettingResult": "bidmp",
    "forgetting": "bidmp",
    "forgetting_runs": "bidmp",
    "BLS": "bls",
    "sparse_autoencoder": "linalg",
    "block_pinv_update": "linalg",
    "truncated_svd": "linalg",
    "svd_update": "linalg",
    "CartesianBiDMP": "cartesian",
    "pose_forgetting": "cartesian",
}
__all__ = list(_EXPORTS)
__getattr__, __dir__ = exports(__name__, _EXPORTS, globals())
