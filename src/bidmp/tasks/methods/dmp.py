"""The plain DMP: fitted once on the demonstration, rolled out to each goal (``dmp``: the task's
protocol; ``dmp-paper`` and ``dmp-robot``: the two protocols, as the LASA benchmark compares them)."""

from __future__ import annotations

import numpy as np

from ...primitives.cartesian import CartesianDMP
from ...primitives.dmp import DMP
from .base import Method, Task, checked_goals

_DMPS = (DMP, CartesianDMP)


class _DMPMethod(Method):
    """A :class:`bidmp.DMP` (or :class:`bidmp.CartesianDMP` on poses) with the task's parameters,
    ``protocol`` overriding the task's when given."""

    poses = True
    closed_loop = True
    settles = True

    def __init__(self, name: str, protocol: str | None = None, lasa: bool = True) -> None:
        self.name, self.protocol, self.lasa = name, protocol, lasa

    def fit(self, task: Task) -> tuple[object, float]:
        return (
            task.fitted_dmp() if self.protocol is None else task.fitted_dmp(protocol=self.protocol)
        )

    def rollout(self, model, goal: np.ndarray) -> np.ndarray:
        self.check_model(model, _DMPS, "a fitted DMP or CartesianDMP")
        return model.rollout(goal)

    def rollouts(self, model, goals: np.ndarray) -> list[np.ndarray]:
        self.check_model(model, _DMPS, "a fitted DMP or CartesianDMP")
        goals = checked_goals(goals)
        if hasattr(model, "rollout_many"):
            return list(model.rollout_many(goals))  # one integration for every goal
        return [model.rollout(goal) for goal in goals]

    def stepper(self, model, goal: np.ndarray, duration: float, coupling):
        self.check_model(model, _DMPS, "a fitted DMP or CartesianDMP")
        return model.stepper(goal, duration=duration, coupling=coupling)


# The methods this module adds to the registry (bidmp.tasks.methods registers them).
METHODS = (
    _DMPMethod("dmp", lasa=False),
    _DMPMethod("dmp-paper", protocol="paper"),
    _DMPMethod("dmp-robot", protocol="robot"),
)
