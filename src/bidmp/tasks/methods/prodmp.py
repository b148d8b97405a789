"""The task method ``prodmp``: a ProDMP learned from the task's demonstrations (else noisy copies
of its one), from the start at rest, its goal moved so that it ends exactly at the goal. Named by
the ProDMP's entry in :mod:`bidmp.primitives.registry` (``method``), which registers it with the
built-in methods."""

from __future__ import annotations

import numpy as np

from .base import Method, Task


class _ProDMPMethod(Method):
    name = "prodmp"
    lasa = False  # on request (--methods): the committed LASA tables keep their methods

    def fit(self, task: Task) -> tuple[object, float]:
        from ...primitives.prodmp import ProDMP

        def build():
            model = ProDMP(n_basis=20).fit(task.all_demonstrations())
            return model, task.demonstration[0], task.demonstration.shape[0]

        return task.shared_model("prodmp", build)

    def rollout(self, model, goal: np.ndarray) -> np.ndarray:
        from ...primitives.prodmp import ProDMP

        if not (isinstance(model, tuple) and len(model) == 3 and isinstance(model[0], ProDMP)):
            raise TypeError(
                f"model must be (a fitted ProDMP, start, samples), what method 'prodmp''s fit "
                f"returns, got {type(model).__name__}"
            )
        prodmp, start, n_samples = model
        attractor = prodmp.goal_for_end(goal, start)  # ends exactly at the goal
        return prodmp.trajectory(start=start, attractor=attractor, n_steps=n_samples).y


METHOD = _ProDMPMethod()
