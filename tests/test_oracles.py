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
@pytest.mark.parametrize("tool_length, beam_bottom, run_up", [(120.0, 100.0, 60.0), (300.0, 270.0, 60.0),
                                                               (60.0, 50.0, 60.0), (100.0, 90.0, 2000.0)])
def test_a_two_point_path_under_a_beam_is_as_deep_as_the_shaft_reaches(tool_length, beam_bottom, run_up):
    """Independent oracle: a vertical cylindrical tool (radius r, its shaft rising ``length``
    above its tip) crosses under a beam between two samples that are both clear of it. Where the
    shaft is under the beam it is inside it by min(shaft top − beam bottom, beam half-width + r)
    (the shorter way out: down, or sideways), so the clearance is minus that; the samples alone
    are at least 35 mm clear. (A 2 m run-up puts the beam past the first 8192 placements.)"""
    radius, half_width, depth_up = 5.0, 20.0, 15.5
    tip = beam_bottom + depth_up - tool_length
    scene = Scene.from_dict({"tool": {"radius": radius, "length": tool_length},
                             "parts": [{"type": "box", "label": "beam", "at": [0.0, 0.0, beam_bottom],
                                        "size": [2 * half_width, 400.0, 30.0]}]})
    path = np.array([[-run_up, 0.0, tip], [60.0, 0.0, tip]])
    truth = -min(depth_up, half_width + radius)
    found = scene.clearance(path)
    assert found.part == "beam"
    assert found.distance == pytest.approx(truth, abs=1e-6)
    at_samples = 60.0 - half_width - radius  # both samples: the shaft's side to the beam's side
    assert scene.clearance(path[1:]).distance == pytest.approx(at_samples, abs=1e-6)
    assert not found.clear and not found.collision_free


def test_a_path_over_a_box_at_the_margin_is_judged_by_its_closed_form_clearance():
    """Independent oracle: a tool tip passing above a box at height h over its top keeps exactly h;
    at the margin it is clear, 1e-3 below it not (the judge compares with ``>=``)."""
    scene = Scene.from_dict({"tool": {"radius": 4.0, "length": 80.0}, "margin": 3.0,
                             "parts": [{"type": "box", "label": "box", "at": [0.0, 0.0, 0.0], "size": [50.0, 50.0, 20.0]}]})
    for height, clear in ((3.001, True), (2.999, False), (10.0, True)):
        path = np.array([[-100.0, 0.0, 20.0 + height], [100.0, 0.0, 20.0 + height]])
        found = scene.clearance(path)
        assert found.distance == pytest.approx(height, abs=1e-6)
        assert found.clear is clear and found.collision_free


def test_the_nearest_point_of_a_v_shaped_pass_over_a_box_is_its_lowest_sample():
    """Independent oracle: a path dipping to 7 mm over a box's top at one sample (x = 10) and
    rising either side is nearest there, 7 mm; with the tool's orientation given (pointing down,
    the default) the answer is the same, also when the path starts at its nearest point."""
    scene = Scene.from_dict({"tool": {"radius": 4.0, "length": 80.0},
                             "parts": [{"type": "box", "label": "box", "at": [0.0, 0.0, 0.0], "size": [60.0, 60.0, 20.0]}]})
    x = np.linspace(-50.0, 50.0, 41)
    path = np.column_stack([x, np.zeros(41), 27.0 + 0.5 * np.abs(x - 10.0)])
    down = np.tile([1.0, 0.0, 0.0, 0.0], (41, 1))  # half a turn about x: the tool's z axis points down
    for points, turns in ((path, None), (path, down), (path[24:], down[24:])):
        found = scene.clearance(points, orientations=turns)
        assert found.distance == pytest.approx(7.0, abs=1e-6)
        np.testing.assert_allclose(found.point, [10.0, 0.0, 27.0], atol=1e-9)
        assert found.part == "box"


def test_segments_free_judges_each_straight_move_by_its_own_closed_form():
    """Independent oracle: moves beside a box (tool radius r, box half-width w): a move at lateral
    offset d from the box's side axis is free iff d − w − r exceeds the checker's margin."""
    radius, half = 4.0, 10.0
    scene = Scene.from_dict({"tool": {"radius": radius, "length": 50.0},
                             "parts": [{"type": "box", "label": "box", "at": [0.0, 0.0, 0.0], "size": [2 * half, 2 * half, 40.0]}]})
    checker = scene.checker()
    offsets = np.array([13.0, 14.5, 15.0, 30.0, -14.0, -30.0])
    starts = np.column_stack([offsets, np.full(6, -100.0), np.full(6, 5.0)])
    ends = np.column_stack([offsets, np.full(6, 100.0), np.full(6, 5.0)])
    expected = np.abs(offsets) - half - radius > 0.0
    assert checker.segments_free(starts, ends).tolist() == expected.tolist()


@pytest.mark.parametrize("distance, margin, collision_free, clear", [
    (0.0, 0.0, True, True), (-1e-12, 0.0, False, False), (2.0, 2.0, True, True), (1.999, 2.0, True, False),
    (-0.5, 2.0, False, False), (math.inf, 2.0, True, True)])
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
    limits = bidmp.sim.JointLimits(lower=(-3.0, -3.0), upper=(3.0, 3.0), velocity=(1.0, 1.0),
                                   acceleration=(5.0, 5.0), jerk=(100.0, 100.0))
    peaks = command_peaks(commands, limits, dt)
    assert peaks.velocity == pytest.approx(15 * amplitude / (8 * duration), rel=2e-3)
    assert peaks.acceleration == pytest.approx(10 * amplitude / (math.sqrt(3) * duration**2) / 5.0, rel=5e-3)
    assert peaks.jerk == pytest.approx(60 * amplitude / duration**3 / 100.0, rel=5e-3)
    assert peaks.joint == 0 and peaks.within
    slow = bidmp.sim.JointLimits(lower=(-3.0, -3.0), upper=(3.0, 3.0), velocity=(0.5, 1.0),
                                 acceleration=(5.0, 5.0), jerk=(100.0, 100.0))
    assert not command_peaks(commands, slow, dt).within  # 0.75 rad/s against 0.5


def test_a_command_jump_at_either_end_is_an_acceleration_from_rest():
    """Independent oracle: a first command 1 mrad from rest is a step of 1e-3/dt² in acceleration."""
    commands = np.array([[0.0], [1e-3], [1e-3], [1e-3]])
    limits = bidmp.sim.JointLimits(lower=(-1.0,), upper=(1.0,), velocity=(10.0,), acceleration=(2000.0,), jerk=None)
    peaks = command_peaks(commands, limits, 1e-3)
    assert peaks.ends == pytest.approx(1e-3 / 1e-6 / 2000.0)
    assert not peaks.within
    backwards = command_peaks(-commands, limits, 1e-3)
    assert backwards.ends == pytest.approx(peaks.ends) and not backwards.within


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
    along_x = np.column_stack([z, offset, np.zeros(81)])  # the same descent along a target's +x axis
    assert approach_error(along_x, np.zeros(3), 25.0, axis=[1.0, 0.0, 0.0]) == pytest.approx(offset[below].max(), rel=1e-12)


@pytest.mark.parametrize("rise, engaged", [(0.0, True), (0.2, True), (0.3, False), (2.0, False)])
def test_a_rise_inside_the_band_beyond_the_tolerance_is_no_engagement(rise, engaged):
    """Independent oracle: a descent into a 20 mm band that rises by ``rise`` on the way down
    (a wobble) engages iff the rise is at most the tolerance (0.25 here)."""
    heights = np.concatenate([np.linspace(30.0, 10.0, 41), 10.0 + rise * np.sin(np.linspace(0, np.pi, 11)),
                              np.linspace(10.0, 0.0, 21)])
    mask = final_approach_mask(heights, 20.0, rise=0.25)
    assert (mask is not None) is engaged
    path = np.column_stack([np.zeros_like(heights), np.zeros_like(heights), heights])
    assert math.isfinite(approach_error(path, np.zeros(3), 20.0, rise=0.25)) is engaged


def test_a_motion_ending_above_the_band_or_never_above_it_does_not_engage():
    """Independent oracle: no final approach without a descent from above the band to its end."""
    assert final_approach_mask(np.linspace(30.0, 21.0, 10), 20.0) is None  # ends above
    assert final_approach_mask(np.linspace(15.0, 0.0, 10), 20.0) is None  # never above
    assert final_approach_mask(np.array([30.0, 20.0, 10.0, 0.0]), 20.0).tolist() == [False, False, True, True]


# -- the job: in the bin, in the slot, removed ----------------------------------------------------
@pytest.mark.parametrize("fraction, inside", [(0.0, True), (0.49, True), (0.5, True), (0.51, False), (0.9, False)])
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

    record = JobTarget("n1", [JobPhase("approach", True, 1.0, contacts={"plate": 0.2}),
                              JobPhase("engage", True, 0.0),
                              JobPhase("drop", False, 2.0, "released outside the bin", contacts={"plate": 0.5, "bin": 0.1},
                                       within_limits=False),
                              JobPhase("settle", False, 0.5, "later")])
    _finish(record, Part())
    assert not record.removed and record.reason == "drop: released outside the bin"
    assert record.final_position.tolist() == [1.0, 2.0, 3.0]
    assert record.contacts == {"plate": 0.5, "bin": 0.1} and not record.within_limits
    good = JobTarget("n2", [JobPhase("approach", True, 1.0), JobPhase("drop", True, 2.0)])
    _finish(good, Part())
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
    params = bidmp.DMP().fit(demo, np.linspace(0.0, 1.0, 100))._params()
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
