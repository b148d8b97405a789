"""Bi-DMP: a DMP whose forcing term grows by Broad Learning System increments (SPEC §7, paper
Eq. 15, 27, 28), with a skill library so that earlier skills are not forgotten.

Learning an extended demonstration y_dn (resampled to the DMP's T samples and phase grid):

* ``F_target`` is Eq. 10 solved for the forcing term with y_dn (its own goal g_n and start);
* ``FI = F_target − f_in^{p−1}(ϑ)``: the increment over the forcing term learned so far, which
  also absorbs the DMP's fit residual (Eq. 15);
* a BLS maps the DMP basis row ``φ(ϑ)`` to ``FI`` (all D outputs jointly); its enhancement nodes
  are then added incrementally (Eq. 23–26);
* ``f_in^p(ϑ) = φ(ϑ)W + Σ_{q ≤ p} A^q(ϑ) W^q`` (Eq. 27–28).

**Why a skill library.** A forcing term that depends only on the phase encodes one shape. Eq. 28
therefore telescopes to the latest demonstration, and the earlier skills are overwritten unless
the query says which one to use. Skill p (0 = the plain DMP … P) uses the sum up to block p.
``rollout(goal, skill="nearest")`` picks the skill whose training goal is nearest the query;
``skill="latest"`` is the paper-literal behaviour (always everything), and it forgets.
"""

from __future__ import annotations

import logging
from dataclasses import dataclass

import numpy as np

from ._checks import as_point, as_trajectory, check_choice, check_fitted, check_int, check_real
from .bls import BLS
from .dmp import DMP, forcing_target
from .segmentation import resample_time

__all__ = ["BiDMP", "ForgettingResult", "forgetting", "forgetting_runs"]

logger = logging.getLogger(__name__)


class BiDMP:
    """A DMP with incrementally learned forcing-term blocks and a skill library (SPEC §7).

    Parameters
    ----------
    dmp : DMP
        A fitted DMP (skill 0). It is never modified.
    n_windows, n_mapped, n_enhance, shrink, reg
        Parameters of each BLS block (see :class:`bidmp.BLS`).
    increments : tuple of int, default (20, 20)
        Enhancement nodes added, one block after another, after each BLS is fitted (the
        incremental step of Eq. 23–26).
    seed : int, default 0
        Block p uses BLS seed ``seed + p``.
    derivatives : {"forward", "gradient", "dmp"}, default "forward"
        How y_dn is differentiated for F_target. Forward differences are what the explicit-Euler
        rollout integrates, so the learned skill reproduces its demonstration up to the BLS fit,
        end point included. ``np.gradient`` leaves a discretisation error at the goal (0.5 mm on
        the battery approach). ``"dmp"`` uses the DMP's own setting.

    Attributes
    ----------
    blocks_ : list of BLS
        One per learned demonstration.
    skill_goals_, skill_starts_ : array (n_skills, D)
        Training goal and start of every skill (row 0: the plain DMP's).
    """

    def __init__(
        self,
        dmp: DMP,
        n_windows: int = 10,
        n_mapped: int = 10,
        n_enhance: int = 100,
        increments: tuple[int, ...] = (20, 20),
        shrink: float = 0.8,
        reg: float = 1e-8,
        seed: int = 0,
        derivatives: str = "forward",
    ) -> None:
        if not isinstance(dmp, DMP):
            raise TypeError(f"dmp must be a bidmp.DMP, got {type(dmp).__name__}")
        check_fitted(dmp, "weights_")
        self.dmp = dmp
        self.n_windows = check_int(n_windows, "n_windows", minimum=1)
        self.n_mapped = check_int(n_mapped, "n_mapped", minimum=1)
        self.n_enhance = check_int(n_enhance, "n_enhance", minimum=1)
        self.increments = tuple(check_int(n, "increments", minimum=1) for n in increments)
        self.shrink = check_real(shrink, "shrink", positive=True)
        self.reg = check_real(reg, "reg", nonnegative=True)
        self.seed = check_int(seed, "seed", minimum=0)
        self.derivatives = check_choice(derivatives, "derivatives", ("forward", "gradient", "dmp"))
        self.blocks_: list[BLS] = []
        self.skill_goals_ = dmp.goal_[None].copy()
        self.skill_starts_ = dmp.start_[None].copy()

    def get_params(self) -> dict:
        return {
            "n_windows": self.n_windows, "n_mapped": self.n_mapped, "n_enhance": self.n_enhance,
            "increments": list(self.increments), "shrink": self.shrink, "reg": self.reg, "seed": self.seed,
            "derivatives": self.derivatives,
        }

    @property
    def n_skills(self) -> int:
        """Number of skills: 1 (the plain DMP) + one per learned demonstration."""
        return 1 + len(self.blocks_)

    def __repr__(self) -> str:
        return f"BiDMP(n_skills={self.n_skills}, {', '.join(f'{k}={v!r}' for k, v in self.get_params().items())})"

    # -- learning --------------------------------------------------------------------------------
    def forcing_term(self, phase, skill: int | None = None) -> np.ndarray:
        """``f_in`` of a skill (default: all blocks) at the given phases, shape (L, D)."""
        phase = np.asarray(phase, dtype=np.float64).reshape(-1)
        basis = self.dmp.basis(phase)
        return basis @ self.dmp.weights_ + self._increment(basis, self._check_skill_index(skill))

    def _increment(self, basis: np.ndarray, skill: int) -> np.ndarray:
        total = np.zeros((basis.shape[0], self.dmp.n_dims_))
        for block in self.blocks_[:skill]:
            total += block.predict(basis)
        return total

    def learn(self, y_dn) -> "BiDMP":
        """Learn an extended demonstration as a new skill (Eq. 15, 27, 28). Returns self.

        Parameters
        ----------
        y_dn : array (T', D)
            Uniform in time, same D as the DMP; resampled to the DMP's T samples. Its last point
            is the skill's goal, its first the skill's start.
        """
        dmp = self.dmp
        y = as_trajectory(y_dn, "y_dn")
        if y.shape[1] != dmp.n_dims_:
            raise ValueError(f"y_dn has D = {y.shape[1]} but the DMP has D = {dmp.n_dims_}")
        y = resample_time(y, dmp.n_steps_)
        phase, basis = dmp.grid_basis()
        target = forcing_target(
            y, phase, dt=dmp.dt_, tau=dmp.tau, alpha=dmp.alpha, beta=dmp.beta_value, K=dmp.K_value,
            derivatives=dmp.derivatives if self.derivatives == "dmp" else self.derivatives,
        )
        current = basis @ dmp.weights_ + self._increment(basis, len(self.blocks_))
        return self.learn_increment(target - current, goal=y[-1], start=y[0])

    def learn_increment(self, forcing_increment, goal, start=None) -> "BiDMP":
        """Lower level of :meth:`learn`: fit one BLS block to a given forcing increment FI.

        Parameters
        ----------
        forcing_increment : array (T, D)
            FI on the DMP's phase grid.
        goal, start : array (D,)
            The new skill's training goal and start (start defaults to the DMP's).
        """
        dmp = self.dmp
        increment = np.asarray(forcing_increment, dtype=np.float64)
        if increment.shape != (dmp.n_steps_, dmp.n_dims_):
            raise ValueError(f"forcing_increment must have shape {(dmp.n_steps_, dmp.n_dims_)}, got {increment.shape}")
        if not np.all(np.isfinite(increment)):
            raise ValueError("forcing_increment contains NaN or inf")
        goal = as_point(goal, dmp.n_dims_, "goal")
        start = dmp.start_ if start is None else as_point(start, dmp.n_dims_, "start")
        _, basis = dmp.grid_basis()
        block = BLS(
            n_windows=self.n_windows, n_mapped=self.n_mapped, n_enhance=self.n_enhance, shrink=self.shrink,
            reg=self.reg, seed=self.seed + len(self.blocks_) + 1,
        ).fit(basis, increment)
        for n_nodes in self.increments:
            block.add_enhancement_nodes(n_nodes)
        self.blocks_.append(block)
        self.skill_goals_ = np.vstack([self.skill_goals_, goal])
        self.skill_starts_ = np.vstack([self.skill_starts_, start])
        logger.debug("learned skill %d (goal %s)", len(self.blocks_), goal)
        return self

    # -- generation ------------------------------------------------------------------------------
    def _check_skill_index(self, skill) -> int:
        if skill is None:
            return len(self.blocks_)
        if isinstance(skill, (bool, np.bool_)) or not isinstance(skill, (int, np.integer)):
            raise ValueError(f"skill must be 'nearest', 'latest' or an integer 0-{len(self.blocks_)}, got {skill!r}")
        if not 0 <= skill <= len(self.blocks_):
            raise ValueError(f"skill must be between 0 and {len(self.blocks_)} (this Bi-DMP has {self.n_skills} skills), got {skill}")
        return int(skill)

    def select_skill(self, goal, skill="nearest") -> int:
        """The skill index used for a query: ``"nearest"`` (training goal nearest ``goal``; ties:
        the later skill), ``"latest"`` or an explicit integer."""
        if isinstance(skill, str):
            if skill == "latest":
                return len(self.blocks_)
            if skill == "nearest":
                goal = as_point(goal, self.dmp.n_dims_, "goal")
                distances = np.linalg.norm(self.skill_goals_ - goal, axis=1)
                return int(len(distances) - 1 - np.argmin(distances[::-1]))
            raise ValueError(f"skill must be 'nearest', 'latest' or an integer, got {skill!r}")
        return self._check_skill_index(skill)

    def rollout(self, goal=None, skill="nearest", start=None, n_steps: int | None = None) -> np.ndarray:
        """Generate a trajectory with one skill of the library.

        Parameters
        ----------
        goal : array (D,), optional
            Default: the selected skill's training goal (for "nearest": the latest skill's).
        skill : "nearest" (default), "latest" or int
        start : array (D,), optional
            Default: the selected skill's training start.
        n_steps : int, optional
            Default: the DMP's T.

        Returns
        -------
        y : array (n_steps, D). Skill 0 is exactly ``dmp.rollout`` (bit for bit).
        """
        query = self.skill_goals_[-1] if goal is None else as_point(goal, self.dmp.n_dims_, "goal")
        index = self.select_skill(query, skill)
        goal = self.skill_goals_[index] if goal is None else query
        start = self.skill_starts_[index] if start is None else start
        if index == 0:
            return self.dmp.rollout(goal=goal, start=start, n_steps=n_steps)
        return self.dmp.rollout(
            goal=goal, start=start, n_steps=n_steps,
            forcing_increment=lambda phase, basis: self._increment(basis, index),
        )

    # -- persistence -----------------------------------------------------------------------------
    def _get_state(self) -> tuple[dict, dict]:
        dmp_meta, dmp_arrays = self.dmp._get_state()
        arrays = {f"dmp/{k}": v for k, v in dmp_arrays.items()}
        arrays["skill_goals_"] = self.skill_goals_
        arrays["skill_starts_"] = self.skill_starts_
        blocks_meta = []
        for index, block in enumerate(self.blocks_):
            meta, block_arrays = block._get_state()
            blocks_meta.append(meta)
            arrays.update({f"block{index}/{k}": v for k, v in block_arrays.items()})
        return {"params": self.get_params(), "dmp": dmp_meta, "blocks": blocks_meta}, arrays

    @classmethod
    def _from_state(cls, meta: dict, arrays: dict) -> "BiDMP":
        def part(prefix: str) -> dict:
            return {k[len(prefix):]: v for k, v in arrays.items() if k.startswith(prefix)}

        dmp = DMP._from_state(meta["dmp"], part("dmp/"))
        params = dict(meta["params"])
        params["increments"] = tuple(params["increments"])
        model = cls(dmp, **params)
        model.blocks_ = [BLS._from_state(block_meta, part(f"block{index}/")) for index, block_meta in enumerate(meta["blocks"])]
        goals = np.asarray(arrays["skill_goals_"], dtype=np.float64)
        starts = np.asarray(arrays["skill_starts_"], dtype=np.float64)
        expected = (len(model.blocks_) + 1, dmp.n_dims_)
        if goals.shape != expected or starts.shape != expected:
            raise ValueError(f"skill goals/starts have shapes {goals.shape}/{starts.shape}, expected {expected}")
        model.skill_goals_, model.skill_starts_ = goals, starts
        return model


# ---------------------------------------------------------------------------------------------
# Forgetting (SPEC §7)
# ---------------------------------------------------------------------------------------------
@dataclass
class ForgettingResult:
    """Errors of every skill after each learning step.

    ``errors[p, j]`` is the RMSE of ``rollout(g_p, skill)`` against demonstration p after
    learning demonstration j (NaN before p is learned). Row 0 is the original skill (the plain
    DMP's own reproduction, before anything is learned: column 0). ``forgetting[p] =
    errors[p, -1] − errors[p, p]``.
    """

    skill: str
    errors: np.ndarray  # (P + 1, P + 1)
    forgetting: np.ndarray  # (P + 1,)

    def to_dict(self) -> dict:
        return {"skill": self.skill, "errors": np.where(np.isnan(self.errors), None, self.errors).tolist(),
                "forgetting": self.forgetting.tolist()}


def forgetting_runs(dmp: DMP, demonstrations, skills=("nearest", "latest"), **bidmp_params) -> dict:
    """:func:`forgetting` for several skill rules from one learning pass: {skill: ForgettingResult}."""
    model = BiDMP(dmp, **bidmp_params)
    references = [dmp.rollout()]
    n_skills = len(demonstrations) + 1
    errors = {skill: np.full((n_skills, n_skills), np.nan) for skill in skills}

    def measure(column: int) -> None:
        for skill in skills:
            for p in range(column + 1):
                rollout = model.rollout(model.skill_goals_[p], skill=skill, start=model.skill_starts_[p])
                errors[skill][p, column] = float(np.sqrt(np.mean(np.sum((rollout - references[p]) ** 2, axis=1))))

    measure(0)
    for index, demonstration in enumerate(demonstrations, start=1):
        model.learn(demonstration)
        references.append(resample_time(as_trajectory(demonstration, "demonstration"), dmp.n_steps_))
        measure(index)
    return {
        skill: ForgettingResult(skill=str(skill), errors=matrix, forgetting=matrix[:, -1] - np.diag(matrix))
        for skill, matrix in errors.items()
    }


def forgetting(dmp: DMP, demonstrations, skill="nearest", **bidmp_params) -> ForgettingResult:
    """Learn ``demonstrations`` (each (T', D)) in turn into a fresh Bi-DMP and measure forgetting.

    The reference of skill 0 is the DMP's own rollout; of skill p, demonstration p resampled to
    the DMP's T. Each skill is queried at its training goal and start with ``skill``.
    """
    return forgetting_runs(dmp, demonstrations, (skill,), **bidmp_params)[skill]
