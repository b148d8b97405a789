"""Nothing runs that the contract refuses: a motion whose plan still breaks the contract after
every repair is never sent to the arm, in ``simulate`` and in the job; the row says why and no
simulated time is spent on it."""

from __future__ import annotations

import pathlib

import numpy as np
import pytest

from bidmp import sim
from bidmp.tasks import scenarios

DATA = pathlib.Path(__file__).resolve().parents[1] / "data"


@pytest.fixture(scope="module")
def two_posts():
    return scenarios.load(str(DATA / "two_posts.json"))


def _cuts_into_a_post(scenario, path) -> float:
    """How deep the tool's axis line comes into a post, from the posts' own numbers (a vertical
    cylinder: the distance of each sample from its axis, below its top), independent of the
    scene's geometry code: the tool's radius is added from the scene's numbers."""
    tool = scenario.scene.tool.radius
    deepest = 0.0
    for solid in scenario.scene.solids:
        if not solid.label.startswith("post"):
            continue
        radius, height = solid.params
        centre = np.asarray(solid.centre, dtype=float)
        below_top = path[:, 2] <= centre[2] + height / 2.0
        across = np.linalg.norm(path[:, :2] - centre[:2], axis=1)
        inside = (radius + tool) - across
        if np.any(below_top):
            deepest = max(deepest, float(np.max(inside[below_top])))
    return deepest


def test_a_motion_the_contract_refuses_is_not_sent_to_the_arm(two_posts):
    """The plain DMP does not repair its motions: to nuts 8 and 13 its rollout passes through a
    post (measured here from the posts' radius and the tool's, not by the scene's code). Those
    are rows that say why, with no commands, no contacts and no simulated time; Bi-DMP's
    repaired motions to the same nuts run and succeed."""
    report = sim.execution_report(two_posts, ["dmp", "bidmp"])
    labels = ["8", "13", "4"]
    result = sim.simulate(
        two_posts,
        ["dmp", "bidmp"],
        targets=labels,
        report=report,
        backend="kinematic",
        record=True,
        workers=1,
    )
    through = {
        label: _cuts_into_a_post(two_posts, np.asarray(report.methods["dmp"].rollouts[label]))
        for label in labels
    }
    assert through["8"] > 0 and through["13"] > 0 and through["4"] <= 0, through
    for label in labels:
        row = result.methods["dmp"].targets[label]
        if through[label] > 0:
            assert not row.ran and row.commands is None and not row.contacts
            assert row.motion_time == 0.0
            assert "not run: the contract refuses" in row.error and "post" in row.error
        else:
            assert row.ran and row.commands is not None
        assert result.methods["bidmp"].targets[label].task_success(two_posts.success_threshold)
    ran = [t for m in result.methods.values() for t in m.targets.values() if t.ran]
    assert result.simulated_s == pytest.approx(sum(t.motion_time for t in ran), rel=0.2)


def test_a_job_refuses_a_straight_move_through_a_part_before_running_it(monkeypatch):
    """The retract after unscrewing, sent sideways into the neighbouring nut's stud by a planted
    bug (a wrong frame: the world's x for the part's axis), is refused from its plan: the phase
    has no commands and no simulated time, and the nut is not counted as removed."""
    from bidmp.sim import job as job_module

    original = job_module._straight

    def sideways(world, direction, length, exclude, name, part=None, **options):
        if name == "retract":
            direction, length = np.array([1.0, 0.0, 0.0]), 30.0
        return original(world, direction, length, exclude, name, part, **options)

    monkeypatch.setattr(job_module, "_straight", sideways)
    nut = scenarios.load("nut-unscrewing")
    report = sim.run_job(nut, targets=["3"], backend="kinematic", record=True)
    (target,) = report.targets
    retract = next(phase for phase in target.phases if phase.name == "retract")
    assert not retract.ok and retract.seconds == 0.0 and retract.commands is None
    assert retract.note.startswith("not run: the contract refuses its plan")
    assert not target.removed and "retract" in target.reason
