"""Length units: the known set, conversion, and the plausibility of a distance for a robot.

A model keeps the unit its demonstration was in (``units_``). bidmp knows the lengths ``m``, ``cm``
and ``mm``, and ``rad`` for joint angles (a joint-space model's), "" when not given; anything else
is refused, so that a typo never becomes a unit. Numbers are
converted only where the user asks (a file declaring one unit read into another), and a goal
implausibly far for a robot in the model's unit, or a motion implausibly fast or slow, is refused
(a millimetre goal given to a metre model is 1000 times too far).
"""

from __future__ import annotations

import logging

import numpy as np

__all__ = [
    "UNITS",
    "ANGLE_UNITS",
    "check_units",
    "conversion",
    "check_reach",
    "check_speed",
    "length_digits",
    "length_text",
    "REACH_M",
    "PLAUSIBLE_SPEED",
]

logger = logging.getLogger(__name__)

UNITS = {"m": 1.0, "cm": 0.01, "mm": 0.001}  # metres per unit
ANGLE_UNITS = ("rad",)  # joint angles: not converted into or out of a length
REACH_M = 5.0  # no robot arm reaches further than this (m): a larger distance is a unit mistake
# The peak speed of a motion a robot is taught or runs, per unit: (slowest, fastest). A hand-guided
# demonstration peaks at centimetres to a metre per second; no arm moves its tool at 10 m/s or a
# joint at 10 rad/s, and one that never passes 1 mm/s (or 0.001 rad/s) is a number in another unit.
PLAUSIBLE_SPEED = {"m": (1e-3, 10.0), "rad": (1e-3, 10.0)}


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
        raise ValueError(
            f"{name} must be one of {', '.join((*UNITS, *ANGLE_UNITS))} (or empty for unknown), got {shown}"
        )
    return units


def mm(value_mm: float, units: str) -> float:
    """``value_mm`` millimetres in ``units`` ("m", "cm", "mm"; "" and joint units are taken as mm)."""
    from ._checks import check_real

    value_mm = check_real(value_mm, "value_mm")
    return value_mm * 1e-3 / UNITS.get(check_units(units), 1e-3)


def length_digits(units: str) -> int:
    """Decimals that show a length in ``units`` to 0.01 mm (mm: 2, cm: 3, m: 5; unknown: 2)."""
    metres = UNITS.get(units, 1e-3)
    return max(int(round(np.log10(metres / 1e-5))), 0)


def length_text(value: float, units: str) -> str:
    """``value`` (in ``units``) as a reader sees it: 0.01 mm detail in any unit, and the unit
    (``length_text(0.0109, "m")`` is ``"0.01090 m"``, not ``"0.01 m"``)."""
    return f"{float(value):.{length_digits(units)}f} {units}".rstrip()


def conversion(source: str, target: str) -> float:
    """The factor that turns lengths in ``source`` into ``target`` (1 when either is unknown)."""
    source, target = check_units(source, "source units"), check_units(target, "target units")
    if not source or not target or source == target:
        return 1.0
    if source in ANGLE_UNITS or target in ANGLE_UNITS:
        raise ValueError(f"cannot convert {source} into {target}: joint angles are not lengths")
    return UNITS[source] / UNITS[target]


def check_reach(distance: float, units: str, what: str) -> None:
    """Refuse ``distance`` (in ``units``) beyond any robot's reach, as a number in another unit
    is (a goal in mm given to a metre model is 1000 times too far). Unknown units are not judged.

    Raises
    ------
    ValueError
        Naming ``what``, the distance and the units in which it would be within reach.
    """
    units = check_units(units)
    if not units or units in ANGLE_UNITS or not np.isfinite(distance):
        return
    if distance * UNITS[units] <= REACH_M:
        return
    within = [unit for unit in UNITS if unit != units and distance * UNITS[unit] <= REACH_M]
    hint = (
        f"; is it in {' or '.join(within)}? Give it in {units}, the model's unit" if within else ""
    )
    raise ValueError(
        f"{what} is {distance:.4g} {units} away, beyond any robot's reach ({REACH_M:g} m){hint}"
    )


def check_speed(peak_speed: float, units: str, what: str, *, fast_only: bool = False) -> None:
    """Refuse a peak speed (``units``/s) no robot moves at, as numbers in another unit give:
    metre data declared as mm peaks at a fraction of a mm/s, millimetre data declared as m at
    hundreds of m/s. Unknown units are not judged (:data:`PLAUSIBLE_SPEED`). ``fast_only``: judge
    only the upper bound (a generated motion to a goal near its start may be as slow as it likes).

    Raises
    ------
    ValueError
        Naming ``what``, the speed and the unit that would make it plausible.
    """
    units = check_units(units)
    if not units or not np.isfinite(peak_speed):
        return
    if units in ANGLE_UNITS:
        slowest, fastest = PLAUSIBLE_SPEED["rad"]
        slowest = 0.0 if fast_only else slowest
        if slowest <= peak_speed <= fastest:
            return
        hint = (
            f"; in degrees it would be {np.radians(peak_speed):.3g} rad/s: convert it to radians"
            if peak_speed > fastest and np.radians(peak_speed) <= fastest
            else ""
        )
        raise ValueError(
            f"{what} peaks at {peak_speed:.4g} rad/s, {'faster' if peak_speed > fastest else 'slower'} than "
            f"any robot's joint moves ({slowest:g} to {fastest:g} rad/s){hint}"
        )
    slowest, fastest = PLAUSIBLE_SPEED["m"]
    slowest = 0.0 if fast_only else slowest
    if slowest <= peak_speed * UNITS[units] <= fastest:
        return
    plausible = [unit for unit in UNITS if slowest <= peak_speed * UNITS[unit] <= fastest]
    # nearest a hand-guided motion's
    plausible.sort(key=lambda unit: abs(np.log(peak_speed * UNITS[unit] / 0.25)))
    hint = (
        f"; in {plausible[0]} it would be {peak_speed * UNITS[plausible[0]]:.3g} m/s: is it in {plausible[0]}? "
        f"(--units {plausible[0]}, or declare '# units: {plausible[0]}' in the file)"
        if plausible
        else ""
    )
    raise ValueError(
        f"{what} peaks at {peak_speed:.4g} {units}/s = {peak_speed * UNITS[units]:.4g} m/s, "
        f"{'faster' if peak_speed * UNITS[units] > fastest else 'slower'} than any robot moves its tool "
        f"({slowest * 1e3:g} mm/s to {fastest:g} m/s){hint}"
    )
