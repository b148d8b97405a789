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
        except KeyError:
            raise KeyError(f"missing member {self._prefix + name}") from None

    def __iter__(self):
        return (name[len(self._prefix) :] for name in self._arrays if name.startswith(self._prefix))

    def __len__(self) -> int:
        return sum(1 for _ in self)
