"""Engagement along the final approach: only the motion's final descent along the
target's axis into the target counts; a pass through the band, a lift out of it or a motion that
never comes down does not engage. The trajectories are built by hand, with the answer known."""

import math

import numpy as np
import pytest

from bidmp.tasks import approach_error, axis_deviation

TARGET = np.array([100.0, 50.0, 0.0])
BAND = 28.5


def segment(a, b, n=60):
    return np.asarray(a, float) + np.linspace(0.0, 1.0, n)[:, None] * (
        np.asarray(b, float) - np.asarray(a, float)
    )


def test_a_lift_through_the_band_at_the_start_does_not_count_against_the_final_approach():
    # Pick beside the target at its height (inside the band, 200 mm away), lift, carry, descend
    # 0.4 mm off the axis: the old height band reported the pick's 200 mm; the approach is 0.4 mm.
    pick = TARGET + [-200.0, 0.0, 0.0]
    path = np.vstack(
        [
            segment(pick, pick + [0, 0, 80]),
            segment(pick + [0, 0, 80], TARGET + [0.4, 0, 80]),
            segment(TARGET + [0.4, 0, 80], TARGET + [0.4, 0, 0]),
        ]
    )
    assert approach_error(path, TARGET, BAND) == pytest.approx(0.4, abs=1e-9)


def test_a_pass_through_the_band_or_a_motion_that_ends_above_it_never_engages():
    passing = np.vstack(
        [
            segment(TARGET + [0, 0, 100], TARGET + [0, 0, 5]),
            segment(TARGET + [0, 0, 5], TARGET + [0, 0, 60]),
        ]
    )
    assert approach_error(passing, TARGET, BAND) == math.inf
    hovering = segment(TARGET + [-50, 0, 100], TARGET + [0, 0, 40])  # never comes lower than 40 mm
    assert approach_error(hovering, TARGET, BAND) == math.inf
    flat = segment(
        TARGET + [-200, 0, 0], TARGET
    )  # slides in at the target's height: never from above
    assert approach_error(flat, TARGET, BAND) == math.inf


def test_a_lift_inside_the_final_band_breaks_the_engagement_but_noise_does_not():
    down = segment(TARGET + [0, 0, 80], TARGET + [0, 0, 10])
    lift = np.vstack(
        [
            down,
            segment(TARGET + [0, 0, 10], TARGET + [0, 0, 20]),
            segment(TARGET + [0, 0, 20], TARGET),
        ]
    )
    assert approach_error(lift, TARGET, BAND) == math.inf  # a 10 mm lift inside the band
    rng = np.random.default_rng(0)
    noisy = np.vstack([down, segment(TARGET + [0, 0, 10], TARGET)])
    noisy[len(down) :, 2] += rng.normal(
        scale=0.05, size=len(noisy) - len(down)
    )  # 0.05 mm sensor noise
    noisy[-1] = TARGET
    assert approach_error(noisy, TARGET, BAND) < 1e-9


def test_a_tilted_target_is_approached_along_its_axis():
    axis = np.array([0.0, np.sin(np.radians(20)), np.cos(np.radians(20))])
    side = np.cross(axis, [1.0, 0.0, 0.0])
    start = TARGET + 90.0 * axis + 0.7 * side
    path = np.vstack([segment(TARGET + [-100, 0, 150], start), segment(start, TARGET + 0.7 * side)])
    assert approach_error(path, TARGET, BAND, axis) == pytest.approx(0.7, abs=1e-9)
    assert approach_error(path, TARGET, BAND) > 0.7  # measured against +z it is not along the axis
    down = np.tile(
        [0.0, 0.0, 0.0, 1.0], (len(path), 1)
    )  # tool pointing down: 20 degrees off the axis
    down[:, :] = [1.0, 0.0, 0.0, 0.0]  # (x, y, z, w): a half turn about x, the tool's z axis down
    assert axis_deviation(path, down, TARGET, BAND, axis) == pytest.approx(20.0, abs=1e-6)
    assert (
        axis_deviation(segment(TARGET + [0, 0, 100], TARGET + [0, 0, 40]), down[:60], TARGET, BAND)
        == math.inf
    )
