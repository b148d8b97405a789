"""What a method is: the :class:`Method` interface and the :class:`Task` it is run on.

A task is one learning problem — a demonstration, the goals to reach, a seed, the DMP and Bi-DMP
parameters, and (for a scenario) how its Bi-DMP skills are grown. A method fits once per task and
then rolls out to each goal; what several methods share (the fitted DMP, the Bi-DMP) is built
once per task (:meth:`Task.shared_model`), so evaluating all methods costs what each shared step
costs once.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from ..._checks import (
    as_trajectory,
    check_bool,
    check_callable,
    check_limit,
    check_options,
    check_seed,
    check_text,
)
from ..._checks import short_token as _short_token

__all__ = ["Method", "Task", "checked_goals"]


def checked_goals(goals) -> np.ndarray:
    """Goals (G, D) for a batch of rollouts: finite numbers, at most ``max_targets`` of them (each
    goal is a whole motion: millions of them are no batch)."""
    goals = as_trajectory(goals, "goals", min_points=1, allow_static=True)
    check_limit(goals.shape[0], "max_targets", "goals: the number of goals")
    return goals


@dataclass
class Task:
    """One learning problem.

    Attributes
    ----------
    demonstration : array (T, D)
        Positions (any unit), or poses ``(T, 7)`` (x, y, z, qx, qy, qz, qw) when ``poses``.
    goals : array (G, D)
        The goals (targets) to roll out to.
    seed : int
        The seed of every random choice (extensions, EM).
    dmp, bidmp : dict
        Parameters of the DMP and of the Bi-DMP (the scenario's; empty: the defaults).
    poses : bool
        Whether the demonstration holds poses.
    build_skills : callable, optional
        ``build_skills(dmp) -> model``: the Bi-DMP (or pose Bi-DMP) of this task, with its
        extended demonstrations learned (a scenario's extension stages). None: a Bi-DMP extends
        the demonstration to each goal it is asked for (the LASA benchmark).
    shared : dict
        Models shared between methods, with the seconds each took to build.
    demonstrations : tuple of arrays (T_i, D)
        Further demonstrations of the same task (any lengths), for the methods that learn from
        several (``promp``, ``dmp-multi``); empty: they learn from ``demonstration`` and noisy
        copies of it, as the GMM baselines do.
    """

    demonstration: np.ndarray
    goals: np.ndarray
    seed: int = 0
    dmp: dict = field(default_factory=dict)
    bidmp: dict = field(default_factory=dict)
    poses: bool = False
    build_skills: Callable | None = None
    shared: dict = field(default_factory=dict)
    demonstrations: tuple = ()

    def __post_init__(self) -> None:
        self.poses = check_bool(self.poses, "poses")
        self.demonstration = as_trajectory(
            self.demonstration, "demonstration", allow_static=self.poses
        )
        self.goals = checked_goals(self.goals)
        if self.goals.shape[1] != self.demonstration.shape[1]:
            raise ValueError(
                f"goals have D = {self.goals.shape[1]} but the demonstration has D = "
                f"{self.demonstration.shape[1]}"
            )
        check_seed(self.seed, "seed")
        from ..options import BiDMPOptions, DMPOptions

        # a scenario's options objects, or their keyword arguments
        if isinstance(self.dmp, DMPOptions):
            self.dmp = self.dmp.arguments
        if isinstance(self.bidmp, BiDMPOptions):
            self.bidmp = self.bidmp.arguments
        self.dmp, self.bidmp = check_options(self.dmp, "dmp"), check_options(self.bidmp, "bidmp")
        if self.build_skills is not None:
            check_callable(
                self.build_skills, "build_skills", "a function build_skills(dmp) -> model"
            )
        if not isinstance(self.shared, dict):
            raise TypeError(f"shared must be a dict, got {type(self.shared).__name__}")
        if not isinstance(self.demonstrations, (tuple, list)):
            raise TypeError(
                f"demonstrations must be a tuple of (T_i, D) arrays, got {type(self.demonstrations).__name__}"
            )
        self.demonstrations = tuple(
            as_trajectory(y, f"demonstrations[{index}]")
            for index, y in enumerate(self.demonstrations)
        )
        for index, y in enumerate(self.demonstrations):
            if y.shape[1] != self.demonstration.shape[1]:
                raise ValueError(
                    f"demonstrations[{index}] has D = {y.shape[1]} but the demonstration has D = "
                    f"{self.demonstration.shape[1]}"
                )

    def all_demonstrations(self) -> list[np.ndarray]:
        """The demonstration and the further ones; with none further, the demonstration and 5
        noisy copies of it (:func:`bidmp.baselines.augment`, the GMM baselines' data)."""
        if self.demonstrations:
            return [self.demonstration, *self.demonstrations]
        from ...baselines import augment

        return list(augment(self.demonstration, 5, 1.5, self.seed % (2**31)))

    def shared_model(self, key, build: Callable) -> tuple[object, float]:
        """``(model, seconds)``: ``build()`` the first time ``key`` is asked for, the same model after."""
        if key not in self.shared:
            start = time.perf_counter()
            model = build()
            self.shared[key] = (model, time.perf_counter() - start)
        return self.shared[key]

    def fitted_dmp(self, **overrides) -> tuple[object, float]:
        """The task's DMP (a :class:`bidmp.CartesianDMP` for poses) fitted on the demonstration,
        with ``overrides`` of its parameters; shared by every method that asks for the same."""
        params = {**self.dmp, **overrides}

        def build():
            from ...primitives.dmp import DMP

            if self.poses:
                from ...primitives.cartesian import CartesianDMP

                return CartesianDMP(DMP(**params)).fit(self.demonstration)
            return DMP(**params).fit(self.demonstration)

        return self.shared_model(("dmp", tuple(sorted(params.items()))), build)


class Method:
    """A way to learn from one demonstration and reach new goals; subclass it and register one
    instance (:func:`bidmp.tasks.methods.register`).

    Class attributes say where it can run: ``poses`` (it learns pose demonstrations),
    ``closed_loop`` (it has a :meth:`stepper` for the simulator's closed loop), ``settles`` (its
    rollouts run past the demonstrated duration to come to rest: the LASA benchmark compares the
    first T samples and takes the end point from the last), ``requires`` (an optional package it
    needs; without it the method is skipped with a note) and ``lasa`` (run by default in the LASA
    benchmark), ``repairs`` (the pipeline's own method: :func:`bidmp.evaluate` repairs its motions
    that break the contract, from its skills; the other methods are reported as they are, for
    comparison).
    """

    name: str = ""
    repairs: bool = False  # the pipeline's method: a motion that breaks the contract is repaired (bidmp.tasks.repair)
    poses: bool = False
    closed_loop: bool = False
    settles: bool = False
    requires: str | None = None
    lasa: bool = True

    def fit(self, task: Task) -> tuple[object, float]:
        """``(model, seconds)``: the model learned for ``task`` and the seconds it took (shared
        models included)."""
        raise NotImplementedError

    def rollout(self, model, goal: np.ndarray) -> np.ndarray:
        """The motion (n, D) to ``goal`` (D,), on the demonstration's sample grid."""
        raise NotImplementedError

    def rollouts(self, model, goals: np.ndarray) -> list[np.ndarray]:
        """The motions to every goal (G, D); override when a batch is cheaper than a loop."""
        return [self.rollout(model, goal) for goal in checked_goals(goals)]

    def check_model(self, model, kinds: tuple, what: str) -> None:
        """Refuse a ``model`` that is not what :meth:`fit` returns (``kinds``, described as ``what``)."""
        kinds = kinds if isinstance(kinds, tuple) else (kinds,)
        if not kinds or not all(isinstance(kind, type) for kind in kinds):
            raise TypeError(
                f"kinds must be a class or a tuple of classes, got {_short_token(kinds, 30)}"
            )
        check_text(what, "what")
        if not isinstance(model, kinds):
            raise TypeError(
                f"model must be {what}, what method {self.name!r}'s fit returns, got {type(model).__name__}"
            )

    def stepper(self, model, goal: np.ndarray, duration: float, coupling):
        """A control-loop stepper to ``goal`` (methods with ``closed_loop`` only)."""
        raise NotImplementedError(f"method {self.name!r} has no stepper for closed-loop control")

    def available(self) -> bool:
        """Whether what it ``requires`` is installed."""
        if self.requires is None:
            return True
        import importlib.util

        return importlib.util.find_spec(self.requires) is not None
