"""The demonstration's pace by default: a motion learned from a timed recording runs on the arm
no faster than the person showed it (the arm's limits only ever slow it down); ``"pace":
"limits"`` asks for the arm's limits alone, and a pace without time stamps is refused.

The oracle is the recording itself: its peak tool speed is computed here from the raw file
(samples' chords over their time steps, after a 25-sample moving average that stands in for the
library's 6 Hz low-pass; it can only overstate the prepared motion's peak by the noise it
leaves), and the arm's is the measured tool path's (its recorded samples' chords)."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from bidmp import sim
from bidmp.demonstrations.datasets import recording_path
from bidmp.tasks import scenarios


def _recorded_peak_speed(path) -> float:
    """mm/s: the raw recording's peak tool speed, lightly smoothed (independent of bidmp)."""
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    t, y = data[:, 0] - data[0, 0], data[:, 1:4]
    kernel = np.ones(25) / 25.0
    smooth = np.column_stack([np.convolve(y[:, k], kernel, mode="valid") for k in range(3)])
    ts = np.convolve(t, kernel, mode="valid")
    return float(np.max(np.linalg.norm(np.diff(smooth, axis=0), axis=1) / np.diff(ts)))


@pytest.fixture(scope="module")
def recorded_cell(tmp_path_factory):
    """The built-in nut cell with its demonstration replaced by operator 1's recording of nut 3
    (t in epoch seconds, mm), as a user's scenario file beside its recording."""
    folder = tmp_path_factory.mktemp("recorded")
    shutil.copy(recording_path("operator1_nut3"), folder / "demo.csv")
    spec = json.loads(scenarios.builtin_text("nut-unscrewing"))
    spec["demonstration"] = {"file": "demo.csv"}
    spec["name"] = "recorded-nut"
    spec["dmp"] = {"protocol": "robot"}
    (folder / "cell.json").write_text(json.dumps(spec))
    return folder, spec


def _measured_peak(result, label) -> float:
    target = result.methods["bidmp"].targets[label]
    path, times = np.asarray(target.path), np.arange(len(target.path)) * 2e-3  # 500 Hz samples
    return float(np.max(np.linalg.norm(np.diff(path, axis=0), axis=1) / np.diff(times)))


def test_a_recorded_demonstration_runs_no_faster_than_it_was_shown(recorded_cell):
    folder, spec = recorded_cell
    paced = scenarios.load(str(folder / "cell.json"))
    shown = _recorded_peak_speed(folder / "demo.csv")
    assert paced.pace is not None and 0.9 * shown <= paced.pace <= 1.05 * shown
    labels = ["3", "5"]  # the demonstrated nut, and one 60 mm further
    result = sim.simulate(
        paced, ["bidmp"], targets=labels, backend="kinematic", record=True, workers=1
    )
    spec["pace"] = "limits"
    (folder / "fast.json").write_text(json.dumps(spec))
    fast = sim.simulate(
        scenarios.load(str(folder / "fast.json")),
        ["bidmp"],
        targets=labels,
        backend="kinematic",
        record=True,
        workers=1,
    )
    for label in labels:
        kept = result.methods["bidmp"].targets[label]
        assert kept.task_success(paced.success_threshold), kept.reason
        # the measured tool never faster than the recording (5 % for the arm's spline between
        # its IK samples, which the pace is set on the chords of)
        assert _measured_peak(result, label) <= 1.05 * shown, label
        # at the arm's limits alone the same motion runs faster than shown: the pace acted
        assert _measured_peak(fast, label) > 1.5 * _measured_peak(result, label), label
        assert fast.methods["bidmp"].targets[label].motion_time < kept.motion_time


def test_a_pace_without_time_stamps_is_refused_and_an_unknown_one_named():
    spec = json.loads(scenarios.builtin_text("nut-unscrewing"))
    spec["pace"] = "demonstration"  # a generated demonstration: no time
    with pytest.raises(scenarios.ScenarioError, match=r"pace.*time stamps"):
        scenarios.from_dict(spec)
    spec["pace"] = "fast"
    with pytest.raises(scenarios.ScenarioError, match=r'pace.*"demonstration" or "limits"'):
        scenarios.from_dict(spec)
    del spec["pace"]
    assert scenarios.from_dict(spec).pace is None  # the built-in task keeps the limits' timing
