"""The motions of a :class:`~bidmp.primitives.dmp.DMP`: rollouts on the normalised grid (one goal or
many), timed trajectories in seconds and the control-loop stepper (a mixin: each prepares the
goal-free part of the affine rollout once and adds the goal's share)."""

from __future__ import annotations

import numpy as np

from .._checks import as_point, check_int, numerically_guarded
from .forcing import _check_forcing_increment
from .grid import _rollout_grid
from .integrate import _check_integration, _unit_responses
from .protocols import _Params
from .rollouts import _iter_rollouts_to, _rollouts_to
from .stepper import DMPStepper
from .timed import _coupled_trajectory, _limited_trajectory, _timed_trajectory
from .via import _via_trajectory

__all__ = ["Motions"]


class Motions:
    """Rollouts, trajectories and the stepper of a fitted DMP (mixed into
    :class:`~bidmp.primitives.dmp.DMP`)."""

    def _rollout_params(self, step: float | None = None, params: _Params | None = None) -> _Params:
        """The validated parameters, with the rollout's integration checked for stability."""
        self._check_fitted()
        params = self._params() if params is None else params  # validated once per rollout
        _check_integration(self.dt_ if step is None else step, params)
        return params

    def _prepare(
        self, start, start_velocity, n_steps, forcing_increment=None, *, params=None, step=None
    ):
        _check_forcing_increment(forcing_increment)
        params = self._rollout_params(step) if params is None else params
        step = self.dt_ if step is None else step
        n_dims = self.weights_.shape[1]
        n_steps = self._n_steps(n_steps, params)
        start = self.start_ if start is None else as_point(start, n_dims, "start")
        velocity = (
            None if start_velocity is None else as_point(start_velocity, n_dims, "start_velocity")
        )
        phase, basis, (goal_response, start_response, velocity_response), gate = _rollout_grid(
            self, params, n_steps, step
        )
        change = getattr(
            forcing_increment, "weight_change", None
        )  # via-points: a change of the weights
        forcing = basis @ (self.weights_ if change is None else self.weights_ + change)
        if change is not None:
            forcing_increment = forcing_increment.wrapped
        if forcing_increment is not None:
            forcing = forcing + forcing_increment(phase, basis)
        free = _unit_responses(params, phase, forcing, step).T
        free += np.outer(start_response, start)
        if start_velocity is not None:
            free += np.outer(velocity_response, velocity)
        # lfilter runs in C, outside NumPy's floating-point checks: check its output once. With
        # these finite and the goals bounded (max_abs_value), y = free + B g cannot overflow.
        if not (np.all(np.isfinite(free)) and np.all(np.isfinite(goal_response))):
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
        """Generate a trajectory on the normalised grid, one sample every ``dt_`` (``duration_ /
        (T - 1)`` seconds at ``tau = 1``), with the protocol's integrator (robot: exact; paper:
        explicit Euler, Eq. 14).

        Parameters
        ----------
        goal : array-like, shape (D,), optional
            Goal position; default the demonstration's last point.
        start : array-like, shape (D,), optional
            Start position; default the demonstration's first point.
        n_steps : int, optional
            Number of samples, including the start; default :meth:`default_n_steps`
            (paper: ``round(tau · T)``, the fixed horizon, the phase ends at ≈ e⁻¹; robot:
            ``round(1.1 · tau · T)``, converged). Use more steps to let a paper DMP converge.
            For samples in seconds use :meth:`trajectory`.
        start_velocity : array-like, shape (D,), optional
            Initial velocity in units per unit of normalised time (:meth:`trajectory` takes units/s); default at rest.
        forcing_increment : callable, optional
            ``forcing_increment(phase (n,), basis (n, N)) -> (n, D)`` added to the learned forcing
            term on the rollout grid (how :class:`bidmp.BiDMP` adds its learned increments).

        Returns
        -------
        y : array, shape (n_steps, D)
        """
        free, goal_response, *_ = self._prepare(start, start_velocity, n_steps, forcing_increment)
        goal = self.goal_ if goal is None else as_point(goal, free.shape[1], "goal")
        return free + np.outer(goal_response, goal)

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
        """Rollouts to many goals for about the cost of one (the rollout is affine in the goal).

        Parameters
        ----------
        goals : array-like, shape (G, D)
        start, n_steps, start_velocity, forcing_increment
            As in :meth:`rollout`, shared by every goal.
        out : array, shape (G, n_steps, D), optional
            Where to write the rollouts (float64, writable), e.g. a ``numpy.memmap`` from
            ``numpy.lib.format.open_memmap`` for more rollouts than fit in memory; it is filled a
            chunk of goals at a time. Without ``out`` the result is one array, refused over
            ``max_array_bytes`` (see :func:`bidmp.set_limits`); :meth:`iter_rollouts` yields chunks
            instead.

        Returns
        -------
        y : array, shape (G, n_steps, D)
            ``y[i]`` equals ``rollout(goals[i], start, n_steps)`` up to rounding (``out`` if given).
        """
        free, goal_response, *_ = self._prepare(start, start_velocity, n_steps, forcing_increment)
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
        """Rollouts to many goals, ``chunk_size`` goals at a time (for more than fit in memory).

        Yields
        ------
        (first, y) : int and array (g, n_steps, D)
            ``y[i]`` is the rollout to ``goals[first + i]``; ``g <= chunk_size``.
        """
        chunk_size = check_int(chunk_size, "chunk_size", minimum=1)
        with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
            free, goal_response, *_ = self._prepare(
                start, start_velocity, n_steps, forcing_increment
            )
        yield from _iter_rollouts_to(goals, free, goal_response, chunk_size)

    # -- real time -------------------------------------------------------------------------------
    @numerically_guarded
    def trajectory(
        self,
        goal=None,
        *,
        start=None,
        duration: float | None = None,
        dt: float | None = None,
        limits: dict | None = None,
        start_velocity=None,
        forcing_increment=None,
        coupling=None,
        via=None,
        via_until: float | None = None,
    ):
        """A timed rollout: positions, velocities and accelerations in seconds.

        Parameters
        ----------
        goal, start : array (D,), optional
            Default: the demonstration's goal and start (in ``units_``).
        duration : float, optional
            Duration of the motion in seconds (temporal scaling: the shape is kept and time
            stretched, like ``execution_time`` in movement_primitives); default ``tau ·
            duration_``. With ``protocol="robot"`` the trajectory runs 1.1x this long, so that it
            reaches its goal and comes to rest.
        dt : float, optional
            Sample period in seconds; default the demonstration's (``duration_ / (T - 1)``).
        limits : dict, optional
            ``{"max_velocity": ..., "max_acceleration": ..., "max_jerk": ..., "norm": "norm" |
            "axis", "fastest": False}`` (units/s, /s², /s³). Caps: a motion that breaks one is
            slowed (uniformly) to the shortest duration that meets them all; one within them runs
            as demonstrated, unless ``"fastest": True`` asks for the shortest duration within the
            limits, faster than demonstrated. ``duration`` is then ignored.
        start_velocity : array (D,), optional
            Initial velocity in units/s (default at rest).
        forcing_increment : callable, optional
            As in :meth:`rollout` (how :class:`bidmp.BiDMP` adds its increments).
        coupling : list of coupling terms, optional
            ``coupling(t, y, yd, phase) -> acceleration`` (units/s², see
            :mod:`bidmp.primitives.coupling`): the motion is integrated step by step with their
            accelerations added. Without them (default) the fast path runs; an empty list runs the
            step integrator, which gives the same samples to rounding.
        via : list of (t, point), optional
            Via-points: the motion passes ``point`` (D,) (units) at ``t`` seconds exactly (on the
            samples, linearly between them), by the least-norm change of the forcing weights
            (:mod:`bidmp.primitives.via`). Points past the horizon, more than the kernels, or
            ones the kernels cannot carry raise ``ValueError``; with ``limits`` the motion is not
            re-timed (the points would move in time) but checked, and one that breaks a limit
            raises. With spatial coupling terms the uncoupled motion passes the points exactly.
        via_until : float, optional
            With ``via``: only the kernels that act (99 % of their activation) before this time (s)
            change, so after it the motion returns to its own course (a lift over a part that keeps
            the final approach and where the motion comes to rest); default every kernel. With it,
            the motion's end is the caller's to judge (without it, via-points that would leave the
            motion off its goal or moving at its end are refused).

        Returns
        -------
        bidmp.Trajectory
            ``t`` from 0 (s), ``y`` (units), ``yd`` (units/s), ``ydd`` (units/s²), each (n, D).
            Exact integrator (robot): ``yd`` and ``ydd`` are the system's own state and
            acceleration at each sample (the same continuous motion at any ``dt``). Euler (paper):
            ``yd[l] = (y[l+1] - y[l]) / dt`` exactly (the explicit-Euler state), likewise ``ydd``.
        """
        self._check_fitted()
        _check_forcing_increment(forcing_increment)  # every path below takes it
        if via is not None:
            return _via_trajectory(
                self,
                goal,
                start,
                duration,
                dt,
                limits,
                start_velocity,
                forcing_increment,
                coupling,
                via,
                via_until,
            )
        if limits is not None:
            return _limited_trajectory(
                self, goal, start, dt, limits, start_velocity, forcing_increment, coupling
            )
        if coupling is not None:
            return _coupled_trajectory(
                self, goal, start, duration, dt, start_velocity, forcing_increment, coupling
            )
        return _timed_trajectory(self, goal, start, duration, dt, start_velocity, forcing_increment)

    def stepper(
        self,
        goal=None,
        *,
        start=None,
        duration: float | None = None,
        coupling=0.0,
        start_velocity=None,
        forcing_increment=None,
    ) -> DMPStepper:
        """A step-by-step integrator for a robot's control loop (see :class:`DMPStepper`).

        ``coupling`` is a list of coupling terms (:mod:`bidmp.primitives.coupling`), or a number:
        ``alpha_e`` of phase stopping (Ijspeert et al. 2013) in 1/units², the system's time running
        ``1 + alpha_e ‖y_measured - y‖²`` times slower while the robot lags, so a held robot makes the
        motion pause rather than run away. 0 turns it off.
        """
        return DMPStepper(self, goal, start, duration, coupling, start_velocity, forcing_increment)
