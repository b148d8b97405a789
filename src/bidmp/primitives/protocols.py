"""What a fitted DMP keeps of its parameters: the ones its weights were learned with (changing one
after ``fit`` makes the model unfitted, naming it), the protocol's rest after the demonstration,
and the resolved parameters as read-only properties. The two protocols and what the unset
parameters resolve to are :mod:`bidmp.primitives.settings`'s.
"""

from __future__ import annotations

import operator

import numpy as np

from .._checks import NotFittedError, check_fitted
from .settings import DMPSettings

__all__ = []


def _with_rest(y: np.ndarray, params: DMPSettings) -> np.ndarray:
    """``y`` followed by rest at its last point for the protocol's settle time (robot: 0.1 T)."""
    n_rest = int(round(params.settle * y.shape[0])) - y.shape[0]
    if n_rest <= 0:
        return y
    out = np.empty((y.shape[0] + n_rest, y.shape[1]))
    out[: y.shape[0]] = y
    out[y.shape[0] :] = y[-1]
    return out


class _FittedParams:
    """Mixin of an estimator whose learned state depends on its parameters (all but ``tau``):
    a parameter changed after ``fit`` makes it unfitted (:class:`bidmp.NotFittedError` names it)."""

    _fitted_attribute = "weights_"

    @classmethod
    def _raw_param_names(cls) -> tuple[str, ...]:
        """The constructor's parameters but tau, as given (compared first: cheap); read from the
        signature once per class (every rollout checks them)."""
        names = cls.__dict__.get("_raw_names")
        if names is None:
            names = tuple(name for name in cls._get_param_names() if name != "tau")
            cls._raw_names = names
            # One call reads them all, from the instance's dict: its lookups skip the class's
            # MRO (a dozen dicts per name once other work has evicted the type cache).
            cls._raw_getter = operator.itemgetter(*names)
        return names

    def _learned_params(self) -> DMPSettings:
        """The resolved parameters the weights depend on (all but tau, which only scales time)."""
        return self.settings().with_tau(1.0)

    def _raw_params(self) -> tuple:
        getter = type(self).__dict__.get("_raw_getter")
        if getter is None:
            self._raw_param_names()
            getter = type(self)._raw_getter
        try:
            return getter(self.__dict__)
        except KeyError:  # a parameter that is not a plain attribute (a subclass's property)
            return tuple(getattr(self, name) for name in type(self)._raw_names)

    def _remember_params(self, resolved: DMPSettings | None = None) -> None:
        """Keep the parameters the weights were learned with: the raw ones and their resolution
        (``resolved``: :meth:`settings` as ``fit`` resolved them a moment ago)."""
        learned = self._learned_params() if resolved is None else resolved.with_tau(1.0)
        self._learned_with = (self._raw_params(), learned)

    def _stale_params(self) -> list[str]:
        """The learned-with parameters that have changed since ``fit`` (with their values)."""
        learned = self.__dict__.get("_learned_with")
        if learned is None:
            return []
        raw, resolved = learned
        try:
            # the common case, without resolving the protocol's defaults
            if self._raw_params() == raw:
                return []
        except (TypeError, ValueError):  # an array set by mistake: resolving names it
            pass
        now = self._learned_params()
        return [
            f"{name} (fitted with {before!r}, now {after!r})"
            for name, before in resolved.as_dict().items()
            if before != (after := getattr(now, name))
        ]

    def __sklearn_is_fitted__(self) -> bool:
        return self._fitted_attribute in self.__dict__ and not self._stale_params()

    def check_fitted(self) -> None:
        """Raise :class:`bidmp.NotFittedError`, saying what to do, unless the model is fitted
        with the parameters it has now (one changed since ``fit`` is named)."""
        check_fitted(self, self._fitted_attribute)
        stale = self._stale_params()
        if stale:
            raise NotFittedError(
                f"this DMP's {', '.join(stale)} changed after fit: the weights were learned with the old value, "
                f"so the model must be fitted again (only tau may change after fit)"
            )


def _resolved_param(name: str, doc: str) -> property:
    """A read-only property: the resolved value of parameter ``name`` (the protocol's default when
    it is None)."""
    return property(lambda self: getattr(self.settings(), name), doc=doc)
