"""The command line's adapters of the model kinds learned from several demonstrations, one module
per kind, each named by its kind's entry in :mod:`bidmp.primitives.registry` (``cli``): what
``bidmp fit``'s options mean for it and how ``bidmp rollout`` conditions it. Each module holds
``ADAPTER``, an object with ``fit_takes`` and ``rollout_takes`` (the option names it acts on),
``learn(args, cls, demos, stamps, units)`` and ``roll(args, model, goal, via)``, which returns a
:class:`Rolled`."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class Rolled(NamedTuple):
    """What an adapter's ``roll`` gives ``bidmp rollout``: the motion written, its mean and
    standard deviation (the figure's conditioned band), the model's own mean and band, the points
    it passes (times, points) or None, the figure's times, the demonstrations, the unit, and
    what the motion is (``"the mean motion"``, ``"the mean conditioned on ..."``)."""

    trajectory: object
    mean: object
    std: object
    base: object
    base_std: object
    marks: object
    times: dict
    demonstrations: list
    units: str
    what: str
    title: str = ""  # the figure's, short; what when empty


def shown(point) -> str:
    """A point as the messages print it."""
    return np.array2string(np.asarray(point, dtype=float), precision=4, separator=" ")


def conditioned_on(start, start_given: bool, via, end, end_given: bool) -> str:
    """``"the mean conditioned on ..."``: the start and the end (each at rest; the
    demonstrations' mean where not given) and the via-points at their times, in order."""
    parts = [
        f"the start {shown(start)}{'' if start_given else ' (the mean start)'} at rest",
        *(f"the via-point {shown(point)} at {t:g} s" for t, point in via),
        f"the goal {shown(end)}{'' if end_given else ' (the mean end)'} at rest",
    ]
    return "the mean conditioned on " + ", ".join(parts[:-1]) + " and " + parts[-1]


def conditioned_title(via) -> str:
    """:func:`conditioned_on` short enough for a figure's title."""
    points = f", {len(via)} via-point{'s' if len(via) != 1 else ''}" if via else ""
    return f"the mean conditioned on the start{points} and the goal, at rest at both ends"


def time_grid(duration: float, rate: float | None) -> np.ndarray:
    """The written motion's times (s): every 1 / ``rate`` (default 100 Hz) from 0 to the last
    whole step within ``duration``, where the motion is conditioned to end (so the rate is exact
    and the end is a sample)."""
    dt = 1.0 / (rate or 100.0)
    return np.arange(max(1, int(duration / dt + 1e-9)) + 1) * dt
