"""A scenario's ``dmp``, ``bidmp`` and ``robot`` objects as checked options
(``bidmp.tasks.DMPOptions``, ``BiDMPOptions``, ``RobotOptions``): refused where what takes them
would refuse them, read back from their file form, and the same skill or arm whichever way they
are passed."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from bidmp import DMP, BiDMP
from bidmp.tasks import (
    BiDMPOptions,
    Contract,
    DMPOptions,
    ExtensionStage,
    RobotOptions,
    scenarios,
)
from bidmp.tasks.methods import Task
from bidmp.tasks.repair import Repairer


@pytest.mark.parametrize(
    ("options", "error", "names"),
    [
        ({"n_kernels": 0}, ValueError, "n_kernels"),
        ({"protocol": "fast"}, ValueError, "protocol"),
        ({"alpha": "stiff"}, TypeError, "alpha"),
        ({"kernels": 30}, TypeError, "kernels"),
    ],
)
def test_dmp_options_are_refused_as_the_dmp_refuses_them(options, error, names):
    with pytest.raises(error, match=names):
        DMPOptions.from_flat(options)
    with pytest.raises(scenarios.ScenarioError, match=names):
        scenarios.load("nut-unscrewing").replace(dmp=options)


def test_bidmp_options_are_refused_as_the_bidmp_refuses_them():
    with pytest.raises(ValueError, match="n_enhance"):
        BiDMPOptions(n_enhance=-1)
    with pytest.raises(TypeError, match="windows"):
        BiDMPOptions.from_flat({"windows": 3})
    scenario = scenarios.load("nut-unscrewing")
    with pytest.raises(TypeError, match="bidmp"):
        Repairer(Contract.of(scenario), scenario.demonstration, bidmp=[("reg", 0.01)])
    with pytest.raises(TypeError, match="shrinking"):
        Repairer(Contract.of(scenario), scenario.demonstration, bidmp={"shrinking": 0.5})


def test_options_read_back_from_their_file_form_and_leave_defaults_unset():
    for scenario in (scenarios.load(name) for name in scenarios.builtin_names()):
        assert DMPOptions.from_flat(scenario.dmp.flat) == scenario.dmp
        assert BiDMPOptions.from_flat(scenario.bidmp.flat) == scenario.bidmp
        assert scenario.dmp.flat == scenario.spec.get("dmp", {})
    options = BiDMPOptions.from_flat({"increments": [5, 5], "reg": 0.01})
    assert options.increments == (5, 5) and options.flat == {"increments": [5, 5], "reg": 0.01}
    assert DMPOptions().arguments == {} and DMPOptions().protocol_name == "robot"


def test_a_skill_is_the_same_from_the_options_or_their_arguments():
    """A Task given the options objects fits what one given their keyword arguments fits, and
    both are the DMP built by hand from the file's numbers (n_kernels 30, alpha 40)."""
    y = np.cumsum(np.random.default_rng(3).normal(size=(200, 3)), axis=0)
    options = DMPOptions(n_kernels=30, alpha=40.0)
    by_object = Task(y, y[-1:], dmp=options, bidmp=BiDMPOptions(reg=0.01))
    by_arguments = Task(y, y[-1:], dmp={"n_kernels": 30, "alpha": 40.0}, bidmp={"reg": 0.01})
    assert by_object.dmp == by_arguments.dmp and by_object.bidmp == by_arguments.bidmp
    fitted, _ = by_object.fitted_dmp()
    by_hand = DMP(n_kernels=30, alpha=40.0).fit(y)
    assert fitted.weights_.shape == (30, 3)
    np.testing.assert_array_equal(fitted.rollout(), by_hand.rollout())
    assert BiDMP(by_hand, **BiDMPOptions(reg=0.01).arguments).reg == 0.01


def test_robot_options_read_back_and_place_the_same_arm(tmp_path):
    """Every built-in scenario's arm: its options read back from their file form, and the model
    and placement the simulator builds from the options are the ones it builds from the file's
    own dict (robot_model and robot_placement take either)."""
    from bidmp import sim
    from bidmp.sim.robots import robot_placement

    for scenario in (scenarios.load(name) for name in scenarios.builtin_names()):
        robot = scenario.robot
        assert RobotOptions.from_flat(robot.flat) == robot
        assert robot.flat == scenario.spec.get("robot", {})
        assert sim.robot_model(robot) is sim.robot_model(scenario.spec.get("robot"))
        as_dict = dataclasses.replace(scenario, robot=scenario.spec.get("robot", {}))
        for ours, theirs in zip(robot_placement(scenario), robot_placement(as_dict)):
            np.testing.assert_array_equal(ours, theirs)
    assert not RobotOptions().own_arm and RobotOptions().flat == {}
    with pytest.raises(scenarios.ScenarioError, match="robot.model"):
        RobotOptions.from_flat({"model": "abb"})
    with pytest.raises(scenarios.ScenarioError, match="flange"):
        RobotOptions.from_flat({"flange": "tool0"})  # an own arm's key without its urdf
    with pytest.raises(TypeError, match="spec"):
        sim.robot_model(["panda"])
    # made directly, checked as a file's: a unit-less text yaw, a non-path urdf, a 2-D base
    for bad, key in (({"yaw": ""}, "robot.yaw"), ({"urdf": float("inf")}, "robot.urdf")):
        with pytest.raises(scenarios.ScenarioError, match=key):
            RobotOptions(**bad)
    with pytest.raises(scenarios.ScenarioError, match="robot.base"):
        RobotOptions(base=(1.0, 2.0))
    assert RobotOptions(model="ur5", yaw=10).yaw == 10.0


def test_extension_stages_are_the_files_own():
    """Each stage of a built-in scenario says what its file says (or, without an "extensions"
    list, the one stage to "extension_target" from the demonstration, in the scene)."""
    for scenario in (scenarios.load(name) for name in scenarios.builtin_names()):
        stages = scenario.spec.get("extensions") or [
            {"target": scenario.spec.get("extension_target", "centre_of_failed")}
        ]
        assert len(scenario.extensions) == len(stages)
        for index, (stage, written) in enumerate(zip(scenario.extensions, stages)):
            assert isinstance(stage, ExtensionStage)
            origin = written.get("from", "demonstration" if index == 0 else "previous")
            assert stage.origin == origin and stage.from_previous == (origin == "previous")
            assert stage.in_scene == written.get("in_scene", True)
            if isinstance(written["target"], str):
                assert stage.target == written["target"]
            else:
                np.testing.assert_array_equal(stage.target, written["target"])
