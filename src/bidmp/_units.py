"""Length units: the known set, conversion, and the plausibility of a distance for a robot.

A model keeps the unit its demonstration was in (``units_``). bidmp knows the lengths ``m``, ``cm``
and ``mm``, and ``rad`` for joint angles (a joint-space model's), "" when not given; anything else
is refused, so that a typo never becomes a unit. Numbers are
converted only where the user asks (a file declaring one unit read into another), and a goal or
a scene implausibly far for a robot in the model's unit is reported (a millimetre goal given to a
metre model is 1000 times too far).
"""

from __future__ import annotations

import logging

import numpy as np

__all__ = ["UNITS", "ANGLE_UNITS", "check_units", "conversion", "check_reach", "REACH_M"]

logger = logging.getLogger(__name__)

UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}  # metres per unit
ANGLE_UNITS = ("rad",)  # joint angles: not converted into or out of a length
REACH_M = 5.0  # no robot arm reaches further than this (m): a larger distance is a unit mistake


def check_units(units, name: str = "units") -> str:
    """A known length unit (``"m"``, ``"cm"``, ``"mm"``), ``"rad"`` (joint angles) or ``""`` (not given).

    Raises
    ------
    TypeError, ValueError
        Naming ``name`` and the accepted units.
    """
    if units is None:
        return ""
    if not isinstance(units, str):
        raise TypeError(f"{name} must be a string such as 'mm', got {type(units).__name__}")
    if units not in ("", *UNITS, *ANGLE_UNITS):
        shown = repr(units[:10]) + ("…" if len(units) > 10 else "")
        raise ValueError(f"{name} must be one of {', '.join((*UNITS, *ANGLE_UNITS))} (or empty for unknown), got {shown}")
    return units


def conversion(source: str, target: str) -> float:
    """The factor that turns lengths in ``source`` into ``target`` (1 when either is unknown)."""
    source, target = check_units(source, "source units"), check_units(target, "target units")
    if not source or not target or source == target:
        return 1.0
    if source in ANGLE_UNITS or target in ANGLE_UNITS:
        raise ValueError(f"cannot convert {source} into {target}: joint angles are not lengths")
    return UNITS[source] / UNITS[target]


def check_reach(distance: float, units: str, what: str) -> bool:
    """Log a warning (and return False) if ``distance`` (in ``units``) is beyond any robot's
    reach, as a number in the wrong unit is; True otherwise. Unknown units are not judged."""
    units = check_units(units)
    if not units or units in ANGLE_UNITS or not np.isfinite(distance):
        return True
    metres = distance * UNITS[units]
    if metres <= REACH_M:
        return True
    within = [unit for unit in UNITS if unit != units and distance * UNITS[unit] <= REACH_M]
    hint = f": is it in {' or '.join(within)}?" if within else ""
    logger.warning("%s is %.4g %s away, beyond any robot's reach (%g m)%s", what, distance, units, REACH_M, hint)
    return False
