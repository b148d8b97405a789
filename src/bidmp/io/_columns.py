"""Which CSV columns are time, positions and quaternions: headers as loggers write them.

A header names its columns. Time is ``t``, ``time`` or ``timestamp`` (seconds); positions are
``x, y[, z]``; quaternions ``qx, qy, qz, qw`` (in any order: the names say which is which). Other
columns (a force, a gripper state, a joint) are ignored, and the reader says which. A *column
mapping* names the file's own columns for the roles, ``{"t": "stamp", "x": "ee_x", …}``, or as
the command line writes it, ``t=stamp,x=ee_x,y=ee_y,z=ee_z``.
"""

from __future__ import annotations

from dataclasses import dataclass

from .._checks import short_token

__all__ = ["TIME_NAMES", "parse_columns", "Selection", "select_positions", "select_poses", "select_joints"]

TIME_NAMES = ("t", "time", "timestamp")
_POSITION_ROLES = ("x", "y", "z")
_QUATERNION_ROLES = ("qx", "qy", "qz", "qw")
_POSE_ROLES = ("x", "y", "z", *_QUATERNION_ROLES)
_MAX_MAPPING = 16


@dataclass(frozen=True)
class Selection:
    """Column indices of a header's roles: ``time`` (or None), ``values`` in role order
    (``x, y[, z]`` or ``x, y, z, qx, qy, qz, qw``) and the names of the ignored columns."""

    time: int | None
    values: tuple[int, ...]
    ignored: tuple[str, ...]


def parse_columns(spec) -> dict[str, str] | None:
    """A column mapping from ``"t=stamp,x=ee_x,…"`` or a dict (roles to the file's names).

    Roles: ``t``, ``x``, ``y``, ``z``, ``qx``, ``qy``, ``qz``, ``qw``. Names are matched without
    regard to case.
    """
    if spec is None:
        return None
    if isinstance(spec, str):
        pairs = [item.split("=", 1) for item in spec.split(",") if item.strip()]
        if not pairs or any(len(pair) != 2 for pair in pairs):
            raise ValueError(f"columns must read role=name[,role=name...], e.g. t=timestamp,x=ee_x; got {short_token(spec, 40)}")
        spec = {role.strip(): name.strip() for role, name in pairs}
    if not isinstance(spec, dict):
        raise TypeError(f"columns must be a dict or a role=name,... string, got {type(spec).__name__}")
    if len(spec) > _MAX_MAPPING:
        raise ValueError(f"columns names {len(spec)} roles; there are at most {len(_POSE_ROLES) + 1}")
    mapping = {}
    for role, name in spec.items():
        if role not in ("t", *_POSE_ROLES):
            raise ValueError(f"columns: unknown role {short_token(role)}; roles are t, x, y, z, qx, qy, qz, qw")
        if not isinstance(name, str) or not name:
            raise ValueError(f"columns: role {role} needs a column name")
        mapping[role] = name.lower()
    if len(set(mapping.values())) != len(mapping):
        raise ValueError("columns: two roles name the same column")
    return mapping


def _index(header: tuple[str, ...], name: str, role: str, path) -> int:
    if name not in header:
        shown = ",".join(short_token(c, 12)[1:-1] for c in header[:10]) + (",…" if len(header) > 10 else "")
        raise ValueError(f"{path}: no column {short_token(name, 20)} for {role} (the header has {shown})")
    return header.index(name)


def _resolve(header: tuple[str, ...], roles: tuple[str, ...], mapping: dict | None, path, required: int) -> Selection:
    if mapping is not None:
        unknown = set(mapping) - {"t", *roles}
        if unknown:
            raise ValueError(f"columns: role {sorted(unknown)[0]} does not belong in this file (roles: t, {', '.join(roles)})")
        time = _index(header, mapping["t"], "t", path) if "t" in mapping else None
        present = [role for role in roles if role in mapping]
        values = tuple(_index(header, mapping[role], role, path) for role in present)
    else:
        times = [name for name in TIME_NAMES if name in header]
        time = header.index(times[0]) if times else None
        present = [role for role in roles if role in header]
        values = tuple(header.index(role) for role in present)
    if tuple(present) != roles[: len(present)] or len(present) < required:
        return Selection(time, (), ())
    used = set(values) | ({time} if time is not None else set())
    return Selection(time, values, tuple(name for index, name in enumerate(header) if index not in used))


def select_positions(header: tuple[str, ...], mapping: dict | None, path) -> Selection:
    """The time and position columns (``x, y`` or ``x, y, z``) of a header; ``values`` is empty
    when the header names no positions."""
    return _resolve(header, _POSITION_ROLES, mapping, path, required=2)


def select_poses(header: tuple[str, ...], mapping: dict | None, path) -> Selection:
    """The time, position and quaternion columns of a pose header (``values`` in the order
    x, y, z, qx, qy, qz, qw); ``values`` is empty when the header names no pose."""
    return _resolve(header, _POSE_ROLES, mapping, path, required=7)


def select_joints(header: tuple[str, ...]) -> Selection:
    """A joint-space recording ``t, <joint names>``: the time column and every other column, in
    the header's order; ``values`` is empty unless the header has a time column and names no
    position or quaternion (a joint-space model has one dimension per joint)."""
    times = [name for name in TIME_NAMES if name in header]
    reserved = {*_POSE_ROLES, *TIME_NAMES}
    if not times or any(name in reserved for name in header if name not in times) or len(header) < 2:
        return Selection(None, (), ())
    time = header.index(times[0])
    return Selection(time, tuple(index for index, name in enumerate(header) if index != time and name not in TIME_NAMES), ())
