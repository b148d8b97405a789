"""One API shape across the estimators: ``rollout``/``trajectory``/``stepper(goal=None, *, ...)``,
keyword-only past the goal (``rollout`` in normalised time, ``trajectory`` in seconds).

bidmp <= 0.4 took the start (and, for Bi-DMP, the skill) by position; :func:`goal_first` keeps
such calls working for now, with a ``DeprecationWarning`` that names the arguments to pass by
keyword.
"""

from __future__ import annotations

import functools
import warnings

__all__ = ["goal_first", "deprecated_alias"]


def goal_first(*old_positional: str):
    """Decorator of ``method(self, goal, *, ...)``: arguments given by position after the goal are
    taken as ``old_positional`` (the order of bidmp <= 0.4's signature), with a warning."""

    def decorate(function):
        @functools.wraps(function)
        def wrapper(self, *args, **kwargs):
            if len(args) > 1:
                # The class the user holds, not the mixin that defines the method.
                where = f"{type(self).__name__}.{function.__name__}"
                extra = args[1:]
                if len(extra) > len(old_positional):
                    raise TypeError(f"{where}() takes the goal by position and the rest by keyword; "
                                    f"got {len(args)} positional arguments")
                names = old_positional[: len(extra)]
                for name, value in zip(names, extra):
                    if name in kwargs:
                        raise TypeError(f"{where}() got multiple values for argument {name!r}")
                    kwargs[name] = value
                warnings.warn(f"{where}(): pass {', '.join(names)} by keyword "
                              f"({', '.join(f'{n}=...' for n in names)}); by position is deprecated",
                              DeprecationWarning, stacklevel=2)
                args = args[:1]
            return function(self, *args, **kwargs)

        return wrapper

    return decorate


def deprecated_alias(new_name: str, hint: str = ""):
    """Decorator of an old method kept under its name: a ``DeprecationWarning`` points to
    ``new_name`` (``hint`` says how the call translates)."""

    def decorate(function):
        @functools.wraps(function)
        def wrapper(*args, **kwargs):
            warnings.warn(f"{function.__qualname__}() is deprecated: use {new_name}(){hint}", DeprecationWarning,
                          stacklevel=2)
            return function(*args, **kwargs)

        return wrapper

    return decorate


class CheckedParams:
    """Mixin before scikit-learn's ``BaseEstimator``: ``get_params(deep)`` takes a bool and
    ``set_params`` refuses an unknown name in one short line (scikit-learn's own answers are an
    array's ambiguous truth value and a two-line message naming the whole estimator)."""

    def get_params(self, deep: bool = True) -> dict:
        """scikit-learn's ``get_params``; ``deep`` must be True or False."""
        if not isinstance(deep, bool):
            raise TypeError(f"get_params: deep must be True or False, got {type(deep).__name__}")
        return super().get_params(deep=deep)

    def set_params(self, **params):
        """scikit-learn's ``set_params``; an unknown name is refused in one short line."""
        from ._checks import short_token

        known = self._get_param_names()
        for name in params:
            if name.partition("__")[0] not in known:  # "dmp__alpha": a nested estimator's, checked by it
                raise ValueError(f"set_params: unknown parameter {short_token(name)}; known: {', '.join(known)}")
        return super().set_params(**params)
