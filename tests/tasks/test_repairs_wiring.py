"""What the evaluation hands its repairs: every motion the contract refuses and every one the arm's
links cannot run goes to the repairer, each with its own target's parts, axis and tool frames,
and the repaired motion and verdict replace that target's own. Three targets of the tilted pack
(two refused, one only by the links' check, one kept), two methods' worth of frames; the
repairer is a recorder that answers with a motion of its own, so what reaches it and what comes
back is checked against the inputs built here."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from bidmp.tasks import scenarios
from bidmp.tasks.contract import Contract
from bidmp.tasks.evaluation import _repaired

LABELS = ["5", "2", "9", "12"]


@pytest.fixture(scope="module")
def tilted():
    return scenarios.load("nut-unscrewing-tilted")


def test_each_refused_or_blocked_motion_is_repaired_with_its_own_inputs(tilted):
    contract = Contract(1.75, None, None, "mm")
    rollouts, frames, verdicts = {}, {}, {}
    for k, label in enumerate(LABELS):
        target = np.asarray(tilted.targets[label][:3])
        end = target + (0.0 if label in ("2", "12") else 6.0)  # 5 and 9 miss their nut
        rollouts[label] = np.linspace(target + [0.0, 0.0, 80.0], end, 20 + k)
        turn = np.array([0.0, 0.0, np.sin(0.05 * (k + 1)), np.cos(0.05 * (k + 1))])
        frames[label] = np.repeat(turn[None], 20 + k, axis=0)
        verdicts[label] = contract.judge(rollouts[label], target, label=label)
    assert [verdicts[label].ok for label in LABELS] == [False, True, False, True]
    outcome = SimpleNamespace(
        name="bidmp", rollouts=rollouts, orientations=frames, verdicts=verdicts, runtime_s=1.0
    )
    calls = {}

    class Recorder:
        def repair(self, model, target, label, **given):
            calls[label] = (np.asarray(target), given)
            motion = np.hstack([np.full((7, 3), float(label)), np.tile([0, 0, 0, 1.0], (7, 1))])
            verdict = contract.judge(motion[:, :3], motion[-1, :3], label=f"repaired {label}")
            return SimpleNamespace(ok=True, how="lift", motion=motion, verdict=verdict, model=None)

    def arm(motion, label):  # the links cannot run target 12's motion (the contract keeps it)
        return "a link would touch 13" if label == "12" else ""

    def result(name, motions, seconds, known):
        return SimpleNamespace(name=name, motions=motions, verdicts=known)

    repaired, _ = _repaired(outcome, (Recorder(), arm), "model", tilted, LABELS, result, None)
    assert sorted(calls) == ["12", "5", "9"]  # refused, refused, blocked; 2 kept as it is
    for label, (target, given) in calls.items():
        np.testing.assert_array_equal(target, tilted.targets[label])
        assert given["exclude"] == tilted.scene.target_parts(label, tilted.targets[label])
        np.testing.assert_allclose(given["axis"], tilted.target_axis(label))
        np.testing.assert_array_equal(given["motion"][:, :3], rollouts[label])
        np.testing.assert_array_equal(given["motion"][:, 3:], frames[label])
        assert given["verdict"] is verdicts[label]
        assert given["arm"](rollouts[label]) == arm(None, label)
    by_label = dict(zip(LABELS, repaired.motions))
    for label in LABELS:
        if label in calls:
            assert np.all(by_label[label][:, :3] == float(label))
            assert repaired.verdicts[label].target == f"repaired {label}"
        else:
            np.testing.assert_array_equal(by_label[label][:, :3], rollouts[label])
            assert repaired.verdicts[label] is verdicts[label]
