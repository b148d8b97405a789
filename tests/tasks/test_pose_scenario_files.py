"""A pose scenario's demonstration may be a pose recording file, prepared like a positions
recording (idle ends trimmed, the same low-pass, uniform time), and a pose target with a
positions demonstration is refused saying what it needs."""

from __future__ import annotations

import json

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bidmp.tasks import scenarios


def _tilted_spec() -> dict:
    return json.loads(scenarios.builtin_text("nut-unscrewing-tilted"))


def test_a_timed_pose_recording_is_a_pose_scenarios_demonstration(tmp_path):
    """The built-in tilted task's demonstration written as a logger would (epoch stamps at 50 Hz,
    5 s at rest before and after, 0.05 mm of noise, the orientation as a rotation vector):
    read, trimmed to the motion, its orientation kept (checked here against the written one)."""
    generated = scenarios.load("nut-unscrewing-tilted").demonstration
    rest = 250
    poses = np.vstack(
        [np.repeat(generated[:1], rest, 0), generated, np.repeat(generated[-1:], rest, 0)]
    )
    noisy = poses[:, :3] + np.random.default_rng(1).normal(0.0, 0.05, (len(poses), 3))
    rotvec = Rotation.from_quat(poses[:, 3:]).as_rotvec()
    t = 1.733e9 + np.arange(len(poses)) * 0.02  # a 50 Hz logger: a 4 s motion
    np.savetxt(
        tmp_path / "pose.csv",
        np.column_stack([t, noisy, rotvec]),
        delimiter=",",
        header="t,x,y,z,rx,ry,rz",
        comments="",
    )
    spec = _tilted_spec()
    spec["demonstration"] = {"file": "pose.csv"}
    (tmp_path / "cell.json").write_text(json.dumps(spec))
    scenario = scenarios.load(str(tmp_path / "cell.json"))
    assert scenario.is_pose and scenario.pace is not None
    demo = scenario.demonstration
    # trimmed: the second at rest before and after is (mostly) gone
    assert len(demo) < len(poses) - rest
    # the start and end where the written motion starts and ends (the filter's 6 Hz aside)
    np.testing.assert_allclose(demo[0, :3], generated[0, :3], atol=1.0)
    np.testing.assert_allclose(demo[-1, :3], generated[-1, :3], atol=1.0)
    end_turn = Rotation.from_quat(demo[-1, 3:]) * Rotation.from_quat(generated[-1, 3:]).inv()
    assert np.degrees(end_turn.magnitude()) < 0.5


def test_a_pose_target_with_a_positions_demonstration_is_refused_saying_so():
    spec = _tilted_spec()
    generated = scenarios.load("nut-unscrewing-tilted").demonstration
    spec["demonstration"] = {"points": generated[:, :3].tolist()}
    with pytest.raises(scenarios.ScenarioError, match=r"is a pose .* needs a pose demonstration"):
        scenarios.from_dict(spec)
