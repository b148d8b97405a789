"""How a repair's motion is accepted (bidmp.tasks.repair.Repairer): planned for one margin, judged by
another, recorded whatever happened. A small cell with a known answer: a DMP whose motion ends 0.6
mm outside a post's margin (the post beside the nut, its distance at the end a closed form: the
gap between two upright circles, the tool's and the post's), judged by a contract with a 0.2 mm
allowance; the extension a repair would learn is replaced by the DMP itself (what is checked here
is what the Repairer does with a motion, not how an extension is grown), recording the margin each
planning was asked for."""

from __future__ import annotations

import numpy as np
import pytest

from bidmp import DMP
from bidmp.demonstrations import minimum_jerk
from bidmp.scene import Scene
from bidmp.tasks.contract import Contract
from bidmp.tasks.repair import Repairer, _Query

RADIUS, MARGIN, ALLOWANCE = 12.5, 3.0, 0.2  # mm
POST_RADIUS, GAP = 2.0, 3.4  # mm: the post's radius, its distance from the tool at the end
GOAL = np.zeros(3)


class _Plain:
    """A model that only runs (no weights: no Bi-DMP can be grown on it): a DMP's motions."""

    def __init__(self, dmp):
        self.dmp = dmp
        self.tau, self.duration_ = dmp.tau, dmp.duration_

    def trajectory(self, goal=None, **options):
        return self.dmp.trajectory(goal, **options)


@pytest.fixture(scope="module")
def cell():
    demo = minimum_jerk(np.array([[-80.0, -120.0, 200.0], [0.0, 0.0, 40.0], [0.0, 0.0, 0.0]]), 200)
    dmp = DMP().fit(demo, np.linspace(0.0, 2.0, 200))
    post_x = RADIUS + POST_RADIUS + GAP
    scene = Scene.from_dict(
        {
            "tool": {"radius": RADIUS, "length": 100.0},
            "margin": MARGIN,
            "parts": [
                {
                    "type": "cylinder",
                    "label": "post",
                    "at": [post_x, 0.0, -10.0],
                    "radius": POST_RADIUS,
                    "height": 15.0,
                }
            ],
        }
    )
    contract = Contract(1.75, 28.5, scene, "mm")
    return dmp, demo, contract


def _recording(repairer, monkeypatch, model):
    """The Repairer with its extension replaced by ``model`` itself; the margins it planned for."""
    planned = []

    def learned(model_, goal, planning, start=None, skill="nearest"):
        planned.append(planning.scene.margin)
        return model, 0

    monkeypatch.setattr(repairer, "_learned", learned)
    return planned


def test_the_cell_has_the_answer_the_tests_assume(cell):
    dmp, _, contract = cell
    motion = dmp.trajectory(GOAL).y
    verdict = contract.judge(motion, GOAL)
    assert verdict.ok
    assert verdict.clearance.distance == pytest.approx(GAP, abs=1e-3)  # the DMP ends within 1 µm


def _query(dmp, carried=None) -> _Query:
    """What Repairer.repair asks of its repairs for the cell's nut "n" (no axis: world z)."""
    return _Query(dmp, GOAL, "n", None, None, [], "nearest", carried)


def test_a_margin_repair_plans_wider_and_is_judged_by_the_margin_and_allowance(cell, monkeypatch):
    """Planned for margin + allowance + the shortfall, accepted when it keeps margin + allowance
    (3.2 mm: the motion passes 3.4), though not the widened 3.7 mm it was planned for."""
    dmp, demo, contract = cell
    repairer = Repairer(contract, demo, allowance=ALLOWANCE)
    planned = _recording(repairer, monkeypatch, dmp)
    motion, _, _, verdict = repairer._try("margin", _query(dmp), 0.5)
    assert planned == [pytest.approx(MARGIN + ALLOWANCE + 0.5)]
    assert verdict.ok, verdict.reason()
    assert verdict.clearance.margin == pytest.approx(MARGIN + ALLOWANCE)
    planned.clear()
    repairer._try("extend", _query(dmp), 0.5)
    assert planned == [pytest.approx(MARGIN + ALLOWANCE)]  # an extension plans without it


def test_a_margin_repair_that_still_comes_too_close_widens_by_what_it_lacked(cell, monkeypatch):
    """With 1 mm more allowance (4.2 mm to keep, the motion passes 3.4) each widening adds the
    0.8 mm the last one lacked, and the motion is refused by the contract it must keep."""
    dmp, demo, contract = cell
    repairer = Repairer(contract, demo, allowance=ALLOWANCE + 1.0)
    planned = _recording(repairer, monkeypatch, dmp)
    *_, verdict = repairer._try("margin", _query(dmp), 0.0)
    lacked = MARGIN + ALLOWANCE + 1.0 - GAP
    assert planned == pytest.approx(
        [MARGIN + ALLOWANCE + 1.0, MARGIN + ALLOWANCE + 1.0 + lacked], abs=1e-3
    )
    assert not verdict.ok and verdict.failed == ["clearance"]


def test_repair_starts_with_no_shortfall_and_keeps_what_the_contract_accepts(cell, monkeypatch):
    """Through repair(): the first margin planning asks for margin + allowance only; the motion is
    accepted as the contract judges it (its verdict the contract's, not the planning's)."""
    dmp, demo, contract = cell
    repairer = Repairer(contract, demo, order=("margin",), allowance=ALLOWANCE)
    planned = _recording(repairer, monkeypatch, dmp)
    broken = contract.judge(dmp.trajectory(GOAL + [0.0, 0.0, 5.0]).y, GOAL)  # ends 5 mm high
    assert not broken.ok
    fixed = repairer.repair(dmp, GOAL, "n", verdict=broken)
    assert planned == [pytest.approx(MARGIN + ALLOWANCE)]
    assert fixed.how == "margin" and fixed.ok
    assert fixed.verdict.clearance.margin == pytest.approx(MARGIN)  # the contract's own verdict
    assert fixed.model is dmp and fixed.skill == 0
    assert [(a.how, a.ok) for a in fixed.attempts] == [("margin", True)]


def test_a_repair_the_planning_refuses_is_not_kept_though_the_contract_would(cell, monkeypatch):
    """A motion that keeps the contract's 3 mm but not the 3.6 mm planned with the allowance is
    not taken: the arm's tracking may take the difference off it when it runs."""
    dmp, demo, contract = cell
    repairer = Repairer(contract, demo, order=("margin",), allowance=0.6)
    _recording(repairer, monkeypatch, dmp)
    broken = contract.judge(dmp.trajectory(GOAL + [0.0, 0.0, 5.0]).y, GOAL)
    fixed = repairer.repair(dmp, GOAL, "n", verdict=broken)
    assert not fixed.ok and fixed.how == ""
    assert fixed.verdict is broken  # the method's own verdict stands
    assert [(a.how, a.ok) for a in fixed.attempts] == [("margin", False)]
    assert "3.6" in fixed.attempts[0].note


def test_a_failed_attempt_is_recorded_failed_with_its_reason_and_its_time(cell, monkeypatch):
    dmp, demo, contract = cell
    repairer = Repairer(contract, demo, order=("extend", "margin"))

    def no_route(*args, **kwargs):
        raise ValueError("no collision-free route\nsecond line")

    monkeypatch.setattr(repairer, "_try", no_route)
    broken = contract.judge(dmp.trajectory(GOAL + [0.0, 0.0, 5.0]).y, GOAL)
    fixed, spent = _timed_repair(repairer, dmp, broken)
    assert [(a.how, a.ok, a.note) for a in fixed.attempts] == [
        ("extend", False, "no collision-free route"),
        ("margin", False, "no collision-free route"),
    ]
    _within(fixed.attempts, spent)


def test_a_model_no_bi_dmp_can_grow_on_is_lifted_but_not_extended(cell, monkeypatch):
    """Lifts and steers need only the model's motions; extensions need a DMP to grow a Bi-DMP on."""
    dmp, demo, contract = cell
    plain = _Plain(dmp)
    assert not Repairer.bidmp_possible(plain) and Repairer.bidmp_possible(dmp)
    repairer = Repairer(contract, demo, order=("lift", "extend", "margin"))
    tried = []

    def tried_and_failed(how, *args):
        tried.append(how)
        raise ValueError("not this one")

    monkeypatch.setattr(repairer, "_try", tried_and_failed)
    # judged with a 1 mm wider margin (4 mm; it passes 3.4), the motion breaks the clearance only
    clearance_only = repairer._widened(1.0).judge(dmp.trajectory(GOAL).y, GOAL)
    assert clearance_only.failed == ["clearance"]
    repairer.repair(plain, GOAL, "n", verdict=clearance_only)
    assert tried == ["lift"]
    tried.clear()
    repairer.repair(dmp, GOAL, "n", verdict=clearance_only)
    assert tried == ["lift", "extend", "margin"]


def test_a_failed_extension_plans_the_margin_repair_wider_by_what_it_lacked(cell, monkeypatch):
    """Extend (planned for margin + allowance = 4.2, the motion passes 3.4) fails 0.8 short; the
    margin repair then plans for 4.2 + 0.8 and once more 0.8 wider, and fails too."""
    dmp, demo, contract = cell
    repairer = Repairer(contract, demo, order=("extend", "margin"), allowance=ALLOWANCE + 1.0)
    planned = _recording(repairer, monkeypatch, dmp)
    broken = contract.judge(dmp.trajectory(GOAL + [0.0, 0.0, 5.0]).y, GOAL)
    fixed, spent = _timed_repair(repairer, dmp, broken)
    keep = MARGIN + ALLOWANCE + 1.0
    lacked = keep - GAP
    assert planned == pytest.approx([keep, keep + lacked, keep + 2 * lacked], abs=1e-3)
    assert [(a.how, a.ok) for a in fixed.attempts] == [("extend", False), ("margin", False)]
    _within(fixed.attempts, spent)


def test_a_carried_part_is_judged_with_the_tool(cell):
    """A 30 mm plate carried 5 mm under the mouth reaches 0.9 mm from the post where the tool keeps
    3.4: the verdict on the move is the part's."""
    from bidmp.scene import Scene

    dmp, demo, contract = cell
    held = Scene.from_dict(
        {
            "tool": {"radius": RADIUS, "length": 100.0},
            "parts": [{"type": "box", "label": "held", "at": [0, 0, -7.5], "size": [30, 30, 5]}],
        }
    ).solids[0]
    repairer = Repairer(contract, demo)
    motion = dmp.trajectory(GOAL).y
    alone = repairer._judge(contract, motion, _query(dmp))
    carrying = repairer._judge(contract, motion, _query(dmp, (held, [0.0, 0.0, -5.0])))
    assert alone.ok and not carrying.ok
    assert carrying.clearance.distance == pytest.approx(GAP + RADIUS - 15.0, abs=1e-3)


def _timed_repair(repairer, dmp, verdict):
    """The repair of the cell's motion and how long the whole call took (s)."""
    import time

    started = time.perf_counter()
    fixed = repairer.repair(dmp, GOAL, "n", verdict=verdict)
    return fixed, time.perf_counter() - started


def _within(attempts, spent: float) -> None:
    """Each attempt's recorded time is a share of the call's own (a consistency check, not a
    limit: no clock decides the test)."""
    shares = [attempt.seconds for attempt in attempts]
    assert min(shares) >= 0.0 and sum(shares) <= spent, (shares, spent)


def test_the_avoid_repair_steers_round_every_part_but_the_target_s_own(monkeypatch):
    """The steering term of an ``avoid`` repair leaves the target's own part out (the tool must
    reach it: steered away from it, the motion could not end there) and is given no target
    when the label names no part. A structure check of what the repair hands the term: whether
    steering then reaches is the avoidance's own tests'."""
    import bidmp.primitives.avoidance as avoidance

    targets = []

    class Recorded(avoidance.SceneAvoidance):
        def __init__(self, scene, **options):
            targets.append(options.get("target"))
            super().__init__(scene, **options)

    monkeypatch.setattr(avoidance, "SceneAvoidance", Recorded)
    # a post across the skill's way to a far goal, and a nut of its own at the goal
    demo = minimum_jerk([[-100, -120, 150], [0, 0, 35], [0, 0, 0]], 300)
    dmp = DMP().fit(demo, np.linspace(0, 3, 300), units="mm")
    goal = np.array([120.0, 0.0, 0.0])
    scene = Scene.from_dict(
        {
            "tool": {"radius": 10.0, "length": 100.0},
            "margin": 3.0,
            "parts": [
                {"type": "cylinder", "label": "post", "at": [60, -33, -2], "radius": 5.0, "height": 80.0},
                {"type": "cylinder", "label": "nut", "at": [120, 0, -8], "radius": 4.0, "height": 8.0},
            ],
        }
    )  # fmt: skip
    contract = Contract(1.75, 25.0, scene, "mm")
    assert contract.judge(dmp.trajectory(goal).y, goal, exclude=["nut"]).failed == ["clearance"]
    repairer = Repairer(contract, demo, order=("avoid",))
    repairer.repair(dmp, goal, "nut", exclude=["nut"])
    repairer.repair(dmp, goal, "far", exclude=["nut"])
    assert targets == ["nut", None]
