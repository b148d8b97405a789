"""A command's output folder is one run (bidmp.io.runs through the commands): an earlier run's
files never survive beside a new one's, a failure or a kill at the worst instant leaves exactly one
run (old or new), two runs into one folder never mix, and `bidmp verify` refuses a command file
its run did not write.

Every check reads the folder itself: each file's SHA-256 computed here against the manifest,
the files on disk against the files it lists, the job's own JSON against the command that ran."""

import errno
import hashlib
import json
import os
import shutil
import signal
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from bidmp.cli import main
from bidmp.io import run_folder

pytest.importorskip("pybullet")

KINEMATIC_JOB = ["job", "--backend", "kinematic", "--no-pictures"]


def one_run(folder: Path) -> dict:
    """Assert ``folder`` is exactly one run: every file on disk listed in its manifest with the
    SHA-256 and size computed here, every listed file there; returns the manifest."""
    manifest = json.loads((folder / "manifest.json").read_text())
    listed = {entry["name"]: (entry["bytes"], entry["sha256"]) for entry in manifest["files"]}
    found = {}
    for root, _, files in os.walk(folder):
        for name in files:
            path = Path(root) / name
            relative = path.relative_to(folder).as_posix()
            if relative != "manifest.json":
                data = path.read_bytes()
                found[relative] = (len(data), hashlib.sha256(data).hexdigest())
    assert found == listed
    return manifest


def job_targets(folder: Path) -> list:
    return [
        target["target"]
        for target in json.loads((folder / "job_results.json").read_text())["targets"]
    ]


@pytest.fixture(scope="module")
def commands_run(tmp_path_factory):
    """A finished `bidmp job --commands` run of target 3 (the earlier run of the tests below)."""
    out = tmp_path_factory.mktemp("earlier") / "job"
    assert main(["job", "--targets", "3", "--no-pictures", "--commands", "--out", str(out)]) == 0
    return out


def copy_run(run: Path, tmp_path: Path) -> Path:
    shutil.copytree(run, tmp_path / "job")
    return tmp_path / "job"


def test_a_new_job_leaves_no_command_of_the_earlier_one_and_verify_refuses_a_planted_one(
    commands_run, tmp_path, capsys, monkeypatch
):
    """The campaign's finding: a second `job --commands` into the same folder left the first
    run's command files beside its own, and verify accepted them all. Now the folder holds the
    new run's only, verify accepts exactly those, and an old one put back is refused by name."""
    monkeypatch.chdir(tmp_path)
    out = copy_run(commands_run, tmp_path)
    earlier = {path.name: path.read_bytes() for path in (out / "commands").iterdir()}
    assert main(["job", "--targets", "11", "--no-pictures", "--commands", "--out", "job"]) == 0
    manifest = one_run(out)
    names = sorted(path.name for path in (out / "commands").iterdir())
    assert names and all("_11_" in name for name in names) and job_targets(out) == ["11"]
    assert "--targets 11" in manifest["command"]
    capsys.readouterr()
    files = sorted(str(Path("job/commands") / name) for name in names)
    assert main(["verify", *files, "--robot", "panda"]) == 0
    assert f"{len(names)} of {len(names)} motions accepted" in capsys.readouterr().out
    stale = sorted(earlier)[0]
    (out / "commands" / stale).write_bytes(earlier[stale])
    assert (
        main(["verify", *sorted(map(str, Path("job/commands").iterdir())), "--robot", "panda"]) == 2
    )
    err = capsys.readouterr().err.strip()
    assert err == (
        f"bidmp verify: error: job/commands/{stale}: not a file of the run in job "
        f"(job/manifest.json does not list it: left by an earlier run, or put there since); "
        f"run the command again"
    )


KILL = textwrap.dedent("""
    import os, signal, stat, sys
    from bidmp.io import runs
    point = sys.argv[1]
    real_exchange, real_fsync = runs._exchange, os.fsync
    def exchange(first, second):
        if point == "before-swap":
            os.kill(os.getpid(), signal.SIGKILL)
        done = real_exchange(first, second)
        if point == "after-swap":
            os.kill(os.getpid(), signal.SIGKILL)
        return done
    written = []
    def fsync(fd):
        if stat.S_ISREG(os.fstat(fd).st_mode):
            written.append(fd)
            if point == "mid-write" and len(written) == 2:  # the second file, half done
                os.kill(os.getpid(), signal.SIGKILL)
        real_fsync(fd)
    runs._exchange, os.fsync = exchange, fsync
    from bidmp.cli import main
    sys.exit(main(sys.argv[2:]))
""")


def killed(point: str, argv: list, cwd: Path) -> None:
    done = subprocess.run(
        [sys.executable, "-c", KILL, point, *argv],
        cwd=cwd,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == -signal.SIGKILL, done.stderr[-2000:]


@pytest.mark.parametrize("point", ["mid-write", "after-swap"])
def test_a_job_killed_at_the_worst_instant_leaves_exactly_one_run(point, tmp_path):
    """SIGKILL while the new run's second file is written, and right after the swap (the earlier
    run not yet deleted): the folder is exactly the earlier run, or exactly the new one."""
    out = tmp_path / "job"
    assert main([*KINEMATIC_JOB, "--targets", "3", "--out", str(out)]) == 0
    earlier = one_run(out)
    killed(point, [*KINEMATIC_JOB, "--targets", "11", "--out", "job"], tmp_path)
    manifest = one_run(out)
    if point == "mid-write":
        assert manifest == earlier and job_targets(out) == ["3"]
    else:
        assert manifest["run"] != earlier["run"] and job_targets(out) == ["11"]
    # what the killed run left beside it (its new or old folder, its lock) the next run clears
    assert len(list(tmp_path.iterdir())) > 1
    with pytest.raises(RuntimeError), run_folder(out, "bidmp next"):
        raise RuntimeError("nothing to write")
    assert sorted(path.name for path in tmp_path.iterdir()) == ["job"] and one_run(out) == manifest


def test_a_job_killed_right_before_its_swap_keeps_every_command_of_the_earlier_run(
    commands_run, tmp_path, capsys, monkeypatch
):
    """Killed with the new run's commands complete beside the folder, the instant before the
    swap: the folder is the earlier run, every command file its own, and verify accepts them."""
    monkeypatch.chdir(tmp_path)
    out = copy_run(commands_run, tmp_path)
    earlier = one_run(out)
    killed(
        "before-swap",
        ["job", "--targets", "11", "--no-pictures", "--commands", "--out", "job"],
        tmp_path,
    )
    assert one_run(out) == earlier and job_targets(out) == ["3"]
    files = sorted(map(str, Path("job/commands").iterdir()))
    assert all("_3_" in name for name in files)
    assert main(["verify", *files, "--robot", "panda"]) == 0
    assert f"{len(files)} of {len(files)} motions accepted" in capsys.readouterr().out


def test_two_jobs_started_together_into_one_folder_never_mix(tmp_path):
    """Two processes write one folder at once: one writes it, the other (if they overlap) is
    refused at once naming the folder; the folder is exactly the run that wrote it."""
    argv = [sys.executable, "-m", "bidmp", *KINEMATIC_JOB, "--out", "job"]
    runs = [
        subprocess.Popen(
            [*argv, "--targets", target],
            cwd=tmp_path,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.PIPE,
            text=True,
        )
        for target in ("3", "11")
    ]
    results = [(run.wait(timeout=300), run.stderr.read()) for run in runs]
    for run in runs:
        run.stderr.close()
    assert 0 in [code for code, _ in results]
    for code, err in results:
        assert code == 0 or (
            code == 2
            and "job is being written by another bidmp command" in err.strip().splitlines()[-1]
        ), err[-2000:]
    manifest = one_run(tmp_path / "job")
    (target,) = job_targets(tmp_path / "job")
    assert f"--targets {target}" in manifest["command"]
    assert sorted(path.name for path in tmp_path.iterdir()) == ["job"]


def test_a_full_disk_midway_through_clfd_replaces_nothing_and_says_so(
    tmp_path, capsys, monkeypatch
):
    """The campaign's finding: on a full disk `benchmark clfd` said "nothing was replaced" after
    replacing clfd.json and clfd.md. The third file's write fails (ENOSPC from the file's fsync):
    the folder is byte for byte the earlier run and the one error line says exactly that."""
    monkeypatch.chdir(tmp_path)
    # the earlier run: any run folder will do (the one under test is the second)
    with run_folder("clfd", "bidmp benchmark clfd --out clfd") as earlier:
        for name in ("clfd.json", "clfd.md", "clfd_accuracy.png", "clfd_dtw.png"):
            (earlier.path / name).write_text(f"the earlier {name}")
    argv = ["benchmark", "clfd", "--tasks", "1", "--methods", "dmp-library", "--out", "clfd"]
    before = {path.name: path.read_bytes() for path in Path("clfd").iterdir()}
    earlier = one_run(Path("clfd"))
    capsys.readouterr()
    written, real_fsync = [], os.fsync

    def fsync(fd):
        if stat.S_ISREG(os.fstat(fd).st_mode):
            written.append(fd)
            if len(written) == 3:
                raise OSError(errno.ENOSPC, "No space left on device")
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    assert main(argv) == 2
    monkeypatch.setattr(os, "fsync", real_fsync)
    err = capsys.readouterr().err.strip()
    assert err == (
        "bidmp benchmark: error: cannot write clfd/clfd_accuracy.png (No space left on "
        f"device); no file of this run was kept: clfd still holds the earlier run, unchanged "
        f"({len(earlier['files'])} files of '{earlier['command']}')"
    )
    assert {path.name: path.read_bytes() for path in Path("clfd").iterdir()} == before
    assert sorted(path.name for path in tmp_path.iterdir()) == ["clfd"]


def test_a_folder_that_is_not_a_run_is_refused_before_any_work(tmp_path, capsys):
    """A folder of bidmp 0.5's outputs (no manifest) or of a user's files: one line naming it and
    the way out; nothing in it changes, nothing runs."""
    out = tmp_path / "old"
    out.mkdir()
    (out / "job_results.json").write_text("{}")
    assert main([*KINEMATIC_JOB, "--targets", "3", "--out", str(out)]) == 2
    captured = capsys.readouterr()
    assert "not a bidmp run" in captured.err and "--overwrite" in captured.err
    assert "parts removed" not in captured.out  # the job never ran
    assert [path.name for path in out.iterdir()] == ["job_results.json"]


LASA = ["benchmark", "lasa", "--shapes", "Sshape", "--demos", "first3", "--every", "50"]
LASA += ["--methods", "dmp-paper", "--workers", "1", "--format", "csv"]


def test_an_interrupted_lasa_benchmark_resumes_from_its_partial_run(tmp_path, capsys, monkeypatch):
    """Interrupted (Ctrl-C) after two of three cells: the output folder is untouched (here: not
    made), the partial run beside it holds the two; --resume computes the third only, and the
    finished run is one run with all three; --resume over a finished run computes none."""
    from bidmp.experiments import benchmark

    out, real = tmp_path / "lasa", benchmark._write_cell

    def write_cell(*args):
        real(*args)
        if len(os.listdir(args[0] / "cells")) == 2:
            raise KeyboardInterrupt

    monkeypatch.setattr(benchmark, "_write_cell", write_cell)
    assert main([*LASA, "--out", str(out)]) == 130
    monkeypatch.setattr(benchmark, "_write_cell", real)
    assert not out.exists()
    assert len(list((tmp_path / ".lasa.bidmp-partial" / "cells").iterdir())) == 2
    capsys.readouterr()
    assert main([*LASA, "--out", str(out), "--resume"]) == 0
    assert "1 cells computed, 2 resumed" in capsys.readouterr().out
    manifest = one_run(out)
    assert sorted(entry["name"] for entry in manifest["files"]) == [
        "cells/Sshape__0.json",
        "cells/Sshape__1.json",
        "cells/Sshape__2.json",
        "lasa.csv",
        "lasa.md",
        "lasa_metrics.png",
        "lasa_shapes.png",
    ]
    assert main([*LASA, "--out", str(out), "--resume"]) == 0
    assert "0 cells computed, 3 resumed" in capsys.readouterr().out
    assert sorted(path.name for path in tmp_path.iterdir()) == ["lasa"]
    assert one_run(out)["files"] == manifest["files"]


def test_a_rollout_whose_plot_fails_keeps_its_earlier_motion_file(tmp_path, capsys, monkeypatch):
    """`bidmp rollout -o r.csv --plot r.png`: -o was written before the figure failed (a full
    disk), a new motion beside an old figure. Now neither is replaced and the line says so."""
    import numpy as np

    import bidmp

    monkeypatch.chdir(tmp_path)
    demo = np.linspace([0.0, 0.0], [1.0, 2.0], 50) + np.sin(np.linspace(0, 3, 50))[:, None]
    bidmp.save(bidmp.DMP(n_kernels=10).fit(demo), "m.npz")
    assert main(["rollout", "m.npz", "--goal", "1", "2", "-o", "r.csv", "--plot", "r.png"]) == 0
    before = {name: Path(name).read_bytes() for name in ("r.csv", "r.png")}
    capsys.readouterr()
    written, real_fsync = [], os.fsync

    def fsync(fd):
        if stat.S_ISREG(os.fstat(fd).st_mode):
            written.append(fd)
            if len(written) == 2:
                raise OSError(errno.ENOSPC, "No space left on device")
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    assert main(["rollout", "m.npz", "--goal", "3", "1", "-o", "r.csv", "--plot", "r.png"]) == 2
    monkeypatch.setattr(os, "fsync", real_fsync)
    assert capsys.readouterr().err.strip() == (
        "bidmp rollout: error: cannot write r.png (No space left on device); none of r.csv, "
        "r.png was replaced"
    )
    assert {name: Path(name).read_bytes() for name in ("r.csv", "r.png")} == before
    assert sorted(path.name for path in tmp_path.iterdir()) == ["m.npz", "r.csv", "r.png"]
