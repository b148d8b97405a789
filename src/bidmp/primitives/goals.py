"""Goal systems: how a DMP's goal enters its input, as small objects a DMP composes.

A goal system gives the goal gate ``G`` of ``u = αβ g + K f - K G (g - y0)`` on a rollout grid
(:meth:`on_grid`), one control step at a time (:meth:`follow`), and on the training grid (what
the forcing target subtracts):

* :class:`PhaseGate` — ``G = ϑ``: the paper's Eq. 10 (``K = α``) and, with ``K = αβ``, Pastor's
  smooth scaling (movement_primitives' ``smooth_scaling=True``);
* :class:`DelayedGoal` — ``G`` decays at its own rate (Kulvicius 2012's delayed goal);
* :class:`ProgressGate` — the robot protocol's: the goal's share follows the demonstration's own
  progress along its path (below), learned at ``fit``;
* :class:`ApproachGate` — the progress gate with the goal's share complete before the final
  approach (the demonstration's straight tail into its goal): the approach to a moved goal is a
  translated copy of the demonstrated one (``DMP(keep_approach=True)``).

A new goal system is one more class with these three methods, chosen in
``bidmp.primitives.dmp.goal_system``.

**The robot protocol's progress gate.**

A DMP's goal enters its input through the goal gate ``G``: ``u = αβ g + K f - K G (g - y0)``. The
motion's response to a change of goal is then ``R(t) (g' - g)``, a scalar *goal share* ``R``
that rises from 0 to 1; the robot protocol chooses ``G`` so that ``R`` is a profile of the
demonstration's own progress along its path:

* ``σ`` — the arc-length progress (0 → 1) of the demonstration as learned;
* ``R = σ · S(t / w)`` over the first ``w`` of the motion and ``1 - (1 - σ) S((T - t) / w)``
  over its last ``w``, ``R = σ`` in between, 1 after. ``S`` is the 7th-order smoothstep (zero
  first to third derivative at both ends), ``w = _GOAL_BLEND`` (15 %) of the demonstration's
  duration. So ``R, R', R'', R'''`` all start at 0: the first ~50 ms of a motion do not depend on
  its goal (no acceleration or jerk step when the goal moves), and ``R`` reaches 1 with zero
  slope when the motion comes to rest;
* ``G`` is the *continuous* inverse of the spring for ``R``:
  ``G = (αβ (1 - R) - R'' - α R') / K`` (normalised time, ``tau = 1``). Integrated exactly
  (:mod:`bidmp.primitives.integrate`), the response is ``R`` at any control rate.

**The bound on a moved goal** (stated in the README): ``y_{g'}(t) = y_g(t) + R(t) (g' - g)``
exactly, and ``|R(t) - σ(t)| ≤ max(σ(w), 1 - σ(T - w))``: the progress made in the first and in
the last ``w``. Against the demonstration scaled to the new goal, ``y_g + σ (g' - g)``, the motion
differs by at most that share of ``‖g' - g‖``: for a straight demonstration and a nearer goal
this is the largest overshoot; a minimum-jerk start makes ``σ(w) ≈ 10 (0.15)³ = 3 %`` and the
overshoot itself is far smaller (``σ (1 - S)`` peaks near ``w/2``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .._checks import as_vector, check_bool, check_int, check_real, checks_input
from .._kernels import goal_gate, goal_share, goal_share_arguments, strictly_decreasing
from .._trajectory import arclength
from .approach import _tail_start
from .canonical import phase_grid
from .gains import _Gains

__all__ = ["PhaseGate", "DelayedGoal", "ProgressGate", "ApproachGate"]

MIN_APPROACH_SHARE = 0.05  # of the path's length: a shorter straight tail is no approach
# share of the demonstration's duration over which the goal's share starts and ends
_GOAL_BLEND = 0.15


def _smoothstep(u: np.ndarray) -> np.ndarray:
    """The 7th-order smoothstep ``35u⁴ - 84u⁵ + 70u⁶ - 20u⁷`` on [0, 1] (clipped outside): 0 → 1 with
    zero first, second and third derivatives at both ends."""
    u = np.clip(u, 0.0, 1.0)
    return u**4 * (35.0 + u * (-84.0 + u * (70.0 - 20.0 * u)))


def _smoothstep_derivatives(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """First and second derivative of :func:`_smoothstep` (0 outside [0, 1])."""
    inside = (u > 0.0) & (u < 1.0)
    first = np.where(inside, 140.0 * u**3 * (1.0 - u) ** 3, 0.0)
    second = np.where(inside, 420.0 * u**2 * (1.0 - u) ** 2 * (1.0 - 2.0 * u), 0.0)
    return first, second


def _goal_share(
    progress: np.ndarray, n_motion: int, dt: float, blend: float = _GOAL_BLEND, begin: float = 0.0
) -> np.ndarray:
    """The goal share ``R`` on the training grid (module docstring), 0 before ``begin`` (normalised
    time: the end of a kept departure) and rising from there.

    Parameters
    ----------
    progress : array (n,)
        Arc-length progress ``σ`` of the trajectory as learned (rest after ``n_motion`` samples).
    n_motion : int
        Samples of the demonstrated motion (``T``); after them ``R = 1``.
    dt : float
        Normalised step.
    """
    end = (n_motion - 1) * dt
    width = max(blend * (end - begin), dt)
    # R = σ S((s - begin) / w), then 1 - (1 - σ) S((end - s) / w) over the last w, then 1: two
    # compiled loops around NumPy's u⁴ (the smoothstep's powers, as _smoothstep takes them).
    arguments = goal_share_arguments(progress.shape[0], dt, begin, end, width)
    return goal_share(progress, arguments, arguments**4, dt, end, width)


def _goal_gate(share: np.ndarray, dt: float, *, alpha: float, beta: float, K: float) -> np.ndarray:
    """The gate ``G = (αβ (1 - R) - R'' - α R') / K`` whose continuous response is ``R``, with
    ``R'`` and ``R''`` as central differences (one compiled loop). R, R' and R'' vanish at the start
    (the smoothstep is flat there): one-sided differences would leave a trace of the next samples,
    and the initial acceleration must not depend on the goal, so ``G[0] = αβ / K``."""
    return goal_gate(share, dt, alpha, beta, K)


def _euler_progress_gate(
    progress: np.ndarray, dt: float, *, alpha: float, beta: float, K: float
) -> np.ndarray:
    """The progress gate of model format 3's robot protocol (``integrator="euler"``): the exact
    inverse of the Euler-discretised spring for the target response ``σ`` delayed by two samples.

    The spring cannot respond before then (``y[1] = y[0]``), and the delay makes ``gate[0] = 1``,
    so the initial acceleration does not depend on the goal (nor on the start).
    """
    response = np.concatenate([np.zeros(2), progress[:-2]])  # σ delayed by two samples
    h = dt
    a1 = -(2.0 - h * alpha)
    a2 = 1.0 - h * alpha + h * h * alpha * beta
    drive = (response[2:] + a1 * response[1:-1] + a2 * response[:-2]) / (h * h)  # = αβ − K gate
    gate = np.empty_like(progress)
    gate[:-2] = (alpha * beta - drive) / K
    gate[-2:] = gate[-3]  # the last two drives never reach the rollout (y[n] depends on u[n-2])
    return gate


def _arclength_progress(y: np.ndarray) -> np.ndarray:
    """Arc-length progress ``σ`` (0 → 1) of a trajectory (n, D); a static one has none (zeros)."""
    arc = arclength(y)
    return arc / arc[-1] if arc[-1] > 0.0 else np.zeros_like(arc)


def _training_progress(train: np.ndarray, progress) -> np.ndarray:
    """The progress σ (n_train,) a gate is learned from: the trajectory's own arc-length progress,
    or the one given (a part that does not move follows another's)."""
    n_train = train.shape[0]
    progress = (
        _arclength_progress(train) if progress is None else np.asarray(progress, dtype=np.float64)
    )
    if progress.shape != (n_train,):
        raise ValueError(f"progress must have shape ({n_train},), got {progress.shape}")
    return progress


# -- the goal systems' arguments, checked (a user may drive a goal system of their own) ------------
_MAX_STEP = 1e3  # normalised time of one step: a motion lasts 1


def _step_args(gate, phase, step, tau, exact) -> tuple[float, float, float, float, bool]:
    return (
        check_real(gate, "gate"),
        check_real(phase, "phase", minimum=0.0, maximum=1.0),
        check_real(step, "step", nonnegative=True, maximum=_MAX_STEP),
        check_real(tau, "tau", positive=True),
        check_bool(exact, "exact"),
    )


def _grid_args(phase, step, tau, exact) -> tuple[np.ndarray, float, float, bool]:
    phase = as_vector(phase, "phase")
    if np.any((phase < 0.0) | (phase > 1.0)):
        raise ValueError("phase must lie in [0, 1]")
    # one sample has no spacing: a step of 0 is then as good as any
    step = check_real(
        step, "step", positive=phase.shape[0] > 1, nonnegative=True, maximum=_MAX_STEP
    )
    return phase, step, check_real(tau, "tau", positive=True), check_bool(exact, "exact")


def _training_args(n_train, dt, exact) -> tuple[int, float, bool]:
    return (
        check_int(n_train, "n_train", minimum=1, limit="max_steps"),
        check_real(dt, "dt", positive=True, maximum=1.0),
        check_bool(exact, "exact"),
    )


# -- goal systems ----------------------------------------------------------------------------------
class _SteppedGoal:
    """A goal system's control step: :meth:`follow` checks its arguments once, here (or takes them
    as given), and the system's own ``_next`` gives the gate."""

    def follow(
        self,
        gate: float,
        phase: float,
        step: float,
        tau: float,
        exact: bool,
        *,
        check_input: bool = True,
    ) -> float:
        """The gate one control step of ``step`` (normalised time) after ``gate``, at ``phase``.
        ``check_input=False`` takes the arguments as given, floats in range (a stepper's control
        loop, which checked them once, asks every step)."""
        if checks_input(check_input):
            gate, phase, step, tau, exact = _step_args(gate, phase, step, tau, exact)
        return self._next(gate, phase, step, tau, exact)


@dataclass(frozen=True)
class DelayedGoal(_SteppedGoal):
    """``G`` decays at ``rate`` (per normalised time), like the phase does at ``alpha_phase``."""

    rate: float

    def __post_init__(self) -> None:
        object.__setattr__(
            self, "rate", check_real(self.rate, f"{type(self).__name__}.rate", positive=True)
        )

    def on_grid(self, phase: np.ndarray, step: float, tau: float, exact: bool) -> np.ndarray:
        """The gate at a rollout grid's samples (``step`` apart in normalised time)."""
        phase, step, tau, exact = _grid_args(phase, step, tau, exact)
        # one sample (the only case a step of 0 passes): the grid's first value is 1 whatever the step
        return phase_grid(phase.shape[0], step or 1.0, tau, self.rate, exact=exact)

    def training_gate(self, n_train: int, dt: float, exact: bool) -> np.ndarray:
        """The gate on the training grid (``tau = 1``)."""
        n_train, dt, exact = _training_args(n_train, dt, exact)
        return phase_grid(n_train, dt, 1.0, self.rate, exact=exact)

    def _next(self, gate: float, phase: float, step: float, tau: float, exact: bool) -> float:
        return gate * (
            math.exp(-self.rate * step / tau) if exact else 1.0 - self.rate * (step / tau)
        )


@dataclass(frozen=True)
class PhaseGate(DelayedGoal):
    """``G = ϑ``: a delayed goal whose rate is the phase's own (Eq. 10; Pastor's smooth scaling with
    ``K = αβ``). It is the phase itself, so it costs nothing."""

    def on_grid(self, phase: np.ndarray, step: float, tau: float, exact: bool) -> np.ndarray:
        return _grid_args(phase, step, tau, exact)[0]

    def _next(self, gate: float, phase: float, step: float, tau: float, exact: bool) -> float:
        return phase


@dataclass(frozen=True, eq=False)
class ProgressGate(_SteppedGoal):
    """The robot protocol's gate, learned at ``fit``: ``gate`` (n_train,) on the training grid of
    phases ``training_phase`` (n_train,), decreasing), looked up by phase at any other grid."""

    training_phase: np.ndarray
    gate: np.ndarray
    _lookup: tuple = field(init=False, repr=False)

    def __post_init__(self) -> None:
        kind = type(self).__name__
        phase, gate = (
            as_vector(self.training_phase, f"{kind}.training_phase"),
            as_vector(self.gate, f"{kind}.gate"),
        )
        if gate.shape != phase.shape or phase.size < 2 or np.any(np.diff(phase) >= 0.0):
            raise ValueError(
                f"{kind}: training_phase must decrease strictly, with one gate value per phase"
            )
        object.__setattr__(self, "training_phase", phase)
        object.__setattr__(self, "gate", gate)
        # np.interp wants increasing abscissae: the reversed grid, built once (a control loop
        # asks for one phase per step).
        object.__setattr__(self, "_lookup", (self.training_phase[::-1], self.gate[::-1]))

    @staticmethod
    def learn(
        train: np.ndarray,
        n_motion: int,
        dt: float,
        *,
        gains: _Gains,
        exact: bool,
        progress: np.ndarray | None = None,
    ) -> np.ndarray:
        """The gate on the training grid for a demonstration as learned, ``train`` (n_train, D)
        (exact: the smooth goal share's continuous inverse; Euler: :func:`_euler_progress_gate`),
        for the transformation system's ``gains``. ``progress`` replaces the demonstration's own
        arc-length progress (a part that does not move follows another's)."""
        alpha, beta, K = gains
        progress = _training_progress(train, progress)
        if not exact:
            return _euler_progress_gate(progress, dt, alpha=alpha, beta=beta, K=K)
        return _goal_gate(_goal_share(progress, n_motion, dt), dt, alpha=alpha, beta=beta, K=K)

    def on_grid(self, phase: np.ndarray, step: float, tau: float, exact: bool) -> np.ndarray:
        return np.interp(_grid_args(phase, step, tau, exact)[0], *self._lookup)

    def training_gate(self, n_train: int, dt: float, exact: bool) -> np.ndarray:
        """The learned gate itself (the training grid is the one it was learned on)."""
        n_train, dt, exact = _training_args(n_train, dt, exact)
        if n_train != self.gate.shape[0]:
            raise ValueError(
                f"n_train: the progress gate was learned on {self.gate.shape[0]} samples, not {n_train}"
            )
        return self.gate

    def _next(self, gate: float, phase: float, step: float, tau: float, exact: bool) -> float:
        return float(np.interp(phase, *self._lookup))


def _learned_progress_gate(system, params) -> ProgressGate:
    """The :class:`ProgressGate` a fitted system learned (its ``goal_gate`` on its training grid,
    :class:`~bidmp.primitives.system.DMPSystem`) for the settings ``params``."""
    gate = system.goal_gate
    n_train = system.n_train
    if gate is None or gate.shape[0] != n_train:
        raise ValueError(
            "this DMP has no progress gate for its goal (it was fitted with goal_rate set); "
            "set goal_rate to a number or fit it again"
        )
    training_phase = params.canonical_system.grid(n_train, system.dt, 1.0)
    _check_decaying(training_phase, params.canonical_system)
    return ProgressGate(training_phase, gate)


def _check_decaying(phase: np.ndarray, canonical_system) -> None:
    if not strictly_decreasing(np.asarray(phase, dtype=np.float64)):
        raise ValueError(
            "the progress gate looks the goal's share up by the phase, which must decay; "
            f"{type(canonical_system).__name__} does not: set goal_rate to a number"
        )


def _gate_past_training(gate: np.ndarray, phase: np.ndarray, canonical_system) -> np.ndarray | None:
    """A learned progress gate ``gate`` (n,) on its own training grid and one sample past it, the
    grid of phases ``phase`` (n + 1,) it was learned on: the gate itself, then its last value (the
    lookup by phase holds it beyond the grid) — what :meth:`ProgressGate.on_grid` returns there,
    without building the lookup (a fit needs it for its cached rollout grid); None where the lookup
    would interpolate instead."""
    _check_decaying(phase[:-1], canonical_system)
    if not phase[-1] <= phase[-2]:
        return None  # a phase rising again past the grid: the lookup interpolates there
    out = np.empty(gate.shape[0] + 1)
    out[:-1] = gate
    out[-1] = gate[-1]
    return out


class ApproachGate(ProgressGate):
    """The progress gate, with the goal's share reaching 1 where the final approach begins, and
    held at 0 until a kept departure ends.

    ``R`` is the demonstration's arc-length progress normalised to the stretch between the
    departure's end and the approach's start, ``(σ - σ_d) / (σ_a - σ_d)`` (``σ_d = 0`` without a
    departure), with the same smooth ends as :func:`_goal_share`; so ``R = 1`` over the whole
    approach, and a goal moved by Δ moves every approach sample by exactly Δ: a translated copy, no
    tilt. ``R = 0`` over the departure, so a moved goal does not move it, and a moved start (which
    moves the motion by ``(1 - R)`` times the shift) moves it whole: a translated copy too. ``R``
    stays monotone and its first three derivatives are 0 where it leaves 0 (the smoothstep begins at
    the departure's end). The overshoot bound of :func:`_goal_share` holds with the approach's start
    in the place of the motion's end.
    """

    @staticmethod
    def learn(
        train: np.ndarray,
        n_motion: int,
        dt: float,
        *,
        gains: _Gains,
        exact: bool,
        progress: np.ndarray | None = None,
        kept: tuple[int, int],
    ) -> np.ndarray:
        """The gate on the training grid; ``kept`` = (the sample where a kept departure ends, 0 for
        none; the one where the approach begins)."""
        alpha, beta, K = gains
        departure_end, approach_start = kept
        progress = _training_progress(train, progress)
        reach, leave = float(progress[approach_start]), float(progress[departure_end])
        normalised = np.clip((progress - leave) / (reach - leave), 0.0, 1.0)
        share = _goal_share(normalised, approach_start + 1, dt, begin=departure_end * dt)
        return _goal_gate(share, dt, alpha=alpha, beta=beta, K=K)


MAX_DEPARTURE_SHARE = 0.4  # of the path's length: a longer straight head is the transfer itself
MIN_TRANSFER_SHARE = 0.3  # of the path's length left between a kept departure and the kept approach


# a departure rises: its direction within this of straight up (+z)
MAX_LIFT_ANGLE = np.radians(45.0)


def _departure_end(demonstration: np.ndarray, approach_start: int) -> int:
    """Where the demonstration's departure ends: its straight head, when that is a lift (3-D, within
    45 degrees of straight up: off a part, not a handwriting stroke), 5-40 % of the path, and leaves
    at least 30 % of it before the approach (a head that is most of the way, like a min-jerk leg
    from the start to the approach, is the transfer); 0 when it has none."""
    from .approach import _straight_head_end

    if demonstration.shape[1] != 3:
        return 0
    end = _straight_head_end(demonstration)
    progress = _arclength_progress(demonstration)
    head, before = float(progress[end]), float(progress[approach_start])
    if (
        end < 2
        or head < MIN_APPROACH_SHARE
        or head > MAX_DEPARTURE_SHARE
        or before - head < MIN_TRANSFER_SHARE
    ):
        return 0
    rise = demonstration[end] - demonstration[0]
    if (
        np.arccos(np.clip(rise[2] / max(float(np.linalg.norm(rise)), 1e-300), -1.0, 1.0))
        > MAX_LIFT_ANGLE
    ):
        return 0
    return int(end)


def _learn_goal_gate(
    train: np.ndarray,
    n_motion: int,
    dt: float,
    params,
    progress=None,
    demonstration: np.ndarray | None = None,
) -> np.ndarray:
    """The goal gate a DMP with resolved ``params`` learns on its training grid: a delayed goal's,
    the progress gate, or (``keep_approach``) the approach gate, the approach found as the straight
    tail of ``demonstration`` (T, D) into its goal and a departure as its straight head
    (:func:`_departure_end`; a demonstration without an approach gets the progress gate)."""
    if params.goal_rate is not None:
        return DelayedGoal(params.goal_rate).training_gate(train.shape[0], dt, params.exact)
    shared = {"gains": params.gains, "exact": params.exact, "progress": progress}
    if params.keep_approach and demonstration is not None:
        start = _tail_start(demonstration)
        progress_at = _arclength_progress(demonstration)[start] if start >= 2 else 0.0
        # An approach is a straight tail of a real share of the path: any curve's last few samples
        # are straight to 2 % of their short chord.
        if progress_at > 0.0 and 1.0 - progress_at >= MIN_APPROACH_SHARE:
            return ApproachGate.learn(
                train,
                n_motion,
                dt,
                kept=(_departure_end(demonstration, start), start),
                **shared,
            )
    return ProgressGate.learn(train, n_motion, dt, **shared)
