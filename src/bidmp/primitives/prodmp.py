"""Probabilistic dynamic movement primitives (ProDMP; Li, Celik, Blessing, Zhou, Neumann,
"ProDMP: A Unified Perspective on Dynamic and Probabilistic Movement Primitives", RA-L 2023).

The DMP's second-order system, in the scaled time ``s = (t - delay) / tau`` (critically damped,
``beta = alpha / 4``),

    y'' + alpha y' + alpha² / 4 · y = alpha² / 4 · g + x(s) Σ_i φ_i(x(s)) w_i,

is linear, so its solution is closed form: the two homogeneous solutions ``y1 = e^(-alpha s / 2)``,
``y2 = s·y1`` carry the boundary condition (position and velocity at a time ``t_b``), and the
forced response is linear in the weights and the goal,

    y(s) = c1 y1(s) + c2 y2(s) + Φ(s)ᵀ [w; g],

with the position basis ``Φ_i(s) = ∫₀ˢ (s - r) e^(-alpha (s - r) / 2) x(r) φ_i(r) dr`` (the system's
Green's function convolved with the forcing basis) and the goal's ``1 - (1 + alpha s / 2)
e^(-alpha s / 2)``. Positions and velocities at any time are then one product of a basis with the
weights (:func:`prodmp_basis`, :class:`ProDMPBasis`), whole batches of starts and goals one
product more, and a Gaussian over the weights learned from several demonstrations conditions
exactly on via-points, as a ProMP's does (:class:`ProDMP`).

The forcing basis is MP_PyTorch's normalised RBF on the exponential phase ``x = e^(-alpha_phase
s)`` (centres evenly in time over [delay, delay + tau], ``n_outside`` more beyond each end,
widths ``bandwidth_factor / (distance between centres in phase)²``). The weights' integral is
precomputed as MP_PyTorch does — the trapezoidal rule on a grid of step ``dt / tau`` over ``s`` in
[0, ``length_factor``], as ``y2 ∫ e^(alpha r / 2) x φ dr - y1 ∫ r e^(alpha r / 2) x φ dr`` — and
read between grid points linearly; so bidmp's ProDMP and MP_PyTorch's give the same trajectories
on equal settings (``benchmarks/bench_prodmp.py`` compares them), and the grid's step sets the
accuracy of both (the trapezoid's error falls with ``dt²``; tested against a fine quadrature).

Layer 1: NumPy only.
"""

from __future__ import annotations

import numpy as np

from .._api import Estimator, integer, real
from .._checks import (
    NotFittedError,
    as_point,
    as_points,
    as_vector,
    check_bool,
    check_bytes,
    check_int,
    check_real,
)
from .._state import state_reader
from .._threads import single_threaded
from .._units import check_units
from .prodmp_responses import _MAX_OUTSIDE, ProDMPBasis, prodmp_basis
from .promp import _conditioned, _Conflict, _demonstrations, _stamps, condition_gaussian
from .timing import Trajectory

__all__ = ["ProDMP", "ProDMPBasis", "prodmp_basis"]


def _conflict_text(rows, times: np.ndarray, rest: np.ndarray, dims: int) -> str:
    """What :meth:`ProDMP.condition` says of two observations that conflict, the argument of
    the first named first."""
    named, arguments = [], []
    for row in sorted(set(rows)):
        index = row // dims
        if index < times.size:
            named.append(f"the via-point {index} (at {times[index]:.6g} s)")
            arguments.append("times")
        elif index < times.size + 2 * rest.size:  # (its velocity, then its acceleration)
            named.append(f"the rest at {rest[(index - times.size) % rest.size]:.6g} s")
            arguments.append("rest")
        else:
            named.append("the goal")
            arguments.append("goal")
    if rows[0] == rows[1]:
        return (
            f"{arguments[0]}: {named[0]} reads none of the weights to the floats' range (the "
            "motion is its start there); move it later or give cov > 0"
        )
    return (
        f"{arguments[0]}: {named[0]} and {named[1]} cannot both be met exactly (one time with "
        "different values, or more points than the weights can carry); give each its own time, "
        "fewer points or cov > 0"
    )


def _weight_covariance(weights: np.ndarray, cov_reg: float) -> np.ndarray:
    """The covariance (M, M) of weights (n, M) of n demonstrations plus ``cov_reg`` times each
    weight's own variance on the diagonal (its square where it does not vary: one demonstration).
    Per weight, not the mean variance a ProMP adds: a ProDMP's forcing weights run to 1e4 where
    its goal is a few units, and one isotropic term would make the goal's spread the forcing's."""
    size = weights.shape[1]
    cov = (
        np.cov(weights, rowvar=False).reshape(size, size)
        if weights.shape[0] > 1
        else np.zeros((size, size))
    )
    variance = np.diag(cov).copy()
    scale = np.where(variance > 0.0, variance, weights.mean(axis=0) ** 2)
    scale = np.maximum(scale, 1e-12 * max(float(scale.max()), 1e-300))
    cov[np.diag_indices(size)] += cov_reg * scale
    return cov


class ProDMP(Estimator):
    """A probabilistic DMP learned from one or several demonstrations (module docstring).

    Parameters
    ----------
    n_basis : int, default 10
        Forcing basis functions per dimension N (plus the goal: N + 1 weights per dimension).
    alpha : float, default 25
        The spring (critically damped: the damper ``alpha``, the stiffness ``alpha² / 4``).
    alpha_phase : float, default 3
        The phase's decay over the motion.
    tau : float or None, default None
        The time constant (s): the motion's duration. None: the demonstrations' mean duration.
    bandwidth_factor : float, default 3
    n_outside : int, default 0
        Forcing centres beyond each end of the motion.
    dt : float, default 0.01
        The precomputation grid's step (s).
    length_factor : float, default 6
        The grid covers ``length_factor · tau`` (at most 6).
    ridge : float, default 1e-9
        Ridge λ of each demonstration's weights (absolute, as MP_PyTorch's ``reg``).
    cov_reg : float, default 1e-2
        Added to the weights' covariance on the diagonal, times each weight's own variance.

    Attributes
    ----------
    basis_ : ProDMPBasis
    weights_ : array (M, D·(N+1))
        Each demonstration's weights, dimension after dimension, each ``[w (N), g]``.
    weight_mean_, weight_cov_ : array (D·(N+1),), (D·(N+1), D·(N+1))
    start_, start_velocity_ : array (D,)
        The demonstrations' mean start (units) and start velocity (units/s).
    duration_ : float
        ``tau`` (s).
    n_dims_ : int
    units_ : str
    """

    # What each parameter may be (set_params and fit check them; prodmp_basis's own bounds)
    _parameter_constraints = {
        "n_basis": integer(minimum=1, limit="max_kernels"),
        "alpha": real(positive=True, maximum=1e3),
        "alpha_phase": real(minimum=1e-6, maximum=1e3),
        "tau": real(optional=True, positive=True, maximum=1e4),
        "bandwidth_factor": real(positive=True, maximum=1e3),
        "n_outside": integer(minimum=0, maximum=_MAX_OUTSIDE),
        "dt": real(positive=True, maximum=1e4),
        "length_factor": real(positive=True, maximum=6.0),
        "ridge": real(nonnegative=True, maximum=1e6),
        "cov_reg": real(positive=True, maximum=1e3),
    }

    def __init__(  # noqa: PLR0913 - an estimator's constructor: each hyperparameter is one
        self,
        n_basis: int = 10,
        alpha: float = 25.0,
        alpha_phase: float = 3.0,
        tau: float | None = None,
        bandwidth_factor: float = 3.0,
        n_outside: int = 0,
        dt: float = 0.01,
        length_factor: float = 6.0,
        ridge: float = 1e-9,
        cov_reg: float = 1e-2,
    ) -> None:
        self.n_basis = n_basis
        self.alpha = alpha
        self.alpha_phase = alpha_phase
        self.tau = tau
        self.bandwidth_factor = bandwidth_factor
        self.n_outside = n_outside
        self.dt = dt
        self.length_factor = length_factor
        self.ridge = ridge
        self.cov_reg = cov_reg

    @single_threaded  # small dense algebra: idle BLAS threads only steal the core
    def fit(self, demonstrations, times=None, units: str | None = None) -> ProDMP:
        """Learn from ``demonstrations`` (a list of (T_i, D) arrays, or one (T, D)) with their
        stamps ``times`` (a list of (T_i,) arrays, s; None: each uniform over 1 s).
        Each demonstration is timed onto tau (its own phase, as a ProMP's), and its weights and
        goal are the least-squares fit of its positions from its own start (its first sample, the
        velocity of its first step), as MP_PyTorch learns them. Returns self."""
        if isinstance(demonstrations, np.ndarray) and demonstrations.ndim == 2:
            demonstrations = [demonstrations]  # one demonstration
        demos = _demonstrations(demonstrations)  # the ProMP's checks: one way to be refused
        self._check_constraints()
        ridge, cov_reg = float(self.ridge), float(self.cov_reg)
        units = "" if units is None else check_units(units)
        stamps = _stamps(times, demos)  # (each is timed onto tau below: the span is its own)
        tau = (
            float(np.mean([t[-1] - t[0] for t in stamps]))
            if self.tau is None
            else check_real(self.tau, "tau", positive=True, maximum=1e4)
        )
        basis = prodmp_basis(
            self.n_basis, tau, 0.0, self.alpha, self.alpha_phase, self.bandwidth_factor,
            self.n_outside, self.dt, self.length_factor,
        )  # fmt: skip
        size = basis.n_basis + 1
        n_dims = demos[0].shape[1]
        weights = np.empty((len(demos), n_dims * size))
        starts, velocities = [], []
        for index, (y, t) in enumerate(zip(demos, stamps)):
            # each demonstration on its own phase: its time stretched onto tau (as a ProMP's)
            t = (t - t[0]) * (tau / (t[-1] - t[0]))
            start, velocity = y[0], (y[1] - y[0]) / (t[1] - t[0])
            p0, v0, _, _, H, _ = basis.boundary_maps(t, 0.0)
            free = y - p0[:, None] * start - v0[:, None] * (velocity * tau)
            gram = H.T @ H + ridge * np.eye(size)
            weights[index] = np.linalg.solve(gram, H.T @ free).T.reshape(-1)
            starts.append(start)
            velocities.append(velocity)
        self.basis_ = basis
        self.weights_ = weights
        self.weight_mean_ = weights.mean(axis=0)
        self.weight_cov_ = _weight_covariance(weights, cov_reg)
        self.start_ = np.mean(starts, axis=0)
        self.start_velocity_ = np.mean(velocities, axis=0)
        self.duration_ = tau
        self.n_dims_ = n_dims
        self.units_ = units
        return self

    def check_fitted(self) -> None:
        """Raise :class:`bidmp.NotFittedError`, saying what to do, unless the model is fitted."""
        if "weight_mean_" not in self.__dict__:
            raise NotFittedError("this ProDMP is not fitted yet: call fit(demonstrations) first")

    def _times(self, times, n_steps: int | None) -> np.ndarray:
        if times is None:
            n_steps = check_int(
                100 if n_steps is None else n_steps, "n_steps", minimum=2, limit="max_steps"
            )
            return np.linspace(0.0, self.duration_, n_steps)
        times = as_vector(times, "times")
        if np.any(np.diff(times) < 0) or times[0] < 0:
            raise ValueError("times must be >= 0 and non-decreasing (s)")
        return times

    def _boundary(
        self, start, start_velocity, names=("start", "start_velocity")
    ) -> tuple[np.ndarray, np.ndarray]:
        """Start(s) and start velocity(ies) as points (k, D) each, refused by the caller's
        argument ``names``; the default start is the demonstrations' mean, one point (1, D), the
        default velocity rest (1, D). Their counts are the caller's to match (one, or one per
        motion)."""
        start = self.start_[None] if start is None else as_points(start, self.n_dims_, names[0])
        velocity = (
            np.zeros((1, self.n_dims_))
            if start_velocity is None
            else as_points(start_velocity, self.n_dims_, names[1])
        )
        return start, velocity

    def _single_boundary(self, start, start_velocity) -> tuple[np.ndarray, np.ndarray]:
        """:meth:`_boundary` of one motion: one start and one start velocity (1, D) each."""
        start, velocity = self._boundary(start, start_velocity)
        for name, values in (("start", start), ("start_velocity", velocity)):
            if len(values) != 1:
                raise ValueError(
                    f"{name} must be one point ({self.n_dims_},) for one motion, got {len(values)} "
                    f"(rollouts takes many)"
                )
        return start, velocity

    def rollouts(  # noqa: PLR0913 - one batch's boundary, goals and weights
        self,
        starts=None,
        goals=None,
        times=None,
        *,
        start_velocities=None,
        weights=None,
        conditioned: bool = False,
    ) -> np.ndarray:
        """(B, T, D) positions (units) at ``times`` (s; default 100 over tau) from each of
        ``starts`` (B, D; default the mean start) at rest (or ``start_velocities`` (B, D),
        units/s) to each of ``goals`` (B, D; default the weights' own goal), all in one product
        per term.

        The weights are the mean (or ``weights`` (D·(N+1),)) with the goal replaced; with
        ``conditioned=True`` the Gaussian's mean conditioned exactly on each goal instead (the
        forcing weights move with the goal as the demonstrations say; affine in the goal, so
        still one product)."""
        self.check_fitted()
        conditioned = check_bool(conditioned, "conditioned")
        t = self._times(times, None)
        starts, velocities = self._boundary(
            starts, start_velocities, ("starts", "start_velocities")
        )
        size, dims, n_times = self.basis_.n_basis + 1, self.n_dims_, len(t)
        mean = (
            self.weight_mean_
            if weights is None
            else as_vector(weights, "weights", length=self.weight_mean_.size)
        )
        p0, v0, _, _, H, _ = self.basis_.boundary_maps(t, 0.0)
        w = mean.reshape(dims, size)
        if goals is None:
            goals, goal_rows, base = np.zeros((1, dims)), None, H @ w.T
        else:
            goals = as_points(goals, dims, "goals")
            eye = np.eye(dims)
            if conditioned:
                goal_index = self._goal_index()
                cov = self.weight_cov_
                gain = np.linalg.solve(cov[np.ix_(goal_index, goal_index)], cov[goal_index]).T
                # row e: what a unit of goal e adds at (t, d) through every weight it moves
                goal_rows = np.einsum("tk,dke->etd", H, gain.reshape(dims, size, dims))
                base = H @ w.T - np.einsum("etd,e->td", goal_rows, mean[goal_index])
            else:
                goal_rows = H[None, :, -1:] * eye[:, None, :]  # the goal weight's own column
                base = H[:, :-1] @ w[:, :-1].T
        batch = max(len(starts), len(velocities), len(goals))
        check_bytes(
            batch * n_times * dims, f"the rollouts ({batch} starts or goals x {n_times} times x D)"
        )
        counts = {"starts": len(starts), "start_velocities": len(velocities), "goals": len(goals)}
        if any(count not in (1, batch) for count in counts.values()):
            # which one is wrong is the caller's to say: name them all with their shapes
            given = ", ".join(f"{name} ({count}, {dims})" for name, count in counts.items())
            raise ValueError(
                f"starts, start_velocities and goals must each have shape (1, {dims}) or (B, "
                f"{dims}) with one B for all (one per rollout); got {given}"
            )
        # The rollouts are affine in the starts, start velocities and goals: one matrix product
        # of their coefficients with a row per coefficient writes the whole batch (B, T·D).
        coefficients, rows = [np.ones((batch, 1))], [base.reshape(1, -1)]
        diagonal = np.eye(dims)[:, None, :]
        for values, profile in ((starts, p0), (velocities * self.duration_, v0)):
            block = (profile[None, :, None] * diagonal).reshape(dims, -1)
            if len(values) == 1:
                rows[0] = rows[0] + values @ block
            else:
                coefficients.append(values)
                rows.append(block)
        if goal_rows is not None:
            coefficients.append(np.broadcast_to(goals, (batch, dims)))
            rows.append(goal_rows.reshape(dims, -1))
        out = np.hstack(coefficients) @ np.vstack(rows)
        return out.reshape(batch, n_times, dims)

    def rollout(self, goal=None, *, start=None, n_steps: int = 100) -> np.ndarray:
        """(n_steps, D): the positions (units) over tau of :meth:`trajectory` (the mean from
        ``start`` at rest to ``goal`` at rest, conditioned on both), as
        :meth:`bidmp.DMP.rollout` gives them."""
        return self.trajectory(goal, start=start, n_steps=n_steps).y

    def conditioned(self, *, start=None, start_velocity=None, goal=None, via=(), duration=None):
        """A copy conditioned exactly on a motion from ``start`` (D,; default the mean start) at
        ``start_velocity`` (D,, units/s; default rest) through each via-point ``(t, point)`` (t
        in s of a motion ``duration`` s long, default tau) to ``goal`` (D,) at rest at the end,
        staying there (the goal weight is the goal) — the model itself (its start set) when
        neither a goal nor a via-point is given. Without a goal, a via-point bends the middle:
        the end is where the mean from that start ends, at rest."""
        import copy

        from .interface import _via_points

        self.check_fitted()
        span, stretch = self._stretch(duration)
        times, points = _via_points(via, self.n_dims_, span)
        velocity = None if start_velocity is None else self._velocity(start_velocity) * stretch
        if goal is None and not times.size:
            if start is None and start_velocity is None:
                return self
            # the boundary is exact in the closed form: no weight moves
            start, velocity = self._single_boundary(start, velocity)
            moved = copy.copy(self)
            moved.start_, moved.start_velocity_ = start[0], velocity[0] / stretch
            return moved
        if goal is None:
            goal = self._closed_form(np.array([self.duration_]), start, velocity, None, None).y[0]
        goal = as_points(goal, self.n_dims_, "goal")[0]
        return self.condition(
            np.concatenate([times / stretch, [self.duration_]]),
            np.vstack([points, goal]),
            start=start,
            start_velocity=velocity,
            rest=[self.duration_],
            goal=goal,
        )

    def _stretch(self, duration) -> tuple[float, float]:
        """A motion ``duration`` s long (default tau) and its stretch of the model's time."""
        if duration is None:
            return self.duration_, 1.0
        duration = check_real(duration, "duration", positive=True, maximum=1e6)
        return duration, duration / self.duration_

    def _velocity(self, start_velocity) -> np.ndarray:
        """One motion's start velocity (D,) (one point: refused otherwise, naming it)."""
        return self._single_boundary(None, start_velocity)[1][0]

    def trajectory(  # noqa: PLR0913 - the motion interface's keywords and ProDMP's own
        self,
        goal=None,
        *,
        start=None,
        start_velocity=None,
        duration: float | None = None,
        dt: float | None = None,
        via=(),
        limits=None,
        times=None,
        n_steps: int | None = None,
        weights=None,
        attractor=None,
    ) -> Trajectory:
        """The **mean** motion conditioned on what is given (:meth:`conditioned`): from
        ``start`` (D,; default the demonstrations' mean start) at ``start_velocity`` (units/s;
        default rest) through ``via`` to ``goal`` at rest; positions and velocities in closed
        form, the acceleration from the system's equation (exact, not differenced).

        Sampled every ``dt`` s over ``duration`` (s; default tau) rounded down to whole steps
        (the end is a sample), or at ``times`` (s), or ``n_steps`` (default 100) over the
        duration. ``limits`` (a :class:`bidmp.MotionLimits` or its dict form): a motion that
        breaks a cap is slowed uniformly to the shortest duration that meets them; with
        via-points it is checked, not re-timed.

        ProDMP's own, the weights as they are (no conditioning; with neither ``goal`` nor
        ``via``): ``weights`` (D·(N+1),) in place of the mean, ``attractor`` (D,) the goal
        weight (the spring's rest point, not where the motion ends: :meth:`goal_for_end`)."""
        from .interface import _via_points, _within_limits

        self.check_fitted()
        raw = weights is not None or attractor is not None
        nominal, _ = self._stretch(duration)
        has_via = bool(_via_points(via, self.n_dims_, nominal)[0].size)
        if raw and (goal is not None or has_via):
            raise ValueError(
                "weights / attractor run the weights as they are: give goal= and via= (the mean "
                "conditioned on them) or weights= / attractor=, not both"
            )
        given = [name for name, value in (("dt", dt), ("times", times), ("n_steps", n_steps))
                 if value is not None]  # fmt: skip
        if len(given) > 1:
            raise ValueError(f"give one of dt, times and n_steps, got {' and '.join(given)}")
        if dt is not None:
            dt = check_real(dt, "dt", positive=True, maximum=nominal)

        def motion_over(span: float) -> Trajectory:
            if dt is not None:
                n = check_int(
                    int(min(span / dt, 1e15) + 1e-9) + 1, "the samples", limit="max_steps"
                )
                span, t = (n - 1) * dt, np.arange(n) * dt
            else:
                t = self._times(times, n_steps)
                if times is None:
                    t = t * (span / self.duration_)
            stretch = span / self.duration_
            model = (
                self
                if raw
                else self.conditioned(
                    start=start, start_velocity=start_velocity, goal=goal, via=via, duration=span
                )
            )
            velocity = None if start_velocity is None else self._velocity(start_velocity) * stretch
            motion = model._closed_form(t / stretch, start, velocity, weights, attractor)
            # the model's time played `stretch` times slower: rates by 1/stretch per order
            return Trajectory(
                motion.t * stretch,
                motion.y,
                motion.yd / stretch,
                motion.ydd / stretch**2,
                units=self.units_,
            )

        if times is not None and limits is not None:
            raise ValueError("limits re-time the motion: give dt or n_steps with them, not times")
        return _within_limits(motion_over, nominal, limits, has_via=has_via, bounds=(1e-6, 1e6))

    def _closed_form(self, s, start, velocity, weights, attractor) -> Trajectory:
        """The motion at model times ``s`` (s of tau) from ``start`` at ``velocity`` (model
        units/s) with ``weights`` (default the mean) and ``attractor`` (default their goal)."""
        start, velocity = self._single_boundary(start, velocity)
        w = (
            (
                self.weight_mean_
                if weights is None
                else as_vector(weights, "weights", length=self.weight_mean_.size)
            )
            .reshape(self.n_dims_, -1)
            .copy()
        )
        if attractor is not None:
            w[:, -1] = as_points(attractor, self.n_dims_, "attractor")[0]
        basis, tau = self.basis_, self.duration_
        p0, v0, p1, v1, H, dH = basis.boundary_maps(s, 0.0)
        y = p0[:, None] * start + v0[:, None] * (velocity * tau) + H @ w.T
        dy = p1[:, None] * start + v1[:, None] * (velocity * tau) + dH @ w.T  # d/ds
        forcing = (basis.phase(s)[:, None] * basis.forcing(s)) @ w[:, :-1].T
        alpha = basis.alpha
        ddy = -alpha * dy - alpha**2 / 4.0 * (y - w[:, -1]) + forcing  # d²/ds²
        return Trajectory(s, y, dy / tau, ddy / tau**2, units=self.units_)

    def goal_for_end(self, end, start=None, *, start_velocity=None) -> np.ndarray:
        """(D,): the goal (the attractor, the goal weight) with which the mean motion from
        ``start`` ends exactly at ``end`` at tau. The learned goal is not where a demonstration
        ends — it is fitted with the forcing weights, which share its effect — so a new end is
        reached by moving the goal by what it lacks there, over the goal column's value at tau."""
        self.check_fitted()
        end = as_points(end, self.n_dims_, "end")[0]
        start, velocity = self._single_boundary(start, start_velocity)
        w = self.weight_mean_.reshape(self.n_dims_, -1)
        p0, v0, _, _, H, _ = self.basis_.boundary_maps(np.array([self.duration_]), 0.0)
        there = p0[0] * start[0] + v0[0] * velocity[0] * self.duration_ + H[0] @ w.T
        return w[:, -1] + (end - there) / H[0, -1]

    def std(self, times=None, n_steps: int = 100) -> np.ndarray:
        """(T, D): the positions' standard deviation (units) under the weights' Gaussian at
        ``times`` (s; default ``n_steps`` over tau) — the boundary condition is exact, so it does
        not depend on the start."""
        self.check_fitted()
        t = self._times(times, n_steps)
        H = self.basis_.boundary_maps(t, 0.0)[4]
        size = self.basis_.n_basis + 1
        out = np.empty((len(t), self.n_dims_))
        for d in range(self.n_dims_):
            block = self.weight_cov_[d * size : (d + 1) * size, d * size : (d + 1) * size]
            out[:, d] = np.sqrt(np.maximum(np.einsum("tk,kl,tl->t", H, block, H), 0.0))
        return out

    def _goal_index(self) -> np.ndarray:
        """(D,): where each dimension's goal weight sits among the weights (the last of its
        block of N + 1)."""
        size = self.basis_.n_basis + 1
        return np.arange(self.n_dims_) * size + size - 1

    def condition_goal(self, goal) -> ProDMP:
        """A copy whose weights are conditioned exactly on the goal ``goal`` (D,): the goal weights
        become ``goal``, the forcing weights move as the demonstrations say they go with it."""
        import copy

        self.check_fitted()
        goal = as_points(goal, self.n_dims_, "goal")[0]
        columns = np.zeros((self.weight_mean_.size, self.n_dims_))
        columns[self._goal_index(), np.arange(self.n_dims_)] = 1.0
        mean, cov = condition_gaussian(
            self.weight_mean_, self.weight_cov_, columns, goal, np.zeros((self.n_dims_,) * 2)
        )
        conditioned = copy.copy(self)
        conditioned.weight_mean_, conditioned.weight_cov_ = mean, cov
        return conditioned

    def condition(  # noqa: PLR0913 - the observations a motion is conditioned on, by name
        self, times, values, cov=0.0, *, start=None, start_velocity=None, rest=None, goal=None
    ) -> ProDMP:
        """A copy whose weights are conditioned exactly on passing ``values`` (K, D) at ``times``
        (K,) (s) with noise ``cov`` (a scalar variance, units²), for motions from ``start`` at
        ``start_velocity`` (default the mean start, at rest): the via-points enter the weights'
        Gaussian like a ProMP's, the boundary condition stays exact. ``rest`` (R,) (s): times
        at which the motion is at rest (velocity and acceleration 0, exactly); ``goal`` (D,): the goal weight
        (the attractor) exactly. The end at tau among the points, ``rest=[tau]`` and ``goal``
        the same point make a motion that ends there at rest and stays. ``times`` and
        ``values`` may be empty when ``rest`` or ``goal`` is given."""
        import copy

        self.check_fitted()
        dims, size = self.n_dims_, self.basis_.n_basis + 1
        optional = rest is not None or goal is not None  # then the points may be none
        times = as_vector(times, "times", min_length=0 if optional else 1)
        values = np.zeros((0, dims)) if not times.size else as_points(values, dims, "values")
        if len(values) != len(times):
            raise ValueError(
                f"times must hold one time per point of values ({len(values)}), got {len(times)}"
            )
        rest = np.zeros(0) if rest is None else as_vector(rest, "rest")
        cov = check_real(cov, "cov", nonnegative=True, maximum=1e12)
        for name, when in (("times", times), ("rest", rest)):
            if np.any(when <= 0.0):
                raise ValueError(
                    f"{name} must be > 0 s: at 0 the motion is at its start (give start= and "
                    "start_velocity= instead)"
                )
        start, velocity = self._single_boundary(start, start_velocity)
        carried = velocity * self.duration_
        # the observations' columns: dimension d of each observation reads block d of the weights
        blocks, observed = [], []
        if times.size:
            p0, v0, _, _, H, _ = self.basis_.boundary_maps(times, 0.0)
            blocks.append(H)
            observed.append(values - p0[:, None] * start - v0[:, None] * carried)
        if rest.size:
            # at rest: the velocity (d/ds) and the acceleration (d²/ds², the system's equation
            # y'' = -α y' - α²/4 (y - g) + x φ·w) are 0 there
            p0, v0, p1, v1, H, dH = self.basis_.boundary_maps(rest, 0.0)
            alpha = self.basis_.alpha
            forcing = self.basis_.phase(rest)[:, None] * self.basis_.forcing(rest)
            pulled = np.hstack([forcing, np.full((rest.size, 1), alpha**2 / 4.0)])
            blocks += [dH, pulled - alpha * dH - alpha**2 / 4.0 * H]
            position = p0[:, None] * start + v0[:, None] * carried
            rate = p1[:, None] * start + v1[:, None] * carried
            observed += [-rate, alpha * rate + alpha**2 / 4.0 * position]
        if goal is not None:
            blocks.append(np.eye(size)[None, -1])  # the goal weight itself
            observed.append(as_point(goal, dims, "goal")[None])
        rows = np.vstack(blocks)  # (observations, N + 1)
        columns = np.zeros((dims * size, len(rows) * dims))
        for d in range(dims):
            columns[d * size : (d + 1) * size, d::dims] = rows.T
        noise = np.zeros((len(rows) * dims,) * 2)
        noise[np.diag_indices(len(times) * dims)] = cov
        try:
            mean, weight_cov = _conditioned(
                self.weight_mean_, self.weight_cov_, columns, np.vstack(observed).reshape(-1), noise
            )
        except _Conflict as conflict:
            raise ValueError(_conflict_text(conflict.rows, times, rest, dims)) from None
        conditioned = copy.copy(self)
        conditioned.weight_mean_, conditioned.weight_cov_ = mean, weight_cov
        conditioned.start_, conditioned.start_velocity_ = start[0], velocity[0]
        return conditioned

    # -- persistence (used by bidmp.io) -----------------------------------------------------
    def to_state(self) -> tuple[dict, dict]:
        """The model-file form of the fitted model, ``(meta, arrays)``: its parameters and scalars
        as a JSON-able dict, its learned arrays by name (:func:`bidmp.io.save_model` writes the two
        into one ``.npz``; no pickle). Raises :class:`bidmp.NotFittedError` before ``fit``."""
        self.check_fitted()
        state = {
            "params": self.get_params(),
            "duration": float(self.duration_),
            "n_dims": int(self.n_dims_),
            "units": self.units_,
        }
        arrays = {
            "weight_mean_": self.weight_mean_,
            "weight_cov_": self.weight_cov_,
            "weights_": self.weights_,
            "start_": self.start_,
            "start_velocity_": self.start_velocity_,
        }
        return state, arrays

    @classmethod
    @state_reader
    def from_state(cls, meta: dict, arrays) -> ProDMP:
        """A fitted ProDMP from a model file: the basis recomputed from the settings (it is a
        function of them), the learned arrays checked for shape and finiteness."""
        from .._checks import check_loaded

        model = cls(**meta["params"])
        n_dims = check_int(meta["n_dims"], "n_dims", minimum=1, limit="max_dims")
        tau = check_real(meta["duration"], "duration", positive=True, maximum=1e4)
        model.basis_ = prodmp_basis(
            model.n_basis, tau, 0.0, model.alpha, model.alpha_phase, model.bandwidth_factor,
            model.n_outside, model.dt, model.length_factor,
        )  # fmt: skip
        size = n_dims * (model.basis_.n_basis + 1)
        model.weight_mean_ = check_loaded(arrays["weight_mean_"], "weight_mean_", (size,))
        cov = check_loaded(arrays["weight_cov_"], "weight_cov_", (size, size))
        if not np.allclose(cov, cov.T, atol=1e-12 * max(np.abs(cov).max(), 1e-300)):
            raise ValueError("member weight_cov_ is not symmetric")
        model.weight_cov_ = cov
        model.weights_ = check_loaded(arrays["weights_"], "weights_", (None, size))
        model.start_ = check_loaded(arrays["start_"], "start_", (n_dims,))
        model.start_velocity_ = check_loaded(
            arrays["start_velocity_"], "start_velocity_", (n_dims,)
        )
        model.duration_ = tau
        model.n_dims_ = n_dims
        model.units_ = "" if not meta["units"] else check_units(meta["units"])
        return model
