"""A recording's conventions, as its columns' names give them or a column mapping declares them:
the unit in a name (``Time(ms)``, ``time_ms``, ``X(mm)``, ``RX(deg)``), the settings beside the
roles (``time=ms``, ``euler=xyz``, ``angles=deg``, ``decimal=comma``, ``gaps=drop``), and the
refusals where the names leave a convention open (roll/pitch/yaw without a sequence, a rotation
vector whose column names degrees, a declaration the names contradict). Used by
:mod:`bidmp.io._columns`, which finds what the columns hold."""

from __future__ import annotations

import re

from .._checks import short_token

# What a file's convention is, declared beside the roles: the time column's unit, Euler angles'
# axis sequence (SciPy's: lower case about fixed axes, upper case about the turning ones) and
# unit, the decimal mark, and whether rows with gaps are dropped.
SETTINGS = {
    "time": ("s", "ms", "us", "ns"),
    "euler": None,  # three of x, y, z: checked by _check_sequence
    "angles": ("rad", "deg"),
    "decimal": ("point", "comma"),
    "gaps": ("refuse", "drop"),
}
_TIME_DIVISORS = {"s": 1.0, "ms": 1e3, "us": 1e6, "ns": 1e9}
# A unit in a column's name, as loggers write it: "X(mm)", "Time [ms]", "time_ms", "RX (deg)".
_UNIT_WORDS = {
    "s": "s", "sec": "s", "secs": "s", "seconds": "s",
    "ms": "ms", "msec": "ms", "milliseconds": "ms",
    "us": "us", "µs": "us", "μs": "us", "usec": "us", "microseconds": "us",
    "ns": "ns", "nsec": "ns", "nanoseconds": "ns",
    "mm": "mm", "cm": "cm", "m": "m",
    "deg": "deg", "degree": "deg", "degrees": "deg", "°": "deg",
    "rad": "rad", "radian": "rad", "radians": "rad",
}  # fmt: skip
_BRACKETED_UNIT = re.compile(r"^(.*?)\s*[(\[]\s*([^()\[\]\s]+)\s*[)\]]$")
_SUFFIXED_UNIT = re.compile(
    r"^(t|time|timestamp|stamp|x|y|z|rx|ry|rz|roll|pitch|yaw)_([a-zµμ]+)$", re.IGNORECASE
)


def split_unit(name: str) -> tuple[str, str]:
    """A header name without the unit it names, and that unit (``"ms"``, ``"deg"``, ``"mm"`` ...;
    ``""`` when it names none): ``X(mm)``, ``Time [ms]``, ``time_ms``."""
    text = name.strip()
    for pattern in (_BRACKETED_UNIT, _SUFFIXED_UNIT):
        match = pattern.match(text)
        if match and match.group(2).lower() in _UNIT_WORDS and match.group(1).strip():
            return match.group(1).strip(), _UNIT_WORDS[match.group(2).lower()]
    return text, ""


def _setting(name: str, value) -> str:
    """A declared convention's value, checked."""
    if not isinstance(value, str) or not value.strip():
        raise ValueError(f"columns: setting {name} needs a value")
    value = value.strip()
    if name == "euler":
        return _check_sequence(value)
    value = _UNIT_WORDS.get(value.lower(), value)  # (a unit as a column's name may spell it)
    if value.lower() not in SETTINGS[name]:
        raise ValueError(
            f"columns: {name}={short_token(value, 20)[1:-1]} is not one of {', '.join(SETTINGS[name])}"
        )
    return value.lower()


def _check_sequence(value: str) -> str:
    """An Euler axis sequence as SciPy reads it: three of x, y, z (no axis twice in a row), all
    lower case (about the fixed axes) or all upper case (about the turning ones)."""
    if (
        len(value) != 3
        or not (value.islower() or value.isupper())
        or set(value.lower()) - set("xyz")
        or value[0].lower() == value[1].lower()
        or value[1].lower() == value[2].lower()
    ):
        raise ValueError(
            f"columns: euler={short_token(value, 20)[1:-1]} is no axis sequence: three of x, y, z, "
            f"lower case about the fixed axes (xyz: roll, pitch, yaw) or upper case about the turning "
            f"ones (ZYX)"
        )
    return value


def _declared_time(header, time, scale: float, settings: dict, path) -> tuple[float, bool]:
    """The time column's units per second and whether they are declared (by the column's name,
    a logger's convention or ``time=``) rather than assumed to be seconds."""
    named = split_unit(header[time[0]])[1] if len(time) == 1 else ""
    declared = len(time) == 2 or scale != 1.0 or named == "s"
    if "time" not in settings:
        return scale, declared
    unit = settings["time"]
    if not time:
        raise ValueError(
            f"{path}: time={unit} declares the unit of the time column, but the header has none "
            f"(name it with t=<column>)"
        )
    if len(time) == 2:
        raise ValueError(
            f"{path}: time={unit} does not apply to a ROS header stamp (its sec and nanosec fields "
            f"are their own units)"
        )
    if named in _TIME_DIVISORS and named != unit:
        raise ValueError(
            f"{path}: time={unit} but the column {short_token(header[time[0]], 30)} names {named}"
        )
    return _TIME_DIVISORS[unit], True


def _refuse_undeclared_euler(header, keys, path) -> None:
    """Euler angles by name (roll, pitch, yaw; KUKA's a, b, c beside x, y, z) give no sequence:
    refused with the declaration that reads them (never guessed)."""
    for names, example in ((("roll", "pitch", "yaw"), "xyz"), (("a", "b", "c"), "ZYX")):
        # (a, b, c and d beside them: four unnamed numbers, no KUKA angles)
        if all(name in keys for name in names) and {"x", "y", "z"} <= set(keys) and "d" not in keys:
            where = [header[keys.index(name)] for name in names]
            unit = split_unit(where[0])[1] or "deg|rad"
            raise ValueError(
                f"{path}: columns {', '.join(where)} are Euler angles, whose axis sequence and unit "
                f"the names do not fix; declare them, e.g. --columns x=x,y=y,z=z,e1={where[0]},"
                f"e2={where[1]},e3={where[2]},euler={example},angles={unit} (or pick the positions "
                f"alone: --columns x=x,y=y,z=z)"
            )


def _units_named(header, chosen, settings: dict, path) -> tuple[str, str]:
    """(the values' unit, the Euler angles' unit) as the columns' names and the declarations
    give them, for ``chosen`` (the motion the columns hold: its kind, value columns, rotation,
    the unit its convention fixes and its label); a name whose unit cannot be the role's is
    refused with the fix."""
    named = [split_unit(header[index])[1] for index in chosen.values]
    if chosen.kind == "joints":
        units = {unit for unit in named if unit}
        if units - {"rad", "deg"} or len(units) > 1:
            raise ValueError(
                f"{path}: the joint columns name {', '.join(sorted(units))}: joints are angles in "
                f"one unit (rad or deg)"
            )
        return (units.pop() if units else chosen.units), ""
    lengths = named[:3]
    given = {unit for unit in lengths if unit}
    if given - {"mm", "cm", "m"} or len(given) > 1:
        raise ValueError(
            f"{path}: the position columns ({', '.join(header[i] for i in chosen.values[:3])}) name "
            f"{', '.join(sorted(given))}: positions are lengths in one unit (mm, cm or m)"
        )
    if given and chosen.units and given != {chosen.units}:
        raise ValueError(
            f"{path}: the position columns name {given.pop()}, but {chosen.label} is in "
            f"{chosen.units} by its convention"
        )
    units = given.pop() if given else chosen.units
    turned = [split_unit(header[index])[1] for index in chosen.values[3:]]
    if chosen.rotation == "rotvec" and set(turned) - {"", "rad"}:
        columns = [header[index] for index in chosen.values[3:]]
        raise ValueError(
            f"{path}: the rotation-vector columns {', '.join(columns)} name {turned[0] or turned[-1]}: "
            f"a rotation vector is an axis times an angle in radians. If these are roll/pitch/yaw "
            f"(TMflow's Rx, Ry, Rz are), declare them as Euler angles: --columns x=..,y=..,z=..,"
            f"e1={columns[0]},e2={columns[1]},e3={columns[2]},euler=xyz,angles=deg"
        )
    if chosen.rotation != "euler":
        return units, ""
    angle_units = {unit for unit in turned if unit}
    if angle_units - {"deg", "rad"} or len(angle_units) > 1:
        raise ValueError(
            f"{path}: the Euler-angle columns name {', '.join(sorted(angle_units))}: angles are "
            f"in one unit (deg or rad)"
        )
    angles = settings.get("angles", "")
    if angle_units and angles and angle_units != {angles}:
        raise ValueError(
            f"{path}: angles={angles} but the Euler-angle columns name {angle_units.pop()}"
        )
    angles = angles or (angle_units.pop() if angle_units else "")
    if not angles:
        raise ValueError(
            f"{path}: the Euler angles' unit is not named: declare it, angles=deg or angles=rad"
        )
    return units, angles
