"""The skills of a :class:`~bidmp.incremental.bidmp.BiDMP`: the forcing term of each skill (the DMP's
plus the sum of the first p blocks' increments), which skill a query uses, and its rollouts,
trajectories and stepper (a mixin: these read the learned blocks and learn nothing)."""

from __future__ import annotations

import copy

import numpy as np

from .._checks import as_point, numerically_guarded

__all__ = ["SkillLibrary"]


class SkillLibrary:
    """Evaluating and querying the skills of a Bi-DMP (mixed into
    :class:`~bidmp.incremental.bidmp.BiDMP`)."""

    # -- learning --------------------------------------------------------------------------------
    def forcing_term(self, phase, skill: int | None = None) -> np.ndarray:
        """``f_in`` of a skill (default: all blocks) at the given phases, shape (L, D)."""
        self._ensure_started()
        basis = self.dmp_.basis(phase)  # validates the phases
        phase = np.asarray(phase, dtype=np.float64).reshape(-1)
        return basis @ self.dmp_.weights_ + self._increment(
            phase, basis, self._check_skill_index(skill)
        )

    def _gate(self, phase: np.ndarray) -> np.ndarray:
        """``min(ϑ / gate_phase_, 1)``: ϑ itself for the paper protocol (gate_phase_ = 1)."""
        if self.gate_phase_ == 1.0:
            return phase
        return np.minimum(phase / self.gate_phase_, 1.0)

    def _increment(self, phase: np.ndarray, basis: np.ndarray, skill: int) -> np.ndarray:
        """Sum of the first ``skill`` blocks' increments, ``ϑ · BLS(φ(clip(ϑ)))``, shape (L, D)."""
        total = np.zeros((phase.shape[0], self.dmp_.n_dims_))
        if skill == 0:
            return total
        # A skill's increment on a grid does not depend on the goal: rollouts to many goals on the
        # same grid (the same phase and basis objects, from the DMP's grid cache) compute it once.
        key = tuple(id(block.output_weights_) for block in self.blocks_[:skill])
        cache = self.__dict__.setdefault("_increments", {})
        hit = cache.get(skill)
        if hit is not None and hit[0] is phase and hit[1] is basis and hit[2] == key:
            return hit[3]
        clipped = np.clip(phase, self.phase_min_, 1.0)
        outside = clipped != phase
        if np.any(outside):  # never extrapolate in phase: hold the BLS input at the trained range
            basis = basis.copy()
            basis[outside] = self.dmp_.basis(clipped[outside])
        inputs = self._bls_input(clipped, basis)
        for block in self.blocks_[:skill]:
            total += block.predict(inputs)
        total *= self._gate(phase)[:, None]
        if phase.shape[0] > 1:  # a control loop's single phases are not worth keeping
            total.setflags(write=False)
            cache[skill] = (phase, basis, key, total)
        return total

    def _bls_input(self, phase: np.ndarray, basis: np.ndarray) -> np.ndarray:
        """The BLS input rows: the DMP basis ``φ = ϑ ψ̄`` (paper), or the normalised kernels
        ``ψ̄ = φ / ϑ`` (robot): with the phase decaying to e^-4 the rows ``φ`` shrink towards 0 at
        the end of the motion and the BLS could no longer tell those phases apart."""
        if self.gate_phase_ == 1.0:
            return basis
        return basis / phase[:, None]

    # -- generation ------------------------------------------------------------------------------
    def _check_skill_index(self, skill) -> int:
        if skill is None:
            return len(self.blocks_)
        if isinstance(skill, (bool, np.bool_)) or not isinstance(skill, (int, np.integer)):
            raise ValueError(
                f"skill must be 'nearest', 'latest' or an integer 0-{len(self.blocks_)}, got {_shown(skill)}"
            )
        if not 0 <= skill <= len(self.blocks_):
            raise ValueError(
                f"skill must be between 0 and {len(self.blocks_)} (this Bi-DMP has {self.n_skills} skills), "
                f"got {_shown(skill)}"
            )
        return int(skill)

    def select_skill(self, goal, skill="nearest") -> int:
        """The skill index used for a query: ``"nearest"`` (training goal nearest ``goal``; ties:
        the later skill), ``"latest"`` or an explicit integer."""
        self._ensure_started()
        if isinstance(skill, str):
            if skill == "latest":
                return len(self.blocks_)
            if skill == "nearest":
                goal = as_point(goal, self.dmp_.n_dims_, "goal")
                distances = np.linalg.norm(self.skill_goals_ - goal, axis=1)
                return int(len(distances) - 1 - np.argmin(distances[::-1]))
            raise ValueError(
                f"skill must be 'nearest', 'latest' or an integer, got {_shown(skill)}"
            )
        return self._check_skill_index(skill)

    def _skill_query(self, goal, skill, start):
        """(skill index, goal, start, forcing increment, DMP timed for the skill) of a query, as
        :meth:`rollout` resolves it."""
        self._ensure_started()
        query = self.skill_goals_[-1] if goal is None else as_point(goal, self.dmp_.n_dims_, "goal")
        index = self.select_skill(query, skill)
        goal = self.skill_goals_[index] if goal is None else query
        start = self.skill_starts_[index] if start is None else start
        increment = (
            None if index == 0 else (lambda phase, basis: self._increment(phase, basis, index))
        )
        return index, goal, start, increment, self._skill_dmp(index)

    def _skill_dmp(self, index: int):
        """The DMP that runs skill ``index``: ``dmp_`` itself, or for a skill learned from a
        demonstration of another duration a copy whose ``tau`` is ``dmp_.tau`` times the skill's
        time scale (the same weights and kernels, the whole skill slower or faster; the increments
        are learned on the phase, so they follow). Kept until ``dmp_.tau`` changes."""
        scale = float(self.skill_time_scales_[index])
        if scale == 1.0:
            return self.dmp_
        views = self.__dict__.setdefault("_timed_dmps", {})
        key = (index, scale, self.dmp_.tau)
        if key not in views:
            view = copy.copy(self.dmp_)  # its caches are keyed by tau: sharing them is safe
            view.tau = self.dmp_.tau * scale
            views[key] = view
        return views[key]

    @numerically_guarded
    def rollout(
        self, goal=None, *, skill="nearest", start=None, n_steps: int | None = None
    ) -> np.ndarray:
        """Generate a trajectory with one skill of the library.

        Parameters
        ----------
        goal : array (D,), optional
            Default: the selected skill's training goal (for "nearest": the latest skill's).
        skill : "nearest" (default), "latest" or int
        start : array (D,), optional
            Default: the selected skill's training start.
        n_steps : int, optional
            Default: the DMP's default horizon (:meth:`DMP.default_n_steps`).

        Returns
        -------
        y : array (n_steps, D). Skill 0 is exactly ``dmp_.rollout`` (bit for bit).
        """
        _, goal, start, increment, dmp = self._skill_query(goal, skill, start)
        # Skill 0 passes no increment: exactly the plain DMP's rollout.
        return dmp.rollout(goal=goal, start=start, n_steps=n_steps, forcing_increment=increment)

    @numerically_guarded
    def trajectory(
        self,
        goal=None,
        *,
        skill="nearest",
        start=None,
        duration: float | None = None,
        dt: float | None = None,
        limits: dict | None = None,
        coupling=None,
        via=None,
        via_until: float | None = None,
    ):
        """A timed rollout of one skill (see :meth:`bidmp.DMP.trajectory`): ``bidmp.Trajectory``
        with ``t`` (s), ``y``, ``yd``, ``ydd`` (units, /s, /s²); ``coupling`` terms and ``via``
        points as there (the skill's increment kept, the least-norm change added to it)."""
        _, goal, start, increment, dmp = self._skill_query(goal, skill, start)
        return dmp.trajectory(
            goal=goal,
            start=start,
            duration=duration,
            dt=dt,
            limits=limits,
            forcing_increment=increment,
            coupling=coupling,
            via=via,
            via_until=via_until,
        )

    def stepper(
        self, goal=None, *, skill="nearest", start=None, duration: float | None = None, coupling=0.0
    ):
        """A step-by-step integrator of one skill for a control loop (see :meth:`bidmp.DMP.stepper`)."""
        _, goal, start, increment, dmp = self._skill_query(goal, skill, start)
        return dmp.stepper(
            goal=goal,
            start=start,
            duration=duration,
            coupling=coupling,
            forcing_increment=increment,
        )


def _shown(skill) -> str:
    """A rejected skill for a message: a short quote of a string, else its type."""
    from .._checks import short_token

    return short_token(skill) if isinstance(skill, str) else type(skill).__name__
