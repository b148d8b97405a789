"""How ``simulate`` hands each motion on: every job carries its own target's rollout, tool
frames, excluded parts and repair (not the first target's), and the report gives each method its
own rows and the arm's own limits. Unit tests of the wiring with several of everything (two
methods, three targets of a tilted pack, an arm that is not the Panda), no simulator run: a value
taken from a neighbour's row changes what is checked here."""

from __future__ import annotations

import json
from types import SimpleNamespace

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bidmp.sim.pybullet.cell import RobotCell
from bidmp.sim.report import SimTarget
from bidmp.sim.robots import IIWA_MODEL, PANDA, UR5_MODEL
from bidmp.sim.run import _jobs, _sim_report
from bidmp.tasks import scenarios

METHODS = ["dmp", "bidmp"]
LABELS = ["4", "1", "9"]


@pytest.fixture(scope="module")
def tilted():
    return scenarios.load("nut-unscrewing-tilted")


def _report(scenario):
    """A made-up evaluation: per method and target a rollout, tool frames and a repair, each
    marked with its own method and target (numbers that differ everywhere)."""
    methods = {}
    for k, method in enumerate(METHODS):
        rollouts, frames = {}, {}
        for j, label in enumerate(LABELS):
            rollouts[label] = np.full((5 + j, 3), 10.0 * k + j)
            frames[label] = np.tile(
                [0.0, 0.0, np.sin(0.1 * (k + j)), np.cos(0.1 * (k + j))], (5 + j, 1)
            )
        methods[method] = SimpleNamespace(
            rollouts=rollouts,
            orientations=frames,
            repaired_at=lambda label, method=method: f"{method} repair of {label}",
        )
    return SimpleNamespace(methods=methods)


def test_every_job_carries_its_own_targets_motion_frames_parts_and_repair(tilted):
    report = _report(tilted)
    frames = {("dmp", "1"): 6}
    jobs = _jobs(tilted, report, METHODS, LABELS, frames, {("bidmp", "9")}, True)
    assert [(job.method, job.label) for job in jobs] == [(m, t) for m in METHODS for t in LABELS]
    for job in jobs:
        own = report.methods[job.method]
        np.testing.assert_array_equal(job.rollout, own.rollouts[job.label])
        np.testing.assert_array_equal(job.orientations, own.orientations[job.label])
        assert job.repair == f"{job.method} repair of {job.label}"
        # the target's own nut is excluded, no other target's
        assert job.label in job.exclude
        assert not set(job.exclude) & (set(LABELS) - {job.label})
        assert job.frames == frames.get((job.method, job.label), 0)
        assert job.view == ((job.method, job.label) == ("bidmp", "9")) and job.record


def _row(label: str, error: float) -> SimTarget:
    return SimTarget(
        label, error, error, None, None, {}, 0.1, 0.1, 0.1, 0.1, 1.0 + error, 0.0, True
    )


@pytest.mark.parametrize("arm", [IIWA_MODEL, UR5_MODEL], ids=lambda arm: arm.name)
def test_the_report_gives_each_method_its_own_rows_and_the_arms_own_limits(tilted, arm):
    outcomes = []
    for k, method in enumerate(METHODS):
        for j, label in enumerate(reversed(LABELS)):  # (the workers finish in any order)
            outcomes.append((method, label, _row(label, 10.0 * k + j), [], 1.0 + k + j, None))
    out = _sim_report(
        tilted, METHODS, LABELS, outcomes, (np.zeros(3), 0.0), False, (RobotCell, arm)
    )
    for method, label, row, _, _, _ in outcomes:
        assert out.methods[method].targets[label] is row
    assert list(out.methods["bidmp"].targets) == LABELS
    assert out.limits is arm.limits and out.limits != PANDA
    assert out.to_dict()["limits"]["velocity_rad_s"] == list(arm.limits.velocity)
    assert out.simulated_s == pytest.approx(sum(outcome[4] for outcome in outcomes))


@pytest.mark.parametrize("units", ["mm", "m"])
def test_the_commanded_penetration_is_the_commands_not_the_measured_tools(units):
    """The commanded tool goes straight through post 1 of the two-post cell (its axis crossed
    20 mm above the plate); the measured tool, pushed aside, passes 30 mm off it. The commanded
    depth is the tool's and the post's radii (12.5 + 4 mm: the axis crossed), in the scene's
    unit; a measured path alone would give 0."""
    from test_execution_wiring import _posts

    from bidmp.sim.run import _commanded_penetration

    metres = {"mm": 1e-3, "m": 1.0}[units]
    scene = _posts(units).scene
    x = np.linspace(40.0, 110.0, 141)
    through = np.column_stack([x, np.full_like(x, 25.0), np.full_like(x, 18.0)]) * 1e-3
    aside = through + [0.0, 0.030, 0.0]
    cell = SimpleNamespace(scene=scene, unit=metres)
    run = SimpleNamespace(commanded_tcp=through, tcp=aside)
    job = SimpleNamespace(exclude=["3"], orientations=None)
    depth = _commanded_penetration(cell, run, job)
    assert depth == pytest.approx(16.5e-3 / metres, rel=1e-2)  # (a post is a polygon: 0.1 mm)
    clear = _commanded_penetration(cell, SimpleNamespace(commanded_tcp=aside, tcp=through), job)
    assert clear == 0.0


@pytest.fixture(scope="module")
def nuts_evaluated():
    from bidmp.sim import execution_report

    nuts = scenarios.load("nut-unscrewing")
    return nuts, execution_report(nuts, METHODS)


def test_each_methods_own_verdict_decides_and_the_arms_own_limits_judge(nuts_evaluated):
    """On the ideal arm (six joints: its own limits, not the Panda's seven), two methods, two
    targets; bidmp's motion to nut 4 refused in the report it is handed (its verdict replaced by
    one that misses the nut): that one motion is not sent, dmp's to the same nut is. Every motion
    sent is judged on its commands against the ideal arm's limits and its commanded depth is
    measured (0: clear)."""
    import copy

    from bidmp.sim import simulate
    from bidmp.sim.kinematic import KinematicCell

    nuts, evaluated = nuts_evaluated
    report = copy.copy(evaluated)
    report.methods = dict(evaluated.methods)
    bidmp = copy.copy(evaluated.methods["bidmp"])
    bidmp.verdicts = dict(bidmp.verdicts)
    missed = bidmp.verdicts["4"]
    bidmp.verdicts["4"] = missed.__class__(**{**vars(missed), "end_error": 9.0})
    assert not bidmp.verdicts["4"].ok
    report.methods["bidmp"] = bidmp
    result = simulate(
        nuts, METHODS, targets=["4", "1"], backend="kinematic", report=report, workers=1
    )
    refused = result.methods["bidmp"].targets["4"]
    assert not refused.ran and "refuses its planned motion" in refused.error
    for method, label in (("dmp", "4"), ("dmp", "1"), ("bidmp", "1")):
        row = result.methods[method].targets[label]
        assert row.ran, row.error
        assert row.verdict.limits is not None and row.commanded_penetration == 0.0
        assert len(KinematicCell.limits.velocity) == 6
        assert result.limits is KinematicCell.limits


def test_a_perception_update_is_judged_where_the_part_turned_out_to_be(nuts_evaluated):
    """Closed loop on the ideal arm: nut 1 turns out 4 mm off where it was seen, half-way; the arm
    follows the moved goal and the row is judged there: on target (4 mm from the seen one)."""
    from bidmp.sim import GoalUpdate, execution_report, simulate

    nuts, _ = nuts_evaluated
    robot = nuts.with_robot_protocol()
    report = execution_report(robot, ["bidmp"])
    offset = (4.0, -1.0, 0.0)
    result = simulate(
        robot,
        ["bidmp"],
        targets=["1", "6"],
        closed_loop=True,
        backend="kinematic",
        report=report,
        goal_update=GoalUpdate(1.0, offset),
        workers=1,
    )
    for label, row in result.methods["bidmp"].targets.items():
        assert row.measured_error <= nuts.success_threshold, (label, row.measured_error)


def test_the_arms_own_route_is_asked_for_each_targets_axis_and_the_margin_with_room(
    tilted, monkeypatch
):
    """What ``simulate`` hands the arm's route planner for a motion (a recorder in its place):
    each target's own axis (a target turned differently from the first included), where the
    motion starts, and the scene's margin plus 0.5 mm of room for the arm's tracking."""
    from bidmp.sim import run as run_module
    from bidmp.sim.backend import SimError
    from bidmp.sim.report import _SimTask

    data = json.loads(scenarios.builtin_text("nut-unscrewing-tilted"))
    turned = Rotation.from_euler("y", 20.0, degrees=True) * Rotation.from_quat([1.0, 0.0, 0.0, 0.0])
    data["targets"]["9"] = [*data["targets"]["9"][:3], *turned.as_quat()]
    data.pop("scene")
    labels = ["4", "9"]
    task = _SimTask.of(scenarios.from_dict(data), labels)
    asked = []

    def recorder(cell, contract, start, target, **given):
        asked.append((np.asarray(start), np.asarray(target), given))
        raise SimError("recorded")

    monkeypatch.setattr(run_module, "judged_route", recorder)
    setup = SimpleNamespace(task=task, pace=None)
    cell = SimpleNamespace(scene=tilted.scene)
    for label in labels:
        rollout = np.linspace(
            np.asarray(task.targets[label][:3]) + 60.0, task.targets[label][:3], 9
        )
        job = SimpleNamespace(label=label, rollout=rollout, exclude=[label])
        with pytest.raises(SimError, match="recorded"):
            run_module._arm_routed(setup, cell, None, job)
        start, target, given = asked[-1]
        np.testing.assert_allclose(start, rollout[0])
        np.testing.assert_allclose(target, task.targets[label])
        axis = -Rotation.from_quat(task.targets[label][3:7]).apply([0.0, 0.0, 1.0])
        np.testing.assert_allclose(given["axis"], axis, atol=1e-6)
        assert given["margin"] == pytest.approx(tilted.scene.margin + 0.5)
        assert given["exclude"] == [label]
