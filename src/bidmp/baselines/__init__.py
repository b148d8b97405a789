"""Probabilistic baselines of the paper's Table 4: GMM/GMR on time (``gmm``) and the
task-parameterised GMM with start and goal frames (``tpgmm``), scikit-learn EM underneath.

Layer 1 (the math): imports only the package root's private helpers (``_checks``, ``_noise``,
``_threads``). The methods registry (:mod:`bidmp.tasks.methods`) runs them as methods.
"""

from .gmm import GMMRegressor, augment
from .tpgmm import TPGMM

__all__ = ["GMMRegressor", "TPGMM", "augment"]
