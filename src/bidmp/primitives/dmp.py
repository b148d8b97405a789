"""Discrete Dynamic Movement Primitive (paper Eq. 10–14): the estimator, a thin
composition of the canonical system (:mod:`~bidmp.primitives.canonical`), the forcing term
(:mod:`~bidmp.primitives.forcing`), a goal system (:mod:`~bidmp.primitives.goals`) and the
integrators (:mod:`~bidmp.primitives.integrate`; coupling terms: :mod:`~bidmp.primitives.coupling`).

Transformation system (Pastor/Park form, no ``(g - y0)`` factor on the forcing term)::

    tau² ÿ = alpha (beta (g - y) - tau ẏ) + K f(phase) - K gate(phase) (g - y0)
    tau phase' = -alpha_phase phase,  phase(0) = 1
    f(phase) = phase · Σ_i w_i ψ_i(phase) / Σ_i ψ_i(phase),  ψ_i = exp(-h_i (phase - c_i)²)

on the normalised grid ``dt = 1/T`` (the demonstration's T samples span one unit of time), with
``z = tau ẏ``. Two integrators (:mod:`bidmp.primitives.integrate`):

* ``integrator="euler"`` (the paper's protocol): explicit Euler for exactly ``T`` steps,
  ``z[l+1] = z[l] + dt/tau · (alpha (beta (g - y[l]) - z[l]) + u[l])``, ``y[l+1] = y[l] + dt/tau · z[l]``
  — for ``tau = 1`` paper Eq. 14 to the letter, with the phase ``(1 - alpha_phase dt)^l``;
* ``integrator="exact"`` (the robot protocol): the continuous system integrated exactly with the
  input linear between samples and the phase ``exp(-alpha_phase t)``, so the same weights give
  the same motion at any control rate.

The goal gate is the phase (Eq. 10), an exponentially delayed goal, or the robot protocol's
progress gate (:mod:`bidmp.primitives.goals`).

**Why this module is fast.** For fixed weights the rollout is a linear time-invariant system
driven by ``u[l] = alpha beta g + K f(phase[l]) - K gate[l] (g - y0)``, so the trajectory is
affine in the goal and the start::

    y(g, y0) = a + B g + C y0        (a: (n, D);  B, C: (n,), the same for every dimension)

Either integrator is a second-order recursion in ``y``, which one compiled loop (the numbers of
:func:`scipy.signal.lfilter`) runs for all dimensions and the three unit responses at once.
Rollouts to many goals then cost one integration plus an outer product (:meth:`DMP.rollout_many`).

**Why a plain DMP misses far goals.** After a finite horizon the phase is still ``≈ e⁻¹``, the
system has not converged, and the end point misses a shifted goal ``g'`` by exactly
``c · ‖g' - g‖`` with ``c = |1 - B[-1]|`` depending only on ``(alpha, K, alpha_phase, tau, T)``
(:meth:`DMP.endpoint_gain`). Run longer (``rollout(n_steps=...)``) or raise ``alpha_phase`` and
``c → 0``.
"""

from __future__ import annotations

import logging

import numpy as np

from .._api import Estimator
from .._checks import (
    _limits_version,
    as_trajectory,
    as_unit_quaternion,
    as_vector,
    check_bool,
    check_bytes,
    check_choice,
    check_names,
    check_text,
    numerically_guarded,
)
from .._state import state_reader
from .._trajectory import resample_time
from .._units import ANGLE_UNITS, check_units
from .canonical import CanonicalSystem
from .forcing import Basis, _check_forcing_increment, _forcing_target, _learn_weights
from .goals import DelayedGoal, PhaseGate, ProgressGate, _gate_past_training, _learn_goal_gate
from .grid import _Caches
from .integrate import _check_integration
from .interface import _none_if_empty
from .protocols import _FittedParams, _resolved_param, _with_rest
from .rest import _rest_started
from .settings import DERIVATIVE_CHOICES, PROTOCOLS, DMPSettings
from .state import _dmp_from_state, _dmp_state
from .stepper import DMPStepper
from .system import DMPSystem, _system_of
from .timed import _coupled_trajectory, _limited_trajectory, _timed_trajectory
from .timing import _checked_on_uniform_time, _Rollout
from .via import _via_trajectory

__all__ = ["DMP", "PROTOCOLS"]

logger = logging.getLogger(__name__)

# DMP.settings() of the models made with the same parameters, the last few sets (newest last)
_SHARED_SETTINGS: dict = {}
_SHARED_SETTINGS_SIZE = 16


def _checked_called(called) -> tuple[str, str | None]:
    """``DMP.fit``'s ``called``: (what the messages call ``y``, its unit's label or None)."""
    if called is None:
        return "y", None
    if not isinstance(called, tuple) or len(called) != 2:
        raise TypeError("called must be (what the messages call y, its unit's label or None)")
    name, label = called
    label = None if label is None else check_text(label, "called[1]", 20)
    return check_text(name, "called[0]"), label


def _checked_progress(progress) -> np.ndarray:
    """``DMP.fit``'s ``progress``: finite, from 0 to 1, non-decreasing (its length is checked
    against the training grid where the gate is learned)."""
    progress = as_vector(progress, "progress")
    if progress.min() < 0.0 or progress.max() > 1.0 or np.any(np.diff(progress) < 0.0):
        raise ValueError("progress must rise from 0 to 1 without going back (the goal's share)")
    return progress


class DMP(_FittedParams, Estimator):
    """Discrete DMP learned from one demonstration, in real time.

    A scikit-learn style estimator: the constructor only stores its parameters, ``fit`` validates
    them and learns, ``get_params``/``set_params``/``sklearn.base.clone`` work, and learned state
    ends in ``_``. Only ``tau`` (an execution parameter: temporal scaling) may change after
    ``fit``; every other parameter shapes what was learned, so changing it (attribute or
    ``set_params``) makes the model unfitted until it is fitted again (a
    :class:`bidmp.NotFittedError` names the parameter).

    **Time.** Internally the demonstration's T samples lie on the grid ``dt_ = 1/T`` (the paper's
    normalised time). ``fit(y, t)`` with timestamps (s) also stores the real duration
    (``duration_``), and :meth:`trajectory` returns positions, velocities and accelerations in
    seconds at any rate; :meth:`rollout` keeps the normalised grid.

    **Protocols.** ``protocol="robot"`` (default) resolves the unset parameters to a DMP a robot
    can run: ``K = alpha beta`` and a goal share that follows the demonstration's own progress
    along its path with smooth ends (a delayed goal, Kulvicius 2012, timed by the demonstration;
    :mod:`bidmp.primitives.goals`): the first ~50 ms and the initial acceleration do not depend on the goal
    or the start, and a moved goal changes the motion by ``R(t) (g' - g)`` with no overshoot
    beyond the stated bound; the exact integrator (the same motion at any control rate); the
    demonstration learned from rest (a start velocity blended out, so the rollout starts at rest
    with the demonstrated acceleration); ridge weights; ``alpha_phase = 4`` and a default horizon
    of 1.1x the demonstration, within which any goal is reached and the motion comes to rest.
    ``protocol="paper"`` is the paper's: ``K = alpha``, ``alpha_phase = 1``, LWR, explicit Euler, the
    goal gated by the phase, exactly T samples (a shifted goal is missed by :meth:`endpoint_gain`
    times the shift).

    Parameters
    ----------
    n_kernels : int or None, default None
        Number of Gaussian kernels ``N_k`` per dimension; ``None``: robot 100, paper 50.
    alpha : float or None, default None
        Spring-damper gain ``alpha`` (per unit of normalised time: 1/duration); ``None``: robot
        50, paper 25.
    beta : float or None, default None
        Spring gain ratio; ``None`` means ``alpha / 4`` (critical damping).
    K : {"paper", "pastor"}, float or None, default None
        Forcing-term gain: ``"paper"`` is ``K = alpha``; ``"pastor"`` is ``K = alpha beta`` (Pastor
        2009, movement_primitives' ``smooth_scaling``); a number sets ``K`` directly; ``None`` is
        the protocol's (robot: ``"pastor"``, paper: ``"paper"``).
    alpha_phase : float or None, default None
        Canonical-system decay ``alpha_phase``; ``None``: robot 4, paper 1.
    tau : float, default 1
        Temporal scaling: a rollout takes ``tau`` times the demonstration's duration, with the same
        shape (larger is slower). The weights are always learned for the demonstration's own
        duration (``tau = 1``), so ``tau`` may be changed after ``fit``.
    regression : {"lwr", "ridge"} or None, default None
        Locally weighted regression per kernel or global ridge least squares; ``None``: robot
        ridge (LWR's one-sided first kernel biases the start's acceleration by up to 40 %), paper
        LWR.
    derivatives : {"gradient", "forward"}, default "gradient"
        How the demonstration is differentiated for the forcing target.
    ridge : float, default 1e-8
        Ridge regulariser for ``regression="ridge"``, relative to the mean diagonal of ``ΦᵀΦ``.
    widths : {"spacing", "pydmps"}, default "spacing"
        Kernel-width rule, see :func:`kernel_widths`.
    protocol : {"robot", "paper"}, default "robot"
        See above.
    goal_rate : float or None, default None
        Rate of an exponentially delayed goal (per normalised time). ``None``: robot, the goal
        follows the demonstration's progress along its path (``goal_gate_``); paper, equal to
        ``alpha_phase``, which is exactly Eq. 10's ``-K phase (g - y0)`` term.
    integrator : {"exact", "euler"} or None, default None
        ``"exact"``: the transformation system integrated exactly with the input linear between
        samples (:mod:`bidmp.primitives.integrate`): stable at any step, the same motion at any control
        rate. ``"euler"``: explicit Euler, Eq. 14 (its motion depends on the step). ``None``:
        robot exact, paper Euler. A robot-protocol model with ``"euler"`` is bidmp's robot
        protocol of model format 3 (such files load with it).
    keep_approach : bool or None, default None
        Robot protocol: complete a moved goal's offset before the final approach (the
        demonstration's straight tail into its goal, :mod:`bidmp.primitives.approach`), and start
        it after the departure (a straight lift it starts with: within 45 degrees of +z, 5-40 % of
        the path), so the
        approach and the departure under a moved goal or start are translated copies of the
        demonstrated ones (:class:`bidmp.primitives.goals.ApproachGate`; the progress gate spreads
        the offset over the whole motion and tilts both). A demonstration without a straight tail
        keeps the progress gate. ``None``: on for the robot protocol (its progress gate) on
        positions, off for joint angles (``units="rad"``: a straight tail in joint space is no
        approach) and for the paper protocol; ``False`` asks for the progress gate.
    canonical_system : CanonicalSystem or None, default None
        The phase as a component (:class:`bidmp.primitives.canonical.CanonicalSystem`): ``None``
        is the exponential phase of ``alpha_phase`` (:class:`~bidmp.primitives.ExponentialPhase`,
        exact or Euler as the integrator); another phase (a rhythmic one) is an object with the
        protocol's methods. Not with ``alpha_phase``.
    forcing_basis : Basis or None, default None
        The forcing term's basis as a component (:class:`bidmp.primitives.forcing.Basis`): ``None``
        is ``n_kernels`` Gaussian kernels sized by ``widths``
        (:class:`~bidmp.primitives.GaussianBasis`); another basis is an object with the
        protocol's methods (its ``size`` functions learned by ridge regression). Not with
        ``n_kernels`` or ``widths``.

    Attributes
    ----------
    weights_ : array, shape (n_kernels, D)
    start_, goal_ : array, shape (D,)
        First and last point of the demonstration.
    n_steps_ : int
        Length T of the demonstration.
    dt_ : float
        ``1 / T``: the normalised time step.
    duration_ : float
        The demonstration's duration in seconds (``(T - 1) / T`` without timestamps: the paper's
        convention of one second per T samples).
    units_ : str
        Unit of the demonstration ("" if not given).
    names_ : list of str
        The names of the D dimensions given to :meth:`fit` (a joint recording's joint names),
        empty when none were.
    held_orientation_ : array (4,) or None
        The tool orientation the demonstration held (``qx, qy, qz, qw``), when given to :meth:`fit`.
    goal_gate_ : array (n_train_,) or None
        The goal gate on the training grid when the goal follows the demonstration's progress
        (``1 - arc length so far / total``), else None.
    centres_, widths_ : array, shape (n_kernels,)
        Kernel centres (phase) and widths.
    """

    def __init__(  # noqa: PLR0913 - an estimator's constructor: each hyperparameter is one (scikit-learn)
        self,
        n_kernels: int | None = None,
        alpha: float | None = None,
        beta: float | None = None,
        K: str | float | None = None,
        alpha_phase: float | None = None,
        tau: float = 1.0,
        regression: str | None = None,
        derivatives: str = "gradient",
        ridge: float = 1e-8,
        widths: str = "spacing",
        protocol: str = "robot",
        goal_rate: float | None = None,
        integrator: str | None = None,
        keep_approach: bool | None = None,
        canonical_system: CanonicalSystem | None = None,
        forcing_basis: Basis | None = None,
    ) -> None:
        self.n_kernels = n_kernels
        self.alpha = alpha
        self.beta = beta
        self.K = K
        self.alpha_phase = alpha_phase
        self.tau = tau
        self.regression = regression
        self.derivatives = derivatives
        self.ridge = ridge
        self.widths = widths
        self.protocol = protocol
        self.goal_rate = goal_rate
        self.integrator = integrator
        self.keep_approach = keep_approach
        self.canonical_system = canonical_system
        self.forcing_basis = forcing_basis

    # -- parameters ----------------------------------------------------------------------------
    def settings(self) -> DMPSettings:
        """The hyperparameters as they are now, resolved for the protocol and checked
        (:class:`~bidmp.primitives.settings.DMPSettings`); raises naming the first bad one.

        Resolved once per change: a rollout asks for them each time, and a changed parameter (or
        :func:`bidmp.set_limits`) resolves them again."""
        raw = self._raw_params() + (self.tau,)
        key = (_limits_version(), raw, tuple(map(type, raw)))
        cached = self.__dict__.get("_settings")
        try:
            if cached is not None and cached[0] == key:
                return cached[1]
        except (TypeError, ValueError):  # an array set by mistake: resolving names it
            pass
        # Models made with the same parameters share one resolution (a fresh DMP() per fit
        # resolved its defaults each time); only with the built-in components, whose objects
        # the settings hold: a user's own component may change after the fact.
        shared = self.canonical_system is None and self.forcing_basis is None
        try:
            settings = _SHARED_SETTINGS.get((type(self), key)) if shared else None
        except TypeError:  # an unhashable value set by mistake: resolving names it
            shared, settings = False, None
        if settings is None:
            settings = DMPSettings.of(self)
            if shared:
                if len(_SHARED_SETTINGS) >= _SHARED_SETTINGS_SIZE:
                    _SHARED_SETTINGS.pop(next(iter(_SHARED_SETTINGS)))  # the oldest
                _SHARED_SETTINGS[(type(self), key)] = settings
        self._settings = (key, settings)
        return settings

    @property
    def system_(self) -> DMPSystem:
        """The fitted DMP as one immutable :class:`~bidmp.primitives.system.DMPSystem` (settings at
        the current ``tau``, weights, demonstration grid), whose methods are the rollouts."""
        self.check_fitted()
        caches = self.__dict__.get("_caches")
        if caches is None:  # learned state set by hand or loaded: its grids are cached from now on
            caches = self._caches = _Caches()
        return _system_of(self, self.settings(), caches)

    alpha_value = _resolved_param(
        "alpha", "The spring gain in use (the protocol's when ``alpha`` is None)."
    )
    n_kernels_value = _resolved_param(
        "n_kernels", "The number of kernels in use (the protocol's when ``n_kernels`` is None)."
    )
    beta_value = _resolved_param(
        "beta", "The spring gain ratio in use (``alpha / 4`` when ``beta`` is None)."
    )
    K_value = _resolved_param("K", "The forcing-term gain in use.")
    alpha_phase_value = _resolved_param(
        "alpha_phase", "The phase decay in use (the protocol's when ``alpha_phase`` is None)."
    )

    # -- learning ------------------------------------------------------------------------------
    @numerically_guarded  # (BLAS threads are limited where a fit's products could use them)
    def fit(  # noqa: PLR0913 - a fit's data and, keyword-only, a part's two options
        self,
        y,
        t=None,
        units: str | None = None,
        names=None,
        held_orientation=None,
        *,
        progress=None,
        called: tuple[str, str | None] | None = None,
    ) -> DMP:
        """Learn the forcing-term weights from one demonstration.

        Parameters
        ----------
        y : array-like, shape (T, D)
            Demonstration, T ≥ 3, any D ≥ 1, in ``units``.
        t : array-like, shape (T,), optional
            Timestamps in seconds: any strictly increasing stamps (jittered, epoch-like); the
            samples are resampled to uniform time over the same span, whose length becomes
            ``duration_``. Without them the samples are taken as uniform over 1 s (the paper's
            protocol).
        units : {"m", "cm", "mm", "rad"}, optional
            The unit of ``y`` (a length, or radians for joint angles), kept in model files
            (anything else is refused).
        names : list of str, optional
            The names of the D dimensions (a joint recording's joint names), kept in model files
            and written in every trajectory file's header and joint trajectory.
        held_orientation : array (4,), optional
            The tool's orientation (unit quaternion x, y, z, w) held through a position-only
            demonstration, kept for the pose the motion is sent with.
        progress : array (n_train,), optional
            The robot protocol's goal share follows this progress (0 to 1, non-decreasing, on
            the training grid: the arc-length progress of another fitted DMP's
            ``training_trajectory``) instead of ``y``'s own (the paper's phase gate has none);
            ``y`` may then stand still. For a part of a model that does not move on its own (a
            pose's orientation while its position moves): it follows the other part's progress.
        called : (str, str or None), optional
            For a DMP that is a part of another model: what the messages call ``y`` and the
            label of its unit when ``units`` does not say it (a pose's orientation part:
            ``("poses' orientation", "rad")``). Default ``("y", None)``.

        Returns
        -------
        self

        A failed ``fit`` (bad parameters or data) leaves the model as it was.
        """
        called = _checked_called(called)
        if progress is not None:
            progress = _checked_progress(progress)
        name, unit_label = called
        params = resolved = self.settings()
        y = as_trajectory(y, name, allow_static=progress is not None)
        units = "" if units is None else check_units(units)
        names = check_names(names, y.shape[1])
        held = (
            None
            if held_orientation is None
            else as_unit_quaternion(held_orientation, "held_orientation")
        )
        y, duration = _checked_on_uniform_time(y, t)
        n_steps = y.shape[0]
        dt = 1.0 / n_steps
        if params.rest_start:
            y_rest = _rest_started(
                y,
                dt,
                duration * n_steps / (n_steps - 1),
                what="the demonstration" if name == "y" else name,
                unit=unit_label or units or "units",
            )
        train = _with_rest(y_rest if params.rest_start else y, params)
        check_bytes(train.shape[0] * params.n_kernels, "the basis matrix (T samples x n_kernels)")
        # Refuse now rather than return a model whose every rollout diverges.
        _check_integration(dt, params.with_tau(1.0))
        _check_integration(dt, params)
        params.canonical_system.check_span(train.shape[0] * dt)
        if units in ANGLE_UNITS and self.keep_approach is None:
            # A straight tail in joint space is no approach along a part's axis (that one is straight
            # in the tool's space): keeping it compressed a moved goal's whole offset into the
            # transfer, a 17 rad/s² spike on a wrist that the demonstration moved at 1.7.
            params = params.replace(keep_approach=False)
        gate = _learn_goal_gate(train, n_steps, dt, params, progress, y)
        weights, centres, widths, phase, phi, band = _learn_weights(train, dt, gate, params)
        self.weights_ = weights
        self.start_ = y[0].copy()
        self.goal_ = y[-1].copy()
        self.n_steps_ = n_steps
        self.dt_ = dt
        self.duration_ = duration
        self.units_ = units
        self.names_ = names
        self.held_orientation_ = held
        self.goal_gate_ = gate if params.goal_rate is None else None
        self.centres_ = centres
        self.widths_ = widths
        self._remember_params(resolved)
        self._caches = _Caches()
        # The training grid is the default rollout grid for tau = 1: cache what fit computed.
        self._caches.store(
            _system_of(self, params.with_tau(1.0), self._caches),
            phase,
            phi,
            dt,
            None
            if params.goal_rate is not None
            else _gate_past_training(gate, phase, params.canonical_system),
            band,
        )
        logger.debug(
            "fitted DMP on %d samples in %d dimension(s) over %.4g s", n_steps, y.shape[1], duration
        )
        return self

    @property
    def n_dims_(self) -> int:
        """Number of dimensions D of the learned demonstration."""
        self.check_fitted()
        return self.weights_.shape[1]

    @property
    def sample_rate_(self) -> float:
        """The demonstration's sample rate in Hz, ``(T - 1) / duration_``."""
        self.check_fitted()
        return (self.n_steps_ - 1) / self.duration_

    @property
    def time_unit_(self) -> float:
        """Seconds per unit of normalised time: ``duration_ · T / (T - 1)`` (1 without timestamps)."""
        self.check_fitted()
        return self.duration_ * self.n_steps_ / (self.n_steps_ - 1)

    # -- evaluation ----------------------------------------------------------------------------
    def default_n_steps(self) -> int:
        """The default rollout length on the normalised grid: ``round(settle · tau · T)`` samples
        (paper: T for ``tau = 1``; robot: 1.1 T, time for any goal to be reached)."""
        return self.system_.rollout_length()

    def phase(self, n_steps: int | None = None) -> np.ndarray:
        """Phase at each rollout step, shape ``(n_steps,)`` (default :meth:`default_n_steps`)."""
        return self.system_.phase(n_steps)

    def grid_basis(self, n_steps: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Phase (n,) and basis rows (n, N) on the rollout grid (default length
        :meth:`default_n_steps`), cached."""
        phase, basis, *_ = self.system_.grid(n_steps)
        return phase, basis

    @property
    def n_train_(self) -> int:
        """Samples of the training grid: T (paper), or T followed by rest up to 1.1 T (robot)."""
        return self.system_.n_train

    def training_grid(self) -> tuple[np.ndarray, np.ndarray]:
        """Phase and basis rows (N columns) of the grid the weights were learned on
        (:attr:`n_train_` samples at ``tau = 1``); what :class:`bidmp.BiDMP` learns on."""
        system = self.system_.with_tau(1.0)
        phase, basis, *_ = system.grid(system.n_train)
        return phase, basis

    def training_gate(self) -> np.ndarray:
        """The goal gate on the training grid: the phase (paper) or the delayed goal's remaining
        fraction (robot); the forcing target (:meth:`forcing_target`) uses it."""
        system = self.system_
        return system.goal_system().training_gate(system.n_train, system.dt, system.settings.exact)

    def goal_system(
        self, settings: DMPSettings | None = None
    ) -> PhaseGate | DelayedGoal | ProgressGate:
        """The goal system (:mod:`bidmp.primitives.goals`) of this model for ``settings`` (default
        its own): the phase gate, a delayed goal, or the learned progress gate (cached: a control
        loop asks for it once per stepper)."""
        return self.system_.goal_system(settings)

    def training_trajectory(self, y, *, quiet: bool = False) -> np.ndarray:
        """A demonstration (T', D) as the weights are learned from it: resampled to T samples and,
        for the robot protocol, started and ended at rest (:func:`bidmp.primitives.rest.rest_started`) and
        followed by rest at its last point up to :attr:`n_train_`. ``quiet``: the rest blends are
        logged at debug level only (a caller that learns many demonstrations on one grid has said
        so once)."""
        self.check_fitted()
        quiet = check_bool(quiet, "quiet")
        y = as_trajectory(y, "y", min_points=2, allow_static=True)
        params = self.settings()
        y = resample_time(y, self.n_steps_)
        if params.rest_start:
            y = _rest_started(y, self.dt_, self.time_unit_, quiet=quiet)
        return _with_rest(y, params)

    def forcing_target(self, y, *, derivatives: str | None = None) -> np.ndarray:
        """The forcing term that makes this DMP reproduce ``y`` exactly: ``y`` (:attr:`n_train_`, D)
        on the training grid (as :meth:`training_trajectory` returns a demonstration), with the
        learned goal gate; ``derivatives`` ("gradient", "forward"; default the DMP's). What
        :class:`bidmp.BiDMP` learns its increments towards, shape (:attr:`n_train_`, D)."""
        system = self.system_
        params = system.settings
        y = as_trajectory(y, "y", min_points=2, allow_static=True)
        if y.shape != (system.n_train, system.n_dims):
            raise ValueError(
                f"y must be on the training grid, shape ({system.n_train}, {system.n_dims}) "
                f"(training_trajectory), got {y.shape}"
            )
        rule = params.derivatives if derivatives is None else derivatives
        rule = check_choice(rule, "derivatives", DERIVATIVE_CHOICES)
        phase, _ = self.training_grid()
        return _forcing_target(
            y,
            phase,
            dt=self.dt_,
            tau=1.0,
            gains=params.gains,
            derivatives=rule,
            gate=self.training_gate(),
        )

    def basis(self, phase) -> np.ndarray:
        """Basis rows ``phi(phase)`` of shape ``(L, n_kernels)`` (the Bi-DMP's BLS input)."""
        return self.system_.basis_rows(phase)

    def forcing_term(self, phase) -> np.ndarray:
        """Learned forcing term ``f(phase) = phi(phase) @ weights_``, shape ``(L, D)``."""
        return self.basis(phase) @ self.weights_

    @numerically_guarded
    def endpoint_gain(self, n_steps: int | None = None) -> float:
        """End-point gain ``c``: the final error for a shifted goal is ``c · ‖g' - g‖``.

        ``c = |1 - B[n_steps - 1]|`` where ``B`` is the goal's share of the affine rollout; it
        depends only on ``(alpha, K, alpha_phase, tau, T, n_steps)``, not on the weights. With the
        paper's fixed horizon it is far from 0 (T = 200, alpha = 100, K = alpha: c ≈ 0.0154); run to
        convergence and it tends to 0.
        """
        return self.system_.endpoint_gain(n_steps)

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
        return self.system_.rollout(
            goal,
            start=start,
            n_steps=n_steps,
            start_velocity=start_velocity,
            forcing_increment=forcing_increment,
        )

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
        return self.system_.rollout_many(
            goals,
            start=start,
            n_steps=n_steps,
            start_velocity=start_velocity,
            forcing_increment=forcing_increment,
            out=out,
        )

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
        yield from self.system_.iter_rollouts(
            goals,
            chunk_size=chunk_size,
            start=start,
            n_steps=n_steps,
            start_velocity=start_velocity,
            forcing_increment=forcing_increment,
        )

    # -- real time -------------------------------------------------------------------------------
    @numerically_guarded
    def trajectory(  # noqa: PLR0913 - the public call spells its options out, as users pass them
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
            Via-points (``()`` or None: none): the motion passes ``point`` (D,) (units) at ``t`` seconds exactly (on the
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
        self.check_fitted()
        _check_forcing_increment(forcing_increment)  # every path below takes it
        via = _none_if_empty(via)
        request = _Rollout(
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
        if via is not None:
            return _via_trajectory(self, request)
        if limits is not None:
            return _limited_trajectory(self, request)
        if coupling is not None:
            return _coupled_trajectory(self, request)
        return _timed_trajectory(self, request)

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

    # -- persistence (used by bidmp.io) --------------------------------------------------------
    def to_state(self) -> tuple[dict, dict]:
        """The model-file form of the fitted model, ``(meta, arrays)``: its parameters and scalars
        as a JSON-able dict, its learned arrays by name (:func:`bidmp.io.save_model` writes the two
        into one ``.npz``; no pickle). Raises :class:`bidmp.NotFittedError` before ``fit``."""
        self.check_fitted()
        return _dmp_state(self)

    @classmethod
    @state_reader
    def from_state(cls, meta: dict, arrays) -> DMP:
        """The fitted model :meth:`to_state` described: ``meta`` as written, ``arrays`` a mapping of
        name to array, each read when needed and checked for dtype, shape and finiteness
        (:func:`bidmp.io.load_model` calls it; a bad file raises, naming the member)."""
        model = _dmp_from_state(cls, meta, arrays)
        model._remember_params()  # the parameters its weights were learned with
        return model


# The constructor's parameters but tau, as given (compared first: cheap), see _FittedParams._stale_params.
_RAW_PARAMS = DMP._raw_param_names()
