"""Bi-DMP: a DMP whose forcing term grows by Broad Learning System increments (paper
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

import copy
import logging
from dataclasses import dataclass

import numpy as np

from .._api import Estimator, clone, integer, real
from .._checks import (
    NotFittedError,
    _as_float_array,
    as_point,
    as_trajectory,
    check_bool,
    check_choice,
    check_int,
    check_limit,
    check_real,
    check_text,
    numerically_guarded,
    short_token,
)
from .._state import state_reader
from .._threads import single_threaded
from .._trajectory import resample_time, rmse
from ..primitives.dmp import DMP
from .bidmp_state import _bidmp_parts, _bidmp_state, _restore_skills
from .bls import BLS

__all__ = ["BiDMP", "ForgettingResult", "forgetting", "forgetting_runs"]

logger = logging.getLogger(__name__)


def _derivative_rule(derivatives: str, params) -> str:
    """How y_dn is differentiated: ``"auto"`` is what the DMP's integrator integrates (forward
    differences for explicit Euler; the DMP's own, central by default, for the exact one)."""
    if derivatives == "auto":
        return "forward" if params.integrator == "euler" else params.derivatives
    return params.derivatives if derivatives == "dmp" else derivatives


# a skill lasts between a thousandth and a thousand times the demonstration
_TIME_SCALES = (
    1e-3,
    1e3,
)


def _time_scale(duration, dmp: DMP) -> float:
    """A skill's time scale: ``duration`` (s) over the demonstration's, 1 when not given."""
    if duration is None:
        return 1.0
    duration = check_real(duration, "duration", positive=True)
    scale = duration / dmp.duration_
    if not _TIME_SCALES[0] <= scale <= _TIME_SCALES[1]:
        raise ValueError(
            f"duration {duration:.4g} s is {scale:.3g} times the demonstration's {dmp.duration_:.4g} s; "
            f"a skill may last {_TIME_SCALES[0]:g} to {_TIME_SCALES[1]:g} times it"
        )
    return float(scale)


_DERIVATIVES = ("auto", "forward", "gradient", "dmp")


def _template(value, name: str) -> None:
    """The Bi-DMP's ``dmp``: None (a DMP of the defaults) or a :class:`bidmp.DMP`."""
    if value is not None and not isinstance(value, DMP):
        raise TypeError(f"{name} must be a bidmp.DMP, got {type(value).__name__}")


def _increments(value, name: str) -> None:
    """The enhancement nodes each later block adds: a sequence of positive integers."""
    if not isinstance(value, (tuple, list)):
        raise TypeError(f"{name} must be a sequence of integers, got {type(value).__name__}")
    check_limit(len(value), "max_hidden_nodes", f"the number of {name}")
    for n in value:
        check_int(n, name, minimum=1, limit="max_hidden_nodes")


class BiDMP(Estimator):
    """A DMP with incrementally learned forcing-term blocks and a skill library.

    A scikit-learn style estimator: ``BiDMP(dmp)`` only stores its parameters (``get_params``
    includes the DMP's as ``dmp__alpha`` …). The model starts from a fitted ``dmp`` at the first
    :meth:`learn` (the DMP is used as skill 0 and never modified), or from a demonstration with
    :meth:`fit`, which fits a copy of ``dmp``.

    **The increments vanish with the phase.** Block p is a BLS trained on
    ``FI_p(ϑ) / ϑ`` over the phases of the DMP's training grid, and the increment is
    ``ϑ · BLS_p(φ(clip(ϑ)))`` with ``ϑ`` clipped to that range. Like the DMP's own forcing term
    (``f = ϑ Σ w ψ / Σ ψ``) it therefore decays to 0 as the phase does, and the BLS is never
    evaluated outside the phases it was trained on. Every skill, rolled out long enough,
    converges to its goal exactly as the plain DMP does.

    Parameters
    ----------
    dmp : DMP, default None
        Skill 0. ``None`` means ``DMP()`` (then call :meth:`fit`).
    n_windows, n_mapped, n_enhance, shrink
        Parameters of each BLS block (see :class:`bidmp.BLS`).
    reg : float, default 1e-4
        Ridge λ of each block's output weights. The hidden nodes are nearly collinear, so a
        smaller λ buys little accuracy with huge, cancelling weights: on the nut task λ = 1e-8
        gave weights up to 1.7e5 and a reproduction RMSE of 0.025 mm, λ = 1e-4 weights up to 3.7e3
        and 0.068 mm (``benchmarks/bidmp_convergence.py``; λ does not depend on the length unit:
        the ridge solution is linear in FI).
    increments : tuple of int, default (20, 20)
        Enhancement nodes added, one block after another, after each BLS is fitted (the
        incremental step of Eq. 23–26).
    seed : int, default 0
        Block p uses BLS seed ``seed + p``.
    derivatives : {"auto", "forward", "gradient", "dmp"}, default "auto"
        How y_dn is differentiated for F_target. ``"auto"``: what the DMP's integrator integrates.
        Forward differences for explicit Euler (paper), so the learned skill reproduces its
        demonstration up to the BLS fit, end point included (``np.gradient`` there leaves a
        discretisation error at the goal: 0.5 mm on the battery approach); for the exact
        integrator (robot) the DMP's own rule, central differences, the continuous system's
        derivatives. ``"dmp"`` always uses the DMP's own setting.

    Attributes
    ----------
    dmp_ : DMP
        The fitted DMP in use (skill 0).
    blocks_ : list of BLS
        One per learned demonstration.
    skill_goals_, skill_starts_ : array (n_skills, D)
        Training goal and start of every skill (row 0: the plain DMP's).
    skill_time_scales_ : array (n_skills,)
        Each skill's duration over the demonstration's (row 0: 1): skill p runs with
        ``tau = dmp_.tau · skill_time_scales_[p]``.
    gate_phase_ : float
        The increments are ``min(ϑ / gate_phase_, 1) · BLS(...)``: 1 for the paper protocol (the
        increment is ``ϑ · BLS``), the phase at the end of the demonstrated motion for the robot
        protocol (whose phase decays to e^-4: dividing FI by it would amplify the end of the
        motion 50-fold and ruin the fit; with this gate the increment is learned as it is during
        the motion and still vanishes with the phase during the rest after it).
    phase_min_ : float
        The smallest phase of the training grid; below it the BLS input is held at this phase.
    """

    def __init__(  # noqa: PLR0913 - an estimator's constructor: each hyperparameter is one (scikit-learn)
        self,
        dmp: DMP | None = None,
        n_windows: int = 10,
        n_mapped: int = 10,
        n_enhance: int = 100,
        increments: tuple[int, ...] = (20, 20),
        shrink: float = 0.8,
        reg: float = 1e-4,
        seed: int = 0,
        derivatives: str = "auto",
    ) -> None:
        self.dmp = dmp
        self.n_windows = n_windows
        self.n_mapped = n_mapped
        self.n_enhance = n_enhance
        self.increments = increments
        self.shrink = shrink
        self.reg = reg
        self.seed = seed
        self.derivatives = derivatives

    def check_params(self) -> None:
        """Check the parameters as they are now, as :meth:`fit` and :meth:`learn` do; raise naming
        the first bad one (for a caller that holds a Bi-DMP's settings before it has a DMP: a
        scenario's options, a pose Bi-DMP's template)."""
        self._check_params()

    _parameter_constraints = {
        "dmp": _template,
        "n_windows": integer(minimum=1, limit="max_hidden_nodes"),
        "n_mapped": integer(minimum=1, limit="max_hidden_nodes"),
        "n_enhance": integer(minimum=1, limit="max_hidden_nodes"),
        "increments": _increments,
        "shrink": real(positive=True, maximum=1e6),
        "reg": real(nonnegative=True, maximum=1e6),
        "seed": integer(minimum=0, maximum=2**62),
        "derivatives": lambda value, name: check_choice(value, name, _DERIVATIVES),
    }

    def _check_params(self) -> tuple[tuple[int, ...], str]:
        """Validate the parameters; return the increments and the derivative rule."""
        self._check_constraints()
        increments = tuple(int(n) for n in self.increments)
        check_limit(
            int(self.n_windows) * int(self.n_mapped) + int(self.n_enhance) + sum(increments),
            "max_hidden_nodes",
            "the hidden nodes of one block, n_windows * n_mapped + n_enhance + sum(increments)",
        )
        return increments, self.derivatives

    def __sklearn_is_fitted__(self) -> bool:
        return "dmp_" in self.__dict__ or (
            isinstance(self.dmp, DMP) and self.dmp.__sklearn_is_fitted__()
        )

    def _start(self, dmp: DMP) -> None:
        """Skill 0 only: the plain DMP."""
        phase, _ = dmp.training_grid()
        self.dmp_ = dmp
        self.blocks_ = []
        self.skill_goals_ = dmp.goal_[None].copy()
        self.skill_starts_ = dmp.start_[None].copy()
        self.skill_time_scales_ = np.ones(1)
        self.phase_min_ = float(phase.min())
        # 1 for the paper protocol (bit for bit the ϑ-gated increment), else the phase at the last
        # sample of the demonstrated motion.
        self.gate_phase_ = (
            1.0 if dmp.settings().protocol == "paper" else float(phase[dmp.n_steps_ - 1])
        )

    def check_fitted(self) -> None:
        """Raise :class:`bidmp.NotFittedError`, saying what to do, unless the model has its skill
        0 (fitted, or built on a fitted DMP) and that DMP is still fitted with the parameters it
        has now."""
        self._ensure_started()
        self.dmp_.check_fitted()

    def _ensure_started(self) -> None:
        if "dmp_" in self.__dict__:
            return
        if not isinstance(self.dmp, DMP) or not self.dmp.__sklearn_is_fitted__():
            raise NotFittedError(
                "this BiDMP is not fitted yet: pass a fitted DMP (BiDMP(DMP().fit(y))) or call fit(y) first"
            )
        self._check_params()
        self._start(self.dmp)

    @single_threaded  # small dense algebra: idle BLAS threads only steal the core
    def fit(self, y) -> BiDMP:
        """Fit a copy of ``dmp`` (default ``DMP()``) on the demonstration ``y`` (T, D) as skill 0,
        forgetting every learned skill. Returns self."""
        self._check_params()
        dmp = clone(self.dmp) if self.dmp is not None else DMP()
        self._start(dmp.fit(y))
        return self

    @property
    def n_skills(self) -> int:
        """Number of skills: 1 (the plain DMP) + one per learned demonstration."""
        self._ensure_started()
        return 1 + len(self.blocks_)

    @property
    def system_(self):
        """Skill 0, the plain DMP, as a :class:`~bidmp.primitives.system.DMPSystem`: a skill's
        rollout is this system's with the skill's forcing increment."""
        self._ensure_started()
        return self.dmp_.system_

    @property
    def n_dims_(self) -> int:
        """Number of dimensions D of the skills."""
        self._ensure_started()
        return self.dmp_.n_dims_

    @numerically_guarded
    @single_threaded  # small dense algebra: idle BLAS threads only steal the core
    def learn(
        self,
        y_dn,
        *,
        duration: float | None = None,
        allow_static: bool = False,
        called: str = "y_dn",
    ) -> BiDMP:
        """Learn an extended demonstration as a new skill (Eq. 15, 27, 28). Returns self.

        Parameters
        ----------
        y_dn : array (T', D)
            Uniform in time, same D as the DMP; resampled to the DMP's T samples. Its last point
            is the skill's goal, its first the skill's start.
        duration : float, optional
            How long ``y_dn`` lasts, in seconds (the DMP's time base: ``duration_``). The skill
            then runs that long (its time scale ``duration / dmp_.duration_``, see
            ``skill_time_scales_``): a longer extension is not rushed into the demonstration's
            time. Default: the demonstration's own duration (the paper's protocol).
        allow_static : bool, default False
            Accept a ``y_dn`` that does not move: for a part of a model whose other part moves
            (a pose skill that only turns, or only moves), which holds its place.
        called : str, default "y_dn"
            What the messages call ``y_dn`` (a part of another model: "poses' orientation").
        """
        still, name = check_bool(allow_static, "allow_static"), check_text(called, "called")
        self._ensure_started()
        increments, derivatives = self._check_params()
        time_scale = _time_scale(duration, self.dmp_)
        dmp = self.dmp_
        params = dmp.settings()
        y = as_trajectory(y_dn, name, allow_static=still)
        if y.shape[1] != dmp.n_dims_:
            raise ValueError(f"{name} has D = {y.shape[1]} but the DMP has D = {dmp.n_dims_}")
        # T samples (and, robot protocol, rest at the goal after them)
        y = dmp.training_trajectory(y)
        phase, basis = dmp.training_grid()
        target = dmp.forcing_target(y, derivatives=_derivative_rule(derivatives, params))
        current = basis @ dmp.weights_ + self._increment(phase, basis, len(self.blocks_))
        return self._learn_block(target - current, y[-1], y[0], increments, time_scale)

    def learn_increment(self, forcing_increment, goal, start=None) -> BiDMP:
        """Lower level of :meth:`learn`: fit one BLS block to a given forcing increment FI.

        Parameters
        ----------
        forcing_increment : array (T, D)
            FI on the DMP's training grid (:meth:`DMP.training_grid`).
        goal, start : array (D,)
            The new skill's training goal and start (start defaults to the DMP's).
        """
        self._ensure_started()
        dmp = self.dmp_
        increment = _as_float_array(forcing_increment, "forcing_increment")
        if increment.shape != (dmp.n_train_, dmp.n_dims_):
            raise ValueError(
                f"forcing_increment must have shape {(dmp.n_train_, dmp.n_dims_)}, got {increment.shape}"
            )
        if not np.all(np.isfinite(increment)):
            raise ValueError("forcing_increment contains NaN or inf")
        goal = as_point(goal, dmp.n_dims_, "goal")
        start = dmp.start_ if start is None else as_point(start, dmp.n_dims_, "start")
        increments, _ = self._check_params()
        return self._learn_block(increment, goal, start, increments)

    def _learn_block(
        self,
        increment: np.ndarray,
        goal: np.ndarray,
        start: np.ndarray,
        increments: tuple[int, ...],
        time_scale: float = 1.0,
    ) -> BiDMP:
        """Fit one BLS block to a validated FI (T, D), grow it by ``increments`` nodes and add
        the skill (goal, start)."""
        dmp = self.dmp_
        phase, basis = dmp.training_grid()
        inputs = self._bls_input(phase, basis)
        # the increment is gate · BLS: learn FI / gate
        block = BLS(
            n_windows=self.n_windows,
            n_mapped=self.n_mapped,
            n_enhance=self.n_enhance,
            shrink=self.shrink,
            reg=self.reg,
            seed=self.seed + len(self.blocks_) + 1,
        ).fit(inputs, increment / self._gate(phase)[:, None])
        for n_nodes in increments:
            block.add_enhancement_nodes(n_nodes)
        self.blocks_.append(block)
        self.skill_goals_ = np.vstack([self.skill_goals_, goal])
        self.skill_starts_ = np.vstack([self.skill_starts_, start])
        self.skill_time_scales_ = np.append(self.skill_time_scales_, time_scale)
        logger.debug("learned skill %d (goal %s)", len(self.blocks_), goal)
        return self

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

    def query(self, goal=None, *, skill="nearest", start=None) -> tuple:
        """What a rollout to ``goal`` runs, as :meth:`rollout` resolves it: for a control loop or
        a rollout of one's own (``dmp.stepper(goal, start=start, forcing_increment=increment)``).

        Parameters
        ----------
        goal, start : array (D,), optional
            Default: the chosen skill's own goal and start.
        skill : "nearest", "latest" or int
            As :meth:`select_skill`.

        Returns
        -------
        (index, goal, start, increment, dmp)
            The skill's index; the goal and start (D,); its forcing increment
            ``(phase, basis) -> (n, D)`` (None for skill 0, the plain DMP); the DMP that runs it
            (``dmp_``, or a copy timed for a skill learned at another duration).
        """
        return self._skill_query(goal, skill, start)

    def _skill_query(self, goal, skill, start):
        """:meth:`query` (the rollouts' own call)."""
        self._ensure_started()
        n_dims = self.dmp_.n_dims_
        query = self.skill_goals_[-1] if goal is None else as_point(goal, n_dims, "goal")
        index = self.select_skill(query, skill)
        goal = self.skill_goals_[index] if goal is None else query
        start = self.skill_starts_[index] if start is None else as_point(start, n_dims, "start")
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
    def trajectory(  # noqa: PLR0913 - the public call spells its options out, as users pass them
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

    # -- persistence (used by bidmp.io) --------------------------------------------------------
    def to_state(self) -> tuple[dict, dict]:
        """The model-file form of the fitted model, ``(meta, arrays)``: its parameters and scalars
        as a JSON-able dict, its learned arrays by name (:func:`bidmp.io.save_model` writes the two
        into one ``.npz``; no pickle). Raises :class:`bidmp.NotFittedError` before ``fit``."""
        self._ensure_started()
        return _bidmp_state(self)

    @classmethod
    @state_reader
    def from_state(cls, meta: dict, arrays) -> BiDMP:
        """The fitted model :meth:`to_state` described: ``meta`` as written, ``arrays`` a mapping of
        name to array, each read when needed and checked for dtype, shape and finiteness
        (:func:`bidmp.io.load_model` calls it; a bad file raises, naming the member)."""
        dmp, params = _bidmp_parts(meta, arrays)
        model = cls(dmp, **params)
        model.check_params()
        model._start(dmp)
        _restore_skills(model, meta, arrays)
        return model


# ---------------------------------------------------------------------------------------------
# Forgetting
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
        return {
            "skill": self.skill,
            "errors": np.where(np.isnan(self.errors), None, self.errors).tolist(),
            "forgetting": self.forgetting.tolist(),
        }


def forgetting_runs(
    dmp: DMP | BiDMP, demonstrations, skills=("nearest", "latest"), **bidmp_params
) -> dict:
    """:func:`forgetting` for several skill rules from one learning pass: {skill: ForgettingResult}.

    ``dmp`` may also be a :class:`BiDMP` with no learned skill yet: the demonstrations are then
    learned into it (so the caller keeps the model; ``bidmp_params`` must be empty).
    """
    if not isinstance(dmp, (DMP, BiDMP)):
        raise TypeError(
            f"dmp must be a fitted bidmp.DMP (or an empty BiDMP), got {type(dmp).__name__}"
        )
    if not isinstance(demonstrations, (list, tuple)):
        raise TypeError(
            f"demonstrations must be a list of arrays (T', D), got {type(demonstrations).__name__}"
        )
    check_limit(len(demonstrations), "max_targets", "demonstrations: the number of skills to learn")
    demonstrations = [
        as_trajectory(y, f"demonstrations[{index}]") for index, y in enumerate(demonstrations)
    ]
    if not isinstance(skills, (list, tuple)) or not skills:
        raise TypeError(
            f"skills must be a list of skill rules ('nearest', 'latest' or indices), got {short_token(skills, 30)}"
        )
    for skill in skills:
        if not (isinstance(skill, str) and skill in ("nearest", "latest")) and (
            isinstance(skill, bool) or not isinstance(skill, int)
        ):
            raise ValueError(
                f"skill must be 'nearest', 'latest' or an integer, got {type(skill).__name__}"
            )
    if isinstance(dmp, BiDMP):
        if bidmp_params:
            raise TypeError(
                "bidmp_params cannot be combined with a BiDMP model (set them on the model)"
            )
        model = dmp
        model._ensure_started()
        if model.blocks_:
            raise ValueError(
                f"the BiDMP given already has {len(model.blocks_)} learned skill(s); forgetting starts from none"
            )
        dmp = model.dmp_
    else:
        model = BiDMP(dmp, **bidmp_params)
        model._ensure_started()
    # Compared over the demonstration's T samples (a robot-protocol rollout rests 0.1 T longer).
    references = [dmp.rollout()[: dmp.n_steps_]]
    n_skills = len(demonstrations) + 1
    errors = {skill: np.full((n_skills, n_skills), np.nan) for skill in skills}

    def measure(column: int) -> None:
        for skill in skills:
            for p in range(column + 1):
                rollout = model.rollout(
                    model.skill_goals_[p], skill=skill, start=model.skill_starts_[p]
                )
                errors[skill][p, column] = rmse(rollout[: dmp.n_steps_], references[p])

    measure(0)
    for index, demonstration in enumerate(demonstrations, start=1):
        model.learn(demonstration, called=f"demonstrations[{index - 1}]")
        references.append(resample_time(demonstration, dmp.n_steps_))
        measure(index)
    return {
        skill: ForgettingResult(
            skill=str(skill), errors=matrix, forgetting=matrix[:, -1] - np.diag(matrix)
        )
        for skill, matrix in errors.items()
    }


def forgetting(dmp: DMP, demonstrations, skill="nearest", **bidmp_params) -> ForgettingResult:
    """Learn ``demonstrations`` (each (T', D)) in turn into a fresh Bi-DMP and measure forgetting.

    The reference of skill 0 is the DMP's own rollout; of skill p, demonstration p resampled to
    the DMP's T. Each skill is queried at its training goal and start with ``skill``.
    """
    return forgetting_runs(dmp, demonstrations, (skill,), **bidmp_params)[skill]


def _shown(skill) -> str:
    """A rejected skill for a message: a short quote of a string, else its type."""
    from .._checks import short_token

    return short_token(skill) if isinstance(skill, str) else type(skill).__name__
