"""Discrete Dynamic Movement Primitive (SPEC §1, paper Eq. 10–14).

Transformation system (Pastor/Park form, no ``(g - y0)`` factor on the forcing term)::

    tau² ÿ = alpha (beta (g - y) - tau ẏ) + K f(phase) - K gate(phase) (g - y0)
    tau phase' = -alpha_phase phase,  phase(0) = 1
    f(phase) = phase · Σ_i w_i ψ_i(phase) / Σ_i ψ_i(phase),  ψ_i = exp(-h_i (phase - c_i)²)

on the normalised grid ``dt = 1/T`` (the demonstration's T samples span one unit of time), with
``z = tau ẏ``. Two integrators (:mod:`bidmp._integrate`):

* ``integrator="euler"`` (the paper's protocol): explicit Euler for exactly ``T`` steps,
  ``z[l+1] = z[l] + dt/tau · (alpha (beta (g - y[l]) - z[l]) + u[l])``, ``y[l+1] = y[l] + dt/tau · z[l]``
  — for ``tau = 1`` SPEC Eq. 14 to the letter, with the phase ``(1 - alpha_phase dt)^l``;
* ``integrator="exact"`` (the robot protocol): the continuous system integrated exactly with the
  input linear between samples and the phase ``exp(-alpha_phase t)``, so the same weights give
  the same motion at any control rate.

The goal gate is the phase (Eq. 10), an exponentially delayed goal, or the robot protocol's
progress gate (:mod:`bidmp._goals`).

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
from typing import NamedTuple

import numpy as np
from sklearn.base import BaseEstimator

from . import goals as _goals
from .integrate import (
    check_euler_stable,
    euler_responses,
    euler_spectral_radius,
    exact_responses,
    exact_state,
    foh_step,
)
from .._trajectory import arclength, resample_time
from .._units import check_reach, check_units
from .._checks import (
    NotFittedError,
    as_point,
    as_points,
    as_trajectory,
    check_bytes,
    check_choice,
    check_fitted,
    check_int,
    check_loaded,
    check_real,
    get_limits,
    numerically_guarded,
)

__all__ = [
    "DMP",
    "phase_grid",
    "kernel_centres",
    "kernel_widths",
    "basis_functions",
    "forcing_target",
    "DMPStepper",
    "PROTOCOLS",
    "euler_spectral_radius",
    "check_euler_stable",
]

logger = logging.getLogger(__name__)

_K_CHOICES = ("paper", "pastor")
_REGRESSION_CHOICES = ("lwr", "ridge")
_DERIVATIVE_CHOICES = ("gradient", "forward")
_WIDTH_CHOICES = ("spacing", "pydmps")
_LOG_PSI_FLOOR = -40.0
# Gains (alpha, beta, alpha_phase in 1/s; K) and tau (s) outside these ranges have no physical use
# and take float64 out of its range in the forcing target (division by K) or the integration.
_GAIN_RANGE = (1e-6, 1e6)
_TAU_RANGE = (1e-6, 1e6)


# ---------------------------------------------------------------------------------------------
# Pure functions: phase, kernels, forcing target, integration
# ---------------------------------------------------------------------------------------------
def _phase_decay(dt: float, tau: float, alpha_phase: float) -> float:
    """Per-step factor of the Euler-discretised canonical system (Eq. 13)."""
    decay = 1.0 - alpha_phase * dt / tau
    if not 0.0 < decay < 1.0:
        raise ValueError(
            f"alpha_phase * dt / tau must lie in (0, 1) for a decaying phase, got "
            f"{alpha_phase * dt / tau:g} (alpha_phase={alpha_phase:g}, dt={dt:g}, tau={tau:g})"
        )
    return decay


def _check_integration(step: float, params) -> None:
    """Refuse a normalised step for which the Euler spring diverges or the Euler phase (or an
    exponentially delayed goal) does not decay. The exact integrator is stable at any step."""
    if params.integrator != "euler":
        return
    check_euler_stable(step, params.tau, params.alpha, params.beta)
    _phase_decay(step, params.tau, params.alpha_phase)
    if params.goal_rate is not None:
        _phase_decay(step, params.tau, params.goal_rate)


# Kernels need distinct, representable phases over the training grid: e^-27.6 = 1e-12.
_MIN_TRAINING_PHASE_LOG = -27.6


def _check_phase_span(span: float, params) -> None:
    """Refuse an ``alpha_phase`` that decays the phase below 1e-12 over the training grid (of
    ``span`` normalised time): its kernels' widths and weights would leave float64's range."""
    if -params.alpha_phase * span < _MIN_TRAINING_PHASE_LOG:
        raise ValueError(f"alpha_phase = {params.alpha_phase:g} decays the phase to e^{-params.alpha_phase * span:.4g} over "
                         f"the demonstration; the kernels need at least e^{_MIN_TRAINING_PHASE_LOG:g}: lower alpha_phase")


def phase_grid(n_steps: int, dt: float, tau: float = 1.0, alpha_phase: float = 1.0, *, exact: bool = False) -> np.ndarray:
    """Phase at every step (shape ``(n_steps,)``): ``(1 - alpha_phase dt / tau) ** l``, the
    Euler-discretised canonical system (Eq. 13), or with ``exact`` its solution
    ``exp(-alpha_phase l dt / tau)``, which does not depend on the step."""
    if exact:
        return np.exp(-alpha_phase * dt / tau * np.arange(n_steps))
    return _phase_decay(dt, tau, alpha_phase) ** np.arange(n_steps)


def kernel_centres(n_kernels: int, n_steps: int, dt: float, tau: float = 1.0, alpha_phase: float = 1.0, *,
                   exact: bool = False) -> np.ndarray:
    """Kernel centres at the phase of ``n_kernels`` equally spaced times over the horizon.

    They span exactly the visited phase range ``[phase[n_steps - 1], 1]``: a centre outside it
    belongs to a kernel that never fires, and its LWR weight blows up. ``exact`` as in
    :func:`phase_grid`.
    """
    steps = np.linspace(0.0, n_steps - 1, n_kernels)
    if exact:
        return np.exp(-alpha_phase * dt / tau * steps)
    return np.exp(np.log(_phase_decay(dt, tau, alpha_phase)) * steps)


def kernel_widths(centres: np.ndarray, alpha_phase: float = 1.0, method: str = "spacing") -> np.ndarray:
    """Kernel widths ``h_i`` of ``ψ_i = exp(-h_i (phase - c_i)²)``.

    ``"spacing"`` (default): ``h_i = 1 / (c_{i+1} - c_i)²``, so neighbouring kernels overlap at
    ``e⁻¹``; LWR then reproduces LASA shapes to < 1 % of their extent.
    ``"pydmps"``: ``h_i = N^1.5 / (c_i alpha_phase)`` (SPEC §1 as printed, the pydmps convention);
    neighbours overlap at ≈ 0.9 and LWR smooths the forcing term noticeably (2–5 % on LASA).
    """
    n_kernels = len(centres)
    if method == "pydmps":
        return n_kernels**1.5 / (centres * alpha_phase)
    if n_kernels == 1:
        return np.ones(1)  # a single normalised kernel is constant whatever its width
    spacing = np.abs(np.diff(centres))
    spacing = np.append(spacing, spacing[-1])
    return 1.0 / spacing**2


def basis_functions(phase: np.ndarray, centres: np.ndarray, widths: np.ndarray) -> np.ndarray:
    """The DMP basis rows ``phi(phase) = phase · ψ(phase) / Σ ψ(phase)``.

    Parameters
    ----------
    phase : array, shape (L,)
    centres, widths : array, shape (N,)

    Returns
    -------
    phi : array, shape (L, N)
        Each row sums to its phase. The normalisation is a softmax of ``-h (phase - c)²``,
        computed after subtracting the row maximum, so it never underflows to 0/0 however far
        the phase is from the centres.
    """
    phase = np.asarray(phase, dtype=np.float64).reshape(-1)
    n_kernels = centres.shape[0]
    # Reference exponent per row: the larger of the two kernels bracketing the phase. It is one
    # of the row's entries, so shifting by it cannot overflow and the largest term survives; it
    # replaces an exact row maximum, which costs more than the exp here.
    order = np.argsort(centres)
    position = np.searchsorted(centres[order], phase)
    shift = np.full(phase.shape[0], -np.inf)
    for offset in (-1, 0):
        column = order[np.clip(position + offset, 0, n_kernels - 1)]
        np.maximum(shift, -widths[column] * (phase - centres[column]) ** 2, out=shift)
    # -h (phase - c)² - shift = [phase², phase, 1, -shift] @ [-h; 2hc; -hc²; 1]: one BLAS product
    # writes the whole (L, N) exponent matrix. Cancellation costs ~h·phase²·1e-16 in the exponent
    # (< 1e-11 for any sensible number of kernels).
    features = np.column_stack([phase * phase, phase, np.ones_like(phase), -shift])
    coefficients = np.stack([-widths, 2.0 * widths * centres, -widths * centres * centres, np.ones_like(centres)])
    log_psi = features @ coefficients
    # Terms below e^-40 of the row maximum cannot change a float64 sum; clipping them keeps exp
    # out of the (slow) subnormal range.
    np.maximum(log_psi, _LOG_PSI_FLOOR, out=log_psi)
    psi = np.exp(log_psi, out=log_psi)
    psi *= (phase / (psi @ np.ones(n_kernels)))[:, None]
    return psi


def _derivatives(y: np.ndarray, dt: float, method: str) -> tuple[np.ndarray, np.ndarray]:
    if method == "gradient":
        velocity = np.gradient(y, dt, axis=0)
        return velocity, np.gradient(velocity, dt, axis=0)
    # Forward differences: exactly the quantities the explicit Euler rollout integrates, padded
    # at the end by holding the last value (the rollout never reads the last two entries).
    velocity = np.empty_like(y)
    velocity[:-1] = np.diff(y, axis=0) / dt
    velocity[-1] = velocity[-2]
    acceleration = np.empty_like(y)
    acceleration[:-1] = np.diff(velocity, axis=0) / dt
    acceleration[-1] = acceleration[-2]
    return velocity, acceleration


def forcing_target(
    y: np.ndarray,
    phase: np.ndarray,
    *,
    dt: float,
    tau: float,
    alpha: float,
    beta: float,
    K: float,
    derivatives: str = "gradient",
    gate: np.ndarray | None = None,
) -> np.ndarray:
    """The forcing term that makes Eq. 10 reproduce ``y`` (SPEC §1, "forcing target").

    ``f*[l] = (tau² ÿ[l] - alpha (beta (g - y[l]) - tau ẏ[l])) / K + gate[l] (g - y0)`` with
    ``g = y[-1]``, ``y0 = y[0]`` and the goal gate ``gate`` (default: the phase, Eq. 10; the
    delayed goal of the robot protocol otherwise).

    Parameters
    ----------
    y : array, shape (T, D)
        Demonstration (positions, any length unit).
    phase : array, shape (T,)
        Phase at each sample.
    dt : float
        Time step of ``y`` in seconds.
    derivatives : {"gradient", "forward"}
        ``np.gradient`` (central differences) or forward differences.

    Returns
    -------
    f_target : array, shape (T, D)
    """
    velocity, acceleration = _derivatives(y, dt, derivatives)
    start, goal = y[0], y[-1]
    spring = alpha * (beta * (goal - y) - tau * velocity)
    gate = phase if gate is None else gate
    return (tau**2 * acceleration - spring) / K + gate[:, None] * (goal - start)


# ---------------------------------------------------------------------------------------------
# The estimator
# ---------------------------------------------------------------------------------------------
class _Params(NamedTuple):
    """The validated hyperparameters of a :class:`DMP` (``beta``, ``K``, ``alpha_phase`` and
    ``goal_rate`` resolved to numbers for the protocol)."""

    n_kernels: int
    alpha: float
    beta: float
    K: float
    alpha_phase: float
    tau: float
    regression: str
    derivatives: str
    ridge: float
    widths: str
    protocol: str
    goal_rate: float | None  # None: the goal follows the demonstration's progress (robot default)
    integrator: str  # "exact" (first-order hold, any rate) or "euler" (the paper's Eq. 14)
    settle: float  # default horizon as a multiple of the (scaled) demonstrated duration

    @property
    def exact(self) -> bool:
        return self.integrator == "exact"

    @property
    def rest_start(self) -> bool:
        """Whether the demonstration is learned with its start and end velocity blended out
        (:func:`bidmp._goals.rest_started`): the robot protocol with the exact integrator."""
        return self.integrator == "exact" and self.protocol == "robot"


# The two protocols (README "Protocols"): what the unset parameters resolve to.
PROTOCOLS = ("robot", "paper")
_INTEGRATOR_CHOICES = ("exact", "euler")
# robot: K = alpha beta (Pastor 2009: the initial acceleration does not depend on the goal or the
# start), a goal share that follows the demonstration's progress with smooth ends
# (bidmp._goals), the exact integrator (the same motion at any control rate), the demonstration
# learned from rest (its start velocity blended out), a phase that decays to e^-4 over the
# demonstration, 100 kernels fitted by ridge regression, a stiffer spring (alpha = 50), and a
# horizon of 1.1x the demonstrated duration. The weights are learned on the demonstration
# followed by rest at its goal for that extra 0.1: the learned forcing term then holds the goal
# at the end instead of extrapolating the last kernel. The README's "Robot protocol" section
# has the measurements (tests/test_timing.py holds them).
ROBOT_ALPHA = 50.0
ROBOT_KERNELS = 100
ROBOT_ALPHA_PHASE = 4.0
ROBOT_SETTLE = 1.1


class DMP(BaseEstimator):
    """Discrete DMP learned from one demonstration (SPEC §1), in real time.

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
    :mod:`bidmp._goals`): the first ~50 ms and the initial acceleration do not depend on the goal
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
        samples (:mod:`bidmp._integrate`): stable at any step, the same motion at any control
        rate. ``"euler"``: explicit Euler, Eq. 14 (its motion depends on the step). ``None``:
        robot exact, paper Euler. A robot-protocol model with ``"euler"`` is bidmp's robot
        protocol of model format 3 (such files load with it).

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
        Length unit of the demonstration ("" if not given).
    goal_gate_ : array (n_train_,) or None
        The goal gate on the training grid when the goal follows the demonstration's progress
        (``1 - arc length so far / total``), else None.
    centres_, widths_ : array, shape (n_kernels,)
        Kernel centres (phase) and widths.
    """

    def __init__(
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

    # -- parameters ----------------------------------------------------------------------------
    def _params(self) -> _Params:
        """Validate the hyperparameters as they are now; raise naming the first bad one."""
        protocol = check_choice(self.protocol, "protocol", PROTOCOLS)
        robot = protocol == "robot"
        alpha = (ROBOT_ALPHA if robot else 25.0) if self.alpha is None else \
            check_real(self.alpha, "alpha", positive=True, minimum=_GAIN_RANGE[0], maximum=_GAIN_RANGE[1])
        beta = alpha / 4.0 if self.beta is None else check_real(self.beta, "beta", positive=True, minimum=_GAIN_RANGE[0], maximum=_GAIN_RANGE[1])
        K_choice = ("pastor" if robot else "paper") if self.K is None else self.K
        if isinstance(K_choice, str):
            check_choice(K_choice, "K", _K_CHOICES)
            K = alpha if K_choice == "paper" else alpha * beta
        else:
            K = check_real(K_choice, "K", positive=True, minimum=_GAIN_RANGE[0], maximum=_GAIN_RANGE[1] ** 2)
        if self.alpha_phase is None:
            alpha_phase = ROBOT_ALPHA_PHASE if robot else 1.0
        else:
            alpha_phase = check_real(self.alpha_phase, "alpha_phase", positive=True, minimum=_GAIN_RANGE[0], maximum=_GAIN_RANGE[1])
        if self.goal_rate is None:
            goal_rate = None if robot else alpha_phase
        else:
            goal_rate = check_real(self.goal_rate, "goal_rate", positive=True, minimum=_GAIN_RANGE[0], maximum=_GAIN_RANGE[1])
        return _Params(
            n_kernels=(ROBOT_KERNELS if robot else 50) if self.n_kernels is None else
            check_int(self.n_kernels, "n_kernels", minimum=1, limit="max_kernels"),
            alpha=alpha,
            beta=beta,
            K=K,
            alpha_phase=alpha_phase,
            tau=check_real(self.tau, "tau", positive=True, minimum=_TAU_RANGE[0], maximum=_TAU_RANGE[1]),
            regression=("ridge" if robot else "lwr") if self.regression is None else
            check_choice(self.regression, "regression", _REGRESSION_CHOICES),
            derivatives=check_choice(self.derivatives, "derivatives", _DERIVATIVE_CHOICES),
            ridge=check_real(self.ridge, "ridge", nonnegative=True, maximum=1e6),
            widths=check_choice(self.widths, "widths", _WIDTH_CHOICES),
            protocol=protocol,
            goal_rate=goal_rate,
            integrator=("exact" if robot else "euler") if self.integrator is None else
            check_choice(self.integrator, "integrator", _INTEGRATOR_CHOICES),
            settle=ROBOT_SETTLE if robot else 1.0,
        )

    @property
    def alpha_value(self) -> float:
        """The spring gain in use (the protocol's when ``alpha`` is None)."""
        return self._params().alpha

    @property
    def n_kernels_value(self) -> int:
        """The number of kernels in use (the protocol's when ``n_kernels`` is None)."""
        return self._params().n_kernels

    @property
    def beta_value(self) -> float:
        """The spring gain ratio in use (``alpha / 4`` when ``beta`` is None)."""
        return self._params().beta

    @property
    def K_value(self) -> float:
        """The forcing-term gain in use."""
        return self._params().K

    @property
    def alpha_phase_value(self) -> float:
        """The phase decay in use (the protocol's when ``alpha_phase`` is None)."""
        return self._params().alpha_phase

    # -- learning ------------------------------------------------------------------------------
    @numerically_guarded
    def fit(self, y, t=None, units: str | None = None) -> "DMP":
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
        units : {"m", "cm", "mm"}, optional
            The length unit of ``y``, kept in model files (anything else is refused).

        Returns
        -------
        self

        A failed ``fit`` (bad parameters or data) leaves the model as it was.
        """
        return self._fit(y, t, units)

    def _fit(self, y, t=None, units: str | None = None, *, progress: np.ndarray | None = None,
             name: str = "y", unit_label: str | None = None) -> "DMP":
        """:meth:`fit`, with the goal share's progress given (for a part of a pose that does not
        move on its own: then ``y`` may be static)."""
        from .timing import drop_duplicate_stamps, uniform_time

        params = self._params()
        y = as_trajectory(y, name, allow_static=progress is not None)
        units = "" if units is None else check_units(units)
        if t is None:
            duration = (y.shape[0] - 1) / y.shape[0]
        else:
            y, stamps = drop_duplicate_stamps(y, t)
            y, grid = uniform_time(y, stamps)
            duration = float(grid[-1])
        n_steps = y.shape[0]
        dt = 1.0 / n_steps
        if params.rest_start:
            y_rest = _goals.rest_started(y, dt, duration * n_steps / (n_steps - 1), what="the demonstration" if name == "y"
                                         else name, unit=unit_label or units or "units")
        train = _with_rest(y_rest if params.rest_start else y, params)
        check_bytes(train.shape[0] * params.n_kernels, "the basis matrix (T samples x n_kernels)")
        # Refuse now rather than return a model whose every rollout diverges.
        _check_integration(dt, params._replace(tau=1.0))
        _check_integration(dt, params)
        _check_phase_span(train.shape[0] * dt, params)
        # The weights belong to the demonstration's own time scale (tau = 1); tau only scales
        # rollouts, so it is not used here.
        n_train = train.shape[0]
        phase = phase_grid(n_train, dt, 1.0, params.alpha_phase, exact=params.exact)
        gate = _training_gate(train, n_steps, dt, params, progress)
        centres = kernel_centres(params.n_kernels, n_train, dt, 1.0, params.alpha_phase, exact=params.exact)
        widths = kernel_widths(centres, params.alpha_phase, params.widths)
        target = forcing_target(
            train, phase, dt=dt, tau=1.0, alpha=params.alpha, beta=params.beta, K=params.K,
            derivatives=params.derivatives, gate=gate,
        )
        phi = basis_functions(phase, centres, widths)
        weights = _regress(phi, phase, target, params)
        self.weights_ = np.ascontiguousarray(weights)
        self.start_ = y[0].copy()
        self.goal_ = y[-1].copy()
        self.n_steps_ = n_steps
        self.dt_ = dt
        self.duration_ = duration
        self.units_ = units
        self.goal_gate_ = gate if params.goal_rate is None else None
        self.centres_ = centres
        self.widths_ = widths
        self._remember_params()
        # The training grid is the default rollout grid for tau = 1: cache what fit computed.
        self._store_grid(params._replace(tau=1.0), phase, phi, dt)
        logger.debug("fitted DMP on %d samples in %d dimension(s) over %.4g s", n_steps, y.shape[1], duration)
        return self

    def _learned_params(self) -> _Params:
        """The resolved parameters the weights depend on (all but tau, which only scales time)."""
        return self._params()._replace(tau=1.0)

    def _raw_params(self) -> tuple:
        return tuple(getattr(self, name) for name in _RAW_PARAMS)

    def _remember_params(self) -> None:
        self._learned_with = (self._raw_params(), self._learned_params())

    def _stale_params(self) -> list[str]:
        """The learned-with parameters that have changed since ``fit`` (with their values)."""
        learned = self.__dict__.get("_learned_with")
        if learned is None:
            return []
        raw, resolved = learned
        try:
            if self._raw_params() == raw:  # the common case, without resolving the protocol's defaults
                return []
        except (TypeError, ValueError):  # an array set by mistake: resolving names it
            pass
        now = self._learned_params()
        return [f"{name} (fitted with {before!r}, now {after!r})" for name, before, after in zip(now._fields, resolved, now)
                if before != after]

    def __sklearn_is_fitted__(self) -> bool:
        return "weights_" in self.__dict__ and not self._stale_params()

    def _check_fitted(self) -> None:
        check_fitted(self, "weights_")
        stale = self._stale_params()
        if stale:
            raise NotFittedError(
                f"this DMP's {', '.join(stale)} changed after fit: the weights were learned with the old value, "
                f"so the model must be fitted again (only tau may change after fit)"
            )

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

    # -- evaluation ----------------------------------------------------------------------------
    def default_n_steps(self) -> int:
        """The default rollout length on the normalised grid: ``round(settle · tau · T)`` samples
        (paper: T for ``tau = 1``; robot: 1.1 T, time for any goal to be reached)."""
        self._check_fitted()
        return self._n_steps(None, self._params())

    def _n_steps(self, n_steps, params: _Params) -> int:
        if n_steps is None:
            n_steps = max(int(round(params.settle * params.tau * self.n_steps_)), 1)
            check_int(n_steps, "the default rollout length round(tau * T)", limit="max_steps")
        else:
            n_steps = check_int(n_steps, "n_steps", minimum=1, limit="max_steps")
        check_bytes(n_steps * self.centres_.shape[0], "the rollout basis (n_steps x n_kernels)")
        return n_steps

    def phase(self, n_steps: int | None = None) -> np.ndarray:
        """Phase at each rollout step, shape ``(n_steps,)`` (default :meth:`default_n_steps`)."""
        self._check_fitted()
        params = self._params()
        return phase_grid(self._n_steps(n_steps, params), self.dt_, params.tau, params.alpha_phase, exact=params.exact)

    def _grid_key(self, params: _Params, n_steps: int, step: float) -> tuple:
        """Everything a rollout grid depends on besides the learned kernels."""
        return (n_steps, params.tau, params.alpha, params.beta, params.K, params.alpha_phase, params.goal_rate,
                params.integrator, step)

    def _store_grid(self, params: _Params, phase: np.ndarray, basis: np.ndarray, step: float) -> tuple:
        gate = self._gate_on(params, phase, step)
        cached = (self._grid_key(params, phase.shape[0], step), self.centres_, self.widths_, phase, basis,
                  self._unit_responses(params, phase, None, step, gate=gate), gate)
        self._grid_cache = cached
        return cached

    def _cached_grid(self, params: _Params, n_steps: int, step: float) -> tuple | None:
        cached = self.__dict__.get("_grid_cache")
        if (cached is None or cached[0] != self._grid_key(params, n_steps, step)
                or cached[1] is not self.centres_ or cached[2] is not self.widths_):
            return None
        return cached

    def _grid(self, params: _Params, n_steps: int, step: float | None = None) -> tuple[np.ndarray, ...]:
        """Phase (n,), basis rows (n, N), unit responses ``[B, C, V]`` (3, n) and goal gate (n,) on the grid of
        ``n_steps`` samples ``step`` apart in normalised time (default ``dt_``) for the validated
        ``params``.

        None of them depends on the weights, so the last grid used is cached. The cache key holds
        every hyperparameter the grid depends on and the learned kernels, so changing any of them
        after ``fit`` can never roll out with stale responses.
        """
        step = self.dt_ if step is None else step
        cached = self._cached_grid(params, n_steps, step)
        if cached is None:
            phase = phase_grid(n_steps, step, params.tau, params.alpha_phase, exact=params.exact)
            cached = self._store_grid(params, phase, basis_functions(phase, self.centres_, self.widths_), step)
        return cached[3:]

    def grid_basis(self, n_steps: int | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Phase (n,) and basis rows (n, N) on the rollout grid (default length
        :meth:`default_n_steps`), cached."""
        self._check_fitted()
        params = self._params()
        phase, basis, *_ = self._grid(params, self._n_steps(n_steps, params))
        return phase, basis

    @property
    def n_train_(self) -> int:
        """Samples of the training grid: T (paper), or T followed by rest up to 1.1 T (robot)."""
        self._check_fitted()
        return max(int(round(self._params().settle * self.n_steps_)), self.n_steps_)

    def training_grid(self) -> tuple[np.ndarray, np.ndarray]:
        """Phase and basis rows (N columns) of the grid the weights were learned on
        (:attr:`n_train_` samples at ``tau = 1``); what :class:`bidmp.BiDMP` learns on."""
        self._check_fitted()
        phase, basis, *_ = self._grid(self._params()._replace(tau=1.0), self.n_train_)
        return phase, basis

    def training_gate(self) -> np.ndarray:
        """The goal gate on the training grid: the phase (paper) or the delayed goal's remaining
        fraction (robot); the forcing target of :func:`forcing_target` uses it."""
        self._check_fitted()
        params = self._params()
        if params.goal_rate is None:
            return self._progress_gate()
        return phase_grid(self.n_train_, self.dt_, 1.0, params.goal_rate, exact=params.exact)

    def _progress_gate(self) -> np.ndarray:
        gate = self.__dict__.get("goal_gate_")
        if gate is None or gate.shape[0] != self.n_train_:
            raise ValueError("this DMP has no progress gate for its goal (it was fitted with goal_rate set); "
                             "set goal_rate to a number or fit it again")
        return gate

    def _progress_gate_at(self, phase, params: _Params) -> np.ndarray:
        """The progress gate (see :func:`_progress_gate`) at the given phases: the share of a
        goal change still to come, interpolated in phase on the training grid. The reversed
        training grid is kept, as the stepper asks for one phase per control step."""
        key = (self.n_train_, self.dt_, params.alpha_phase, params.exact)
        cached = self.__dict__.get("_gate_lookup")
        if cached is None or cached[0] != key or cached[2] is not self.goal_gate_:
            training_phase = phase_grid(self.n_train_, self.dt_, 1.0, params.alpha_phase, exact=params.exact)
            cached = (key, training_phase[::-1], self._progress_gate(), self._progress_gate()[::-1])
            self._gate_lookup = cached
        return np.interp(phase, cached[1], cached[3])

    def training_trajectory(self, y) -> np.ndarray:
        """A demonstration (T', D) as the weights are learned from it: resampled to T samples and,
        for the robot protocol, started and ended at rest (:func:`bidmp._goals.rest_started`) and
        followed by rest at its last point up to :attr:`n_train_`."""
        self._check_fitted()
        params = self._params()
        y = resample_time(np.asarray(y, dtype=np.float64), self.n_steps_)
        if params.rest_start:
            y = _goals.rest_started(y, self.dt_, self.time_unit_)
        return _with_rest(y, params)

    def basis(self, phase) -> np.ndarray:
        """Basis rows ``phi(phase)`` of shape ``(L, n_kernels)`` (the Bi-DMP's BLS input)."""
        self._check_fitted()
        return basis_functions(np.asarray(phase, dtype=np.float64).reshape(-1), self.centres_, self.widths_)

    def forcing_term(self, phase) -> np.ndarray:
        """Learned forcing term ``f(phase) = phi(phase) @ weights_``, shape ``(L, D)``."""
        return self.basis(phase) @ self.weights_

    def _unit_responses(self, params: _Params, phase: np.ndarray, forcing: np.ndarray | None, step: float, *,
                        gate: np.ndarray | None = None) -> np.ndarray:
        """Responses that compose every rollout on the grid ``phase`` (n samples ``step`` apart).

        ``y = a + B g + C y0 + V v0``: ``a`` is driven by ``K f`` from rest at 0 (one row per
        dimension, returned when ``forcing`` (n, D) is given); otherwise the rows are ``B`` (the
        goal's share of the input), ``C`` (the start's, with ``y[0] = y[1] = 1``) and ``V`` (the
        free response to a unit start velocity, ``y[1] = step``), shape (3, n).
        """
        alpha, beta, K = params.alpha, params.beta, params.K
        n_steps = phase.shape[0]
        # Euler's y[n] depends on u[n-2] at the latest; the exact step uses u[n] too.
        n_inputs = n_steps if params.exact else max(n_steps - 2, 0)
        if forcing is not None:
            drives = K * forcing[:n_inputs].T
            y_first = second = np.zeros(drives.shape[0])
        else:
            # The goal enters through alpha beta g - K gate (g - y0).
            gate = self._gate_on(params, phase, step) if gate is None else gate
            gate = gate[:n_inputs]
            drives = np.stack([alpha * beta - K * gate, K * gate, np.zeros_like(gate)])
            y_first = np.array([0.0, 1.0, 0.0])
            # The second state: Euler's y[1] (a unit start velocity moves it by one step), or
            # the exact integrator's z = tau dy/ds.
            second = np.array([0.0, 0.0, params.tau]) if params.exact else np.array([0.0, 1.0, step])
        if params.exact:
            return exact_responses(drives, y_first, second, step=step, alpha=alpha, beta=beta, tau=params.tau)
        responses = euler_responses(drives, y_first, second, h=step / params.tau, alpha=alpha, beta=beta)
        return responses[:, :n_steps]

    def _gate_on(self, params: _Params, phase: np.ndarray, step: float) -> np.ndarray:
        """The goal gate at the grid's phases: the phase itself (Eq. 10), the robot protocol's
        progress gate, or an exponentially delayed goal at ``goal_rate``."""
        if params.goal_rate == params.alpha_phase:
            return phase
        if params.goal_rate is None:
            return self._progress_gate_at(phase, params)
        return phase_grid(phase.shape[0], step, params.tau, params.goal_rate, exact=params.exact)

    def _rollout_params(self, step: float | None = None, params: _Params | None = None) -> _Params:
        """The validated parameters, with the rollout's integration checked for stability."""
        self._check_fitted()
        params = self._params() if params is None else params  # validated once per rollout
        _check_integration(self.dt_ if step is None else step, params)
        return params

    def _prepare(self, start, start_velocity, n_steps, forcing_increment=None, *, params=None, step=None):
        params = self._rollout_params(step) if params is None else params
        step = self.dt_ if step is None else step
        n_dims = self.weights_.shape[1]
        n_steps = self._n_steps(n_steps, params)
        start = self.start_ if start is None else as_point(start, n_dims, "start")
        velocity = None if start_velocity is None else as_point(start_velocity, n_dims, "start_velocity")
        phase, basis, (goal_response, start_response, velocity_response), gate = self._grid(params, n_steps, step)
        forcing = basis @ self.weights_
        if forcing_increment is not None:
            forcing = forcing + forcing_increment(phase, basis)
        free = self._unit_responses(params, phase, forcing, step).T
        free += np.outer(start_response, start)
        if start_velocity is not None:
            free += np.outer(velocity_response, velocity)
        # lfilter runs in C, outside NumPy's floating-point checks: check its output once. With
        # these finite and the goals bounded (max_abs_value), y = free + B g cannot overflow.
        if not (np.all(np.isfinite(free)) and np.all(np.isfinite(goal_response))):
            raise ValueError("rollout: the integration is not finite; the inputs' scale or the forcing increment is out of range")
        return free, goal_response, forcing, gate

    @numerically_guarded
    def rollout(self, goal=None, start=None, n_steps: int | None = None, start_velocity=None, *,
                forcing_increment=None) -> np.ndarray:
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
    def rollout_many(self, goals, start=None, n_steps: int | None = None, start_velocity=None, *,
                     forcing_increment=None, out: np.ndarray | None = None) -> np.ndarray:
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
        goals = as_points(goals, free.shape[1], "goals")
        shape = (goals.shape[0], *free.shape)
        if out is None:
            n_bytes = 8 * goals.shape[0] * free.size
            budget = get_limits().max_array_bytes
            if n_bytes > budget:
                chunk = max(budget // (8 * free.size), 1)
                raise ValueError(
                    f"rollout_many: {goals.shape[0]:,} goals x {free.shape[0]:,} steps x {free.shape[1]} dims would take "
                    f"{n_bytes / 2**30:.3g} GiB in one array, over the limit max_array_bytes = {budget / 2**30:.3g} GiB; "
                    f"write into a file with out=numpy.lib.format.open_memmap(path, mode='w+', dtype='float64', "
                    f"shape={shape}), iterate with iter_rollouts(goals, chunk_size={chunk:,}), or raise the limit "
                    f"with bidmp.set_limits(max_array_bytes=...)"
                )
            return _affine_rollouts(goal_response, goals, free)
        if not isinstance(out, np.ndarray) or out.shape != shape or out.dtype != np.float64 or not out.flags.writeable:
            described = f"{type(out).__name__} {getattr(out, 'shape', '')} {getattr(out, 'dtype', '')}".strip()
            raise ValueError(f"out must be a writable float64 array of shape {shape}, got {described}")
        for first, chunk in self._chunks(goals, free):
            _affine_rollouts(goal_response, chunk, free, out[first : first + chunk.shape[0]])
        return out

    @staticmethod
    def _chunks(goals: np.ndarray, free: np.ndarray, chunk_size: int | None = None):
        if chunk_size is None:
            chunk_size = max((64 << 20) // (8 * free.size), 1)  # about 64 MiB per chunk
        for first in range(0, goals.shape[0], chunk_size):
            yield first, goals[first : first + chunk_size]

    def iter_rollouts(self, goals, chunk_size: int = 1024, start=None, n_steps: int | None = None,
                      start_velocity=None, *, forcing_increment=None):
        """Rollouts to many goals, ``chunk_size`` goals at a time (for more than fit in memory).

        Yields
        ------
        (first, y) : int and array (g, n_steps, D)
            ``y[i]`` is the rollout to ``goals[first + i]``; ``g <= chunk_size``.
        """
        chunk_size = check_int(chunk_size, "chunk_size", minimum=1)
        with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
            free, goal_response, *_ = self._prepare(start, start_velocity, n_steps, forcing_increment)
        goals = as_points(goals, free.shape[1], "goals")
        check_bytes(min(chunk_size, goals.shape[0]) * free.size, "one chunk of iter_rollouts (chunk_size x n_steps x D)")
        for first, chunk in self._chunks(goals, free, chunk_size):
            yield first, _affine_rollouts(goal_response, chunk, free)

    @numerically_guarded
    def endpoint_gain(self, n_steps: int | None = None) -> float:
        """End-point gain ``c``: the final error for a shifted goal is ``c · ‖g' - g‖``.

        ``c = |1 - B[n_steps - 1]|`` where ``B`` is the goal's share of the affine rollout; it
        depends only on ``(alpha, K, alpha_phase, tau, T, n_steps)``, not on the weights. With the
        paper's fixed horizon it is far from 0 (T = 200, alpha = 100, K = alpha: c ≈ 0.0154); run to
        convergence and it tends to 0.
        """
        params = self._rollout_params()
        n_steps = self._n_steps(n_steps, params)
        cached = self._cached_grid(params, n_steps, self.dt_)
        if cached is not None:
            goal_response = cached[5][0]
        else:  # B needs no basis matrix, and other horizons should not evict the cached grid
            phase = phase_grid(n_steps, self.dt_, params.tau, params.alpha_phase, exact=params.exact)
            goal_response = self._unit_responses(params, phase, None, self.dt_)[0]
        return float(abs(1.0 - goal_response[-1]))

    # -- real time -------------------------------------------------------------------------------
    def _time_grid(self, duration, dt, params: _Params) -> tuple[float, float, int, float]:
        """(motion duration s, sample period s, number of samples, normalised step) of a timed
        rollout; the motion's duration defaults to ``tau · duration_``, the period to the
        demonstration's."""
        motion = params.tau * self.duration_ if duration is None else check_real(duration, "duration", positive=True)
        period = self.duration_ / (self.n_steps_ - 1)
        dt = period if dt is None else check_real(dt, "dt", positive=True, minimum=1e-6)  # 1 MHz at most
        if dt > motion:
            raise ValueError(f"dt = {dt:g} s is longer than the motion ({motion:g} s)")
        scale = motion / self.duration_  # temporal scaling: the shape is kept, time stretched
        check_real(scale, "duration / duration_ (the temporal scaling)", minimum=_TAU_RANGE[0], maximum=_TAU_RANGE[1])
        if params.protocol == "paper" and duration is None and dt == period:
            n_samples = max(int(round(params.tau * self.n_steps_)), 1)  # the rollout's own samples
        else:
            samples = params.settle * motion / dt * (1 + 1e-12)
            check_real(samples, "the trajectory's samples (duration / dt)", maximum=get_limits().max_steps)
            n_samples = int(np.floor(samples)) + 1  # never past settle x motion
        check_int(n_samples, "the trajectory's samples (duration / dt)", limit="max_steps")
        step = self.dt_ if dt == period else dt / self.time_unit_
        return motion, dt, n_samples, step

    @numerically_guarded
    def trajectory(self, goal=None, start=None, duration: float | None = None, dt: float | None = None, *,
                   limits: dict | None = None, start_velocity=None, forcing_increment=None):
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

        Returns
        -------
        bidmp.Trajectory
            ``t`` from 0 (s), ``y`` (units), ``yd`` (units/s), ``ydd`` (units/s²), each (n, D).
            Exact integrator (robot): ``yd`` and ``ydd`` are the system's own state and
            acceleration at each sample (the same continuous motion at any ``dt``). Euler (paper):
            ``yd[l] = (y[l+1] - y[l]) / dt`` exactly (the explicit-Euler state), likewise ``ydd``.
        """
        from .timing import Trajectory

        self._check_fitted()
        if limits is not None:
            return self._limited_trajectory(goal, start, dt, limits, start_velocity, forcing_increment)
        params = self._params()
        motion, dt, n_samples, step = self._time_grid(duration, dt, params)
        params = self._rollout_params(step, params._replace(tau=motion / self.duration_))
        velocity = None if start_velocity is None else as_point(start_velocity, self.n_dims_, "start_velocity") * self.time_unit_
        # Two extra samples give the last velocity and acceleration as forward differences (Euler),
        # one the last exact state.
        free, goal_response, forcing, gate = self._prepare(start, velocity, n_samples + 2, forcing_increment,
                                                           params=params, step=step)
        goal = self.goal_ if goal is None else as_point(goal, free.shape[1], "goal")
        if self.units_:  # a goal in the wrong unit is far beyond any robot's reach: say so
            check_reach(float(min(np.linalg.norm(goal - self.goal_), np.linalg.norm(goal - self.start_))), self.units_,
                        "the goal")
        positions = free + np.outer(goal_response, goal)
        if params.exact:
            start = self.start_ if start is None else as_point(start, free.shape[1], "start")
            velocities, accelerations = self._exact_rates(params, positions, forcing, gate, goal, start, velocity, step)
        else:
            velocities = np.diff(positions, axis=0) / dt
            accelerations = np.diff(velocities, axis=0) / dt
        return Trajectory(np.arange(n_samples) * dt, positions[:n_samples], velocities[:n_samples],
                          accelerations[:n_samples], self.units_)

    def _exact_rates(self, params: _Params, positions, forcing, gate, goal, start, velocity, step) -> tuple:
        """Velocities (units/s) and accelerations (units/s²) of an exact rollout (n + 1 samples in,
        n out): the system's own state and acceleration, from the positions and the input."""
        inputs = params.K * forcing  # u = αβ g + K f - K gate (g - y0), built in place
        inputs -= np.multiply.outer(gate, params.K * (goal - start))
        inputs += params.alpha * params.beta * goal
        z, acceleration = exact_state(positions, inputs, step=step, alpha=params.alpha, beta=params.beta, tau=params.tau)
        # The first state is given, not solved for: a rest start is exactly at rest.
        z[0] = 0.0 if velocity is None else params.tau * velocity
        acceleration[0] = (inputs[0] - params.alpha * params.beta * positions[0] - params.alpha * z[0]) / params.tau**2
        return z / (params.tau * self.time_unit_), acceleration / self.time_unit_**2

    def _limited_trajectory(self, goal, start, dt, limits, start_velocity, forcing_increment):
        """The trajectory within ``limits``: at the nominal duration if that meets them (limits
        are caps: they never speed a motion up, unless ``"fastest": True``), otherwise the
        shortest duration that does: scale by the exact factor of
        :func:`bidmp.timing.scale_factor`, then bisect for what the discretisation changes."""
        from .timing import scale_factor

        if not isinstance(limits, dict):
            raise TypeError(f"limits must be a dict of max_velocity / max_acceleration / max_jerk / norm / fastest, "
                            f"got {type(limits).__name__}")
        unknown = set(limits) - {"max_velocity", "max_acceleration", "max_jerk", "norm", "fastest"}
        if unknown:
            raise ValueError(f"limits has unknown key(s) {sorted(unknown)}; known: max_velocity, max_acceleration, "
                             f"max_jerk, norm, fastest")
        limits = dict(limits)
        fastest = limits.pop("fastest", False)
        if not isinstance(fastest, (bool, np.bool_)):
            raise TypeError(f"limits['fastest'] must be True or False, got {type(fastest).__name__}")

        def attempt(duration):
            trajectory = self.trajectory(goal, start, duration, dt, start_velocity=start_velocity,
                                         forcing_increment=forcing_increment)
            return trajectory, scale_factor(trajectory, **limits)

        # The exact factor first (speed ~ 1/k, acceleration ~ 1/k²), then a bisection in log
        # duration for what re-integrating at another step changes: the result meets every
        # limit and touches the binding one within 0.1 %.
        duration = self._params().tau * self.duration_
        trajectory, factor = attempt(duration)
        if factor <= 1.0 and not fastest:
            return trajectory  # within the limits as demonstrated: a cap does not hurry it
        low = high = best = None  # durations known to break / to meet the limits
        for _ in range(60):
            if 1.0 - 1e-3 <= factor <= 1.0:
                return trajectory
            if factor > 1.0:
                low = duration
            else:
                high, best = duration, trajectory
            if low is not None and high is not None:
                duration = float(np.sqrt(low * high))
            else:
                duration *= factor * (1.0 + 1e-4) if factor > 1.0 else factor
            trajectory, factor = attempt(duration)
        return trajectory if factor <= 1.0 or best is None else best

    def stepper(self, goal=None, start=None, duration: float | None = None, *, coupling: float = 0.0,
                start_velocity=None, forcing_increment=None) -> "DMPStepper":
        """A step-by-step integrator for a robot's control loop (see :class:`DMPStepper`).

        ``coupling`` is ``alpha_e`` of phase stopping (Ijspeert et al. 2013) in 1/units²: the
        system's time runs ``1 + alpha_e ‖y_measured - y‖²`` times slower while the robot lags, so
        a held robot makes the motion pause rather than run away. 0 turns it off.
        """
        return DMPStepper(self, goal, start, duration, coupling, start_velocity, forcing_increment)

    # -- persistence (used by bidmp.io) --------------------------------------------------------
    def _get_state(self) -> tuple[dict, dict]:
        self._check_fitted()
        arrays = {
            "weights_": self.weights_,
            "start_": self.start_,
            "goal_": self.goal_,
            "centres_": self.centres_,
            "widths_": self.widths_,
        }
        if self.__dict__.get("goal_gate_") is not None:
            arrays["goal_gate_"] = self.goal_gate_
        return {"params": self.get_params(), "n_steps_": self.n_steps_, "duration_": self.duration_,
                "units_": self.units_}, arrays

    @classmethod
    def _from_state(cls, meta: dict, arrays: dict) -> "DMP":
        params = dict(meta["params"])
        if "fit" in params:  # format 1 stored the regression under the name "fit"
            params["regression"] = params.pop("fit")
        params.setdefault("protocol", "paper")  # formats 1-2 knew only the paper's protocol
        if "integrator" not in params:  # formats 1-3 integrated with explicit Euler
            params["integrator"] = "euler"
        model = cls(**params)
        params = model._params()
        n_kernels = params.n_kernels
        n_steps = check_int(meta["n_steps_"], "n_steps_", minimum=3, limit="max_samples")
        weights = check_loaded(arrays["weights_"], "weights_", (n_kernels, None))
        n_dims = weights.shape[1]
        check_int(n_dims, "the model's number of dimensions D", minimum=1, limit="max_dims")
        model.weights_ = weights
        model.start_ = check_loaded(arrays["start_"], "start_", (n_dims,))
        model.goal_ = check_loaded(arrays["goal_"], "goal_", (n_dims,))
        model.centres_ = check_loaded(arrays["centres_"], "centres_", (n_kernels,), positive=True)
        model.widths_ = check_loaded(arrays["widths_"], "widths_", (n_kernels,), positive=True)
        for name in ("weights_", "start_", "goal_"):
            limit = 1e3 * get_limits().max_abs_value if name == "weights_" else get_limits().max_abs_value
            if np.max(np.abs(getattr(model, name))) > limit:
                raise ValueError(f"member {name} has values beyond {limit:.3g}, which no fit produces")
        if np.any(model.centres_ > 1.0):
            raise ValueError("member centres_ must lie in (0, 1] (they are phases)")
        model.n_steps_ = n_steps
        model.dt_ = 1.0 / n_steps
        model.duration_ = check_real(meta.get("duration_", (n_steps - 1) / n_steps), "duration_", positive=True, maximum=1e7)
        if (n_steps - 1) / model.duration_ > 1e5 or (n_steps - 1) / model.duration_ < 1e-3:
            raise ValueError(f"duration_ = {model.duration_:g} s implies an implausible sample rate for {n_steps} samples")
        model.units_ = check_units(meta.get("units_", ""))
        model.goal_gate_ = None
        if params.goal_rate is None:
            gate = check_loaded(arrays["goal_gate_"], "goal_gate_", (model.n_train_,))
            if np.max(np.abs(gate)) > 1e6:
                raise ValueError("member goal_gate_ has values beyond 1e6, which no fit produces")
            model.goal_gate_ = gate
        if params.integrator == "euler":
            check_euler_stable(model.dt_, 1.0, params.alpha, params.beta)
        model._remember_params()
        return model


# The constructor's parameters but tau, as given (compared first: cheap), see DMP._stale_params.
_RAW_PARAMS = tuple(name for name in DMP._get_param_names() if name != "tau")


def _progress_gate(progress: np.ndarray, dt: float, params: _Params) -> np.ndarray:
    """The goal gate of the robot protocol of model format 3 (``integrator="euler"``): the share
    of a goal change still to come, such that the Euler rollout's response to a moved goal follows
    the demonstration's own progress along its path.

    With ``σ`` the demonstration's arc-length progress (0 → 1), the gate is the exact inverse of
    the Euler-discretised spring for the target response ``σ`` delayed by two samples: the
    spring cannot respond before then (``y[1] = y[0]``), and the delay makes ``gate[0] = 1``, so
    the initial acceleration does not depend on the goal (nor on the start). A moved goal is
    thus approached in step with the demonstrated motion: a straight demonstration to a nearer
    goal becomes the same motion scaled down, without overshoot or moving backwards.
    """
    response = np.concatenate([np.zeros(2), progress[:-2]])  # σ delayed by two samples
    h = dt
    a1 = -(2.0 - h * params.alpha)
    a2 = 1.0 - h * params.alpha + h * h * params.alpha * params.beta
    drive = (response[2:] + a1 * response[1:-1] + a2 * response[:-2]) / (h * h)  # = αβ − K gate
    gate = np.empty_like(progress)
    gate[:-2] = (params.alpha * params.beta - drive) / params.K
    gate[-2:] = gate[-3]  # the last two drives never reach the rollout (y[n] depends on u[n-2])
    return gate


def arclength_progress(y: np.ndarray) -> np.ndarray:
    """Arc-length progress ``σ`` (0 → 1) of a trajectory (n, D); a static one has none (zeros)."""
    arc = arclength(y)
    return arc / arc[-1] if arc[-1] > 0.0 else np.zeros_like(arc)


def _training_gate(train: np.ndarray, n_motion: int, dt: float, params: _Params, progress) -> np.ndarray:
    """The goal gate on the training grid: the progress gate of the protocol (exact: the smooth
    goal share of :mod:`bidmp._goals`; Euler: the legacy discrete inverse) or an exponentially
    delayed goal at ``goal_rate``."""
    n_train = train.shape[0]
    if params.goal_rate is not None:
        return phase_grid(n_train, dt, 1.0, params.goal_rate, exact=params.exact)
    progress = arclength_progress(train) if progress is None else np.asarray(progress, dtype=np.float64)
    if progress.shape != (n_train,):
        raise ValueError(f"progress must have shape ({n_train},), got {progress.shape}")
    if not params.exact:
        return _progress_gate(progress, dt, params)
    share = _goals.goal_share(progress, n_motion, dt)
    return _goals.goal_gate(share, dt, alpha=params.alpha, beta=params.beta, K=params.K)


def _regress(phi: np.ndarray, phase: np.ndarray, target: np.ndarray, params: _Params) -> np.ndarray:
    """Forcing-term weights (N, D): LWR per kernel or ridge least squares on the basis rows."""
    if params.regression == "lwr":
        # w_i = Σ_l phase_l ψ̄_il f_l / Σ_l phase_l² ψ̄_il, with phi = phase · ψ̄.
        denominator = phi.T @ phase
        weights = (phi.T @ target) / np.maximum(denominator, np.finfo(float).tiny)[:, None]
    else:
        gram = phi.T @ phi
        reg = params.ridge * max(np.trace(gram) / params.n_kernels, np.finfo(float).tiny)
        weights = np.linalg.solve(gram + reg * np.eye(params.n_kernels), phi.T @ target)
    if not np.all(np.isfinite(weights)):
        raise ValueError("fit: the learned weights are not finite; the demonstration's scale or the gains are out of range")
    return weights


def _affine_rollouts(goal_response: np.ndarray, goals: np.ndarray, free: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """``y[i] = free + B goals[i]`` for every goal at once, (G, n, D), written into ``out`` if given."""
    out = np.multiply(goal_response[None, :, None], goals[:, None, :], out=out)
    out += free[None]
    return out


def _with_rest(y: np.ndarray, params: _Params) -> np.ndarray:
    """``y`` followed by rest at its last point for the protocol's settle time (robot: 0.1 T)."""
    n_rest = int(round(params.settle * y.shape[0])) - y.shape[0]
    if n_rest <= 0:
        return y
    return np.vstack([y, np.repeat(y[-1:], n_rest, axis=0)])


class DMPStepper:
    """Integrates a DMP (or a Bi-DMP skill) one control step at a time.

    ``step(dt, y_measured=None)`` returns the command ``(y, yd, ydd)`` for the current sample (units,
    units/s, units/s²) and advances the state by ``dt`` seconds. Without a measurement (or with
    ``coupling = 0``) the commands equal :meth:`DMP.trajectory` sample for sample (the same
    integration steps, exact or Euler). With a measurement the system's time runs ``1 + coupling ‖y_measured - y‖²`` times
    slower (phase stopping, Ijspeert et al. 2013, applied to the whole system so that the spring
    waits too): a robot held back makes the command pause where it is, and the motion resumes once
    it catches up.

    Attributes
    ----------
    phase : float
        The canonical state ``ϑ``.
    time : float
        The motion's own time in seconds (slower than the wall clock while paused).
    """

    def __init__(self, dmp: DMP, goal, start, duration, coupling, start_velocity, forcing_increment) -> None:
        dmp._check_fitted()
        params = dmp._params()
        self._dmp = dmp
        n_dims = dmp.n_dims_
        self.goal = dmp.goal_.copy() if goal is None else as_point(goal, n_dims, "goal")
        self.start = dmp.start_.copy() if start is None else as_point(start, n_dims, "start")
        motion = params.tau * dmp.duration_ if duration is None else check_real(duration, "duration", positive=True)
        self._scale = check_real(motion / dmp.duration_, "duration / duration_ (the temporal scaling)",
                                 minimum=_TAU_RANGE[0], maximum=_TAU_RANGE[1])  # tau of the normalised system
        self._params = params._replace(tau=self._scale)
        self.coupling = check_real(coupling, "coupling", nonnegative=True, maximum=1e6)
        self._forcing_increment = forcing_increment
        self.y = self.start.copy()
        velocity = np.zeros(n_dims) if start_velocity is None else as_point(start_velocity, n_dims, "start_velocity")
        self._z = velocity * dmp.time_unit_ * self._scale  # z = tau ẏ in normalised time
        # What every step reads, taken once: a control loop should not revalidate the model.
        self._centres, self._widths, self._weights = dmp.centres_, dmp.widths_, dmp.weights_
        self._gate_lookup = None
        if params.goal_rate is None:
            dmp._progress_gate_at(1.0, params)  # builds the reversed training grid
            self._gate_lookup = dmp._gate_lookup[1], dmp._gate_lookup[3]
        self._last_input = None  # (phase, gate, goal, start, u): the end of one step starts the next
        self.phase = 1.0
        self._gate = 1.0
        self._gate = self._next_gate(1.0, 1.0)
        self.time = 0.0
        self._checked_step = None

    def _basis_row(self, phase: float) -> np.ndarray:
        """``phi(phase)`` (1, N) for one phase: :func:`basis_functions` without its batching."""
        log_psi = -self._widths * (phase - self._centres) ** 2
        log_psi -= log_psi.max()
        psi = np.exp(np.maximum(log_psi, _LOG_PSI_FLOOR))
        return (psi * (phase / psi.sum()))[None]

    def _input(self, phase: float, gate: float) -> np.ndarray:
        """The system's input ``u = αβ g + K f(phase) - K gate (g - y0)`` (D,)."""
        last = self._last_input
        if (last is not None and last[0] == phase and last[1] == gate and np.array_equal(last[2], self.goal)
                and np.array_equal(last[3], self.start)):
            return last[4]
        params = self._params
        basis = self._basis_row(phase)
        forcing = basis @ self._weights
        if self._forcing_increment is not None:
            forcing = forcing + self._forcing_increment(np.array([phase]), basis)
        value = params.alpha * params.beta * self.goal + params.K * (forcing[0] - gate * (self.goal - self.start))
        self._last_input = (phase, gate, self.goal.copy(), self.start.copy(), value)
        return value

    def _next_gate(self, phase: float, decay: float) -> float:
        params = self._params
        if params.goal_rate is None:
            return float(np.interp(phase, *self._gate_lookup))
        if params.goal_rate == params.alpha_phase:
            return phase
        return self._gate * decay

    def step(self, dt: float, y_measured=None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The command for now, then advance ``dt`` seconds (less while the robot lags).

        Returns
        -------
        (y, yd, ydd) : arrays (D,)
            Position (units), velocity (units/s) and acceleration (units/s²) to command.
        """
        dt = check_real(dt, "dt", positive=True, minimum=1e-6, maximum=1e3)
        params = self._params
        time_unit = self._dmp.time_unit_
        slowdown = 1.0
        if y_measured is not None and self.coupling > 0.0:
            error = as_point(y_measured, self.y.shape[0], "y_measured") - self.y
            slowdown = 1.0 + self.coupling * float(error @ error)
        step = dt / time_unit / slowdown  # the normalised time this control step advances
        alpha, beta, tau = params.alpha, params.beta, params.tau
        input_now = self._input(self.phase, self._gate)  # not cached: goal and start are public
        position = self.y.copy()
        # The command's velocity and acceleration, as trajectory() reports them: the system's own.
        velocity = self._z / (tau * time_unit) / slowdown
        acceleration = (input_now - alpha * beta * self.y - alpha * self._z) / (tau * time_unit * slowdown) ** 2
        if params.exact:
            decay = float(np.exp(-params.alpha_phase * step / tau))
            phase = self.phase * decay
            gate = self._next_gate(phase, float(np.exp(-(params.goal_rate or 0.0) * step / tau)))
            input_next = self._input(phase, gate)
            transition, now, after = foh_step(step, alpha, beta, tau)
            state = transition @ np.stack([self.y, self._z]) + np.outer(now, input_now) + np.outer(after, input_next)
            self.y, self._z = state[0], state[1]
        else:
            h = step / tau
            if h != self._checked_step:
                check_euler_stable(step, tau, alpha, beta)
                self._checked_step = h
            z_next = self._z + h * (input_now - alpha * beta * self.y - alpha * self._z)
            self.y = self.y + h * self._z
            self._z = z_next
            phase = self.phase * (1.0 - params.alpha_phase * h)
            gate = self._next_gate(phase, 1.0 - (params.goal_rate or 0.0) * h)
        self.phase, self._gate = phase, gate
        self.time += dt / slowdown
        return position, velocity, acceleration
