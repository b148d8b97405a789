"""The methods registry: every way bidmp can learn a task, one small class in one file each.

Evaluation (:func:`bidmp.evaluate`), the LASA benchmark (``bidmp benchmark lasa``) and the
simulator (``bidmp sim``) look methods up here by name, so a new method is one file and one
:func:`register` call::

    from bidmp.tasks.methods import Method, register

    class StraightLine(Method):
        name = "line"
        def fit(self, task):
            return task.demonstration[0], 0.0
        def rollout(self, model, goal):  # model: what fit returned (here the start)
            return model + np.linspace(0, 1, 100)[:, None] * (goal - model)

    register(StraightLine())

Layer 2 (tasks): a method may import the math; the registry imports the built-in methods lazily.
"""

from __future__ import annotations

from ..._checks import short_token as _short_token
from .base import Method, Task, checked_goals

__all__ = ["Method", "Task", "checked_goals", "register", "unregister", "get", "names"]

_REGISTRY: dict[str, Method] = {}
_BUILTINS_LOADED = False
# The built-in methods, in the order names() lists them (whichever module is imported first).
_BUILTIN_ORDER = (
    "dmp",
    "dmp-paper",
    "dmp-robot",
    "dmp-converged",
    "bidmp",
    "bidmp-latest",
    "gmm",
    "tpgmm",
    "mp-dmp",
    "promp",
    "dmp-multi",
    "prodmp",
)


def _load_builtins() -> None:
    """Register the built-in methods (once, on first use: importing them needs NumPy)."""
    global _BUILTINS_LOADED
    if _BUILTINS_LOADED:
        return
    _BUILTINS_LOADED = True
    # Each module lists its methods (METHODS) and never imports the registry: one way only.
    from . import bidmp, dmp, dmp_converged, gmm, mp_dmp, multi, tpgmm

    for module in (dmp, dmp_converged, bidmp, gmm, tpgmm, mp_dmp, multi):
        for method in module.METHODS:
            register(method)
    # and the task methods the model kinds name (bidmp.primitives.registry): a new primitive's
    # method is its module and its kind's entry
    from ...primitives.registry import MODEL_KINDS

    for kind in MODEL_KINDS.values():
        if kind.method is not None:
            register(kind.task_method())


def register(method: Method, *, replace: bool = False) -> Method:
    """Add ``method`` under ``method.name``; a name taken by another method is refused unless
    ``replace``. Returns ``method``."""
    _load_builtins()
    if not isinstance(method, Method):
        raise TypeError(f"method must be a bidmp.tasks.methods.Method, got {type(method).__name__}")
    name = method.name
    if (
        not isinstance(name, str)
        or not name
        or not name.replace("-", "").replace("_", "").isalnum()
    ):
        raise ValueError(
            f"method.name must be a non-empty name of letters, digits, '-' and '_', got {name!r:.40}"
        )
    if name in _REGISTRY and _REGISTRY[name] is not method and not replace:
        raise ValueError(
            f"a method named {name!r} is registered already (pass replace=True to replace it)"
        )
    _REGISTRY[name] = method
    return method


def unregister(name: str) -> None:
    """Remove the method ``name`` (a test's own, say)."""
    _load_builtins()
    _REGISTRY.pop(name, None)


def get(name: str) -> Method:
    """The method registered as ``name``; a ``ValueError`` lists the known ones otherwise."""
    _load_builtins()
    if not isinstance(name, str):
        raise TypeError(f"name must be a method's name (a string), got {type(name).__name__}")
    if name not in _REGISTRY:
        raise ValueError(
            f"name: unknown method {_short_token(name, 40)}; known: {', '.join(names())}"
        )
    return _REGISTRY[name]


def names(
    *, poses: bool | None = None, lasa: bool | None = None, closed_loop: bool | None = None
) -> list[str]:
    """Registered method names, in registration order, optionally those that learn poses, run by
    default in the LASA benchmark, or have a closed-loop stepper."""
    _load_builtins()
    wanted = {"poses": poses, "lasa": lasa, "closed_loop": closed_loop}
    for key, value in wanted.items():
        if value is not None and not isinstance(value, bool):
            raise TypeError(f"names: {key} must be True, False or None, got {type(value).__name__}")
    order = sorted(
        _REGISTRY,
        key=lambda name: (
            _BUILTIN_ORDER.index(name) if name in _BUILTIN_ORDER else len(_BUILTIN_ORDER)
        ),
    )
    return [
        name
        for name in order
        if all(
            value is None or getattr(_REGISTRY[name], key) == value for key, value in wanted.items()
        )
    ]
