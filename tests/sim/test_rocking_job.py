"""A periodic skill in the battery job: cells rocked loose before the lift (the built-in
cell-rocking scenario), judged by the one motion contract. On the kinematic arm (the measured
motion is exactly the commands, so what is checked is the plan and the judging), against the
numbers the recording was made with (tools/rocking_recording.py: ±2 mm along x at 1.6 Hz)."""

from __future__ import annotations

import json

import numpy as np
import pytest

from bidmp.sim.job import run_job
from bidmp.tasks import scenarios


def test_cells_are_rocked_as_recorded_then_lifted_and_placed():
    scenario = scenarios.load("cell-rocking")
    report = run_job(scenario, targets=["B2", "B7"], backend="kinematic", record=True)
    for target in report.targets:
        assert target.removed, target.reason
        names = [phase.name for phase in target.phases]
        assert names == ["approach", "grasp", "rock", "lift", "place"]
        rock = target.phases[2]
        assert rock.ok and rock.verdict.ok
        path = rock.path  # the measured tool path, scene units
        grasp = path[0]
        sway = path[:, 0] - grasp[0]
        # ±2 mm along x as recorded (the learned swing, measured on the executed motion)
        assert np.ptp(sway) == pytest.approx(4.0, rel=0.05)
        assert np.ptp(path[:, 1]) < 0.6 and np.ptp(path[:, 2]) < 0.5
        # from rest at the grasp and back to rest there
        np.testing.assert_allclose(path[-1], grasp, atol=0.01)
        # 3 cycles: 6 sign changes of the sway at least, at about the recorded frequency
        moving = np.abs(sway) > 0.2
        signs = np.sign(sway[moving])
        crossings = np.count_nonzero(np.diff(signs) != 0)
        assert crossings >= 5
        t = np.linspace(0.0, rock.seconds, path.shape[0])
        up = np.flatnonzero((sway[:-1] < 0) & (sway[1:] >= 0))
        periods = np.diff(t[up])
        steady = periods[1:-1] if periods.size > 2 else periods
        assert 1.0 / np.median(steady) == pytest.approx(1.6, rel=0.05)


def test_a_rock_too_wide_for_the_slot_breaks_the_contract(tmp_path):
    """Planted: a swing of ±8 mm in 10 mm gaps brings the rocked cell within the margin of its
    neighbour: the rock phase fails by clearance, naming a neighbouring cell, and the cell is not
    removed."""
    data = json.loads(scenarios.builtin_text("cell-rocking"))
    data["job"]["rock"]["amplitude"] = 4.0
    path = tmp_path / "wide.json"
    path.write_text(json.dumps(data))
    report = run_job(scenarios.load(str(path)), targets=["B2"], backend="kinematic")
    target = report.targets[0]
    assert not target.removed
    rock = next(phase for phase in target.phases if phase.name == "rock")
    assert not rock.ok
    assert "rock" in target.reason and ("B1" in target.reason or "B3" in target.reason)


def test_the_rock_key_is_checked_by_name():
    data = json.loads(scenarios.builtin_text("cell-rocking"))
    data["job"]["rock"]["recording"] = "nowhere"
    with pytest.raises(ValueError, match="job.rock.recording"):
        scenarios.from_dict(data, source="x")
    del data["job"]["rock"]
    with pytest.raises(ValueError, match="job.rock"):
        scenarios.from_dict(data, source="x")


def test_cell_jobs_run_on_the_kinematic_arm():
    """Found while building the rock step: the kinematic arm measured contacts on the scenario's
    scene without the job's rack, and refused the place step's exclusion of it."""
    report = run_job(scenarios.load("cell-removal"), targets=["B1"], backend="kinematic")
    assert report.targets[0].removed, report.targets[0].reason
