"""The spindle's free axis: the socket is symmetric about its axis and a spindle turns it, so
inverse kinematics prescribes the tool's axis only (5 DOF) and leaves the turn about it to the arm
(an arm whose last joint turns the tool keeps that joint at its start pose's turn, chosen farthest
inside its limits).

The case: an xArm6 unscrewing a nut straight up through its wrist singularity (joint 5 crosses 0,
where joints 4 and 6 turn about the same line). Solving the full tool pose there left up to 0.06 mm
at a sample (over the 0.05 mm the planner accepts: the motion was refused); with the axis free
every sample is within 0.01 mm and neither joint 4 nor joint 6 moves. The oracle is PyBullet's
forward kinematics of the solved joints set on the simulated arm (not the planning copy the IK
ran on, nor its own error), the tool's axis read from the tool's frame there, and the joint
ranges typed here from UFACTORY's table."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("pybullet")

from bidmp import sim  # noqa: E402
from bidmp.sim import run  # noqa: E402
from bidmp.tasks import scenarios  # noqa: E402

# xArm6 joint ranges (deg), UFACTORY's user manual: J1, J4, J6 ±360; J2 -118..120; J3 -225..11;
# J5 -97..180
LOWER = np.radians([-360.0, -118.0, -225.0, -360.0, -97.0, -360.0])
UPPER = np.radians([360.0, 120.0, 11.0, 360.0, 180.0, 360.0])


@pytest.fixture(scope="module")
def xarm6():
    scenario = scenarios.load("nut-unscrewing-xarm6")
    base, yaw = sim.robot_placement(scenario)
    cell = run._open_world(sim.get_backend("pybullet"), scenario, base, yaw)
    yield cell
    cell.close()


def test_unscrewing_through_the_wrist_singularity_keeps_the_axis_and_leaves_the_turn_free(xarm6):
    cell = xarm6
    base = np.asarray(cell.base, dtype=float)  # mm
    q = np.asarray(cell.rest, dtype=float)
    wrist, errors, axes, path = [], [], [], []
    for z in np.linspace(0.0, 30.0, 61):  # mm: 30 mm up a nut 240 mm in front of the base
        point = base + [1.0, 240.0, z]
        q, _ = cell.solve_ik(point * cell.unit, q)
        cell._set_joints(q)  # the simulated arm (not the planning copy the IK ran on)
        errors.append(np.linalg.norm(cell.tcp_position() - point * cell.unit))
        axes.append(_tool_axis(cell))
        wrist.append(q[4])
        path.append(q)
    path = np.array(path)
    assert min(wrist) < 0.0 < max(wrist)  # through the singularity
    assert max(errors) <= 1e-5  # m: 0.01 mm at every sample
    down = np.array(axes) @ [0.0, 0.0, -1.0]
    assert np.degrees(np.arccos(np.clip(down, -1.0, 1.0))).max() <= 0.01
    np.testing.assert_allclose(path[:, 5], cell.rest[5], atol=1e-12)  # the turn left to the arm
    assert np.ptp(path[:, 3]) <= 1e-3  # joint 4 does not swing against joint 6
    assert np.all(path >= LOWER) and np.all(path <= UPPER)


def _tool_axis(cell) -> np.ndarray:
    """The tool's axis (its frame's z) in the world, from the measured tool frame."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_quat(cell.tool_orientation()).apply([0.0, 0.0, 1.0])


def test_the_closed_form_aim_is_scipys_shortest_arc():
    """The IK's per-burst aim (the frame nearest the current one with the wanted axis) against
    SciPy's align_vectors, on random frames and axes, and an axis opposite the tool's."""
    from scipy.spatial.transform import Rotation

    from bidmp.sim.pybullet.ik import _aimed

    rng = np.random.default_rng(7)
    for _ in range(200):
        current = Rotation.random(random_state=rng)
        axis = rng.normal(size=3)
        axis /= np.linalg.norm(axis)
        swing, _ = Rotation.align_vectors([axis], [current.apply([0.0, 0.0, 1.0])])
        expected = (swing * current).as_quat()
        got = np.asarray(_aimed(current.as_quat(), axis))
        assert min(np.abs(got - expected).max(), np.abs(got + expected).max()) <= 1e-12
    current = Rotation.random(random_state=rng)
    opposite = -current.apply([0.0, 0.0, 1.0])
    turned = Rotation.from_quat(_aimed(current.as_quat(), opposite))
    np.testing.assert_allclose(turned.apply([0.0, 0.0, 1.0]), opposite, atol=1e-12)
