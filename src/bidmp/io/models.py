"""Model files: an ``.npz`` archive (a zip of ``.npy`` members, stored or deflated) holding the
model's arrays under their attribute names plus ``__bidmp__``, a uint8 array with UTF-8 JSON::

    {"format": "bidmp-model", "format_version": 4, "class": "DMP",
     "bidmp_version": "0.6.0", "state": {...class-specific, e.g. constructor params...}}

It is read member by member with ``allow_pickle=False``, so loading a file can never execute
code, and a member the model does not ask for is never read; every array is checked for dtype,
shape and finiteness by the model class. Files of every earlier format load."""

from __future__ import annotations

import json
import logging
import os
import zipfile
from pathlib import Path

import numpy as np

from .._checks import check_path, short_token
from ..primitives.registry import MODEL_KINDS as _KINDS
from ..primitives.registry import kind_of as _kind_of
from ._npy import NpzMembers, read_npz
from .atomic import _destination, atomic_write
from .strict_json import load_json

__all__ = ["ModelFileError", "FORMAT_VERSION", "save_model", "load_model"]

logger = logging.getLogger(__name__)


FORMAT_VERSION = 5
# Format 5 (bidmp 0.5): a Bi-DMP stores each skill's time scale (skill_time_scales_: an extension
# lasts as long as it needs); files without it load with 1 for every skill, as they were learned.
# Format 4 (bidmp 0.4): a DMP stores its integrator ("exact" for the robot protocol); files without
# one load with explicit Euler, so a format-3 robot model rolls out as it did. Format 3 (bidmp
# 0.3): a DMP keeps its protocol, duration_ (s) and units_. Format 2 (bidmp 0.2):
# Bi-DMP increments are gated by the phase and the DMP's regression is stored as "regression".
# Format-1 and -2 DMP and BLS files still load (as protocol "paper", 1 s, no units); format-1
# Bi-DMP files do not, because their blocks were trained on the ungated increment.
_MIN_VERSION = {"BiDMP": 2}
_FORMAT_NAME = "bidmp-model"
_META_KEY = "__bidmp__"
_META_MAX_BYTES = 16 << 20
# The classes a file may name: the model kinds of bidmp.primitives.registry, each imported when
# a file names it, so that reading a DMP does not import the whole pipeline.


class ModelFileError(ValueError):
    """A model file is missing, corrupt, truncated, foreign, or from a newer bidmp."""


def _model_class(name: str):
    return _KINDS[name].load()


def _model_path(path: str | os.PathLike) -> Path:
    """The model file to write: ``path`` with ``.npz`` added when missing. The given path is
    checked first, so ``-o somefolder`` or ``-o /dev/null`` are refused, not turned into
    ``somefolder.npz``."""
    path = check_path(path)
    _destination(path)
    if path.suffix != ".npz":
        path = path.with_name(path.name + ".npz")
    return path


def save_model(model, path: str | os.PathLike) -> Path:
    """Save a fitted model to ``path`` (``.npz``; the suffix is added if missing).

    Returns
    -------
    path : Path
        The path written.
    """
    from .. import __version__

    class_name = type(model).__name__
    try:
        _kind_of(model)
    except ValueError:
        known = False
    else:
        known = hasattr(model, "to_state")
    if not known:
        raise TypeError(f"model must be one of {', '.join(sorted(_KINDS))}, got {class_name}")
    if not isinstance(path, (str, os.PathLike)):
        raise TypeError(f"path must be a file name, got {type(path).__name__}")
    path = _model_path(path)
    state, arrays = model.to_state()
    if _META_KEY in arrays:
        raise ValueError(f"array name {_META_KEY!r} is reserved")
    meta = {
        "format": _FORMAT_NAME,
        "format_version": FORMAT_VERSION,
        "class": class_name,
        "bidmp_version": __version__,
        "state": state,
    }
    payload = {name: np.asarray(value) for name, value in arrays.items()}
    payload[_META_KEY] = np.frombuffer(
        json.dumps(meta, allow_nan=False).encode("utf-8"), dtype=np.uint8
    )
    with atomic_write(path, "wb") as handle:
        np.savez(handle, **payload)
    logger.debug("saved %s to %s", class_name, path)
    return path


def _read_meta(members: NpzMembers, path: Path) -> dict:
    if _META_KEY not in members.names:
        raise ModelFileError(
            f"{path} is not a bidmp model file (an .npz archive without bidmp metadata)"
        )

    def check(shape, dtype):
        if dtype != np.uint8 or len(shape) != 1 or shape[0] > _META_MAX_BYTES:
            raise ValueError(
                f"{path} is not a bidmp model file (its metadata member is not UTF-8 JSON bytes)"
            )

    try:
        raw = members.read(_META_KEY, check)
        meta = load_json(raw.tobytes(), f"{path} metadata")
    except ValueError as exc:
        raise ModelFileError(f"{path} is not a readable bidmp model file ({exc})") from None
    if not isinstance(meta, dict) or meta.get("format") != _FORMAT_NAME:
        raise ModelFileError(f"{path} is not a bidmp model file (unknown metadata format)")
    return meta


def load_model(path: str | os.PathLike):
    """Load a model written by :func:`save_model`.

    Only the members the model needs are read, each after its header passed the size limits, and
    the model class validates every array (dtype, shape, finite) before it is used.

    Raises
    ------
    ModelFileError
        If the file is missing, not an ``.npz`` archive, truncated or corrupt, has no bidmp
        metadata (a foreign file), was written by a newer format version, or its contents are
        inconsistent (the message names the member).
    """
    path = check_path(path)
    with read_npz(path, "bidmp model file", ModelFileError) as members:
        meta = _read_meta(members, path)
        class_name = _model_class_name(meta, path)
        state = meta.get("state")
        if not isinstance(state, dict):
            raise ModelFileError(f"{path} is corrupt: its metadata has no state object")
        try:
            return _model_class(class_name).from_state(state, members)
        except MemoryError:
            raise ModelFileError(f"{path}: a member is too large to load") from None
        except KeyError as exc:
            detail = (
                exc.args[0]
                if exc.args and str(exc.args[0]).startswith("missing member")
                else f"missing key {exc}"
            )
            raise ModelFileError(
                f"{path} is corrupt: {class_name} state is inconsistent ({detail})"
            ) from None
        except (
            TypeError,
            ValueError,
            AttributeError,
            IndexError,
            RecursionError,
            OverflowError,
            zipfile.BadZipFile,
            EOFError,
            OSError,
        ) as exc:
            raise ModelFileError(
                f"{path} is corrupt: {class_name} state is inconsistent ({exc})"
            ) from None


def _model_class_name(meta: dict, path: Path) -> str:
    """The model class the metadata names, once its format version is one this bidmp reads."""
    version = meta.get("format_version")
    if not isinstance(version, int) or isinstance(version, bool) or version < 1:
        raise ModelFileError(f"{path} has an invalid format_version {short_token(version)}")
    if version > FORMAT_VERSION:
        raise ModelFileError(
            f"{path} was written in model format {version} by bidmp {short_token(meta.get('bidmp_version', '?'), 20)}; "
            f"this bidmp reads format {FORMAT_VERSION} or older: upgrade bidmp"
        )
    class_name = meta.get("class")
    if not isinstance(class_name, str) or class_name not in _KINDS:
        raise ModelFileError(f"{path} holds an unknown model class {short_token(class_name, 20)}")
    if version < _MIN_VERSION.get(class_name, 1):
        raise ModelFileError(
            f"{path} holds a {class_name} in model format {version} (bidmp "
            f"{short_token(meta.get('bidmp_version', '?'), 20)}), "
            f"whose learned increments did not vanish with the phase; this bidmp cannot use it: learn the skills again"
        )
    return class_name
