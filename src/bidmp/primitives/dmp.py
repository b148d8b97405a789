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

Either integrator is a second-order recursion in ``y``, which :func:`scipy.signal.lfilter` runs in
C for all dimensions and the three unit responses at once. Rollouts to many goals then cost one
integration plus an outer product (:meth:`DMP.rollout_many`).

**Why a plain DMP misses far goals.** After a finite horizon the phase is still ``≈ e⁻¹``, the
system has not converged, and the end point misses a shifted goal ``g'`` by exactly
``c · ‖g' - g‖`` with ``c = |1 - B[-1]|`` depending only on ``(alpha, K, alpha_phase, tau, T)``
(:meth:`DMP.endpoint_gain`). Run longer (``rollout(n_steps=...)``) or raise ``alpha_phase`` and
``c → 0``.
"""

from __future__ import annotations

import logging

import numpy as np
from sklearn.base import BaseEstimator

from .._api import CheckedParams
from .._checks import (
    as_trajectory,
    as_unit_quaternion,
    check_bytes,
    check_names,
    numerically_guarded,
)
from .._units import ANGLE_UNITS, check_units
from ._dmp_grids import GridQueries
from ._dmp_motions import Motions
from .canonical import _check_phase_span
from .forcing import _learn_weights
from .goals import _learn_goal_gate
from .grid import _store_grid
from .integrate import _check_integration
from .protocols import (
    PROTOCOLS,
    _FittedParams,
    _Params,
    _resolve_params,
    _resolved_param,
    _with_rest,
)
from .rest import _rest_started
from .state import _dmp_from_state, _dmp_state
from .timing import on_uniform_time

__all__ = ["DMP", "PROTOCOLS"]

logger = logging.getLogger(__name__)


class DMP(GridQueries, Motions, _FittedParams, CheckedParams, BaseEstimator):
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

    # -- parameters ----------------------------------------------------------------------------
    def _params(self) -> _Params:
        """Validate the hyperparameters as they are now; raise naming the first bad one."""
        return _resolve_params(self)

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
    @numerically_guarded
    def fit(self, y, t=None, units: str | None = None, names=None, held_orientation=None) -> DMP:
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

        Returns
        -------
        self

        A failed ``fit`` (bad parameters or data) leaves the model as it was.
        """
        return self._fit(y, t, units, names=names, held_orientation=held_orientation)

    def _fit(
        self,
        y,
        t=None,
        units: str | None = None,
        *,
        progress: np.ndarray | None = None,
        name: str = "y",
        unit_label: str | None = None,
        names=None,
        held_orientation=None,
    ) -> DMP:
        """:meth:`fit`, with the goal share's progress given (for a part of a pose that does not
        move on its own: then ``y`` may be static)."""
        params = self._params()
        y = as_trajectory(y, name, allow_static=progress is not None)
        units = "" if units is None else check_units(units)
        names = check_names(names, y.shape[1])
        held = (
            None
            if held_orientation is None
            else as_unit_quaternion(held_orientation, "held_orientation")
        )
        y, duration = on_uniform_time(y, t)
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
        _check_integration(dt, params._replace(tau=1.0))
        _check_integration(dt, params)
        _check_phase_span(train.shape[0] * dt, params.alpha_phase)
        if units in ANGLE_UNITS and self.keep_approach is None:
            # A straight tail in joint space is no approach along a part's axis (that one is straight
            # in the tool's space): keeping it compressed a moved goal's whole offset into the
            # transfer, a 17 rad/s² spike on a wrist that the demonstration moved at 1.7.
            params = params._replace(keep_approach=False)
        gate = _learn_goal_gate(train, n_steps, dt, params, progress, y)
        weights, centres, widths, phase, phi = _learn_weights(train, dt, gate, params)
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
        self._remember_params()
        # The training grid is the default rollout grid for tau = 1: cache what fit computed.
        _store_grid(self, params._replace(tau=1.0), phase, phi, dt)
        logger.debug(
            "fitted DMP on %d samples in %d dimension(s) over %.4g s", n_steps, y.shape[1], duration
        )
        return self

    @property
    def n_dims_(self) -> int:
        """Number of dimensions D of the learned demonstration."""
        self._check_fitted()
        return self.weights_.shape[1]

    @property
    def sample_rate_(self) -> float:
        """The demonstration's sample rate in Hz, ``(T - 1) / duration_``."""
        self._check_fitted()
        return (self.n_steps_ - 1) / self.duration_

    @property
    def time_unit_(self) -> float:
        """Seconds per unit of normalised time: ``duration_ · T / (T - 1)`` (1 without timestamps)."""
        self._check_fitted()
        return self.duration_ * self.n_steps_ / (self.n_steps_ - 1)

    # -- persistence (used by bidmp.io) --------------------------------------------------------
    def _get_state(self) -> tuple[dict, dict]:
        return _dmp_state(self)

    @classmethod
    def _from_state(cls, meta: dict, arrays) -> DMP:
        return _dmp_from_state(cls, meta, arrays)


# The constructor's parameters but tau, as given (compared first: cheap), see _FittedParams._stale_params.
_RAW_PARAMS = DMP._raw_param_names()
