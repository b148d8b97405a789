"""``gmm``: GMM/GMR on time (the paper's baseline): it reproduces the demonstration and has no
notion of a new goal, so every goal gets the same mean motion."""

from __future__ import annotations

import numpy as np

from . import register
from .base import Method, Task


class _GMMMethod(Method):
    name = "gmm"

    def fit(self, task: Task) -> tuple[object, float]:
        from ...baselines import GMMRegressor

        return task.shared_model("gmm", lambda: GMMRegressor(seed=task.seed % (2**31)).fit(task.demonstration))

    def rollouts(self, model, goals: np.ndarray) -> list[np.ndarray]:
        mean = model.rollout()
        return [mean] * len(goals)

    def rollout(self, model, goal: np.ndarray) -> np.ndarray:
        return model.rollout()


register(_GMMMethod())
