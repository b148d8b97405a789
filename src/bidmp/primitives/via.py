"""Exact via-points: the smallest change of a DMP's forcing weights that makes its timed rollout
pass through given points at given times (``trajectory(..., via=[(t, point), ...])``).

A rollout is affine in the forcing weights: the weights enter the input ``K f(phase) = K ψ(phase) W``
and the transformation system is linear time-invariant on the sample grid. So the positions at
the via times are ``y_k = y_k⁰ + A_k ΔW`` with ``A`` (m, N) the response of sample ``k`` to a unit
weight on each kernel, and the least-norm ``ΔW = A⁺ (p - y⁰)`` (N, D) passes every via-point
exactly (to rounding) while changing the learned shape as little as the kernels allow: one small
least-squares solve, no iteration.

``A`` is not built by N rollouts: sample ``k`` weighs the input at sample ``i`` by the system's
impulse response ``r[k - i]`` (the same for every ``i ≥ 1`` on a uniform grid; the first sample
has its own, the exact integrator holding the input linear over each step), so ``A_k = r_k ψ``
is one impulse response and one matrix product per via-point. Tested against N perturbed
rollouts (tests/primitives/test_via.py).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple

import numpy as np

from .._checks import as_point, check_real
from .integrate import _unit_responses
from .timed import _checked_limits, _time_grid
from .timing import _Rollout, scale_factor

__all__ = []

# A via-point whose response rows are this close to dependent (relative smallest singular value)
# asks the kernels for a weight change out of proportion: refused rather than returned.
_CONDITION = 1e-9
# Without limits, a motion through the via-points whose peak acceleration is this many times a
# minimum-jerk motion's over the same reach and duration is refused: the kernels can only carry it
# as a violent swing (two via-points 50 mm apart 0.1 ms apart on a 3 s motion ask for 60 000x; a
# via-point 30 mm off the path 11x).
_MAX_SWING = 100.0
# of a kernel's activation on the rollout grid: before ``via_until``, it may change
_UNTIL_SHARE = 0.99


class _Via(NamedTuple):
    """Checked via-points: times (m,) in seconds, points (m, D), and ``until`` (s) or None."""

    times: np.ndarray
    points: np.ndarray
    until: float | None


class _Grid(NamedTuple):
    """The rollout's grid: the system at the motion's ``tau``
    (:class:`~bidmp.primitives.system.DMPSystem`), normalised step, samples, sample period (s)."""

    system: object
    step: float
    n_samples: int
    dt: float


# peak acceleration of a rest-to-rest minimum-jerk motion, reach / T²
_MINIMUM_JERK_PEAK = 10.0 / np.sqrt(3.0)


def _parse_via(via, n_dims: int, horizon: float) -> tuple[np.ndarray, np.ndarray]:
    """(times (m,) s, points (m, D)) of ``via`` = ``[(t, point), ...]``, validated; ``horizon``
    (s) is the motion's duration (after it the motion settles at its goal)."""
    if not isinstance(via, (list, tuple)):
        raise TypeError(f"via must be a list of (t_seconds, point) pairs, got {type(via).__name__}")
    times, points = [], []
    for index, pair in enumerate(via):
        if isinstance(pair, (str, bytes)) or not hasattr(pair, "__len__") or len(pair) != 2:
            raise TypeError(f"via[{index}] must be a (t_seconds, point) pair")
        t = check_real(pair[0], f"via[{index}] time", nonnegative=True)
        if t > horizon * (1 + 1e-12):
            raise ValueError(
                f"via[{index}] time {t:g} s is past the motion's duration ({horizon:g} s; after it the "
                f"motion settles at its goal)"
            )
        times.append(t)
        points.append(as_point(pair[1], n_dims, f"via[{index}] point"))
    if not times:
        raise ValueError("via is empty: give at least one (t_seconds, point) pair")
    times = np.array(times)
    if np.unique(times).size != times.size:
        raise ValueError("via has two points at the same time")
    return times, np.array(points)


def _interpolation(times: np.ndarray, dt: float, n: int) -> list[tuple[int, float]]:
    """For each time, the sample below it and the share of the one above (linear interpolation on
    a grid ``dt`` apart, ``n`` samples)."""
    pairs = []
    for t in times:
        index = t / dt
        low = min(int(np.floor(index + 1e-9)), n - 2)
        pairs.append((low, min(max(index - low, 0.0), 1.0)))
    return pairs


def _impulse_rows(
    params, phase: np.ndarray, step: float, between: list[tuple[int, float]]
) -> np.ndarray:
    """(m, n) weights of each sample's forcing ``f`` (K included) on the position at each via time,
    linearly between the two samples around it (``between``: :func:`_interpolation`):
    ``y(t_k) = y⁰(t_k) + rows_k @ f``."""
    n = phase.shape[0]
    impulses = np.zeros((n, 2))
    impulses[0, 0] = impulses[1, 1] = 1.0
    first, later = _unit_responses(params, phase, impulses, step)  # (n,) each: y's response
    rows = np.zeros((len(between), n))
    for row, (low, share) in zip(rows, between):
        for sample, weight in ((low, 1.0 - share), (low + 1, share)):
            if weight == 0.0:
                continue
            row[0] += weight * first[sample]
            if sample >= 1:  # inputs 1..sample, each through the shifted impulse response
                row[1 : sample + 1] += weight * later[sample:0:-1]
    return rows


def _via_increment(
    via: _Via, ends: tuple, grid: _Grid, forcing_increment: Callable | None
) -> Callable:
    """The forcing increment ``(phase, basis) -> (n, D)`` that moves the rollout from ``ends`` =
    (goal, start) through the via-points with the least-norm weight change. The rollout's own
    positions at the via times come from the same responses (its forcing through the impulse
    rows, goal and start through their unit responses): no rollout is run for them. ``via.until``
    (s): only the kernels with :data:`_UNTIL_SHARE` of their activation before it change (after it
    the motion returns to its own course). Raises ``ValueError`` when the kernels cannot carry
    the via-points."""
    times, points, until = via
    system, step, n_samples, dt = grid
    params = system.settings
    n_kernels = system.weights.shape[0]
    if times.size > n_kernels:
        raise ValueError(
            f"via has {times.size} points; this DMP's {n_kernels} kernels can carry at most {n_kernels}"
        )
    phase, basis, (goal_response, start_response, _), _ = system.grid(n_samples, step)
    # Only the samples up to the last via-point's matter (a response never reaches back in time).
    used = min(int(np.ceil(times.max() / dt)) + 2, phase.shape[0])
    between = _interpolation(times, dt, used)
    rows = _impulse_rows(params, phase[:used], step, between)
    response = rows @ basis[:used]  # (m, N): per unit weight (K inside)
    if until is not None:
        cut = min(max(int(np.floor(until / dt)) + 1, 1), basis.shape[0])
        activation = np.abs(basis)
        early = activation[:cut].sum(axis=0) >= _UNTIL_SHARE * activation.sum(axis=0)
        if not np.any(early):
            raise ValueError(
                f"via_until {until:g} s: no kernel of this DMP acts before it; give a later time"
            )
        response = response * early  # the kernels acting after ``until`` keep their weights
    singular = np.linalg.svd(response, compute_uv=False)
    if singular[-1] <= _CONDITION * max(singular[0], 1e-300):
        at = ", ".join(f"{t:g}" for t in times)
        raise ValueError(
            f"via: the kernels cannot carry via-points at t = {at} s (too close together, at the "
            f"start, or where the phase has decayed); move them apart or earlier"
        )
    goal, start = ends
    baseline = response @ system.weights  # rows @ (basis @ W), without the (n, D) forcing
    if forcing_increment is not None:
        baseline += rows @ forcing_increment(phase, basis)[:used]
    for k, (low, share) in enumerate(between):
        at = (1.0 - share) * np.array([goal_response[low], start_response[low]]) + share * np.array(
            [goal_response[low + 1], start_response[low + 1]]
        )
        baseline[k] += at[0] * goal + at[1] * start
    change = np.linalg.lstsq(response, points - baseline, rcond=None)[0]  # least-norm (N, D)
    # A protocol that comes to rest at its goal (the paper's stops before it does), its change free to
    # act anywhere: a change kept before ``until`` is the caller's to judge (a repair judges the
    # motion it makes by the motion contract).
    if params.settle > 1.0 and until is None:
        _check_end(grid, (phase, basis), change, ends, via)

    def increment(phase_in: np.ndarray, basis_in: np.ndarray) -> np.ndarray:
        added = basis_in @ change
        return added if forcing_increment is None else forcing_increment(phase_in, basis_in) + added

    # (N, D): what the via-points cost the learned shape; a rollout adds it to the weights in one
    # product (DMPSystem.free_response) and calls ``wrapped`` for the rest.
    increment.weight_change, increment.wrapped = change, forcing_increment
    return increment


# A via-point change may move the motion's end by at most this share of its reach, and leave it moving
# at most this share of its reach per second of its duration: the goal reached at rest, as without it.
_END_SHARE = 1e-4
_END_SPEED_SHARE = 1e-2


def _check_end(grid: _Grid, rows: tuple, change: np.ndarray, ends: tuple, via: _Via) -> None:
    """Refuse a weight change that moves the motion's last sample off where it ends without it, or
    leaves it moving there: via-points late in a motion are carried by kernels that still act at its
    end. From the same impulse responses as the via-points (no rollout); ``rows`` = the rollout
    grid's phase (n,) and basis (n, N)."""
    system, step, _, dt = grid
    params = system.settings
    phase, basis = rows
    times, points, _ = via
    last = phase.shape[0] - 1
    # samples last, last - 1
    rows = _impulse_rows(params, phase, step, [(last - 1, 1.0), (last - 1, 0.0)])
    moved = rows @ (basis @ change)  # (2, D)
    corners = np.vstack([ends[0], ends[1], points])
    reach = max(float(np.max(np.linalg.norm(corners[:, None] - corners[None], axis=2))), 1e-300)
    horizon = last * dt
    off = float(np.linalg.norm(moved[0]))
    speed = float(np.linalg.norm(moved[0] - moved[1])) / dt
    if off > _END_SHARE * reach or speed > _END_SPEED_SHARE * reach / horizon:
        raise ValueError(
            f"via: the kernels that carry a via-point at {times.max():g} s still act at the motion's end: "
            f"it would end {off:.3g} units off its goal and still moving ({speed:.3g} units/s) after "
            f"{horizon:.3g} s; put the via-points earlier"
        )


def _via_trajectory(dmp, request: _Rollout):
    """:meth:`bidmp.DMP.trajectory` through ``request.via``: the least-norm weight change, then the
    rollout with it (and ``limits`` checked, not met by re-timing: a re-timed motion would reach
    the via-points at other times)."""
    goal, start, limits, until = request.goal, request.start, request.limits, request.via_until
    if request.start_velocity is not None:
        raise ValueError(
            "via-points are solved for a motion from rest: start_velocity cannot be given with via"
        )
    if limits is not None:
        # checked before the solve; "fastest" does not apply (not re-timed)
        limits = _checked_limits(limits)[0]
    system = dmp.system_
    motion, dt_used, n_samples, step = _time_grid(system, request.duration, request.dt)
    times, points = _parse_via(request.via, system.n_dims, min(motion, (n_samples - 1) * dt_used))
    ends = (
        system.goal if goal is None else as_point(goal, system.n_dims, "goal"),
        system.start if start is None else as_point(start, system.n_dims, "start"),
    )
    system = system.with_tau(motion / system.duration)  # its grid checks the step
    if until is not None:
        until = check_real(until, "via_until", positive=True)
        if np.any(times > until):
            raise ValueError(
                f"via_until {until:g} s is before a via-point ({times.max():g} s): the change must act there"
            )
    increment = _via_increment(
        _Via(times, points, until),
        ends,
        _Grid(system, step, n_samples + 2, dt_used),
        request.forcing_increment,
    )
    result = dmp.trajectory(
        goal,
        start=start,
        duration=motion,
        dt=dt_used,
        forcing_increment=increment,
        coupling=request.coupling,
    )
    if limits:
        factor = scale_factor(result, **limits)
        if factor > 1.0 + 1e-9:
            raise ValueError(
                f"via: the motion through the via-points needs {factor:.3g}x its duration to stay within "
                f"the limits; move the via-points or give a longer duration"
            )
    else:
        # Against the peak acceleration of a minimum-jerk motion over the same reach and duration.
        scale = (
            _MINIMUM_JERK_PEAK * max(float(np.linalg.norm(ends[0] - ends[1])), 1e-300) / motion**2
        )
        swing = _peak(result.ydd) / scale
        if swing > _MAX_SWING:
            raise ValueError(
                f"via: the kernels can carry these via-points only with {swing:.3g}x the peak acceleration "
                f"of a minimum-jerk motion over the same reach (at most {_MAX_SWING:g}x without limits); "
                f"move them apart or closer to the path"
            )
    return result


def _peak(values: np.ndarray) -> float:
    return float(np.max(np.linalg.norm(values, axis=1)))
