"""Lazy re-exports for the package and its subpackages (PEP 562), written as plain imports.

A package's ``__init__`` imports its public names under ``if TYPE_CHECKING:``: editors and type
checkers read them as the imports they are, and at run time :func:`exports` reads the same block
from the file and imports each name on first use. One list, seen by both; nothing is imported
until a name is used, so ``import bidmp.cli`` and ``bidmp --help`` never pay for NumPy, and a first
``bidmp fit`` imports only what fitting needs.
"""

from __future__ import annotations

import importlib
import importlib.util
from collections.abc import Callable


def typing_imports(package: str, file: str) -> dict[str, tuple[str, str]]:
    """The names the ``if TYPE_CHECKING:`` block of ``package``'s ``__init__`` (``file``)
    imports: public name -> (absolute module, attribute)."""
    import ast  # here, not at import: bidmp --help never reads the block

    with open(file, encoding="utf-8") as source:
        tree = ast.parse(source.read(), filename=file)
    table = {}
    for block in tree.body:
        if not (isinstance(block, ast.If) and ast.unparse(block.test) == "TYPE_CHECKING"):
            continue
        for node in block.body:
            if not isinstance(node, ast.ImportFrom):
                raise ValueError(f"{file}: the TYPE_CHECKING block holds only 'from . import'")
            base = package.split(".")
            if node.level:
                base = base[: len(base) - node.level + 1]
            module = ".".join(base + ([node.module] if node.module else []))
            for alias in node.names:
                table[alias.asname or alias.name] = (module, alias.name)
    return table


def exports(package: str, file: str, namespace: dict, extra=()) -> tuple[Callable, Callable]:
    """``__getattr__`` and ``__dir__`` for ``package``, whose public names are the imports of its
    ``if TYPE_CHECKING:`` block; ``__all__`` (those names and ``extra``) is served by the same
    ``__getattr__``. The block is read on the first name asked for, not at import: ``bidmp --help``
    imports the package and never asks.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    file : str
        The package's ``__file__`` (its ``__init__.py``).
    namespace : dict
        The package's ``globals()``: a resolved name is cached there, so it is looked up once.
    extra : iterable of str
        Names of ``__all__`` that the package defines itself (the root's ``__version__``).
    """
    cache: dict[str, dict] = {}

    def table() -> dict[str, tuple[str, str]]:
        if "table" not in cache:
            cache["table"] = typing_imports(package, file)
        return cache["table"]

    def __getattr__(name: str):
        if name == "__all__":
            value = [*extra, *table()]
            namespace[name] = value
            return value
        if name not in table():
            # a submodule: bidmp.io.models
            if importlib.util.find_spec(f"{package}.{name}") is not None:
                value = importlib.import_module(f"{package}.{name}")
                namespace[name] = value
                return value
            raise AttributeError(f"module {package!r} has no attribute {name!r}")
        module, attribute = table()[name]
        value = getattr(importlib.import_module(module), attribute)
        namespace[name] = value
        return value

    def __dir__() -> list[str]:
        return sorted(__getattr__("__all__"))

    return __getattr__, __dir__
