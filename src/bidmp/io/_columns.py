"""Which CSV columns are time, positions, orientations and joints: headers as robot loggers write them.

Recognised by name (case does not matter; ``/``, ``[ ]`` and ``.`` separate a field's parts alike):

* **time** — ``t``, ``time``, ``timestamp``, ``stamp``, ``__time`` (PlotJuggler), ``%time``
  (``rostopic echo -p``: nanoseconds), and header stamps: ``header.stamp`` (``field.header.stamp``:
  nanoseconds) or ``header.stamp.sec`` with ``header.stamp.nanosec`` (``nsec``). A header stamp
  is preferred over a receive time, as bags are read; two candidates of one kind are refused;
* **positions** — ``x, y[, z]``; ROS exports ``<prefix>position.x/y/z`` or
  ``<prefix>translation.x/y/z``;
* **orientations** — ``qx, qy, qz, qw`` (any order) or a rotation vector ``rx, ry, rz`` (rad,
  beside ``x, y, z``); ROS ``<prefix>orientation.x/y/z/w`` or ``rotation.x/y/z/w``; UR RTDE
  ``actual_TCP_pose_0..5`` (and ``target_TCP_pose_…``): x, y, z in metres and a rotation vector;
* **joints** — UR RTDE ``actual_q_0..`` / ``target_q_0..`` (rad), a ``rostopic echo -p``
  JointState (``field.position0..``, the names from the rows' ``field.name0..``), or a file
  ``t, <joint names>`` whose other columns are all joints.

A file whose columns hold more than one motion (an RTDE log of the measured and the commanded
pose and joints) is refused with the candidates listed and the ``columns`` that picks each; it
is never guessed. A *column mapping* decides: roles ``t``, ``x``, ``y``, ``z``, ``qx``…``qw``,
``rx``, ``ry``, ``rz`` name single columns, and ``pose=``, ``position=``, ``joints=`` a group by
its prefix (``pose=actual_TCP_pose``, ``joints=actual_q``) or joints by name
(``joints=shoulder_pan_joint|elbow_joint``, in that order); as the command line writes it,
``t=stamp,x=ee_x,y=ee_y,z=ee_z``. A mapping with only ``t`` fixes the time and leaves the rest
to the names.

**Conventions.** A unit in a column's name is read (``Time(ms)``, ``time_ms``, ``t [us]``,
``X(mm)``, ``RX(deg)``, ``j1 (deg)``); settings beside the roles declare the rest: ``time=ms``
(s, ms, us, ns), Euler angles ``e1, e2, e3`` with ``euler=<sequence>`` (SciPy's: ``xyz`` about the
fixed axes, roll/pitch/yaw; ``ZYX`` about the turning ones, KUKA's A, B, C) and ``angles=deg|rad``,
``decimal=comma`` (seen by itself in a file separated by ``;``, tabs or spaces), ``gaps=drop``
(rows with a NaN dropped, with a warning). What the names leave open is refused with the
declaration that settles it, never guessed: roll/pitch/yaw or A/B/C without a sequence, a rotation
vector whose columns name degrees, a declaration the names contradict.
"""

from __future__ import annotations

import logging
import re
from dataclasses import dataclass

import numpy as np

from .._checks import short_token
from ._conventions import (
    _TIME_DIVISORS,
    SETTINGS,
    _declared_time,
    _refuse_undeclared_euler,
    _setting,
    _units_named,
    split_unit,
)

logger = logging.getLogger(__name__)

__all__ = ["TIME_NAMES", "Layout", "parse_columns", "resolve", "times_in_seconds"]

TIME_NAMES = ("t", "time", "timestamp", "stamp", "__time", "%time")
_POSITION_ROLES = ("x", "y", "z")
_QUATERNION_ROLES = ("qx", "qy", "qz", "qw")
_ROTVEC_ROLES = ("rx", "ry", "rz")
_EULER_ROLES = ("e1", "e2", "e3")
_SINGLE_ROLES = ("t", *_POSITION_ROLES, *_QUATERNION_ROLES, *_ROTVEC_ROLES, *_EULER_ROLES)
_GROUP_ROLES = ("pose", "position", "joints")
_MAX_MAPPING = 24
_RTDE_POSE = re.compile(r"^(.*tcp_pose)_([0-9]+)$")
_RTDE_JOINTS = re.compile(r"^((?:actual|target)_q)_([0-9]+)$")
_INDEXED = re.compile(r"^(.*?)[._]?([0-9]+)$")
_TRANSLATIONS = (("position.", "orientation."), ("translation.", "rotation."))


@dataclass(frozen=True)
class Layout:
    """What a header's columns hold.

    Attributes
    ----------
    kind : {"positions", "pose", "joints"}
    time : tuple of int
        The time column (one index), a header stamp's ``sec`` and ``nanosec`` columns (two), or
        none.
    time_divisor : float
        Units of the time column per second (1e9 for nanosecond stamps; a division, so that a
        stamp a float holds exactly in seconds comes out exact).
    values : tuple of int
        Positions ``x, y[, z]``; a pose's ``x, y, z`` and its rotation (``qx, qy, qz, qw`` or
        ``rx, ry, rz``); or the joints, in order.
    rotation : {"quaternion", "rotvec", "euler", None}
        How a pose's rotation columns (or the ``orientation`` columns) give it.
    orientation : tuple of int
        Positions picked from a pose group (``position=actual_TCP_pose``): the group's rotation
        columns, read beside them (a position model keeps the orientation the demonstration held).
    names : tuple of str
        The file's own names of the value columns (a joint recording's joint names).
    units : str
        The unit the logger's convention fixes (metres for ROS and RTDE poses, radians for
        joints), "" when the names say none.
    label : str
        What was read, for messages (``UR RTDE actual_TCP_pose_0..5``).
    ignored : tuple of str
        The other columns.
    euler : str
        Euler angles' axis sequence (SciPy's) when the rotation is ``"euler"``.
    angles : {"rad", "deg", ""}
        The unit of Euler angles.
    names_from : tuple of int
        Text columns whose cells are the joints' names (a ``rostopic echo -p`` JointState's
        ``name0..``): the names are read from the rows.
    time_declared : bool
        Whether the time column's unit is declared (by its name or ``time=``), not assumed.
    """

    kind: str
    time: tuple[int, ...]
    time_divisor: float
    values: tuple[int, ...]
    rotation: str | None
    orientation: tuple[int, ...]
    names: tuple[str, ...]
    units: str
    label: str
    ignored: tuple[str, ...]
    euler: str = ""
    angles: str = ""
    names_from: tuple[int, ...] = ()
    time_declared: bool = False


@dataclass(frozen=True)
class _Candidate:
    kind: str
    values: tuple[int, ...]
    rotation: str | None
    units: str
    label: str
    pick: str  # the mapping that selects it
    orientation: tuple[int, ...] = ()
    names_from: tuple[int, ...] = ()  # text columns holding the joints' names (a JointState)


def _key(name: str) -> str:
    """A header name as compared: lower case, one separator (``.``), no ``field.`` prefix, no
    unit (``X(mm)`` is ``x``)."""
    key = re.sub(r"[/\[\]]", ".", split_unit(name)[0].lower())
    key = re.sub(r"\.+", ".", key).strip(".")
    return key[len("field.") :] if key.startswith("field.") else key


def parse_columns(spec) -> dict[str, str] | None:
    """A column mapping from ``"t=stamp,x=ee_x,…"`` or a dict (roles to the file's names).

    Roles: ``t``, ``x``, ``y``, ``z``, ``qx``, ``qy``, ``qz``, ``qw``, ``rx``, ``ry``, ``rz``
    (single columns) and ``pose``, ``position``, ``joints`` (a group by its prefix). Names are
    matched without regard to case.
    """
    if spec is None:
        return None
    if isinstance(spec, str):
        pairs = [item.split("=", 1) for item in spec.split(",") if item.strip()]
        if not pairs or any(len(pair) != 2 for pair in pairs):
            raise ValueError(
                f"columns must read role=name[,role=name...], e.g. t=timestamp,x=ee_x; got {short_token(spec, 40)}"
            )
        spec = {role.strip(): name.strip() for role, name in pairs}
    if not isinstance(spec, dict):
        raise TypeError(
            f"columns must be a dict or a role=name,... string, got {type(spec).__name__}"
        )
    if len(spec) > _MAX_MAPPING:
        raise ValueError(
            f"columns names {len(spec)} roles and settings; there are at most {_MAX_MAPPING}"
        )
    mapping = {}
    for role, name in spec.items():
        if role in SETTINGS:
            mapping[role] = _setting(role, name)
            continue
        if role not in (*_SINGLE_ROLES, *_GROUP_ROLES):
            raise ValueError(
                f"columns: unknown role {short_token(role)}; roles are {', '.join(_SINGLE_ROLES)} "
                f"and the groups {', '.join(_GROUP_ROLES)}; settings {', '.join(SETTINGS)}"
            )
        if not isinstance(name, str) or not name:
            raise ValueError(f"columns: role {role} needs a column name")
        mapping[role] = _key(name)
    names = [mapping[role] for role in mapping if role not in SETTINGS]
    if len(set(names)) != len(names):
        raise ValueError("columns: two roles name the same column")
    groups = [role for role in _GROUP_ROLES if role in mapping]
    singles = [role for role in mapping if role in _SINGLE_ROLES and role != "t"]
    if len(groups) > 1 or (groups and singles):
        raise ValueError(
            f"columns: give one group ({', '.join(_GROUP_ROLES)}) or single columns, not "
            f"{' and '.join(groups + singles[:1])}"
        )
    _check_rotation_roles(mapping)
    return mapping


def _check_rotation_roles(mapping: dict) -> None:
    """One rotation, whole, with what it needs declared (an Euler sequence; its unit)."""
    if any(role in mapping for role in _QUATERNION_ROLES) and not all(
        role in mapping for role in _QUATERNION_ROLES
    ):
        raise ValueError("columns: a quaternion needs all of qx, qy, qz, qw")
    if any(role in mapping for role in _ROTVEC_ROLES) and not all(
        role in mapping for role in _ROTVEC_ROLES
    ):
        raise ValueError("columns: a rotation vector needs all of rx, ry, rz")
    if any(role in mapping for role in _EULER_ROLES) and not all(
        role in mapping for role in _EULER_ROLES
    ):
        raise ValueError("columns: Euler angles need all of e1, e2, e3")
    given = [
        roles[0]
        for roles in (_QUATERNION_ROLES, _ROTVEC_ROLES, _EULER_ROLES)
        if roles[0] in mapping
    ]
    if len(given) > 1:
        raise ValueError(
            "columns: give one rotation: a quaternion (qx..qw), a rotation vector (rx, ry, rz) or "
            "Euler angles (e1, e2, e3)"
        )
    if "e1" in mapping and "euler" not in mapping:
        raise ValueError(
            "columns: Euler angles e1, e2, e3 need their axis sequence, e.g. euler=xyz (roll, "
            "pitch, yaw about fixed x, y, z: ROS, TMflow) or euler=ZYX (KUKA's A, B, C)"
        )
    if "euler" in mapping and "e1" not in mapping:
        raise ValueError(
            "columns: euler= declares the sequence of Euler angles e1, e2, e3: name them"
        )
    if "angles" in mapping and "e1" not in mapping:
        raise ValueError(
            "columns: angles= declares the unit of Euler angles e1, e2, e3 (a rotation vector is "
            "radians, a quaternion has none)"
        )


def _shown(header, limit: int = 8) -> str:
    return ",".join(short_token(c, 16)[1:-1] for c in header[:limit]) + (
        ",…" if len(header) > limit else ""
    )


# -- time -----------------------------------------------------------------------------------------
def _time_divisor(name: str, key: str) -> float:
    """Units of a time column per second: the unit its name gives (``Time(ms)``, ``time_us``);
    nanoseconds for ``rostopic echo -p``'s columns (``%time``, ``field.…``); else seconds."""
    unit = split_unit(name)[1]
    if unit in _TIME_DIVISORS:
        return _TIME_DIVISORS[unit]
    return 1e9 if name.strip().lower().startswith("field.") or key == "%time" else 1.0


def _time_candidates(header: tuple[str, ...], keys: list[str]) -> tuple[list, list]:
    """(header stamps, other time columns): each a list of (indices, scale, name)."""
    stamps, others = [], []
    for index, key in enumerate(keys):
        divisor = _time_divisor(header[index], key)
        if key == "header.stamp" or key.endswith(".header.stamp"):
            stamps.append(((index,), divisor, header[index]))
        elif key.endswith("header.stamp.sec") or key == "stamp.sec":
            stem = key[: -len("sec")]
            fraction = next(
                (keys.index(stem + part) for part in ("nanosec", "nsec") if stem + part in keys),
                None,
            )
            if fraction is not None:
                stamps.append(((index, fraction), 1.0, f"{header[index]} + {header[fraction]}"))
        elif key in TIME_NAMES:
            others.append(((index,), divisor, header[index]))
    return stamps, others


def _time_from_names(header, keys, path) -> tuple[tuple[int, ...], float]:
    stamps, others = _time_candidates(header, keys)
    for found, what in ((stamps, "header stamps"), (others, "time columns")):
        if len(found) > 1:
            names = ", ".join(name for _, _, name in found)
            raise ValueError(
                f"{path}: {len(found)} {what} ({names}); name the one to use, e.g. --columns / columns= "
                f"t={short_token(found[0][2], 30)[1:-1]}"
            )
        if found:
            return found[0][0], found[0][1]
    return (), 1.0


def times_in_seconds(values: np.ndarray, layout: Layout, path) -> np.ndarray | None:
    """The time column of ``values`` (rows of the file) in seconds, or None without one.

    Stamps as loggers write them: seconds, the two fields of a ROS header, or nanoseconds by
    name (``%time``, ``field.header.stamp``); epoch stamps in milliseconds, microseconds or
    nanoseconds are recognised by their size (no epoch in seconds lies beyond the year 5000)."""
    if not layout.time:
        return None
    if len(layout.time) == 2:  # sec + nanosec: seconds counted from the first, so no digit is lost
        seconds, fraction = values[:, layout.time[0]], values[:, layout.time[1]]
        return (seconds - seconds[0]) + fraction / 1e9 + seconds[0]
    stamps = values[:, layout.time[0]] / layout.time_divisor
    first = float(np.min(np.abs(stamps))) if stamps.size else 0.0
    if layout.time_divisor == 1.0 and first > 1e11:
        for divisor, unit in ((1e9, "nanoseconds"), (1e6, "microseconds"), (1e3, "milliseconds")):
            if first / divisor > 1e8:  # an epoch stamp after 1973
                logger.info("%s: the time column holds epoch stamps in %s", path, unit)
                return stamps / divisor
    return stamps


# -- motions --------------------------------------------------------------------------------------
def _ros_candidates(header, keys) -> list[_Candidate]:
    found = []
    for _index, key in enumerate(keys):
        for translation, rotation in _TRANSLATIONS:
            if not key.endswith(translation + "x"):
                continue
            prefix = key[: -len(translation + "x")]
            where = [
                keys.index(prefix + translation + axis)
                if prefix + translation + axis in keys
                else None
                for axis in "xyz"
            ]
            if None in where:
                continue
            turn = [
                keys.index(prefix + rotation + axis) if prefix + rotation + axis in keys else None
                for axis in "xyzw"
            ]
            group = prefix.rstrip(".") or translation.rstrip(".")
            if None in turn:
                found.append(
                    _Candidate(
                        "positions",
                        tuple(where),
                        None,
                        "m",
                        f"{prefix}{translation}x/y/z",
                        f"position={group}",
                    )
                )
            else:
                found.append(
                    _Candidate(
                        "pose",
                        (*where, *turn),
                        "quaternion",
                        "m",
                        f"{prefix}{translation}x/y/z + {prefix}{rotation}x/y/z/w",
                        f"pose={group}",
                    )
                )
    return found


def _indexed_groups(header, keys, pattern) -> dict[str, list[tuple[int, int]]]:
    groups: dict[str, list[tuple[int, int]]] = {}
    for index, key in enumerate(keys):
        match = pattern.match(key)
        if match:
            groups.setdefault(match.group(1), []).append((int(match.group(2)), index))
    return groups


def _rtde_candidates(header, keys) -> list[_Candidate]:
    found = []
    for _prefix, members in _indexed_groups(header, keys, _RTDE_POSE).items():
        by_number = dict(members)
        if all(n in by_number for n in range(6)):
            name = header[by_number[0]][:-2]
            found.append(
                _Candidate(
                    "pose",
                    tuple(by_number[n] for n in range(6)),
                    "rotvec",
                    "m",
                    f"UR RTDE {name}_0..5",
                    f"pose={name}",
                )
            )
    for _prefix, members in _indexed_groups(header, keys, _RTDE_JOINTS).items():
        members.sort()
        if [n for n, _ in members] == list(range(len(members))):
            name = header[members[0][1]][:-2]
            found.append(
                _Candidate(
                    "joints",
                    tuple(index for _, index in members),
                    None,
                    "rad",
                    f"UR RTDE {name}_0..{len(members) - 1}",
                    f"joints={name}",
                )
            )
    return found


def _plain_candidate(keys) -> list[_Candidate]:
    if not ("x" in keys and "y" in keys):
        return []
    where = tuple(keys.index(axis) for axis in _POSITION_ROLES if axis in keys)
    if all(role in keys for role in _QUATERNION_ROLES) and len(where) == 3:
        return [
            _Candidate(
                "pose",
                (*where, *(keys.index(r) for r in _QUATERNION_ROLES)),
                "quaternion",
                "",
                "x,y,z,qx,qy,qz,qw",
                "x=x,y=y,z=z,qx=qx,qy=qy,qz=qz,qw=qw",
            )
        ]
    if all(role in keys for role in _ROTVEC_ROLES) and len(where) == 3:
        return [
            _Candidate(
                "pose",
                (*where, *(keys.index(r) for r in _ROTVEC_ROLES)),
                "rotvec",
                "",
                "x,y,z,rx,ry,rz",
                "x=x,y=y,z=z,rx=rx,ry=ry,rz=rz",
            )
        ]
    return [
        _Candidate(
            "positions",
            where,
            None,
            "",
            ",".join(_POSITION_ROLES[: len(where)]),
            ",".join(f"{axis}={axis}" for axis in _POSITION_ROLES[: len(where)]),
        )
    ]


def _own_timed_joints(keys) -> tuple[int, ...] | None:
    """A timed joint trajectory bidmp wrote, ``t, <names>, v<names>, a<names>``: the names' columns."""
    if len(keys) < 4 or (len(keys) - 1) % 3 or keys[0] not in TIME_NAMES:
        return None
    n = (len(keys) - 1) // 3
    names = keys[1 : 1 + n]
    if keys[1 + n :] != [f"v{name}" for name in names] + [f"a{name}" for name in names]:
        return None
    return tuple(range(1, 1 + n))


def _joints_candidate(header, keys, time: tuple[int, ...]) -> list[_Candidate]:
    """``t, <joint names>``: every column but the time is a joint (none may be a reserved name)."""
    if not time:
        return []
    own = _own_timed_joints(keys)
    if own is not None:
        return [_Candidate("joints", own, None, "rad", "t,<joint names>", "joints=<names>")]
    reserved = {*_POSITION_ROLES, *_QUATERNION_ROLES, *TIME_NAMES}
    rest = [index for index in range(len(keys)) if index not in time]
    if not rest or any(keys[index] in reserved for index in rest):
        return []
    return [_Candidate("joints", tuple(rest), None, "rad", "t,<joint names>", "joints=<names>")]


# what save_trajectory / save_poses add beside positions
_OWN_RATES = re.compile(r"^(v|a|w|dw)(x|y|z|x[0-9]+)$")


def _layout(
    header, keys, clock: tuple, chosen: _Candidate, settings: dict, conventions: tuple
) -> Layout:
    """The :class:`Layout` of ``header`` (its ``keys``) with the motion ``chosen``; ``clock`` = (the
    time column's index tuple, the divisor to seconds, whether the file declared it), and
    ``conventions`` = (length units, angle units)."""
    time, scale, declared = clock
    units, angles = conventions
    used = set(chosen.values) | set(time) | set(chosen.orientation)
    ignored = tuple(
        name
        for index, (name, key) in enumerate(zip(header, keys))
        if index not in used
        and not _OWN_RATES.match(key)
        and not (
            chosen.kind == "joints"
            and key[:1] in "va"
            and key[1:] in {keys[i] for i in chosen.values}
        )
    )
    return Layout(
        chosen.kind,
        time,
        scale,
        chosen.values,
        chosen.rotation,
        chosen.orientation,
        tuple(header[index] for index in chosen.values),
        units,
        chosen.label,
        ignored,
        settings.get("euler", ""),
        angles,
        chosen.names_from,
        declared,
    )


def resolve(header: tuple[str, ...], mapping: dict | None, path) -> Layout:
    """The layout of a CSV header, by the names or by a column mapping (module docstring), with
    the conventions the mapping declares (``time=ms``, ``euler=xyz``, ``angles=deg``) or the names
    give (``Time(ms)``, ``X(mm)``, ``RX(deg)``).

    Raises
    ------
    ValueError
        A header that names no motion, or more than one (the candidates listed), a mapping that
        names a column the header does not have, or columns whose names say they cannot be what
        they would be read as (a rotation vector in degrees, roll/pitch/yaw without their
        sequence).
    """
    header = tuple(header)
    keys = [_key(name) for name in header]
    roles = {key: value for key, value in (mapping or {}).items() if key not in SETTINGS}
    settings = {key: value for key, value in (mapping or {}).items() if key in SETTINGS}
    if "t" in roles:
        time = (_index(header, keys, roles["t"], "t", path),)
        scale = _time_divisor(header[time[0]], keys[time[0]])
    else:
        time, scale = _time_from_names(header, keys, path)
    scale, declared = _declared_time(header, time, scale, settings, path)
    if set(roles) - {"t"}:
        chosen = _mapped(header, keys, roles, path)
    else:
        chosen = _by_names(header, keys, time, path)
    _refuse_repeated(header, keys, (*time, *chosen.values, *chosen.orientation), path)
    units, angles = _units_named(header, chosen, settings, path)
    return _layout(header, keys, (time, scale, declared), chosen, settings, (units, angles))


def _refuse_repeated(header, keys, used, path) -> None:
    """A column read whose name the header gives twice (``t,j1,j2,j1``; ``x`` and ``X(mm)``):
    which of them holds the value is unknown, so the file is refused, naming it."""
    for index in used:
        twins = [other for other, key in enumerate(keys) if key == keys[index]]
        if len(twins) > 1:
            raise ValueError(
                f"{path}: the header names {short_token(header[index], 30)} {len(twins)} times "
                f"(columns {', '.join(str(other + 1) for other in twins[:4])}): which one it is "
                f"is unknown; give each column its own name"
            )


def _by_names(header, keys, time, path) -> _Candidate:
    """The one motion the header's names give (refused: none, several, or a rotation whose
    convention the names leave open)."""
    _refuse_undeclared_euler(header, keys, path)
    candidates = (
        _plain_candidate(keys)
        + _ros_candidates(header, keys)
        + _rtde_candidates(header, keys)
        + _joint_state_candidates(header, keys)
    )
    if not candidates:
        candidates = _joints_candidate(header, keys, time)
    if len(candidates) > 1:
        listed = "; ".join(
            f"{c.label} ({'joints' if c.kind == 'joints' else c.kind}: columns {c.pick})"
            for c in candidates
        )
        raise ValueError(
            f"{path}: the columns hold {len(candidates)} motions, so which to learn is yours to say: {listed}. "
            f"Pick one with --columns / columns=, e.g. --columns {candidates[0].pick}"
        )
    if not candidates:
        raise ValueError(
            f"{path}: header {_shown(header)} names no motion; expected x,y[,z] (with qx,qy,qz,qw or "
            f"rx,ry,rz for poses) and a time column t/time/timestamp/stamp, a robot logger's columns (UR "
            f"RTDE actual_TCP_pose_0..5 or actual_q_0..5, ROS pose.position.x ...), t,<joint names> for "
            f"joint space, or name them with a column mapping (--columns t=stamp,x=ee_x,y=ee_y,z=ee_z)"
        )
    return candidates[0]


def _joint_state_candidates(header, keys) -> list[_Candidate]:
    """A ``rostopic echo -p`` JointState export: ``name0..n`` (text: the joints' names, read
    from the rows) beside ``position0..n`` (radians)."""
    names = dict(
        (int(m.group(1)), index)
        for index, key in enumerate(keys)
        if (m := re.match(r"^name([0-9]+)$", key))
    )
    positions = dict(
        (int(m.group(1)), index)
        for index, key in enumerate(keys)
        if (m := re.match(r"^position([0-9]+)$", key))
    )
    count = len(positions)
    if not count or sorted(positions) != list(range(count)) or sorted(names) != list(range(count)):
        return []
    return [
        _Candidate(
            "joints",
            tuple(positions[n] for n in range(count)),
            None,
            "rad",
            f"JointState position0..{count - 1} (names from name0..{count - 1})",
            "joints=position",
            names_from=tuple(names[n] for n in range(count)),
        )
    ]


def _index(header, keys, name: str, role: str, path) -> int:
    if name not in keys:
        raise ValueError(
            f"{path}: no column {short_token(name, 30)} for {role} (the header has {_shown(header, 10)})"
        )
    return keys.index(name)


def _mapped(header, keys, mapping: dict, path) -> _Candidate:
    """The motion a mapping names: single columns or a group by prefix."""
    if "pose" in mapping or "position" in mapping:
        wanted = mapping.get("pose", mapping.get("position"))
        for candidate in _ros_candidates(header, keys) + _rtde_candidates(header, keys):
            if candidate.kind != "joints" and _key(
                candidate.pick.split("=", 1)[1]
            ) == wanted.rstrip("."):
                if "position" in mapping:
                    return _Candidate(
                        "positions",
                        candidate.values[:3],
                        candidate.rotation,
                        candidate.units,
                        candidate.label.split(" + ")[0].replace("_0..5", "_0..2"),
                        f"position={wanted}",
                        candidate.values[3:],
                    )
                if candidate.kind == "pose":
                    return candidate
        role = "pose" if "pose" in mapping else "position"
        raise ValueError(
            f"{path}: no {role} group {short_token(wanted, 30)} (x, y, z{' and a rotation' if role == 'pose' else ''} "
            f"under that prefix) in the header {_shown(header, 10)}"
        )
    if "joints" in mapping:
        wanted = mapping["joints"]
        if "|" in wanted:  # the joints by name, in this order
            names = [name for name in wanted.split("|") if name]
            where = tuple(_index(header, keys, name, "joints", path) for name in names)
            if len(set(where)) != len(where):
                raise ValueError("columns: joints names a column twice")
            return _Candidate(
                "joints", where, None, "rad", "|".join(header[i] for i in where), f"joints={wanted}"
            )
        members = sorted(
            (int(m.group(2)), index)
            for index, key in enumerate(keys)
            if (m := _INDEXED.match(key)) and m.group(1).rstrip("._") == wanted
        )
        if not members:
            raise ValueError(
                f"{path}: no joint columns {short_token(wanted, 30)}_0, _1, ... in the header {_shown(header, 10)}"
            )
        state = _joint_state_candidates(header, keys)
        if state and wanted == "position" and state[0].values == tuple(i for _, i in members):
            return state[0]  # a JointState's positions: their names from its name columns
        return _Candidate(
            "joints",
            tuple(index for _, index in members),
            None,
            "rad",
            f"{wanted}_0..{len(members) - 1}",
            f"joints={wanted}",
        )
    where = tuple(
        _index(header, keys, mapping[role], role, path)
        for role in _POSITION_ROLES
        if role in mapping
    )
    present = [role for role in _POSITION_ROLES if role in mapping]
    if present != list(_POSITION_ROLES[: len(present)]) or len(present) < 2:
        raise ValueError("columns: positions need x and y (and z), e.g. x=ee_x,y=ee_y,z=ee_z")
    for roles, rotation in (
        (_QUATERNION_ROLES, "quaternion"),
        (_ROTVEC_ROLES, "rotvec"),
        (_EULER_ROLES, "euler"),
    ):
        if roles[0] in mapping:
            if len(where) != 3:
                raise ValueError("columns: a pose needs x, y and z")
            turn = tuple(_index(header, keys, mapping[role], role, path) for role in roles)
            return _Candidate("pose", (*where, *turn), rotation, "", "mapped pose", "")
    return _Candidate("positions", where, None, "", "mapped positions", "")
