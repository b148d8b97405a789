"""Timed rollouts of a DMP: positions, velocities and accelerations in seconds at any rate
(:meth:`bidmp.DMP.trajectory`), within velocity, acceleration and jerk limits, and through the
step integrator when coupling terms are given."""

from __future__ import annotations

import numpy as np

from .._checks import _limit, as_point, check_int, check_real, short_token
from .._kernels import exact_rates
from .._units import check_reach
from .avoidance import SceneAvoidance, _check_avoidance
from .canonical import _TAU_RANGE
from .integrate import _foh_step
from .limits import MotionLimits
from .settings import DMPSettings
from .stepper import DMPStepper
from .system import DMPSystem
from .timing import Trajectory, _Rollout, _rollout_trajectory, scale_factor

__all__ = []


def _time_grid(system: DMPSystem, duration, dt) -> tuple[float, float, int, float]:
    """(motion duration s, sample period s, number of samples, normalised step) of a timed
    rollout of ``system``; the motion's duration defaults to ``tau · duration``, the period to the
    demonstration's."""
    params = system.settings
    motion = (
        params.tau * system.duration
        if duration is None
        else check_real(duration, "duration", positive=True)
    )
    period = system.duration / (system.n_samples - 1)
    # 1 MHz at most
    dt = period if dt is None else check_real(dt, "dt", positive=True, minimum=1e-6)
    if dt > motion:
        raise ValueError(f"dt = {dt:g} s is longer than the motion's duration ({motion:g} s)")
    scale = motion / system.duration  # temporal scaling: the shape is kept, time stretched
    check_real(
        scale,
        "duration / duration_ (the temporal scaling)",
        minimum=_TAU_RANGE[0],
        maximum=_TAU_RANGE[1],
    )
    if params.protocol == "paper" and duration is None and dt == period:
        n_samples = max(int(round(params.tau * system.n_samples)), 1)  # the rollout's own samples
    else:
        samples = params.settle * motion / dt * (1 + 1e-12)
        check_real(samples, "the trajectory's samples (duration / dt)", maximum=_limit("max_steps"))
        n_samples = int(np.floor(samples)) + 1  # never past settle x motion
    check_int(n_samples, "the trajectory's samples (duration / dt)", limit="max_steps")
    step = system.dt if dt == period else dt / system.time_unit
    return motion, dt, n_samples, step


def _timed_trajectory(dmp, request: _Rollout):
    """The fast path of :meth:`bidmp.DMP.trajectory` (no limits, no coupling terms)."""
    goal, start, start_velocity = request.goal, request.start, request.start_velocity
    system = dmp.system_
    motion, dt, n_samples, step = _time_grid(system, request.duration, request.dt)
    system = system.with_tau(motion / system.duration)
    params = system.settings
    velocity = (
        None
        if start_velocity is None
        else as_point(start_velocity, system.n_dims, "start_velocity") * system.time_unit
    )
    # Two extra samples give the last velocity and acceleration as forward differences (Euler),
    # one the last exact state.
    free, goal_response, forcing, gate = system.free_response(
        n_samples + 2,
        start=start,
        start_velocity=velocity,
        forcing_increment=request.forcing_increment,
        step=step,
    )
    goal = system.goal if goal is None else as_point(goal, free.shape[1], "goal")
    if dmp.units_:  # a goal in the wrong unit is far beyond any robot's reach: say so
        check_reach(
            float(min(np.linalg.norm(goal - system.goal), np.linalg.norm(goal - system.start))),
            dmp.units_,
            "the goal",
        )
    positions = free + goal_response[:, None] * goal
    if params.exact:
        start = system.start if start is None else as_point(start, free.shape[1], "start")
        velocities, accelerations = _exact_rates(
            params, positions, forcing, gate, (goal, start, velocity), step, system.time_unit
        )
    else:
        velocities = np.diff(positions, axis=0) / dt
        accelerations = np.diff(velocities, axis=0) / dt
    return _rollout_trajectory(
        np.arange(n_samples) * dt,
        positions[:n_samples],
        velocities[:n_samples],
        accelerations[:n_samples],
        dmp.units_,
        tuple(dmp.__dict__.get("names_", ())),
    )


def _exact_rates(
    params: DMPSettings, positions, forcing, gate, ends: tuple, step: float, time_unit: float
) -> tuple:
    """Velocities (units/s) and accelerations (units/s²) of an exact rollout (n + 1 samples in,
    n out): the system's own state and acceleration, from the positions and the input ``u = αβ g
    + K f - K gate (g - y0)`` (one compiled pass); ``ends`` = (goal, start, start velocity or
    None), the velocity in units per normalised time. The first state is given, not solved for:
    a rest start is exactly at rest."""
    goal, start, velocity = ends
    transition, now, after = _foh_step(step, params.alpha, params.beta, params.tau)
    return exact_rates(
        positions,
        forcing,
        gate,
        goal,
        start,
        None if velocity is None else params.tau * velocity,
        params.K,
        params.alpha * params.beta,
        params.alpha,
        params.tau**2,
        transition[0, 0],
        transition[0, 1],
        now[0],
        after[0],
        params.tau * time_unit,
        time_unit**2,
    )


def _checked_limits(limits) -> tuple[dict, bool]:
    """A trajectory's ``limits`` (a :class:`bidmp.MotionLimits` or its dict form) as
    :func:`scale_factor`'s keywords, and its ``fastest`` flag."""
    if isinstance(limits, MotionLimits):
        return limits.caps(), limits.fastest
    if not isinstance(limits, dict):
        raise TypeError(
            f"limits must be a bidmp.MotionLimits or a dict of max_velocity / max_acceleration / "
            f"max_jerk / norm / fastest, got {type(limits).__name__}"
        )
    unknown = set(limits) - {"max_velocity", "max_acceleration", "max_jerk", "norm", "fastest"}
    if unknown:
        raise ValueError(
            f"limits has unknown key(s) {short_token(sorted(map(str, unknown)), 40)}; known: max_velocity, "
            f"max_acceleration, max_jerk, norm, fastest"
        )
    limits = dict(limits)
    fastest = limits.pop("fastest", False)
    if not isinstance(fastest, (bool, np.bool_)):
        raise TypeError(f"limits['fastest'] must be True or False, got {type(fastest).__name__}")
    return limits, bool(fastest)


def _limited_trajectory(dmp, request: _Rollout):
    """The trajectory within ``limits``: at the nominal duration if that meets them (limits
    are caps: they never speed a motion up, unless ``"fastest": True``), otherwise the
    shortest duration that does: scale by the exact factor of
    :func:`bidmp.primitives.timing.scale_factor`, then bisect for what the discretisation changes."""
    limits, fastest = _checked_limits(request.limits)

    def attempt(duration):
        trajectory = dmp.trajectory(
            request.goal,
            start=request.start,
            duration=duration,
            dt=request.dt,
            start_velocity=request.start_velocity,
            forcing_increment=request.forcing_increment,
            coupling=request.coupling,
        )
        return trajectory, scale_factor(trajectory, **limits)

    # The exact factor first (speed ~ 1/k, acceleration ~ 1/k²), then a bisection in log
    # duration for what re-integrating at another step changes: the result meets every
    # limit and touches the binding one within 0.1 %.
    duration = dmp.settings().tau * dmp.duration_
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


def _coupled_trajectory(dmp, request: _Rollout) -> Trajectory:
    """:meth:`bidmp.DMP.trajectory` through the step integrator, with coupling terms: the same
    samples as :func:`_timed_trajectory` (to rounding) when the terms add nothing. With a
    :class:`bidmp.primitives.avoidance.SceneAvoidance` term the motion runs on past the horizon
    until it comes to rest (at most as long again: steering round a part takes time), and its
    clearance is then checked exactly."""
    motion, dt, n_samples, _ = _time_grid(dmp.system_, request.duration, request.dt)
    stepper = DMPStepper(
        dmp,
        request.goal,
        request.start,
        motion,
        request.coupling,
        request.start_velocity,
        request.forcing_increment,
    )
    states = [stepper.step(dt) for _ in range(n_samples)]
    avoiding = [term for term in stepper.couplings if isinstance(term, SceneAvoidance)]
    reach = float(np.linalg.norm(stepper.target - stepper.start))
    if avoiding:
        for _ in range(n_samples):
            position, velocity = states[-1][0], states[-1][1]
            if (
                np.linalg.norm(velocity) * motion <= _REST_SHARE * reach
                and np.linalg.norm(position - stepper.target) <= _REST_SHARE * reach
            ):
                break
            states.append(stepper.step(dt))
    y, yd, ydd = (np.array([state[k] for state in states]) for k in range(3))
    if not (np.all(np.isfinite(y)) and np.all(np.isfinite(ydd))):
        raise ValueError(
            "trajectory: the coupled integration is not finite; a coupling term is out of range"
        )
    trajectory = Trajectory(
        np.arange(len(states)) * dt, y, yd, ydd, dmp.units_, tuple(dmp.__dict__.get("names_", ()))
    )
    if avoiding:
        _check_avoidance(avoiding, trajectory, stepper.target, reach)
    return trajectory


# A coupled motion is at rest when its speed is below this share of its mean speed (start-goal
# distance over the duration) and it is at its goal within this share of that distance.
_REST_SHARE = 1e-4
