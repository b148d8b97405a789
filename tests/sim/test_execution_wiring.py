"""What the simulator takes from the evaluation is each motion's own: the refusal of a motion is
its own verdict's (not the first target's), and the room the repairs leave for the arm's
tracking is 0.5 mm in the scenario's own unit. Several of everything: two methods, three targets
refused and accepted in both orders, the same cell in mm, cm and m."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from types import SimpleNamespace

import pytest

from bidmp.sim.execution import _refusal, execution_settings
from bidmp.tasks import scenarios
from bidmp.tasks.contract import Contract

DATA = Path(__file__).resolve().parents[1] / "data"
PER_MM = {"mm": 1.0, "cm": 0.1, "m": 1e-3}


def _posts(units: str):
    """The two-post cell with its lengths in ``units`` (from the mm file)."""
    data = json.loads((DATA / "two_posts.json").read_text())
    f = PER_MM[units]
    data = copy.deepcopy(data)
    data["name"] += f"-{units}"
    data["units"] = units
    data["targets"] = {k: [v * f for v in p] for k, p in data["targets"].items()}
    via = data["demonstration"]["minimum_jerk"]["via"]
    data["demonstration"]["minimum_jerk"]["via"] = [[v * f for v in p] for p in via]
    data["success_threshold"] *= f
    data["approach_height"] *= f
    data["robot"]["base"] = [v * f for v in data["robot"]["base"]]
    scene = data["scene"]
    scene["tool"] = {k: v * f for k, v in scene["tool"].items()}
    scene["margin"] *= f
    scene["standoff"] = {k: v * f for k, v in scene["standoff"].items()}
    for part in scene["parts"]:
        for key in ("at", "size", "offset"):
            if key in part:
                part[key] = [v * f for v in part[key]]
        for key in ("across_flats", "height", "radius"):
            if key in part:
                part[key] *= f
        if "stud" in part:
            part["stud"] = {k: v * f for k, v in part["stud"].items()}
    data.pop("job", None)
    return scenarios.from_dict(data)


@pytest.mark.parametrize("units", sorted(PER_MM))
def test_the_tracking_allowance_is_half_a_millimetre_in_the_scenarios_unit(units):
    settings = execution_settings(_posts(units))
    assert settings["allowance"] == pytest.approx(0.5 * PER_MM[units], rel=1e-12)
    assert settings["geometry"] is True


def test_each_motions_refusal_is_its_own_verdicts():
    """Three targets per method, refused and accepted in both orders: each refusal is decided by
    and names the verdict of its own method and target."""
    contract = Contract(1.75, None, None, "mm")
    on, off = [0.0, 0.0, 0.0], [0.0, 0.0, 5.0]
    verdicts = {
        "dmp": {"1": (off, "nut-one"), "2": (on, "nut-two"), "3": (off, "nut-three")},
        "bidmp": {"1": (on, "nut-one"), "2": (off, "nut-two"), "3": (on, "nut-three")},
    }
    report = SimpleNamespace(
        methods={
            method: SimpleNamespace(
                verdicts={
                    label: contract.judge([end], [0.0, 0.0, 0.0], label=name)
                    for label, (end, name) in targets.items()
                }
            )
            for method, targets in verdicts.items()
        }
    )
    for method, targets in verdicts.items():
        for label, (end, name) in targets.items():
            refusal = _refusal(report, method, label)
            if end == on:
                assert refusal == ""
            else:
                assert refusal.startswith("not run: the contract refuses its planned motion: ")
                assert name in refusal, refusal
