"""``bidmp verify`` hands each file's commands to the judge of the robot asked for, in the robot's
joint order, checks every file against its run, and fails on any rejected file wherever it stands
in the list. Several of everything: two robots (the Panda and the FR3, whose tables differ), joint
columns in another order, files accepted and rejected in both orders, two files of a run folder.
The expected verdicts come from the published ranges (typed here) and closed forms."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from bidmp.cli import main

# the joints' ranges (rad) of the robots' FCI tables, as published
PANDA_RANGE = (
    (-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973),
    (2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973),
)
FR3_RANGE = (
    (-2.7501, -1.7918, -2.9065, -3.0481, -2.8101, 0.54092, -3.0196),
    (2.7501, 1.7918, 2.9065, -0.1458, 2.8101, 4.5205, 3.0196),
)


def _stroke(start, joint: int, amplitude: float, seconds: float = 2.0) -> np.ndarray:
    """1 kHz commands (T, 7): a minimum-jerk stroke of ``amplitude`` rad on ``joint`` from
    ``start``, at rest at both ends (peak velocity 1.875 A/T)."""
    tau = np.linspace(0.0, 1.0, int(round(seconds * 1000)) + 1)[:, None]
    commands = np.repeat(np.asarray(start, dtype=float)[None], tau.shape[0], axis=0)
    commands[:, joint] += amplitude * (
        10 * tau[:, 0] ** 3 - 15 * tau[:, 0] ** 4 + 6 * tau[:, 0] ** 5
    )
    return commands


def _write(path: Path, commands: np.ndarray, names: list[str], order=None) -> Path:
    """A motion file: t and the joints, columns in ``order`` (indices into the joints)."""
    order = list(range(7)) if order is None else list(order)
    t = np.arange(commands.shape[0]) * 1e-3
    header = "t," + ",".join(names[k] for k in order)
    np.savetxt(
        path,
        np.column_stack([t, commands[:, order]]),
        delimiter=",",
        header=header,
        comments="",
        fmt="%.17g",
    )
    return path


def _inside(q, table) -> bool:
    return bool(np.all(np.asarray(table[0]) <= q) and np.all(q <= np.asarray(table[1])))


def test_each_robots_motion_is_judged_by_its_own_tables(tmp_path, capsys):
    """Joint 1 taken to 2.8 rad: inside the Panda's range (2.8973), past the FR3's (2.7501):
    accepted for the Panda; the same motion as the FR3's, rejected. Joint 6 at 4.0 rad: the
    FR3's (to 4.5205), past the Panda's (3.7525): the other way round."""
    near_stop = _stroke([0.0, 0.0, 0.0, -1.5, 0.0, 2.0, 0.0], 0, 2.8, 4.0)
    high_wrist = _stroke([0.0, 0.0, 0.0, -1.5, 0.0, 2.0, 0.0], 5, 2.0, 4.0)
    assert _inside(near_stop[-1], PANDA_RANGE) and not _inside(near_stop[-1], FR3_RANGE)
    assert _inside(high_wrist[-1], FR3_RANGE) and not _inside(high_wrist[-1], PANDA_RANGE)
    for commands, accepted_by in ((near_stop, "panda"), (high_wrist, "fr3")):
        for robot in ("panda", "fr3"):
            names = [f"{robot}_joint{k}" for k in range(1, 8)]
            path = _write(tmp_path / f"{robot}_{accepted_by}.csv", commands, names)
            code = main(["verify", str(path), "--robot", robot])
            out = capsys.readouterr().out
            assert code == (0 if robot == accepted_by else 3), (robot, accepted_by, out)


@pytest.mark.parametrize("order", [(5, 0, 3, 1, 6, 2, 4), (6, 5, 4, 3, 2, 1, 0)])
def test_joint_columns_in_another_order_are_read_by_name(tmp_path, capsys, order):
    """The FR3's motion with its columns shuffled: accepted as written in order. Read by column
    position, joint 6's column would hold another joint's angle (0.0 or -2.0 rad, outside its
    0.54-4.52 range) and the motion would be rejected."""
    start = np.array([0.3, -0.4, 0.1, -2.0, 0.0, 1.9, 0.8])
    commands = _stroke(start, 2, 0.3)
    names = [f"fr3_joint{k}" for k in range(1, 8)]
    assert not _inside(commands[0][list(order)], FR3_RANGE)  # by position: outside
    path = _write(tmp_path / "shuffled.csv", commands, names, order)
    assert main(["verify", str(path), "--robot", "fr3"]) == 0, capsys.readouterr()


def test_any_rejected_file_fails_the_command_wherever_it_stands(tmp_path, capsys):
    start = np.array([0.3, -0.4, 0.1, -2.0, 0.0, 1.9, 0.8])
    names = [f"fr3_joint{k}" for k in range(1, 8)]
    good = _write(tmp_path / "good.csv", _stroke(start, 2, 0.3), names)
    fast = _write(tmp_path / "fast.csv", _stroke(start, 2, 3.0, 0.5), names)  # 11 rad/s
    for files, code in (([good, good], 0), ([fast, good], 3), ([good, fast], 3), ([fast], 3)):
        assert main(["verify", *map(str, files), "--robot", "fr3"]) == code
        capsys.readouterr()


def test_every_file_of_a_run_is_checked_against_its_manifest(tmp_path, capsys):
    """Two command files of one run, then a stale one planted beside them: refused by name
    whichever place it has in the list, before anything is judged."""
    from bidmp.io.runs import run_folder

    start = np.array([0.3, -0.4, 0.1, -2.0, 0.0, 1.9, 0.8])
    names = [f"fr3_joint{k}" for k in range(1, 8)]
    with run_folder(tmp_path / "job", "bidmp test") as run:
        folder = Path(run.path) / "commands"
        folder.mkdir()
        for k in (1, 2):
            _write(folder / f"00{k}_3_approach.csv", _stroke(start, k, 0.2), names)
    files = sorted((tmp_path / "job" / "commands").glob("*.csv"))
    assert main(["verify", *map(str, files), "--robot", "fr3"]) == 0
    capsys.readouterr()
    stale = _write(
        tmp_path / "job" / "commands" / "000_9_approach.csv", _stroke(start, 3, 0.2), names
    )
    for listed in ([stale, *files], [*files, stale], [files[0], stale, files[1]]):
        assert main(["verify", *map(str, listed), "--robot", "fr3"]) == 2
        err = capsys.readouterr().err
        assert "000_9_approach.csv" in err, err
