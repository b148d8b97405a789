"""The Franka Research 3 as a built-in arm: its URDF (tools/fr3_urdf.py) against independent
references — the modified DH product typed here from Franka's published parameters, and the
Panda's own URDF (pybullet_data), whose kinematics the FR3 shares — its ranges pinned to the
published table, and a simulated motion on it whose 1 kHz commands the FR3's own FCI tables
accept (bidmp.sim.fci)."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from bidmp import sim, tasks
from bidmp.sim.fci import judge_commands

pytest.importorskip("pybullet")

# (a_{i-1}, d_i, alpha_{i-1}): Franka's modified DH table (the FR3's and the Panda's)
MDH = [
    (0.0, 0.333, 0.0),
    (0.0, 0.0, -np.pi / 2),
    (0.0, 0.316, np.pi / 2),
    (0.0825, 0.0, np.pi / 2),
    (-0.0825, 0.384, -np.pi / 2),
    (0.0, 0.0, np.pi / 2),
    (0.088, 0.0, np.pi / 2),
]


def mdh_flange(q) -> np.ndarray:
    """The flange's pose (4, 4): Rx(alpha) Tx(a) Rz(q) Tz(d) per joint, then Tz(0.107)."""

    def rot_x(angle):
        c, s = np.cos(angle), np.sin(angle)
        return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])

    def rot_z(angle):
        c, s = np.cos(angle), np.sin(angle)
        return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])

    def shift(x=0.0, z=0.0):
        out = np.eye(4)
        out[0, 3], out[2, 3] = x, z
        return out

    pose = np.eye(4)
    for (a, d, alpha), angle in zip(MDH, q):
        pose = pose @ rot_x(alpha) @ shift(x=a) @ rot_z(angle) @ shift(z=d)
    return pose @ shift(z=0.107)


def _flange_poses(urdf: str, flange: str, joints: list[str], qs) -> list[np.ndarray]:
    import pybullet_data

    p = sim.pybullet.world._pybullet_module()
    client = p.connect(p.DIRECT)
    try:
        p.setAdditionalSearchPath(pybullet_data.getDataPath(), physicsClientId=client)
        robot = p.loadURDF(urdf, useFixedBase=True, physicsClientId=client)
        info = [
            p.getJointInfo(robot, j, physicsClientId=client)
            for j in range(p.getNumJoints(robot, physicsClientId=client))
        ]
        by_name = {item[1].decode(): item[0] for item in info}
        link = next(item[0] for item in info if item[12].decode() == flange)
        poses = []
        for q in qs:
            for name, angle in zip(joints, q):
                p.resetJointState(robot, by_name[name], angle, physicsClientId=client)
            state = p.getLinkState(robot, link, computeForwardKinematics=1, physicsClientId=client)
            pose = np.eye(4)
            pose[:3, :3] = np.array(p.getMatrixFromQuaternion(state[5])).reshape(3, 3)
            pose[:3, 3] = state[4]
            poses.append(pose)
        return poses
    finally:
        p.disconnect(client)


def test_the_fr3_urdf_is_its_published_kinematics_and_the_pandas():
    """50 random joint vectors within the FR3's ranges: PyBullet's flange of the written URDF
    equals the modified DH product (1 µm, 1e-6) and the Panda URDF's panda_link8; the file is
    the one the tool writes (structure guard)."""
    tools = Path(__file__).resolve().parents[2] / "tools"
    sys.path.insert(0, str(tools))
    try:
        import fr3_urdf
    finally:
        sys.path.remove(str(tools))
    model = sim.ROBOT_MODELS["fr3"]
    assert Path(model.urdf).read_text() == fr3_urdf.urdf()
    limits = model.limits
    rng = np.random.default_rng(4)
    qs = rng.uniform(np.array(limits.lower), np.array(limits.upper), (50, 7))
    fr3 = _flange_poses(model.urdf, "fr3_link8", [f"fr3_joint{i}" for i in range(1, 8)], qs)
    panda = _flange_poses(
        "franka_panda/panda.urdf", "panda_link8", [f"panda_joint{i}" for i in range(1, 8)], qs
    )
    for q, ours, theirs in zip(qs, fr3, panda):
        expected = mdh_flange(q)
        np.testing.assert_allclose(ours[:3, 3], expected[:3, 3], atol=1e-6)
        np.testing.assert_allclose(ours[:3, :3], expected[:3, :3], atol=1e-6)
        np.testing.assert_allclose(theirs[:3, 3], expected[:3, 3], atol=1e-6)


def test_the_fr3_ranges_are_the_published_table():
    """Typed from the FR3's URDF as served to libfranka >= 0.10 (its joint 6: 0.54-4.52 rad)."""
    limits = sim.ROBOT_MODELS["fr3"].limits
    assert limits.lower == (-2.7501, -1.7918, -2.9065, -3.0481, -2.8101, 0.54092, -3.0196)
    assert limits.upper == (2.7501, 1.7918, 2.9065, -0.1458, 2.8101, 4.5205, 3.0196)
    assert limits.velocity == (2.62, 2.62, 2.62, 2.62, 5.26, 4.18, 5.26)
    assert limits.acceleration == (10.0,) * 7 and limits.jerk == (5000.0,) * 7
    from bidmp.sim.robots import ROBOT_NAMES

    assert ROBOT_NAMES["fr3"] == "Franka Research 3"


def test_a_simulated_motion_on_the_fr3_is_accepted_by_its_fci_tables():
    """The nut task's Bi-DMP motion to nut 3 on the FR3 (PyBullet, 1 kHz position control): a task
    success, and every joint command it sent within the FR3's FCI limits, its position-based
    velocities included."""
    nut = tasks.load("nut-unscrewing")
    data = nut.to_dict() if hasattr(nut, "to_dict") else None
    if data is None:
        pytest.skip("scenarios cannot be rewritten here")
    data["robot"] = {**data.get("robot", {}), "model": "fr3"}
    scenario = tasks.scenarios.from_dict(data)
    report = sim.simulate(scenario, ["bidmp"], targets=["3"], workers=1, record=True)
    target = report.methods["bidmp"].targets["3"]
    assert target.task_success(scenario.success_threshold), target.reason
    commands = np.asarray(target.commands)
    assert commands.shape[1] == 7 and commands.shape[0] > 1000  # the whole motion, every 1 ms
    verdict = judge_commands(commands, "fr3")
    assert verdict.ok, verdict.reason()


def test_the_jobs_motions_on_the_fr3_are_written_and_accepted_by_bidmp_verify(tmp_path, capsys):
    """bidmp job --commands on the FR3 (two nuts, PyBullet): one file per motion, t 1 ms apart and
    the FR3's joint names; bidmp verify accepts every one (exit 0) and refuses them as a Panda's
    (exit 2: the names are the FR3's)."""
    import json

    from bidmp.cli import main

    data = tasks.load("nut-unscrewing").to_dict()
    data["robot"] = {**data.get("robot", {}), "model": "fr3"}
    scenario = tmp_path / "fr3.json"
    scenario.write_text(json.dumps(data))
    out = tmp_path / "job"
    argv = ["job", "--scenario", str(scenario), "--targets", "1,7", "--no-pictures"]
    assert main([*argv, "--commands", "--out", str(out)]) == 0
    files = sorted((out / "commands").glob("*.csv"))
    assert [f.name for f in files][:4] == [
        "001_1_approach.csv",
        "002_1_unscrew.csv",
        "003_1_retract.csv",
        "004_1_drop.csv",
    ]
    header = [line for line in files[0].read_text().splitlines() if not line.startswith("#")][0]
    assert header == "t," + ",".join(f"fr3_joint{i}" for i in range(1, 8))
    capsys.readouterr()
    assert main(["verify", *map(str, files), "--robot", "fr3"]) == 0
    assert (
        capsys.readouterr().out.strip().splitlines()[-1]
        == f"{len(files)} of {len(files)} motions accepted"
    )
    assert main(["verify", str(files[0]), "--robot", "panda"]) == 2
