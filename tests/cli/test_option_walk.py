"""No option is silently ignored: every ``bidmp rollout`` option on every kind of model either acts
(the written motion, bag or figure differs from the run without it) or is refused in one line
naming it. The walk found ``--rate`` ignored by a ``--multi`` model and ``--via`` by a ProMP.

Each option is given a value other than its default, with what it needs beside it (a bag for the
bag's options, a scene for ``--target-label``, a cap for ``--fastest``); its run is compared with
the run that has only what it needs. What "acts" means is the output alone: this test does not
say the option acts *right* (the option's own tests do), only that it is never dropped unread.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import numpy as np
import pytest

from bidmp.cli import main
from bidmp.demonstrations import lasa, minimum_jerk
from bidmp.io import save_poses, save_trajectory

STAMP = ["--stamp", "1700000000"]


def _text(values) -> list[str]:
    return [f"{float(v):.6g}" for v in values]


class Kind:
    """A saved model of one kind and the values its options take."""

    def __init__(self, name, model, goal, start, dims, speed, via=None):
        self.name, self.model, self.goal, self.start, self.dims = name, model, goal, start, dims
        self.speed = speed  # its motion's peak speed, to set caps below and above it
        self.via = goal if via is None else via  # a point to pass at 0.5 s


@pytest.fixture(scope="module")
def kinds(tmp_path_factory):
    """One model per kind, fitted by the command line from files written here."""
    folder = tmp_path_factory.mktemp("kinds")
    out: dict[str, Kind] = {}

    def fit(argv):
        assert main(argv) == 0, argv

    t = np.linspace(0.0, 3.0, 300)
    positions = minimum_jerk([[-80, -120, 200], [0, 0, 40], [0, 0, 0]], 300)
    save_trajectory(positions, folder / "pos.csv", t, units="mm")
    fit(["fit", str(folder / "pos.csv"), "--units", "mm", "-o", str(folder / "dmp.npz")])
    out["dmp"] = Kind("dmp", folder / "dmp.npz", [20, 10, 0], [-70, -110, 190], 3, 150.0)
    fit(["extend", str(folder / "dmp.npz"), str(folder / "pos.csv"), "--units", "mm",
         "--target", "120", "0", "0", "-o", str(folder / "bidmp.npz")])  # fmt: skip
    out["bidmp"] = Kind("bidmp", folder / "bidmp.npz", [110, 5, 0], [-70, -110, 190], 3, 150.0)

    down = np.array([1.0, 0.0, 0.0, 0.0])
    turned = np.array([np.sin(np.pi / 2 - 0.2), 0.0, 0.0, np.cos(np.pi / 2 - 0.2)])
    s = np.linspace(0, 1, 300)[:, None]
    quats = (1 - s) * down + s * turned
    quats /= np.linalg.norm(quats, axis=1, keepdims=True)
    save_poses(np.hstack([positions, quats]), folder / "pose.csv", t, units="mm")
    fit(["fit", str(folder / "pose.csv"), "--units", "mm", "-o", str(folder / "pose.npz")])
    out["pose"] = Kind(
        "pose", folder / "pose.npz", [20, 10, 0, *turned], [-70, -110, 190, *down], 7, 150.0
    )

    rest = np.array([0.0, -0.785, 0.0, -2.356, 0.0, 1.571, 0.785])
    # fast enough for the Panda's joint limits to slow it (--joint-limits must bind to act)
    joints = rest + minimum_jerk([np.zeros(7), np.linspace(0.5, 2.5, 7)], 300) * 1.0
    t_joints = np.linspace(0.0, 1.2, 300)
    names = [f"panda_joint{i}" for i in range(1, 8)]
    header = "t," + ",".join(names)
    np.savetxt(folder / "joints.csv", np.column_stack([t_joints, joints]), delimiter=",",
               header=header, comments="")  # fmt: skip
    fit(["fit", str(folder / "joints.csv"), "-o", str(folder / "joints.npz")])
    out["joints"] = Kind(
        "joints", folder / "joints.npz", joints[-1] + 0.05, joints[0] + 0.02, 7, 4.0,
        via=joints[125] + 0.02,
    )  # fmt: skip

    periodic_t = np.linspace(0.0, 6.0, 600)
    circle = np.column_stack(
        [30 * np.cos(2 * np.pi * 0.8 * periodic_t), 20 * np.sin(2 * np.pi * 0.8 * periodic_t)]
    )
    save_trajectory(circle, folder / "circle.csv", periodic_t, units="mm")
    fit(["fit", str(folder / "circle.csv"), "--periodic", "--units", "mm",
         "-o", str(folder / "rhythm.npz")])  # fmt: skip
    out["rhythmic"] = Kind("rhythmic", folder / "rhythm.npz", [5, 5], [30, 0], 2, 150.0)

    demos = lasa("Sshape")[:3]
    paths = []
    for index, demo in enumerate(demos):
        path = folder / f"s{index}.csv"
        save_trajectory(demo, path, np.linspace(0, 2.0 + 0.2 * index, len(demo)), units="mm")
        paths.append(str(path))
    for flag in ("multi", "promp", "prodmp"):
        fit(
            [
                "fit",
                f"--{flag}",
                *paths,
                "--units",
                "mm",
                "--raw",
                "-o",
                str(folder / f"{flag}.npz"),
            ]
        )
        mean = demos.mean(axis=0)
        out[flag] = Kind(
            flag, folder / f"{flag}.npz", mean[-1] + [4, -3], mean[0] + [2, 2], 2, 50.0
        )
    return out


def option_runs(kind: Kind) -> dict[str, tuple[list, list]]:
    """Each option's arguments and what it needs beside it (its baseline)."""
    bag = ["--bag", "@/out.bag"]  # "@/": the run's own folder
    scene = ["--scene", "nut-unscrewing"]
    return {
        "--goal": (["--goal", *_text(kind.goal)], []),
        "--start": (["--start", *_text(kind.start)], []),
        "--duration": (["--duration", "4.5"], []),
        "--rate": (["--rate", "250"], []),
        "--n-steps": (["--n-steps", "77"], []),
        "--max-speed": (["--max-speed", f"{kind.speed / 4:g}"], []),
        "--max-acc": (["--max-acc", f"{kind.speed / 10:g}"], []),
        "--max-jerk": (["--max-jerk", f"{kind.speed / 40:g}"], []),
        "--joint-limits": (["--joint-limits", "panda"], []),
        "--fastest": (["--fastest"], ["--max-speed", f"{kind.speed * 2:g}"]),
        "--robot": (["--robot", "iiwa"], []),
        "--cartesian-goal": (["--cartesian-goal", "0.5", "0.05", "0.3"], []),
        "--tool-length": (["--tool-length", "0.1"], ["--cartesian-goal", "0.5", "0.05", "0.3"]),
        "--base": (["--base", "0.1", "0", "0"], ["--cartesian-goal", "0.5", "0.05", "0.3"]),
        "--yaw": (["--yaw", "30"], ["--cartesian-goal", "0.5", "0.05", "0.3"]),
        "--skill": (["--skill", "0"], []),
        "--plot": (["--plot", "@/figure.png"], []),
        "--cycles": (["--cycles", "2"], []),
        "--frequency": (["--frequency", "0.5"], []),
        "--amplitude": (["--amplitude", "0.5"], []),
        "--anchor": (["--anchor", *_text(kind.start)], []),
        "--from-rest": (["--from-rest"], []),
        "--via": (["--via", "0.5", *_text(kind.via)], []),
        "--scene": (scene, []),
        "--avoid": (["--avoid"], []),
        "--no-avoid": (["--no-avoid"], scene),
        "--target-label": (["--target-label", "4"], scene),
        "--bag": (bag, STAMP),
        "--ros1": (["--ros1"], bag + STAMP),
        "--frame": (["--frame", "world"], bag + STAMP),
        "--bag-topic": (["--bag-topic", "/walk"], bag + STAMP),
        "--stamp": (["--stamp", "1700000500"], bag + STAMP),
        "--orientation": (["--orientation", "0", "1", "0", "0"], bag + STAMP),
        "--follow": (["--follow"], bag + STAMP),
    }


def _outputs(folder: Path) -> str:
    """A digest of everything a run wrote (the motion, the bag, the figure), by name and bytes."""
    digest = hashlib.sha256()
    for path in sorted(folder.rglob("*")):
        if path.is_file():
            digest.update(str(path.relative_to(folder)).encode())
            digest.update(path.read_bytes())
    return digest.hexdigest()


def _run(kind: Kind, extra: list, folder: Path, capsys) -> tuple[int, str, str]:
    import shutil

    shutil.rmtree(folder, ignore_errors=True)
    folder.mkdir(parents=True)
    extra = [str(folder / arg[2:]) if arg.startswith("@/") else arg for arg in extra]
    code = main(["rollout", str(kind.model), *extra, "-o", str(folder / "motion.csv")])
    err = capsys.readouterr().err
    return code, _outputs(folder) if code == 0 else "", err


def test_the_rollout_parser_has_no_option_the_walk_does_not_take():
    """Structure guard: a new rollout option joins the walk."""
    import argparse

    from bidmp.cli.rollout import _add_rollout_arguments

    parser = argparse.ArgumentParser()
    _add_rollout_arguments(parser)
    flags = {
        option
        for action in parser._actions
        for option in action.option_strings
        if option.startswith("--") and option not in ("--help", "--output")
    }
    walked = set(option_runs(Kind("x", "m", [0], [0], 1, 1.0)))
    assert flags == walked, flags ^ walked


@pytest.mark.parametrize(
    "kind_name", ["dmp", "bidmp", "pose", "joints", "rhythmic", "multi", "promp", "prodmp"]
)
def test_every_option_acts_or_is_refused_on_every_kind(kinds, kind_name, tmp_path, capsys):
    kind = kinds[kind_name]
    ignored, broken = [], []
    baselines: dict[tuple, tuple] = {}
    for option, (given, needs) in option_runs(kind).items():
        key = tuple(needs)
        if key not in baselines:
            baselines[key] = _run(kind, needs, tmp_path / "base", capsys)
        base_code, base_out, base_err = baselines[key]
        code, out, err = _run(kind, needs + given, tmp_path / "run", capsys)
        lines = err.strip().splitlines()
        if code == 0:
            if base_code != 0:
                continue  # what it needs is refused without it, and it is taken with it: it acts
            if out == base_out:
                ignored.append(option)
        elif not (code == 2 and len(lines) == 1 and option in lines[0]):
            if base_code != 0 and code == 2 and len(lines) == 1:
                continue  # refused for what it needs (that option's own row says why)
            broken.append(f"{option}: exit {code}, {err.strip()[:300]}")
    assert not ignored, f"{kind_name}: silently ignored: {ignored}"
    assert not broken, f"{kind_name}: neither acts nor refused in one line naming it: {broken}"
