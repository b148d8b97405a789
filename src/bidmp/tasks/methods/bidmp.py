"""Bi-DMP (the paper's method): the plain DMP plus skills learned incrementally from extended
demonstrations (``bidmp``: the skill nearest the goal; ``bidmp-latest``: the last one learned)."""

from __future__ import annotations

import numpy as np

from ..._checks import as_point
from ...incremental.bidmp import BiDMP
from ...incremental.cartesian import CartesianBiDMP
from .base import Method, Task


class _BiDMPMethod(Method):
    """A task with ``build_skills`` (a scenario) builds its Bi-DMP once from its extension stages;
    one without (the LASA benchmark) extends the demonstration to each goal it is asked for, except
    the demonstrated goal itself, which the plain DMP reaches."""

    poses = True
    closed_loop = True
    settles = True

    def __init__(self, name: str, skill: str, lasa: bool = True, repairs: bool = False) -> None:
        self.name, self.skill, self.lasa, self.repairs = name, skill, lasa, repairs

    def fit(self, task: Task) -> tuple[object, float]:
        dmp, seconds = task.fitted_dmp()
        if task.build_skills is None:
            return _PerGoal(dmp, task), seconds
        model, built = task.shared_model("bidmp", lambda: task.build_skills(dmp))
        return model, seconds + built

    def rollout(self, model, goal: np.ndarray) -> np.ndarray:
        self.check_model(model, _MODELS, "a Bi-DMP (or a per-goal one)")
        if isinstance(model, _PerGoal):
            return model.rollout(as_point(goal, model.dmp.n_dims_, "goal"))
        return model.rollout(goal, skill=self.skill)

    def stepper(self, model, goal: np.ndarray, duration: float, coupling):
        self.check_model(model, _MODELS[:2], "a Bi-DMP")
        return model.stepper(goal, skill=self.skill, duration=duration, coupling=coupling)


class _PerGoal:
    """A Bi-DMP grown to each goal as it is asked for (one extension, one skill per goal)."""

    def __init__(self, dmp, task: Task) -> None:
        self.dmp, self.task = dmp, task

    def rollout(self, goal: np.ndarray) -> np.ndarray:
        from ...extension.extend import extend_demonstration
        from ...incremental.bidmp import BiDMP

        demonstration = self.task.demonstration
        if np.array_equal(goal, demonstration[-1]):
            return self.dmp.rollout(goal)
        extension = extend_demonstration(demonstration, goal, seed=self.task.seed)
        model = BiDMP(self.dmp, **self.task.bidmp).learn(
            extension.complete, duration=extension.duration_for(self.dmp)
        )
        return model.rollout(goal)


_MODELS = (BiDMP, CartesianBiDMP, _PerGoal)

# The methods this module adds to the registry (bidmp.tasks.methods registers them).
METHODS = (
    _BiDMPMethod("bidmp", "nearest", repairs=True),
    _BiDMPMethod("bidmp-latest", "latest", lasa=False),
)
