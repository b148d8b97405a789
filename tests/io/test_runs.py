"""Run folders (bidmp.io.runs): a folder is one run, whole, or the one before it.

The oracle of every check is the folder itself as the test reads it: its files' bytes hashed by the
test's own hashlib, set against what the test wrote, never the manifest's word alone."""

import errno
import hashlib
import json
import os
import stat
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from bidmp.io import atomic_write
from bidmp.io import runs as runs_module
from bidmp.io.runs import (
    MANIFEST,
    RunManifest,
    check_run_files,
    output_files,
    read_manifest,
    run_folder,
    update_manifest,
)


def snapshot(folder) -> dict:
    """Every file under ``folder``: relative name -> bytes (the manifest included)."""
    found = {}
    for root, _, files in os.walk(folder):
        for name in files:
            path = os.path.join(root, name)
            with open(path, "rb") as handle:
                found[os.path.relpath(path, folder).replace(os.sep, "/")] = handle.read()
    return found


def write_run(out, files: dict, command: str = "bidmp test", **options):
    """A run of ``files`` (name -> bytes) into ``out``, each written atomically as commands do."""
    with run_folder(out, command, **options) as run:
        for name, data in files.items():
            path = run.path / name
            path.parent.mkdir(parents=True, exist_ok=True)
            with atomic_write(path, "wb") as handle:
                handle.write(data)
    return run


def assert_exactly(out, files: dict) -> dict:
    """``out`` holds exactly ``files`` and its manifest, which lists each with the hash the test
    computes; returns the manifest as read back."""
    found = snapshot(out)
    manifest = json.loads(found.pop(MANIFEST))
    assert found == files
    listed = {entry["name"]: (entry["bytes"], entry["sha256"]) for entry in manifest["files"]}
    assert listed == {
        name: (len(data), hashlib.sha256(data).hexdigest()) for name, data in files.items()
    }
    return manifest


def assert_no_leftovers(parent, *names):
    """Beside the run folders, nothing: no new, old, partial folder nor lock file."""
    assert sorted(p.name for p in parent.iterdir()) == sorted(names)


NAMES = st.lists(
    st.lists(st.sampled_from(["a", "b", "c.csv", "d.png", "sub", "x-1"]), min_size=1, max_size=3),
    min_size=1,
    max_size=6,
)


def _files(paths, seed: int) -> dict:
    """Names from path parts (a name never both a file and a folder), each with its own bytes."""
    files = {}
    for index, parts in enumerate(paths):
        name = "/".join(parts[:-1] + [f"f{index}_{parts[-1]}"])
        files[name] = f"{seed}:{name}".encode() * (index + 1)
    return files


@settings(
    max_examples=15, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(old=NAMES, new=NAMES)
def test_a_new_run_replaces_the_old_one_whole(tmp_path_factory, old, new):
    """Runs of random nested files one after the other: the folder holds exactly the last run's
    files, each listed with its SHA-256; none of the earlier run's survives beside it."""
    parent = tmp_path_factory.mktemp("runs")
    out = parent / "out"
    first, second = _files(old, 1), _files(new, 2)
    write_run(out, first)
    earlier = assert_exactly(out, first)
    write_run(out, second)
    assert assert_exactly(out, second)["run"] != earlier["run"]
    assert_no_leftovers(parent, "out")


def test_the_manifest_names_the_run_and_its_command(tmp_path):
    run = write_run(tmp_path / "o", {"a.json": b"{}"}, command="bidmp job --targets 3")
    manifest = read_manifest(tmp_path / "o")
    assert manifest.command == "bidmp job --targets 3" and manifest.run == run.manifest.run
    assert len(manifest.run) == 32 and manifest.files == {
        "a.json": (2, hashlib.sha256(b"{}").hexdigest())
    }


def test_a_failed_run_leaves_the_earlier_one_byte_for_byte(tmp_path):
    out = tmp_path / "o"
    write_run(out, {"keep.md": b"old", "sub/old.csv": b"1,2"})
    before = snapshot(out)
    with pytest.raises(RuntimeError, match="midway"):
        with run_folder(out, "bidmp test") as run:
            (run.path / "keep.md").write_bytes(b"new")
            raise RuntimeError("midway")
    assert snapshot(out) == before
    assert_no_leftovers(tmp_path, "o")


@pytest.mark.parametrize("earlier", ["run", "none", "empty"])
def test_a_full_disk_midway_says_what_was_and_was_not_replaced(tmp_path, monkeypatch, earlier):
    """The third file's write fails with ENOSPC (a patched fsync, where a full disk fails):
    the error names that file where it was going and says the folder holds the earlier run, and
    the folder is byte for byte that run (or was not made)."""
    monkeypatch.chdir(tmp_path)  # the paths as a user gives them, in the messages whole
    out = Path("o")
    if earlier == "run":
        write_run(out, {"a.json": b"old a", "z.png": b"old z"}, command="bidmp old")
    elif earlier == "empty":
        out.mkdir()
    before = snapshot(out) if out.exists() else None
    calls = []
    real_fsync = os.fsync

    def fsync(fd):
        if stat.S_ISREG(os.fstat(fd).st_mode):  # a file's, not a folder's
            calls.append(fd)
        if len(calls) == 3:
            raise OSError(errno.ENOSPC, "No space left on device")
        real_fsync(fd)

    monkeypatch.setattr(runs_module.os, "fsync", fsync)
    with pytest.raises(OSError) as caught:
        write_run(out, {"a.json": b"new a", "b.md": b"new b", "c.png": b"new c", "d": b"d"})
    monkeypatch.setattr(runs_module.os, "fsync", real_fsync)
    message = str(caught.value.strerror)
    assert caught.value.errno == errno.ENOSPC
    assert f"cannot write {out / 'c.png'} (No space left on device)" in message
    assert "no file of this run was kept" in message
    assert {
        "run": f"{out} still holds the earlier run, unchanged (2 files of 'bidmp old')",
        "none": f"{out} was not written",
        "empty": f"{out} is as it was",
    }[earlier] in message
    assert "nothing was replaced" not in message and ".bidmp-new-" not in message
    assert (snapshot(out) if out.exists() else None) == before
    assert_no_leftovers(tmp_path, *([] if earlier == "none" else ["o"]))


def test_an_oserror_with_a_file_name_is_shown_where_the_file_was_going(tmp_path):
    out = tmp_path / "o"
    with pytest.raises(OSError, match=r"cannot write .*o/deep/x.bin \(No space left on device\)"):
        with run_folder(out, "bidmp test") as run:
            raise OSError(errno.ENOSPC, "No space left on device", str(run.path / "deep/x.bin"))


def test_a_folder_of_someone_elses_files_is_refused_unless_overwrite(tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "notes.txt").write_text("mine")
    with pytest.raises(ValueError, match=r"not a bidmp run .*--overwrite"):
        write_run(out, {"a": b"1"})
    assert snapshot(out) == {"notes.txt": b"mine"}
    write_run(out, {"a": b"1"}, overwrite=True)
    assert_exactly(out, {"a": b"1"})
    assert_no_leftovers(tmp_path, "mine")


def test_a_file_added_to_a_run_folder_is_refused_by_name(tmp_path):
    out = tmp_path / "o"
    write_run(out, {"a": b"1", "sub/b": b"2"})
    (out / "sub" / "mine.txt").write_text("keep me")
    (out / "other.txt").write_text("and me")
    with pytest.raises(ValueError, match=r"holds other.txt and 1 more, which its run"):
        write_run(out, {"a": b"new"})
    assert snapshot(out)["sub/mine.txt"] == b"keep me"


def test_an_empty_folder_is_taken_and_a_file_is_refused(tmp_path):
    (tmp_path / "empty").mkdir()
    write_run(tmp_path / "empty", {"a": b"1"})
    assert_exactly(tmp_path / "empty", {"a": b"1"})
    (tmp_path / "f").write_text("x")
    with pytest.raises(ValueError, match="is a file, not a folder"):
        write_run(tmp_path / "f", {"a": b"1"})


def test_the_folder_you_are_in_is_refused(tmp_path, monkeypatch):
    (tmp_path / "inner").mkdir()
    monkeypatch.chdir(tmp_path / "inner")
    for out in (".", tmp_path, tmp_path / "inner"):
        with pytest.raises(ValueError, match="the folder you are in"):
            write_run(out, {"a": b"1"})


def test_a_second_writer_of_the_same_folder_is_refused_at_once(tmp_path):
    out = tmp_path / "o"
    with run_folder(out, "bidmp first") as run:
        (run.path / "a").write_bytes(b"1")
        with pytest.raises(
            ValueError, match=rf"being written by another bidmp command \(process {os.getpid()}\)"
        ):
            write_run(out, {"b": b"2"})
    assert_exactly(out, {"a": b"1"})
    assert_no_leftovers(tmp_path, "o")


def test_a_symlink_is_written_through(tmp_path):
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    write_run(tmp_path / "link", {"a": b"1"})
    write_run(tmp_path / "link", {"b": b"2"})
    assert (tmp_path / "link").is_symlink()
    assert_exactly(tmp_path / "real", {"b": b"2"})


def test_without_an_atomic_exchange_the_result_is_the_same(tmp_path, monkeypatch):
    """Where the system cannot exchange two folders (two renames instead)."""
    monkeypatch.setattr(runs_module, "_exchange", lambda first, second: False)
    out = tmp_path / "o"
    write_run(out, {"a": b"1", "s/b": b"2"})
    write_run(out, {"c": b"3"})
    assert_exactly(out, {"c": b"3"})
    assert_no_leftovers(tmp_path, "o")


KILL_BETWEEN_RENAMES = textwrap.dedent("""
    import os, signal, sys
    from bidmp.io import runs
    runs._exchange = lambda first, second: False
    real = os.rename
    def rename(source, target):
        real(source, target)
        if ".bidmp-old-" in str(target):  # the earlier run moved aside, the new not yet in
            os.kill(os.getpid(), signal.SIGKILL)
    os.rename = rename
    with runs.run_folder(sys.argv[1], "bidmp killed") as run:
        (run.path / "new").write_bytes(b"new")
""")


def test_a_run_killed_between_the_two_renames_is_put_back_by_the_next(tmp_path):
    """Without an atomic exchange a run killed between moving the earlier run aside and moving
    its own in leaves no folder; the next run into it puts the earlier one back first."""
    out = tmp_path / "o"
    write_run(out, {"old": b"old"})
    before = snapshot(out)
    killed = subprocess.run([sys.executable, "-c", KILL_BETWEEN_RENAMES, str(out)], timeout=120)
    assert killed.returncode == -9
    assert not out.exists()
    with pytest.raises(RuntimeError):
        with run_folder(out, "bidmp next"):
            assert snapshot(out) == before  # put back before the new run writes
            raise RuntimeError("stop")
    assert snapshot(out) == before
    assert_no_leftovers(tmp_path, "o")


def test_check_run_files_refuses_a_file_its_run_did_not_write(tmp_path):
    out = tmp_path / "o"
    write_run(out, {"commands/001.csv": b"1", "commands/002.csv": b"2"})
    listed = [out / "commands/001.csv", out / "commands/002.csv"]
    assert [folder for _, folder, _ in check_run_files(listed)] == [out, out]
    (out / "commands/000_old.csv").write_bytes(b"0")
    with pytest.raises(ValueError, match=r"000_old.csv: not a file of the run in .*does not list"):
        check_run_files([*listed, out / "commands/000_old.csv"])
    (out / "commands/002.csv").write_bytes(b"changed")
    with pytest.raises(ValueError, match=r"002.csv: changed since its run wrote it"):
        check_run_files(listed)
    outside = tmp_path / "loose.csv"
    outside.write_bytes(b"x")
    assert check_run_files([outside]) == [(outside, None, None)]


def test_a_manifest_of_another_tool_is_no_run_and_a_broken_one_is_refused(tmp_path):
    (tmp_path / MANIFEST).write_text('{"name": "a web app"}')
    assert read_manifest(tmp_path) is None
    (tmp_path / MANIFEST).write_text('{"format": "bidmp-run", "version": 1, "files": 3}')
    with pytest.raises(ValueError, match="file list is malformed"):
        read_manifest(tmp_path)
    with pytest.raises(ValueError, match=r"manifest.json is unreadable"):
        write_run(tmp_path, {"a": b"1"})


def test_a_partial_run_is_kept_for_resume_and_cleared_without(tmp_path):
    out = tmp_path / "o"
    with pytest.raises(RuntimeError):
        with run_folder(out, "bidmp long", partial=True) as run:
            (run.path / "cell1").write_bytes(b"1")
            raise RuntimeError("killed")
    partial = tmp_path / ".o.bidmp-partial"
    assert snapshot(partial) == {"cell1": b"1"}
    with run_folder(out, "bidmp long", partial=True, resume=True) as run:
        assert run.path == partial and snapshot(run.path) == {"cell1": b"1"}
        (run.path / "cell2").write_bytes(b"2")
    assert_exactly(out, {"cell1": b"1", "cell2": b"2"})
    assert_no_leftovers(tmp_path, "o")
    with pytest.raises(RuntimeError):
        with run_folder(out, "bidmp long", partial=True) as run:
            (run.path / "cell3").write_bytes(b"3")
            raise RuntimeError("killed")
    with run_folder(out, "bidmp long", partial=True) as run:
        assert snapshot(run.path) == {}  # no resume: a fresh run
    assert_exactly(out, {})


def test_update_manifest_records_a_rewritten_file(tmp_path):
    out = tmp_path / "o"
    write_run(out, {"view.html": b"<p>1</p>", "a": b"1"})
    (out / "view.html").write_bytes(b"<p>2</p>")
    with pytest.raises(ValueError, match="changed since"):
        check_run_files([out / "view.html"])
    update_manifest(out, "view.html")
    assert_exactly(out, {"view.html": b"<p>2</p>", "a": b"1"})
    check_run_files([out / "view.html"])


def test_bad_arguments_are_refused_by_name(tmp_path):
    with pytest.raises(TypeError, match="command"):
        write_run(tmp_path / "o", {}, command="")
    with pytest.raises(ValueError, match="partial"):
        write_run(tmp_path / "o", {}, resume=True)
    with pytest.raises(TypeError, match="out must be a file name"):
        write_run(3, {})
    with pytest.raises(TypeError, match="list of file paths, got str"):
        check_run_files("one.csv")
    with pytest.raises(TypeError, match="paths must be a list of file paths, got int"):
        check_run_files(3)
    with pytest.raises(TypeError, match="run must be text"):
        RunManifest(float("nan"), "bidmp x", "0.6.0")
    with pytest.raises(TypeError, match="files must map"):
        RunManifest("a", "bidmp x", "0.6.0", {"a.csv": (1, "not a hash")})
    with pytest.raises(TypeError, match="name must be a file's name"):
        update_manifest(tmp_path, 3)
    write_run(tmp_path / "r", {"a": b"1"})
    for name in ("../a", "/etc/passwd", "manifest.json", "missing"):
        with pytest.raises(ValueError, match="name"):
            update_manifest(tmp_path / "r", name)


def test_several_outputs_appear_together(tmp_path):
    """Two files at places of the user's choosing: both written beside their places, both put
    in place at the end; nothing else is left."""
    (tmp_path / "sub").mkdir()
    (tmp_path / "a.csv").write_bytes(b"old a")
    with output_files() as outputs:
        first, second = outputs.path(tmp_path / "a.csv"), outputs.path(tmp_path / "sub/b.png")
        first.write_bytes(b"new a")
        assert (tmp_path / "a.csv").read_bytes() == b"old a"  # not yet
        second.write_bytes(b"new b")
        assert outputs.shown(f"wrote {second}") == f"wrote {tmp_path / 'sub/b.png'}"
    assert snapshot(tmp_path) == {"a.csv": b"new a", "sub/b.png": b"new b"}


def test_a_full_disk_at_the_second_output_replaces_neither(tmp_path, monkeypatch):
    """`bidmp rollout -o a.csv --plot a.png`'s case: the second write fails (ENOSPC): the first
    file is the old one, and the message says where the failing one was going and that none of
    the outputs was replaced."""
    monkeypatch.chdir(tmp_path)
    Path("a.csv").write_bytes(b"old a")
    Path("a.png").write_bytes(b"old png")
    calls, real_fsync = [], os.fsync

    def fsync(fd):
        if stat.S_ISREG(os.fstat(fd).st_mode):
            calls.append(fd)
            if len(calls) == 2:
                raise OSError(errno.ENOSPC, "No space left on device")
        real_fsync(fd)

    monkeypatch.setattr(os, "fsync", fsync)
    with pytest.raises(OSError) as caught:
        with output_files() as outputs:
            for name, data in (("a.csv", b"new a"), ("a.png", b"new png")):
                with atomic_write(outputs.path(name), "wb") as handle:
                    handle.write(data)
    monkeypatch.setattr(os, "fsync", real_fsync)
    assert caught.value.strerror == (
        "cannot write a.png (No space left on device); none of a.csv, a.png was replaced"
    )
    assert snapshot(tmp_path) == {"a.csv": b"old a", "a.png": b"old png"}


def test_an_output_is_never_put_in_place_of_a_folder(tmp_path):
    (tmp_path / "taken").mkdir()
    (tmp_path / "a.csv").write_bytes(b"old")
    with pytest.raises(ValueError, match="taken: it is a folder; give a file name"):
        with output_files() as outputs:
            outputs.path(tmp_path / "a.csv").write_bytes(b"new")
            outputs.path(tmp_path / "taken").write_bytes(b"x")
    assert snapshot(tmp_path) == {"a.csv": b"old"}  # checked before any was put in place
    with pytest.raises(ValueError, match="folder .*nowhere does not exist"):
        with output_files() as outputs:
            outputs.path(tmp_path / "nowhere" / "a.csv")


def test_a_bag_folder_is_replaced_by_the_new_bag(tmp_path):
    pytest.importorskip("rosbags")
    import numpy as np

    from bidmp.io import read_bag, write_bag

    t = np.linspace(0.0, 1.0, 11)
    for scale in (1.0, 2.0):
        with output_files() as outputs:
            write_bag(
                outputs.path(tmp_path / "bag"), t, scale * np.c_[t, t, t], kind="pose", origin=0.0
            )
    recording = read_bag(tmp_path / "bag")
    np.testing.assert_allclose(recording.values[-1], [2.0, 2.0, 2.0])
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bag"]


def test_a_failed_run_takes_away_the_folders_it_made(tmp_path):
    """A run into a/b/out (a and b missing) that fails leaves no a; one that succeeds makes them."""
    with pytest.raises(ValueError, match="bad input"):
        with run_folder(tmp_path / "a" / "b" / "out", "bidmp test"):
            raise ValueError("bad input")
    assert list(tmp_path.iterdir()) == []
    write_run(tmp_path / "a" / "b" / "out", {"x": b"1"})
    assert_exactly(tmp_path / "a" / "b" / "out", {"x": b"1"})


def test_a_writer_that_adds_a_suffix_puts_its_own_name_in_place(tmp_path):
    """save_model adds .npz to a name without it: the output is the file it wrote (m.npz), not
    dropped, and the message names it as the user would see it."""
    import numpy as np

    import bidmp

    model = bidmp.DMP(n_kernels=8).fit(np.c_[np.linspace(0, 1, 40), np.sin(np.linspace(0, 3, 40))])
    with output_files() as outputs:
        written = bidmp.io.save_model(model, outputs.path(tmp_path / "m"))
        assert outputs.shown(written) == tmp_path / "m.npz"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.npz"]
    np.testing.assert_array_equal(bidmp.io.load_model(tmp_path / "m.npz").weights_, model.weights_)
