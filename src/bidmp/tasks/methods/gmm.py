"""``gmm``: GMM/GMR on time (the paper's baseline): it reproduces the demonstration and has no
notion of a new goal, so every goal gets the same mean motion."""

from __future__ import annotations

import numpy as np

from ..._checks import as_vector
from .base import Method, Task, checked_goals


class _GMMMethod(Method):
    name = "gmm"

    def fit(self, task: Task) -> tuple[object, float]:
        from ...baselines import GMMRegressor

        return task.shared_model(
            "gmm", lambda: GMMRegressor(seed=task.seed % (2**31)).fit(task.demonstration)
        )

    def rollouts(self, model, goals: np.ndarray) -> list[np.ndarray]:
        goals = checked_goals(goals)
        return [self.rollout(model, goals[0])] * len(goals)

    def rollout(self, model, goal: np.ndarray) -> np.ndarray:
        from ...baselines import GMMRegressor

        self.check_model(model, GMMRegressor, "a fitted GMMRegressor")
        # a goal is asked for, and ignored: GMR on time reproduces its demonstration
        as_vector(goal, "goal")
        return model.rollout()


# The methods this module adds to the registry (bidmp.tasks.methods registers them).
METHODS = (_GMMMethod(),)
