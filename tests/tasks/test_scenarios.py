"""Scenario files: built-ins, round trips and every kind of malformed file."""

import copy
import json

import numpy as np
import pytest

from bidmp.cli import main
from bidmp.io import save_trajectory
from bidmp.tasks import ScenarioError, scenarios


def nut_spec():
    return json.loads(scenarios.builtin_text("nut-unscrewing"))


def test_builtins_load_and_have_the_spec_geometry():
    assert scenarios.builtin_names() == [
        "cell-removal",
        "cell-rocking",
        "nut-unscrewing",
        "nut-unscrewing-iiwa",
        "nut-unscrewing-tilted",
        "nut-unscrewing-ur5",
        "nut-unscrewing-xarm6",
        "pick-and-place",
    ]
    nut = scenarios.load("nut-unscrewing")
    assert len(nut.targets) == 14 and nut.demonstrated == "3"
    np.testing.assert_array_equal(nut.targets["3"], [0, 0, 0])
    # The paper's numbering: row y = 0: 3, 4, 5, 6, 9, 10, 11; row y = 50: 2, 1, 7, 8, 14, 13, 12.
    row0 = [label for label, p in sorted(nut.targets.items(), key=lambda kv: kv[1][0]) if p[1] == 0]
    row50 = [
        label for label, p in sorted(nut.targets.items(), key=lambda kv: kv[1][0]) if p[1] == 50
    ]
    assert row0 == ["3", "4", "5", "6", "9", "10", "11"] and row50 == [
        "2",
        "1",
        "7",
        "8",
        "14",
        "13",
        "12",
    ]
    assert nut.demonstration.shape == (200, 3)
    np.testing.assert_allclose(nut.demonstration[[0, -1]], [[-80, -120, 200], [0, 0, 0]])
    for name in ("cell-removal", "pick-and-place"):
        assert scenarios.load(name).targets


def test_copy_a_builtin_to_a_file_and_edit_it(tmp_path, capsys):
    assert main(["scenario", "show", "nut-unscrewing"]) == 0
    text = capsys.readouterr().out
    data = json.loads(text)
    data["name"] = "my-layout"
    data["targets"] = {"3": [0, 0, 0], "far": [250, 40, -10]}
    (tmp_path / "mine.json").write_text(json.dumps(data))
    mine = scenarios.load(tmp_path / "mine.json")
    assert mine.name == "my-layout" and list(mine.targets) == ["3", "far"]
    assert scenarios.from_dict(mine.to_dict()).targets.keys() == mine.targets.keys()
    assert main(["scenario", "check", str(tmp_path / "mine.json")]) == 0


def test_demonstration_from_points_and_from_a_csv_file(tmp_path):
    demo = scenarios.load("nut-unscrewing").demonstration
    save_trajectory(demo, tmp_path / "demo.csv")
    data = nut_spec()
    data["demonstration"] = {"file": "demo.csv"}
    (tmp_path / "s.json").write_text(json.dumps(data))
    np.testing.assert_array_equal(scenarios.load(tmp_path / "s.json").demonstration, demo)
    data["demonstration"] = {"points": demo.tolist()}
    np.testing.assert_array_equal(scenarios.from_dict(data).demonstration, demo)


def mutate(change):
    data = nut_spec()
    change(data)
    return data


MALFORMED = [
    (lambda d: d.update(colour="red"), "colour: unknown key"),
    (lambda d: d.pop("targets"), "targets: missing"),
    (lambda d: d.pop("demonstration"), "demonstration: missing"),
    (lambda d: d.update(targets={}), "targets: expected a non-empty object"),
    (lambda d: d["targets"].update({"7": [60, "fifty", 0]}), "targets.7: expected a point"),
    (lambda d: d["targets"].update({"7": [60, 50]}), "targets.7: has 2 coordinates, expected 3"),
    (lambda d: d.update(demonstrated="99"), 'demonstrated: "99" is not among the targets'),
    (lambda d: d.update(success_threshold=-1), "success_threshold: must be > 0"),
    (lambda d: d.update(success_threshold="tight"), "success_threshold: expected a number"),
    (lambda d: d.update(approach_height=0), "approach_height: must be > 0"),
    (lambda d: d["dmp"].update(alpah=3), "dmp.alpah: unknown parameter"),
    (lambda d: d["dmp"].update(alpha=-5), "dmp: alpha must be > 0"),
    (lambda d: d.update(methods=["dmp", "magic"]), "methods: unknown method 'magic'"),
    (lambda d: d.update(extension_target="middle"), "extension_target: 'middle' is neither"),
    (
        lambda d: d.update(demonstration={"minimum_jerk": {"via": [[0, 0, 0]]}}),
        "via: expected a list of at least 2 points",
    ),
    (
        lambda d: d.update(
            demonstration={"minimum_jerk": {"via": [[0, 0, 1], [0, 0, 0]], "speed": 3}}
        ),
        "minimum_jerk.speed: unknown key",
    ),
    (
        lambda d: d.update(demonstration={"points": [[0, 0, 0], [1, 1, 1]], "file": "x.csv"}),
        "demonstration: expected exactly one of",
    ),
    (lambda d: d.update(demonstration={"file": "missing.csv"}), "demonstration.file:"),
    (lambda d: d.update(extensions=[{"target": "3", "from": "previous"}]), "extensions[0].from"),
    (lambda d: d.update(seed=-2), "seed: expected an integer in [0, 2**32)"),
    (lambda d: d["dmp"].update(fit="ridge"), "dmp.fit: renamed to 'regression'"),
    (lambda d: d.update(bidmp={"reg": -1.0}), "bidmp: reg must be >= 0"),
    (lambda d: d.update(bidmp={"n_nodes": 3}), "bidmp.n_nodes: unknown parameter"),
    (
        lambda d: d.update(extension={"n_iterations": 3}),
        "extension.n_iterations: unknown parameter",
    ),
]


@pytest.mark.parametrize("change, match", MALFORMED)
def test_malformed_scenarios_give_an_error_naming_the_key(change, match):
    with pytest.raises(ScenarioError) as info:
        scenarios.from_dict(mutate(change), source="bad.json")
    assert match in str(info.value)
    assert str(info.value).startswith("scenario bad.json: ")


@pytest.mark.parametrize("change, match", MALFORMED[:12])
def test_cli_reports_malformed_scenarios_in_one_line(tmp_path, change, match, capsys):
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(mutate(change)))
    code = main(["demo", "--scenario", str(path), "--out", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert code == 2 and match in err and len(err.strip().splitlines()) == 1, err


def test_not_json_and_unknown_builtin(tmp_path):
    (tmp_path / "broken.json").write_text("{ not json")
    with pytest.raises(ScenarioError, match="not valid JSON"):
        scenarios.load(tmp_path / "broken.json")
    with pytest.raises(ScenarioError, match="no such file, and not a built-in"):
        scenarios.load("nuts-unscrewing")
    with pytest.raises(ScenarioError, match="unknown built-in scenario"):
        scenarios.builtin_text("nope")


def test_scenario_sets_bidmp_and_extension_parameters():
    from bidmp.tasks import evaluate

    data = mutate(
        lambda d: d.update(
            bidmp={"reg": 1e-2, "increments": [5]}, extension={"n_iter": 3, "n_samples": 120}
        )
    )
    scenario = scenarios.from_dict(data)
    assert scenario.bidmp.arguments == {
        "reg": 1e-2,
        "increments": (5,),
    } and scenario.extension.flat == {
        "n_iter": 3,
        "n_samples": 120,
    }
    assert scenario.extension.roadmap.n_iter == 3 and scenario.extension.approach == "keep"
    report = evaluate(scenario, ["bidmp"])
    assert report.model.reg == 1e-2 and report.model.increments == (5,)
    assert report.extensions[0].similarity_history.shape == (3,)
    assert report.model.blocks_[0].n_hidden_ == 10 * 10 + 100 + 5


def test_replace_checks_the_changed_keys_as_a_file_and_leaves_the_scenario_as_it_was():
    """``Scenario.replace`` instead of a dict round trip: a changed parameter object is checked by
    what takes it (the DMP's, the extension's own checks), a changed other key by reading the whole
    file again; the original scenario is untouched."""
    from bidmp.extension import RoadmapOptions
    from bidmp.tasks.scenarios import ScenarioError, load

    nuts = load("nut-unscrewing")
    before = copy.deepcopy(nuts.spec)
    paper = nuts.replace(extension={**nuts.extension.flat, "approach": "paper", "n_iter": 4})
    assert paper.extension_arguments["approach"] == "paper"
    assert paper.extension_arguments["roadmap"] == RoadmapOptions(n_iter=4)
    assert paper.spec["extension"]["n_iter"] == 4 and nuts.spec == before
    robot = load("nut-unscrewing").replace(dmp={"protocol": "paper", "n_kernels": 30})
    assert robot.protocol == "paper" and robot.with_robot_protocol().protocol == "robot"
    assert robot.with_robot_protocol().dmp.arguments == {"protocol": "robot", "n_kernels": 30}
    fewer = nuts.replace(targets={label: nuts.spec["targets"][label] for label in ("1", "3")})
    assert fewer.labels == ["1", "3"] and len(nuts.labels) == 14
    with pytest.raises(ScenarioError, match="extension.*n_iter must be >= 1"):
        nuts.replace(extension={"n_iter": 0})
    with pytest.raises(ScenarioError, match="dmp.*alpha"):
        nuts.replace(dmp={"alpha": -1.0})
    with pytest.raises(ScenarioError, match="colour.*unknown key"):
        nuts.replace(colour="red")
