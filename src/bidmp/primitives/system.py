"""A fitted discrete DMP as one immutable system: settings, components and what was learned, with
the rollout paths as its methods.

:class:`DMPSystem` is what :class:`bidmp.DMP` (and through it :class:`bidmp.MultiDMP`,
:class:`bidmp.BiDMP`'s skills, the timed rollout, via-points and the control-loop stepper) rolls
out: the resolved :class:`~bidmp.primitives.settings.DMPSettings` (with the canonical system, the
basis and the integrator they choose), the goal system, the weights and the demonstration's grid.
It is built from a fitted DMP by :meth:`bidmp.DMP.system` at the DMP's ``tau``; :meth:`with_tau`
gives the same system at another temporal scaling. Nothing in it changes; the rollout grid it last
used (phase, basis rows, unit responses, goal gate: none depends on the weights) is cached with it
and shared by every system of the same fit.

For fixed weights the rollout is affine in the goal and the start (``y = free + B g``, see
:mod:`bidmp.primitives.dmp`), so :meth:`free_response` returns the part without the goal and the
goal's unit response, and :meth:`rollout_many` reaches many goals with one outer product each.
"""

from __future__ import annotations

import numpy as np

from .._checks import (
    _as_bounded_array,
    _check_finite,
    as_point,
    as_vector,
    check_bytes,
    check_int,
    check_real,
    numerically_guarded,
)
from .._kernels import all_finite
from .forcing import _check_forcing_increment
from .goals import DelayedGoal, PhaseGate, ProgressGate, _learned_progress_gate
from .grid import _Caches
from .integrate import StepIntegrator, _check_integration, _unit_responses
from .rollouts import _iter_rollouts_to, _rollouts_to
from .settings import DMPSettings

__all__ = ["DMPSystem"]

_FIELDS = (
    "settings",
    "weights",
    "start",
    "goal",
    "n_samples",
    "duration",
    "centres",
    "widths",
    "goal_gate",
)


class DMPSystem:
    """A fitted discrete DMP: its settings, weights and demonstration grid, immutable.

    Parameters
    ----------
    settings : DMPSettings
        The resolved settings (gains, integrator, goal rule, canonical system, basis, ``tau``).
    weights : array, shape (N, D)
        The forcing term's weights, N = ``settings.n_kernels``.
    start, goal : array, shape (D,)
        The demonstration's start and goal (units).
    n_samples : int
        T, the demonstration's samples (≥ 3); the normalised grid's step is ``1 / T``.
    duration : float
        The demonstration's duration in seconds.
    centres, widths : array, shape (N,)
        The kernels' centres (phases in (0, 1]) and widths (> 0).
    goal_gate : array, shape (n_train,), optional
        The learned progress gate on the training grid: required when ``settings.goal_rate`` is
        None (the robot protocol), refused otherwise.

    Attributes
    ----------
    dt : float
        The normalised grid's step ``1 / T``.
    time_unit : float
        Seconds per unit of normalised time, ``duration · T / (T - 1)``.
    n_train : int
        Samples of the training grid: T (paper) or ``round(settle · T)`` (robot).
    n_dims : int
        D.

    Notes
    -----
    Immutable as a description: no field can be set. The arrays are not copied (a fitted DMP
    builds a system for every rollout, on its own arrays), so a system reads what its model holds.
    """

    __slots__ = (*_FIELDS, "dt", "_caches")

    def __init__(  # noqa: PLR0913 - a system is these nine parts, each checked
        self,
        settings: DMPSettings,
        weights,
        start,
        goal,
        n_samples: int,
        duration: float,
        centres,
        widths,
        goal_gate=None,
    ) -> None:
        if not isinstance(settings, DMPSettings):
            raise TypeError(f"settings must be a DMPSettings, got {type(settings).__name__}")
        n_samples = check_int(n_samples, "n_samples", minimum=3, limit="max_samples")
        weights = _as_bounded_array(weights, "weights", max_ndim=2)
        if weights.ndim != 2 or weights.shape[0] != settings.n_kernels or weights.shape[1] < 1:
            raise ValueError(
                f"weights must have shape ({settings.n_kernels}, D) for these settings' "
                f"{settings.n_kernels} kernels, got {weights.shape}"
            )
        _check_finite(weights, "weights")
        n_dims = weights.shape[1]
        centres = as_vector(centres, "centres", length=settings.n_kernels, positive=True)
        if np.any(centres > 1.0):
            raise ValueError("centres must lie in (0, 1] (they are phases)")
        fields = {
            "settings": settings,
            "weights": weights,
            "start": as_point(start, n_dims, "start"),
            "goal": as_point(goal, n_dims, "goal"),
            "n_samples": n_samples,
            "duration": check_real(duration, "duration", positive=True, maximum=1e7),
            "centres": centres,
            "widths": as_vector(widths, "widths", length=settings.n_kernels, positive=True),
            "goal_gate": None,
        }
        if settings.goal_rate is None:
            n_train = max(int(round(settings.settle * n_samples)), n_samples)
            if goal_gate is None:
                raise ValueError(
                    "goal_gate is required when settings.goal_rate is None (the goal follows the "
                    "demonstration's progress)"
                )
            fields["goal_gate"] = as_vector(goal_gate, "goal_gate", length=n_train)
        elif goal_gate is not None:
            raise ValueError(
                f"goal_gate is the learned progress gate of settings with goal_rate=None; these "
                f"settings' goal is delayed at goal_rate={settings.goal_rate:g}: leave it out"
            )
        self._set(fields, _Caches())

    @classmethod
    def _of(cls, fields: dict, caches: _Caches) -> DMPSystem:
        """A system of checked fields (every rollout builds one: no re-check)."""
        system = object.__new__(cls)
        system._set(fields, caches)
        return system

    def _set(self, fields: dict, caches: _Caches) -> None:
        for name in _FIELDS:
            object.__setattr__(self, name, fields[name])
        object.__setattr__(self, "dt", 1.0 / fields["n_samples"])
        object.__setattr__(self, "_caches", caches)

    def __setattr__(self, name, value) -> None:
        raise AttributeError(f"a DMPSystem is immutable: {name} cannot be set")

    def __reduce__(self):
        # pickle and copy rebuild it from its fields (its grid cache is made again when used)
        return _system_from_fields, ({name: getattr(self, name) for name in _FIELDS},)

    def __repr__(self) -> str:
        s = self.settings
        return (
            f"DMPSystem({s.protocol} protocol, {s.integrator} integrator, N={s.n_kernels}, "
            f"D={self.n_dims}, T={self.n_samples}, duration={self.duration:g} s, tau={s.tau:g})"
        )

    # -- what it is ----------------------------------------------------------------------------
    @property
    def n_dims(self) -> int:
        return self.weights.shape[1]

    @property
    def canonical_system(self):
        """The phase (:class:`~bidmp.primitives.canonical.CanonicalSystem`) its settings chose."""
        return self.settings.canonical_system

    @property
    def basis(self):
        """The forcing term's basis (:class:`~bidmp.primitives.forcing.Basis`) its settings chose."""
        return self.settings.basis

    def step_integrator(self) -> StepIntegrator:
        """The transformation system one step at a time (exact or Euler, as the settings say) at
        this system's ``tau``: what a control loop integrates; with no coupling it gives the
        rollouts' samples (:class:`~bidmp.primitives.stepper.DMPStepper`)."""
        settings = self.settings
        return StepIntegrator(settings.alpha, settings.beta, settings.tau, settings.exact)

    @property
    def time_unit(self) -> float:
        return self.duration * self.n_samples / (self.n_samples - 1)

    @property
    def n_train(self) -> int:
        return max(int(round(self.settings.settle * self.n_samples)), self.n_samples)

    def with_tau(self, tau: float) -> DMPSystem:
        """The same system at temporal scaling ``tau`` (the shape kept, time stretched)."""
        return self._at(self.settings.with_tau(tau))

    def _at(self, settings: DMPSettings) -> DMPSystem:
        """This system with ``settings`` (checked by the caller), sharing its caches."""
        if settings is self.settings:
            return self
        fields = {name: getattr(self, name) for name in _FIELDS}
        fields["settings"] = settings
        return DMPSystem._of(fields, self._caches)

    def goal_system(
        self, settings: DMPSettings | None = None
    ) -> PhaseGate | DelayedGoal | ProgressGate:
        """The goal system (:mod:`bidmp.primitives.goals`) for ``settings`` (default the system's
        own): the phase gate, a delayed goal, or the learned progress gate (cached)."""
        if settings is not None and not isinstance(settings, DMPSettings):
            raise TypeError(
                f"goal_system: settings must be a DMPSettings (or None), got {type(settings).__name__}"
            )
        settings = self.settings if settings is None else settings
        if settings.goal_rate is not None:
            gate_class = PhaseGate if settings.goal_rate == settings.alpha_phase else DelayedGoal
            return gate_class(settings.goal_rate)
        # cached: a control loop asks for it once per stepper
        key = (self.n_train, self.dt, settings.canonical_system)
        cached = self._caches.goal_system
        if cached is None or cached[0] != key or cached[1].gate is not self.goal_gate:
            cached = (key, _learned_progress_gate(self, settings))
            self._caches.goal_system = cached
        return cached[1]

    # -- grids -----------------------------------------------------------------------------------
    def rollout_length(self, n_steps: int | None = None) -> int:
        """``n_steps`` checked, or the default rollout length ``round(settle · tau · T)`` (paper:
        T at ``tau = 1``; robot: 1.1 T, time for any goal to be reached)."""
        if n_steps is None:
            n_steps = max(int(round(self.settings.settle * self.settings.tau * self.n_samples)), 1)
            check_int(n_steps, "the default rollout length round(tau * T)", limit="max_steps")
        else:
            n_steps = check_int(n_steps, "n_steps", minimum=1, limit="max_steps")
        check_bytes(n_steps * self.centres.shape[0], "the rollout basis (n_steps x n_kernels)")
        return n_steps

    def check_step(self, step: float | None = None) -> None:
        """Refuse a normalised grid step (default ``dt``) on which this system's integration is
        unstable (explicit Euler) or out of range."""
        self._checked_step(step)

    def _checked_step(self, step: float | None) -> float:
        """``step`` (default ``dt``) checked as a number and for the integrator; returned."""
        step = self.dt if step is None else check_real(step, "step", positive=True)
        _check_integration(step, self.settings)
        return step

    def phase(self, n_steps: int | None = None) -> np.ndarray:
        """Phase at each rollout sample, shape ``(n_steps,)`` (default :meth:`rollout_length`)."""
        settings = self.settings
        return settings.canonical_system.grid(self.rollout_length(n_steps), self.dt, settings.tau)

    def grid(self, n_steps: int | None = None, step: float | None = None) -> tuple[np.ndarray, ...]:
        """On the grid of ``n_steps`` samples ``step`` apart in normalised time (defaults
        :meth:`rollout_length`, ``dt``): the phase (n,), the basis rows (n, N), the unit
        responses ``[B, C, V]`` (3, n) of goal, start and start velocity, and the goal gate (n,).
        Cached (the last grid used)."""
        step = self._checked_step(step)
        entry = self._caches.entry(self, self.rollout_length(n_steps), step)
        return entry.phase, entry.basis, entry.responses, entry.gate

    def basis_rows(self, phase) -> np.ndarray:
        """Basis rows ``phi(phase)`` of shape ``(L, N)`` (the Bi-DMP's BLS input)."""
        settings = self.settings
        phase = settings.canonical_system.as_phase(phase)
        check_bytes(
            np.size(phase) * len(self.centres), "the basis rows at phase (phases x kernels)"
        )
        return settings.basis.rows(phase, self.centres, self.widths)

    def forcing_term(self, phase) -> np.ndarray:
        """The learned forcing term ``f(phase) = phi(phase) @ weights``, shape ``(L, D)``."""
        return self.basis_rows(phase) @ self.weights

    @numerically_guarded
    def endpoint_gain(self, n_steps: int | None = None) -> float:
        """End-point gain ``c``: the final error for a shifted goal is ``c · ‖g' - g‖``, with
        ``c = |1 - B[n_steps - 1]|`` (``B`` the goal's unit response)."""
        self.check_step()
        settings = self.settings
        n_steps = self.rollout_length(n_steps)
        cached = self._caches.cached(self, n_steps, self.dt)
        if cached is not None:
            goal_response = cached.responses[0]
        else:  # B needs no basis matrix, and other horizons should not evict the cached grid
            phase = settings.canonical_system.grid(n_steps, self.dt, settings.tau)
            gate = self.goal_system().on_grid(phase, self.dt, settings.tau, settings.exact)
            goal_response = _unit_responses(settings, phase, None, self.dt, gate)[0]
        return float(abs(1.0 - goal_response[-1]))

    # -- rollouts --------------------------------------------------------------------------------
    def free_response(
        self,
        n_steps: int | None = None,
        *,
        start=None,
        start_velocity=None,
        forcing_increment=None,
        step: float | None = None,
    ) -> tuple[np.ndarray, ...]:
        """The rollout without its goal, and what the goal adds.

        Parameters
        ----------
        n_steps : int, optional
            Samples (default :meth:`rollout_length`).
        start : array (D,), optional
            Default the demonstration's start.
        start_velocity : array (D,), optional
            Units per unit of normalised time (default at rest).
        forcing_increment : callable, optional
            ``(phase (n,), basis (n, N)) -> (n, D)`` added to the learned forcing term (or a
            via-point change: an object with ``weight_change`` (N, D) and ``wrapped``).
        step : float, optional
            The normalised grid step (default ``dt``), checked for the integrator.

        Returns
        -------
        free : array (n, D)
            The rollout to a zero goal (units).
        goal_response : array (n,)
            ``B``: the rollout to ``goal`` is ``free + outer(B, goal)``.
        forcing : array (n, D)
            The forcing term on the grid (learned plus increment).
        gate : array (n,)
            The goal gate on the grid.
        """
        _check_forcing_increment(forcing_increment)
        step = self._checked_step(step)
        n_dims = self.weights.shape[1]
        n_steps = self.rollout_length(n_steps)
        start = self.start if start is None else as_point(start, n_dims, "start")
        velocity = (
            None if start_velocity is None else as_point(start_velocity, n_dims, "start_velocity")
        )
        grid = self._caches.entry(self, n_steps, step)
        phase, basis, gate = grid.phase, grid.basis, grid.gate
        goal_response, start_response, velocity_response = grid.responses
        # via-points: a change of the weights
        change = getattr(forcing_increment, "weight_change", None)
        forcing = grid.forcing(self.weights if change is None else self.weights + change)
        if change is not None:
            forcing_increment = forcing_increment.wrapped
        if forcing_increment is not None:
            forcing = forcing + forcing_increment(phase, basis)
        free = _unit_responses(self.settings, phase, forcing, step).T
        free += start_response[:, None] * start  # the outer product, without np.outer's ravels
        if velocity is not None:
            free += velocity_response[:, None] * velocity
        # The integration runs compiled, outside NumPy's floating-point checks: check its output
        # once. With these finite and the goals bounded (max_abs_value), y = free + B g cannot overflow.
        if not (all_finite(free) and all_finite(goal_response[:, None])):
            raise ValueError(
                "rollout: the integration is not finite; the inputs' scale or the forcing increment is out of range"
            )
        return free, goal_response, forcing, gate

    @numerically_guarded
    def rollout(
        self,
        goal=None,
        *,
        start=None,
        n_steps: int | None = None,
        start_velocity=None,
        forcing_increment=None,
    ) -> np.ndarray:
        """Positions (n_steps, D) on the normalised grid, one sample every ``dt`` (see
        :meth:`bidmp.DMP.rollout`; the arguments are its)."""
        free, goal_response, *_ = self.free_response(
            n_steps, start=start, start_velocity=start_velocity, forcing_increment=forcing_increment
        )
        goal = self.goal if goal is None else as_point(goal, free.shape[1], "goal")
        return free + goal_response[:, None] * goal

    @numerically_guarded
    def rollout_many(
        self,
        goals,
        *,
        start=None,
        n_steps: int | None = None,
        start_velocity=None,
        forcing_increment=None,
        out: np.ndarray | None = None,
    ) -> np.ndarray:
        """Rollouts to many goals (G, D) → (G, n_steps, D) for about the cost of one (see
        :meth:`bidmp.DMP.rollout_many`)."""
        free, goal_response, *_ = self.free_response(
            n_steps, start=start, start_velocity=start_velocity, forcing_increment=forcing_increment
        )
        return _rollouts_to(goals, free, goal_response, out)

    def iter_rollouts(
        self,
        goals,
        *,
        chunk_size: int = 1024,
        start=None,
        n_steps: int | None = None,
        start_velocity=None,
        forcing_increment=None,
    ):
        """Rollouts to many goals ``chunk_size`` at a time: yields ``(first, y)`` with ``y``
        (g, n_steps, D) the rollouts to ``goals[first:first + g]``."""
        chunk_size = check_int(chunk_size, "chunk_size", minimum=1)
        with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
            free, goal_response, *_ = self.free_response(
                n_steps,
                start=start,
                start_velocity=start_velocity,
                forcing_increment=forcing_increment,
            )
        yield from _iter_rollouts_to(goals, free, goal_response, chunk_size)


def _system_of(model, settings: DMPSettings, caches: _Caches) -> DMPSystem:
    """The system of a fitted :class:`bidmp.DMP`'s learned state with ``settings`` (the model's
    own, checked), sharing ``caches`` with its other systems."""
    return DMPSystem._of(
        {
            "settings": settings,
            "weights": model.weights_,
            "start": model.start_,
            "goal": model.goal_,
            "n_samples": model.n_steps_,
            "duration": model.duration_,
            "centres": model.centres_,
            "widths": model.widths_,
            "goal_gate": model.__dict__.get("goal_gate_"),
        },
        caches,
    )


def _system_from_fields(fields: dict) -> DMPSystem:
    """A system again from its fields, as pickled (they were checked when it was made)."""
    return DMPSystem._of(fields, _Caches())
