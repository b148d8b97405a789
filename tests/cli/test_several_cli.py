"""bidmp fit --promp / --multi on several demonstration files of other lengths and durations, and
bidmp rollout of the models: the written motion reaches the goal, starts at the demonstrations'
mean start, and the printed spread is the demonstrations' own."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from bidmp.cli import main
from bidmp.demonstrations import lasa
from bidmp.io import load_trajectory, save_trajectory


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("several")
    demos = lasa("Sshape")[:4]
    paths = []
    for index, (n, seconds) in enumerate(((1000, 2.0), (640, 2.4), (420, 1.8), (880, 2.2))):
        y = np.column_stack(
            [np.interp(np.linspace(0, 1, n), np.linspace(0, 1, 1000), c) for c in demos[index].T]
        )
        paths.append(str(save_trajectory(y, folder / f"s{index}.csv", np.linspace(0, seconds, n))))
    return folder, paths, demos


@pytest.mark.parametrize("flag", ["--promp", "--multi", "--prodmp"])
def test_fit_several_then_roll_out_to_a_goal(files, flag, capsys):
    folder, paths, demos = files
    model, figure = folder / f"m{flag}.npz", folder / f"m{flag}.png"
    code, out, _ = run(
        ["fit", flag, *paths, "--units", "mm", "--raw", "-o", str(model), "--plot", str(figure)],
        capsys,
    )
    assert code == 0 and figure.stat().st_size > 10_000
    assert "on 4 demonstrations (1000, 640, 420, 880 samples)" in out
    # the printed largest spread is of the order of the demonstrations' own
    largest = float(re.search(r"largest ([0-9.]+) mm", out).group(1))
    own = np.linalg.norm(np.std(demos, axis=0, ddof=1), axis=1).max()
    assert 0.5 * own < largest < 2.0 * own
    goal = demos.mean(axis=0)[-1] + [4.0, -3.0]
    out_csv = folder / f"o{flag}.csv"
    code, out, _ = run(
        [
            "rollout",
            str(model),
            "--goal",
            *map(str, goal),
            "-o",
            str(out_csv),
            "--plot",
            str(figure),
        ],
        capsys,
    )
    assert code == 0
    motion = load_trajectory(out_csv)
    y = motion[0] if isinstance(motion, tuple) else motion
    np.testing.assert_allclose(y[-1], goal, atol=0.01)
    np.testing.assert_allclose(y[0], demos.mean(axis=0)[0], atol=0.5)


def test_one_file_or_two_flags_are_refused_in_one_line(files, capsys):
    folder, paths, _ = files
    code, _, err = run(["fit", "--promp", paths[0], "-o", str(folder / "x.npz")], capsys)
    assert code == 2 and "two or more" in err and len(err.strip().splitlines()) == 1
    code, _, err = run(
        ["fit", "--promp", *paths[:2], "--multi", *paths[2:], "-o", str(folder / "x.npz")], capsys
    )
    assert code == 2 and "--promp" in err


@pytest.mark.parametrize("flag", ["--promp", "--multi", "--prodmp"])
def test_every_rollout_option_acts_or_is_refused(files, flag, capsys):
    """--rate was ignored for a --multi model (169 Hz for 500), --via on a ProMP gave the
    unconditioned mean, and other options passed unnoticed. Now --rate sets the sample interval,
    --via is passed exactly (at its time, to 1e-6 of the extent), and an option the model does not
    act on is refused in one line."""
    folder, paths, demos = files
    model = folder / f"opt{flag}.npz"
    assert run(["fit", flag, *paths, "--units", "mm", "--raw", "-o", str(model)], capsys)[0] == 0
    out_csv = folder / f"opt{flag}.csv"
    assert run(["rollout", str(model), "--rate", "500", "-o", str(out_csv)], capsys)[0] == 0
    t, _ = _columns(out_csv)
    np.testing.assert_allclose(np.diff(t), 0.002, rtol=1e-9)
    point = demos.mean(axis=0)[400] + [3.0, -2.0]
    code, out, err = run(
        [
            "rollout",
            str(model),
            "--rate",
            "500",
            "--via",
            "1.0",
            *map(str, point),
            "-o",
            str(out_csv),
        ],
        capsys,
    )
    assert code == 0, err
    t, y = _columns(out_csv)
    at = int(np.argmin(np.abs(t - 1.0)))
    assert abs(t[at] - 1.0) < 1e-9
    extent = np.ptp(demos.reshape(-1, 2), axis=0).max()
    assert np.linalg.norm(y[at] - point) <= 1e-6 * extent
    for option in (["--max-acc", "5"], ["--n-steps", "50"], ["--fastest"], ["--yaw", "30"]):
        code, _, err = run(["rollout", str(model), *option, "-o", str(out_csv)], capsys)
        lines = err.strip().splitlines()
        assert code == 2 and len(lines) == 1 and f"{option[0]} does not apply" in lines[0], err


def _columns(path) -> tuple:
    """A written trajectory's time column and positions (x, y), read as plain numbers."""
    text = Path(path).read_text()
    rows = [line for line in text.splitlines() if line and not line.startswith("#")]
    table = np.array([[float(v) for v in row.split(",")] for row in rows[1:]])
    return table[:, 0], table[:, 1:3]


@pytest.mark.parametrize("flag", ["--multi", "--promp"])
def test_the_fit_figure_draws_the_mean_among_the_demonstrations_in_time(
    files, flag, monkeypatch, capsys
):
    """The --multi figure drew the mean outside all the demonstrations: the mean motion (which runs
    on 10 % past their time to come to rest) was squeezed onto [0, 1] beside them. On time, the mean
    lies within the demonstrations' envelope (each on its own stamps) wherever all of them run:
    checked on the figure's own lines."""
    from bidmp.plotting import trajectories

    made = []
    monkeypatch.setattr(trajectories, "_save", lambda fig, path: made.append(fig) or Path(path))
    folder, paths, _ = files
    argv = ["fit", flag, *paths, "--units", "mm", "--raw", "-o", str(folder / "f.npz")]
    assert run([*argv, "--plot", str(folder / "f.png")], capsys)[0] == 0
    for ax in made[-1].axes:
        assert ax.get_xlabel() == "time [s]"
        grey = [line for line in ax.lines if line.get_color() == "0.7"]
        (mean,) = [line for line in ax.lines if line.get_label() == "mean ± 2σ"]
        assert len(grey) == len(paths)
        t, y = np.asarray(mean.get_xdata()), np.asarray(mean.get_ydata())
        common = t <= min(np.max(line.get_xdata()) for line in grey)
        curves = np.array(
            [np.interp(t[common], line.get_xdata(), line.get_ydata()) for line in grey]
        )
        extent = np.ptp(curves)
        inside = (y[common] >= curves.min(axis=0) - 0.02 * extent) & (
            y[common] <= curves.max(axis=0) + 0.02 * extent
        )
        assert inside.mean() >= 0.97, inside.mean()
    import matplotlib.pyplot as plt

    plt.close("all")
