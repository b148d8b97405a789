"""Your own robot in the simulator (issue 24.3): the KUKA iiwa of pybullet_data on the nut task,
a URDF named in a scenario, its validation, and the one-line message for targets out of reach."""

import json

import numpy as np
import pytest

pytest.importorskip("pybullet")

from bidmp import scenarios, sim  # noqa: E402
from bidmp.cli import main  # noqa: E402
from bidmp.evaluation import evaluate  # noqa: E402
from bidmp.scenarios import ScenarioError  # noqa: E402


def nut_spec(**robot):
    spec = json.loads(scenarios.builtin_text("nut-unscrewing"))
    spec["robot"] = robot
    return spec


@pytest.fixture(scope="module")
def iiwa():
    return scenarios.load("nut-unscrewing-iiwa")


def test_the_iiwa_runs_the_nut_task_within_its_own_limits(iiwa):
    report = evaluate(iiwa, ["bidmp"], geometry=False)
    labels = ["1", "11", "12"]  # the demonstration's start side, and the two furthest nuts
    result = sim.simulate(iiwa, ["bidmp"], targets=labels, report=report, workers=1)
    assert result.robot == "iiwa" and result.limits == sim.IIWA
    method = result.methods["bidmp"]
    assert method.task_successes == 3 and method.contacts == 0 and method.within_limits == 3
    for label, target in method.targets.items():
        # The measured motion against the iiwa's limits, not the Panda's (the iiwa's joint speeds
        # are 0.75-1.2 rad/s lower: a plan timed to the Panda would break them).
        assert target.measured_peak_velocity <= 1.0 and target.measured_peak_acceleration <= 1.0
        assert target.peak_jerk <= 1.0 and target.measured_error <= iiwa.success_threshold
    assert "KUKA LBR iiwa" in result.summary()
    assert result.to_dict()["robot"]["model"] == "iiwa"


def test_plans_are_timed_to_the_arm_own_limits(iiwa):
    """The same path on the iiwa with its limits, then with every limit halved: the joint speeds
    stay within each model's own velocity limits, and the motion takes between 2^(1/3) times
    (jerk-bound) and 2 times (velocity-bound) as long: a property of time scaling."""
    import dataclasses

    report = evaluate(iiwa, ["bidmp"], geometry=False)
    rollout = report.methods["bidmp"].rollouts["11"]
    full = sim.ROBOT_MODELS["iiwa"]
    halved = dataclasses.replace(full, limits=sim.JointLimits(
        full.limits.lower, full.limits.upper, *(tuple(v / 2 for v in getattr(full.limits, name))
                                                for name in ("velocity", "acceleration", "jerk"))))
    durations = []
    for model in (full, halved):
        with sim.RobotCell(iiwa.scene, iiwa.units, [50.0, -550.0, 0.0], 90.0, model) as cell:
            plan = cell.plan(rollout, "11")
            grid = np.linspace(0.0, 1.0, 4001)
            speeds = np.abs(plan.spline(grid, 1)) / plan.duration
            assert np.all(speeds.max(axis=0) <= np.asarray(model.limits.velocity) * sim.LIMIT_MARGIN * 1.001)
            durations.append(plan.duration)
    assert 2 ** (1 / 3) - 1e-3 <= durations[1] / durations[0] <= 2.0 + 1e-3


def test_a_base_too_close_names_what_is_out_of_reach():
    scenario = scenarios.from_dict(nut_spec(model="iiwa", base=[50, -450, 0], yaw=90))
    targets = sim.simulate(scenario, ["dmp"], targets=["3", "4"], workers=1).methods["dmp"].targets
    for target in targets.values():  # every motion starts there: every target is a row with the reason
        assert not target.ran and target.reason.startswith("the demonstration's start is unreachable for the iiwa at base")
        assert "\n" not in target.reason


def test_the_default_placement_of_the_iiwa_reaches_the_task():
    spec = nut_spec(model="iiwa")
    scenario = scenarios.from_dict(spec)
    base, _ = sim.robot_placement(scenario)
    assert base[1] == pytest.approx(-120.0 - 430.0)  # its standoff, not the Panda's 330 mm
    result = sim.simulate(scenario, ["bidmp"], targets=["3"], workers=1)
    assert result.methods["bidmp"].task_successes == 1


def test_a_urdf_named_in_the_scenario(tmp_path):
    limits = {"lower": [-2.9, -2.0, -2.9, -2.0, -2.9, -2.0, -3.0], "upper": [2.9, 2.0, 2.9, 2.0, 2.9, 2.0, 3.0],
              "velocity": [1.0] * 7, "acceleration": [5.0] * 7, "jerk": [500.0] * 7}
    spec = nut_spec(urdf="kuka_iiwa/model.urdf", flange="lbr_iiwa_link_7", limits=limits,
                    rest=[0.0, 0.5, 0.0, -1.4, 0.0, 1.2, 0.0], base=[50, -550, 0])
    scenario = scenarios.from_dict(spec)
    result = sim.simulate(scenario, ["bidmp"], targets=["3"], workers=1)
    assert result.robot == "model" and result.limits.velocity == (1.0,) * 7
    target = result.methods["bidmp"].targets["3"]
    assert result.methods["bidmp"].task_successes == 1 and target.peak_velocity <= 1.0
    # A URDF in the scenario's folder is read from there; outside it, refused.
    (tmp_path / "arm.urdf").write_text("<robot name='x'></robot>")
    local = scenarios.from_dict(nut_spec(urdf="arm.urdf", flange="tool0", limits=limits), base_dir=tmp_path)
    assert local.robot["urdf"] == str((tmp_path / "arm.urdf").resolve())
    with pytest.raises(ValueError, match="no link 'tool0'"):
        sim.simulate(local, ["dmp"], targets=["3"], workers=1)


@pytest.mark.parametrize("robot, message", [
    ({"model": "kr6"}, r"robot.model: expected one of \['panda', 'iiwa', 'xarm6', 'ur5'\]"),
    ({"model": "iiwa", "urdf": "a.urdf"}, "not both"),
    ({"flange": "x"}, "describe your own"),
    ({"urdf": "a.urdf"}, "robot.flange"),
    ({"urdf": "a.txt", "flange": "x"}, r"robot.urdf: expected the path of a .urdf"),
    ({"urdf": "a.urdf", "flange": "x", "limits": {"lower": [0] * 7}}, "robot.limits: expected"),
    ({"urdf": "a.urdf", "flange": "x", "limits": {"lower": [0] * 7, "upper": [1] * 7, "velocity": [1] * 6,
                                                   "acceleration": [1] * 7}}, r"robot.limits.velocity: expected 7"),
    ({"urdf": "a.urdf", "flange": "x", "limits": {"lower": [1] * 7, "upper": [0] * 7, "velocity": [1] * 7,
                                                   "acceleration": [1] * 7}}, "lower must be below upper"),
    ({"urdf": "a.urdf", "flange": "x", "limits": {"lower": [0] * 7, "upper": [1] * 7, "velocity": [-1] * 7,
                                                   "acceleration": [1] * 7}}, r"velocity\[0\]: must be > 0"),
    ({"speed": 3}, r"unknown \['speed'\]"),
])
def test_robot_keys_are_validated_by_name(robot, message):
    with pytest.raises(ScenarioError, match=message):
        scenarios.from_dict(nut_spec(**robot))


def test_a_urdf_outside_the_scenario_folder_is_refused(tmp_path):
    outside = tmp_path / "arm.urdf"
    outside.write_text("<robot/>")
    inner = tmp_path / "cell"
    inner.mkdir()
    limits = {"lower": [0] * 7, "upper": [1] * 7, "velocity": [1] * 7, "acceleration": [1] * 7}
    with pytest.raises(ScenarioError, match="outside the scenario's folder"):
        scenarios.from_dict(nut_spec(urdf="../arm.urdf", flange="x", limits=limits), base_dir=inner)


def test_bidmp_sim_runs_the_iiwa_scenario(tmp_path, capsys):
    code = main(["sim", "--scenario", "nut-unscrewing-iiwa", "--methods", "bidmp", "--targets", "3",
                 "--no-pictures", "--workers", "1", "--out", str(tmp_path)])
    out = capsys.readouterr().out
    assert code == 0 and "KUKA LBR iiwa 7 R800" in out
    written = json.loads((tmp_path / "sim_results.json").read_text())
    assert written["robot"]["model"] == "iiwa"
    assert written["limits"]["velocity_rad_s"] == list(sim.IIWA.velocity)


def test_the_iiwa_runs_the_nut_job(iiwa):
    """Issue 25 on another arm: the same job, its plans timed to the iiwa's own limits."""
    from bidmp.sim.job import run_job

    report = run_job(iiwa, targets=["3", "12"])
    assert report.robot == "iiwa" and report.removed == 2
    assert all(not target.contacts and target.within_limits for target in report.targets)
