"""Methods that learn from several demonstrations (the task's ``demonstrations``, else noisy
copies of its one): ``promp`` — a ProMP conditioned exactly on the start and the goal;
``dmp-multi`` — a DMP whose forcing term is learned from all of them (the robot protocol)."""

from __future__ import annotations

import numpy as np

from .base import Method, Task


class _ProMPMethod(Method):
    name = "promp"

    def fit(self, task: Task) -> tuple[object, float]:
        from ...primitives.promp import ProMP

        def build():
            demos = task.all_demonstrations()
            # a broad prior: goals far outside the demonstrations' spread (ProMP.cov_reg)
            model = ProMP(n_basis=20, cov_reg=0.1).fit(demos)
            return model, task.demonstration[0], task.demonstration.shape[0]

        return task.shared_model("promp", build)

    def rollout(self, model, goal: np.ndarray) -> np.ndarray:
        from ...primitives.promp import ProMP

        if not (isinstance(model, tuple) and len(model) == 3 and isinstance(model[0], ProMP)):
            raise TypeError(
                f"model must be (a fitted ProMP, start, samples), what method 'promp''s fit "
                f"returns, got {type(model).__name__}"
            )
        promp, start, n_samples = model
        goal = np.asarray(goal, dtype=float)
        # the start and the goal passed exactly (zero variance)
        conditioned = promp.condition([0.0, 1.0], np.stack([start, goal]), 0.0)
        return conditioned.mean(n_steps=n_samples)


class _MultiDMPMethod(Method):
    name = "dmp-multi"
    settles = True

    def fit(self, task: Task) -> tuple[object, float]:
        from ...primitives.multi import MultiDMP

        return task.shared_model("dmp-multi", lambda: MultiDMP().fit(task.all_demonstrations()))

    def rollout(self, model, goal: np.ndarray) -> np.ndarray:
        from ...primitives.multi import MultiDMP

        self.check_model(model, MultiDMP, "a fitted MultiDMP")
        return model.rollout(goal)


# The methods this module adds to the registry (bidmp.tasks.methods registers them).
METHODS = (_ProMPMethod(), _MultiDMPMethod())
