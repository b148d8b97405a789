"""The bidmp command line: happy paths end to end, and one-line errors with exit code 2."""

import json
import pathlib
import subprocess
import sys

import numpy as np
import pytest
from conftest import curved_demo

import bidmp
from bidmp.cli import main
from bidmp.io import load_trajectory, save_trajectory


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture
def demo_csv(tmp_path):
    return save_trajectory(curved_demo(200, 3), tmp_path / "demo.csv")


def test_fit_then_rollout_round_trip(tmp_path, demo_csv, capsys):
    model = tmp_path / "model.npz"
    code, out, err = run(
        [
            "fit",
            str(demo_csv),
            "-o",
            str(model),
            "--alpha",
            "100",
            "--protocol",
            "paper",
            "--no-time",
        ],
        capsys,
    )
    assert code == 0 and err == ""
    assert "T = 200" in out and "end-point gain" in out and model.is_file()
    dmp = bidmp.load(model)
    assert dmp.alpha_value == 100.0 and dmp.protocol == "paper"

    goal = [0.5, -0.25, 1.0]
    out_csv = tmp_path / "out.csv"
    code, out, err = run(
        [
            "rollout",
            str(model),
            "--goal",
            *map(str, goal),
            "-o",
            str(out_csv),
            "--plot",
            str(tmp_path / "r.png"),
        ],
        capsys,
    )
    assert code == 0, err
    assert out_csv.read_text().splitlines()[0] == "t,x,y,z,vx,vy,vz,ax,ay,az"
    data = np.loadtxt(out_csv, delimiter=",", skiprows=1)
    expected = dmp.trajectory(goal=goal)
    np.testing.assert_allclose(
        data,
        np.column_stack([expected.t, expected.y, expected.yd, expected.ydd]),
        rtol=1e-12,
        atol=1e-12,
    )
    # The paper protocol's timed rollout is its rollout, sample for sample.
    np.testing.assert_allclose(
        load_trajectory(out_csv), dmp.rollout(goal=goal), rtol=1e-12, atol=1e-12
    )
    assert (tmp_path / "r.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

    code, _, _ = run(
        ["rollout", str(model), "-o", str(tmp_path / "out.npy"), "--n-steps", "600"], capsys
    )
    assert code == 0
    records = np.load(tmp_path / "out.npy")
    assert records.dtype.names == (
        "t",
        "x",
        "y",
        "z",
        "vx",
        "vy",
        "vz",
        "ax",
        "ay",
        "az",
    ) and records.shape == (600,)
    assert records["t"][-1] == pytest.approx(
        dmp.duration_
    )  # the same motion, three times the samples
    finer = dmp.trajectory(dt=dmp.duration_ / 599)
    np.testing.assert_array_equal(records["x"], finer.y[:, 0])


def test_lasa_list_and_export(tmp_path, capsys):
    code, out, _ = run(["lasa", "list"], capsys)
    assert code == 0 and len(out.split()) == 30 and "Sshape" in out.split()
    code, _, _ = run(
        ["lasa", "export", "WShape", "--demo", "2", "-o", str(tmp_path / "w.npy")], capsys
    )
    assert code == 0
    np.testing.assert_array_equal(
        np.load(tmp_path / "w.npy"), bidmp.demonstrations.lasa("WShape")[2]
    )


def test_lasa_demo_prints_a_table_and_writes_results(tmp_path, capsys):
    code, out, err = run(["demo", "--lasa", "Sshape", "--out", str(tmp_path / "out")], capsys)
    assert code == 0, err
    assert "reproduction RMSE" in out and "c * shift" in out
    results = json.loads((tmp_path / "out" / "lasa_generalisation.json").read_text())
    assert results["shape"] == "Sshape"
    assert results["reproduction_rmse_percent"] < 1.0
    # The fixed-horizon error departs from the demonstrated goal's error by exactly c * shift.
    shifts = np.array(results["goal_shifts"])
    errors = np.array(results["endpoint_errors_fixed_horizon"])
    assert np.all(
        np.abs(errors - results["endpoint_gain"] * shifts) <= results["goal_error"] + 1e-9
    )
    assert max(results["endpoint_errors_converged"]) < 0.1 * min(errors)
    assert (tmp_path / "out" / "lasa_generalisation.png").stat().st_size > 10_000


def test_demo_runs_the_nut_scenario_prints_tables_and_writes_results(tmp_path, capsys):
    code, out, err = run(["demo", "--out", str(tmp_path / "out")], capsys)
    assert code == 0, err
    assert "Table 4 analogue" in out and "Tables 1 and 2 analogue" in out
    assert "57.14 %" in out and "100.00 %" in out
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results["scenario"] == "nut-unscrewing"
    assert (
        results["methods"]["dmp"]["successes"] == 8
        and results["methods"]["bidmp"]["successes"] == 14
    )
    for figure in ("targets_top_view.png", "error_vs_distance.png", "scenario_3d.png"):
        assert (tmp_path / "out" / figure).stat().st_size > 20_000


def test_demo_with_a_method_subset_and_scenario_list(tmp_path, capsys):
    code, out, err = run(
        [
            "demo",
            "--scenario",
            "pick-and-place",
            "--methods",
            "dmp,bidmp",
            "--out",
            str(tmp_path / "o"),
        ],
        capsys,
    )
    assert code == 0, err
    assert set(json.loads((tmp_path / "o" / "results.json").read_text())["methods"]) == {
        "dmp",
        "bidmp",
    }
    assert "forgetting" in out
    code, out, _ = run(["scenario", "list"], capsys)
    assert (
        code == 0 and "nut-unscrewing" in out and "cell-removal" in out and "pick-and-place" in out
    )


RESULTS = pathlib.Path(__file__).resolve().parents[2] / "docs" / "results"


def assert_committed(produced):
    """The command's Markdown equals the committed copy the README embeds (make readme), by value
    (tools/compare_results.py: a decimal may move in its last printed place, a count may not)."""
    import sys

    sys.path.insert(0, str(RESULTS.parents[1] / "tools"))
    from compare_results import compare_files

    differences = compare_files(produced, RESULTS / produced.name)
    assert not differences, f"{produced.name} changed ({differences[:3]}): run 'make readme'"


def test_reproduce_table4_runs_the_three_case_studies(tmp_path, capsys):
    code, out, err = run(["reproduce", "table4", "--out", str(tmp_path / "t4")], capsys)
    assert code == 0, err
    summary = json.loads((tmp_path / "t4" / "table4.json").read_text())
    assert {"nut-unscrewing", "cell-removal", "pick-and-place", "case_studies"} <= set(summary)
    cells = summary["case_studies"]["cell_removal"]
    assert cells["after"]["B6"] < cells["before"]["B6"]
    assert "end error before" in out
    assert_committed(tmp_path / "t4" / "table4.md")
    assert_committed(tmp_path / "t4" / "tasks.md")
    keep = summary["approach_keep"]["nut-unscrewing"]["methods"]["bidmp"]
    assert (
        keep["task_successes"] == 14
        and summary["nut-unscrewing"]["methods"]["bidmp"]["engaged"] == 6
    )


@pytest.mark.parametrize(
    "argv, match",
    [
        (["fit", "{tmp}/missing.csv", "-o", "{tmp}/m.npz"], "does not exist"),
        (["fit", "{tmp}/bad.csv", "-o", "{tmp}/m.npz"], "line 3, column 2: 'oops' is not a number"),
        (["fit", "{tmp}/nan.csv", "-o", "{tmp}/m.npz"], "contains NaN"),
        (
            ["fit", "{tmp}/demo.csv", "-o", "{tmp}/m.npz", "--n-kernels", "0", "--no-time"],
            "n_kernels must be >= 1",
        ),
        (["fit", "{tmp}/demo.csv", "-o", "{tmp}/no/such/dir/m.npz", "--no-time"], "does not exist"),
        (["rollout", "{tmp}/corrupt.npz", "-o", "{tmp}/o.csv"], "not a readable bidmp model file"),
        (
            ["rollout", "{tmp}/model.npz", "--goal", "1", "2", "-o", "{tmp}/o.csv"],
            "goal must have 3 coordinate",
        ),
        (["rollout", "{tmp}/model.npz", "-o", "{tmp}/o.txt"], "unsupported file type .txt"),
        (["lasa", "export", "Banana", "-o", "{tmp}/b.csv"], "unknown LASA shape 'Banana'"),
        (["lasa", "export", "Sshape", "--demo", "9", "-o", "{tmp}/b.csv"], "--demo must be 0-6"),
        (["fit", "{tmp}/demo.csv"], "required: -o/--output"),
        (["rollout", "{tmp}/model.npz", "--goal", "x", "-o", "{tmp}/o.csv"], "invalid float value"),
        (["frobnicate"], "invalid choice"),
        (["demo", "--scenario", "nowhere", "--out", "{tmp}/o"], "no such file, and not a built-in"),
        (["demo", "--methods", "dmp,magic", "--out", "{tmp}/o"], "unknown method 'magic'"),
        (["scenario", "show", "nope"], "unknown built-in scenario"),
    ],
)
def test_bad_input_gives_one_line_and_exit_code_2(tmp_path, demo_csv, argv, match, capsys):
    (tmp_path / "bad.csv").write_text("x,y\n0,0\n1,oops\n2,2\n")
    (tmp_path / "nan.csv").write_text("x,y\n0,0\nnan,1\n2,2\n")
    (tmp_path / "corrupt.npz").write_bytes(b"PK\x03\x04 broken")
    bidmp.save(bidmp.DMP(protocol="paper").fit(curved_demo(100, 3)), tmp_path / "model.npz")
    code = exit_code([arg.format(tmp=tmp_path) for arg in argv])
    _, err = capsys.readouterr()
    assert code == 2
    assert match in err
    assert len(err.strip().splitlines()) == 1, err
    assert "Traceback" not in err


def exit_code(argv):
    """main()'s return value, or the code argparse exits with on a usage error."""
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


def test_real_process_error_has_no_traceback_and_exit_2(tmp_path):
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "bidmp",
            "fit",
            str(tmp_path / "none.csv"),
            "-o",
            str(tmp_path / "m.npz"),
        ],
        capture_output=True,
        text=True,
    )
    assert result.returncode == 2
    assert result.stderr.startswith("bidmp fit: error:") and "Traceback" not in result.stderr


def test_version_and_help(capsys):
    with pytest.raises(SystemExit) as exit_info:
        main(["--version"])
    assert exit_info.value.code == 0
    assert bidmp.__version__ in capsys.readouterr().out
    with pytest.raises(SystemExit):
        main(["fit", "--help"])
    assert "--n-kernels" in capsys.readouterr().out


@pytest.fixture
def battery_files(tmp_path, capsys):
    from bidmp.demonstrations import minimum_jerk
    from bidmp.experiments import BATTERY_APPROACH_VIA

    demo = save_trajectory(minimum_jerk(BATTERY_APPROACH_VIA, 200), tmp_path / "approach.csv")
    model = tmp_path / "approach.npz"
    assert main(["fit", str(demo), "-o", str(model), "--alpha", "100", "--no-time"]) == 0
    capsys.readouterr()
    return demo, model


def test_segment_prints_points_and_plots(tmp_path, battery_files, capsys):
    demo, _ = battery_files
    code, out, err = run(["segment", str(demo), "--plot", str(tmp_path / "seg.png")], capsys)
    assert code == 0, err
    assert "segmentation point" in out and "max" in out
    assert (tmp_path / "seg.png").stat().st_size > 10_000
    expected = bidmp.segment(load_trajectory(demo)).points
    for index in expected:
        assert f"{index} " in out


def test_extend_learns_a_bidmp_and_rollout_uses_its_skills(tmp_path, battery_files, capsys):
    demo, model = battery_files
    bidmp_file, demo_out = tmp_path / "bidmp.npz", tmp_path / "extended.npy"
    code, out, err = run(
        [
            "extend",
            str(model),
            str(demo),
            "--target",
            "150",
            "25",
            "0",
            "-o",
            str(bidmp_file),
            "--seed",
            "3",
            "--save-demo",
            str(demo_out),
            "--plot",
            str(tmp_path / "ext.png"),
        ],
        capsys,
    )
    assert code == 0, err
    assert "G-PRM similarity per iteration" in out and "learned skill 1" in out
    extension = bidmp.extend_demonstration(load_trajectory(demo), [150, 25, 0], seed=3)
    records = np.load(demo_out)
    np.testing.assert_array_equal(
        np.column_stack([records["x"], records["y"], records["z"]]), extension.complete
    )
    dmp = bidmp.load(
        model
    )  # the extension lasts longer than the demonstration: written as it lasts
    assert (
        records["t"][-1] == pytest.approx(extension.duration_for(dmp))
        and extension.duration_for(dmp) > dmp.duration_
    )
    learned = bidmp.load(bidmp_file)
    assert isinstance(learned, bidmp.BiDMP) and learned.n_skills == 2
    expected = bidmp.BiDMP(dmp).learn(extension.complete, duration=extension.duration_for(dmp))
    np.testing.assert_array_equal(learned.rollout([150, 25, 0]), expected.rollout([150, 25, 0]))
    assert (tmp_path / "ext.png").stat().st_size > 10_000

    # A second extension stacks a skill on the Bi-DMP model.
    second = tmp_path / "bidmp2.npz"
    assert (
        main(["extend", str(bidmp_file), str(demo), "--target", "60", "50", "0", "-o", str(second)])
        == 0
    )
    assert bidmp.load(second).n_skills == 3
    capsys.readouterr()

    for skill, expected_rollout in (
        ("0", learned.dmp_.trajectory([150, 25, 0])),
        ("latest", learned.trajectory([150, 25, 0], skill="latest")),
    ):
        out_file = tmp_path / f"r{skill}.npy"
        code, out, err = run(
            [
                "rollout",
                str(bidmp_file),
                "--goal",
                "150",
                "25",
                "0",
                "--skill",
                skill,
                "-o",
                str(out_file),
            ],
            capsys,
        )
        assert code == 0, err
        records = np.load(out_file)
        np.testing.assert_array_equal(
            np.column_stack([records["x"], records["y"], records["z"]]), expected_rollout.y
        )
        np.testing.assert_array_equal(records["vz"], expected_rollout.yd[:, 2])
    code, out, _ = run(["rollout", str(bidmp_file), "-o", str(tmp_path / "default.npy")], capsys)
    assert code == 0 and "using skill 1" in out


def test_reproduce_figures_prints_forgetting_and_writes_figure(tmp_path, capsys):
    code, out, err = run(["reproduce", "figures", "--out", str(tmp_path / "f")], capsys)
    assert code == 0, err
    assert "forgetting nearest" in out
    results = json.loads((tmp_path / "f" / "figures.json").read_text())["results"]
    assert [r["shape"] for r in results] == ["Sshape", "WShape", "NShape"]
    for result in results:
        assert max(result["bidmp_rmse"]) < 0.05 * min(result["dmp_rmse"])  # far below the plain DMP
        assert (
            min(result["forgetting_latest"]["forgetting"][:-1]) > 1.0
        )  # "latest" overwrites earlier skills
    assert (tmp_path / "f" / "bidmp_lasa.png").stat().st_size > 30_000
    assert_committed(tmp_path / "f" / "figures.md")


def test_reproduce_table5_writes_table_json_and_figure(tmp_path, capsys):
    code, out, err = run(
        ["reproduce", "table5", "--out", str(tmp_path / "t5")], capsys
    )  # 20 seeds, as the README
    assert code == 0, err
    assert "G-PRM" in out and "PRM" in out and "battery approach" in out
    summary = json.loads((tmp_path / "t5" / "table5.json").read_text())
    assert summary["n_seeds"] == 20 and len(summary["cases"]) == 5
    assert_committed(tmp_path / "t5" / "table5.md")
    case = summary["cases"][0]
    assert len(case["gprm_per_iteration"]) == 10
    assert case["gprm_final"]["mean"] >= case["gprm_first"]["mean"]
    assert (tmp_path / "t5" / "table5.png").stat().st_size > 50_000
    assert "| case |" in (tmp_path / "t5" / "table5.md").read_text()


@pytest.mark.parametrize(
    "argv, match",
    [
        (["segment", "{demo}", "--eps-frac", "1.5"], "eps_frac must lie in (0, 1)"),
        (
            ["extend", "{model}", "{demo}", "--target", "1", "2", "-o", "{tmp}/x.npz"],
            "new_target must have 3",
        ),
        (
            ["extend", "{model}", "{tmp}/flat.csv", "--target", "1", "2", "-o", "{tmp}/x.npz"],
            "has D = 2 but the model",
        ),
        (["extend", "{model}", "{demo}", "--target", "1", "nan", "0", "-o", "{tmp}/x.npz"], "NaN"),
        (
            ["extend", "{model}", "{demo}", "--target", "1", "2", "0", "-o", "{tmp}/x.csv"],
            "-o must be the Bi-DMP model file",
        ),
        (
            ["rollout", "{model}", "--skill", "1", "-o", "{tmp}/x.csv"],
            "--skill needs a Bi-DMP model",
        ),
        (["reproduce", "table5", "--seeds", "0", "--out", "{tmp}/o"], "--seeds must be 1-200"),
    ],
)
def test_extension_commands_reject_bad_input(tmp_path, battery_files, argv, match, capsys):
    demo, model = battery_files
    save_trajectory(curved_demo(50, 2), tmp_path / "flat.csv")
    code = exit_code([a.format(demo=demo, model=model, tmp=tmp_path) for a in argv])
    _, err = capsys.readouterr()
    assert code == 2 and match in err and len(err.strip().splitlines()) == 1, err


def test_fit_tau_makes_rollouts_slower_in_real_time(tmp_path, demo_csv, capsys):
    for tau in ("1", "2"):
        assert (
            main(
                [
                    "fit",
                    str(demo_csv),
                    "-o",
                    str(tmp_path / f"m{tau}.npz"),
                    "--tau",
                    tau,
                    "--no-time",
                ]
            )
            == 0
        )
        assert (
            main(["rollout", str(tmp_path / f"m{tau}.npz"), "-o", str(tmp_path / f"r{tau}.csv")])
            == 0
        )
    capsys.readouterr()
    one = np.loadtxt(tmp_path / "r1.csv", delimiter=",", skiprows=1)[:, :4]
    two = np.loadtxt(tmp_path / "r2.csv", delimiter=",", skiprows=1)[:, :4]
    assert abs(two.shape[0] - 2 * one.shape[0]) <= 1 and two[-1, 0] == pytest.approx(
        2 * one[-1, 0], rel=0.01
    )
    np.testing.assert_allclose(
        two[::2, 1:][: one.shape[0]], one[:, 1:], atol=0.01 * np.ptp(one[:, 1:], axis=0).max()
    )


def test_the_cli_seed_bound_is_the_library_one():
    from bidmp import cli
    from bidmp import experiments as reproduce

    assert cli.common.MAX_SEEDS == reproduce.MAX_SEEDS


# --- the pose commands, units, loggers' files, limits as caps ---------------------------
@pytest.fixture
def pose_recording(tmp_path):
    from scipy.spatial.transform import Rotation

    from bidmp.demonstrations import kinesthetic_recording
    from bidmp.io import save_poses

    positions, t = kinesthetic_recording([[0, 0, 120], [60, -40, 60], [120, 10, 0]], seed=4)
    _, moving = bidmp.prepare(positions, t)
    s = np.clip((t - t[0] - moving.start_s) / (moving.end_s - moving.start_s), 0.0, 1.0)
    down = Rotation.from_euler("x", 180, degrees=True)
    quaternions = (Rotation.from_rotvec(np.outer(s, [0.2, 0.1, 0.6])) * down).as_quat()
    return save_poses(np.hstack([positions, quaternions]), tmp_path / "poses.csv", times=t)


def test_the_pose_commands_extend_learn_and_roll_out_a_pose_bidmp(tmp_path, pose_recording, capsys):
    """before the fix, extend and learn on a pose model ended with 'internal error:
    AttributeError: Namespace object has no attribute skill', and rollout --plot wrote nothing."""
    model, grown, more = tmp_path / "pose.npz", tmp_path / "grown.npz", tmp_path / "more.npz"
    assert run(["fit", str(pose_recording), "-o", str(model), "--units", "mm"], capsys)[0] == 0
    code, out, err = run(
        [
            "extend",
            str(model),
            str(pose_recording),
            "--target",
            "170",
            "30",
            "0",
            "-o",
            str(grown),
            "--save-demo",
            str(tmp_path / "extended.csv"),
            "--plot",
            str(tmp_path / "x.png"),
        ],
        capsys,
    )
    assert code == 0, err
    assert "learned skill 1" in out and (tmp_path / "x.png").is_file()
    skills = bidmp.load(grown)
    assert isinstance(skills, bidmp.CartesianBiDMP) and skills.n_skills == 2
    extended, _ = bidmp.io.read_poses(tmp_path / "extended.csv")
    np.testing.assert_allclose(extended[-1, :3], [170.0, 30.0, 0.0], atol=1e-6)
    code, out, err = run(["learn", str(grown), str(pose_recording), "-o", str(more)], capsys)
    assert code == 0, err
    assert bidmp.load(more).n_skills == 3
    figure = tmp_path / "r.png"
    code, out, err = run(
        [
            "rollout",
            str(more),
            "--skill",
            "1",
            "-o",
            str(tmp_path / "r.csv"),
            "--plot",
            str(figure),
        ],
        capsys,
    )
    assert code == 0, err
    assert figure.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and "using skill 1" in out
    poses, _ = bidmp.io.read_poses(tmp_path / "r.csv")
    assert np.linalg.norm(poses[-1, :3] - [170.0, 30.0, 0.0]) <= 0.1
    # A pose demonstration for a position model (and the reverse) is one clear line.
    positions = save_trajectory(
        bidmp.io.read_poses(pose_recording)[0][:, :3], tmp_path / "positions.csv"
    )
    assert run(["learn", str(grown), str(positions), "-o", str(more)], capsys)[2].count("\n") == 1


def test_units_are_a_known_set_checked_against_the_model_and_converted_on_request(tmp_path, capsys):
    """before the fix, --units took any text, a mm recording learned into a metre
    model silently, and a mm goal on a metre model wrote a 458 m/s trajectory without a word."""
    y, t = bidmp.demonstrations.recording("operator1_nut3")
    in_metres = save_trajectory(y / 1000.0, tmp_path / "m.csv", times=t, units="m")
    undeclared_mm = save_trajectory(y, tmp_path / "mm.csv", times=t)
    assert in_metres.read_text().startswith("# units: m\n")
    with pytest.raises(SystemExit) as exited:
        main(["fit", str(undeclared_mm), "-o", str(tmp_path / "x.npz"), "--units", "furlong"])
    assert (
        exited.value.code == 2 and "--units: invalid choice: 'furlong'" in capsys.readouterr().err
    )
    assert (
        run(["fit", str(in_metres), "-o", str(tmp_path / "m.npz")], capsys)[0] == 0
    )  # the declared unit is kept
    assert bidmp.load(tmp_path / "m.npz").units_ == "m"
    code, _, err = run(
        ["learn", str(tmp_path / "m.npz"), str(undeclared_mm), "-o", str(tmp_path / "y.npz")],
        capsys,
    )
    assert code == 2 and "declares no units" in err and "times the model's" in err
    assert (
        run(["fit", str(undeclared_mm), "-o", str(tmp_path / "mm.npz"), "--units", "mm"], capsys)[0]
        == 0
    )
    code, _, err = run(
        ["learn", str(tmp_path / "mm.npz"), str(in_metres), "-o", str(tmp_path / "y.npz")], capsys
    )
    assert code == 2 and "is in m but the model" in err and "in mm: pass --units mm" in err
    code, out, err = run(
        [
            "learn",
            str(tmp_path / "mm.npz"),
            str(in_metres),
            "-o",
            str(tmp_path / "y.npz"),
            "--units",
            "mm",
        ],
        capsys,
    )
    assert code == 0 and "converted from m (declared in the file) to mm" in out
    assert bidmp.load(tmp_path / "y.npz").skill_goals_[1] == pytest.approx(
        y[-1], abs=1.0
    )  # learned in mm
    code, out, err = run(
        [
            "rollout",
            str(tmp_path / "m.npz"),
            "--goal",
            "150",
            "20",
            "0",
            "-o",
            str(tmp_path / "g.csv"),
        ],
        capsys,
    )
    assert (
        code == 2 and "beyond any robot's reach" in err and "is it in cm or mm?" in err
    )  # refused, not warned
    assert not (tmp_path / "g.csv").exists()
    code, _, err = run(
        [
            "extend",
            str(tmp_path / "m.npz"),
            str(in_metres),
            "--target",
            "0.1",
            "0.1",
            "0",
            "--scene",
            "nut-unscrewing",
            "-o",
            str(tmp_path / "z.npz"),
        ],
        capsys,
    )
    assert code == 2 and "the scene of nut-unscrewing is in mm but the model is in m" in err


def test_a_loggers_file_reads_with_a_column_mapping(tmp_path, capsys):
    """other column names, extra columns and a repeated stamp, as loggers write them."""
    y, t = bidmp.demonstrations.recording("operator2_nut5")
    t = t.copy()
    t[300] = t[299]
    rows = np.column_stack([t, y[:, 2], np.ones(len(t)), y[:, 0], y[:, 1]])
    path = tmp_path / "log.csv"
    path.write_text(
        "stamp,ee_z,grip,ee_x,ee_y\n"
        + "\n".join(",".join(repr(float(v)) for v in row) for row in rows)
        + "\n"
    )
    code, out, err = run(
        [
            "fit",
            str(path),
            "-o",
            str(tmp_path / "m.npz"),
            "--units",
            "mm",
            "--columns",
            "t=stamp,x=ee_x,y=ee_y,z=ee_z",
        ],
        capsys,
    )
    assert code == 0, err
    assert "ignored 1 column(s) that are not time or the motion read: grip" in err
    assert "dropped 1 sample(s) whose timestamp repeats" in err
    expected = bidmp.prepare(y, bidmp.demonstrations.recording("operator2_nut5")[1])[0].y[
        -1
    ]  # the file without a dropped sample
    np.testing.assert_allclose(bidmp.load(tmp_path / "m.npz").goal_, expected, atol=0.1)
    # Without the mapping, stamp is the time and the other columns read as a joint recording,
    # whose speed (3.4 "rad/s" of millimetres) no arm's joints reach: refused, naming --columns.
    code, _, err = run(["fit", str(path), "-o", str(tmp_path / "m.npz")], capsys)
    assert code == 2 and "read as joints (ee_z, grip, ee_x, ee_y)" in err and "--columns" in err


def test_max_speed_is_a_cap_and_fastest_asks_for_more(tmp_path, demo_csv, capsys):
    """before the fix, --max-speed above the demonstrated speed shortened the motion."""
    y, t = bidmp.demonstrations.recording("operator1_nut3")
    recording = save_trajectory(y, tmp_path / "r.csv", times=t)
    assert (
        run(["fit", str(recording), "-o", str(tmp_path / "m.npz"), "--units", "mm"], capsys)[0] == 0
    )
    durations = {}
    for name, extra in (
        ("plain", []),
        ("cap", ["--max-speed", "1000"]),
        ("fastest", ["--max-speed", "1000", "--fastest"]),
        ("slow", ["--max-speed", "50"]),
    ):
        code, _, err = run(
            ["rollout", str(tmp_path / "m.npz"), "-o", str(tmp_path / f"{name}.csv"), *extra],
            capsys,
        )
        assert code == 0, err
        durations[name] = bidmp.io.read_trajectory(tmp_path / f"{name}.csv")[1][-1]
    assert durations["cap"] == durations["plain"]
    assert (
        durations["fastest"] < 0.5 * durations["plain"]
        and durations["slow"] > 2 * durations["plain"]
    )
    code, _, err = run(
        ["rollout", str(tmp_path / "m.npz"), "-o", str(tmp_path / "x.csv"), "--fastest"], capsys
    )
    assert code == 2 and "--fastest needs --max-speed, --max-acc or --joint-limits" in err


def test_fifos_are_refused_not_waited_on(tmp_path, capsys):
    """`mkfifo f.csv; bidmp fit f.csv` blocked for ever (the unit sniffing opened it)."""
    import os
    import threading

    os.mkfifo(tmp_path / "f.csv")
    os.mkfifo(tmp_path / "m.npz")
    os.mkfifo(tmp_path / "s.json")
    codes = []
    for argv in (
        ["fit", tmp_path / "f.csv", "-o", tmp_path / "out.npz"],
        ["segment", tmp_path / "f.csv"],
        ["rollout", tmp_path / "m.npz", "-o", tmp_path / "r.csv"],
        ["scenario", "check", tmp_path / "s.json"],
    ):
        worker = threading.Thread(
            target=lambda argv=argv: codes.append(main([str(a) for a in argv])), daemon=True
        )
        worker.start()
        worker.join(10.0)
        assert not worker.is_alive(), f"{argv[0]} blocked on a FIFO"
    assert codes == [2, 2, 2, 2]
    err = capsys.readouterr().err
    assert err.count("not a regular file") == 4


def test_printed_names_cannot_drive_the_terminal(tmp_path, capsys):
    """a scenario's name and labels are printed; escape sequences in them are shown as '?'."""
    from bidmp.tasks import scenarios

    spec = json.loads(scenarios.builtin_text("pick-and-place"))
    spec["name"] = "evil\x1b[31mRED\x1b[0m"
    spec["targets"] = {"t\x1b[2J" + label: point for label, point in spec["targets"].items()}
    spec["demonstrated"] = "t\x1b[2J" + spec["demonstrated"]
    path = tmp_path / "evil.json"
    path.write_text(json.dumps(spec))
    assert main(["scenario", "check", str(path)]) == 0
    assert (
        main(["demo", "--scenario", str(path), "--methods", "dmp", "--out", str(tmp_path / "o")])
        == 0
    )
    out = capsys.readouterr().out
    assert "\x1b" not in out and "evil?[31mRED" in out


def test_every_help_text_renders_as_written(capsys):
    """Structure guard: no command's --help shows argparse's escapes ('%%') or an unfilled
    '%(...)s' (descriptions and epilogs are not %-formatted, argument help is)."""
    import argparse

    from bidmp.cli import build_parser

    parser = build_parser()
    commands = next(
        action for action in parser._actions if isinstance(action, argparse._SubParsersAction)
    )
    shown = [parser.format_help()]
    for _name, sub in commands.choices.items():
        shown.append(sub.format_help())
        for action in sub._actions:
            if isinstance(action, argparse._SubParsersAction):
                shown += [inner.format_help() for inner in action.choices.values()]
    assert len(shown) > 10
    for text in shown:
        assert "%%" not in text and "%(" not in text, text[:200]


@pytest.mark.parametrize("approach", ["paper", "keep"])
def test_demo_approach_reaches_the_evaluation(tmp_path, monkeypatch, approach):
    """``bidmp demo --approach`` acts (no option silently ignored): the scenario the evaluation
    gets extends with that approach, its other extension options kept."""
    import bidmp.tasks.evaluation as evaluation

    seen = []

    class Stop(Exception):
        pass

    def evaluate(scenario, methods, **options):
        seen.append(scenario.extension)
        raise Stop

    monkeypatch.setattr(evaluation, "evaluate", evaluate)
    # the CLI reports the stop as an internal error (exit 1) once the scenario has reached it
    assert main(["demo", "--approach", approach, "--out", str(tmp_path)]) == 1
    (extension,) = seen
    assert extension.approach == approach
    assert extension.replace(approach="keep") == bidmp.tasks.load("nut-unscrewing").extension
