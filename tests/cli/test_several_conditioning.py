"""bidmp rollout of a ProDMP or a ProMP learned from several demonstrations, conditioned from the
command line on the goal and via-points together: the written motion passes each via-point at
its time and ends at the goal at rest, judged here from the written positions alone (finite
differences of the file's samples, not the model's own velocities); and what the motion is
conditioned on is said.

Before, a ProDMP's --goal moved its goal weight after the via-points were met, so the motion
missed them (exit 0), and with --via alone it dipped below the goal, ended 4.3 mm off it still
moving at 41.8 mm/s, labelled "the mean motion"."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from bidmp.cli import main
from bidmp.io import save_trajectory

RATE = 200.0  # Hz: the via-points' times below are on its grid


def _demonstrations(rng, count: int = 5):
    """``count`` demonstrations of one reach with shapes of their own: a minimum-jerk profile to
    a goal spread by a few mm, plus sine bumps of random size and phase that vanish at both
    ends; each of its own duration and sample count, timed in seconds."""
    start, goal = np.zeros(3), np.array([100.0, -20.0, 50.0])
    demos = []
    for _ in range(count):
        n, duration = int(rng.integers(150, 400)), float(rng.uniform(1.6, 2.4))
        s = np.linspace(0.0, 1.0, n)[:, None]
        profile = 10 * s**3 - 15 * s**4 + 6 * s**5
        bumps = sum(
            rng.normal(0.0, 12.0, 3) * np.sin(k * np.pi * s + rng.uniform(0, np.pi)) * (s * (1 - s))
            for k in (1, 2, 3)
        )
        end = goal + rng.normal(0.0, 3.0, 3)
        demos.append((start + (end - start) * profile + 4.0 * bumps, np.linspace(0, duration, n)))
    return demos


def _run(argv, capsys):
    code = main([str(part) for part in argv])
    out, err = capsys.readouterr()
    assert code == 0, err
    return out


def _end_speed(y: np.ndarray, dt: float) -> float:
    """The speed at the last sample from the positions: the one-sided second-order difference
    (3 y_N - 4 y_N-1 + y_N-2) / 2 dt, exact for a quadratic (a backward difference of a motion
    at rest but accelerating would read a dt / 2)."""
    return float(np.linalg.norm(3 * y[-1] - 4 * y[-2] + y[-3]) / (2 * dt))


def _written(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """The file's time column and positions (x, y, z), read as plain numbers."""
    rows = [line for line in path.read_text().splitlines() if line and not line.startswith("#")]
    table = np.array([[float(v) for v in row.split(",")] for row in rows[1:]])
    return table[:, 0], table[:, 1:4]


@pytest.fixture(scope="module", params=[0, 1])
def fitted(request, tmp_path_factory):
    """Two sets of demonstrations (seeded), each as files, and a ProDMP and a ProMP learned from
    them by bidmp fit."""
    folder = tmp_path_factory.mktemp(f"several{request.param}")
    rng = np.random.default_rng(40 + request.param)
    demos = _demonstrations(rng)
    paths = [
        save_trajectory(y, folder / f"d{i}.csv", t, units="mm") for i, (y, t) in enumerate(demos)
    ]
    models = {}
    for flag in ("--prodmp", "--promp"):
        models[flag] = folder / f"{flag[2:]}.npz"
        assert main(["fit", flag, *map(str, paths), "--raw", "-o", str(models[flag])]) == 0
    return folder, demos, models, rng


@pytest.mark.parametrize("flag", ["--prodmp", "--promp"])
def test_the_goal_and_two_via_points_are_passed_together_and_it_ends_at_rest(fitted, flag, capsys):
    folder, demos, models, rng = fitted
    capsys.readouterr()
    duration = min(t[-1] for _, t in demos)  # within every demonstration's time
    # two via-points off the first demonstration by a few mm, at times on the rate's grid
    times = np.round(np.sort(rng.uniform(0.25, 0.75, 2)) * duration * RATE) / RATE
    first_y, first_t = demos[0]
    via = [
        np.array([np.interp(when, first_t, c) for c in first_y.T]) + rng.normal(0.0, 4.0, 3)
        for when in times
    ]
    goal = first_y[-1] + rng.normal(0.0, 6.0, 3)
    out_csv = folder / f"rolled{flag}.csv"
    argv = ["rollout", models[flag], "--rate", RATE, "--goal", *goal]
    for when, point in zip(times, via):
        argv += ["--via", when, *point]
    out = _run([*argv, "-o", out_csv], capsys)
    t, y = _written(out_csv)
    assert np.allclose(np.diff(t), 1.0 / RATE, rtol=1e-9)
    for when, point in zip(times, via):
        at = int(np.argmin(np.abs(t - when)))
        assert abs(t[at] - when) < 1e-9
        assert np.linalg.norm(y[at] - point) <= 0.5, (when, y[at], point)
    assert np.linalg.norm(y[-1] - goal) <= 0.5
    # at rest: the last step's speed, from the positions, well below the motion's mean speed
    mean_speed = np.sum(np.linalg.norm(np.diff(y, axis=0), axis=1)) / (t[-1] - t[0])
    end_speed = _end_speed(y, 1.0 / RATE)
    assert end_speed <= 0.01 * mean_speed, (end_speed, mean_speed)
    first = out.splitlines()[0]
    assert first.startswith("rolled out the mean conditioned on the start ")
    assert all(f"at {when:g} s" in first for when in times) and "the goal [" in first


@pytest.mark.parametrize("flag", ["--prodmp", "--promp"])
def test_a_via_point_alone_says_what_it_is_conditioned_on_and_ends_at_the_mean_end(
    fitted, flag, capsys
):
    folder, demos, models, rng = fitted
    capsys.readouterr()
    plain_csv, via_csv = folder / f"plain{flag}.csv", folder / f"via{flag}.csv"
    plain = _run(["rollout", models[flag], "--rate", RATE, "-o", plain_csv], capsys)
    assert plain.splitlines()[0].startswith("rolled out the mean motion: ")
    _, mean = _written(plain_csv)
    when = 0.5
    point = mean[int(when * RATE)] + [0.0, 0.0, 8.0]
    out = _run(
        ["rollout", models[flag], "--rate", RATE, "--via", when, *point, "-o", via_csv], capsys
    )
    first = out.splitlines()[0]
    assert re.match(
        r"rolled out the mean conditioned on the start \[.*\] \(the mean start\)", first
    )
    assert f"the via-point {np.array2string(point, precision=4, separator=' ')} at 0.5 s" in first
    assert "(the mean end) at rest" in first
    t, y = _written(via_csv)
    assert np.linalg.norm(y[int(when * RATE)] - point) <= 0.5
    assert np.linalg.norm(y[-1] - mean[-1]) <= 0.5  # where the mean motion ends
    assert _end_speed(y, 1.0 / RATE) <= 0.01 * np.ptp(mean, axis=0).max() / t[-1]
