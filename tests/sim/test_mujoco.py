"""The MuJoCo backend against the PyBullet one and pinocchio: the small version of ``make engines``
(tools/engines.py, docs/results/engines.md).

Oracles from outside the backend: pinocchio's forward kinematics and recursive Newton-Euler on
the same URDF text; the PyBullet backend's verdicts and tracking on the same motion; the bin's
floor height from the scene, for a nut dropped from 80 mm.
"""

from __future__ import annotations

import sys

import numpy as np
import pytest

pytest.importorskip("pybullet")
mujoco = pytest.importorskip("mujoco")

from bidmp import tasks  # noqa: E402
from bidmp.cli import main  # noqa: E402
from bidmp.scene import Scene, Tool  # noqa: E402
from bidmp.sim import execution_report, simulate  # noqa: E402
from bidmp.sim.backend import get_backend  # noqa: E402
from bidmp.sim.robots import ROBOT_MODELS  # noqa: E402


def _arm(name: str):
    """The MuJoCo cell of built-in arm ``name`` with a 0.1 m tool at the origin, no parts."""
    return get_backend("mujoco")(
        Scene([], Tool(radius=0.02, length=0.1)), "m", (0.0, 0.0, 0.0), 0.0, ROBOT_MODELS[name]
    )


def _pinocchio(cell):
    pin = pytest.importorskip("pinocchio")
    from bidmp.sim.pybullet.world import _tool_urdf

    text = _tool_urdf(cell.model, 0.02, 0.1)
    model = pin.buildModelFromXML(text[0] if isinstance(text, tuple) else text)
    return pin, model, model.createData()


def _pin_q(model, q):
    """pinocchio's configuration of joint angles ``q`` (a continuous joint holds cos, sin)."""
    out = []
    for joint, angle in zip(model.joints[1:], q):
        out += [np.cos(angle), np.sin(angle)] if joint.nq == 2 else [angle]
    return np.array(out)


def _random_states(cell, rng, count: int):
    lower = np.maximum(cell.limits.lower, -np.pi)
    upper = np.minimum(cell.limits.upper, np.pi)
    for _ in range(count):
        yield (
            rng.uniform(lower, upper),
            rng.uniform(-1.0, 1.0, len(lower)) * cell.limits.velocity,
            rng.uniform(-1.0, 1.0, len(lower)) * np.asarray(cell.limits.acceleration),
        )


@pytest.mark.parametrize("name", ["panda", "ur5"])
def test_forward_kinematics_agree_with_pinocchio_and_pybullet(name):
    """The tool's mouth at random joints: MuJoCo's model, pinocchio's and PyBullet's planning copy
    within 1 µm (a 7-joint and a 6-joint arm, several joints' worth of random poses)."""
    cell = _arm(name)
    try:
        pin, model, data = _pinocchio(cell)
        frame = model.getFrameId("tcp")
        for q, _, _ in _random_states(cell, np.random.default_rng(7), 25):
            ours = cell.model_fk(q)
            pin.framesForwardKinematics(model, data, _pin_q(model, q))
            assert np.max(np.abs(ours - data.oMf[frame].translation)) <= 1e-6
            assert np.max(np.abs(ours - cell.forward(q))) <= 1e-6
    finally:
        cell.close()


@pytest.mark.parametrize("name", ["panda", "iiwa"])
def test_inverse_dynamics_agree_with_pinocchio(name):
    """MuJoCo's inverse dynamics of the compiled model (joint damping and armature off: rigid
    bodies only) against pinocchio's RNEA on the URDF text, within 1e-6 N m: no link's inertia
    dropped or fused away (the Panda's massless panda_link8 and tool's mouth included)."""
    cell = _arm(name)
    try:
        pin, model, data = _pinocchio(cell)
        m = cell.m.__copy__()
        m.dof_damping[:] = 0.0
        m.dof_armature[:] = 0.0
        d = mujoco.MjData(m)
        n = len(cell.arm)
        for q, qd, qdd in _random_states(cell, np.random.default_rng(11), 25):
            d.qpos[:n], d.qvel[:n], d.qacc[:n] = q, qd, qdd
            mujoco.mj_inverse(m, d)
            expected = pin.rnea(model, data, _pin_q(model, q), qd, qdd)
            assert np.max(np.abs(d.qfrc_inverse[:n] - expected)) <= 1e-6
            assert np.max(np.abs(expected)) > 1.0  # a state that loads the joints
    finally:
        cell.close()


def test_the_same_motion_gets_the_same_verdict_on_both_engines():
    """One nut's Bi-DMP motion on both engines: the same plan, so the same verdict; the measured
    tracking errors within 2x of each other; no contacts on either."""
    nut = tasks.load("nut-unscrewing")
    report = execution_report(nut, ["bidmp"])
    runs = {
        engine: simulate(nut, ["bidmp"], targets=["7"], report=report, workers=1, backend=engine)
        .methods["bidmp"]
        .targets["7"]
        for engine in ("pybullet", "mujoco")
    }
    bullet, ours = runs["pybullet"], runs["mujoco"]
    assert bullet.ran and ours.ran
    threshold = nut.success_threshold
    assert bullet.task_success(threshold) == ours.task_success(threshold)
    assert bullet.within_limits == ours.within_limits
    assert set(bullet.contacts) == set(ours.contacts) == set()
    assert bullet.commanded_error == ours.commanded_error  # one plan for both
    ratio = max(bullet.tracking_error, ours.tracking_error) / min(
        bullet.tracking_error, ours.tracking_error
    )
    assert ratio <= 2.0
    assert ours.tracking_error > 0.0 and ours.measured_error != bullet.measured_error


def test_a_dropped_nut_lands_on_a_thin_floor():
    """A nut let go 80 mm above a 1.4 mm sheet (the job's bin floor) lies on the sheet: at 1 kHz
    with MuJoCo's default soft contacts it passed the sheet's middle before its first contact and
    fell through."""
    from bidmp.scene.parts import Solid

    nut = tasks.load("nut-unscrewing")
    cell = get_backend("mujoco")(nut.scene, nut.units)
    try:
        label = next(s.label for s in nut.scene.solids if s.kind == "convex")
        part = cell.movable_part(label, 0.02)
        stud_top = max(s.upper[2] for s in nut.scene.solids if s.label == f"{label}/stud")
        centre = part.centre0
        top = stud_top + 10.0  # mm: the sheet's top, clear above the stud
        sheet = Solid(
            "sheet",
            "sheet",
            "box",
            np.array([centre[0], centre[1], top - 0.7]),
            np.eye(3),
            (60.0, 60.0, 1.4),
            np.array([centre[0] - 30, centre[1] - 30, top - 1.4]),
            np.array([centre[0] + 30, centre[1] + 30, top]),
        )
        cell.add_solids([sheet])
        part.thread(top + 80.0 - centre[2], 1.0, 0.0)  # lifted 80 mm above the sheet
        part.release()
        cell.settle(0.6)
        resting, _ = part.pose()
        # on the sheet: its centre half its height above the top (within the contact's give)
        assert abs(resting[2] - (top + part.height / 2)) < 0.2
    finally:
        cell.close()


def test_the_job_removes_a_nut_on_mujoco():
    """The job's whole cycle (approach, unscrew, retract, drop into the bin) on MuJoCo."""
    from bidmp.sim import run_job

    nut = tasks.load("nut-unscrewing")
    report = run_job(nut, targets=["1"], backend="mujoco")
    record = report.targets[0]
    assert record.removed, record.reason
    assert all(not phase.contacts for phase in record.phases)


def test_without_mujoco_the_backend_says_how_to_install_it(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "mujoco", None)
    assert main(["sim", "--backend", "mujoco", "--out", "unused"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "pip install 'bidmp[mujoco]'" in err
    assert main(["job", "--backend", "mujoco", "--out", "unused"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "pip install 'bidmp[mujoco]'" in err
