"""Incremental learning (paper Eq. 15–28): the exact incremental Broad Learning System (``bls``),
the Bi-DMP skill library on a DMP's forcing term with forgetting measures (``bidmp``), and its
pose version (``cartesian``).

Layer 1 (the math): imports ``bidmp.primitives`` and the package root's private helpers only.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from .._lazy import exports

# The public names: imported on first use (bidmp._lazy reads this block), seen by type checkers.
if TYPE_CHECKING:
    from .bidmp import BiDMP, ForgettingResult, forgetting, forgetting_runs
    from .bls import BLS
    from .cartesian import CartesianBiDMP, pose_forgetting
    from .linalg import block_pinv_update, sparse_autoencoder, svd_update, truncated_svd
__getattr__, __dir__ = exports(__name__, __file__, globals())
