"""Probabilistic baselines of the paper's Table 4: GMM/GMR and TP-GMM (SPEC §8)."""

from .gmm import GMMRegressor, augment, gmr
from .tpgmm import TPGMM

__all__ = ["GMMRegressor", "TPGMM", "augment", "gmr"]
