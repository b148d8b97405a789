"""``tpgmm``: the task-parameterised GMM (start and goal frames), a baseline that does take a goal."""

from __future__ import annotations

import numpy as np

from .base import Method, Task


class _TPGMMMethod(Method):
    name = "tpgmm"

    def fit(self, task: Task) -> tuple[object, float]:
        from ...baselines import TPGMM

        return task.shared_model(
            "tpgmm",
            lambda: (
                TPGMM(seed=task.seed % (2**31)).fit(task.demonstration),
                task.demonstration[0],
            ),
        )

    def rollout(self, model, goal: np.ndarray) -> np.ndarray:
        from ...baselines import TPGMM

        if not (isinstance(model, tuple) and len(model) == 2 and isinstance(model[0], TPGMM)):
            raise TypeError(
                f"model must be (a fitted TPGMM, start), what method 'tpgmm''s fit returns, got "
                f"{type(model).__name__}"
            )
        tpgmm, start = model
        return tpgmm.rollout(goal, start=start)


# The methods this module adds to the registry (bidmp.tasks.methods registers them).
METHODS = (_TPGMMMethod(),)
