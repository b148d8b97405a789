"""A DMP's settings: its hyperparameters resolved for its protocol, checked, immutable.

:class:`DMPSettings` is what every part of a DMP reads (the integrator, the grid, the goal system,
the timed rollout, the stepper): the numbers the constructor's ``None`` resolve to, the chosen
integrator and regression, and the components (canonical system and basis). It is a value, made
once per change of the hyperparameters (:meth:`bidmp.DMP.settings`), compared and hashed by its
fields, so a cache keyed on it can never serve a rollout of other settings.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from .._checks import check_choice, check_int, check_real
from .canonical import _TAU_RANGE, CanonicalSystem, ExponentialPhase
from .forcing import Basis, GaussianBasis
from .gains import _Gains

__all__ = [
    "DMPSettings",
    "PROTOCOLS",
    "ROBOT_ALPHA",
    "ROBOT_KERNELS",
    "ROBOT_ALPHA_PHASE",
    "ROBOT_SETTLE",
]

PROTOCOLS = ("robot", "paper")
INTEGRATOR_CHOICES = ("exact", "euler")
REGRESSION_CHOICES = ("lwr", "ridge")
DERIVATIVE_CHOICES = ("gradient", "forward")
WIDTH_CHOICES = ("spacing", "pydmps")
# Gains (alpha, beta, alpha_phase in 1/s; K) and tau (s) outside these ranges have no physical use
# and take float64 out of its range in the forcing target (division by K) or the integration.
_GAIN_RANGE = (1e-6, 1e6)
# The horizon as a multiple of the demonstration: the paper's 1, the robot's 1.1; past 10 a
# rollout is mostly rest.
_SETTLE_RANGE = (1.0, 10.0)


def _gain(value, name: str) -> float:
    return check_real(value, name, positive=True, minimum=_GAIN_RANGE[0], maximum=_GAIN_RANGE[1])


def _component(component, protocol, name: str):
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
    return component


# One check per field: made settings check them all, replaced ones only what changed.
_FIELD_CHECKS = {
    "n_kernels": lambda v: check_int(v, "n_kernels", minimum=1, limit="max_kernels"),
    "alpha": lambda v: _gain(v, "alpha"),
    "beta": lambda v: _gain(v, "beta"),
    "K": lambda v: check_real(
        v, "K", positive=True, minimum=_GAIN_RANGE[0], maximum=_GAIN_RANGE[1] ** 2
    ),
    "alpha_phase": lambda v: _gain(v, "alpha_phase"),
    "tau": lambda v: check_real(
        v, "tau", positive=True, minimum=_TAU_RANGE[0], maximum=_TAU_RANGE[1]
    ),
    "regression": lambda v: check_choice(v, "regression", REGRESSION_CHOICES),
    "derivatives": lambda v: check_choice(v, "derivatives", DERIVATIVE_CHOICES),
    "ridge": lambda v: check_real(v, "ridge", nonnegative=True, maximum=1e6),
    "widths": lambda v: (
        v if isinstance(v, str) and v == "" else check_choice(v, "widths", WIDTH_CHOICES)
    ),
    "protocol": lambda v: check_choice(v, "protocol", PROTOCOLS),
    "goal_rate": lambda v: None if v is None else _gain(v, "goal_rate"),
    "integrator": lambda v: check_choice(v, "integrator", INTEGRATOR_CHOICES),
    "settle": lambda v: check_real(v, "settle", minimum=_SETTLE_RANGE[0], maximum=_SETTLE_RANGE[1]),
    "keep_approach": lambda v: _flag(v, "keep_approach"),
    "canonical_system": lambda v: _component(v, CanonicalSystem, "canonical_system"),
    "basis": lambda v: _component(v, Basis, "basis"),
}


# What the resolution reads of an estimator (the DMP's constructor's parameters).
_ESTIMATOR_PARAMETERS = (
    "n_kernels",
    "alpha",
    "beta",
    "K",
    "alpha_phase",
    "tau",
    "regression",
    "derivatives",
    "ridge",
    "widths",
    "protocol",
    "goal_rate",
    "integrator",
)


def _flag(value, name: str) -> bool:
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {type(value).__name__}")
    return bool(value)


@dataclass(frozen=True, slots=True, kw_only=True)
class DMPSettings:
    """The resolved, checked settings of a discrete DMP (what :meth:`bidmp.DMP.settings` returns).

    Every field is a number, a choice or a component, never ``None`` for "the protocol's": the two
    protocols' defaults are filled in (``goal_rate``'s None is a choice: the progress gate). Made
    directly, each field is checked as the estimator checks its parameter; :meth:`replace` returns
    a copy with some changed, checked again.

    Parameters
    ----------
    n_kernels : int
        Number of basis functions N (equal to ``basis.size``).
    alpha, beta : float
        The spring's gains (1/s in normalised time); ``beta`` is ``alpha / 4`` for critical damping.
    K : float
        The forcing term's gain (``alpha`` for the paper, ``alpha · beta`` for the robot protocol).
    alpha_phase : float
        The phase's decay (1/s in normalised time).
    tau : float
        Temporal scaling (1: as demonstrated).
    regression : {"lwr", "ridge"}
        How the weights were (or are) learned.
    derivatives : {"gradient", "forward"}
        How the forcing target differentiates the demonstration.
    ridge : float
        Ridge regularisation (≥ 0).
    widths : {"spacing", "pydmps", ""}
        The Gaussian kernels' width rule ("" for another basis).
    protocol : {"robot", "paper"}
        The protocol the unset parameters were resolved for.
    goal_rate : float or None
        The delayed goal's rate (1/s); None: the goal follows the demonstration's progress.
    integrator : {"exact", "euler"}
        Exact (first-order hold, any rate) or the paper's explicit Euler (Eq. 14).
    settle : float
        The default horizon as a multiple of the demonstrated duration (robot 1.1, paper 1).
    keep_approach : bool
        Whether the goal's offset is complete before the final approach (progress gate, exact
        integrator only).
    canonical_system : CanonicalSystem
        The phase.
    basis : Basis
        The forcing term's basis.
    """

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
    goal_rate: float | None
    integrator: str
    settle: float
    keep_approach: bool = False
    canonical_system: CanonicalSystem
    basis: Basis

    def __post_init__(self) -> None:
        for name, check in _FIELD_CHECKS.items():
            object.__setattr__(self, name, check(getattr(self, name)))
        self._check_together()

    def _check_together(self) -> None:
        """The checks that read two fields at once."""
        if self.basis.size != self.n_kernels:
            raise ValueError(
                f"n_kernels ({self.n_kernels}) must equal the basis's size ({self.basis.size})"
            )
        expected = self.basis.widths if isinstance(self.basis, GaussianBasis) else ""
        if self.widths != expected:
            raise ValueError(
                f"widths ({self.widths!r}) must be the basis's width rule ({expected!r}; '' for a "
                f"basis other than GaussianBasis)"
            )
        if self.regression == "lwr" and not isinstance(self.basis, GaussianBasis):
            raise ValueError(
                "regression='lwr' weighs each kernel's samples by the decaying phase, which only "
                f"GaussianBasis is scaled by; with {type(self.basis).__name__} use regression='ridge'"
            )
        if self.keep_approach and (self.goal_rate is not None or self.integrator != "exact"):
            raise ValueError(
                "keep_approach shapes the robot protocol's progress gate: it needs goal_rate=None "
                "and the exact integrator"
            )

    @classmethod
    def of(cls, estimator) -> DMPSettings:
        """The settings of a :class:`bidmp.DMP` (or anything with its constructor's parameters)
        as its parameters are now, the protocol's defaults filled in; raises naming the first bad
        parameter."""
        missing = [name for name in _ESTIMATOR_PARAMETERS if not hasattr(estimator, name)]
        if missing:
            raise TypeError(
                f"estimator must be a bidmp.DMP (or have its constructor's parameters); "
                f"{type(estimator).__name__} lacks {', '.join(missing)}"
            )
        return _resolved(estimator)

    @classmethod
    def _trusted(cls, **fields) -> DMPSettings:
        """Settings from fields the caller has checked one by one (the estimator's resolution):
        only the checks across fields run."""
        settings = object.__new__(cls)
        for name, value in fields.items():
            object.__setattr__(settings, name, value)
        settings._check_together()
        return settings

    def replace(self, **changes) -> DMPSettings:
        """A copy with ``changes`` (field names as keywords), each checked, and the checks across
        fields run again."""
        unknown = set(changes) - set(_FIELD_CHECKS)
        if unknown:
            raise TypeError(
                f"replace: unknown setting(s) {', '.join(sorted(map(str, unknown)))}; known: "
                f"{', '.join(_FIELD_CHECKS)}"
            )
        return self._copy(**{name: _FIELD_CHECKS[name](value) for name, value in changes.items()})

    def with_tau(self, tau: float) -> DMPSettings:
        """A copy at temporal scaling ``tau`` (checked; the hot path of every timed rollout)."""
        tau = _FIELD_CHECKS["tau"](tau)
        return self if tau == self.tau else self._copy(tau=tau)

    def _copy(self, **checked) -> DMPSettings:
        """A copy with ``checked`` fields changed (each checked by the caller)."""
        fields = {name: getattr(self, name) for name in _FIELD_CHECKS}
        return DMPSettings._trusted(**{**fields, **checked})

    def as_dict(self) -> dict:
        """The fields by name (the components as the objects they are)."""
        return {field.name: getattr(self, field.name) for field in dataclasses.fields(self)}

    @property
    def exact(self) -> bool:
        """Whether the integrator is exact (first-order hold)."""
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


K_CHOICES = ("paper", "pastor")


# The two protocols (README "Protocols"): what the unset parameters resolve to.
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


def _resolved(estimator) -> DMPSettings:
    """The validated parameters of a :class:`bidmp.DMP` (or anything with its constructor's
    parameters) as they are now, the protocol's defaults filled in; raise naming the first bad one."""
    protocol = check_choice(estimator.protocol, "protocol", PROTOCOLS)
    robot = protocol == "robot"
    check = _FIELD_CHECKS  # a parameter given is checked as the field it becomes
    alpha = (
        (ROBOT_ALPHA if robot else 25.0)
        if estimator.alpha is None
        else check["alpha"](estimator.alpha)
    )
    beta = alpha / 4.0 if estimator.beta is None else check["beta"](estimator.beta)
    K_choice = ("pastor" if robot else "paper") if estimator.K is None else estimator.K
    if isinstance(K_choice, str):
        check_choice(K_choice, "K", K_CHOICES)
        K = alpha if K_choice == "paper" else alpha * beta
    else:
        K = check["K"](K_choice)
    alpha_phase = (
        (ROBOT_ALPHA_PHASE if robot else 1.0)
        if estimator.alpha_phase is None
        else check["alpha_phase"](estimator.alpha_phase)
    )
    if estimator.goal_rate is None:
        goal_rate = None if robot else alpha_phase
    else:
        goal_rate = check["goal_rate"](estimator.goal_rate)
    integrator = (
        ("exact" if robot else "euler")
        if estimator.integrator is None
        else check["integrator"](estimator.integrator)
    )
    regression = (
        ("ridge" if robot else "lwr")
        if estimator.regression is None
        else check["regression"](estimator.regression)
    )
    canonical_system, basis = _components(estimator, alpha_phase, integrator, regression)
    return DMPSettings._trusted(
        n_kernels=basis.size,
        alpha=alpha,
        beta=beta,
        K=K,
        alpha_phase=alpha_phase,
        tau=check["tau"](estimator.tau),
        regression=regression,
        derivatives=check["derivatives"](estimator.derivatives),
        ridge=check["ridge"](estimator.ridge),
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
        _component(canonical, CanonicalSystem, "canonical_system")
    basis = getattr(estimator, "forcing_basis", None)
    if basis is None:
        n_kernels = (
            (ROBOT_KERNELS if estimator.protocol == "robot" else 50)
            if estimator.n_kernels is None
            else _FIELD_CHECKS["n_kernels"](estimator.n_kernels)
        )
        basis = GaussianBasis(n_kernels, check_choice(estimator.widths, "widths", WIDTH_CHOICES))
    else:
        widths = check_choice(estimator.widths, "widths", WIDTH_CHOICES)
        if estimator.n_kernels is not None or widths != "spacing":
            raise ValueError(
                "give either forcing_basis or n_kernels and widths: they set the default Gaussian basis"
            )
        _component(basis, Basis, "forcing_basis")
        check_int(basis.size, "forcing_basis.size", minimum=1, limit="max_kernels")
    # (LWR on another basis is refused by the settings' checks across fields)
    return canonical, basis


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
