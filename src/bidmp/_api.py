"""The estimators' shared conventions (scikit-learn's): :class:`Estimator` and :func:`clone`.

bidmp's estimators follow scikit-learn — parameters stored by the constructor, validation and
learned state (``_``) in ``fit``, ``get_params``/``set_params``, ``sklearn.base.clone`` works —
without importing it: ``sklearn.base`` pulls in SciPy's statistics and sparse matrices, 0.6 s of
a 0.8 s ``import bidmp; bidmp.DMP``. :class:`Estimator` is the part of scikit-learn's
``BaseEstimator`` they use (what ``sklearn.base.clone`` asks of an estimator: ``get_params``
and a constructor that stores them), with ``get_params`` taking only a bool and ``set_params``
refusing an unknown name in one short line (scikit-learn's answers are an array's ambiguous
truth value and a two-line message naming the whole estimator).
"""

from __future__ import annotations

import copy
import inspect

__all__ = ["Estimator", "clone"]


def integer(*, minimum: int | None = None, maximum: int | None = None, limit: str | None = None,
            optional: bool = False):  # fmt: skip
    """A parameter constraint: an integer within the bounds (``limit``: a :class:`bidmp.Limits`
    field), or None when ``optional``."""

    def check(value, name: str) -> None:
        from ._checks import check_int

        if not (optional and value is None):
            check_int(value, name, minimum=minimum, maximum=maximum, limit=limit)

    return check


def real(*, optional: bool = False, **bounds):
    """A parameter constraint: a finite number within ``bounds`` (``check_real``'s ``positive``,
    ``nonnegative``, ``minimum``, ``maximum``), or None when ``optional``."""

    def check(value, name: str) -> None:
        from ._checks import check_real

        if not (optional and value is None):
            check_real(value, name, **bounds)

    return check


class Estimator:
    """Parameters as in scikit-learn: the constructor's keyword arguments, stored as attributes
    of the same names.

    ``_parameter_constraints`` declares, as scikit-learn's estimators do, what each parameter may
    be: name -> a check ``(value, name)`` that raises a ``ValueError``/``TypeError`` naming it
    (:func:`integer`, :func:`real`). :meth:`set_params` runs the checks of the parameters it is
    given before it sets any (a NaN is refused there, not stored to fail a later ``fit`` or a
    model file's JSON), and :meth:`_check_constraints` runs them all (``fit``)."""

    _parameter_constraints: dict = {}

    def _check_constraints(self) -> None:
        """Every declared constraint on the parameters as they are now."""
        for name, check in self._parameter_constraints.items():
            check(getattr(self, name), name)

    @classmethod
    def _get_param_names(cls) -> list[str]:
        """The constructor's parameter names, sorted (as scikit-learn lists them)."""
        names = cls.__dict__.get("_param_names")
        if names is None:
            if cls.__init__ is object.__init__:
                names = []
            else:
                parameters = inspect.signature(cls.__init__).parameters.values()
                names = sorted(
                    p.name for p in parameters if p.name != "self" and p.kind != p.VAR_KEYWORD
                )
            cls._param_names = names
        return list(names)

    def get_params(self, deep: bool = True) -> dict:
        """The parameters by name; with ``deep`` those of nested estimators too, as
        ``name__parameter``."""
        if not isinstance(deep, bool):
            raise TypeError(f"get_params: deep must be True or False, got {type(deep).__name__}")
        out = {}
        for name in self._get_param_names():
            value = getattr(self, name)
            if deep and hasattr(value, "get_params") and not isinstance(value, type):
                out.update((f"{name}__{key}", item) for key, item in value.get_params().items())
            out[name] = value
        return out

    def set_params(self, **params):
        """Set parameters by name (``name__parameter`` for a nested estimator's); an unknown
        name is refused in one short line. Returns self."""
        from ._checks import short_token

        known = self._get_param_names()
        nested: dict[str, dict] = {}
        own: dict = {}
        for key, value in params.items():
            name, nested_key, inner = key.partition("__")
            if name not in known:
                raise ValueError(
                    f"set_params: unknown parameter {short_token(key)}; known: {', '.join(known)}"
                )
            if nested_key:
                nested.setdefault(name, {})[inner] = value
            else:
                check = self._parameter_constraints.get(name)
                if check is not None:
                    check(value, name)  # all checked before any is set
                own[name] = value
        for name, value in own.items():
            setattr(self, name, value)
        for name, inner in nested.items():
            getattr(self, name).set_params(**inner)
        return self

    def __sklearn_tags__(self):
        """scikit-learn's default tags (asked by scikit-learn's own checks such as
        ``check_is_fitted``, so scikit-learn is imported by then)."""
        from sklearn.base import BaseEstimator

        return BaseEstimator.__sklearn_tags__(self)

    def __repr__(self) -> str:
        """``Name(parameter=value, ...)``, the parameters that differ from the defaults."""
        defaults = {
            name: p.default
            for name, p in inspect.signature(type(self).__init__).parameters.items()
            if p.default is not p.empty
        }
        shown = []
        for name in self._get_param_names():
            value = getattr(self, name, None)
            default = defaults.get(name, inspect.Parameter.empty)
            try:
                same = value is default or bool(value == default)
            except (TypeError, ValueError):  # an array compares element by element
                same = False
            if not same:
                shown.append(f"{name}={value!r}")
        return f"{type(self).__name__}({', '.join(shown)})"


def clone(estimator):
    """A new unfitted estimator with the same parameters (``sklearn.base.clone``'s contract for
    bidmp's own estimators: nested estimators cloned, other parameters deep-copied)."""
    params = {
        name: clone(value)
        if isinstance(value, Estimator) and not isinstance(value, type)
        else copy.deepcopy(value)
        for name, value in estimator.get_params(deep=False).items()
    }
    return type(estimator)(**params)
