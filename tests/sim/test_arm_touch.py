"""The arm, not only the tool, is checked before a motion is sent: on a user's kind of cell (a
random user cell nobody tuned for: a UR5 in centimetres, a 90 mm cable duct beside the nuts,
seed 25 of tests/tasks/test_random_user_cells.py) the learned approach to nut r0c1 keeps the
tool clear of the duct, but the UR5's wrist runs into it. The oracle is the physics itself: the
same job with the check switched off executes the motion, and PyBullet reports the arm in
contact with the duct and the tool pushed off its path; with the check, the motion is not sent
and nothing touches anything."""

from __future__ import annotations

import pathlib
import sys

import pytest

pytest.importorskip("pybullet")

from bidmp import sim  # noqa: E402
from bidmp.sim.pybullet.cell import RobotCell  # noqa: E402
from bidmp.tasks import scenarios  # noqa: E402

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "tasks"))
from test_random_user_cells import user_cell  # noqa: E402


@pytest.fixture(scope="module")
def duct_cell():
    spec = user_cell(25)
    assert spec["robot"]["model"] == "ur5" and spec["units"] == "cm"
    return scenarios.from_dict(spec)


def test_a_motion_whose_arm_would_touch_a_part_is_not_sent(duct_cell, monkeypatch):
    with monkeypatch.context() as unchecked:
        unchecked.setattr(RobotCell, "arm_touch", lambda self, plan, exclude=(): None)
        ran = sim.run_job(duct_cell, targets=["r0c1"])
    (executed,) = ran.targets
    approach = executed.phases[0]
    assert approach.name == "approach" and "duct0" in approach.contacts  # the physics' word
    assert not executed.removed

    report = sim.run_job(duct_cell, targets=["r0c1", "r0c0"])
    refused, after = report.targets
    (phase,) = refused.phases
    # (seconds: simulated time; a motion not run spends none)
    assert not phase.ok and phase.seconds == 0.0 and not phase.contacts
    assert "the arm would touch duct0" in refused.reason
    assert after.removed and not after.contacts  # the next nut is done from where the arm stood


def test_the_simulator_does_not_send_it_either(duct_cell, monkeypatch):
    with monkeypatch.context() as unchecked:
        unchecked.setattr(RobotCell, "arm_touch", lambda self, plan, exclude=(): None)
        ran = sim.simulate(duct_cell, ["bidmp"], targets=["r0c1"], workers=1)
    executed = ran.methods["bidmp"].targets["r0c1"]
    assert executed.ran and "duct0" in executed.contacts  # the physics' word
    result = sim.simulate(duct_cell, ["bidmp"], targets=["r0c1"], workers=1)
    row = result.methods["bidmp"].targets["r0c1"]
    assert not row.ran and not row.contacts and "the arm would touch duct0" in row.error
    assert result.simulated_s == 0.0
