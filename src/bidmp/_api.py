"""The estimators' shared parameter handling: :class:`CheckedParams` before scikit-learn's
``BaseEstimator`` (``get_params``/``set_params`` that refuse bad input in one line)."""

from __future__ import annotations

__all__ = ["CheckedParams"]


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
            if (
                name.partition("__")[0] not in known
            ):  # "dmp__alpha": a nested estimator's, checked by it
                raise ValueError(
                    f"set_params: unknown parameter {short_token(name)}; known: {', '.join(known)}"
                )
        return super().set_params(**params)
