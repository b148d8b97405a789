"""The simulator seam: backends by name, and the kinematic backend (an ideal arm in memory) running
the evaluation, the simulated runs and the whole job without PyBullet.

The kinematic arm does exactly what it is told, so what it measures can be predicted from outside
the simulator: its end point is the evaluated rollout's end, its contacts are the scene's geometry,
a released nut lands on the bin's floor under where it was let go.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bidmp import tasks
from bidmp.sim import (
    Hold,
    KinematicCell,
    backend_names,
    execution_report,
    get_backend,
    register_backend,
    run_job,
    simulate,
)
from bidmp.sim import backend as backend_module


@pytest.fixture(scope="module")
def nuts():
    return tasks.load("nut-unscrewing")


def test_backends_are_found_by_name_and_refused_by_name():
    assert {"pybullet", "kinematic"} <= set(backend_names())
    assert get_backend("kinematic") is KinematicCell
    with pytest.raises(ValueError, match="unknown simulator backend 'bullet'.*pybullet, kinematic"):
        get_backend("bullet")
    with pytest.raises(TypeError, match="backend must be a backend's name"):
        get_backend(KinematicCell)
    with pytest.raises(TypeError, match="lacks load_robot, plan, execute"):
        register_backend("broken", object)


def test_a_registered_backend_runs_by_name(nuts, monkeypatch):
    """A backend of one's own is one class and one register line (here a kinematic arm standing
    somewhere else by name): simulate finds it by its name and reports it by its own."""
    monkeypatch.setattr(backend_module, "_BACKENDS", dict(backend_module._BACKENDS))

    class Gantry(KinematicCell):
        name = "gantry"

    register_backend("gantry", Gantry)
    result = simulate(nuts, ["bidmp"], targets=["1"], backend="gantry", workers=1)
    assert result.robot == "gantry" and result.methods["bidmp"].task_successes == 1


def test_the_ideal_arm_ends_where_the_evaluated_rollout_ends(nuts):
    """What the kinematic arm measures is the command: its end point's error is the evaluated
    rollout's own (computed here from the rollout, not by the simulator), and the whole measured
    path stays on the planned joint spline's tool path."""
    labels = ["1", "7", "12"]
    report = execution_report(nuts, ["dmp", "bidmp"])
    result = simulate(
        nuts, ["dmp", "bidmp"], targets=labels, backend="kinematic", report=report, record=True
    )
    for method in ("dmp", "bidmp"):
        for label in labels:
            rollout = np.asarray(report.methods[method].rollouts[label])
            expected = float(np.linalg.norm(rollout[-1, :3] - nuts.targets[label][:3]))
            measured = result.methods[method].targets[label]
            if expected > nuts.success_threshold:  # the plain DMP's far nut: refused, not run
                assert not measured.ran and measured.commands is None, (method, label)
                assert measured.error.startswith("not run: the contract refuses")
                assert f"ends {expected:.2f} mm from the target" in measured.error
                continue
            assert measured.measured_error == pytest.approx(expected, abs=1e-6), (method, label)
            assert measured.tracking_error < 1e-9
            # the measured path starts at the rollout's start and ends at its end
            np.testing.assert_allclose(measured.path[0], rollout[0, :3], atol=1e-6)
            np.testing.assert_allclose(measured.path[-1], rollout[-1, :3], atol=1e-6)


def test_contacts_are_the_swept_tools_depth_in_the_scene(nuts):
    """A descent through a nut reports a contact with it as deep as the scene's own clearance says
    (from outside the backend); excepted, the same descent touches nothing."""
    cell = KinematicCell.load_robot(nuts.scene, nuts.units, (50.0, -450.0, 0.0), 90.0)
    nut = nuts.scene.solids[[s.label for s in nuts.scene.solids].index("5")]
    top = float(nut.upper[2])
    path = np.array([[*nut.centre[:2], top + 40.0], [*nut.centre[:2], top - 2.0]])
    run = cell.execute(cell.plan(path, "5"))
    clearance = nuts.scene.clearance(run.tcp / cell.unit)
    assert clearance.part in ("5", "5/stud") and -clearance.distance > 1.0
    assert run.contacts == {
        clearance.part: pytest.approx(-clearance.distance * cell.unit, rel=1e-9)
    }
    assert cell.execute(cell.plan(path, "5"), exclude=["5"]).contacts == {}


def test_inverse_kinematics_is_exact_and_kept_within_the_limits(nuts):
    cell = KinematicCell(nuts.scene, nuts.units)
    rng = np.random.default_rng(4)
    for _ in range(20):
        point = cell.base * cell.unit + rng.uniform(-0.5, 0.5, 3)
        turn = Rotation.from_rotvec(rng.uniform(-0.5, 0.5, 3))
        wanted = (Rotation.from_quat([1.0, 0.0, 0.0, 0.0]) * turn).as_quat()
        q, error = cell.solve_ik(point, cell.rest, wanted)
        assert error < 1e-12
        np.testing.assert_allclose(cell.fk(q), point, atol=1e-12)
        assert (
            np.degrees((Rotation.from_quat(wanted).inv() * cell._orientation(q)).magnitude()) < 1e-9
        )
    far = cell.base * cell.unit + [3.0, 0.0, 0.0]  # past the carriage's 1.5 m
    assert cell.solve_ik(far, cell.rest)[1] == pytest.approx(3.0 - 1.5)


def test_the_whole_job_on_the_ideal_arm_drops_each_nut_on_the_bins_floor(nuts):
    """Every nut is unscrewed (one turn per pitch risen, the nut's own trace), carried and let go
    over the bin; it lands on the bin's floor (its centre half a nut above the floor slab's top,
    within the bin's inner footprint: the geometry of the job's spec, checked here)."""
    labels = ["1", "9", "14"]
    report = run_job(nuts, targets=labels, backend="kinematic")
    assert report.robot == "kinematic arm" and report.removed == len(labels)
    spec = nuts.job
    floor, inner = np.asarray(spec.bin_floor), np.asarray(spec.bin[1])
    for record in report.targets:
        rise, angle, _ = np.array(record.thread).T
        np.testing.assert_allclose(angle / (2.0 * np.pi) * spec.pitch, rise, rtol=1e-12)
        centre = np.asarray(record.final_position)
        assert np.all(np.abs(centre[:2] - floor[:2]) <= inner[:2] / 2.0), record.label
        nut = nuts.scene.solids[[s.label for s in nuts.scene.solids].index(record.label)]
        height = float(nut.upper[2] - nut.lower[2])  # the nut stands upright
        assert centre[2] == pytest.approx(floor[2] + height / 2.0, abs=0.01)


def _command_files(folder):
    """(first lines, header, numbers) of each command file in ``folder``, in order."""
    out = []
    for path in sorted(folder.glob("*.csv")):
        lines = path.read_text().splitlines()
        comments = [line for line in lines if line.startswith("#")]
        header = [line for line in lines if not line.startswith("#")][0].split(",")
        out.append((comments, header, np.loadtxt(path, delimiter=",", skiprows=len(comments) + 1)))
    return out


CARRIAGE = ["carriage_x", "carriage_y", "carriage_z", "wrist_x", "wrist_y", "wrist_z"]


@pytest.mark.parametrize(("model", "joints"), [("panda", 7), ("xarm6", 6)])
def test_job_commands_on_the_kinematic_arm_name_its_own_six_joints(tmp_path, capsys, model, joints):
    """bidmp job --commands --backend kinematic wrote its results, then failed on a 7-joint
    scenario arm ('7 names for commands of 6 joints') and, on a 6-joint one (the xArm6), named
    the kinematic arm's carriage by the xArm's joints. The files carry the joints of the arm that
    ran: the carriage (m) and the wrist (rad), said in a comment, no '# units: rad' over metres;
    the first command is the arm's rest (0.3, 0, 0.45 m; the tool down)."""
    from bidmp.cli import main
    from bidmp.sim.robots import ROBOT_MODELS

    assert len(ROBOT_MODELS[model].limits.lower) == joints  # the scenario's arm, not the one run
    data = tasks.load("nut-unscrewing").to_dict()
    data["robot"] = {**data.get("robot", {}), "model": model}
    scenario = tmp_path / f"{model}.json"
    scenario.write_text(json.dumps(data))
    out = tmp_path / "job"
    argv = ["job", "--scenario", str(scenario), "--targets", "3", "--no-pictures"]
    assert main([*argv, "--backend", "kinematic", "--commands", "--out", str(out)]) == 0
    files = _command_files(out / "commands")
    assert len(files) == 4  # approach, unscrew, retract, drop
    for comments, header, numbers in files:
        assert header == ["t", *CARRIAGE]
        assert comments == [
            "# joint units: carriage_x m, carriage_y m, carriage_z m, wrist_x rad, wrist_y rad, "
            "wrist_z rad"
        ]
        assert numbers.shape[1] == 7
        np.testing.assert_allclose(np.diff(numbers[:, 0]), 1e-3, atol=1e-12)
    np.testing.assert_allclose(files[0][2][0, 1:], [0.3, 0.0, 0.45, 0.0, 0.0, 0.0], atol=1e-12)


def test_job_commands_on_a_seven_joint_arm_read_back_as_it_sent_them(nuts, tmp_path):
    """The PyBullet Panda (7 joints): the report names the joints of the arm that ran (its URDF's,
    typed here), the files read back to the last bit of the commands it sent, and names of
    another count or a name twice are refused."""
    pytest.importorskip("pybullet")
    from bidmp.sim import write_job_commands

    report = run_job(nuts, targets=["3"], record=True)
    names = [f"panda_joint{k}" for k in range(1, 8)]
    assert list(report.joint_names) == names and set(report.joint_units) == {"rad"}
    assert len(write_job_commands(report, tmp_path / "c")) == 4
    files = _command_files(tmp_path / "c")
    sent = [
        p.commands for target in report.targets for p in target.phases if p.commands is not None
    ]
    assert len(files) == len(sent) == 4
    for (comments, header, numbers), commands in zip(files, sent):
        assert comments == ["# units: rad"] and header == ["t", *names]
        np.testing.assert_array_equal(numbers[:, 1:], np.asarray(commands))
    with pytest.raises(ValueError, match="6 names for commands of 7 joints"):
        write_job_commands(report, tmp_path / "d", names[:6])
    with pytest.raises(ValueError, match="a name repeats"):
        write_job_commands(report, tmp_path / "e", [*names[:6], names[0]])


def test_a_scripted_hold_needs_dynamics_and_an_arm_with_that_joint(nuts):
    with pytest.raises(ValueError, match="needs dynamics"):
        simulate(nuts, ["dmp"], targets=["1"], backend="kinematic", hold=Hold(0, 0.5), workers=1)
    with pytest.raises(TypeError, match="hold must be a bidmp.sim.Hold"):
        simulate(nuts, ["dmp"], targets=["1"], backend="kinematic", hold=(6, 0.5), workers=1)
    with pytest.raises(ValueError, match="joint 7 of an arm with 6 joints"):
        simulate(nuts, ["dmp"], targets=["1"], backend="kinematic", hold=Hold(6, 0.5), workers=1)


def test_the_simulator_and_the_job_run_without_pybullet(tmp_path):
    """``bidmp sim`` (the evaluation, then every motion on the arm) and ``bidmp job`` with
    ``--backend kinematic`` in a process where PyBullet cannot be imported."""
    code = (
        "import sys; sys.modules['pybullet'] = None; sys.modules['pybullet_data'] = None\n"
        "from bidmp.cli import main\n"
        f"out = {str(tmp_path)!r}\n"
        "common = ['--backend', 'kinematic', '--no-pictures']\n"
        "sim = main(['sim', '--targets', '1,12', '--out', out + '/sim', *common])\n"
        "job = main(['job', '--targets', '1,7', '--out', out + '/job', *common])\n"
        "sys.exit(10 * sim + job)"
    )
    done = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, check=False
    )
    # 0 and 0: Bi-DMP reaches both nuts (the run is judged on it), the job removes both
    assert done.returncode == 0, done.stderr[-2000:]
    sim = json.loads((tmp_path / "sim" / "sim_results.json").read_text())
    job = json.loads((tmp_path / "job" / "job_results.json").read_text())
    assert sim["robot"]["model"] == "kinematic arm"
    # the plain DMP misses the far nut 12 on this arm as on the PyBullet one (its rollout's miss)
    assert sim["methods"]["dmp"]["targets"]["12"]["task_success"] is False
    assert [target["removed"] for target in job["targets"]] == [True, True]


def test_the_closed_loop_on_the_ideal_arm_sends_commands_within_the_limits_along_the_skill(nuts):
    """Closed loop on the kinematic arm: the commands come from the same generator as the PyBullet
    arm's (cubic between the 100 Hz targets, jerk-limited), so the contract finds them within the
    limits (plain linear steps between targets broke the jerk limit 7-11×: this test's first
    catch); nothing holds the arm, so the motion never pauses and traces the learned rollout (the
    evaluation's, on the robot protocol the closed loop runs) within the limiter's lag."""
    from scipy.spatial import cKDTree

    robot = nuts.with_robot_protocol()
    report = execution_report(robot, ["bidmp"])
    result = simulate(
        robot,
        ["bidmp"],
        targets=["1", "12"],
        closed_loop=True,
        backend="kinematic",
        report=report,
        record=True,
        workers=1,
    )
    method = result.methods["bidmp"]
    for label, measured in method.targets.items():
        assert measured.task_success(method.threshold), (label, measured.reason)
        assert measured.within_limits and measured.paused == 0.0
        rollout = np.asarray(report.methods["bidmp"].rollouts[label])
        off, _ = cKDTree(rollout).query(measured.path)
        assert off.max() < 3.0, (label, off.max())


def test_the_commands_real_time_factor_is_the_whole_commands(tmp_path, capsys):
    """``bidmp sim`` and ``bidmp job`` end with the whole command's wall time (reading, learning,
    simulating, writing) against the simulated time — not the simulation's alone, which the
    summary above it states (and which is shorter)."""
    import re

    from bidmp.cli import main

    for argv in (
        ["sim", "--targets", "1", "--methods", "bidmp"],
        ["job", "--targets", "1"],
    ):
        code = main([*argv, "--backend", "kinematic", "--no-pictures", "--out", str(tmp_path)])
        out = capsys.readouterr().out
        assert code == 0, out[-1000:]
        whole = re.search(
            r"the whole command: ([\d.]+) s for ([\d.]+) s simulated \(([\d.]+)x", out
        )
        alone = re.search(r"simulated ([\d.]+) s in ([\d.]+) s wall time", out)
        assert whole and alone, out[-1000:]
        elapsed, simulated, factor = (float(v) for v in whole.groups())
        assert simulated == float(alone.group(1))
        # the two printed wall times agree with each other (no limit on either: a loaded machine
        # changes both): the simulation is part of the command
        assert elapsed >= float(alone.group(2))
        # the printed times are rounded to 0.1 s, the factor to 0.1
        low = (simulated - 0.05) / (elapsed + 0.05) - 0.05
        assert low <= factor <= (simulated + 0.05) / max(elapsed - 0.05, 1e-3) + 0.05


def test_a_bug_in_a_cycle_is_an_internal_error_not_a_failed_target(
    nuts, monkeypatch, capsys, tmp_path
):
    """A planted bug (a ValueError where the engagement is measured, as a wrong shape would raise)
    stops the job: exit 1 from the command, naming the target and the phase; a refusal of the
    task's (an unreachable target, a SimError) is still that target's row and the job goes on."""
    from bidmp.cli import main
    from bidmp.sim import JobInternalError, SimError
    from bidmp.sim import job as job_module

    def broken(world, part, target):
        raise ValueError("operands could not be broadcast together with shapes (3,) (2,)")

    monkeypatch.setattr(job_module, "_engaged", broken)
    with pytest.raises(JobInternalError, match=r"target 3 \(approach\): ValueError: operands"):
        run_job(nuts, targets=["3", "4"], backend="kinematic")
    code = main(
        [
            "job",
            "--targets",
            "3",
            "--backend",
            "kinematic",
            "--no-pictures",
            "--out",
            "/tmp/bidmp-job-bug",
        ]
    )
    assert code == 1
    assert "internal error" in capsys.readouterr().err
    monkeypatch.undo()

    calls = []
    original = job_module._approach

    def unreachable_once(world, label, target, axis):
        calls.append(label)
        if label == "3":
            raise SimError("target 3 is unreachable for the arm (a refusal of the task's)")
        return original(world, label, target, axis)

    monkeypatch.setattr(job_module, "_approach", unreachable_once)
    report = run_job(nuts, targets=["3", "4"], backend="kinematic")
    rows = {target.label: target for target in report.targets}
    assert "unreachable" in rows["3"].reason and not rows["3"].removed
    assert rows["4"].removed and calls == ["3", "4"]
