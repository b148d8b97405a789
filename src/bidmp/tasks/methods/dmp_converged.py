"""``dmp-converged``: the plain DMP run for whole multiples of the demonstration until its
end-point gain (:meth:`bidmp.DMP.endpoint_gain`) is at most :data:`CONVERGED_GAIN`: the paper's
fixed horizon taken away, the DMP's own generalisation without Bi-DMP."""

from __future__ import annotations

import numpy as np

from ..._checks import as_vector
from ...primitives.dmp import DMP
from .base import Method, Task, checked_goals

CONVERGED_GAIN = 1e-4  # dmp-converged runs whole multiples of T until endpoint_gain() <= this


class _DMPConverged(Method):
    name = "dmp-converged"
    lasa = False

    def fit(self, task: Task) -> tuple[object, float]:
        return task.fitted_dmp()

    def rollouts(self, model, goals: np.ndarray) -> list[np.ndarray]:
        self.check_model(model, DMP, "a fitted DMP")
        goals = checked_goals(goals)
        n_steps = model.n_steps_
        factor = next(
            (k for k in range(2, 101) if model.endpoint_gain(k * n_steps) <= CONVERGED_GAIN), 100
        )
        return list(model.rollout_many(goals, n_steps=factor * n_steps))

    def rollout(self, model, goal: np.ndarray) -> np.ndarray:
        return self.rollouts(model, as_vector(goal, "goal")[None])[0]


# The methods this module adds to the registry (bidmp.tasks.methods registers them).
METHODS = (_DMPConverged(),)
