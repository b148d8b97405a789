"""Lazy re-exports for the package and its subpackages (PEP 562).

A subpackage's ``__init__`` lists its public names and the module each lives in; nothing is
imported until a name is used, so ``import bidmp.cli`` and ``bidmp --help`` never pay for NumPy.
"""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Callable


def exports(package: str, table: dict[str, str], namespace: dict) -> tuple[Callable, Callable]:
    """``__getattr__`` and ``__dir__`` for ``package`` whose public names live in its modules.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    table : dict
        Public name -> module, relative to ``package`` (``"dmp"``) or ``"module:attribute"`` when
        the attribute's name differs from the public one.
    namespace : dict
        The package's ``globals()``: a resolved name is cached there, so it is looked up once.
    """

    def __getattr__(name: str):
        if name not in table:
            if (
                importlib.util.find_spec(f"{package}.{name}") is not None
            ):  # a submodule: bidmp.io.models
                value = importlib.import_module(f"{package}.{name}")
                namespace[name] = value
                return value
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, _, attribute = table[name].partition(":")
        value = getattr(importlib.import_module(f"{package}.{module}"), attribute or name)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(set(namespace.get("__all__", ())) | set(table))

    return __getattr__, __dir__
