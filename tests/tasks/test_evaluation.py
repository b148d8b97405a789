"""Scenario evaluation: the paper's structure on the battery tasks, honestly measured."""

import json

import numpy as np
import pytest
from scipy.stats import spearmanr

import bidmp
from bidmp import DMP
from bidmp.tasks import approach_error, evaluate, scenarios

NUT_COLUMNS_FAILED = ["9", "10", "11", "12", "13", "14"]


@pytest.fixture(scope="module")
def nut():
    return evaluate("nut-unscrewing")


def test_plain_dmp_succeeds_on_the_first_four_columns_only(nut):
    dmp = nut.methods["dmp"]
    assert dmp.successes == 8
    failed = sorted(label for label, e in dmp.errors.items() if e > 1.75)
    assert failed == sorted(NUT_COLUMNS_FAILED)
    assert 2.5 < max(dmp.errors.values()) < 3.2  # paper: 2.76 mm
    assert nut.failed_targets == NUT_COLUMNS_FAILED
    np.testing.assert_allclose(nut.extension_targets[0], [150.0, 25.0, 0.0])


def test_bidmp_succeeds_everywhere_with_the_two_level_pattern(nut):
    errors = nut.methods["bidmp"].errors
    assert nut.methods["bidmp"].successes == 14
    middle = [errors[label] for label in ("10", "13")]  # the column of the extension target
    outer = [errors[label] for label in ("9", "11", "12", "14")]  # 39 mm from it
    # Each level spreads by at most twice the skill's own end-point error (a vector added to the
    # horizon term c·(g − g_n), whose direction differs per nut).
    target = np.asarray(nut.extension_targets[0])
    own = np.linalg.norm(nut.model.rollout(target)[-1] - target)
    assert own < 0.25  # 0.18 mm since the skill lasts as long as its extension (0.04 before)
    assert np.ptp(middle) <= 2 * own + 0.02 and np.ptp(outer) <= 2 * own + 0.02
    assert max(middle) + 0.05 < min(outer) < 0.8
    # The two levels are the horizon artefact around the new skill's goal: c · ‖g − g_n‖.
    gain = DMP(**nut.scenario.dmp.arguments).fit(nut.scenario.demonstration).endpoint_gain()
    assert np.mean(outer) == pytest.approx(gain * np.hypot(30, 25), abs=0.05)
    assert np.mean(middle) == pytest.approx(gain * 25, abs=0.05)


def test_bidmp_latest_loses_the_demonstrated_nut(nut):
    latest = nut.methods["bidmp-latest"]
    assert latest.errors["3"] > 1.75 and latest.successes == 10
    assert nut.methods["bidmp"].errors["3"] < 0.1


def test_run_to_convergence_reaches_every_nut_but_dips_below_it_and_its_descent_tilts(nut):
    """Independent oracle: the dip and the tilt are computed here from the rollouts' own heights and
    horizontal offsets, not by the metrics the evaluation uses."""
    converged = nut.methods["dmp-converged"]
    assert max(converged.errors.values()) < 0.05
    origin = nut.scenario.targets["3"]
    distance, tilt = [], []
    for label, rollout in converged.rollouts.items():
        target = nut.scenario.targets[label]
        height = rollout[:, 2] - target[2]
        lowest = int(np.argmin(height))
        # Below the nut and back up by more than the contract's rise tolerance (0.002 x 28.5 mm): no
        # monotone descent, so not engaged (it was counted engaged while the rule allowed 1.4 mm).
        assert height[lowest] < -0.1 and height[-1] - height[lowest] > 0.002 * 28.5
        assert converged.engaged_at(label) is False and "monotone" in converged.reason_at(label)
        band = height < 28.5
        tilt.append(np.max(np.linalg.norm(rollout[band, :2] - target[:2], axis=1)))
        distance.append(np.linalg.norm(target - origin))
    assert (
        spearmanr(distance, tilt).statistic > 0.95
    )  # the descent tilts more as the goal moves away
    assert max(tilt) > 1.75 and converged.engaged == 0


def test_gmm_succeeds_only_at_the_demonstrated_nut_tpgmm_is_low(nut):
    gmm = nut.methods["gmm"]
    assert [label for label, e in gmm.errors.items() if e <= 1.75] == ["3"]
    assert nut.methods["tpgmm"].successes <= 2


def test_report_json_follows_the_spec_schema(nut):
    data = json.loads(json.dumps(nut.to_dict()))
    assert data["scenario"] == "nut-unscrewing"
    assert set(data["methods"]) == {"dmp", "dmp-converged", "bidmp", "bidmp-latest", "gmm", "tpgmm"}
    for result in data["methods"].values():
        assert {
            "success_rate",
            "successes",
            "n_targets",
            "errors",
            "approach_errors",
            "max_error",
            "difference_range",
            "runtime_s",
        } <= set(result)
        assert result["n_targets"] == 14 and set(result["errors"]) == set(nut.scenario.targets)
        assert result["success_rate"] == pytest.approx(result["successes"] / 14, abs=1e-4)
        assert isinstance(result["max_error"], float) and result["runtime_s"] > 0
        low, high = result["difference_range"]
        assert 0 <= low <= high
    assert data["methods"]["dmp"]["success_rate"] == pytest.approx(0.5714, abs=1e-4)


def test_another_layout_from_a_file_agrees_with_the_endpoint_gain(tmp_path):
    data = json.loads(scenarios.builtin_text("nut-unscrewing"))
    rng = np.random.default_rng(5)
    data["targets"] = {
        f"n{i}": [float(x), float(y), 0.0]
        for i, (x, y) in enumerate(rng.uniform(-100, 250, (9, 2)))
    }
    data["targets"]["demo"] = [0.0, 0.0, 0.0]
    data["demonstrated"] = "demo"
    data["methods"] = ["dmp"]
    (tmp_path / "layout.json").write_text(json.dumps(data))
    report = evaluate(scenarios.load(tmp_path / "layout.json"))
    dmp = DMP(**data["dmp"]).fit(report.scenario.demonstration)
    gain = dmp.endpoint_gain()
    e0 = dmp.rollout()[-1] - report.scenario.targets["demo"]
    for label, target in report.scenario.targets.items():
        shift = target - report.scenario.targets["demo"]
        assert report.methods["dmp"].errors[label] == pytest.approx(
            np.linalg.norm(e0 - gain * shift), abs=1e-9
        )


def test_pick_and_place_learns_every_operator_faithfully():
    """Each operator's skill reproduces that operator's demonstration as well as a DMP fitted on
    it alone (the zero forgetting of "nearest" is structural; "latest" does forget)."""
    report = evaluate("pick-and-place", ["dmp", "bidmp", "bidmp-latest"])
    assert np.all(report.forgetting["latest"].forgetting[:-1] > 1.0)
    scenario = report.scenario
    for label, demonstration in scenario.demonstrations.items():
        learned = report.model.rollout(demonstration[-1], start=demonstration[0])[
            : len(demonstration)
        ]
        scratch = DMP(**scenario.dmp.arguments).fit(demonstration).rollout()[: len(demonstration)]
        errors = [
            np.sqrt(np.mean(np.sum((r - demonstration) ** 2, axis=1))) for r in (learned, scratch)
        ]
        assert errors[0] <= 1.05 * errors[1], (label, errors)
    assert report.methods["bidmp"].successes == 3
    # Every operator's own trajectory is reproduced (difference to its demonstration, mm summed).
    for label in ("op2", "op3"):
        assert (
            report.methods["bidmp"].differences[label]
            < 0.05 * report.methods["dmp"].differences[label] + 5.0
        )


def test_cell_removal_second_extension_fixes_b6():
    before_spec = scenarios.load("cell-removal").to_dict()
    before_spec["extensions"] = before_spec["extensions"][:1]
    before = evaluate(scenarios.from_dict(before_spec), ["bidmp"]).methods["bidmp"].errors
    after = evaluate("cell-removal", ["bidmp"]).methods["bidmp"].errors
    assert after["B6"] < 0.6 * before["B6"]  # 0.51 since the extensions are timed (0.10 before)
    assert after["N3"] == pytest.approx(before["N3"])  # the nut skill is not forgotten


def test_approach_error_definition():
    path = np.array([[10.0, 0.0, 100.0], [3.0, 4.0, 20.0], [1.0, 0.0, 5.0], [0.0, 0.0, 0.0]])
    assert approach_error(path, np.zeros(3), 28.5) == pytest.approx(5.0)
    assert approach_error(path, np.zeros(3), 1.0) == 0.0


def test_unknown_method_is_rejected():
    with pytest.raises(ValueError, match="unknown method 'magic'"):
        bidmp.evaluate("nut-unscrewing", ["magic"])


def test_a_target_with_no_route_is_that_targets_failure_not_the_evaluations():
    """A closed cage round the far nuts (four walls and a lid, high enough for the tool to come
    straight down onto each nut inside it) leaves them no collision-free route from outside, by
    any planner; the evaluation still reports every method, the far targets fail, each saying
    why (the nuts beside the wall: no motion can come down onto them; the others: the
    extension's roadmap and the route's search found none), and the report keeps the extension
    stage's failure."""
    import json

    base = scenarios.load("nut-unscrewing")
    spec = base.to_dict()
    cage = [  # (centre of the bottom face, size) in mm: x 100..270, y -185..235, lid at z 300
        ([105, 25, -2], [10, 400, 302]),
        ([265, 25, -2], [10, 400, 302]),
        ([185, -180, -2], [150, 10, 302]),
        ([185, 230, -2], [150, 10, 302]),
        ([185, 25, 300], [170, 420, 10]),
    ]
    spec["scene"]["parts"] += [
        {"type": "box", "label": f"cage{k}", "at": at, "size": size}
        for k, (at, size) in enumerate(cage)
    ]
    walled = scenarios.from_dict(spec, base_dir=base.base_dir)
    report = evaluate(walled, ["dmp", "bidmp"])
    assert set(report.methods) == {"dmp", "bidmp"}
    assert (
        len(report.route_failures) == 1
        and "no collision-free route" in report.route_failures[0]["reason"]
    )
    far = [label for label in walled.labels if walled.targets[label][0] > 105]
    bidmp = report.methods["bidmp"]
    assert far and not any(bidmp.task_success_at(label) for label in far)
    for label in far:  # refused at once beside the wall, else the complete fallback was tried
        repaired = bidmp.repairs[label]
        tried = [attempt.how for attempt in repaired.attempts]
        assert "cage0" in repaired.refused or "route" in tried, (label, repaired.reason())
    data = json.loads(
        json.dumps(report.to_dict(), allow_nan=False)
    )  # strict JSON: no Infinity, no NaN
    assert data["route_failures"][0]["target"][0] == pytest.approx(150.0)


def test_a_learned_skill_inside_the_margin_is_planned_again_wider(caplog, monkeypatch):
    """4 (structure: the repair loop's control flow, with the first check of the learned
    rollout forced inside the margin; on 150 random cells no learned rollout came inside its
    extension's margin). The extension is planned again with the margin widened by the shortfall,
    and the evaluation goes on to the same successes."""
    import inspect
    import logging

    from bidmp.scene.clearance import Clearance

    nut = scenarios.load("nut-unscrewing")
    real = type(nut.scene).clearance
    calls = []

    def first_too_close(scene, trajectory, exclude=(), **options):
        found = real(scene, trajectory, exclude, **options)
        if inspect.stack()[1].function == "_learned_clear":  # the check of the learned rollout
            calls.append(found)
            if len(calls) == 1:
                return Clearance(scene.margin - 0.5, "12", None, scene.margin)
        return found

    monkeypatch.setattr(type(nut.scene), "clearance", first_too_close)
    with caplog.at_level(logging.INFO, logger="bidmp.tasks.evaluation"):
        report = evaluate(nut, ["bidmp"])
    assert "planned again with a margin of 3.5" in caplog.text and len(calls) == 2
    assert report.methods["bidmp"].task_successes == 14
