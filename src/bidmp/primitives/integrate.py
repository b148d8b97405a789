"""Integrators of the DMP transformation system, a linear time-invariant spring-damper driven by
an input ``u``. In normalised time ``s`` with ``z = tau dy/ds``::

    tau dz/ds = u - alpha beta y - alpha z,      tau dy/ds = z

* **Explicit Euler** (the paper's Eq. 14): ``z[l+1] = z[l] + h/tau (u[l] - αβ y[l] - α z[l])``,
  ``y[l+1] = y[l] + h/tau z[l]``. Its result depends on the step ``h``: the same weights give
  another motion at another rate, and it diverges for ``h α / tau`` beyond a bound.
* **Exact** (first-order hold): the input is taken as linear between samples and the system is
  integrated exactly over each step, ``x[l+1] = Φ x[l] + Γ₀ u[l] + Γ₁ u[l+1]`` with ``Φ = e^{A h}``.
  It is stable for every step and samples the same continuous motion at any rate, up to the
  linear interpolation of the input (a 100 Hz demonstration rolled out at 1 kHz and 10 kHz
  agrees with its own-rate rollout to about 1e-6 of its extent).

Both run as a second-order recursion in ``y`` for many input signals at once, a compiled loop
(``bidmp._kernels.second_order``: SciPy's ``lfilter`` operation for operation, checked
against it to the bit): this is what makes rollouts to many goals cost one integration (the *fast
path*: :func:`_unit_responses`, :func:`_affine_rollouts`).

State feedback (a coupling term that depends on where the system is) cannot go through a filter:
:class:`StepIntegrator` takes the same exact (or Euler) steps one at a time and adds coupling
accelerations. With no coupling term it equals the fast path to rounding (``tests/primitives/test_dmp.py``).
"""

from __future__ import annotations

import cmath
from functools import lru_cache

import numpy as np

from .._checks import as_vector, check_bool, check_real, checks_input
from .._kernels import exact_state, foh_responses, second_order
from .canonical import _phase_decay

GEMM_GOALS = 64  # rollouts to this many goals and more: one matrix product

__all__ = ["StepIntegrator"]


# -- explicit Euler --------------------------------------------------------------------------------
def _euler_spectral_radius(step: float, alpha: float, beta: float) -> float:
    """Spectral radius of one explicit-Euler step of the spring-damper (step ``h = dt/tau``).

    The homogeneous update ``[y, z] ← [[1, h], [−h α β, 1 − h α]] [y, z]`` has characteristic
    polynomial ``r² − (2 − hα) r + (1 − hα + h²αβ)``; the integration is stable iff both roots lie
    inside the unit circle (for ``β = α/4``: iff ``h α < 4``).
    """
    trace = 2.0 - step * alpha
    determinant = 1.0 - step * alpha + step * step * alpha * beta
    root = cmath.sqrt(trace * trace / 4.0 - determinant)  # closed form: this runs on every rollout
    return max(abs(trace / 2.0 + root), abs(trace / 2.0 - root))


def _max_stable_step(alpha: float, beta: float, step: float) -> float:
    """The largest ``h`` below ``step`` for which :func:`_euler_spectral_radius` stays < 1 (bisection)."""
    low, high = 0.0, step
    for _ in range(60):
        middle = 0.5 * (low + high)
        low, high = (
            (middle, high) if _euler_spectral_radius(middle, alpha, beta) < 1.0 else (low, middle)
        )
    return low


def _check_euler_stable(dt: float, tau: float, alpha: float, beta: float) -> None:
    """Refuse an explicit-Euler step ``dt/tau`` for which the transformation system diverges.

    Raises
    ------
    ValueError
        Naming the bound on ``dt/tau`` (s) for these gains.
    """
    step = dt / tau
    radius = _euler_spectral_radius(step, alpha, beta)
    if not radius < 1.0:
        bound = _max_stable_step(alpha, beta, step)
        raise ValueError(
            f"explicit Euler integration is unstable for alpha = {alpha:g}, beta = {beta:g} with the step dt/tau = "
            f"{step:.4g} s (spectral radius {radius:.4g} >= 1): it needs dt/tau < {bound:.4g} s "
            f"(alpha * dt/tau = {alpha * step:.4g}, below {alpha * bound:.4g}); lower alpha, "
            f"raise tau or use more samples"
        )


def _euler_responses(
    drives: np.ndarray,
    y_first: np.ndarray,
    y_second: np.ndarray,
    *,
    h: float,
    alpha: float,
    beta: float,
) -> np.ndarray:
    """Integrate the Euler-discretised spring-damper for several input signals at once.

    With ``z = (y[n+1] - y[n]) / h`` the two Euler updates become
    ``y[n+2] = (2 - h alpha) y[n+1] - (1 - h alpha + h² alpha beta) y[n] + h² u[n]``.

    Parameters
    ----------
    drives : array, shape (S, n - 2)
        Input ``u[n]`` of each signal for ``n = 0 … n-3``.
    y_first, y_second : array, shape (S,)
        ``y[0]`` and ``y[1]`` of each signal.
    h : float
        ``step / tau``.

    Returns
    -------
    y : array, shape (S, n)
    """
    a1 = -(2.0 - h * alpha)
    a2 = 1.0 - h * alpha + h * h * alpha * beta
    return second_order(drives, y_first, y_second, h * h, 0.0, 0.0, a1, a2)


# -- exact (first-order hold) ---------------------------------------------------------------------
@lru_cache(maxsize=64)
def _foh_step(
    step: float, alpha: float, beta: float, tau: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The exact step of the spring-damper with the input linear over the step.

    Returns ``(Φ (2, 2), Γ₀ (2,), Γ₁ (2,))`` with ``x[l+1] = Φ x[l] + Γ₀ u[l] + Γ₁ u[l+1]`` for the
    state ``x = [y, z]`` and a normalised step ``step``. One matrix exponential of the augmented
    4 x 4 system (Van Loan): ``exp([[A h, B h, 0], [0, 0, 1], [0, 0, 0]])`` holds
    ``∫ e^{Aσ} B dσ`` and ``∫ e^{Aσ} B (h - σ)/h dσ``. The arrays are shared (cached): do not write
    to them.
    """
    augmented = np.zeros((4, 4))
    augmented[0, 1] = step / tau
    augmented[1, 0] = -alpha * beta * step / tau
    augmented[1, 1] = -alpha * step / tau
    augmented[1, 2] = step / tau
    augmented[2, 3] = 1.0
    from scipy.linalg import expm  # at first use: SciPy's linear algebra is 0.1 s of imports

    exponential = expm(augmented)
    transition = exponential[:2, :2]
    hold, ramp = exponential[:2, 2], exponential[:2, 3]
    for array in (transition, hold, ramp):
        array.setflags(write=False)
    # The input at the step's end weighs the ramp's share; at its start what remains of the hold.
    now, after = hold - ramp, ramp
    now.setflags(write=False)
    return transition, now, after


def _exact_responses(
    inputs: np.ndarray,
    y_first: np.ndarray | None,
    z_first: np.ndarray | None,
    *,
    step: float,
    alpha: float,
    beta: float,
    tau: float,
) -> np.ndarray:
    """Exact (first-order hold) integration for several input signals at once.

    Parameters
    ----------
    inputs : array, shape (S, n)
        Input ``u`` of each signal at every sample.
    y_first, z_first : array, shape (S,), or None
        Initial position and ``z = tau dy/ds`` of each signal (None: 0).

    Returns
    -------
    y : array, shape (S, n)
    """
    transition, now, after = _foh_step(step, alpha, beta, tau)
    n = inputs.shape[1]
    if n >= 3:
        # The second sample from the transition, then the transfer function of the held
        # system, C (zI - Φ)⁻¹ (Γ₀ + Γ₁ z), for C = [1, 0], acting on u[n+2], u[n+1], u[n]:
        # one compiled call.
        return foh_responses(inputs, y_first, z_first, transition, now, after)
    n_signals = inputs.shape[0]
    y_first = np.zeros(n_signals) if y_first is None else y_first
    z_first = np.zeros(n_signals) if z_first is None else z_first
    y_second = transition[0, 0] * y_first + transition[0, 1] * z_first
    if n > 1:
        y_second = y_second + now[0] * inputs[:, 0] + after[0] * inputs[:, 1]
    return np.column_stack([y_first, y_second])[:, :n]


def _exact_state(
    y: np.ndarray, inputs: np.ndarray, *, step: float, alpha: float, beta: float, tau: float
) -> tuple[np.ndarray, np.ndarray]:
    """``z`` and ``d²y/ds²`` at the samples of an exact rollout, from consecutive positions.

    Parameters
    ----------
    y, inputs : array, shape (n + 1, D)
        Positions and inputs, one sample past the last one wanted.

    Returns
    -------
    (z, acceleration) : arrays (n, D)
        ``z = tau dy/ds`` and ``d²y/ds²`` (normalised time) at samples ``0 … n-1``. The first
        row of ``Φ`` gives ``y[l+1] = Φ₁₁ y[l] + Φ₁₂ z[l] + Γ₀₁ u[l] + Γ₁₁ u[l+1]``, solved for
        ``z[l]``; the acceleration is the system's own, ``(u - αβ y - α z) / tau²``.
    """
    transition, now, after = _foh_step(step, alpha, beta, tau)
    return exact_state(
        y,
        inputs,
        transition[0, 0],
        transition[0, 1],
        now[0],
        after[0],
        alpha * beta,
        alpha,
        tau**2,
    )


# -- the fast path: unit responses and affine rollouts ---------------------------------------------
def _check_integration(step: float, params) -> None:
    """Refuse a normalised step for which the Euler spring diverges or the Euler phase (or an
    exponentially delayed goal) does not decay; ``params`` a DMP's resolved parameters. The exact
    integrator is stable at any step."""
    if params.integrator != "euler":
        return
    _check_euler_stable(step, params.tau, params.alpha, params.beta)
    params.canonical_system.check_step(step, params.tau)
    if params.goal_rate is not None:
        _phase_decay(step, params.tau, params.goal_rate)


def _unit_responses(
    params,
    phase: np.ndarray,
    forcing: np.ndarray | None,
    step: float,
    gate: np.ndarray | None = None,
) -> np.ndarray:
    """Responses that compose every rollout on the grid ``phase`` (n samples ``step`` apart).

    ``y = a + B g + C y0 + V v0``: ``a`` is driven by ``K f`` from rest at 0 (one row per
    dimension, returned when ``forcing`` (n, D) is given); otherwise the rows are ``B`` (the
    goal's share of the input, through the goal gate ``gate`` (n,)), ``C`` (the start's, with
    ``y[0] = y[1] = 1``) and ``V`` (the free response to a unit start velocity, ``y[1] = step``),
    shape (3, n). ``params`` are a DMP's resolved parameters.
    """
    alpha, beta, K = params.alpha, params.beta, params.K
    exact = params.integrator == "exact"
    n_steps = phase.shape[0]
    # Euler's y[n] depends on u[n-2] at the latest; the exact step uses u[n] too.
    n_inputs = n_steps if exact else max(n_steps - 2, 0)
    if forcing is not None:
        drives = K * forcing[:n_inputs].T  # driven by K f from rest at 0
        y_first = second = None if exact else np.zeros(drives.shape[0])
    else:
        # The goal enters through alpha beta g - K gate (g - y0).
        drives = np.empty((3, n_inputs))  # rows αβ - K gate, K gate, 0, written in place
        np.multiply(gate[:n_inputs], K, out=drives[1])
        np.subtract(alpha * beta, drives[1], out=drives[0])
        drives[2] = 0.0
        y_first = np.array([0.0, 1.0, 0.0])
        # The second state: Euler's y[1] (a unit start velocity moves it by one step), or
        # the exact integrator's z = tau dy/ds.
        second = np.array([0.0, 0.0, params.tau]) if exact else np.array([0.0, 1.0, step])
    if exact:
        return _exact_responses(
            drives, y_first, second, step=step, alpha=alpha, beta=beta, tau=params.tau
        )
    responses = _euler_responses(
        drives, y_first, second, h=step / params.tau, alpha=alpha, beta=beta
    )
    return responses[:, :n_steps]


def _affine_rollouts(
    goal_response: np.ndarray, goals: np.ndarray, free: np.ndarray, out: np.ndarray | None = None
) -> np.ndarray:
    """``y[i] = free + B goals[i]`` for every goal at once, (G, n, D), written into ``out`` if given.

    From :data:`GEMM_GOALS` goals on, one matrix product ``[goals | 1] @ [B e_d ... | free]``
    writes the output once (a multiply then an add pass over it twice, and the output is what
    costs: 10 000 goals are 260 MB). Each entry is ``g B + free`` with exact zeros elsewhere, so
    both ways give the same numbers.
    """
    n_goals, (n_steps, n_dims) = goals.shape[0], free.shape
    if n_goals < GEMM_GOALS or (out is not None and not out.flags.c_contiguous):
        out = np.multiply(goal_response[None, :, None], goals[:, None, :], out=out)
        out += free[None]
        return out
    weights = np.zeros((n_dims + 1, n_steps, n_dims))
    for dim in range(n_dims):
        weights[dim, :, dim] = goal_response
    weights[n_dims] = free
    augmented = np.empty((n_goals, n_dims + 1))
    augmented[:, :n_dims] = goals
    augmented[:, n_dims] = 1.0
    flat = None if out is None else out.reshape(n_goals, n_steps * n_dims)
    flat = np.matmul(augmented, weights.reshape(n_dims + 1, n_steps * n_dims), out=flat)
    return flat.reshape(n_goals, n_steps, n_dims) if out is None else out


# -- one step at a time --------------------------------------------------------------------------
class StepIntegrator:
    """The transformation system ``tau dz/ds = u - αβ y - α z``, ``tau dy/ds = z``, one step at a time.

    The same steps as the fast path: exact with the input linear over the step
    (:func:`_foh_step`), or explicit Euler. What the fast path cannot take is an input that depends
    on the state: here the caller adds it to ``u`` before each step (coupling terms, see
    :mod:`bidmp.primitives.coupling`).

    Parameters
    ----------
    alpha, beta, tau : float
        Gains and temporal scaling of the system.
    exact : bool
        First-order-hold exact steps (any step is stable) or explicit Euler (refused beyond its
        stability bound).
    """

    def __init__(self, alpha: float, beta: float, tau: float, exact: bool) -> None:
        self.alpha = check_real(alpha, "alpha", positive=True)
        self.beta = check_real(beta, "beta", positive=True)
        self.tau = check_real(tau, "tau", positive=True)
        self.exact = check_bool(exact, "exact")
        self._checked_step = None
        self._floats = None  # (step, the exact step's coefficients as floats) of the last step

    def step(
        self,
        y: np.ndarray,
        z: np.ndarray,
        u_now: np.ndarray,
        u_next: np.ndarray,
        step: float,
        *,
        check_input: bool = True,
    ) -> tuple[np.ndarray, np.ndarray]:
        """The state ``step`` (normalised time) later; ``u_next`` (the input at the step's end) is
        read by the exact step only. ``y``, ``z``, ``u_now`` and ``u_next`` are (D,) arrays.
        ``check_input=False`` takes them as given: float arrays of one shape and a step in
        (0, 1e3] (a stepper's control loop, which checked them once, calls it every step)."""
        if checks_input(check_input):
            y, z, u_now, u_next = (
                as_vector(value, name)
                for value, name in ((y, "y"), (z, "z"), (u_now, "u_now"), (u_next, "u_next"))
            )
            if not y.shape == z.shape == u_now.shape == u_next.shape:
                raise ValueError(
                    f"y, z, u_now and u_next must have one value per dimension each, got "
                    f"{y.shape[0]}, {z.shape[0]}, {u_now.shape[0]} and {u_next.shape[0]}"
                )
            step = check_real(step, "step", positive=True, maximum=1e3)
        alpha, beta, tau = self.alpha, self.beta, self.tau
        if self.exact:
            # Row by row with Python floats: a control loop's step is a few (D,) arrays, where
            # NumPy's per-call cost is the time.
            if self._floats is None or self._floats[0] != step:
                transition, now, after = _foh_step(step, alpha, beta, tau)
                self._floats = (step, *transition.ravel().tolist(), *now.tolist(), *after.tolist())
            _, t00, t01, t10, t11, n0, n1, a0, a1 = self._floats
            return (
                t00 * y + t01 * z + n0 * u_now + a0 * u_next,
                t10 * y + t11 * z + n1 * u_now + a1 * u_next,
            )
        h = step / tau
        if h != self._checked_step:
            _check_euler_stable(step, tau, alpha, beta)
            self._checked_step = h
        z_next = z + h * (u_now - alpha * beta * y - alpha * z)
        return y + h * z, z_next
