"""The checks that guard the robot, each against an answer computed here independently.

Every test names its kind in its docstring: *independent oracle* (a closed form or a plain
computation written in the test, not the library's), *property* (a law the result must obey
whatever it is), or *structure guard* (holds by construction; guards the wiring, not the math).
Each was written to catch a planted bug the older tests missed (``make mutation``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import minimum_jerk

import bidmp
from bidmp.extension.roadmap import template
from bidmp.extension.similarity import frechet_distance, frechet_similarity, polyline_length
from bidmp.primitives.coupling import PhaseStopping
from bidmp.scene import Scene
from bidmp.sim.job_report import JobPhase, JobReport, JobTarget, in_bin, in_slot
from bidmp.tasks.contract import command_peaks
from bidmp.tasks.metrics import approach_error, final_approach_mask


# -- clearance: the tool's whole shaft between sparse samples -------------------------------------
@pytest.mark.parametrize(
    "tool_length, beam_bottom, run_up",
    [(120.0, 100.0, 60.0), (300.0, 270.0, 60.0), (60.0, 50.0, 60.0), (100.0, 90.0, 2000.0)],
)
def test_a_two_point_path_under_a_beam_is_as_deep_as_the_shaft_reaches(
    tool_length, beam_bottom, run_up
):
    """Independent oracle: a vertical cylindrical tool (radius r, its shaft rising ``length``
    above its tip) crosses under a beam between two samples that are both clear of it. Where the
    shaft is under the beam it is inside it by min(shaft top − beam bottom, beam half-width + r)
    (the shorter way out: down, or sideways), so the clearance is minus that; the samples alone
    are at least 35 mm clear. (A 2 m run-up puts the beam past the first 8192 placements.)"""
    radius, half_width, depth_up = 5.0, 20.0, 15.5
    tip = beam_bottom + depth_up - tool_length
    scene = Scene.from_dict(
        {
            "tool": {"radius": radius, "length": tool_length},
            "parts": [
                {
                    "type": "box",
                    "label": "beam",
                    "at": [0.0, 0.0, beam_bottom],
                    "size": [2 * half_width, 400.0, 30.0],
                }
            ],
        }
    )
    path = np.array([[-run_up, 0.0, tip], [60.0, 0.0, tip]])
    truth = -min(depth_up, half_width + radius)
    found = scene.clearance(path)
    assert found.part == "beam"
    assert found.distance == pytest.approx(truth, abs=1e-6)
    down = np.tile(
        [1.0, 0.0, 0.0, 0.0], (2, 1)
    )  # the same, the tool's attitude given (pointing down)
    assert scene.clearance(path, orientations=down).distance == pytest.approx(truth, abs=1e-5)
    # Turned about its own axis (the same cylinder), by an angle whose unit quaternion's square sums
    # to 1 + 2e-16: the attitude does not change along the path, whatever the rounding says.
    spun = np.tile([0.99759293, 0.0693423, 0.0, 0.0], (2, 1))
    assert scene.clearance(path, orientations=spun).distance == pytest.approx(truth, abs=1e-5)
    at_samples = 60.0 - half_width - radius  # both samples: the shaft's side to the beam's side
    assert scene.clearance(path[1:]).distance == pytest.approx(at_samples, abs=1e-6)
    assert not found.clear and not found.collision_free


def test_a_later_segment_under_a_beam_is_checked_by_its_own_sweep():
    """Independent oracle: a path comes from far away (its first segment passes the beam 28 mm
    clear), then crosses under it with the shaft 15.5 mm inside; both ends of the crossing are
    75 mm clear. The clearance is the crossing's −15.5 (the shorter way out: down)."""
    scene = Scene.from_dict(
        {
            "tool": {"radius": 5.0, "length": 120.0},
            "parts": [
                {
                    "type": "box",
                    "label": "beam",
                    "at": [0.0, 0.0, 100.0],
                    "size": [40.0, 100.0, 30.0],
                }
            ],
        }
    )
    tip = 100.0 + 15.5 - 120.0
    for sign in (1.0, -1.0):  # from either side
        path = sign * np.array([[500.0, 500.0, 0.0], [-100.0, 0.0, 0.0], [100.0, 0.0, 0.0]]) + [
            0.0,
            0.0,
            tip,
        ]
        found = scene.clearance(path)
        assert found.distance == pytest.approx(-15.5, abs=1e-6) and found.part == "beam"
        assert abs(found.point[1]) < 1e-9 and abs(found.point[0]) <= 20.0 + 5.0 - 15.5


def test_a_path_over_a_box_at_the_margin_is_judged_by_its_closed_form_clearance():
    """Independent oracle: a tool tip passing above a box at height h over its top keeps exactly h;
    at the margin it is clear, 1e-3 below it not (the judge compares with ``>=``)."""
    scene = Scene.from_dict(
        {
            "tool": {"radius": 4.0, "length": 80.0},
            "margin": 3.0,
            "parts": [
                {"type": "box", "label": "box", "at": [0.0, 0.0, 0.0], "size": [50.0, 50.0, 20.0]}
            ],
        }
    )
    for height, clear in ((3.001, True), (2.999, False), (10.0, True)):
        path = np.array([[-100.0, 0.0, 20.0 + height], [100.0, 0.0, 20.0 + height]])
        found = scene.clearance(path)
        assert found.distance == pytest.approx(height, abs=1e-6)
        assert found.clear is clear and found.collision_free


def test_the_nearest_point_of_a_v_shaped_pass_over_a_box_is_its_lowest_sample():
    """Independent oracle: a path dipping to 7 mm over a box's top at one sample (x = 10) and
    rising either side is nearest there, 7 mm; with the tool's orientation given (pointing down,
    the default) the answer is the same, also when the path starts at its nearest point and
    when the quaternions are not normalised."""
    scene = Scene.from_dict(
        {
            "tool": {"radius": 4.0, "length": 80.0},
            "parts": [
                {"type": "box", "label": "box", "at": [0.0, 0.0, 0.0], "size": [60.0, 60.0, 20.0]}
            ],
        }
    )
    x = np.linspace(-50.0, 50.0, 41)
    path = np.column_stack([x, np.zeros(41), 27.0 + 0.5 * np.abs(x - 10.0)])
    down = np.tile(
        [1.0, 0.0, 0.0, 0.0], (41, 1)
    )  # half a turn about x: the tool's z axis points down
    for points, turns in ((path, None), (path, down), (path[24:], down[24:]), (path, 2.5 * down)):
        found = scene.clearance(points, orientations=turns)
        assert found.distance == pytest.approx(7.0, abs=1e-6)
        np.testing.assert_allclose(found.point, [10.0, 0.0, 27.0], atol=1e-9)
        assert found.part == "box"


def test_segments_free_judges_each_straight_move_by_its_own_closed_form():
    """Independent oracle: moves beside a box (tool radius r, box half-width w): a move at lateral
    offset d from the box's side axis is free iff d − w − r exceeds the checker's margin."""
    radius, half = 4.0, 10.0
    scene = Scene.from_dict(
        {
            "tool": {"radius": radius, "length": 50.0},
            "parts": [
                {
                    "type": "box",
                    "label": "box",
                    "at": [0.0, 0.0, 0.0],
                    "size": [2 * half, 2 * half, 40.0],
                }
            ],
        }
    )
    checker = scene.checker()
    offsets = np.array([13.0, 14.5, 15.0, 30.0, -13.0, -14.5, -30.0])
    starts = np.column_stack([offsets, np.full(7, -100.0), np.full(7, 5.0)])
    ends = np.column_stack([offsets, np.full(7, 100.0), np.full(7, 5.0)])
    expected = np.abs(offsets) - half - radius > 0.0
    assert checker.segments_free(starts, ends).tolist() == expected.tolist()
    # Under the box (its bottom at 0): the shaft (50 long) reaches into it from a tip 20 below.
    under = checker.segments_free(
        np.array([[-100.0, 0.0, -20.0], [-100.0, 0.0, -60.0]]),
        np.array([[100.0, 0.0, -20.0], [100.0, 0.0, -60.0]]),
    )
    assert under.tolist() == [False, True]
    # With a 3 mm margin: a move passing 2 mm beside the box (either side) or 2 mm under it is not free.
    kept = bidmp.scene.SceneChecker(scene, np.arange(len(scene.solids)), 3.0)
    side = half + radius + 2.0
    starts = np.array(
        [
            [side, -100.0, 5.0],
            [-side, -100.0, 5.0],
            [-100.0, -side, 5.0],
            [-100.0, side, 5.0],
            [-100.0, 0.0, -52.0],
            [side + 1.5, -100.0, 5.0],
        ]
    )
    along_y, along_x = [0.0, 200.0, 0.0], [200.0, 0.0, 0.0]
    ends = starts + [along_y, along_y, along_x, along_x, along_x, along_y]
    assert kept.segments_free(starts, ends).tolist() == [False, False, False, False, False, True]
    # A move of no length is its one placement; a move shorter than 1 ending inside the box is not
    # free; a move that grazes the margin (1e-7 outside it) all along is taken as touching.
    inside, outside = (
        np.array([[half + radius - 0.5, 0.0, 5.0]]),
        np.array([[half + radius + 1.0, 0.0, 5.0]]),
    )
    assert checker.segments_free(inside, inside).tolist() == [False]
    assert checker.segments_free(outside, outside).tolist() == [True]
    near = np.array([[half + radius + 0.3, 0.0, 5.0]])
    assert checker.segments_free(near, near - [0.8, 0.0, 0.0]).tolist() == [
        False
    ]  # ends 0.5 inside
    post = Scene.from_dict(
        {
            "tool": {"radius": radius, "length": 50.0},
            "parts": [
                {
                    "type": "cylinder",
                    "label": "post",
                    "at": [0.0, 0.0, -200.0],
                    "radius": 20.0,
                    "height": 400.0,
                }
            ],
        }
    )
    corner = (20.0 + radius + 3.0) / np.sqrt(
        2.0
    )  # 3 from the post, diagonally (inside its bounding box)
    top, bottom = np.array([[corner, corner, 100.0]]), np.array([[corner, corner, -100.0]])
    clearance = post.clearance(top).distance
    grazing = bidmp.scene.SceneChecker(post, np.arange(len(post.solids)), clearance - 1e-7)
    assert grazing.segments_free(top, bottom).tolist() == [
        False
    ]  # 200 along the margin: taken as touching
    assert bidmp.scene.SceneChecker(
        post, np.arange(len(post.solids)), clearance - 1.0
    ).segments_free(top, bottom).tolist() == [True]
    # Starting 0.5 inside the box's side and moving straight away: the first placement decides.
    away = checker.segments_free(
        np.array([[half + radius - 0.5, 0.0, 5.0]]), np.array([[100.0, 0.0, 5.0]])
    )
    assert away.tolist() == [False]


@pytest.mark.parametrize(
    "distance, margin, collision_free, clear",
    [
        (0.0, 0.0, True, True),
        (-1e-12, 0.0, False, False),
        (2.0, 2.0, True, True),
        (1.999, 2.0, True, False),
        (-0.5, 2.0, False, False),
        (math.inf, 2.0, True, True),
    ],
)
def test_a_clearance_is_judged_at_its_boundaries(distance, margin, collision_free, clear):
    """Independent oracle: touching is not a collision; at the margin is clear, under it is not."""
    from bidmp.scene import Clearance

    found = Clearance(distance, "part", np.zeros(3), margin)
    assert found.collision_free is collision_free and found.clear is clear
    assert found.collision_part == (None if collision_free else "part")


# -- limits on the 1 kHz commands: every direction ------------------------------------------------
@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_command_peaks_of_a_quintic_match_its_closed_form_in_either_direction(sign):
    """Independent oracle: a minimum-jerk joint move of amplitude A over T has peak speed
    15A/(8T), peak acceleration 10A/(√3 T²) and jerk 60A/T³ at its ends; the peaks of its 1 kHz
    commands are these over the limits, moving up or down (the absolute value matters)."""
    amplitude, duration, dt = 0.8, 2.0, 1e-3
    s = np.linspace(0.0, 1.0, int(round(duration / dt)) + 1)
    q = sign * amplitude * (10 * s**3 - 15 * s**4 + 6 * s**5)
    commands = np.column_stack([q, np.zeros_like(q)])
    limits = bidmp.sim.JointLimits(
        lower=(-3.0, -3.0),
        upper=(3.0, 3.0),
        velocity=(1.0, 1.0),
        acceleration=(5.0, 5.0),
        jerk=(100.0, 100.0),
    )
    peaks = command_peaks(commands, limits, dt)
    assert peaks.velocity == pytest.approx(15 * amplitude / (8 * duration), rel=2e-3)
    assert peaks.acceleration == pytest.approx(
        10 * amplitude / (math.sqrt(3) * duration**2) / 5.0, rel=5e-3
    )
    assert peaks.jerk == pytest.approx(60 * amplitude / duration**3 / 100.0, rel=5e-3)
    assert peaks.joint == 0 and peaks.within
    slow = bidmp.sim.JointLimits(
        lower=(-3.0, -3.0),
        upper=(3.0, 3.0),
        velocity=(0.5, 1.0),
        acceleration=(5.0, 5.0),
        jerk=(100.0, 100.0),
    )
    assert not command_peaks(commands, slow, dt).within  # 0.75 rad/s against 0.5


def test_a_command_jump_at_either_end_is_an_acceleration_from_rest():
    """Independent oracle: a first command 1 mrad from rest is a step of 1e-3/dt² in acceleration."""
    commands = np.array([[0.0], [1e-3], [1e-3], [1e-3]])
    limits = bidmp.sim.JointLimits(
        lower=(-1.0,), upper=(1.0,), velocity=(10.0,), acceleration=(2000.0,), jerk=None
    )
    peaks = command_peaks(commands, limits, 1e-3)
    assert peaks.ends == pytest.approx(1e-3 / 1e-6 / 2000.0)
    assert not peaks.within
    backwards = command_peaks(-commands, limits, 1e-3)
    assert backwards.ends == pytest.approx(peaks.ends) and not backwards.within
    assert peaks.jerk == 0.0  # no jerk limit: not judged
    stopping = command_peaks(
        commands[::-1], limits, 1e-3
    )  # the same jump at the end: to rest at once
    assert stopping.ends == pytest.approx(peaks.ends) and not stopping.within
    two = command_peaks(commands[:2], limits, 1e-3)  # one step: from rest and back to rest at once
    assert two.ends == pytest.approx(peaks.ends) and not two.within
    for held in (np.full((1, 1), 0.3), np.full((6, 1), 0.3)):  # an arm held still: nothing moves
        still = command_peaks(held, limits, 1e-3)
        assert (still.velocity, still.acceleration, still.jerk, still.ends) == (
            0.0,
            0.0,
            0.0,
            0.0,
        ) and still.within


# -- engagement: the final approach ---------------------------------------------------------------
def test_the_final_approach_is_the_descent_below_its_height_and_its_error_is_the_largest_sideways_offset():
    """Independent oracle: a path that comes down 40 mm to the target, sideways off by a known
    bump below the approach height of 25 mm; the approach error is the largest horizontal distance
    from the target's axis over the samples below 25 mm, computed here by hand."""
    target = np.array([10.0, -5.0, 0.0])
    z = np.linspace(40.0, 0.0, 81)
    offset = 0.4 * np.sin(np.pi * z / 40.0) ** 2  # largest at 20 mm
    path = np.column_stack([target[0] + offset, np.full(81, target[1]), z])
    heights = path[:, 2] - target[2]
    mask = final_approach_mask(heights, 25.0)
    assert mask.tolist() == (heights < 25.0).tolist()  # after the last sample at or above the band
    below = z < 25.0
    assert approach_error(path, target, 25.0) == pytest.approx(offset[below].max(), rel=1e-12)
    along_x = np.column_stack(
        [z, offset, np.zeros(81)]
    )  # the same descent along a target's +x axis
    assert approach_error(along_x, np.zeros(3), 25.0, axis=[1.0, 0.0, 0.0]) == pytest.approx(
        offset[below].max(), rel=1e-12
    )


@pytest.mark.parametrize(
    "rise, engaged", [(0.0, True), (0.2, True), (0.25, True), (0.3, False), (2.0, False)]
)
def test_a_rise_inside_the_band_beyond_the_tolerance_is_no_engagement(rise, engaged):
    """Independent oracle: a descent into a 20 mm band that rises by ``rise`` on the way down
    (a wobble) engages iff the rise is at most the tolerance (0.25 here)."""
    heights = np.concatenate(
        [
            np.linspace(30.0, 10.0, 41),
            10.0 + rise * np.sin(np.linspace(0, np.pi, 11)),
            np.linspace(10.0, 0.0, 21),
        ]
    )
    mask = final_approach_mask(heights, 20.0, rise=0.25)
    assert (mask is not None) is engaged
    path = np.column_stack([np.zeros_like(heights), np.zeros_like(heights), heights])
    assert math.isfinite(approach_error(path, np.zeros(3), 20.0, rise=0.25)) is engaged


def test_a_motion_ending_above_the_band_or_never_above_it_does_not_engage():
    """Independent oracle: no final approach without a descent from above the band to its end."""
    assert final_approach_mask(np.linspace(30.0, 21.0, 10), 20.0) is None  # ends above
    assert final_approach_mask(np.linspace(15.0, 0.0, 10), 20.0) is None  # never above
    assert final_approach_mask(np.array([30.0, 20.0, 10.0, 0.0]), 20.0).tolist() == [
        False,
        False,
        True,
        True,
    ]


# -- the job: in the bin, in the slot, removed ----------------------------------------------------
@pytest.mark.parametrize(
    "fraction, inside", [(0.0, True), (0.49, True), (0.5, True), (0.51, False), (0.9, False)]
)
def test_a_part_is_in_the_bin_within_half_its_inner_width(fraction, inside):
    """Independent oracle: a bin 120 × 80 inside: a part at rest a fraction f of the inner width
    off its centre (in x, then in y, either side) is in it iff f ≤ 1/2; below the floor or over
    the rim it is not."""
    floor, inner = np.array([300.0, -200.0, 10.0]), np.array([120.0, 80.0, 60.0])
    for axis in (0, 1):
        for sign in (1.0, -1.0):
            centre = floor + [0.0, 0.0, 5.0]
            centre[axis] += sign * fraction * inner[axis]
            assert in_bin(centre, floor, inner) is inside
    assert not in_bin(floor + [0.0, 0.0, -1.0], floor, inner)
    assert not in_bin(floor + [0.0, 0.0, 61.0], floor, inner)
    assert in_bin(floor + [0.0, 0.0, 60.0], floor, inner) and in_bin(floor, floor, inner)


def test_a_part_is_in_its_slot_within_both_tolerances():
    """Independent oracle: a part of height 40 resting with its centre at the slot's floor + 20 is
    in the slot; off sideways by more than the tolerance, or standing proud, it is not."""
    slot = np.array([100.0, 50.0, 5.0])
    centre = slot + [0.0, 0.0, 20.0]
    assert in_slot(centre, slot, 40.0, 2.0, 1.0)
    assert in_slot(centre + [0.0, -2.0, 0.0], slot, 40.0, 2.0, 1.0)  # at the tolerance
    assert not in_slot(centre + [1.2, -1.61, 0.0], slot, 40.0, 2.0, 1.0)  # 2.008 off
    assert in_slot(centre + [0.0, 0.0, 1.0], slot, 40.0, 2.0, 1.0)
    assert not in_slot(centre + [0.0, 0.0, 1.01], slot, 40.0, 2.0, 1.0)
    assert not in_slot(centre - [0.0, 0.0, 1.01], slot, 40.0, 2.0, 1.0)


def test_a_target_is_removed_only_when_every_phase_kept_the_contract_and_says_the_first_breach():
    """Property: removed = every phase ok; the reason names the first failed phase; contacts take
    the deepest per part; limits hold only if they held in every phase."""
    from bidmp.sim.job import _finish

    class Part:
        def pose(self):
            return np.array([1.0, 2.0, 3.0]), np.array([0.0, 0.0, 0.0, 1.0])

    record = JobTarget(
        "n1",
        [
            JobPhase("approach", True, 1.0, contacts={"plate": 0.2}),
            JobPhase("engage", True, 0.0),
            JobPhase(
                "drop",
                False,
                2.0,
                "released outside the bin",
                contacts={"plate": 0.5, "bin": 0.1},
                within_limits=False,
            ),
            JobPhase("settle", False, 0.5, "later"),
        ],
    )
    _finish(record, Part())
    assert not record.removed and record.reason == "drop: released outside the bin"
    assert record.final_position.tolist() == [1.0, 2.0, 3.0]
    assert record.contacts == {"plate": 0.5, "bin": 0.1} and not record.within_limits
    # an early phase's breach is not undone by a later phase that went well
    early = JobTarget("n6", [JobPhase("approach", False, 1.0, "off"), JobPhase("leave", True, 0.5)])
    _finish(early, Part())
    assert not early.removed and early.reason == "approach: off"
    good = JobTarget("n2", [JobPhase("approach", True, 1.0), JobPhase("drop", True, 2.0)])
    _finish(good, Part())
    # (seconds: the phases' simulated durations, 1.0 + 2.0, not a clock)
    assert good.removed and good.reason == "" and good.within_limits and good.seconds == 3.0

    class Verdict:
        def __init__(self, ok):
            self.ok = ok

        def reason(self):
            return "the contract's reason"

    kept = JobTarget("n4", [JobPhase("approach", False, 1.0, "its note", verdict=Verdict(True))])
    _finish(kept, Part())
    assert kept.reason == "approach: its note"  # the motion kept the contract: the phase's own note
    broken = JobTarget("n5", [JobPhase("approach", False, 1.0, "its note", verdict=Verdict(False))])
    _finish(broken, Part())
    assert broken.reason == "approach: the contract's reason"
    report = JobReport(None, "unscrew", "panda", [record, good, JobTarget("n3", removed=True)])
    assert report.removed == 2


# -- similarity: template and normaliser ----------------------------------------------------------
def _rodrigues(a, b):
    """The rotation taking the direction of a onto b about their common normal (written here)."""
    u, v = a / np.linalg.norm(a), b / np.linalg.norm(b)
    axis = np.cross(u, v)
    sine, cosine = np.linalg.norm(axis), float(u @ v)
    k = axis / sine
    cross = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + sine * cross + (1 - cosine) * cross @ cross


@pytest.mark.parametrize("seed", range(4))
def test_the_similarity_template_turns_the_piece_the_way_its_chord_turns(seed):
    """Independent oracle: the similarity template is seg + s R (piece − seg), R by Rodrigues'
    formula from the old chord to the new one, s the ratio of their lengths — at every sample, so
    its last step is as long as the piece's (no kink where it is pinned to the new target)."""
    rng = np.random.default_rng(seed)
    s = np.linspace(0.0, 1.0, 60)[:, None]
    chord = rng.uniform(-100, 100, 3)
    bump = rng.uniform(-30, 30, 3)
    piece = s * chord + np.sin(np.pi * s) * bump + 5.0
    new_target = piece[0] + rng.uniform(-150, 150, 3)
    out = template(piece, new_target, scaling="similarity")
    scale = np.linalg.norm(new_target - piece[0]) / np.linalg.norm(chord)
    expected = piece[0] + scale * (piece - piece[0]) @ _rodrigues(chord, new_target - piece[0]).T
    np.testing.assert_allclose(out, expected, atol=1e-9 * np.abs(expected).max())
    steps = np.linalg.norm(np.diff(out, axis=0), axis=1)
    assert steps[-1] <= 1.2 * steps[-2]


def test_frechet_similarity_of_curves_of_unequal_length_is_the_papers_normalised_distance():
    """Independent oracle: ``similaritymeasures.frechet_dist`` and polyline lengths summed here
    give 1 − F/(√(L_a L_b)/√2) for curves of unequal length and sample count."""
    similaritymeasures = pytest.importorskip("similaritymeasures")
    s = np.linspace(0.0, 1.0, 80)[:, None]
    a = np.column_stack([100 * s, 10 * np.sin(3 * s), 0 * s])
    t = np.linspace(0.0, 1.0, 37)[:, None]
    b = np.column_stack([130 * t, 25 * np.sin(2 * t) + 4, 3 * t])
    length_a = float(np.sum(np.sqrt(np.sum(np.diff(a, axis=0) ** 2, axis=1))))
    length_b = float(np.sum(np.sqrt(np.sum(np.diff(b, axis=0) ** 2, axis=1))))
    assert abs(length_a - length_b) > 20.0
    distance = similaritymeasures.frechet_dist(a, b)
    assert frechet_distance(a, b) == pytest.approx(distance, rel=1e-12)
    assert polyline_length(b) == pytest.approx(length_b, rel=1e-12)
    for denom, r in (("sqrt2", math.sqrt(2.0)), ("2", 2.0)):
        expected = max(1.0 - distance / (math.sqrt(length_a * length_b) / r), 0.0)
        assert frechet_similarity(a, b, denom) == pytest.approx(expected, rel=1e-12)
        assert frechet_similarity(b, a, denom) == pytest.approx(expected, rel=1e-12)


# -- skills, phase stopping, the spring -----------------------------------------------------------
def test_a_tie_in_the_nearest_skill_goes_to_the_later_skill():
    """Independent oracle: two skills whose goals are equidistant from the query; the docstring
    promises the later one. Off the tie, the nearer one wins."""
    demo = minimum_jerk(np.zeros(3), np.array([100.0, 0.0, 0.0]), 100)
    dmp = bidmp.DMP().fit(demo, np.linspace(0.0, 1.0, 100), units="mm")
    model = bidmp.BiDMP(dmp).learn_increment(np.zeros((dmp.n_train_, 3)), goal=[100.0, 60.0, 0.0])
    model.learn_increment(np.zeros((dmp.n_train_, 3)), goal=[100.0, -60.0, 0.0])
    assert model.select_skill([100.0, 30.0, 0.0]) == 1  # equidistant from skills 0 and 1
    assert model.select_skill([100.0, 0.0, 0.0]) == 0  # skill 0's own goal
    assert model.select_skill([100.0, 29.0, 0.0]) == 0
    assert model.select_skill([100.0, 31.0, 0.0]) == 1
    assert model.select_skill([100.0, -30.0, 0.0]) == 2  # equidistant from skills 0 and 2


def test_phase_stopping_slows_time_by_one_plus_gain_times_the_squared_error():
    """Independent oracle: 1 + α_e ‖e‖² (Ijspeert et al. 2013), for errors of norm 3 (the square,
    9, tells it from the norm) and 0.5, and none without a measurement."""
    stop = PhaseStopping(gain=0.25)
    y = np.array([1.0, 2.0, 3.0])
    assert stop.slowdown(y, y + [2.0, 1.0, 2.0]) == pytest.approx(1.0 + 0.25 * 9.0)
    assert PhaseStopping(1.0).slowdown(y, y + [2.0, 1.0, 2.0]) == pytest.approx(10.0)
    assert stop.slowdown(y, y - [0.3, 0.4, 0.0]) == pytest.approx(1.0 + 0.25 * 0.25)
    assert stop.slowdown(y, None) == 1.0 and PhaseStopping(0.0).slowdown(y, y + 5.0) == 1.0


def test_the_default_spring_is_critically_damped():
    """Independent oracle: with the default gains, the transformation system without forcing,
    released from rest at 0 towards g, follows the critically damped closed form
    g (1 − (1 + λ t) e^(−λ t)), λ = α/2 (normalised time), sampled with the exact integrator."""
    demo = minimum_jerk(np.zeros(2), np.array([1.0, 2.0]), 100)
    params = bidmp.DMP().fit(demo, np.linspace(0.0, 1.0, 100)).settings()
    alpha, beta = params.alpha, params.beta
    integrator = bidmp.primitives.StepIntegrator(alpha, beta, 1.0, True)
    goal, step = np.array([1.0, -2.0]), 1e-3
    drive = alpha * beta * goal
    y, z = np.zeros(2), np.zeros(2)
    lam = alpha / 2.0
    for index in range(1, 1001):
        y, z = integrator.step(y, z, drive, drive, step)
        t = index * step
        expected = goal * (1.0 - (1.0 + lam * t) * np.exp(-lam * t))
        assert np.allclose(y, expected, atol=1e-9), (t, y, expected)


# -- clearance on random cells against a closed form ----------------------------------------------
def _tool_to_boxes(tips, radius, length, lower, upper, discs=None):
    """Signed distance (n, k) from a vertical cylindrical tool (tip at ``tips`` (n, 3), radius r,
    rising ``length``) to axis-aligned boxes (k, 3), or with ``discs`` (k, 3: x, y, radius) to
    vertical cylinders spanning the boxes' heights: both are products of a horizontal and a
    vertical set, so the distance is the hypotenuse of the horizontal and vertical gaps, and a
    penetration is the smaller of the two ways out (sideways, or along z)."""
    xy, lo, hi = tips[:, None, :2], lower[None, :, :2], upper[None, :, :2]
    outside = np.maximum(np.maximum(lo - xy, xy - hi), 0.0)
    horizontal_gap = np.linalg.norm(outside, axis=2) - radius
    inside_depth = np.min(
        np.minimum(xy - lo, hi - xy), axis=2
    )  # to the rectangle's edge, when inside
    horizontal_depth = np.where(
        np.all(outside == 0.0, axis=2),
        inside_depth + radius,
        radius - np.linalg.norm(outside, axis=2),
    )
    if discs is not None:  # cylinders: the distance between two discs' centres less both radii
        round_ = ~np.isnan(discs[:, 2])
        apart = np.linalg.norm(xy - discs[None, :, :2], axis=2) - radius - discs[None, :, 2]
        horizontal_gap = np.where(round_[None], apart, horizontal_gap)
        horizontal_depth = np.where(round_[None], -apart, horizontal_depth)
    bottom, top = tips[:, None, 2], tips[:, None, 2] + length
    vertical_gap = np.maximum(np.maximum(lower[None, :, 2] - top, bottom - upper[None, :, 2]), 0.0)
    vertical_depth = np.minimum(top - lower[None, :, 2], upper[None, :, 2] - bottom)
    separated = (horizontal_gap > 0.0) | (vertical_gap > 0.0)
    distance = np.hypot(np.maximum(horizontal_gap, 0.0), vertical_gap)
    return np.where(separated, distance, -np.minimum(horizontal_depth, vertical_depth))


def _random_cell(rng, cylinders=False):
    """1-4 boxes (or, with ``cylinders``, some vertical cylinders) 100 apart on a grid, and a
    tool: (scene, radius, length, lower, upper, discs)."""
    parts, discs = [], []
    cells = [
        (x, y) for x in (-100.0, 0.0, 100.0) for y in (-100.0, 0.0, 100.0)
    ]  # 100 apart: no overlap
    for cell in rng.permutation(len(cells))[: int(rng.integers(1, 5))]:
        size = rng.uniform([10, 10, 10], [90, 90, 60])
        at = np.array([*cells[cell], 0.0]) + [*rng.uniform(-5.0, 5.0, 2), rng.uniform(0.0, 40.0)]
        label = f"b{len(parts)}"
        if cylinders and rng.random() < 0.5:
            size[:2] = 2 * rng.uniform(5.0, 45.0)
            parts.append(
                {
                    "type": "cylinder",
                    "label": label,
                    "at": at.tolist(),
                    "radius": size[0] / 2,
                    "height": size[2],
                }
            )
            discs.append([at[0], at[1], size[0] / 2])
        else:
            parts.append({"type": "box", "label": label, "at": at.tolist(), "size": size.tolist()})
            discs.append([at[0], at[1], np.nan])
        parts[-1]["_lower"] = (at - [size[0] / 2, size[1] / 2, 0.0]).tolist()
        parts[-1]["_upper"] = (at + [size[0] / 2, size[1] / 2, size[2]]).tolist()
    lower = np.array([part.pop("_lower") for part in parts])
    upper = np.array([part.pop("_upper") for part in parts])
    radius, length = rng.uniform(2.0, 12.0), rng.uniform(30.0, 150.0)
    scene = Scene.from_dict({"tool": {"radius": radius, "length": length}, "parts": parts})
    return scene, radius, length, lower, upper, np.array(discs)


def _random_path(rng):
    kind = rng.integers(3)
    points = rng.uniform([-160, -160, -60], [160, 160, 140], (int(rng.integers(2, 6)), 3))
    if kind == 1:  # out and back
        points = np.vstack([points[:2], points[:1]])
    elif kind == 2:  # a level pass under or through the parts
        points[:, 2] = rng.uniform(-80.0, 60.0)
    return points


def _dense(points, spacing):
    pieces = [
        np.linspace(a, b, max(int(np.ceil(np.linalg.norm(b - a) / spacing)), 1) + 1)
        for a, b in zip(points[:-1], points[1:])
    ]
    return np.vstack(pieces)


@pytest.mark.parametrize("seed", range(12))
def test_clearance_on_random_cells_is_the_closed_form_minimum_within_the_placement_step(seed):
    """Independent oracle: for random boxes, tools and multi-point paths (zig-zags, out and back,
    level passes through the parts), the clearance is the minimum of the closed-form signed
    distance over the path sampled 20 times finer than the library's placements, within the
    documented step / 2; its part is the nearest box there, its point on the path."""
    rng = np.random.default_rng(seed)
    scene, radius, length, lower, upper, discs = _random_cell(rng, cylinders=seed % 2 == 1)
    step = 0.002 * length
    for _ in range(6):
        path = _random_path(rng)
        found = scene.clearance(path)
        fine = _dense(path, step / 20.0)
        distances = _tool_to_boxes(fine, radius, length, lower, upper, discs)
        truth = float(distances.min())
        # coal's penetration depths (EPA) agree with the closed form to ~3e-5 for boxes, 4e-4 of the
        # depth for cylinders; separations to 1e-8
        tolerance = 1e-4 + (1e-3 * abs(truth) if truth < 0 else 0.0)
        assert (
            truth - step / 40.0 - tolerance <= found.distance <= truth + step / 2.0 + tolerance
        ), (found.distance, truth)
        own = _tool_to_boxes(found.point[None], radius, length, lower, upper, discs)[0]
        assert own.min() == pytest.approx(found.distance, abs=tolerance)
        assert found.part == f"b{int(np.argmin(own))}" or np.sort(own)[1] - own.min() < tolerance
        on_path = np.min(np.linalg.norm(_dense(path, step / 4.0) - found.point, axis=1))
        assert on_path <= step


@pytest.mark.parametrize("seed", range(8))
def test_the_checker_and_straight_moves_on_random_cells_agree_with_the_closed_form(seed):
    """Independent oracle: a placement is free iff its closed-form clearance is at least the
    margin; a straight move iff it is along the whole move (sampled finely here). Cases within
    a hair of the margin are left out (either answer is right there)."""
    rng = np.random.default_rng(100 + seed)
    scene, radius, length, lower, upper, discs = _random_cell(rng, cylinders=True)
    margin = 0.0 if seed % 3 == 0 else float(rng.uniform(0.0, 6.0))
    checker = bidmp.scene.SceneChecker(scene, np.arange(len(scene.solids)), margin)
    points = rng.uniform([-160, -160, -60], [160, 160, 140], (300, 3))
    truth = _tool_to_boxes(points, radius, length, lower, upper, discs).min(axis=1)
    sure = np.abs(truth - margin) > 1e-4
    assert checker(points)[sure].tolist() == (truth >= margin)[sure].tolist()
    a = rng.uniform([-160, -160, -60], [160, 160, 140], (40, 3))
    b = a + rng.uniform(-120.0, 120.0, (40, 3))
    along = np.array(
        [
            _tool_to_boxes(
                _dense(np.vstack([p, q]), 0.05), radius, length, lower, upper, discs
            ).min()
            for p, q in zip(a, b)
        ]
    )
    sure = np.abs(along - margin) > 0.1
    assert checker.segments_free(a, b)[sure].tolist() == (along >= margin)[sure].tolist()
    assert sure.sum() >= 30
    blocked = int(np.argmin(along))  # one move alone, and none
    assert checker.segments_free(a[blocked : blocked + 1], b[blocked : blocked + 1]).tolist() == [
        bool(along[blocked] >= margin)
    ]
    nothing = bidmp.scene.SceneChecker(scene, np.array([], dtype=int), margin)
    assert nothing.segments_free(a, b).all() and nothing(points).all()


@pytest.mark.parametrize("seed", range(4))
def test_the_culling_bounds_are_the_exact_distances_to_boxes(seed):
    """Independent oracle: the culling's lower bound of a tool placement against a box is the
    closed-form distance (0 when they overlap); two boxes' distance is the norm of their per-axis
    gaps, computed here axis by axis."""
    from bidmp.scene.distances import _box_distance, _cylinder_box_bounds

    rng = np.random.default_rng(seed)
    lower = rng.uniform(-100.0, 100.0, (5, 3))
    upper = lower + rng.uniform(1.0, 60.0, (5, 3))
    points = rng.uniform(-200.0, 200.0, (400, 3))
    radius, length = rng.uniform(1.0, 15.0), rng.uniform(10.0, 120.0)
    expected = np.maximum(_tool_to_boxes(points, radius, length, lower, upper), 0.0)
    np.testing.assert_allclose(
        _cylinder_box_bounds(points, radius, length, lower, upper), expected, atol=1e-9
    )
    other_lower = rng.uniform(-150.0, 150.0, (400, 3))
    other_upper = other_lower + rng.uniform(0.0, 50.0, (400, 3))
    for k in range(5):
        gaps = [
            max(lower[k, axis] - other_upper[i, axis], other_lower[i, axis] - upper[k, axis], 0.0)
            for i in range(400)
            for axis in range(3)
        ]
        by_hand = np.sqrt(np.sum(np.reshape(gaps, (400, 3)) ** 2, axis=1))
        np.testing.assert_allclose(
            _box_distance(other_lower, other_upper, lower[k], upper[k]), by_hand, atol=1e-9
        )


@pytest.mark.parametrize("seed", range(4))
def test_placements_along_a_path_are_at_most_a_step_apart_and_no_more_than_needed(seed):
    """Property: the placements of every (or every chosen) segment run from its start to its end,
    no two more than ``step`` apart, ceil(length / step) + 1 of them (none wasted); their segment
    index and fraction give them back."""
    from bidmp.scene.distances import _densify

    rng = np.random.default_rng(seed)
    points = np.cumsum(rng.uniform(-30.0, 30.0, (7, 3)), axis=0)
    step = float(rng.uniform(0.5, 4.0))
    chosen = np.sort(rng.choice(6, 3, replace=False))
    for segments in (None, chosen):
        dense, which, fraction = _densify(points, step, segments, weights=True)
        indices = np.arange(6) if segments is None else segments
        np.testing.assert_allclose(
            dense,
            points[which] + fraction[:, None] * (points[which + 1] - points[which]),
            atol=1e-9,
        )
        for index in indices:
            own = dense[which == index]
            length = np.linalg.norm(points[index + 1] - points[index])
            assert own.shape[0] == max(int(np.ceil(length / step)), 1) + 1
            np.testing.assert_allclose(own[[0, -1]], points[[index, index + 1]], atol=1e-9)
            assert np.all(np.linalg.norm(np.diff(own, axis=0), axis=1) <= step + 1e-9)
        assert set(which.tolist()) == set(indices.tolist())
    pause = _densify(np.vstack([points[:2], points[1:2], points[2:3]]), step, weights=True)
    assert np.sum(pause[1] == 1) == 2  # a segment that does not move: its two ends only
    single = _densify(points[:1], step)
    assert single.tolist() == points[:1].tolist()
    assert _densify(points, step, np.array([], dtype=int)).shape == (0, 3)


@pytest.mark.parametrize("field", ["velocity", "acceleration", "jerk"])
def test_a_peak_at_its_limit_is_within_it_and_a_hair_over_is_not(field):
    """Independent oracle: a peak equal to its limit (to rounding, 1e-9) is within it; 3e-9 over,
    or half over, is not; a motion that starts or ends at 5 % of the acceleration limit is at rest."""
    from bidmp.tasks.contract import AT_REST, CommandPeaks

    def peaks(value, ends=0.0):
        return CommandPeaks(
            **{"velocity": 0.2, "acceleration": 0.2, "jerk": 0.2, field: value}, ends=ends
        )

    assert peaks(1.0).within and peaks(1.0 + 1e-9).within
    assert not peaks(1.0 + 3e-9).within and not peaks(1.5).within
    assert peaks(0.5, ends=AT_REST).within and not peaks(0.5, ends=AT_REST * 1.001).within
    assert AT_REST == 0.05


def test_the_worst_joint_is_the_one_with_the_largest_peak_of_any_kind():
    """Independent oracle: two joints making the same move, joint 2 with a tight speed limit
    (0.9 of it used) and loose others, joint 1 at half of every limit: joint 2 is the worst."""
    s = np.linspace(0.0, 1.0, 2001)
    q = 0.8 * (10 * s**3 - 15 * s**4 + 6 * s**5)
    speed, acceleration, jerk = 15 * 0.8 / 16, 10 * 0.8 / (math.sqrt(3) * 4), 60 * 0.8 / 8
    limits = bidmp.sim.JointLimits(
        lower=(-3.0, -3.0),
        upper=(3.0, 3.0),
        velocity=(2 * speed, speed / 0.9),
        acceleration=(2 * acceleration, 100 * acceleration),
        jerk=(2 * jerk, 100 * jerk),
    )
    peaks = command_peaks(np.column_stack([q, q]), limits, 1e-3)
    assert peaks.joint == 1 and peaks.velocity == pytest.approx(0.9, rel=2e-3)


def test_a_verdict_is_ok_only_when_every_check_that_applies_holds():
    """Independent oracle: the end within the threshold (equal is success), and each of
    engagement, clearance, alignment and limits True or not applying (None); contacts of the arm
    with another part are no clearance."""
    from bidmp.scene import Clearance
    from bidmp.tasks.contract import CommandPeaks, Verdict

    base = Verdict("3", end_error=1.0, threshold=1.0, units="mm")
    assert (
        base.reached
        and base.ok
        and base.failed == []
        and base.clear is None
        and base.within_limits is None
    )
    assert not Verdict("3", 1.0 + 1e-12, 1.0, "mm").reached
    for change, name in (
        ({"engaged": False}, "engagement"),
        ({"aligned": False, "axis_deviation": 7.0}, "alignment"),
        ({"contacts": {"plate": 0.2}}, "clearance"),
        ({"clearance": Clearance(1.0, "plate", np.zeros(3), 3.0)}, "clearance"),
        ({"limits": CommandPeaks(1.2, 0.1, 0.1)}, "limits"),
    ):
        verdict = Verdict("3", 0.5, 1.0, "mm", **change)
        assert (
            not verdict.ok
            and verdict.failed == [name]
            and verdict.reason().startswith("the motion to 3 ")
        )
    assert (
        Verdict("3", 0.5, 1.0, "mm", aligned=False).reason()
        == "the motion to 3 tilts the tool off the target's axis"
    )
    for change in (
        {"engaged": True},
        {"aligned": True},
        {"clearance": Clearance(3.0, "plate", np.zeros(3), 3.0)},
        {"limits": CommandPeaks(1.0, 0.1, 0.1)},
    ):
        assert Verdict("3", 0.5, 1.0, "mm", **change).ok


def test_the_tools_tilt_over_the_final_approach_is_the_largest_angle_below_the_band():
    """Independent oracle: a tool pointing down tilted by θ about x has its axis at angle |θ| from
    the target's −z; above the band a 30° tilt does not count, below it the largest |θ| is 6°. Along
    a target's +x axis, the same tilts turned with it give the same angles."""
    from bidmp.tasks.metrics import axis_deviation

    z = np.linspace(40.0, 0.0, 81)
    tilt = np.full(81, 30.0)  # above the band
    tilt[z < 25.0] = (
        6.0 * np.sin(np.pi * z[z < 25.0] / 25.0) ** 2 * np.where(z[z < 25.0] > 12.5, 1.0, -1.0)
    )
    half = np.radians(tilt + 180.0) / 2.0  # the tilt after half a turn about x (pointing down)
    q = np.column_stack([np.sin(half), np.zeros(81), np.zeros(81), np.cos(half)])
    path = np.column_stack([np.zeros(81), np.zeros(81), z])
    expected = np.max(np.abs(tilt[z < 25.0]))
    assert axis_deviation(path, q, np.zeros(3), 25.0) == pytest.approx(expected, abs=1e-9)
    # The same along +x: turn the world by 90° about y (z -> x); the tool's frame turns with it.
    turn = np.array([0.0, np.sin(np.pi / 4), 0.0, np.cos(np.pi / 4)])
    turned_q = np.array([_quaternion_product(turn, row) for row in q])
    turned_path = np.column_stack([z, np.zeros(81), np.zeros(81)])
    assert axis_deviation(
        turned_path, turned_q, np.zeros(3), 25.0, axis=[1.0, 0.0, 0.0]
    ) == pytest.approx(expected, abs=1e-9)
    assert math.isinf(axis_deviation(path[:30], q[:30], np.zeros(3), 25.0))  # ends above the band


def _quaternion_product(a, b):
    """Hamilton product of quaternions (x, y, z, w), written out."""
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return np.array(
        [
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz,
        ]
    )


def _frechet_by_table(a, b):
    """The discrete Fréchet distance by its defining recursion over the full table (Eiter and
    Mannila 1994), written here."""
    n, m = len(a), len(b)
    table = np.full((n, m), np.inf)
    for i in range(n):
        for j in range(m):
            d = float(np.linalg.norm(a[i] - b[j]))
            if i == 0 and j == 0:
                table[i, j] = d
            elif i == 0:
                table[i, j] = max(table[i, j - 1], d)
            elif j == 0:
                table[i, j] = max(table[i - 1, j], d)
            else:
                table[i, j] = max(min(table[i - 1, j], table[i, j - 1], table[i - 1, j - 1]), d)
    return table[-1, -1]


@pytest.mark.parametrize("seed", range(6))
def test_both_frechet_implementations_are_the_defining_recursion(seed):
    """Independent oracle: the kernel and the anti-diagonal reference equal the full-table
    recursion on random curves of unequal lengths (1 to 40 points, 1 to 3 dimensions), including
    ones whose last points decide and ones that wander."""
    from bidmp.extension.similarity import _frechet_compiled, frechet_distance_reference

    rng = np.random.default_rng(seed)
    for _ in range(8):
        n_dims = int(rng.integers(1, 4))
        a = np.cumsum(rng.normal(size=(int(rng.integers(1, 41)), n_dims)), axis=0)
        b = np.cumsum(rng.normal(size=(int(rng.integers(1, 41)), n_dims)), axis=0)
        truth = _frechet_by_table(a, b)
        assert frechet_distance(a, b) == pytest.approx(truth, rel=1e-12, abs=1e-12)
        assert frechet_distance_reference(a, b) == pytest.approx(truth, rel=1e-12, abs=1e-12)
        assert _frechet_compiled(a, b) == pytest.approx(truth, rel=1e-12, abs=1e-12)
        assert frechet_distance(b, a) == pytest.approx(truth, rel=1e-12, abs=1e-12)
        for same in (a, b):  # a curve against itself: the diagonal path, distance 0
            assert (
                frechet_distance(same, same) == 0.0
                and frechet_distance_reference(same, same) == 0.0
            )


def test_the_axis_template_scales_each_axis_and_ramps_the_ones_the_piece_barely_moves_along():
    """Independent oracle: per axis, seg + (n_tar − seg)/(tar − seg) · (piece − seg); an axis whose
    chord is under 1e-3 of the chord's length (or whose factor is over 10) instead gets the piece
    plus λ (n_tar − tar), λ the normalised arc length computed here; a closed piece (it ends where it
    starts) is ramped on every axis, with either scaling."""
    s = np.linspace(0.0, 1.0, 50)
    piece = np.column_stack(
        [100 * s, 20 * np.sin(np.pi * s), 5.0 + 0 * s]
    )  # z: the piece does not move
    new_target = np.array([160.0, -30.0, 12.0])
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(piece, axis=0), axis=1))])
    lam = arc / arc[-1]
    out = template(piece, new_target, scaling="axis")
    np.testing.assert_allclose(out[:, 0], 1.6 * piece[:, 0], atol=1e-9)
    np.testing.assert_allclose(
        out[:, 1], piece[:, 1] + lam * (-30.0 - piece[-1, 1]), atol=1e-9
    )  # y: chord ~0
    np.testing.assert_allclose(out[:, 2], 5.0 + lam * 7.0, atol=1e-9)
    steep = piece.copy()
    steep[:, 1] = (
        20 * np.sin(np.pi * s) + 2.0 * s
    )  # y chord 2: factor (-30 - 0)/2 = -15, over 10: ramped
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(steep, axis=0), axis=1))])
    out = template(steep, new_target, scaling="axis")
    np.testing.assert_allclose(out[:, 1], steep[:, 1] + arc / arc[-1] * (-30.0 - 2.0), atol=1e-9)
    loop = np.column_stack([30 * np.sin(2 * np.pi * s), 30 * (1 - np.cos(2 * np.pi * s)), 0 * s])
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(loop, axis=0), axis=1))])
    for scaling in ("axis", "similarity"):
        np.testing.assert_allclose(
            template(loop, [10.0, 5.0, 2.0], scaling=scaling),
            loop + (arc / arc[-1])[:, None] * np.array([10.0, 5.0, 2.0]),
            atol=1e-9,
        )
    # In metres (shorter than 1 in all), pausing at its start: λ is still the arc length's share.
    short = np.vstack([piece[:1], piece]) / 1000.0
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(short, axis=0), axis=1))])
    out = template(short, new_target / 1000.0, scaling="axis")
    np.testing.assert_allclose(out[:, 2], short[:, 2] + arc / arc[-1] * 0.007, atol=1e-12)
    for offset in (
        [1e4, 1e4, 0.0],
        [-1e4, -1e4, 0.0],
    ):  # closed to rounding (1e-10) far from the origin
        far_loop = loop + offset
        far_loop[-1] += 1e-10
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(far_loop, axis=0), axis=1))])
        np.testing.assert_allclose(
            template(far_loop, far_loop[0] + [10.0, 5.0, 2.0], scaling="similarity"),
            far_loop + (arc / arc[-1])[:, None] * (far_loop[0] + [10.0, 5.0, 2.0] - far_loop[-1]),
            atol=1e-7,
        )
    waits = np.array(
        [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0], [10.0, 0.0, 0.0]]
    )  # one step, at the end
    np.testing.assert_allclose(
        template(waits, [20.0, 5.0, 0.0])[:, 1], [0.0, 0.0, 0.0, 5.0], atol=1e-12
    )
    still = np.tile([3.0, 4.0, 5.0], (5, 1))  # no length at all: λ by sample
    np.testing.assert_allclose(
        template(still, [7.0, 4.0, 5.0]),
        still + np.linspace(0, 1, 5)[:, None] * [4.0, 0, 0],
        atol=1e-12,
    )


@pytest.mark.parametrize("direction", [1.0, -1.0, 0.5])
def test_a_similarity_template_along_or_against_its_chord_keeps_the_shape(direction):
    """Property: a similarity template is the piece turned and scaled — all pairwise distances
    times the chord ratio — also when the new chord points the same way (no turn) or the opposite
    way (half a turn, a special case of the rotation), and it ends on the new target."""
    from scipy.spatial.distance import pdist

    s = np.linspace(0.0, 1.0, 40)[:, None]
    piece = s * np.array([80.0, 30.0, -10.0]) + np.sin(np.pi * s) * np.array([0.0, 15.0, 25.0])
    new_target = piece[0] + direction * 1.7 * (piece[-1] - piece[0])
    out = template(piece, new_target, scaling="similarity")
    np.testing.assert_allclose(pdist(out), 1.7 * abs(direction) * pdist(piece), rtol=1e-9)
    np.testing.assert_allclose(out[-1], new_target, atol=1e-9)
    if direction > 0:
        np.testing.assert_allclose(out, piece[0] + 1.7 * direction * (piece - piece[0]), atol=1e-9)


# -- segmentation ---------------------------------------------------------------------------------
def _documented_curvature(y, smooth=0.05, smooth_curvature=0.03):
    """The documented procedure, written out from the docstring: Savitzky–Golay first and second
    derivatives (order 3) over an odd window of round(smooth T) samples (at least 7, at most T),
    κ = ‖r′ × r″‖ / ‖r′‖³, then κ smoothed (order 2) over round(smooth_curvature T) (at least 5),
    clipped at 0."""
    from scipy.signal import savgol_filter

    def odd(fraction, n, least):
        window = max(int(round(fraction * n)), least)
        window = window if window % 2 else window + 1
        return min(window, n if n % 2 else n - 1)

    n = y.shape[0]
    first = savgol_filter(y, odd(smooth, n, 7), 3, deriv=1, axis=0)
    second = savgol_filter(y, odd(smooth, n, 7), 3, deriv=2, axis=0)
    kappa = np.linalg.norm(np.cross(first, second), axis=1) / np.linalg.norm(first, axis=1) ** 3
    window = odd(smooth_curvature, n, 5)
    return np.maximum(savgol_filter(kappa, window, 2) if window > 3 else kappa, 0.0)


@pytest.mark.parametrize(
    "n_points, smooth, smooth_curvature",
    [(400, 0.05, 0.03), (120, 0.1, 0.08), (57, 0.02, 0.01), (2000, 0.05, 0.03)],
)
def test_curvature_is_the_documented_smoothing_of_the_closed_form(
    n_points, smooth, smooth_curvature
):
    """Independent oracle: on a helix (κ = r / (r² + c²)) the curvature is the closed form inside
    the curve, and everywhere it is the documented procedure written out in the test."""
    from bidmp.extension.segmentation import curvature

    radius, pitch = 40.0, 15.0
    t = np.linspace(0.0, 3 * np.pi, n_points)
    helix = np.column_stack(
        [radius * np.cos(t), radius * np.sin(t), pitch * t]
    )  # even in arc length
    kappa = curvature(helix, smooth, smooth_curvature)
    np.testing.assert_allclose(
        kappa, _documented_curvature(helix, smooth, smooth_curvature), rtol=1e-9, atol=1e-12
    )
    inside = slice(n_points // 10, -n_points // 10)
    # a cubic fit over a window of 5-10 % of the helix (0.5-0.9 rad of turn) reads 0.4-1.8 % low
    np.testing.assert_allclose(kappa[inside], radius / (radius**2 + pitch**2), rtol=3e-2)
    rng = np.random.default_rng(n_points)
    wiggly = np.cumsum(rng.normal(size=(n_points, 3)), axis=0)
    np.testing.assert_allclose(
        curvature(wiggly, smooth, smooth_curvature),
        _documented_curvature(wiggly, smooth, smooth_curvature),
        rtol=1e-9,
        atol=1e-12,
    )
    flat = curvature(wiggly[:, :2], smooth, smooth_curvature)  # a 2-D curve is the z = 0 curve
    padded = np.column_stack([wiggly[:, :2], np.zeros(n_points)])
    np.testing.assert_allclose(
        flat, _documented_curvature(padded, smooth, smooth_curvature), rtol=1e-9, atol=1e-12
    )


def test_curvature_where_the_curve_stops_is_zero_and_a_tiny_curve_has_none():
    """Independent oracle: samples where the curve does not advance have κ = 0 (not inf); a
    curve shorter than the smallest window has no curvature to estimate."""
    from bidmp.extension.segmentation import curvature

    still = np.tile([1.0, 2.0, 3.0], (30, 1))
    assert curvature(still).tolist() == [0.0] * 30
    rng = np.random.default_rng(1)  # held still far from the origin, jittering by rounding (1e-14)
    for centre in ([0.0, -1000.0, -5.0], [0.0, 1000.0, 5.0]):
        jittered = np.array(centre) * (1.0 + 1e-14 * rng.standard_normal((30, 3)))
        assert curvature(jittered).tolist() == [0.0] * 30
    # A path that stops for 120 samples between two arcs: inside the pause (a smoothing window from
    # its ends) the curve does not advance and has no curvature.
    t = np.linspace(0.0, np.pi / 2, 100)
    arc = np.column_stack([50 * np.cos(t), 50 * np.sin(t), np.zeros(100)])
    paused = np.vstack(
        [arc, np.tile(arc[-1], (120, 1)), arc[-1] + (arc - arc[0])[::-1] * [-1, 1, 1]]
    )
    kappa = curvature(paused)
    window = 17  # 5 % of 320 samples, odd
    assert np.all(kappa[100 + window : 220 - window] == 0.0)
    assert np.all(kappa[20:80] > 0.01)
    assert curvature(np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0]])).tolist() == [0.0, 0.0, 0.0]


def _extrema_by_runs(kappa, low, high):
    """Interior local extrema of kappa[low:high], a plateau counted once at its middle sample:
    runs of equal values, a run higher than both neighbours a maximum, lower a minimum."""
    segment = list(kappa[low:high])
    runs = []
    for index, value in enumerate(segment):
        if runs and runs[-1][0] == value:
            runs[-1][2] = index
        else:
            runs.append([value, index, index])
    indices, types = [], []
    for previous, (value, first, last), following in zip(runs, runs[1:], runs[2:]):
        kind = (
            1
            if previous[0] < value > following[0]
            else -1
            if previous[0] > value < following[0]
            else 0
        )
        if kind:
            indices.append(low + (first + last) // 2)
            types.append(kind)
    return indices, types


@pytest.mark.parametrize("seed", range(6))
def test_curvature_extrema_are_the_runs_higher_or_lower_than_both_neighbours(seed):
    """Independent oracle: extrema found by comparing runs of equal values with their
    neighbours, written here, on random sequences full of plateaus, in random windows."""
    from bidmp.extension.segmentation import _alternating_extrema

    flat = _alternating_extrema(np.full(10, 2.0), 0, 10)
    assert flat[0].tolist() == [] and flat[1].tolist() == []
    rng = np.random.default_rng(seed)
    for _ in range(50):
        kappa = rng.integers(0, 4, int(rng.integers(3, 40))).astype(float)
        low = int(rng.integers(0, 3))
        high = int(rng.integers(low, kappa.size + 1))
        indices, types = _alternating_extrema(kappa, low, high)
        expected = _extrema_by_runs(kappa, low, high) if high - low >= 3 else ([], [])
        assert (indices.tolist(), types.tolist()) == expected, (kappa, low, high)
        assert all(a != b for a, b in zip(types, types[1:]))  # they alternate


def _prune_by_hand(values, epsilon):
    """The persistence rule written out: cancel the adjacent pair with the smallest difference
    (the leftmost of equals) while it is below epsilon."""
    kept = list(range(len(values)))
    while len(kept) >= 2:
        gaps = [abs(values[b] - values[a]) for a, b in zip(kept, kept[1:])]
        smallest = min(gaps)
        if smallest >= epsilon:
            break
        pair = gaps.index(smallest)
        del kept[pair : pair + 2]
    return kept


def _paper_by_hand(types, values, epsilon):
    """The paper's rule written out: walk the sequence; a maximum followed by a minimum closer
    than epsilon in curvature is dropped, the pair is skipped either way; anything else steps one."""
    keep, position = [True] * len(types), 0
    while position + 1 < len(types):
        if types[position] == 1 and types[position + 1] == -1:
            if abs(values[position] - values[position + 1]) < epsilon:
                keep[position] = keep[position + 1] = False
            position += 2
        else:
            position += 1
    return [i for i in range(len(types)) if keep[i]]


@pytest.mark.parametrize("seed", range(6))
def test_both_pruning_rules_are_their_written_out_loops(seed):
    """Independent oracle: the heap-based persistence pruning and the paper's rule against loops
    written here, on random alternating sequences with ties (integer curvatures), epsilon on a
    tie too."""
    from bidmp.extension.segmentation import _prune_paper, _prune_persistence

    rng = np.random.default_rng(seed)
    for _ in range(60):
        count = int(rng.integers(0, 14))
        types = np.where(np.arange(count) % 2 == int(rng.integers(2)), 1, -1)
        values = rng.integers(0, 6, count).astype(float)
        kappa = np.zeros(count + 5)
        indices = np.sort(rng.choice(count + 5, count, replace=False))
        kappa[indices] = values
        epsilon = float(rng.integers(0, 4))
        kept, kinds = _prune_persistence(indices, types, kappa, epsilon)
        expected = _prune_by_hand(values, epsilon)
        assert (
            kept.tolist() == indices[expected].tolist()
            and kinds.tolist() == types[expected].tolist()
        )
        kept, kinds = _prune_paper(indices, types, kappa, epsilon)
        expected = _paper_by_hand(types, values, epsilon)
        assert (
            kept.tolist() == indices[expected].tolist()
            and kinds.tolist() == types[expected].tolist()
        )


# -- the Broad Learning System --------------------------------------------------------------------
@pytest.mark.parametrize("reg", [1e-6, 0.0])
def test_a_bls_is_its_documented_forward_pass_and_output_solve(reg):
    """Independent oracle: with the fitted weights, the hidden layer is [Z | H] written out:
    Z_i = ([X, 0.1] W_Z,i − min) / range (each node spanning exactly [0, 1] on the training
    inputs), H = tanh(s [Z, 0.1] W_H) with s = shrink / max|[Z, 0.1] W_H| and W_H orthonormal; the
    output weights are the ridge solution (AᵀA + λI)⁻¹AᵀY, or numpy.linalg.pinv(A) Y at λ = 0;
    predictions are A W. Inputs of 4 columns with 3 nodes per window (no shape coincides)."""
    rng = np.random.default_rng(7)
    X, Y = rng.normal(size=(70, 4)), rng.normal(size=(70, 2))
    model = bidmp.BLS(n_windows=2, n_mapped=3, n_enhance=9, shrink=0.7, reg=reg, seed=5).fit(X, Y)
    with_bias = np.hstack([X, np.full((70, 1), 0.1)])
    Z = np.hstack([with_bias @ model.mapping_weights_[i] for i in range(2)])
    Z = (Z - model.mapping_min_) / model.mapping_range_
    np.testing.assert_allclose(Z.min(axis=0), 0.0, atol=1e-12)
    np.testing.assert_allclose(Z.max(axis=0), 1.0, atol=1e-12)
    weights = model.enhancement_weights_[0]
    assert weights.shape == (7, 9)
    pre = np.hstack([Z, np.full((70, 1), 0.1)]) @ weights
    assert model.enhancement_scales_[0] == pytest.approx(0.7 / np.abs(pre).max(), rel=1e-12)
    A = np.hstack([Z, np.tanh(model.enhancement_scales_[0] * pre)])
    np.testing.assert_allclose(model.hidden(X), A, atol=1e-12)
    np.testing.assert_allclose(weights @ weights.T, np.eye(7), atol=1e-12)  # wide: orthonormal rows
    if reg > 0:
        expected = np.linalg.solve(A.T @ A + reg * np.eye(A.shape[1]), A.T @ Y)
    else:
        expected = np.linalg.pinv(A) @ Y
    np.testing.assert_allclose(model.output_weights_, expected, rtol=1e-6, atol=1e-8)
    np.testing.assert_allclose(model.predict(X), A @ model.output_weights_, atol=1e-10)
    fresh = rng.normal(size=(5, 4))
    fresh_with_bias = np.hstack([fresh, np.full((5, 1), 0.1)])
    Z_fresh = (
        np.hstack([fresh_with_bias @ model.mapping_weights_[i] for i in range(2)])
        - model.mapping_min_
    ) / model.mapping_range_
    H_fresh = np.tanh(
        model.enhancement_scales_[0] * np.hstack([Z_fresh, np.full((5, 1), 0.1)]) @ weights
    )
    np.testing.assert_allclose(
        model.predict(fresh), np.hstack([Z_fresh, H_fresh]) @ model.output_weights_, atol=1e-10
    )


def test_a_bls_learns_its_mapped_features_by_the_sparse_autoencoder_of_its_seeded_projections():
    """Independent oracle of the fit (Chen & Liu 2018, as documented): window i projects [X, 0.1]
    by a matrix uniform in [−1, 1] drawn from default_rng([seed, 0, i]), min–max normalises it to
    F_i, and W_Z,i is the sparse autoencoder's answer for F_i → [X, 0.1] (its lasso is checked in
    test_bls); an added enhancement block is a new draw, not the first block again."""
    from bidmp.incremental.linalg import sparse_autoencoder

    rng = np.random.default_rng(3)
    X, Y = rng.normal(size=(50, 2)), rng.normal(size=(50, 1))
    model = bidmp.BLS(
        n_windows=3, n_mapped=4, n_enhance=6, reg=1e-6, l1=1e-3, admm_iterations=30, seed=11
    ).fit(X, Y)
    with_bias = np.hstack([X, np.full((50, 1), 0.1)])
    for window in range(3):
        projection = with_bias @ np.random.default_rng([11, 0, window]).uniform(
            -1.0, 1.0, size=(3, 4)
        )
        F = (projection - projection.min(axis=0)) / np.ptp(projection, axis=0)
        expected = sparse_autoencoder(F, with_bias, 1e-3, 30).T
        np.testing.assert_allclose(model.mapping_weights_[window], expected, rtol=1e-10, atol=1e-12)
    model.add_enhancement_nodes(6)
    assert not np.allclose(model.enhancement_weights_[1], model.enhancement_weights_[0])
    # Small inputs (projections spanning less than 1) are normalised all the same.
    small = X * 0.01
    model = bidmp.BLS(
        n_windows=1, n_mapped=4, n_enhance=6, reg=1e-6, l1=1e-6, admm_iterations=30, seed=11
    ).fit(small, Y)
    small_with_bias = np.hstack([small, np.full((50, 1), 0.1)])
    projection = small_with_bias @ np.random.default_rng([11, 0, 0]).uniform(-1.0, 1.0, size=(3, 4))
    assert np.ptp(projection, axis=0).max() < 1.0
    F = (projection - projection.min(axis=0)) / np.ptp(projection, axis=0)
    np.testing.assert_allclose(
        model.mapping_weights_[0],
        sparse_autoencoder(F, small_with_bias, 1e-6, 30).T,
        rtol=1e-10,
        atol=1e-12,
    )
    # A sparsity weight so large that every mapped node is 0: constant nodes stay 0, not 0/0.
    flat = bidmp.BLS(n_windows=1, n_mapped=4, n_enhance=6, reg=1e-6, l1=1e6, seed=11).fit(X, Y)
    assert np.all(flat.mapping_weights_[0] == 0.0) and np.all(flat.mapping_range_ == 1.0)
    assert np.all(flat.hidden(X)[:, :4] == 0.0) and np.all(np.isfinite(flat.predict(X)))
    # Inputs that never change: every projection is constant, and the fit stays finite.
    same = bidmp.BLS(n_windows=1, n_mapped=4, n_enhance=6, reg=1e-6, seed=11).fit(
        np.ones((50, 2)), Y
    )
    assert np.all(np.isfinite(same.predict(np.ones((3, 2)))))


def test_a_tool_turning_past_a_block_is_checked_at_its_nearest_mid_turn_attitude():
    """Property: a turn given by its two end attitudes (quaternions unnormalised too) is judged as
    the same turn given by 2001 attitudes written out here: within the documented step / 2. The
    block sits beyond the tool's end at mid-turn (45°), 4.7 mm away; at both ends it is 68 mm away,
    so a check that places the turning tool too sparsely sees 68."""
    length, radius = 100.0, 6.0
    centre = np.array([0.0, -np.sin(np.pi / 4), np.cos(np.pi / 4)]) * length * 1.12
    scene = Scene.from_dict(
        {
            "tool": {"radius": radius, "length": length},
            "parts": [
                {
                    "type": "box",
                    "label": "block",
                    "at": (centre - [0, 0, 5]).tolist(),
                    "size": [10, 10, 10],
                }
            ],
        }
    )

    def attitude(angle):  # pointing down (half a turn about x), then turned by angle about x
        half = (angle + np.pi) / 2.0
        return np.array([np.sin(half), 0.0, 0.0, np.cos(half)])

    angles = np.linspace(0.0, np.pi / 2, 2001)
    dense = scene.clearance(
        np.zeros((2001, 3)), orientations=np.array([attitude(a) for a in angles])
    ).distance
    step = 0.002 * length
    ends = np.array([attitude(0.0), attitude(np.pi / 2)])
    moving = np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 3.0]])  # rising 3 mm as it turns: nearer still
    for points, turns in ((np.zeros((2, 3)), ends), (np.zeros((2, 3)), 2.5 * ends)):
        found = scene.clearance(points, orientations=turns)
        assert dense - step / 2.0 - 1e-6 <= found.distance <= dense + 1e-6
        assert found.distance < 5.0
    rising = scene.clearance(moving, orientations=ends).distance
    assert rising < dense - 1.0
    # Turning there and back, the way back at the block: the way out turns 300 mm away from it.
    there_and_back = np.array([attitude(0.0), attitude(np.pi / 2), attitude(0.0)])
    tips = np.array([[-300.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])
    found = scene.clearance(tips, orientations=there_and_back)
    assert dense - step / 2.0 - 1e-6 <= found.distance <= dense + 1e-6
    # Three attitudes, each segment turning its own way (−30° → 0° → 90°): the second passes 45°.
    three = np.array([attitude(-np.pi / 6), attitude(0.0), attitude(np.pi / 2)])
    found = scene.clearance(np.zeros((3, 3)), orientations=three)
    assert dense - step / 2.0 - 1e-6 <= found.distance <= dense + 1e-6


def test_a_separation_is_kept_only_when_the_nearest_points_are_that_far_apart():
    """Structure guard of the check on coal's answers: a separation whose nearest points lie on
    the shapes as far apart as it says is kept; the same points offered for a larger or a smaller
    separation are not (coal's known failure: a distance between points off the shapes)."""
    scene = Scene.from_dict(
        {
            "tool": {"radius": 5.0, "length": 50.0},
            "parts": [
                {"type": "box", "label": "box", "at": [0.0, 0.0, 0.0], "size": [20.0, 20.0, 20.0]}
            ],
        }
    )
    engine = scene._engine()
    distance = engine.tool_to(np.array([0.0, 0.0, 32.0]), 0)  # 12 above the box's top
    assert distance == pytest.approx(12.0, abs=1e-8)
    tool_pose = engine.coal.Transform3s(np.eye(3), np.array([0.0, 0.0, 32.0]) + engine.tool_offset)
    shape, pose = engine.shapes[0]
    assert engine._witnessed(engine.tool, tool_pose, shape, pose, distance)
    for claimed in (15.0, 9.0):
        assert not engine._witnessed(engine.tool, tool_pose, shape, pose, claimed)
    # The tolerance is 1e-6 of the distance (of 1 below 1): 12 ± 1e-5 is borne out, 12 ± 1.5e-5 not.
    for claimed, kept in (
        (distance + 1e-5, True),
        (distance - 1e-5, True),
        (distance + 1.5e-5, False),
    ):
        assert engine._witnessed(engine.tool, tool_pose, shape, pose, claimed) is kept
    near = engine.tool_to(np.array([0.0, 0.0, 21.5]), 0)  # 1.5 above: the tolerance is 1.5e-6
    near_pose = engine.coal.Transform3s(np.eye(3), np.array([0.0, 0.0, 21.5]) + engine.tool_offset)
    assert engine._witnessed(engine.tool, near_pose, shape, pose, near + 1.2e-6)
    assert not engine._witnessed(engine.tool, near_pose, shape, pose, near + 1.8e-6)


# -- goal systems ---------------------------------------------------------------------------------
def test_the_smoothstep_is_its_polynomial_with_flat_ends():
    """Independent oracle: S(u) = 35u⁴ − 84u⁵ + 70u⁶ − 20u⁷ on [0, 1] (0 before, 1 after), its
    derivatives those of the polynomial, zero at both ends."""
    from bidmp.primitives.goals import _smoothstep, _smoothstep_derivatives

    u = np.linspace(-0.2, 1.2, 141)
    inside = np.clip(u, 0.0, 1.0)
    np.testing.assert_allclose(
        _smoothstep(u),
        35 * inside**4 - 84 * inside**5 + 70 * inside**6 - 20 * inside**7,
        atol=1e-14,
    )
    first, second = _smoothstep_derivatives(u)
    within = (u > 0) & (u < 1)
    np.testing.assert_allclose(
        first[within], (140 * u**3 - 420 * u**4 + 420 * u**5 - 140 * u**6)[within], atol=1e-12
    )
    np.testing.assert_allclose(
        second[within], (420 * u**2 - 1680 * u**3 + 2100 * u**4 - 840 * u**5)[within], atol=1e-11
    )
    assert np.all(first[~within] == 0.0) and np.all(second[~within] == 0.0)
    assert _smoothstep(np.array([0.5]))[0] == pytest.approx(0.5)


@pytest.mark.parametrize("begin", [0.0, 0.3])
def test_the_goal_share_follows_the_progress_with_smooth_ends(begin):
    """Independent oracle: R = σ S((t − b)/w) over the first w after b, 1 − (1 − σ) S((T − t)/w)
    over the last w, σ between, 1 from T on (w = 15 % of T − b), written out here."""
    from bidmp.primitives.goals import _goal_share

    n_motion, dt, n_total = 120, 0.01, 150
    progress = np.clip(np.linspace(-0.1, 1.1, n_total), 0.0, 1.0) ** 1.5
    share = _goal_share(progress, n_motion, dt, begin=begin)
    t = np.arange(n_total) * dt
    end = (n_motion - 1) * dt
    width = 0.15 * (end - begin)

    def smooth(u):
        u = np.clip(u, 0.0, 1.0)
        return 35 * u**4 - 84 * u**5 + 70 * u**6 - 20 * u**7

    expected = progress * smooth((t - begin) / width)
    closing = t > end - width
    expected[closing] = 1.0 - (1.0 - progress[closing]) * smooth((end - t[closing]) / width)
    expected[t >= end] = 1.0
    np.testing.assert_allclose(share, expected, atol=1e-12)
    assert np.all(share[t <= begin] == 0.0)


def test_the_goal_gate_is_the_springs_inverse_for_the_share():
    """Independent oracle: for a share R with known derivatives, G = (αβ (1 − R) − R'' − α R') / K
    from the analytic R', R'' (the library differentiates numerically: within 2e-3 of the
    drive's scale), and exactly αβ / K at the start."""
    from bidmp.primitives.goals import _goal_gate

    alpha, beta, K, dt = 25.0, 6.25, 25.0 * 6.25, 1e-3
    t = np.arange(0.0, 1.0 + dt / 2, dt)
    share = 0.5 - 0.5 * np.cos(np.pi * t)
    rate, curvature = 0.5 * np.pi * np.sin(np.pi * t), 0.5 * np.pi**2 * np.cos(np.pi * t)
    gate = _goal_gate(share, dt, alpha=alpha, beta=beta, K=K)
    expected = (alpha * beta * (1.0 - share) - curvature - alpha * rate) / K
    assert gate[0] == alpha * beta / K
    np.testing.assert_allclose(
        gate[2:-2], expected[2:-2], atol=2e-3 * alpha * beta / K
    )  # central differences


@pytest.mark.parametrize("exact", [True, False])
def test_a_delayed_goal_decays_at_its_own_rate(exact):
    """Independent oracle: G_l = exp(−r l h / τ) (exact) or (1 − r h / τ)^l (Euler) on a grid of
    step h; one control step multiplies by the same factor; the phase gate is the phase."""
    from bidmp.primitives.goals import DelayedGoal, PhaseGate

    rate, step, tau = 3.0, 0.01, 1.7
    goal = DelayedGoal(rate)
    factor = math.exp(-rate * step / tau) if exact else 1.0 - rate * step / tau
    grid = goal.on_grid(np.linspace(1.0, 0.2, 40), step, tau, exact)
    np.testing.assert_allclose(grid, factor ** np.arange(40), rtol=1e-12)
    assert goal.follow(0.6, 0.5, step, tau, exact) == pytest.approx(0.6 * factor, rel=1e-12)
    phase = np.linspace(1.0, 0.2, 40)
    assert PhaseGate(rate).on_grid(phase, step, tau, exact).tolist() == phase.tolist()
    assert PhaseGate(rate).follow(0.6, 0.37, step, tau, exact) == 0.37
    # the stepper's unchecked call gives the same value; the public one refuses bad input by name
    assert goal.follow(0.6, 0.5, step, tau, exact, check_input=False) == goal.follow(
        0.6, 0.5, step, tau, exact
    )
    for bad, name in (((math.nan, 0.5), "gate"), ((0.6, 1.5), "phase")):
        with pytest.raises(ValueError, match=name):
            goal.follow(*bad, step, tau, exact)
    with pytest.raises(TypeError, match="check_input"):
        goal.follow(0.6, 0.5, step, tau, exact, check_input="no")


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_the_measured_joints_peaks_are_a_quintics_closed_forms(sign):
    """Independent oracle: a joint moving a minimum-jerk A over T, its velocity recorded every
    2 ms: peak speed 15A/(8T) as recorded, acceleration 10A/(√3 T²) and jerk 60A/T³ estimated by
    differences over 10 ms windows, as fractions of the limits, either direction;
    a joint with no jerk limit is not judged on jerk."""
    from bidmp.sim.limits import _measured_peaks

    amplitude, duration, step = 0.9, 2.0, 0.002
    t = np.arange(0.0, duration + step / 2, step) / duration
    velocity = sign * amplitude / duration * (30 * t**2 - 60 * t**3 + 30 * t**4)
    recorded = np.column_stack([velocity, 0.5 * velocity])
    limits = bidmp.sim.JointLimits(
        lower=(-3.0, -3.0),
        upper=(3.0, 3.0),
        velocity=(2.0, 2.0),
        acceleration=(4.0, 4.0),
        jerk=(50.0, 50.0),
    )
    peaks = _measured_peaks(recorded, step, limits)
    assert peaks.velocity == pytest.approx(15 * amplitude / (8 * duration) / 2.0, rel=1e-6)
    assert peaks.acceleration == pytest.approx(
        10 * amplitude / (math.sqrt(3) * duration**2) / 4.0, rel=1e-2
    )
    # the first jerk estimate is centred 10 ms in, where it is 60A/T³ (1 − 6u + 6u²), u = 0.005
    u = 0.01 / duration
    assert peaks.jerk == pytest.approx(
        60 * amplitude / duration**3 * (1 - 6 * u + 6 * u**2) / 50.0, rel=2e-3
    )
    loose = bidmp.sim.JointLimits(
        lower=(-3.0, -3.0),
        upper=(3.0, 3.0),
        velocity=(2.0, 2.0),
        acceleration=(4.0, 4.0),
        jerk=None,
    )
    assert _measured_peaks(recorded, step, loose).jerk == 0.0
    # A short recording: one sample has no acceleration; two windows' worth one (its difference).
    one = _measured_peaks(recorded[:1], step, limits)
    assert (one.acceleration, one.jerk) == (0.0, 0.0)
    two = _measured_peaks(
        np.array([[0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.0], [0.2, 0.0]]),
        step,
        limits,
    )
    assert (
        two.acceleration == pytest.approx(0.2 / 0.01 / 4.0)
        and two.jerk == 0.0
        and two.velocity == pytest.approx(0.1)
    )


def test_the_end_error_is_the_last_samples_distance():
    """Independent oracle: the end error is the distance of the last sample alone (the one before
    it is farther)."""
    from bidmp.tasks.metrics import endpoint_error

    path = np.array([[0.0, 0.0, 0.0], [3.0, 4.0, 12.0], [1.0, 2.0, 2.0]])
    assert endpoint_error(path, [1.0, 0.0, 0.0]) == pytest.approx(math.sqrt(8.0))


def test_the_tools_tilt_is_measured_about_every_axis_and_survives_rounding():
    """Independent oracle: a tool pointing down and tilted by θ about y, over a final approach
    offset sideways in x and y, is |θ| off the default +z axis; a tool spun about its own axis
    (whose unit axis rounds to 1 + 2e-16 in its cosine) is 0° off, and one pointing straight up,
    spun, is 180° off — not NaN."""
    from scipy.spatial.transform import Rotation

    from bidmp.tasks.metrics import axis_deviation

    z = np.linspace(40.0, 0.0, 41)
    path = np.column_stack([np.full(41, 7.0), np.full(41, -3.0), z])
    tilt = np.where(z < 25.0, 4.0 * np.sin(np.pi * z / 25.0), 20.0)
    q = (
        Rotation.from_euler("y", tilt[:, None], degrees=True)
        * Rotation.from_quat([1.0, 0.0, 0.0, 0.0])
    ).as_quat()
    assert axis_deviation(path, q, [7.0, -3.0, 0.0], 25.0) == pytest.approx(
        np.max(np.abs(tilt[z < 25.0])), abs=1e-9
    )
    spins = np.linspace(0.0, 2 * np.pi, 4001)
    down = [
        (Rotation.from_euler("z", a) * Rotation.from_quat([1.0, 0.0, 0.0, 0.0])).as_quat()
        for a in spins
    ]
    rounding_up = next(
        q for q in down if Rotation.from_quat(q).apply([0.0, 0.0, 1.0]) @ [0.0, 0.0, -1.0] > 1.0
    )
    assert axis_deviation(path, np.tile(rounding_up, (41, 1)), [7.0, -3.0, 0.0], 25.0) == 0.0
    up = [Rotation.from_euler("z", a).as_quat() for a in spins]
    rounding_down = next(
        q for q in up if Rotation.from_quat(q).apply([0.0, 0.0, 1.0]) @ [0.0, 0.0, -1.0] < -1.0
    )
    assert axis_deviation(path, np.tile(rounding_down, (41, 1)), [7.0, -3.0, 0.0], 25.0) == 180.0


def test_the_axis_template_scales_negative_chords_and_ramps_by_the_documented_thresholds():
    """Independent oracle: an axis moving backwards is scaled like any other; an axis whose chord
    is under 1e-3 of the chord's length is ramped even when its factor would be small; a factor of
    exactly 10 is still scaled, 10.5 is ramped."""
    s = np.linspace(0.0, 1.0, 30)
    bump = np.sin(np.pi * s)
    piece = np.column_stack([-100 * s, 0.05 * s + 3 * bump, 2 * s + bump])  # y: chord 0.05 (< 0.1)
    for new_z, scaled in ((20.0, True), (21.0, False)):
        out = template(piece, [-160.0, 0.4, new_z], scaling="axis")
        arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(piece, axis=0), axis=1))])
        lam = arc / arc[-1]
        np.testing.assert_allclose(out[:, 0], 1.6 * piece[:, 0], atol=1e-9)
        np.testing.assert_allclose(out[:, 1], piece[:, 1] + lam * (0.4 - piece[-1, 1]), atol=1e-9)
        z = new_z / 2.0 * piece[:, 2] if scaled else piece[:, 2] + lam * (new_z - piece[-1, 2])
        np.testing.assert_allclose(out[1:-1, 2], z[1:-1], atol=1e-9)


def test_a_half_turn_template_turns_in_the_plane_of_the_least_aligned_axis():
    """Independent oracle: when the new chord points against the old one, the template is the
    piece turned half a turn in the plane of the chord and the coordinate axis least aligned with
    it (|component| smallest), scaled: the direction normal to that plane keeps its sign. In 1-D
    it is the mirror image; a new chord of length exactly 1 turns like any other."""
    s = np.linspace(0.0, 1.0, 25)[:, None]
    chord = np.array([-0.8, 0.6, 0.0]) * 50.0  # least aligned: z
    normal = np.cross(chord / 50.0, [0.0, 0.0, 1.0])
    piece = s * chord + np.sin(np.pi * s) * (10.0 * normal + np.array([0.0, 0.0, 7.0]))
    out = template(piece, -0.5 * chord, scaling="similarity")
    np.testing.assert_allclose(
        (out - piece[0]) @ normal, 0.5 * (piece - piece[0]) @ normal, atol=1e-9
    )
    np.testing.assert_allclose(
        (out - piece[0]) @ chord, -0.5 * (piece - piece[0]) @ chord, atol=1e-9
    )
    np.testing.assert_allclose(
        out[:, 2], -0.5 * piece[:, 2], atol=1e-9
    )  # in the plane: turned over
    line = np.linspace(0.0, 10.0, 11)[:, None] + 0.5 * np.sin(np.linspace(0, np.pi, 11))[:, None]
    np.testing.assert_allclose(
        template(line, [-5.0], scaling="similarity"), -0.5 * line, atol=1e-12
    )
    unit = template(
        piece, piece[0] + [0.0, 1.0, 0.0], scaling="similarity"
    )  # a new chord exactly 1 long
    from scipy.spatial.distance import pdist

    np.testing.assert_allclose(pdist(unit), pdist(piece) / 50.0, rtol=1e-9)
    np.testing.assert_allclose(
        unit[-2] - unit[0],
        (piece[-2] - piece[0]) @ _rodrigues(chord, [0.0, 1.0, 0.0]).T / 50.0,
        atol=1e-9,
    )


def _segment_by_hand(y, eps_frac, method):
    """1D-SEG as the module documents it, the wiring written out here (its parts — curvature,
    extrema, pruning — are checked against their own oracles above): resample to min(T, 4096)
    points equally spaced in arc length, curvature, extrema on the interior 5 % … 95 %, prune with
    ε = eps_frac (max − min) of the interior's curvature, map each kept point to the original sample
    nearest in arc length (the earlier one on a tie), one point per sample."""
    from bidmp.extension.segmentation import (
        _alternating_extrema,
        _prune_paper,
        _prune_persistence,
        curvature,
    )

    steps = np.linalg.norm(np.diff(y, axis=0), axis=1)
    s = np.concatenate([[0.0], np.cumsum(steps)])
    n = min(len(y), 4096)
    moving = np.concatenate([[True], steps > 0])
    targets = np.linspace(0.0, s[-1], n)
    resampled = np.column_stack([np.interp(targets, s[moving], column) for column in y[moving].T])
    resampled[0], resampled[-1] = y[0], y[-1]
    kappa = curvature(resampled)
    low, high = int(np.ceil(0.05 * (n - 1))), int(np.floor(0.95 * (n - 1))) + 1
    interior = kappa[low:high]
    if np.max(interior) * s[-1] < 1e-6:
        return [], []
    indices, types = _alternating_extrema(kappa, low, high)
    epsilon = eps_frac * (np.max(interior) - np.min(interior))
    kept, kinds = (_prune_persistence if method == "persistence" else _prune_paper)(
        indices, types, kappa, epsilon
    )
    points, point_kinds = [], []
    for index, kind in zip(kept, kinds):
        position = index / (n - 1) * s[-1]
        distance = np.abs(s - position)
        nearest = int(np.flatnonzero(distance == distance.min())[0])
        if nearest not in points:
            points.append(nearest)
            point_kinds.append(int(kind))
    order = np.argsort(points)
    return [points[i] for i in order], [point_kinds[i] for i in order]


@pytest.mark.parametrize("seed", range(6))
def test_segmentation_is_its_documented_procedure_on_random_recordings(seed):
    """Independent oracle of the wiring: random smooth 2-D and 3-D curves with corners, sampled
    unevenly (a hand slowing down and pausing), 200 to 5000 samples (past the 4096 analysed), both
    pruning rules and three thresholds, against :func:`_segment_by_hand`."""
    from bidmp.extension.segmentation import segment

    rng = np.random.default_rng(seed)
    n = [200, 900, 5000, 350, 1200, 4500][seed]
    u = np.cumsum(rng.uniform(0.2, 1.8, n))  # uneven speed along the path
    u = (u - u[0]) / (u[-1] - u[0])
    u[n // 3 : n // 3 + 10] = u[n // 3]  # a pause
    corners = rng.uniform(-100, 100, (int(rng.integers(3, 7)), 3 if seed % 2 else 2))
    knots = np.linspace(0.0, 1.0, len(corners))
    y = np.column_stack([np.interp(u, knots, c) for c in corners.T]) + 0.5 * np.sin(7 * u)[:, None]
    for method in ("persistence", "paper"):
        for eps_frac in (0.05, 0.1, 0.3):
            found = segment(y, eps_frac, method)
            points, kinds = _segment_by_hand(y, eps_frac, method)
            assert (found.points.tolist(), found.kinds.tolist()) == (points, kinds), (
                method,
                eps_frac,
            )
    # An ellipse and a spiral: curved everywhere, so the threshold's min κ is far from 0.
    t = np.linspace(0.0, 3 * np.pi, 700 + 300 * seed)
    for curve in (
        np.column_stack([100 * np.cos(t), 40 * np.sin(t)]),
        np.column_stack([1e4 * np.cos(t), 4e3 * np.sin(t)]),  # 100 m long: κ·L decides, not κ
        np.column_stack([(60 + 8 * t) * np.cos(t), (60 + 8 * t) * np.sin(t), 3 * t]),
    ):
        for method in ("persistence", "paper"):
            for eps_frac in (0.02, 0.2, 0.95):
                found = segment(curve, eps_frac, method)
                assert (found.points.tolist(), found.kinds.tolist()) == _segment_by_hand(
                    curve, eps_frac, method
                )
    line = np.outer(np.linspace(0.0, 1.0, 300), [40.0, -20.0, 5.0])  # a straight line: no points
    assert len(segment(line)) == 0 and _segment_by_hand(line, 0.1, "persistence") == ([], [])


def test_the_command_generator_feeds_the_targets_rates_forward_and_settles_on_a_held_target():
    """Property of the cascaded loops with feed-forward: a target moving at a constant 0.1 rad/s
    (its velocity given) is tracked with no lag once the start has settled (each command is the
    position at the end of its 1 ms step) (a position loop of
    gain 15/s alone would lag 0.1/15 = 6.7 mrad); one accelerating at 0.2 rad/s² (velocity and
    acceleration given) likewise; a held target given alone is reached at rest."""
    from bidmp.sim.limits import _RateLimiter

    limits = bidmp.sim.JointLimits(
        lower=(-3.0,), upper=(3.0,), velocity=(1.0,), acceleration=(5.0,), jerk=(100.0,)
    )
    ramp, accelerating, held = (_RateLimiter(np.zeros(1), limits, 0.9) for _ in range(3))
    for k in range(4000):
        t = k * 1e-3
        ramp_command = ramp([0.1 * t], [0.1])
        accelerating_command = accelerating([0.1 * t * t], [0.2 * t], [0.2])
        held_command = held([0.3])
    end = t + 1e-3  # each command is where the joint is at the end of its 1 ms step
    assert abs(ramp_command[0] - 0.1 * end) < 1e-6
    # (fed its acceleration the lag is a discretisation residue, 7e-6; without it the velocity loop
    # would lag 0.2/50 rad/s and the position 0.2/(50 · 15) = 2.7e-4 rad)
    assert abs(accelerating_command[0] - 0.1 * end * end) < 2e-5
    assert abs(held_command[0] - 0.3) < 1e-6 and abs(held.velocity[0]) < 1e-5


def test_the_measured_acceleration_is_the_velocitys_difference_over_10_ms():
    """Independent oracle: velocities recorded every 10 ms (one window) or every 2 ms (five
    samples a window): the acceleration peak is the largest difference of the velocities 10 ms
    apart over 10 ms, computed here."""
    from bidmp.sim.limits import _measured_peaks

    limits = bidmp.sim.JointLimits(
        lower=(-3.0,), upper=(3.0,), velocity=(2.0,), acceleration=(1.0,), jerk=(1e6,)
    )
    for step in (0.01, 0.002):
        t = np.arange(0.0, 1.0, step)
        velocity = np.sin(3.0 * t) ** 3
        every = int(round(0.01 / step))
        expected = np.max(np.abs(np.diff(velocity[::every]))) / 0.01
        assert _measured_peaks(velocity[:, None], step, limits).acceleration == pytest.approx(
            expected, rel=1e-12
        )


@pytest.mark.parametrize(
    "n, bumps, expected",
    [
        (101, (6, 94), ([6, 50, 94], [1, -1, 1])),
        (101, (95,), ([], [])),
        (101, (4,), ([], [])),
        (102, (6,), ([], [])),
        (102, (7,), ([7], [1])),
    ],
)
def test_segmentation_looks_for_extrema_on_the_interior_5_to_95_percent(
    monkeypatch, n, bumps, expected
):
    """Structure guard of the window, with a curvature designed here (the curve is a straight line
    of 101 evenly spaced samples, so sample i is resampled point i): on the interior, samples
    ceil(0.05 · 100) = 5 … floor(0.95 · 100) = 95, a maximum needs a neighbour on each side inside
    it — so bumps at 6 and 94 are found (with the minimum between them at its plateau's middle),
    one at the edge (95) or outside (4) is not. With 102 samples the interior starts at
    ceil(0.05 · 101) = 6."""
    from bidmp.extension import segmentation

    kappa = np.zeros(n)
    kappa[list(bumps)] = 1.0
    monkeypatch.setattr(segmentation, "_curvature", lambda y, *smoothing: kappa.copy())
    line = np.outer(np.linspace(0.0, 1.0, n), [100.0, 20.0, 0.0])
    found = segmentation.segment(line)
    assert (found.points.tolist(), found.kinds.tolist()) == expected


@pytest.mark.parametrize(
    "x, bump, height, expected",
    [
        (
            np.r_[0.0, np.arange(30.0, 101.0)],
            6,
            1.0,
            ([0], [1]),
        ),  # at 8.5 % of the path: sample 0 (0 %), not 1 (30 %)
        (
            np.r_[np.arange(0.0, 71.0), 100.0],
            65,
            1.0,
            ([71], [1]),
        ),  # at 91.5 %: the last sample (100 %), not 70 %
        (
            np.linspace(0.0, 100.0, 101),
            50,
            1.5e-8,
            ([50], [1]),
        ),  # κ·L = 1.5e-6: a bend, however slight
        (np.linspace(0.0, 100.0, 101), 50, 0.5e-8, ([], [])),  # κ·L = 5e-7: straight
    ],
)
def test_segmentation_maps_each_point_to_the_nearest_sample_and_calls_only_a_flat_path_straight(
    monkeypatch, x, bump, height, expected
):
    """Structure guard of the mapping and the straight-path threshold, with a curvature designed
    here on a straight line sampled unevenly (a first or last step of 30 % of the path): a point
    found at a resampled position goes to the original sample nearest in arc length, whichever end
    of the path it is near; a path whose curvature times length stays below 1e-6 is straight."""
    from bidmp.extension import segmentation

    kappa = np.zeros(len(x))
    kappa[bump] = height
    monkeypatch.setattr(segmentation, "_curvature", lambda y, *smoothing: kappa.copy())
    line = np.column_stack([x, 0.2 * x, np.zeros(len(x))]) / np.sqrt(1.04)  # arc length = x
    found = segmentation.segment(line)
    assert (found.points.tolist(), found.kinds.tolist()) == expected


# -- units and speeds a robot can run; bags' stamp order --------------------------------
@pytest.mark.parametrize("units, per_metre", [("m", 1.0), ("cm", 100.0), ("mm", 1000.0)])
def test_a_peak_speed_is_judged_at_1_mm_per_s_and_10_m_per_s_in_every_unit(units, per_metre):
    """Boundaries written out: 1 mm/s and 10 m/s are plausible, a hair beyond either is not, in
    the numbers of each unit; fast_only judges only the upper bound."""
    from bidmp._units import check_speed

    for metres_per_s in (1e-3, 0.25, 10.0):
        check_speed(metres_per_s * per_metre, units, "x")
    for metres_per_s, word in ((1e-3 * (1 - 1e-9), "slower"), (10.0 * (1 + 1e-9), "faster")):
        with pytest.raises(ValueError, match=word):
            check_speed(metres_per_s * per_metre, units, "x")
    check_speed(1e-6 * per_metre, units, "x", fast_only=True)
    with pytest.raises(ValueError, match="faster"):
        check_speed(10.0 * (1 + 1e-9) * per_metre, units, "x", fast_only=True)
    check_speed(float("nan"), units, "x")  # not a speed: nothing to judge
    check_speed(1e9, "", "x")  # no unit: not judged


@pytest.mark.parametrize(
    "speed, units, hint",
    [
        (0.3, "mm", "is it in m?"),  # metre numbers declared as mm: 0.3 mm/s, 0.3 m/s in m
        (300.0, "m", "is it in mm?"),  # mm numbers declared as m: 300 m/s, 0.3 m/s in mm
        (
            30.0,
            "m",
            "is it in cm?",
        ),  # 30 m/s: 0.3 m/s in cm (0.03 in mm is further from a hand's 0.25 m/s)
        (0.03, "cm", "is it in m?"),  # 0.3 mm/s in cm: 0.03 m/s in m
        (
            120.0,
            "m",
            "is it in mm?",
        ),  # 1.2 m/s in cm, 0.12 m/s in mm: mm is nearer a hand's 0.25 m/s (log scale)
        (
            1e-3,
            "mm",
            "is it in m?",
        ),  # 1 mm/s in m: plausible at its very boundary, and no other unit is
        (1e4, "m", "is it in mm?"),  # 10 m/s in mm: at the other boundary (100 m/s in cm is not)
    ],
)
def test_an_implausible_speed_names_the_unit_that_fits_it(speed, units, hint):
    from bidmp._units import check_speed

    with pytest.raises(ValueError, match=hint.replace("?", r"\?")):
        check_speed(speed, units, "the demonstration")


def test_a_joint_speed_is_judged_in_radians_and_degrees_are_named():
    from bidmp._units import check_speed

    for speed in (1e-3, 3.0, 10.0):
        check_speed(speed, "rad", "q")
    with pytest.raises(ValueError, match=r"in degrees it would be 0\.524 rad/s"):
        check_speed(30.0, "rad", "q")  # 30 deg/s read as rad/s
    with pytest.raises(ValueError, match=r"in degrees it would be 10 rad/s"):
        check_speed(
            float(np.degrees(10.0)), "rad", "q"
        )  # at the boundary in degrees (radians() gives 10.0 exactly)
    with pytest.raises(ValueError, match="faster") as refused:
        check_speed(1000.0, "rad", "q")  # 17 rad/s even in degrees: no hint
    assert "degrees" not in str(refused.value)
    with pytest.raises(ValueError, match="slower"):
        check_speed(1e-3 * (1 - 1e-9), "rad", "q")
    check_speed(1e-6, "rad", "q", fast_only=True)


@pytest.mark.parametrize("units, per_metre", [("m", 1.0), ("cm", 100.0), ("mm", 1000.0)])
def test_a_goal_is_within_reach_up_to_5_m_in_every_unit(units, per_metre):
    from bidmp._units import check_reach

    check_reach(5.0 * per_metre, units, "the goal")
    with pytest.raises(ValueError, match="beyond any robot's reach"):
        check_reach(5.0 * (1 + 1e-9) * per_metre, units, "the goal")
    check_reach(1e9, "rad", "the goal")  # joint angles are no distance
    check_reach(1e9, "", "the goal")


def test_a_metre_goal_named_in_mm_is_told_so():
    from bidmp._units import check_reach

    with pytest.raises(ValueError, match="is it in cm or mm"):
        check_reach(150.0, "m", "the goal")  # 150 m: 1.5 m in cm, 0.15 m in mm
    with pytest.raises(ValueError, match="is it in cm or mm"):
        check_reach(500.0, "m", "the goal")  # 500 m: 5 m in cm, at the boundary of reach
    with pytest.raises(ValueError, match=r"is it in mm\?"):
        check_reach(4000.0, "m", "the goal")  # 40 m in cm: only mm is within reach


def test_bag_stamps_are_ordered_and_only_repeats_and_real_jumps_back_refused():
    """Boundaries written out: 0.1 s behind the latest stamp received is transport jitter, a
    nanosecond more is a jump back; equal stamps are refused wherever they sit."""
    from bidmp.io.bags import MAX_STAMP_DISORDER, _stamp_order

    limit = int(MAX_STAMP_DISORDER * 1e9)
    np.testing.assert_array_equal(_stamp_order([0, 10, 20, 30], "s", "c"), [0, 1, 2, 3])
    np.testing.assert_array_equal(_stamp_order([0, 20, 10, 30], "s", "c"), [0, 2, 1, 3])
    np.testing.assert_array_equal(
        _stamp_order([5, limit + 5, 5 + 1, limit + 10], "s", "c"), [0, 2, 1, 3]
    )
    np.testing.assert_array_equal(
        _stamp_order([1, limit + 2, 2, limit + 3], "s", "c"), [0, 2, 1, 3]
    )  # limit behind
    with pytest.raises(ValueError, match=r"jump back in time \(message 3 at "):
        _stamp_order([5, limit + 6, 5, limit + 10], "s", "c")  # 5 is limit + 1 ns behind
    with pytest.raises(ValueError, match="jump back"):
        _stamp_order([0, 10 * limit, 20, 10 * limit + 5], "s", "c")
    with pytest.raises(
        ValueError, match=r"jump back in time \(message 4 at "
    ):  # message 3 is only at the limit
        _stamp_order([1, limit + 2, 2, 0], "s", "c")
    for stamps, messages in (
        ([0, 10, 10, 20], "2 and 3"),
        ([0, 20, 10, 20], "2 and 4"),
        ([7, 3, 7], "1 and 3"),
    ):
        with pytest.raises(
            ValueError, match=f"repeat: two messages stamped .* \\(messages {messages}\\)"
        ):
            _stamp_order(stamps, "s", "c")


def test_bag_messages_put_in_order_are_counted_in_the_log(caplog):
    import logging

    from bidmp.io.bags import _stamp_order

    with caplog.at_level(logging.INFO, logger="bidmp.io.bags"):
        _stamp_order([0, 4_000_000, 13_000_000, 9_000_000, 20_000_000], "bag b", "c")
    assert (
        "bag b: 2 message(s) out of receive order, put in the order of their stamps (at most 4 ms apart)"
        in caplog.text
    )
    caplog.clear()
    with caplog.at_level(logging.INFO, logger="bidmp.io.bags"):
        _stamp_order([0, 4_000_000, 9_000_000], "bag b", "c")
    assert "out of receive order" not in caplog.text
