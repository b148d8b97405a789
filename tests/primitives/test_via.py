"""exact via-points by the least-norm weight change.

References independent of the code under test: the response of the via samples to each weight is
measured by N perturbed rollouts (finite differences of a linear map, exact to rounding), and the
least-norm change is ``numpy.linalg.pinv`` of that measured matrix. Random DMPs (robot and paper
protocol, mm and m, random rates) and random via-points off the grid.
"""

import numpy as np
import pytest

from bidmp import DMP, BiDMP
from bidmp.demonstrations import minimum_jerk
from bidmp.primitives.timed import _time_grid
from bidmp.primitives.via import _impulse_rows, _interpolation


def random_dmp(seed: int, protocol: str = "robot"):
    rng = np.random.default_rng(seed)
    unit = float(rng.choice([1.0, 1e-3]))
    points = np.cumsum(rng.uniform(-80, 80, (3, 3)), axis=0) * unit
    n, duration = int(rng.integers(100, 400)), float(rng.uniform(1.5, 4.0))
    dmp = DMP(protocol=protocol, n_kernels=int(rng.integers(20, 60))).fit(
        minimum_jerk(points, n), np.linspace(0, duration, n)
    )
    return rng, unit, dmp


def sample_at(trajectory, t):
    return np.array([np.interp(t, trajectory.t, column) for column in trajectory.y.T])


@pytest.mark.parametrize("protocol", ["robot", "paper"])
def test_the_response_matrix_equals_perturbed_rollouts(protocol):
    rng, unit, dmp = random_dmp(1, protocol)
    dt = dmp.duration_ / (dmp.n_steps_ - 1) if protocol == "paper" else 0.0037
    motion, dt, n_samples, step = _time_grid(dmp.system_, None, dt)
    times = np.sort(rng.uniform(0.05, 0.95, 3)) * motion
    system = dmp.system_.with_tau(motion / dmp.duration_)
    phase, basis, *_ = system.grid(n_samples + 2, step)
    fast = (
        _impulse_rows(system.settings, phase, step, _interpolation(times, dt, len(phase))) @ basis
    )
    base = dmp.trajectory(dt=dt)
    measured = np.empty_like(fast)
    for kernel in range(dmp.weights_.shape[0]):

        def bump(_, rows, kernel=kernel):
            return rows[:, [kernel]] @ np.array([[1.0, 0.0, 0.0]])

        moved = dmp.trajectory(dt=dt, forcing_increment=bump)
        measured[:, kernel] = [sample_at(moved, t)[0] - sample_at(base, t)[0] for t in times]
    np.testing.assert_allclose(fast, measured, rtol=1e-7, atol=1e-9 * np.abs(measured).max())


@pytest.mark.parametrize("seed", range(6))
def test_via_points_are_passed_exactly_with_the_least_norm_change(seed):
    protocol = "paper" if seed % 3 == 2 else "robot"
    rng, unit, dmp = random_dmp(seed, protocol)
    dt = None if protocol == "paper" else float(rng.choice([0.001, 0.004, 0.0073]))
    plain = dmp.trajectory(dt=dt)
    motion = dmp.duration_ * dmp.settings().tau
    times = (
        np.sort(rng.choice(np.linspace(0.1, 0.9, 17), size=int(rng.integers(1, 4)), replace=False))
        * motion
    )
    times += rng.uniform(0, 0.3) * (plain.t[1] - plain.t[0])  # between samples too
    points = (
        np.array([sample_at(plain, t) for t in times])
        + rng.uniform(-10, 10, (times.size, 3)) * unit
    )
    via = list(zip(times, points))
    try:
        result = dmp.trajectory(dt=dt, via=via)
    except (
        ValueError
    ) as refused:  # a late via-point whose kernels would still act at the end: said, not done
        assert protocol == "robot" and "put the via-points earlier" in str(refused)
        return
    for t, point in via:
        assert np.max(np.abs(sample_at(result, t) - point)) <= 1e-6 * max(unit, 1e-3)
    # The least-norm change: pinv of the measured response (perturbed rollouts, one per kernel).
    change = _measured_least_norm_change(dmp, dt, plain, times, points)
    increment = dmp.trajectory(dt=dt, forcing_increment=lambda _, rows: rows @ change)
    np.testing.assert_allclose(result.y, increment.y, atol=1e-7 * max(unit, 1e-3))
    # The whole motion, not only the via samples: the robot protocol still comes to rest at its
    # goal, or the call was refused above (the paper's rollout stops after T samples, before it
    # settles, so its end moves too).
    if protocol == "robot":
        corners = np.vstack([dmp.goal_, dmp.start_, points])
        reach = np.max(np.linalg.norm(corners[:, None] - corners[None], axis=2))
        assert np.linalg.norm(result.y[-1] - dmp.goal_) <= 1.1e-4 * reach + np.linalg.norm(
            plain.y[-1] - dmp.goal_
        )
        assert np.linalg.norm(result.yd[-1]) <= 1.1e-2 * reach / result.t[-1] + np.linalg.norm(
            plain.yd[-1]
        )


def _measured_least_norm_change(dmp, dt, plain, times, points):
    response = np.empty((times.size, dmp.weights_.shape[0]))
    for kernel in range(response.shape[1]):
        moved = dmp.trajectory(
            dt=dt,
            forcing_increment=lambda _, rows, kernel=kernel: rows[:, [kernel]] @ np.ones((1, 3)),
        )
        response[:, kernel] = [sample_at(moved, t)[0] - sample_at(plain, t)[0] for t in times]
    residual = points - np.array([sample_at(plain, t) for t in times])
    return np.linalg.pinv(response) @ residual


def test_via_points_for_a_bidmp_skill():
    demonstration = minimum_jerk([[0, 0, 60], [100, 0, 60], [100, 0, 0]], 200)
    dmp = DMP().fit(demonstration, np.linspace(0, 2, 200))
    model = BiDMP(dmp).learn(
        minimum_jerk([[0, 0, 60], [150, 40, 60], [200, 50, 0]], 200), duration=2.0
    )
    trajectory = model.trajectory([200, 50, 0], via=[(1.0, [120, 30, 70])], dt=0.002)
    assert np.max(np.abs(sample_at(trajectory, 1.0) - [120, 30, 70])) <= 1e-6


def test_via_points_the_kernels_cannot_carry_are_refused():
    demonstration = minimum_jerk([[0, 0, 60], [100, 0, 60], [100, 0, 0]], 300)
    dmp = DMP(n_kernels=10).fit(demonstration, np.linspace(0, 3, 300))
    cases = [
        ([(3.5, [0, 0, 0])], "duration"),
        ([(0.0, [1, 1, 1])], "cannot carry"),
        (
            [(1.0, [0, 0, 0]), (1.0001, [50, 0, 0])],
            "cannot carry|peak acceleration|still act at the motion.s end",
        ),
        ([(0.1 * k + 0.1, [50, 0, 60]) for k in range(11)], "at most 10"),
        ([(1.0, [1, 2, 3]), (1.0, [1, 2, 3])], "same time"),
        ([(1.0, [1, 2])], "via\\[0\\] point"),
        ("1.0 1 2 3", "list of"),
    ]
    for via, message in cases:
        with pytest.raises((ValueError, TypeError), match=message):
            dmp.trajectory(via=via)
    with pytest.raises(ValueError, match="limits"):
        dmp.trajectory(via=[(1.0, [60, 30, 70])], limits={"max_acceleration": 100.0})
    # no via-points (the motion interface's default, ()) is the motion without them
    np.testing.assert_array_equal(dmp.trajectory(via=[]).y, dmp.trajectory().y)


def test_via_poses_for_a_multi_turn_cartesian_dmp():
    """Position and orientation through a via pose at its time: the orientation part's via-point is
    the pose's error on the turn its own motion takes (5.2 rad about z here), so the motion does not
    unwind a turn to reach it."""
    from scipy.spatial.transform import Rotation

    from bidmp import CartesianDMP
    from bidmp.primitives import angle_between

    s = np.linspace(0.0, 1.0, 200)
    turn = Rotation.from_rotvec(np.outer(10 * s**3 - 15 * s**4 + 6 * s**5, [0.3, -0.8, 5.2]))
    poses = np.hstack(
        [
            minimum_jerk(np.array([[0.0, 0, 100], [80, 20, 40], [150, 25, 0]]), 200),
            (turn * Rotation.from_euler("x", 180, degrees=True)).as_quat(),
        ]
    )
    model = CartesianDMP().fit(poses, np.linspace(0.0, 2.0, 200), units="mm")
    plain = model.trajectory(dt=0.001)
    k = 900
    q = (Rotation.from_rotvec([0.2, 0.0, 0.1]) * Rotation.from_quat(plain.q[k])).as_quat()
    result = model.trajectory(dt=0.001, via=[(plain.t[k], np.r_[plain.y[k] + [5, -3, 2], q])])
    assert np.max(np.abs(result.y[k] - (plain.y[k] + [5, -3, 2]))) <= 1e-6
    assert angle_between(result.q[k : k + 1], q[None])[0] <= 1e-6
    # No unwinding: the turn between samples stays as small as the plain motion's.
    step = angle_between(result.q[1:], result.q[:-1])
    assert step.max() <= 1.5 * angle_between(plain.q[1:], plain.q[:-1]).max()


def test_a_via_pose_that_only_lifts_keeps_a_still_orientation_as_it_is():
    """A lift over a part gives via poses with the motion's own tool frame. On a pose skill that
    keeps its orientation still (the tool down all the way) that orientation via-point asks no
    change: it was refused (a still part has no reach to scale its acceleration by); now the
    orientation runs as without via-points, bit for bit, while the position passes its points
    exactly (checked on the motion's samples) and, with ``via_until``, returns after that time to
    the course the position DMP alone takes through the same points."""
    from scipy.spatial.transform import Rotation

    from bidmp import CartesianDMP

    down = Rotation.from_euler("x", 180, degrees=True).as_quat()
    positions = minimum_jerk(np.array([[-80.0, -120, 200], [0, 0, 40], [0, 0, 0]]), 200)
    poses = np.hstack([positions, np.repeat(down[None], 200, axis=0)])
    model = CartesianDMP().fit(poses, np.linspace(0.0, 2.0, 200), units="mm")
    plain = model.trajectory(dt=0.001)
    ks = (500, 800)
    via = [(plain.t[k], np.r_[plain.y[k] + [0.0, 0.0, 15.0], plain.q[k]]) for k in ks]
    lifted = model.trajectory(dt=0.001, via=via, via_until=1.2)
    assert np.array_equal(lifted.q, plain.q)
    for k, (_, pose) in zip(ks, via):
        assert np.max(np.abs(lifted.y[k] - pose[:3])) <= 1e-6
    alone = model.position_.trajectory(
        dt=0.001, via=[(t, pose[:3]) for t, pose in via], via_until=1.2
    )
    assert np.array_equal(lifted.y, alone.y)  # the same solve (structure)
    assert np.max(np.abs(lifted.y[-1] - plain.y[-1])) <= 1e-4  # mm: back on its own course


def test_the_cli_passes_via_points_and_names_a_bad_one(tmp_path, capsys):
    from bidmp.cli import main

    demonstration = minimum_jerk([[0, 0, 60], [100, 0, 60], [100, 0, 0]], 300)
    np.savetxt(
        tmp_path / "demo.csv",
        np.column_stack([np.linspace(0, 3, 300), demonstration]),
        delimiter=",",
        header="t,x,y,z",
        comments="",
    )
    assert main(["fit", str(tmp_path / "demo.csv"), "-o", str(tmp_path / "m.npz")]) == 0
    out = tmp_path / "r.csv"
    assert (
        main(
            [
                "rollout",
                str(tmp_path / "m.npz"),
                "--rate",
                "1000",
                "--via",
                "1.25",
                "60",
                "20",
                "75",
                "--via",
                "2",
                "110",
                "5",
                "30",
                "-o",
                str(out),
            ]
        )
        == 0
    )
    rows = np.loadtxt(out, delimiter=",", skiprows=1)
    for t, point in ((1.25, [60, 20, 75]), (2.0, [110, 5, 30])):
        assert (
            np.max(
                np.abs(np.array([np.interp(t, rows[:, 0], rows[:, k]) for k in (1, 2, 3)]) - point)
            )
            <= 1e-6
        )
    assert (
        main(["rollout", str(tmp_path / "m.npz"), "--via", "9", "60", "20", "75", "-o", str(out)])
        == 2
    )
    assert "duration" in capsys.readouterr().err
