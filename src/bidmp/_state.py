"""Model-state helpers shared by the estimators' ``to_state``/``from_state`` (bidmp.io stores them)."""

from __future__ import annotations

from collections.abc import Mapping


class Prefixed(Mapping):
    """The members of ``arrays`` whose names start with ``prefix``, without it; lazy, so that
    loading a model reads only the members a part asks for."""

    def __init__(self, arrays: Mapping, prefix: str) -> None:
        self._arrays, self._prefix = arrays, prefix

    def __getitem__(self, name: str):
        try:
            return self._arrays[self._prefix + name]
        except KeyError as exc:
            if exc.args and str(exc.args[0]).startswith("missing member"):
                raise  # named by the mapping under this one, with its whole prefix
            raise KeyError(f"missing member {self._prefix + name}") from None

    def __iter__(self):
        return (name[len(self._prefix) :] for name in self._arrays if name.startswith(self._prefix))

    def __len__(self) -> int:
        return sum(1 for _ in self)


class StateError(ValueError):
    """A model's state that does not describe a fitted model of its kind (raised once, by the
    outermost ``from_state``: a composite's parts' errors pass through as they are)."""


_MESSAGE_CHARS = 200  # of the underlying error, in a one-line message


def state_reader(read):
    """``read(cls, meta, arrays)`` as a model kind's public ``from_state``: ``meta`` must be a dict
    and ``arrays`` a mapping of member names to arrays (what ``to_state`` gives). A state they do
    not describe raises :class:`StateError` (a ``ValueError``) naming them and what was wrong
    (a missing key or member by name), never a ``KeyError`` or ``AttributeError`` from inside;
    ``MemoryError`` and a file's read errors pass (:func:`bidmp.io.load_model` words those)."""
    import functools

    @functools.wraps(read)
    def from_state(cls, meta, arrays):
        if not isinstance(meta, dict):
            raise TypeError(
                f"meta must be a model's state (a dict, to_state's first part), "
                f"got {type(meta).__name__}"
            )
        if not isinstance(arrays, Mapping):
            raise TypeError(
                f"arrays must map member names to arrays (to_state's second part), "
                f"got {type(arrays).__name__}"
            )
        try:
            # a member asked for and not there: "missing member <name>" (not a bare KeyError)
            return read(cls, meta, arrays if isinstance(arrays, Prefixed) else Prefixed(arrays, ""))
        except StateError:
            raise
        except KeyError as exc:
            missing = exc.args[0] if exc.args else ""
            what = missing if str(missing).startswith("missing member") else f"missing key {exc}"
            raise StateError(_described(cls, what[:_MESSAGE_CHARS])) from None
        except (TypeError, ValueError, AttributeError, IndexError, RecursionError) as exc:
            raise StateError(_described(cls, str(exc)[:_MESSAGE_CHARS])) from None

    return from_state


def _described(cls, what: str) -> str:
    return f"meta and arrays do not describe a fitted {cls.__name__}: {' '.join(what.split())}"
