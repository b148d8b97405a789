"""What the simulator takes from the evaluation is each motion's own: the refusal of a motion is
its own verdict's (not the first target's), and the room the repairs leave for the arm's
tracking is 0.5 mm in the scenario's own unit. Several of everything: two methods, three targets
refused and accepted in both orders, the same cell in mm, cm and m."""

from __future__ import annotations

import copy
import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
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


def _descent(target, axis, length: float, frames=None) -> np.ndarray:
    """A motion down ``axis`` onto ``target`` from ``length`` out (the tool's frames beside the
    positions when given)."""
    path = np.asarray(target, dtype=float)[:3] + np.linspace(length, 0.0, 30)[:, None] * axis
    return path if frames is None else np.hstack([path, np.repeat(frames[None], 30, axis=0)])


@pytest.mark.parametrize("units", ["mm", "m"])
def test_the_links_check_excludes_each_targets_own_parts_and_places_the_arm_in_metres(units):
    """The two-post cell's arm (its URDF on pinocchio): the socket coming straight down onto nuts
    4 and 6 takes in its own nut (not a touch), in mm and m; a move of the tool through post 1
    is a touch of post 1 (the arm placed at its base in metres, where it reaches)."""
    pytest.importorskip("pinocchio")
    from bidmp.sim.execution import _links_check

    scenario = _posts(units)
    check = _links_check(scenario)
    f = PER_MM[units]
    for label in ("4", "6"):
        motion = _descent(scenario.targets[label], np.array([0.0, 0.0, 1.0]), 40.0 * f)
        assert check(motion, label) == "", label
    x = np.linspace(40.0, 110.0, 30)
    through = np.column_stack([x, np.full_like(x, 25.0), np.full_like(x, 18.0)]) * f
    assert "post1" in check(through, "4")


def test_the_links_check_takes_a_tilted_tools_frames():
    """The tilted pack (30 degrees): the socket coming down nut 4's axis turned onto it takes the
    nut in clear of the plate; held upright on the same path its rim cuts into the tilted plate."""
    pytest.importorskip("pinocchio")
    from scipy.spatial.transform import Rotation

    from bidmp.sim.execution import _links_check

    tilted = scenarios.load("nut-unscrewing-tilted")
    check = _links_check(tilted)
    pose = np.asarray(tilted.targets["4"], dtype=float)
    axis = -Rotation.from_quat(pose[3:7]).apply([0.0, 0.0, 1.0])
    assert check(_descent(pose, axis, 40.0, pose[3:7]), "4") == ""
    upright = Rotation.from_quat([1.0, 0.0, 0.0, 0.0]).as_quat()
    assert "plate" in check(_descent(pose, axis, 40.0, upright), "4")
