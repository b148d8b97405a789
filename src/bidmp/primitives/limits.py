"""The caps a motion runs within: :class:`MotionLimits`, the typed form of the ``limits`` every
primitive's ``trajectory`` takes (the dict ``{"max_velocity": …}`` stays its file form and is
still accepted).

Layer 1: the package's own math.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, fields

import numpy as np

from .._checks import short_token

__all__ = ["MotionLimits", "as_motion_limits"]

_CAPS = ("max_velocity", "max_acceleration", "max_jerk")
_NORMS = ("norm", "axis")


def _cap(value, name: str):
    """One cap as a float or a tuple of floats (one per axis), each positive and finite."""
    if value is None:
        return None
    if isinstance(value, (bool, np.bool_)) or not isinstance(
        value, (int, float, np.integer, np.floating, list, tuple, np.ndarray)
    ):
        raise TypeError(
            f"MotionLimits.{name} must be a positive number or one per axis, got "
            f"{type(value).__name__}"
        )
    try:
        array = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise TypeError(
            f"MotionLimits.{name} must hold numbers, got {short_token(repr(value), 40)}"
        ) from None
    if array.ndim > 1 or array.size == 0:
        raise ValueError(
            f"MotionLimits.{name} must be a number or a flat list (one per axis), got shape "
            f"{array.shape}"
        )
    if not (np.all(np.isfinite(array)) and np.all(array > 0.0)):
        raise ValueError(
            f"MotionLimits.{name} must be positive and finite, got "
            f"{short_token(np.array2string(array, threshold=4), 40)}"
        )
    return float(array) if array.ndim == 0 else tuple(float(v) for v in array)


@dataclass(frozen=True)
class MotionLimits:
    """Caps on a motion's speed, acceleration and jerk, checked when made.

    A motion that breaks one is slowed, uniformly, to the shortest duration that meets them all;
    one within them runs as demonstrated (a cap never hurries a motion) unless ``fastest``.

    Parameters
    ----------
    max_velocity : float or sequence of float, optional
        Units/s: one bound on the speed (``norm="norm"``) or one per axis (``norm="axis"``).
    max_acceleration : float or sequence of float, optional
        Units/s².
    max_jerk : float or sequence of float, optional
        Units/s³.
    norm : {"norm", "axis"}
        Bound the vector's length, or each axis on its own.
    fastest : bool
        Run at the shortest duration within the caps, faster than demonstrated where they allow.

    Examples
    --------
    >>> MotionLimits(max_velocity=0.25).as_dict()
    {'max_velocity': 0.25, 'norm': 'norm', 'fastest': False}
    """

    max_velocity: float | tuple[float, ...] | None = None
    max_acceleration: float | tuple[float, ...] | None = None
    max_jerk: float | tuple[float, ...] | None = None
    norm: str = "norm"
    fastest: bool = False

    def __post_init__(self) -> None:
        # the options first: a refusal names the argument that is wrong, whatever else is
        if not isinstance(self.norm, str) or self.norm not in _NORMS:
            raise ValueError(
                f"MotionLimits.norm must be 'norm' or 'axis', got {short_token(repr(self.norm), 30)}"
            )
        if not isinstance(self.fastest, (bool, np.bool_)):
            raise TypeError(
                f"MotionLimits.fastest must be True or False, got {type(self.fastest).__name__}"
            )
        object.__setattr__(self, "fastest", bool(self.fastest))
        for name in _CAPS:
            object.__setattr__(self, name, _cap(getattr(self, name), name))
        if all(getattr(self, name) is None for name in _CAPS):
            raise ValueError(
                "MotionLimits needs at least one of max_velocity, max_acceleration, max_jerk"
            )
        if self.norm == "norm":
            for name in _CAPS:
                value = getattr(self, name)
                if isinstance(value, tuple) and len(value) > 1:
                    raise ValueError(
                        f"MotionLimits.{name}: one bound per axis ({len(value)}) needs "
                        "norm='axis'; with norm='norm' the bound is one number"
                    )

    def caps(self) -> dict:
        """The given caps and the norm, as :func:`bidmp.primitives.timing.scale_factor`'s
        keywords."""
        out = {name: getattr(self, name) for name in _CAPS if getattr(self, name) is not None}
        return {**out, "norm": self.norm}

    def as_dict(self) -> dict:
        """The file form: the given caps (lists for per-axis ones), ``norm`` and ``fastest``."""
        out = {}
        for name in _CAPS:
            value = getattr(self, name)
            if value is not None:
                out[name] = list(value) if isinstance(value, tuple) else value
        return {**out, "norm": self.norm, "fastest": self.fastest}

    @classmethod
    def from_dict(cls, limits: Mapping) -> MotionLimits:
        """The limits a ``{"max_velocity": …, "norm": …, "fastest": …}`` mapping gives (a model
        file's or a caller's); an unknown key is refused, naming the known ones."""
        if not isinstance(limits, Mapping):
            raise TypeError(
                f"limits must be a bidmp.MotionLimits or a dict of "
                f"{', '.join(f.name for f in fields(cls))}, got {type(limits).__name__}"
            )
        known = {f.name for f in fields(cls)}
        unknown = set(limits) - known
        if unknown:
            raise ValueError(
                f"limits has unknown key(s) {short_token(sorted(map(str, unknown)), 40)}; known: "
                f"{', '.join(f.name for f in fields(cls))}"
            )
        return cls(**dict(limits))


def as_motion_limits(limits) -> MotionLimits | None:
    """``limits`` (None, a :class:`MotionLimits` or its dict form) as :class:`MotionLimits`."""
    if limits is None or isinstance(limits, MotionLimits):
        return limits
    return MotionLimits.from_dict(limits)
