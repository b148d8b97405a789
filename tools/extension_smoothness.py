"""How smooth and how long an extension's transfer is where a part forces a detour.

    .venv/bin/python tools/extension_smoothness.py [--random N]

Printed, for a demonstration that comes to rest at a corner and a target 300 mm sideways:

* a tall post on the straight transfer (radius 5/10/20 mm, margin 0/3 mm): the transfer's log
  dimensionless jerk (LDJ, Hogan & Sternad 2009: -ln(T^5 / v_peak^2 * integral |jerk|^2)) beside
  the free transfer's (the template, timed the same way), its length over the shortest free route
  (closed form: tangent, arc, tangent), the whole extended demonstration's peaks over the
  demonstration's;
* a cable duct across the plate (60/100/130 mm tall): the same, the shortest route not in closed
  form;
* N random demonstrations (mm or m, 150-600 samples) with a post near the transfer's middle: the
  LDJ difference against the post's size relative to the transfer (the tool radius plus the post
  radius plus the margin, over the chord), and the length ratio;
* the floor, floor(h): the least LDJ deficit, against the straight quintic, of any rest-to-rest
  route through the clearance point the post forces (its reach less its distance from the chord,
  at its place along the chord), the time and velocity at that point optimised and the route
  least-jerk between (tests/extension/test_extension_timing.py's ldj_floor, exact piecewise quintics); for
  each random post the transfer's deficit against its template, the floor, and the excess over it
  (the bound: at most 0.3). Beside the floor: the least-jerk route with the point at mid-time
  (Flash & Hogan 1985), which is not the least-LDJ one, and a half-sine bow on the quintic time law.

All derivatives by central differences (``numpy.gradient``) on the extension's own samples.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
from extension_pace import peaks  # the same estimator as the pace script (central differences)

# The measures and closed forms of the tests themselves (tests/extension/test_extension_timing.py): what this
# script prints is what they assert on.
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests" / "extension"))
from test_extension_timing import ldj_floor, shortest_around, transfer  # noqa: E402
from test_extension_timing import log_dimensionless_jerk as ldj  # noqa: E402

from bidmp.demonstrations import minimum_jerk
from bidmp.extension import RoadmapOptions, extend_demonstration
from bidmp.extension.roadmap import NoFreeRouteError
from bidmp.scene import Scene

TOOL = {"radius": 12.5, "length": 100.0}


def length(path: np.ndarray) -> float:
    return float(np.sum(np.linalg.norm(np.diff(path, axis=0), axis=1)))


def row(label, extension, blind, demo, dt, shortest=None) -> str:
    n = len(demo)
    ratio = peaks(extension.complete, dt) / peaks(demo, dt)
    shortest_text = "   -  " if shortest is None else f"{length(extension.tra_gen) / shortest:6.3f}"
    return (
        f"{label:28s} {extension.refinement:9s} {ldj(transfer(extension, n), dt):7.2f} "
        f"{ldj(transfer(blind, n), dt):7.2f}"
        f"   {shortest_text}   {ratio[0]:.2f} {ratio[1]:.2f} {ratio[2]:.2f}"
    )


def fixed_cases() -> None:
    print(
        "case                         transfer  LDJ    template  length/shortest  peaks (speed acc jerk)"
    )
    demo = minimum_jerk([[0, 0, 60], [100, 0, 60], [100, 0, 0]], 300)
    target = np.array([100.0, 300.0, 0.0])
    blind = extend_demonstration(demo, target, seed=0)
    seg, hover = blind.tra_gen[0], blind.tra_gen[-1]
    centre = (seg + hover) / 2
    for margin in (0.0, 3.0):
        for radius in (5.0, 10.0, 20.0):
            post = {
                "type": "cylinder",
                "label": "post",
                "at": [centre[0], centre[1], -200.0],
                "radius": radius,
                "height": 600.0,
            }
            scene = Scene.from_dict({"tool": TOOL, "parts": [post], "margin": margin})
            extension = extend_demonstration(
                demo, target, seed=0, scene=scene, roadmap=RoadmapOptions(sigma_rel=0.1)
            )
            keep = radius + TOOL["radius"] + margin
            print(
                row(
                    f"post r={radius:g} margin={margin:g}",
                    extension,
                    blind,
                    demo,
                    1 / 300,
                    shortest_around(seg, hover, centre, keep),
                )
            )
    demo = minimum_jerk([[-80, -120, 200], [0, 0, 40], [0, 0, 0]], 200)
    target = np.array([150.0, 25.0, 0.0])
    blind = extend_demonstration(demo, target, seed=0)
    for height in (60.0, 100.0, 130.0):
        duct = {
            "type": "box",
            "label": "duct",
            "at": [75.0, 0.0, 0.0],
            "size": [20.0, 2000.0, height],
        }
        extension = extend_demonstration(
            demo,
            target,
            seed=0,
            scene=Scene.from_dict({"tool": TOOL, "parts": [duct], "margin": 3.0}),
        )
        print(row(f"duct {height:g} mm", extension, blind, demo, 1 / 200))


def random_cases(count: int) -> None:
    print(
        "\nrandom posts: seed  unit  post size / chord  LDJ worse by  floor(h)  excess  length/shortest  peaks max"
    )
    excesses = []
    for seed in range(count):
        rng = np.random.default_rng(seed)
        unit = float(rng.choice([1.0, 1e-3]))
        start = rng.uniform(-100, 100, 3) + [0, 0, 80]
        corner = start + np.append(rng.uniform(-150, 150, 2), rng.uniform(-20, 20))
        n = int(rng.integers(150, 600))
        demo = minimum_jerk(
            np.array([start, corner, corner - [0, 0, rng.uniform(30, 80)]]) * unit, n
        )
        heading = rng.uniform(0.0, 2.0 * np.pi)
        target = demo[-1] + np.append(
            np.array([np.cos(heading), np.sin(heading)])
            * rng.uniform(1.5, 3.0)
            * np.ptp(demo, axis=0).max(),
            0.0,
        )
        blind = extend_demonstration(demo, target, seed=seed)
        seg, hover = blind.tra_gen[0], blind.tra_gen[-1]
        tool = {"radius": rng.uniform(6, 14) * unit, "length": 100 * unit}
        radius, margin = rng.uniform(3, 20) * unit, rng.uniform(0, 3) * unit
        centre = seg + rng.uniform(0.3, 0.7) * (hover - seg)
        centre[:2] += rng.uniform(-0.5, 0.5, 2) * radius
        keep = radius + tool["radius"] + margin
        if (
            min(np.linalg.norm(seg[:2] - centre[:2]), np.linalg.norm(hover[:2] - centre[:2]))
            <= keep
        ):
            print(f"  {seed:4d}  skipped: the post is within reach of the transfer's start or end")
            continue
        post = {
            "type": "cylinder",
            "label": "post",
            "at": [centre[0], centre[1], -300 * unit],
            "radius": radius,
            "height": 800 * unit,
        }
        try:
            extension = extend_demonstration(
                demo,
                target,
                seed=seed,
                scene=Scene.from_dict({"tool": tool, "parts": [post], "margin": margin}),
            )
        except NoFreeRouteError as exc:
            print(f"  {seed:4d}  no free route: {exc}")
            continue
        worse = ldj(transfer(blind, n), 1 / n) - ldj(transfer(extension, n), 1 / n)
        chord = hover[:2] - seg[:2]
        along = float(np.dot(centre[:2] - seg[:2], chord) / np.dot(chord, chord))
        beside = abs(
            float(chord[0] * (centre[1] - seg[1]) - chord[1] * (centre[0] - seg[0]))
        ) / np.linalg.norm(chord)
        floor = ldj_floor(max(keep - beside, 0.0) / np.linalg.norm(hover[:2] - seg[:2]), along)
        ratio = length(extension.tra_gen) / shortest_around(seg, hover, centre, keep)
        top = (peaks(extension.complete, 1 / n) / peaks(demo, 1 / n)).max()
        excesses.append(worse - floor)
        print(
            f"  {seed:4d}  {'mm' if unit == 1.0 else 'm ':4s}  "
            f"{keep / np.linalg.norm(hover - seg):14.3f}  {worse:11.2f}  "
            f"{floor:8.2f}  {worse - floor:6.2f}  {ratio:15.3f}  {top:9.2f}"
        )
    if excesses:
        print(
            f"  excess over floor(h): at most {max(excesses):.2f}; "
            f"{sum(e <= 0.3 for e in excesses)} of {len(excesses)} within 0.3"
        )


def _least_jerk_offset(height: float, when: float, n: int = 801) -> np.ndarray:
    """Samples (n, 2) of the least-jerk rest-to-rest transfer of unit length that is ``height`` away
    from its chord at the fraction ``when`` of its duration (Flash & Hogan 1985: each axis is the
    minimum of the integral of its squared third derivative under its own constraints, so the
    along-chord axis is the quintic and the across axis a via-point problem, solved here as a
    least-squares problem on third differences)."""
    third = np.zeros((n - 3, n))
    rows = np.arange(n - 3)
    for k, weight in enumerate((-1.0, 3.0, -3.0, 1.0)):
        third[rows, rows + k] = weight
    fixed = {
        0: 0.0,
        1: 0.0,
        2: 0.0,
        n - 3: 0.0,
        n - 2: 0.0,
        n - 1: 0.0,
        int(round(when * (n - 1))): height,
    }
    across = np.zeros(n)
    across[list(fixed)] = list(fixed.values())
    free = np.setdiff1d(np.arange(n), list(fixed))
    across[free] = np.linalg.lstsq(third[:, free], -third @ across, rcond=None)[0]
    t = np.linspace(0.0, 1.0, n)
    return np.column_stack([10 * t**3 - 15 * t**4 + 6 * t**5, across])


def jerk_floor(height: float, when: float = 0.5) -> float:
    """How much worse the jerk measure of the least-jerk transfer that passes ``height`` (a fraction
    of the transfer's length) from the chord is than the straight quintic's."""
    bowed = _least_jerk_offset(height, when)
    straight = bowed.copy()
    straight[:, 1] = 0.0  # the same quintic along the chord, nothing across
    return ldj(straight, 1 / (len(bowed) - 1)) - ldj(bowed, 1 / (len(bowed) - 1))


def ideal_bows() -> None:
    """The floor of the jerk measure's excess: the least-jerk transfer through a point h (a fraction
    of its length) from the chord at mid-transfer, and one half-sine bow of height h on the quintic
    rest-to-rest time law (the shape the refinement's second candidate takes)."""
    heights = (0.05, 0.08, 0.1, 0.15, 0.2, 0.3)
    t = np.linspace(0.0, 1.0, 20001)
    s = 10 * t**3 - 15 * t**4 + 6 * t**5
    straight = ldj(np.column_stack([s, 0 * s]), t[1])
    print("\nfloor, offset from the chord / length:   " + "  ".join(f"{h:5.2f}" for h in heights))
    print(
        "  floor(h), the least-LDJ route:         "
        + "  ".join(f"{ldj_floor(h):5.2f}" for h in heights)
    )
    print(
        "  least-jerk route, point at mid-time:   "
        + "  ".join(f"{jerk_floor(h):5.2f}" for h in heights)
    )
    bows = [straight - ldj(np.column_stack([s, h * np.sin(np.pi * s)]), t[1]) for h in heights]
    print("  half-sine bow, quintic law, worse by:  " + "  ".join(f"{w:5.2f}" for w in bows))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--random", type=int, default=24, help="random post cases (default 24)")
    args = parser.parse_args()
    fixed_cases()
    random_cases(args.random)
    ideal_bows()


if __name__ == "__main__":
    main()
