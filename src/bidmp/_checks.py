"""Input validation and resource bounds shared by every public entry point.

Every check raises ``TypeError`` (wrong kind of object) or ``ValueError`` (right kind, bad value)
with a message that names the argument and says what was wrong, so that the CLI can show it as a
one-line error.

**Limits.** Sizes and magnitudes that would exhaust memory, run for minutes or overflow float64
are refused up front, before anything is allocated, with a message that names the limit. The
limits are process-wide settings (:class:`Limits`): read them with :func:`get_limits`, change
them with :func:`set_limits` (which also works as a context manager that restores them).
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import math
from collections.abc import Iterable
from numbers import Integral, Real

import numpy as np

from ._kernels import extent as _extent
from ._norms import row_norms

__all__ = [
    "as_unit_quaternion",
    "check_names",
    "printable",
    "as_rotation",
    "as_labels",
    "check_options",
    "NotFittedError",
    "MissingExtraError",
    "TaskRefusal",
    "require_extra",
    "Limits",
    "get_limits",
    "set_limits",
    "check_limit",
    "check_bytes",
    "as_trajectory",
    "as_point",
    "as_points",
    "check_int",
    "check_real",
    "check_choice",
    "check_fitted",
    "check_seed",
    "check_loaded",
    "numerically_guarded",
    "short_token",
]


@dataclasses.dataclass
class Limits:
    """Resource and magnitude bounds every entry point enforces (change with :func:`set_limits`).

    Attributes
    ----------
    max_samples : int
        Samples in one trajectory or training set (T, or the rows of a BLS input).
    max_dims : int
        Dimensions D of a trajectory.
    max_steps : int
        Samples of one rollout (``n_steps``).
    max_kernels : int
        DMP kernels ``n_kernels``.
    max_hidden_nodes : int
        Hidden nodes of one Broad Learning System (mapped + enhancement, all blocks).
    max_array_bytes : int
        Bytes of any one array the library allocates or reads from a file (default 1 GiB).
    max_work : float
        Multiply-adds of one dense step: a BLS solve (samples × hidden²), a curvature smoothing
        (samples × window) or a roadmap run (samples × neighbours × iterations); about a second
        per 1e9 on one core.
    max_frechet_cells : int
        Cells n × m of one discrete Fréchet table (about 1 s per 1e8), and n_compare² × n_iter
        of one roadmap run.
    max_roadmap_nodes : int
        Nodes one G-PRM / classic PRM run draws (n_samples × n_iter; about 5 s per 1e6).
    max_abs_value : float
        Largest coordinate magnitude (any unit): beyond it squares and spring forces overflow.
    min_extent : float
        Smallest motion of a demonstration: the largest distance of a coordinate from its start
        (below it the motion is rounding noise).
    max_targets : int
        Targets of one scenario.
    max_file_bytes : int
        Size of a trajectory, scenario or model file read.
    max_json_bytes : int
        Size of a JSON document (model metadata, scenario) before parsing.
    max_json_depth : int
        Nesting depth of a JSON document.
    """

    max_samples: int = 1_000_000
    max_dims: int = 256
    max_steps: int = 2_000_000
    max_kernels: int = 1_000
    max_hidden_nodes: int = 3_000
    max_array_bytes: int = 1 << 30
    max_work: float = 5e9
    max_frechet_cells: int = 200_000_000
    max_roadmap_nodes: int = 1_000_000
    max_abs_value: float = 1e9
    min_extent: float = 1e-9
    max_targets: int = 1_000
    max_file_bytes: int = 1 << 31
    max_json_bytes: int = 64 << 20
    max_json_depth: int = 64

    def __post_init__(self) -> None:
        for field in dataclasses.fields(self):
            value, default = getattr(self, field.name), field.default
            whole = isinstance(default, int)
            kind = Integral if whole else Real
            if isinstance(value, bool) or not isinstance(value, kind):
                wanted = "an integer" if whole else "a number"
                raise TypeError(f"Limits.{field.name} must be {wanted}, got {type(value).__name__}")
            if not (value > 0 and (whole or math.isfinite(value))):
                raise ValueError(f"Limits.{field.name} must be finite and > 0, got {value}")


_LIMITS = Limits()
_LIMIT_NAMES = tuple(f.name for f in dataclasses.fields(Limits))
# Bumped on every set_limits: what was checked against the old limits is checked again.
_LIMITS_VERSION = [0]


def get_limits() -> Limits:
    """A copy of the limits in force."""
    return dataclasses.replace(_LIMITS)


def _limits_version() -> int:
    """How many times the limits have been set (a cache of checked values keys on it)."""
    return _LIMITS_VERSION[0]


def _limit(name: str):
    """One limit in force, without copying them all (the hot paths' read)."""
    return getattr(_LIMITS, name)


class _Restore(contextlib.AbstractContextManager):
    """What :func:`set_limits` returns: the previous limits; as a context manager it restores them."""

    def __init__(self, previous: Limits) -> None:
        self.previous = previous

    def __exit__(self, *exc) -> None:
        set_limits(**dataclasses.asdict(self.previous))


def set_limits(**changes) -> _Restore:
    """Change limits by name, e.g. ``bidmp.set_limits(max_steps=10_000_000)``.

    Returns an object holding the previous limits (``.previous``); used as a context manager
    (``with bidmp.set_limits(max_samples=5_000_000): ...``) it restores them on exit.
    """
    previous = get_limits()
    for name, value in changes.items():
        if name not in _LIMIT_NAMES:
            raise TypeError(
                f"set_limits: unknown limit {short_token(name)}; known: {', '.join(_LIMIT_NAMES)}"
            )
        current = getattr(_LIMITS, name)
        if isinstance(current, int) and not isinstance(current, bool):
            value = check_int(value, name, minimum=1)
        else:
            value = check_real(value, name, positive=True)
        setattr(_LIMITS, name, value)
        _LIMITS_VERSION[0] += 1
    return _Restore(previous)


def _limit_hint(limit: str) -> str:
    return f"the limit {limit} = {getattr(_LIMITS, limit):,}; raise it with bidmp.set_limits({limit}=...)"


def _count(value) -> str:
    """A number for a message: thousands separated, or its order of magnitude when it has more than
    15 digits (an integer of hundreds of digits is not a message)."""
    if isinstance(value, (int, np.integer)):
        digits = len(str(abs(int(value))))
        return (
            f"{int(value):,}"
            if digits <= 15
            else f"{'-' if value < 0 else ''}about 10^{digits - 1}"
        )
    return f"{float(value):.3g}"


def check_limit(value, limit: str, what: str) -> None:
    """Raise ``ValueError`` if ``value`` exceeds the limit named ``limit`` (a :class:`Limits` field)."""
    if value > getattr(_LIMITS, limit):
        raise ValueError(f"{what} = {_count(value)} exceeds {_limit_hint(limit)}")


def check_bytes(n_elements, what: str, itemsize: int = 8) -> None:
    """Refuse an array of ``n_elements`` (of ``itemsize`` bytes) over ``max_array_bytes``."""
    n_bytes = int(n_elements) * int(itemsize)
    if n_bytes > _LIMITS.max_array_bytes:
        raise ValueError(
            f"{what} would take {n_bytes / 2**30:.3g} GiB, over {_limit_hint('max_array_bytes')}"
        )


def printable(text) -> str:
    """``text`` with every character that is not printable (a terminal escape, a control code) shown
    as '?': what a name read from a file may be shown as, in a message, a terminal or a figure."""
    return "".join(c if c.isprintable() else "?" for c in str(text))


def short_token(value, width: int = 10) -> str:
    """A rejected value quoted for an error message: at most ``width`` characters, printable only
    (a file read by mistake must not be echoed into a terminal or a log)."""
    if (
        isinstance(value, (list, tuple, dict, set))
        and len(value) > 4
        or isinstance(value, np.ndarray)
        and value.size > 8
    ):
        text = f"{type(value).__name__} of {len(value) if not isinstance(value, np.ndarray) else value.shape}"
    else:
        try:  # a container nested thousands deep, or an integer of thousands of digits, has no short text
            text = str(value)
        except (RecursionError, ValueError, TypeError):
            text = f"{type(value).__name__} that cannot be shown"
    text = printable(text[: width + 1])
    return repr(text[:width] + "…") if len(text) > width else repr(text)


class MissingExtraError(ImportError):
    """An optional dependency is not installed; the message says which extra installs it."""


def require_extra(module: str, extra: str, what: str):
    """Import ``module`` from the optional extra ``extra`` or raise :class:`MissingExtraError`
    with the one-line install command."""
    import importlib

    try:
        return importlib.import_module(module)
    except ImportError:
        raise MissingExtraError(
            f"{module}, needed for {what}, is not installed: pip install 'bidmp[{extra}]'"
        ) from None


class TaskRefusal(ValueError):
    """The library declines a motion for a reason of the task, not of the code: a target out of
    the arm's reach, past a joint limit, no collision-free route, a coupled motion held short by
    the parts. A job reports it as that target's failure and goes on; any other exception there
    is a bug and stops the job as an internal error."""


class NotFittedError(ValueError, AttributeError):
    """Raised when a model is used before ``fit`` (same contract as scikit-learn's)."""


def _as_float_array(value, name: str) -> np.ndarray:
    if isinstance(value, (str, bytes)):
        raise TypeError(f"{name} must be an array of numbers, got a string")
    if value is None:
        raise TypeError(f"{name} must be an array of numbers, got None")
    if isinstance(value, np.ndarray) and value.dtype.kind == "c" or isinstance(value, complex):
        # NumPy would drop the imaginary part with a ComplexWarning and go on with the real one.
        raise TypeError(f"{name} must be real numbers, got complex values")
    if _holds_bools(value):
        # NumPy reads True as 1.0: a flag where a point or a value goes is a caller's slip, not a
        # coordinate (check_real and check_int refuse a bool for the same reason)
        raise TypeError(f"{name} must be numbers, got True/False")
    try:
        array = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError, OverflowError):
        # NumPy's own text ("setting an array element with a sequence", …) names no argument.
        shape = (
            "ragged rows"
            if isinstance(value, (list, tuple))
            else f"{type(value).__name__} {short_token(value)}"
        )
        raise TypeError(f"{name} must be an array of numbers, got {shape}") from None
    return array


def _holds_bools(value) -> bool:
    """Whether ``value`` is a bool, a boolean array or a list or tuple with a bool among its
    entries (or its first row's)."""
    if isinstance(value, (bool, np.bool_)):
        return True
    if isinstance(value, np.ndarray):
        return value.dtype.kind == "b"
    if isinstance(value, (list, tuple)) and value:
        first = value[0]
        row = first if isinstance(first, (list, tuple)) else ()
        return any(isinstance(item, (bool, np.bool_)) for item in (*value[:64], *row[:64]))
    return False


def _check_finite(array: np.ndarray, name: str) -> None:
    if not np.all(np.isfinite(array)):
        bad = np.argwhere(~np.isfinite(array))[0]
        kind = "NaN" if np.isnan(array[tuple(bad)]) else "inf"
        where = f"row {bad[0]}" if array.ndim == 2 else f"index {tuple(int(b) for b in bad)}"
        raise ValueError(f"{name} contains {kind} (first at {where})")


def _check_magnitude(array: np.ndarray, name: str) -> None:
    """Refuse coordinates beyond ``max_abs_value`` (finite, but their squares or spring forces overflow)."""
    if array.size and float(np.max(np.abs(array))) > _LIMITS.max_abs_value:
        raise ValueError(
            f"{name} has a coordinate of magnitude {float(np.max(np.abs(array))):.3g}, beyond "
            f"{_limit_hint('max_abs_value')} (or rescale the data to another unit)"
        )


def _as_bounded_array(value, name: str, max_ndim: int) -> np.ndarray:
    """``_as_float_array`` that refuses oversized inputs before converting them."""
    if isinstance(value, np.ndarray):
        if value.ndim > max_ndim:
            raise ValueError(f"{name} must have at most {max_ndim} dimension(s), got {value.ndim}")
        check_bytes(value.size, name)
        if value.dtype.kind == "c":
            raise TypeError(f"{name} must be real numbers, got complex")
        if value.dtype == np.float64:
            return value
    elif isinstance(value, complex) or (
        isinstance(value, (list, tuple)) and any(isinstance(v, complex) for v in value)
    ):
        raise TypeError(f"{name} must be real numbers, got complex")
    array = _as_float_array(value, name)
    return array


def as_trajectory(
    y, name: str = "y", min_points: int = 3, allow_static: bool = False
) -> np.ndarray:
    """Validate a trajectory and return it as a C-contiguous float64 array of shape (T, D).

    Raises
    ------
    TypeError
        If ``y`` is not numeric.
    ValueError
        If ``y`` is not 2-D, has fewer than ``min_points`` samples, contains NaN/inf, or all its
        points are identical (there is no motion to learn; allowed with ``allow_static``).
    """
    array = _as_bounded_array(y, name, 3)
    if array.ndim != 2:
        hint = " (for a 1-D signal use shape (T, 1))" if array.ndim == 1 else ""
        raise ValueError(
            f"{name} must have shape (T, D), got an array with {array.ndim} dimension(s){hint}"
        )
    n_points, n_dims = array.shape
    if n_dims < 1:
        raise ValueError(f"{name} must have at least one column (D >= 1), got shape {array.shape}")
    if n_points < min_points:
        raise ValueError(f"{name} needs at least {min_points} points, got {n_points}")
    check_limit(n_points, "max_samples", f"{name}: the number of samples T")
    check_limit(n_dims, "max_dims", f"{name}: the number of dimensions D")
    if n_points == 0:
        return np.ascontiguousarray(array)
    # One compiled pass for the finiteness, the range and the motion (on every fit: as NumPy
    # reductions they were a dozen calls); the detailed scans run only to word an error.
    finite, low, high, motion = _extent(array)
    if not finite:
        _check_finite(array, name)
    scale = max(-low, high)
    if scale > _LIMITS.max_abs_value:
        _check_magnitude(array, name)
    if not allow_static:
        # The largest distance of any coordinate from the start: 0 for a static demonstration,
        # and within a factor 2·sqrt(D) of the bounding-box diagonal.
        if motion == 0.0:
            raise ValueError(f"{name} is degenerate: all {n_points} points are identical")
        if motion < _LIMITS.min_extent or motion < 1e-12 * scale:
            raise ValueError(
                f"{name} barely moves: no coordinate leaves the start by more than {motion:.3g}, below the "
                f"smallest supported motion (min_extent = {_LIMITS.min_extent:g}, or 1e-12 of its "
                f"coordinates' magnitude {scale:.3g}); rescale the data"
            )
    return np.ascontiguousarray(array)


def as_point(p, n_dims: int, name: str = "point", like: str = "") -> np.ndarray:
    """Validate one point of dimension ``n_dims`` and return it as a float64 array (n_dims,)
    (``like``: the argument whose dimension it must match, for the message; default the model)."""
    array = _as_bounded_array(p, name, 2)
    if array.ndim == 0:
        array = array.reshape(1)
    if array.ndim != 1 or array.shape[0] != n_dims:
        match = f"as {like} has" if like else "to match the model"
        raise ValueError(
            f"{name} must have {n_dims} coordinate(s) {match}, got shape {array.shape}"
        )
    _check_finite(array, name)
    _check_magnitude(array, name)
    return array


def as_points(points, n_dims: int, name: str = "points") -> np.ndarray:
    """Validate a set of points and return them as a float64 array (G, n_dims)."""
    array = _as_bounded_array(points, name, 3)
    if array.ndim == 1 and array.shape[0] == n_dims:
        array = array.reshape(1, n_dims)
    if array.ndim != 2 or array.shape[1] != n_dims:
        raise ValueError(
            f"{name} must have shape (G, {n_dims}) to match the model, got shape {array.shape}"
        )
    if array.shape[0] == 0:
        raise ValueError(f"{name} is empty")
    _check_finite(array, name)
    _check_magnitude(array, name)
    return np.ascontiguousarray(array)


def check_int(
    value,
    name: str,
    minimum: int | None = None,
    limit: str | None = None,
    maximum: int | None = None,
) -> int:
    """Return ``value`` as an ``int`` after checking it is an integer >= ``minimum``, at most
    ``maximum`` and within the :class:`Limits` field ``limit``."""
    # An int is the common case: ``Integral`` is an abstract class, whose check costs a microsecond.
    if type(value) is not int and (isinstance(value, bool) or not isinstance(value, Integral)):
        raise TypeError(
            f"{name} must be an integer, got {type(value).__name__} {short_token(value)}"
        )
    if minimum is not None and value < minimum:
        raise ValueError(f"{name} must be >= {minimum}, got {_count(value)}")
    if maximum is not None and value > maximum:
        raise ValueError(f"{name} must be <= {maximum:,}, got {_count(value)}")
    if limit is not None:
        check_limit(int(value), limit, name)
    return int(value)


def check_real(
    value,
    name: str,
    *,
    positive: bool = False,
    nonnegative: bool = False,
    minimum: float | None = None,
    maximum: float | None = None,
) -> float:
    """Return ``value`` as a finite ``float`` (optionally > 0, >= 0, or within [minimum, maximum])."""
    # A float is the common case: ``Real`` is an abstract class, whose check costs a microsecond.
    if type(value) is not float and (isinstance(value, bool) or not isinstance(value, Real)):
        raise TypeError(f"{name} must be a number, got {type(value).__name__} {short_token(value)}")
    try:
        value = float(value)
    except OverflowError:
        raise ValueError(f"{name} is too large for a float") from None
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value}")
    if positive and value <= 0:
        raise ValueError(f"{name} must be > 0, got {value}")
    if nonnegative and value < 0:
        raise ValueError(f"{name} must be >= 0, got {value}")
    if minimum is not None and value < minimum:
        raise ValueError(f"{name} must be >= {minimum:g}, got {value:g}")
    if maximum is not None and value > maximum:
        raise ValueError(f"{name} must be <= {maximum:g}, got {value:g}")
    return value


def check_seed(seed, name: str = "seed") -> np.random.Generator:
    """A ``numpy.random.Generator`` from ``seed``: a non-negative integer (< 2**128), a
    ``Generator`` (used as is) or a ``SeedSequence``. ``None`` is refused: results must be
    reproducible."""
    if isinstance(seed, np.random.Generator):
        return seed
    if isinstance(seed, np.random.SeedSequence):
        return np.random.default_rng(seed)
    if seed is None:
        raise TypeError(
            f"{name} must be an integer or a numpy.random.Generator (None would make results irreproducible)"
        )
    seed = check_int(seed, name, minimum=0, maximum=2**128 - 1)
    return np.random.default_rng(seed)


def as_unit_quaternion(value, name: str) -> np.ndarray:
    """A unit quaternion ``qx, qy, qz, qw`` (4,), its norm within 1e-6 of 1."""
    quaternion = as_vector(value, name, length=4)
    norm = float(row_norms(quaternion))
    if not abs(norm - 1.0) <= 1e-6:
        raise ValueError(f"{name} must be a unit quaternion qx, qy, qz, qw; its norm is {norm:.6g}")
    return quaternion


def check_names(names, count: int, name: str = "names") -> list[str]:
    """``count`` distinct, non-empty names of at most 256 printable characters (the names of a
    model's dimensions: a joint recording's joint names); ``[]`` for None."""
    if names is None:
        return []
    if isinstance(names, str) or not isinstance(names, (list, tuple)):
        raise TypeError(
            f"{name} must be a list of {count} names (text), got {type(names).__name__}"
        )
    if len(names) != count:
        raise ValueError(
            f"{name} must name the {count} dimension(s), one each; got {len(names)} name(s)"
        )
    for entry in names:
        if (
            not isinstance(entry, str)
            or not entry.strip()
            or len(entry) > 256
            or not entry.isprintable()
        ):
            raise ValueError(
                f"{name}: each name must be printable text of 1-256 characters, got {short_token(entry, 30)}"
            )
    if len(set(names)) != len(names):
        raise ValueError(f"{name}: two dimensions have the same name")
    return [str(entry) for entry in names]


def check_choice(value, name: str, choices: Iterable[str]) -> str:
    """Check that ``value`` is one of ``choices`` (strings)."""
    choices = tuple(choices)
    if not isinstance(value, str) or value not in choices:
        shown = short_token(value) if isinstance(value, str) else type(value).__name__
        raise ValueError(f"{name} must be one of {', '.join(map(repr, choices))}; got {shown}")
    return value


def as_vector(
    values, name: str, *, length: int | None = None, min_length: int = 1, positive: bool = False
) -> np.ndarray:
    """A 1-D array of finite numbers within ``max_abs_value``: ``length`` of them if given, else
    at least ``min_length`` (``positive``: each > 0). A scalar is a vector of one."""
    array = _as_bounded_array(values, name, max_ndim=1).reshape(-1)
    if length is not None and array.shape[0] != length:
        raise ValueError(f"{name} must have {length} entries, got {array.shape[0]}")
    if array.shape[0] < min_length:
        raise ValueError(
            f"{name} is empty"
            if array.shape[0] == 0
            else f"{name} needs at least {min_length} entries"
        )
    _check_finite(array, name)
    _check_magnitude(array, name)
    if positive and np.any(array <= 0.0):
        raise ValueError(f"{name} must be > 0")
    return array


def as_indices(values, name: str, last: int, of: str = "the trajectory") -> np.ndarray:
    """A 1-D array of sample indices in ``[0, last]``: integers (whole-valued floats accepted)."""
    array = _as_bounded_array(values, name, max_ndim=1).reshape(-1)
    _check_finite(array, name)
    if np.any(array != np.round(array)):
        raise ValueError(f"{name} must be whole sample indices")
    if np.any((array < 0) | (array > last)):
        raise ValueError(f"{name} must lie in [0, {last}] (sample indices of {of})")
    return array.astype(np.int64)


def check_bool(value, name: str) -> bool:
    """Return ``value`` if it is a bool (NumPy's included); an array's truth value is ambiguous."""
    if not isinstance(value, (bool, np.bool_)):
        raise TypeError(f"{name} must be True or False, got {type(value).__name__}")
    return bool(value)


def checks_input(check_input) -> bool:
    """Whether a method a control loop calls every step checks its arguments (its
    ``check_input``): ``False`` takes them as given (the hot path: one identity test), ``True``
    checks them, anything else is refused by name (as scikit-learn's trees' ``check_input``)."""
    return check_input is not False and check_bool(check_input, "check_input")


def as_rotation(value, name: str = "rotation") -> np.ndarray:
    """A rotation matrix (3, 3): orthonormal within 1e-6, determinant +1."""
    array = _as_bounded_array(value, name, 2)
    if array.shape != (3, 3):
        raise ValueError(f"{name} must be a 3 x 3 rotation matrix, got shape {array.shape}")
    _check_finite(array, name)
    if not np.allclose(array @ array.T, np.eye(3), atol=1e-6) or np.linalg.det(array) <= 0.0:
        raise ValueError(f"{name} must be a rotation matrix (orthonormal, determinant +1)")
    return np.ascontiguousarray(array)


def as_labels(values, name: str) -> list[str]:
    """Part or target labels: a list, tuple or set of strings (None: none)."""
    if values is None:
        return []
    if isinstance(values, str) or not isinstance(values, (list, tuple, set, frozenset)):
        raise TypeError(
            f"{name} must be a list of labels (strings), got {type(values).__name__} {short_token(values)}"
        )
    if len(values) > _LIMITS.max_targets * 10:
        raise ValueError(
            f"{name} names {len(values):,} labels; at most {_LIMITS.max_targets * 10:,}"
        )
    if not all(isinstance(value, str) and len(value) <= 256 for value in values):
        raise TypeError(
            f"{name} must hold labels (strings of at most 256 characters), got {short_token(list(values), 30)}"
        )
    return list(values)


def check_text(value, name: str, max_length: int = 80) -> str:
    """A name or phrase that a message will show: a string of printable characters, at most
    ``max_length`` long (a caller's wording must not make the message unreadable)."""
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a string, got {type(value).__name__}")
    if len(value) > max_length or not value.isprintable():
        raise ValueError(
            f"{name} must be at most {max_length} printable characters, got {short_token(value, 30)}"
        )
    return value


def check_options(value, name: str) -> dict:
    """An options mapping: a dict with string keys (None: no options)."""
    if value is None:
        return {}
    if not isinstance(value, dict) or not all(isinstance(key, str) for key in value):
        raise TypeError(
            f"{name} must be a dict of options (string keys), got {type(value).__name__} {short_token(value)}"
        )
    return dict(value)


def check_callable(value, name: str, what: str = "a function"):
    """Return ``value`` if it can be called."""
    if not callable(value):
        raise TypeError(f"{name} must be {what}, got {type(value).__name__}")
    return value


_MAX_PATH, _MAX_NAME = 4096, 255  # bytes: Linux's PATH_MAX and NAME_MAX


def check_path(value, name: str = "path"):
    """A file name as a ``pathlib.Path``: a str or PathLike, not empty, no NUL byte, within the
    operating system's lengths (beyond them ``os.stat`` raises, and ``Path.exists`` with it)."""
    import os
    from pathlib import Path

    if not isinstance(value, (str, os.PathLike)):
        raise TypeError(f"{name} must be a file name, got {type(value).__name__}")
    text = os.fsdecode(os.fspath(value))
    if not text:
        raise ValueError(f"{name} is empty")
    if "\x00" in text:
        raise ValueError(f"{name} contains a NUL character")
    encoded = os.fsencode(text)
    if len(encoded) > _MAX_PATH or any(len(part) > _MAX_NAME for part in encoded.split(b"/")):
        raise ValueError(
            f"{name} is too long for a file name ({len(encoded):,} bytes, a part over {_MAX_NAME})"
        )
    return Path(text)


def shown_path(path, width: int = 60) -> str:
    """A path for a message: its last ``width`` characters (the file name is what tells)."""
    text = printable(path)
    return text if len(text) <= width else "…" + text[-(width - 1) :]


def check_loaded(value, name: str, shape: tuple, *, positive: bool = False) -> np.ndarray:
    """Validate an array read from a model file: real numbers, the expected ``shape`` (``None``
    for a free axis), finite (and > 0 with ``positive``). Returns it as float64."""
    array = np.asarray(value)
    if array.dtype.kind not in "fiub":
        raise ValueError(f"member {name} holds {array.dtype} data, expected float64")
    array = array.astype(np.float64, copy=False)
    if array.ndim != len(shape) or any(
        s is not None and a != s for a, s in zip(array.shape, shape)
    ):
        expected = (
            "("
            + ", ".join("any" if s is None else str(s) for s in shape)
            + ("," if len(shape) == 1 else "")
            + ")"
        )
        raise ValueError(f"member {name} has shape {array.shape}, expected {expected}")
    if not np.all(np.isfinite(array)):
        raise ValueError(f"member {name} contains NaN or inf")
    if positive and array.size and not np.all(array > 0):
        raise ValueError(f"member {name} must be > 0 everywhere")
    return np.ascontiguousarray(array)


def numerically_guarded(function):
    """Decorator for the math entry points: floating-point overflow, invalid operations and
    division by zero raise instead of warning, and surface as one ``ValueError``; a singular
    matrix (``LinAlgError``) or an allocation failure (``MemoryError``) likewise. Underflow to 0
    is harmless and ignored. No call returns NaN/inf silently."""

    @functools.wraps(function)
    def wrapper(*args, **kwargs):
        try:
            with np.errstate(over="raise", invalid="raise", divide="raise", under="ignore"):
                return function(*args, **kwargs)
        except FloatingPointError as exc:
            raise ValueError(
                f"{function.__qualname__}: the computation overflowed ({exc}): the inputs' scale or the "
                f"parameters are out of the range float64 can represent"
            ) from None
        except np.linalg.LinAlgError as exc:
            raise ValueError(
                f"{function.__qualname__}: a linear system is singular ({exc}); "
                f"increase the regularisation or check the inputs"
            ) from None
        except MemoryError:
            raise ValueError(
                f"{function.__qualname__}: out of memory; lower the sizes or "
                f"bidmp.set_limits(max_array_bytes=...)"
            ) from None

    return wrapper


def check_fitted(model, attribute: str) -> None:
    """Raise :class:`NotFittedError` if ``model`` lacks the learned ``attribute``."""
    if getattr(model, attribute, None) is None:
        raise NotFittedError(f"this {type(model).__name__} is not fitted yet: call fit() first")


def check_kind(value, kinds, name: str, expected: str):
    """``value`` if it is one of ``kinds`` (a class or a tuple of them); else a TypeError naming
    ``name``, what it must be (``expected``, in words) and what it is."""
    if not isinstance(value, kinds):
        raise TypeError(f"{name} must be {expected}, got {type(value).__name__}")
    return value


def check_members(value, members: tuple, name: str, expected: str):
    """``value`` if it has every attribute in ``members`` (what a function reads of it); else a
    TypeError naming ``name``, what it must be and what it is (for a module that may not import
    the class: a layer below it)."""
    if not all(hasattr(value, member) for member in members):
        raise TypeError(f"{name} must be {expected}, got {type(value).__name__}")
    return value


def check_sequence_of(values, members: tuple, name: str, expected: str, most: int = 64) -> list:
    """``values`` as a list if it is a non-empty list or tuple of at most ``most`` items, each
    with every attribute in ``members`` (what a plot reads of each panel); else a TypeError or
    ValueError naming ``name`` and what each item must be."""
    if not isinstance(values, (list, tuple)):
        raise TypeError(f"{name} must be a list of {expected}, got {type(values).__name__}")
    if not values or len(values) > most:
        raise ValueError(f"{name} must hold 1 to {most} {expected}, got {len(values)}")
    for index, value in enumerate(values):
        check_members(value, members, f"{name}[{index}]", expected)
    return list(values)


# Hz: the slowest rhythm bidmp runs (a period of 11.6 days); slower is a unit mistake, or a denormal
# whose period overflows the sample count (5e-324 Hz divided by zero)
SLOWEST_HZ = 1e-6
