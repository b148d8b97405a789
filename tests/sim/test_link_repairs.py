"""A link of the arm that would touch a part the tool passes clear of starts the same repairs as
the tool's own contact, and where none keeps the arm clear the arm's own route takes the motion:
the two-posts cell with a tall post by the Panda's elbow (found by a scan of where the arm's
links run: at (90, -150) mm, 300 mm tall, the forearm of the motions to nuts 5 and 6 passes
through it). Judged from outside the repairs: PyBullet's closest points of every link along the
executed joints, the contacts the physics reports, the end and engagement by the tests' own
closed forms."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

pytest.importorskip("pybullet")
pytest.importorskip("pinocchio")

from bidmp import sim  # noqa: E402
from bidmp.tasks import scenarios  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tasks"))
from test_random_user_cells import check_end_and_descent  # noqa: E402
from test_user_cells import spec  # noqa: E402

LABELS = ("3", "5", "6")


def elbow_cell():
    data = spec("two_posts.json", "mm")
    data["targets"] = {label: data["targets"][label] for label in LABELS}
    data["scene"]["parts"].append(
        {
            "type": "cylinder",
            "label": "elbow_post",
            "at": [90, -150, -2],
            "radius": 8,
            "height": 300,
        }
    )
    data["methods"] = ["bidmp"]
    return json.loads(json.dumps(data))


@pytest.fixture(scope="module")
def simulated():
    scenario = scenarios.from_dict(elbow_cell())
    report = sim.execution_report(scenario, ["bidmp"])
    result = sim.simulate(scenario, ["bidmp"], report=report, workers=1, record=True)
    return scenario, report, result


def test_a_link_touching_a_part_starts_the_repairs_and_the_arm_runs_clear(simulated):
    scenario, report, result = simulated
    assert report.settings["arm"] is True
    bidmp = report.methods["bidmp"]
    # the links' contact started repairs for motions the contract on the tool alone keeps
    noted = [
        attempt.note
        for label in ("5", "6")
        for attempt in bidmp.repairs[label].attempts
        if attempt.note.startswith("the arm cannot run it: a link would touch elbow_post")
    ]
    assert noted, {label: bidmp.repairs[label].attempts for label in ("5", "6")}
    ran = result.methods["bidmp"].targets
    for label in LABELS:
        target = ran[label]
        assert target.ran and target.task_success(scenario.success_threshold), (
            label,
            target.reason,
        )
        assert not target.contacts, (label, target.contacts)
        check_end_and_descent(target.path, scenario.targets[label], elbow_cell(), (label,))


def test_the_executed_joints_keep_every_link_off_the_post(simulated):
    """PyBullet's closest points of the whole arm to the post at the executed joints (every
    recorded sample, 500 Hz): never touching."""
    scenario, _, result = simulated
    base, yaw = sim.robot_placement(scenario)
    with sim.RobotCell(scenario.scene, scenario.units, base, yaw) as cell:
        post = next(body for body, owner in cell._owners.items() if owner == "elbow_post")
        p = cell.p
        for label in ("5", "6"):
            commands = result.methods["bidmp"].targets[label].commands
            for q in commands[::10]:
                cell._set_joints(q)
                near = p.getClosestPoints(cell.robot, post, 0.0, physicsClientId=cell.client)
                assert not [point for point in near if point[8] < -1e-4], label


def test_an_evaluation_without_the_links_check_is_not_what_the_simulator_runs():
    from bidmp.tasks import evaluate

    scenario = scenarios.from_dict(elbow_cell())
    settings = sim.execution_settings(scenario)
    unchecked = evaluate(
        scenario, ["bidmp"], repair=True, allowance=settings["allowance"]
    )  # the tool's contract alone
    with pytest.raises(ValueError, match=r"report: judged with .*arm"):
        sim.simulate(scenario, ["bidmp"], report=unchecked, workers=1)
    with pytest.raises(ValueError, match="arm checks the motions repairs are kept by"):
        evaluate(scenario, ["bidmp"], repair=False, arm=lambda motion, label: "")
    assert np.isfinite(settings["allowance"])
