"""Random obstacle fields between a motion's start and goal: what avoidance is tested and
benchmarked on (tests/primitives/test_avoidance.py, benchmarks/bench_avoidance.py), and what a user can
try their own coupling terms on.

A field is 1-4 parts, each a tall post (cylinder) or a tall box standing across the straight line
from start to goal at a random place along it and a random offset across it. A free path is
guaranteed by construction: every part spans the tool's whole height range (nothing to pass over
or under), the parts' footprints are kept apart by more than the tool's width plus twice the margin
(the tool fits between any two, so the free plane around them is connected), and none comes
within reach of the start or the goal.
"""

from __future__ import annotations

import numpy as np

from .._checks import as_point, check_int, check_real, short_token
from .clearance import Scene

__all__ = ["random_field"]


def random_field(
    rng: np.random.Generator,
    start,
    goal,
    tool: dict,
    margin: float,
    n_parts: tuple[int, int] = (1, 4),
    attempts: int = 200,
) -> Scene:
    """A random field of posts and boxes across the line from ``start`` to ``goal`` (module docstring).

    Parameters
    ----------
    rng : numpy.random.Generator
    start, goal : array (3,)
        The motion's ends (scene units); the parts stand across the line between them.
    tool : dict
        ``{"radius": ..., "length": ...}`` (scene units).
    margin : float
        The clearance to keep (scene units).
    n_parts : (int, int)
        Fewest and most parts.
    attempts : int
        Placements tried per part before the field is returned with fewer.

    Returns
    -------
    Scene
        With ``margin``; its parts labelled ``o0``, ``o1``, ...
    """
    if not isinstance(rng, np.random.Generator):
        raise TypeError(f"rng must be a numpy.random.Generator, got {type(rng).__name__}")
    start, goal = as_point(start, 3, "start"), as_point(goal, 3, "goal")
    margin = check_real(margin, "margin", nonnegative=True)
    if not isinstance(n_parts, (tuple, list)) or len(n_parts) != 2:
        raise TypeError(
            f"n_parts must be (fewest, most), two integers, got {short_token(n_parts, 30)}"
        )
    low, high = (check_int(n, "n_parts", minimum=1, maximum=16) for n in n_parts)
    if low > high:
        raise ValueError(f"n_parts: the fewest ({low}) is more than the most ({high})")
    attempts = check_int(attempts, "attempts", minimum=1, maximum=100_000)
    if not isinstance(tool, dict) or set(tool) != {"radius", "length"}:
        raise TypeError(
            f"tool must be {{'radius': r, 'length': l}} (scene units), got {short_token(tool, 30)}"
        )
    tool = {key: check_real(value, f"tool's {key}", positive=True) for key, value in tool.items()}
    chord = goal - start
    reach = float(np.linalg.norm(chord[:2]))
    if reach <= 0.0:
        raise ValueError("start and goal must differ in x or y: the parts stand between them")
    along, across = chord[:2] / reach, np.array([-chord[1], chord[0]]) / reach
    width = 2.0 * (float(tool["radius"]) + margin)  # what the tool needs to pass between two parts
    keep = width + 0.02 * reach  # no part this close to the start or the goal (plus its own size)
    parts, footprints = [], []
    bottom, top = (
        min(start[2], goal[2]) - 0.5 * reach,
        max(start[2], goal[2]) + 0.5 * reach + float(tool["length"]),
    )
    for index in range(int(rng.integers(low, high + 1))):
        for _ in range(attempts):
            size = float(rng.uniform(0.03, 0.10)) * reach  # the part's half-width
            centre = (
                start[:2]
                + float(rng.uniform(0.25, 0.75)) * reach * along
                + float(rng.uniform(-1.5, 1.5)) * size * across
            )
            ends_ok = min(
                np.linalg.norm(centre - start[:2]), np.linalg.norm(centre - goal[:2])
            ) > keep + size * np.sqrt(2.0)
            apart = all(
                np.linalg.norm(centre - other) > size * np.sqrt(2.0) + reach_ * np.sqrt(2.0) + width
                for other, reach_ in footprints
            )
            if ends_ok and apart:
                break
        else:
            continue
        footprints.append((centre, size))
        at = [float(centre[0]), float(centre[1]), float(bottom)]
        if rng.random() < 0.5:
            parts.append(
                {
                    "type": "cylinder",
                    "label": f"o{index}",
                    "at": at,
                    "radius": size,
                    "height": float(top - bottom),
                }
            )
        else:
            yaw = float(rng.uniform(0.0, 180.0))
            sides = [2.0 * size, 2.0 * size * float(rng.uniform(0.4, 1.0)), float(top - bottom)]
            parts.append({"type": "box", "label": f"o{index}", "at": at, "size": sides, "yaw": yaw})
    if not parts:  # the margin or the tool leaves no room between the start and the goal
        raise ValueError(
            f"margin and tool: no part fits between start and goal {reach:.3g} apart with a margin of "
            f"{margin:g} and a tool of radius {tool['radius']:g}"
        )
    return Scene.from_dict(
        {
            "tool": {"radius": float(tool["radius"]), "length": float(tool["length"])},
            "parts": parts,
            "margin": margin,
        }
    )
