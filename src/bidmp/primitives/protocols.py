"""The DMP's parameters and its two protocols (README "Protocols"): what the unset parameters
resolve to, validated in one place.

* ``robot`` (default): a DMP a robot can run — ``K = αβ``, the progress gate, the exact
  integrator, the demonstration learned from rest, ridge weights, ``alpha_phase = 4``, 100 kernels,
  ``alpha = 50`` and a horizon of 1.1x the demonstration;
* ``paper``: the paper's — ``K = α``, the phase gate, explicit Euler, LWR, ``alpha_phase = 1``,
  50 kernels, ``alpha = 25``, exactly T samples.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .._checks import (
    NotFittedError,
    check_choice,
    check_fitted,
    check_int,
    check_real,
)
from .canonical import _TAU_RANGE, CanonicalSystem, ExponentialPhase
from .forcing import Basis, GaussianBasis
from .gains import _Gains

__all__ = ["PROTOCOLS", "ROBOT_ALPHA", "ROBOT_KERNELS", "ROBOT_ALPHA_PHASE", "ROBOT_SETTLE"]

K_CHOICES = ("paper", "pastor")
REGRESSION_CHOICES = ("lwr", "ridge")
DERIVATIVE_CHOICES = ("gradient", "forward")
WIDTH_CHOICES = ("spacing", "pydmps")
# Gains (alpha, beta, alpha_phase in 1/s; K) and tau (s) outside these ranges have no physical use
# and take float64 out of its range in the forcing target (division by K) or the integration.
_GAIN_RANGE = (1e-6, 1e6)


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
    # the goal's offset complete before the final approach (ApproachGate)
    keep_approach: bool = False
    # the phase and the forcing term's basis (components; the protocol's unless given)
    canonical_system: CanonicalSystem | None = None
    basis: Basis | None = None

    @property
    def exact(self) -> bool:
        return self.integrator == "exact"

    @property
    def gains(self) -> _Gains:
        """``alpha``, ``beta`` and ``K`` (Eq. 10)."""
        return _Gains(self.alpha, self.beta, self.K)

    @property
    def rest_start(self) -> bool:
        """Whether the demonstration is learned with its start and end velocity blended out
        (:func:`bidmp.primitives.rest.rest_started`): the robot protocol with the exact integrator."""
        return self.integrator == "exact" and self.protocol == "robot"


# The two protocols (README "Protocols"): what the unset parameters resolve to.
PROTOCOLS = ("robot", "paper")
INTEGRATOR_CHOICES = ("exact", "euler")
# robot: K = alpha beta (Pastor 2009: the initial acceleration does not depend on the goal or the
# start), a goal share that follows the demonstration's progress with smooth ends
# (bidmp.primitives.goals), the exact integrator (the same motion at any control rate), the demonstration
# learned from rest (its start velocity blended out), a phase that decays to e^-4 over the
# demonstration, 100 kernels fitted by ridge regression, a stiffer spring (alpha = 50), and a
# horizon of 1.1x the demonstrated duration. The weights are learned on the demonstration
# followed by rest at its goal for that extra 0.1: the learned forcing term then holds the goal
# at the end instead of extrapolating the last kernel. The README's "Robot protocol" section
# has the measurements (tests/primitives/test_timing.py holds them).
ROBOT_ALPHA = 50.0
ROBOT_KERNELS = 100
ROBOT_ALPHA_PHASE = 4.0
ROBOT_SETTLE = 1.1


def _resolve_params(estimator) -> _Params:
    """The validated parameters of a :class:`bidmp.DMP` (or anything with its constructor's
    parameters) as they are now, the protocol's defaults filled in; raise naming the first bad one."""
    protocol = check_choice(estimator.protocol, "protocol", PROTOCOLS)
    robot = protocol == "robot"
    alpha = (
        (ROBOT_ALPHA if robot else 25.0)
        if estimator.alpha is None
        else check_real(
            estimator.alpha, "alpha", positive=True, minimum=_GAIN_RANGE[0], maximum=_GAIN_RANGE[1]
        )
    )
    beta = (
        alpha / 4.0
        if estimator.beta is None
        else check_real(
            estimator.beta, "beta", positive=True, minimum=_GAIN_RANGE[0], maximum=_GAIN_RANGE[1]
        )
    )
    K_choice = ("pastor" if robot else "paper") if estimator.K is None else estimator.K
    if isinstance(K_choice, str):
        check_choice(K_choice, "K", K_CHOICES)
        K = alpha if K_choice == "paper" else alpha * beta
    else:
        K = check_real(
            K_choice, "K", positive=True, minimum=_GAIN_RANGE[0], maximum=_GAIN_RANGE[1] ** 2
        )
    if estimator.alpha_phase is None:
        alpha_phase = ROBOT_ALPHA_PHASE if robot else 1.0
    else:
        alpha_phase = check_real(
            estimator.alpha_phase,
            "alpha_phase",
            positive=True,
            minimum=_GAIN_RANGE[0],
            maximum=_GAIN_RANGE[1],
        )
    if estimator.goal_rate is None:
        goal_rate = None if robot else alpha_phase
    else:
        goal_rate = check_real(
            estimator.goal_rate,
            "goal_rate",
            positive=True,
            minimum=_GAIN_RANGE[0],
            maximum=_GAIN_RANGE[1],
        )
    integrator = (
        ("exact" if robot else "euler")
        if estimator.integrator is None
        else check_choice(estimator.integrator, "integrator", INTEGRATOR_CHOICES)
    )
    regression = (
        ("ridge" if robot else "lwr")
        if estimator.regression is None
        else check_choice(estimator.regression, "regression", REGRESSION_CHOICES)
    )
    canonical_system, basis = _components(estimator, alpha_phase, integrator, regression)
    return _Params(
        n_kernels=basis.size,
        alpha=alpha,
        beta=beta,
        K=K,
        alpha_phase=alpha_phase,
        tau=check_real(
            estimator.tau, "tau", positive=True, minimum=_TAU_RANGE[0], maximum=_TAU_RANGE[1]
        ),
        regression=regression,
        derivatives=check_choice(estimator.derivatives, "derivatives", DERIVATIVE_CHOICES),
        ridge=check_real(estimator.ridge, "ridge", nonnegative=True, maximum=1e6),
        widths=basis.widths if isinstance(basis, GaussianBasis) else "",
        protocol=protocol,
        goal_rate=goal_rate,
        integrator=integrator,
        settle=ROBOT_SETTLE if robot else 1.0,
        keep_approach=_keep_approach(estimator, goal_rate, integrator),
        canonical_system=canonical_system,
        basis=basis,
    )


def _components(
    estimator, alpha_phase: float, integrator: str, regression: str
) -> tuple[CanonicalSystem, Basis]:
    """The DMP's canonical system and basis: the ones given, or the protocol's exponential phase
    and Gaussian kernels built from ``alpha_phase``, ``n_kernels`` and ``widths``. A component
    given beside the parameter that would build it is refused (which one counts would be a guess)."""
    canonical = getattr(estimator, "canonical_system", None)
    if canonical is None:
        canonical = ExponentialPhase(alpha_phase, exact=integrator == "exact")
    else:
        if estimator.alpha_phase is not None:
            raise ValueError(
                "give either canonical_system or alpha_phase: alpha_phase sets the default "
                "canonical system's decay"
            )
        _check_component(canonical, CanonicalSystem, "canonical_system")
    basis = getattr(estimator, "forcing_basis", None)
    if basis is None:
        n_kernels = (
            (ROBOT_KERNELS if estimator.protocol == "robot" else 50)
            if estimator.n_kernels is None
            else check_int(estimator.n_kernels, "n_kernels", minimum=1, limit="max_kernels")
        )
        basis = GaussianBasis(n_kernels, check_choice(estimator.widths, "widths", WIDTH_CHOICES))
    else:
        widths = check_choice(estimator.widths, "widths", WIDTH_CHOICES)
        if estimator.n_kernels is not None or widths != "spacing":
            raise ValueError(
                "give either forcing_basis or n_kernels and widths: they set the default Gaussian basis"
            )
        _check_component(basis, Basis, "forcing_basis")
        check_int(basis.size, "forcing_basis.size", minimum=1, limit="max_kernels")
    if regression == "lwr" and not isinstance(basis, GaussianBasis):
        raise ValueError(
            "regression='lwr' weighs each kernel's samples by the decaying phase, which only "
            f"GaussianBasis is scaled by; with {type(basis).__name__} use regression='ridge'"
        )
    return canonical, basis


def _check_component(component, protocol, name: str) -> None:
    """Refuse an object that lacks one of the protocol's methods or attributes, naming it."""
    members = sorted(
        {member for member in vars(protocol) if not member.startswith("_")}
        | set(protocol.__annotations__)
    )
    missing = [member for member in members if not hasattr(component, member)]
    if missing:
        raise TypeError(
            f"{name} must provide {protocol.__name__}'s {', '.join(members)}; "
            f"{type(component).__name__} lacks {', '.join(missing)}"
        )


def _with_rest(y: np.ndarray, params: _Params) -> np.ndarray:
    """``y`` followed by rest at its last point for the protocol's settle time (robot: 0.1 T)."""
    n_rest = int(round(params.settle * y.shape[0])) - y.shape[0]
    if n_rest <= 0:
        return y
    return np.vstack([y, np.repeat(y[-1:], n_rest, axis=0)])


class _FittedParams:
    """Mixin of an estimator whose learned state depends on its parameters (all but ``tau``):
    a parameter changed after ``fit`` makes it unfitted (:class:`bidmp.NotFittedError` names it)."""

    _fitted_attribute = "weights_"

    @classmethod
    def _raw_param_names(cls) -> tuple[str, ...]:
        """The constructor's parameters but tau, as given (compared first: cheap); read from the
        signature once per class (every rollout checks them)."""
        names = cls.__dict__.get("_raw_names")
        if names is None:
            names = tuple(name for name in cls._get_param_names() if name != "tau")
            cls._raw_names = names
        return names

    def _learned_params(self) -> _Params:
        """The resolved parameters the weights depend on (all but tau, which only scales time)."""
        return self._params()._replace(tau=1.0)

    def _raw_params(self) -> tuple:
        return tuple(getattr(self, name) for name in self._raw_param_names())

    def _remember_params(self, resolved: _Params | None = None) -> None:
        """Keep the parameters the weights were learned with: the raw ones and their resolution
        (``resolved``: :meth:`_params` as ``fit`` resolved them a moment ago)."""
        learned = self._learned_params() if resolved is None else resolved._replace(tau=1.0)
        self._learned_with = (self._raw_params(), learned)

    def _stale_params(self) -> list[str]:
        """The learned-with parameters that have changed since ``fit`` (with their values)."""
        learned = self.__dict__.get("_learned_with")
        if learned is None:
            return []
        raw, resolved = learned
        try:
            # the common case, without resolving the protocol's defaults
            if self._raw_params() == raw:
                return []
        except (TypeError, ValueError):  # an array set by mistake: resolving names it
            pass
        now = self._learned_params()
        return [
            f"{name} (fitted with {before!r}, now {after!r})"
            for name, before, after in zip(now._fields, resolved, now)
            if before != after
        ]

    def __sklearn_is_fitted__(self) -> bool:
        return self._fitted_attribute in self.__dict__ and not self._stale_params()

    def _check_fitted(self) -> None:
        check_fitted(self, self._fitted_attribute)
        stale = self._stale_params()
        if stale:
            raise NotFittedError(
                f"this DMP's {', '.join(stale)} changed after fit: the weights were learned with the old value, "
                f"so the model must be fitted again (only tau may change after fit)"
            )


def _resolved_param(name: str, doc: str) -> property:
    """A read-only property: the resolved value of parameter ``name`` (the protocol's default when
    it is None)."""
    return property(lambda self: getattr(self._params(), name), doc=doc)


def _keep_approach(estimator, goal_rate, integrator: str) -> bool:
    """``keep_approach``, validated: a choice of the progress gate on the exact integrator. None
    (the default) is True where that is the goal system (the robot protocol), else False."""
    keep = getattr(estimator, "keep_approach", None)
    if keep is None:
        return goal_rate is None and integrator == "exact"
    if not isinstance(keep, (bool, np.bool_)):
        raise TypeError(f"keep_approach must be True, False or None, got {type(keep).__name__}")
    if keep and (goal_rate is not None or integrator != "exact"):
        raise ValueError(
            "keep_approach shapes the robot protocol's progress gate: it needs goal_rate=None and the "
            "exact integrator"
        )
    return bool(keep)
