"""The CLFD protocol's input: a damaged copy of its data folder, scalars where arrays go and a
scalar where the list of cells goes are each refused in one line naming the file or the
argument (they were IndexError, EOFError, zipfile.BadZipFile, KeyError, AttributeError or a
silent NaN); an intact copy reads as the bundled data."""

from __future__ import annotations

import io
import os
import shutil

import numpy as np
import pytest

from bidmp.experiments import clfd
from bidmp.experiments.clfd import data as clfd_data

LASA_TASK = "LASA/lasa_numpy/task_x3_y3.npz"
POSE_TASK = "robottasks/pos_ori/openbox.npy"


def _one_line(caught, *names) -> str:
    message = str(caught.value)
    assert "\n" not in message and len(message) <= 300, message
    assert any(name in message for name in names), message
    return message


def _npz(**arrays) -> bytes:
    out = io.BytesIO()
    np.savez(out, **arrays)
    return out.getvalue()


def _copy(tmp_path):
    """A copy of the bundled data folder (its files linked, not copied: 8 MB)."""
    folder = tmp_path / "clfd"
    shutil.copytree(clfd_data.DATA, folder, copy_function=os.symlink)
    return folder


def _damage(folder, relative: str, content: bytes) -> None:
    (folder / relative).unlink()
    (folder / relative).write_bytes(content)


def _damages():
    """(label, file, its new content): what a bad download, a full disk or an editor leaves."""
    raw_npz = (clfd_data.DATA / LASA_TASK).read_bytes()
    raw_npy = (clfd_data.DATA / POSE_TASK).read_bytes()
    garbage = bytes(np.random.default_rng(0).integers(0, 256, 4000, dtype=np.uint8))
    t = np.tile(np.linspace(0.0, 1.0, 50), (7, 1))
    return [
        ("truncated npz", LASA_TASK, raw_npz[: len(raw_npz) // 2]),
        ("zero-byte npz", LASA_TASK, b""),
        ("garbled npz", LASA_TASK, garbage),
        ("npz without t", LASA_TASK, _npz(pos=np.zeros((7, 50, 2)))),
        ("npz of NaN", LASA_TASK, _npz(pos=np.full((7, 50, 2), np.nan), t=t)),
        ("npz of one demonstration", LASA_TASK, _npz(pos=np.zeros((50, 2)), t=t)),
        ("zero-byte npy", POSE_TASK, b""),
        ("truncated npy", POSE_TASK, raw_npy[:1000]),
        ("garbled npy", POSE_TASK, b"\x93NUMPY\x01\x00" + garbage),
        ("garbled sequence", "LASA/lasa_numpy_sequence_all.txt", b"\xff\xfe" + garbage),
        ("a path in the sequence", "LASA/lasa_numpy_sequence_all.txt", b"../../x/passwd\n"),
        ("an empty sequence", "robottasks/robottasks_pos_ori_sequence_all.txt", b""),
        ("garbled names", "LASA/lasa_names.json", b"{not json"),
        ("zero-byte names", "LASA/lasa_names.json", b""),
        ("too few names", "LASA/lasa_names.json", b'["Angle", "BendedLine"]'),
    ]


@pytest.mark.parametrize("label, relative, content", _damages(), ids=[d[0] for d in _damages()])
def test_a_damaged_copy_of_the_data_is_refused_naming_the_file(
    tmp_path, monkeypatch, label, relative, content
):
    """The bundled folder damaged in place (as an install can be): one line naming the file it
    read, never NumPy's, zipfile's or Python's own error."""
    folder = _copy(tmp_path)
    _damage(folder, relative, content)
    monkeypatch.setattr(clfd_data, "DATA", folder)
    dataset = "lasa" if relative.startswith("LASA") else "robottasks"
    with pytest.raises(ValueError) as caught:
        clfd.clfd_tasks(dataset)
    message = _one_line(caught, "folder: ")
    assert "task_x" in message or os.path.basename(relative) in message, message


def test_an_intact_copy_reads_as_the_bundled_data(tmp_path):
    folder = _copy(tmp_path)
    for dataset in ("lasa", "robottasks"):
        copied, bundled = clfd.clfd_tasks(dataset, folder=folder), clfd.clfd_tasks(dataset)
        assert [task.name for task in copied] == [task.name for task in bundled]
        for a, b in zip(copied, bundled):
            np.testing.assert_array_equal(a.poses, b.poses)
            np.testing.assert_array_equal(a.times, b.times)


@pytest.fixture(scope="module")
def learned():
    """Each method with the first LASA task learned (on every 20th sample: fast)."""
    task = clfd.clfd_tasks("lasa")[0]
    small = clfd.ClfdTask(task.name, task.positions[:, ::20], task.times[:, ::20])
    methods = {}
    for name, cls in clfd.METHODS.items():
        method = cls(n_basis=10) if name == "promp-library" else cls()
        method.learn(small)
        methods[name] = method
    return small, methods


SCALAR_CALLS = [
    ("task", lambda m, task: m.learn(5.0)),
    ("starts", lambda m, task: m.reproduce(0, 5.0, task.times[0])),
    ("starts", lambda m, task: m.reproduce(0, True, task.times[0])),
    ("t", lambda m, task: m.reproduce(0, task.poses[:, 0], 5.0)),
    ("index", lambda m, task: m.reproduce(1.5, task.poses[:, 0], task.times[0])),
    ("index", lambda m, task: m.reproduce(True, task.poses[:, 0], task.times[0])),
    ("index", lambda m, task: m.reproduce(3, task.poses[:, 0], task.times[0])),
]


@pytest.mark.parametrize("method", list(clfd.METHODS))
@pytest.mark.parametrize(
    "name, call", SCALAR_CALLS, ids=[f"{n}-{i}" for i, (n, _) in enumerate(SCALAR_CALLS)]
)
def test_a_method_refuses_scalars_by_name(learned, method, name, call):
    task, methods = learned
    with pytest.raises((ValueError, TypeError)) as caught:
        call(methods[method], task)
    _one_line(caught, name)


@pytest.mark.parametrize(
    "name, call",
    [
        ("poses", lambda: clfd.TangentChart([1.0, 0.0, 0.0, 0.0]).curves(5.0)),
        ("curves", lambda: clfd.TangentChart([1.0, 0.0, 0.0, 0.0]).poses(5.0)),
        ("poses", lambda: clfd.TangentChart([1.0, 0.0, 0.0, 0.0]).curves(np.zeros((3, 2)))),
        ("poses", lambda: clfd.TangentChart(None).curves(np.array(5.0))),
        ("positions", lambda: clfd.ClfdTask("x", 5.0, 5.0)),
        ("times", lambda: clfd.ClfdTask("x", np.zeros((2, 5, 2)), np.zeros((2, 5)))),
        ("orientations", lambda: clfd.ClfdTask("x", np.zeros((1, 3, 2)), [[0, 1, 2]], 5.0)),
        ("true", lambda: clfd.orientation_error(np.zeros((3, 4)), np.ones((3, 4)))),
        ("n_kernels", lambda: clfd.DMPLibrary(5.5)),
        ("cov_reg", lambda: clfd.ProMPLibrary(cov_reg=np.nan)),
        ("seeds", lambda: clfd.run_clfd(seeds=1.5, n_tasks=1)),
        ("seeds", lambda: clfd.run_clfd(seeds=3, n_tasks=1)),
        ("methods", lambda: clfd.run_clfd(methods="dmp-library", n_tasks=1)),
        ("folder", lambda: clfd.clfd_tasks("lasa", folder=5.0)),
    ],
)
def test_scalars_where_arrays_or_lists_go_are_refused_by_name(name, call):
    """orientation_error of zero quaternions was a silent NaN; run_clfd(seeds=1.5) Python's
    'float object is not iterable'; methods="dmp-library" a refusal of its first letter."""
    with pytest.raises((ValueError, TypeError)) as caught:
        call()
    _one_line(caught, name)
