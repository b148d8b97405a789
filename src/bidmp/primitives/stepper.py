"""The control-loop stepper: a DMP (or a Bi-DMP skill) integrated one control step at a time,
with coupling terms (:mod:`bidmp.primitives.coupling`)."""

from __future__ import annotations

import logging

import numpy as np

from .._checks import as_point, check_real
from .canonical import _TAU_RANGE
from .coupling import _as_couplings
from .goal_shift import _goal_complete_time, _GoalShifts, _shortest_blend

__all__ = ["DMPStepper"]

logger = logging.getLogger(__name__)


_SHORTEST_BLEND = 1e-6  # s


class DMPStepper:
    """Integrates a DMP (or a Bi-DMP skill) one control step at a time.

    ``step(dt, y_measured=None)`` returns the command ``(y, yd, ydd)`` for the current sample (units,
    units/s, units/s²) and advances the state by ``dt`` seconds. Without coupling terms the
    commands equal :meth:`DMP.trajectory` sample for sample (the same integration steps, exact or
    Euler). Coupling terms (``coupling``: a list of ``coupling(t, y, yd, phase) -> acceleration``)
    add their acceleration over each step. A number as ``coupling`` is the gain of phase
    stopping (:class:`bidmp.primitives.coupling.PhaseStopping`): with a measurement the system's
    time runs ``1 + coupling ‖y_measured - y‖²`` times slower, so a robot held back makes the
    command pause where it is, and the motion resumes once it catches up.

    Attributes
    ----------
    phase : float
        The canonical state ``ϑ``.
    time : float
        The motion's own time in seconds (slower than the wall clock while paused).
    """

    def __init__(
        self, dmp, goal, start, duration, coupling, start_velocity, forcing_increment
    ) -> None:
        if not callable(getattr(dmp, "goal_system", None)):  # DMP.stepper() passes itself
            raise TypeError(
                f"dmp must be a fitted bidmp.DMP (DMP.stepper() builds its stepper), got {type(dmp).__name__}"
            )
        system = dmp.system_
        self._dmp = dmp
        n_dims = system.n_dims
        self.goal = system.goal.copy() if goal is None else as_point(goal, n_dims, "goal")
        self.start = system.start.copy() if start is None else as_point(start, n_dims, "start")
        motion = (
            system.settings.tau * system.duration
            if duration is None
            else check_real(duration, "duration", positive=True)
        )
        # tau of the normalised system
        self._scale = check_real(
            motion / system.duration,
            "duration / duration_ (the temporal scaling)",
            minimum=_TAU_RANGE[0],
            maximum=_TAU_RANGE[1],
        )
        self._system = system = system.with_tau(self._scale)
        params = system.settings
        self._couplings, self._temporal = _as_couplings(coupling)
        self._forcing_increment = forcing_increment
        self.y = self.start.copy()
        velocity = (
            np.zeros(n_dims)
            if start_velocity is None
            else as_point(start_velocity, n_dims, "start_velocity")
        )
        self._z = velocity * system.time_unit * self._scale  # z = tau ẏ in normalised time
        # What every step reads, taken once: a control loop should not revalidate the model.
        self._centres, self._widths, self._weights = system.centres, system.widths, system.weights
        self._canonical, self._basis = params.canonical_system, params.basis
        self._goal_system = system.goal_system()
        self._time_unit = system.time_unit
        self._integrator = system.step_integrator()
        # (phase, gate, goal, start, u): the end of one step starts the next
        self._last_input = None
        self.phase = self._canonical.initial
        self._gate = 1.0
        self._gate = self._goal_system.follow(
            1.0, self.phase, 0.0, self._scale, params.exact, check_input=False
        )
        self.time = 0.0
        self._shifts = _GoalShifts(n_dims)
        # the motion time its own goal offset completes (set_goal asks for it)
        self._complete = None
        self._peaks = None  # the motion's own peaks (set_goal without limits asks for them)
        # terms that need the motion (a scene's avoidance: its goal, its scale)
        for term in self._couplings:
            if hasattr(term, "bind"):
                term.bind(self)

    @property
    def model(self):
        """The fitted model this stepper runs (a :class:`bidmp.DMP` or a Bi-DMP skill's)."""
        return self._dmp

    @property
    def system(self):
        """The :class:`~bidmp.primitives.system.DMPSystem` it integrates, at the motion's ``tau``."""
        return self._system

    @property
    def forcing_increment(self):
        """The forcing increment added to the learned forcing term (None: none)."""
        return self._forcing_increment

    @property
    def couplings(self) -> tuple:
        """The coupling terms acting on the motion."""
        return tuple(self._couplings)

    @property
    def position(self) -> np.ndarray:
        """The position the next :meth:`step` commands (D,): the state plus any moved goal's offset."""
        offset = self._shifts.at(self.time) if self._shifts else None
        return self.y.copy() if offset is None else self.y + offset[0]

    @property
    def horizon(self) -> float:
        """The motion's own time (s) at which it is complete: its duration times the protocol's
        horizon (the robot protocol's 1.1, within which it comes to rest; the paper's 1, its fixed
        horizon)."""
        return float(self._system.settings.settle * self._scale * self._system.duration)

    @property
    def target(self) -> np.ndarray:
        """The goal the motion ends at (D,): :attr:`goal` plus every :meth:`set_goal` offset."""
        return self.goal + self._shifts.total

    def set_goal(self, goal, *, limits: dict | None = None, blend: float | None = None) -> float:
        """Move the goal to ``goal`` (D,) (units) from now on, smoothly (see
        :mod:`bidmp.primitives.goal_shift`): the command is offset by the change along a
        7th-order smoothstep that ends where the DMP's own goal offset is complete (the final
        approach's start with ``keep_approach``), so the approach is a translated copy and the
        motion comes to rest at ``goal``.

        Parameters
        ----------
        goal : array (D,)
            The new goal (units).
        limits : dict, optional
            ``max_velocity`` / ``max_acceleration`` / ``max_jerk`` (units/s, /s², /s³): the blend
            is at least long enough that the offset alone uses a quarter of each. Default the
            motion's own peaks (its learned motion at this duration): a goal moved after the DMP's
            own goal share is complete still arrives smoothly, never in one step.
        blend : float, optional
            The blend's duration (s), in place of the one above.

        Returns
        -------
        float
            The blend's duration (s). A blend that ends after the final approach began tilts the
            approach: logged as a warning.
        """
        delta = as_point(goal, self.goal.shape[0], "goal") - self.target
        if blend is None:
            complete = self._goal_complete()
            blend = max(
                complete - self.time,
                _shortest_blend(delta, limits if limits is not None else self._own_peaks()),
            )
            if self.time + blend > complete + 1e-9 and np.any(delta != 0.0):
                logger.warning(
                    "set_goal at %.3f s: the goal's offset ends %.3f s after the final approach began; "
                    "the approach is not a translated copy",
                    self.time,
                    self.time + blend - complete,
                )
        else:
            blend = check_real(blend, "blend", nonnegative=True, maximum=1e6)
            if 0.0 < blend < _SHORTEST_BLEND:  # below it a blend's acceleration is not a number
                raise ValueError(
                    f"blend must be 0 (a jump) or at least {_SHORTEST_BLEND:g} s, got {blend:g}"
                )
        self._shifts.add(delta, self.time, blend)
        return float(blend)

    def _own_peaks(self) -> dict:
        """The peak speed, acceleration and jerk (norms, units/s, /s², /s³) of the motion this
        stepper runs, without coupling: what a moved goal's blend keeps a quarter of, when no limits
        are given. Computed once."""
        if getattr(self, "_peaks", None) is None:
            motion = self._dmp.trajectory(
                self.goal,
                start=self.start,
                duration=self._scale * self._system.duration,
                forcing_increment=self._forcing_increment,
            )
            jerk = np.gradient(motion.ydd, motion.t, axis=0)
            tiny = 1e-12 * max(float(np.ptp(motion.y)), 1e-300)
            self._peaks = {
                key: max(float(np.max(np.linalg.norm(values, axis=1))), tiny)
                for key, values in (
                    ("max_velocity", motion.yd),
                    ("max_acceleration", motion.ydd),
                    ("max_jerk", jerk),
                )
            }
        return self._peaks

    def _goal_complete(self) -> float:
        """The motion time (s) from which the DMP's own goal offset is complete."""
        if self._complete is None:
            system = self._system  # its grid checks the step
            n_steps = (
                int(np.ceil(system.settings.settle * self._scale * (system.n_samples - 1))) + 2
            )
            goal_response = system.grid(n_steps)[2][0]
            self._complete = _goal_complete_time(goal_response, system.dt * system.time_unit)
        return self._complete

    @property
    def coupling(self) -> float:
        """The phase-stopping gain (0 without phase stopping)."""
        return sum(getattr(term, "gain", 0.0) for term in self._temporal)

    def _input(self, phase: float, gate: float) -> np.ndarray:
        """The system's input ``u = αβ g + K f(phase) - K gate (g - y0)`` (D,)."""
        last = self._last_input
        if (
            last is not None
            and last[0] == phase
            and last[1] == gate
            and (last[2] == self.goal).all()
            and (last[3] == self.start).all()
        ):
            return last[4]
        params = self._system.settings
        basis = self._basis.row(phase, self._centres, self._widths)
        forcing = basis @ self._weights
        if self._forcing_increment is not None:
            forcing = forcing + self._forcing_increment(np.array([phase]), basis)
        value = params.alpha * params.beta * self.goal + params.K * (
            forcing[0] - gate * (self.goal - self.start)
        )
        self._last_input = (phase, gate, self.goal.copy(), self.start.copy(), value)
        return value

    def step(self, dt: float, y_measured=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The command for now, then advance ``dt`` seconds (less while the robot lags).

        Returns
        -------
        (y, yd, ydd) : arrays (D,)
            Position (units), velocity (units/s) and acceleration (units/s²) to command.
        """
        # the usual case checked in one comparison
        if not (type(dt) is float and 1e-6 <= dt <= 1e3):
            dt = check_real(dt, "dt", positive=True, minimum=1e-6, maximum=1e3)
        params = self._system.settings
        time_unit = self._time_unit
        slowdown = 1.0
        offset = self._shifts.at(self.time) if self._shifts else None
        commanded = self.y if offset is None else self.y + offset[0]
        for term in self._temporal:
            slowdown *= term.slowdown(commanded, y_measured)
        if y_measured is not None and not self._temporal:
            # read by no term (no phase stopping), but a measurement all the same: one that is
            # no point of the model is refused, not ignored
            as_point(y_measured, commanded.shape[0], "y_measured", like="y")
        step = dt / time_unit / slowdown  # the normalised time this control step advances
        alpha, beta, tau = params.alpha, params.beta, params.tau
        input_now = self._input(self.phase, self._gate)  # not cached: goal and start are public
        position = commanded.copy()
        # The command's velocity and acceleration, as trajectory() reports them: the system's own
        # (plus a moved goal's offset, whose time runs with the system's).
        velocity = self._z / (tau * time_unit) / slowdown
        if offset is not None:
            velocity = velocity + offset[1] / slowdown
        if self._couplings:
            # An acceleration a (units/s²) enters the input as a (tau T slowdown)², held over the step.
            terms = self._couplings
            pushed = (
                np.asarray(terms[0](self.time, position, velocity, self.phase), dtype=np.float64)
                if len(terms) == 1
                else sum(
                    np.asarray(term(self.time, position, velocity, self.phase), dtype=np.float64)
                    for term in terms
                )
            )
            push = pushed * (tau * time_unit * slowdown) ** 2
            if not np.all(np.isfinite(push)):
                raise ValueError("a coupling term returned a non-finite acceleration")
            input_now = input_now + push
        acceleration = (input_now - alpha * beta * self.y - alpha * self._z) / (
            tau * time_unit * slowdown
        ) ** 2
        if offset is not None:
            acceleration = acceleration + offset[2] / slowdown**2
        phase = self._canonical.advance(self.phase, step, tau)
        gate = self._goal_system.follow(
            self._gate, phase, step, tau, params.exact, check_input=False
        )
        input_next = self._input(phase, gate) if params.exact else input_now
        if self._couplings and params.exact:
            input_next = input_next + push
        self.y, self._z = self._integrator.step(
            self.y, self._z, input_now, input_next, step, check_input=False
        )
        self.phase, self._gate = phase, gate
        self.time += dt / slowdown
        return position, velocity, acceleration
