"""Strict JSON for files bidmp reads: a size and depth cap, no NaN or Infinity, a clear error
naming the source."""

from __future__ import annotations

import json
import re

import numpy as np

from .._checks import get_limits, short_token

__all__ = ["load_json", "json_number"]

_JSON_STRING = re.compile(rb'"(?:[^"\\]|\\.)*"')


def _json_depth(data: bytes) -> int:
    """Maximum nesting depth of ``[``/``{`` in a JSON text, strings excluded (no parsing)."""
    codes = np.frombuffer(_JSON_STRING.sub(b'""', data), dtype=np.uint8)
    steps = (np.isin(codes, (ord("["), ord("{")))).astype(np.int64) - np.isin(
        codes, (ord("]"), ord("}"))
    )
    return int(np.max(np.cumsum(steps), initial=0))


def _finite_float(text: str) -> float:
    value = float(text)
    if not np.isfinite(value):
        raise ValueError(f"number {short_token(text)} is out of the float64 range")
    return value


def _no_constant(name: str):
    raise ValueError(f"{name} is not allowed (JSON numbers must be finite)")


def load_json(data: bytes | str, source: str):
    """Parse JSON text from an untrusted file with bounded size and depth, finite numbers only.

    Raises
    ------
    ValueError
        Naming ``source`` and what was wrong (too large, too deep, not UTF-8, not JSON).
    """
    if not isinstance(source, str):
        raise TypeError(
            f"source must be a string naming where the JSON came from, got {type(source).__name__}"
        )
    source = short_token(source, 60)[1:-1]
    if isinstance(data, str):
        data = data.encode("utf-8", "surrogatepass")
    if not isinstance(data, (bytes, bytearray)):
        raise TypeError(
            f"{source}: data must be JSON text (str or bytes), got {type(data).__name__}"
        )
    limits = get_limits()
    if len(data) > limits.max_json_bytes:
        raise ValueError(
            f"{source}: JSON of {len(data):,} bytes exceeds the limit max_json_bytes = "
            f"{limits.max_json_bytes:,}; raise it with bidmp.set_limits(max_json_bytes=...)"
        )
    depth = _json_depth(data)
    if depth > limits.max_json_depth:
        raise ValueError(
            f"{source}: JSON nested {depth} levels deep exceeds the limit max_json_depth = "
            f"{limits.max_json_depth}; raise it with bidmp.set_limits(max_json_depth=...)"
        )
    try:
        text = data.decode("utf-8-sig")
        return json.loads(text, parse_float=_finite_float, parse_constant=_no_constant)
    except UnicodeDecodeError:
        raise ValueError(f"{source}: not UTF-8 text") from None
    except RecursionError:  # pragma: no cover - the depth cap comes first
        raise ValueError(f"{source}: JSON nested too deeply") from None
    except json.JSONDecodeError as exc:
        raise ValueError(
            f"{source}: not valid JSON (line {exc.lineno}, column {exc.colno}: {exc.msg})"
        ) from None
    except ValueError as exc:  # a non-finite number, an integer of too many digits
        raise ValueError(f"{source}: {exc}") from None


def json_number(value) -> float | None:
    """A length or angle for a JSON report: rounded to 4 decimals; None when absent or not finite
    (strict JSON has no Infinity: the approach error of a motion without a final approach)."""
    if value is None:
        return None
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)):
        raise TypeError(f"value must be a number or None, got {type(value).__name__}")
    try:
        number = float(value)
    except OverflowError:  # an integer past float64's range
        raise ValueError(
            f"value is beyond float64's range ({len(str(abs(value)))} digits)"
        ) from None
    return round(number, 4) if np.isfinite(number) else None
