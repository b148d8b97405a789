"""A scenario's options as checked objects: its ``"dmp"``, ``"bidmp"`` and ``"robot"`` objects.

Each is the keyword arguments of the estimator it configures (:class:`bidmp.DMP`,
:class:`bidmp.BiDMP`), checked once when made by the estimator's own checks (a ``ValueError`` or
``TypeError`` naming the first bad one); an option left ``None`` is the estimator's default.
``arguments`` gives them back as keyword arguments, ``flat`` as a scenario file writes them.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field

__all__ = ["BiDMPOptions", "DMPOptions", "ExtensionStage", "RobotOptions"]


class _Options:
    """What the option objects share: fields left ``None`` are not set."""

    @property
    def arguments(self) -> dict:
        """The options that are set, by name (an estimator's keyword arguments)."""
        return {
            item.name: getattr(self, item.name)
            for item in dataclasses.fields(self)
            if getattr(self, item.name) is not None
        }

    @property
    def flat(self) -> dict:
        """A scenario file's form of the options (``from_flat`` reads it back)."""
        return {
            key: list(value) if isinstance(value, tuple) else value
            for key, value in self.arguments.items()
        }

    def replace(self, **changes):
        """These options with ``changes`` (checked again)."""
        return dataclasses.replace(self, **changes)


class _EstimatorOptions(_Options):
    """Options whose fields are an estimator's keyword arguments, checked by the estimator."""

    def __post_init__(self) -> None:
        self._check(self.arguments)

    @staticmethod
    def _check(arguments: dict) -> None:  # pragma: no cover - each subclass has its own
        raise NotImplementedError

    @classmethod
    def from_flat(cls, options: dict | None = None):
        """The options from a scenario file's form (``{"n_kernels": 30, ...}``); an unknown name
        is a ``TypeError`` listing the known ones."""
        if options is None:
            options = {}
        if not isinstance(options, dict) or not all(isinstance(key, str) for key in options):
            raise TypeError(
                f"{cls.__name__} options must be a dict with string keys, got {type(options).__name__}"
            )
        known = [item.name for item in dataclasses.fields(cls)]
        unknown = sorted(set(options) - set(known))
        if unknown:
            raise TypeError(f"unknown option {unknown[0]!r} (known: {', '.join(sorted(known))})")
        return cls(**options)


@dataclass(frozen=True)
class DMPOptions(_EstimatorOptions):
    """A scenario's DMP: the keyword arguments of :class:`bidmp.DMP` it sets (units as there:
    gains in 1/s, ``tau`` a time scale), each ``None`` for the DMP's default (the protocol's).

    ``protocol`` is "robot" (the default) or "paper"; the rest are the DMP's parameters of the
    same names.
    """

    protocol: str | None = None
    n_kernels: int | None = None
    alpha: float | None = None
    beta: float | None = None
    K: float | str | None = None
    alpha_phase: float | None = None
    tau: float | None = None
    regression: str | None = None
    widths: str | None = None
    derivatives: str | None = None
    keep_approach: bool | None = None
    goal_rate: float | None = None

    @staticmethod
    def _check(arguments: dict) -> None:
        from ..primitives.dmp import DMP

        DMP(**arguments).settings()

    @property
    def protocol_name(self) -> str:
        """The protocol in use: "robot" unless "paper" is set."""
        return self.protocol or "robot"


@dataclass(frozen=True)
class BiDMPOptions(_EstimatorOptions):
    """A scenario's Bi-DMP: the keyword arguments of :class:`bidmp.BiDMP` it sets (its broad
    learning system's sizes, regularisation, increments and seed), each ``None`` for the
    Bi-DMP's default."""

    n_windows: int | None = None
    n_mapped: int | None = None
    n_enhance: int | None = None
    increments: tuple | None = None
    shrink: float | None = None
    reg: float | None = None
    seed: int | None = None
    derivatives: str | None = None

    def __post_init__(self) -> None:
        if isinstance(self.increments, list):  # as a file writes them
            object.__setattr__(self, "increments", tuple(self.increments))
        super().__post_init__()

    @staticmethod
    def _check(arguments: dict) -> None:
        from ..incremental.bidmp import BiDMP

        BiDMP(**arguments).check_params()


@dataclass(frozen=True)
class RobotOptions(_Options):
    """A scenario's arm and where it stands: its ``"robot"`` object, checked as a file's is.

    Attributes
    ----------
    base : tuple of 3 floats or None
        The arm's base in the scenario's units (None: placed in front of the work).
    yaw : float or None
        The base's turn about z, degrees (None: 90, facing +y).
    model : str or None
        A built-in arm (panda, the default; iiwa, xarm6, ur5); None with ``urdf``.
    urdf : str or None
        The arm's own URDF file (resolved when the scenario loaded), with ``flange`` (the link
        the tool is mounted on), ``limits`` (``{"lower", "upper", "velocity", "acceleration",
        "jerk"}``, one value per joint: rad, rad/s, rad/s², rad/s³), ``rest`` (the job's start
        pose, rad; None: found by IK from the demonstration's start) and ``effort`` (N m).
    """

    base: tuple | None = None
    yaw: float | None = None
    model: str | None = None
    urdf: str | None = None
    flange: str | None = None
    limits: dict | None = field(default=None, hash=False)
    rest: tuple | None = None
    effort: tuple | None = None

    def __post_init__(self) -> None:
        # Checked as a file's "robot" object is (a ScenarioError, a ValueError, names the key); a
        # relative urdf is left as given (from_flat resolves it in the scenario's folder).
        from ._scenario_fields import _robot

        checked = _robot({"robot": self.flat}, "robot", ".", allow_outside=True)
        for key in ("base", "yaw", "limits", "rest", "effort"):  # as numbers, one per joint
            if key in checked:
                value = checked[key]
                object.__setattr__(self, key, tuple(value) if isinstance(value, list) else value)

    @classmethod
    def from_flat(cls, robot: dict | None = None, base_dir=".") -> RobotOptions:
        """The options from a scenario file's ``"robot"`` object (a relative ``urdf`` resolved in
        ``base_dir``); a :class:`~bidmp.tasks.ScenarioError` names the first bad key."""
        from ._scenario_fields import _robot

        if robot is not None and not isinstance(robot, dict):
            raise TypeError(
                f'robot must be a scenario\'s "robot" object (a dict) or None, got {type(robot).__name__}'
            )
        return cls(**_robot({"robot": robot or {}}, "robot", base_dir, allow_outside=True))

    @property
    def own_arm(self) -> bool:
        """Whether the arm is the user's own URDF (not a built-in one)."""
        return self.urdf is not None


@dataclass(frozen=True)
class ExtensionStage:
    """One stage of a scenario's extended demonstrations (its ``"extensions"`` list), checked
    when the scenario loads.

    Attributes
    ----------
    target : array (D,) or str
        Where the stage grows to: a point (or pose) in the scenario's units, or
        ``"centre_of_failed"`` (the centre of the targets the plain DMP misses).
    origin : {"demonstration", "previous"}
        What it grows from: the demonstration, or the previous stage's extension.
    in_scene : bool
        Whether its route is planned among the scene's parts.
    """

    target: object
    origin: str = "demonstration"
    in_scene: bool = True

    def __post_init__(self) -> None:
        # made directly too (not only by a scenario file): checked as the file's are
        from .._checks import as_vector, short_token

        target = self.target
        if isinstance(target, str):
            if not target.strip() or len(target) > 200 or not target.isprintable():
                raise ValueError(
                    f"target must be 'centre_of_failed', a target's label or a point, got "
                    f"{short_token(target, 40)}"
                )
        else:
            point = as_vector(target, "target", min_length=2)
            if point.shape[0] > 7:
                raise ValueError(
                    f"target must be a point (2-3 coordinates, 7 for a pose), got {point.shape[0]}"
                )
            object.__setattr__(self, "target", point.tolist())
        if not isinstance(self.origin, str) or self.origin not in ("demonstration", "previous"):
            raise ValueError(
                f"origin must be 'demonstration' or 'previous', got {short_token(self.origin, 40)}"
            )
        if not isinstance(self.in_scene, bool):
            raise TypeError(f"in_scene must be True or False, got {type(self.in_scene).__name__}")

    @property
    def from_previous(self) -> bool:
        """Whether the stage grows from the previous stage's extension."""
        return self.origin == "previous"
