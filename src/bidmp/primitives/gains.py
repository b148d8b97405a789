"""The transformation system's gains, as one value: what the forcing target, the goal gate and the
integration each read of a DMP's settings (instead of three numbers passed one by one)."""

from __future__ import annotations

from typing import NamedTuple

__all__ = []


class _Gains(NamedTuple):
    """``tau² ÿ = alpha (beta (g - y) - tau ẏ) + K f`` (Eq. 10): the spring-damper's ``alpha`` and
    ``beta`` (critically damped at ``beta = alpha / 4``) and ``K``, the forcing term's scale."""

    alpha: float
    beta: float
    K: float
