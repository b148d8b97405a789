"""The fault trials kept as tests: concurrent writers of one file and a disk
that fills up mid-write leave either the old file or a complete new one, and no temporary file.
(A writer killed mid-write: tests/test_robustness.py; a benchmark worker killed, and a resumed
run: tests/experiments/test_benchmark.py.)"""

import multiprocessing
import os
import resource
import signal
import subprocess
import sys
import textwrap

import numpy as np
import pytest

import bidmp
from bidmp.io import load_trajectory, save_trajectory


def _writer(args):
    path, seed = args
    rng = np.random.default_rng(seed)
    for _ in range(5):
        save_trajectory(rng.normal(size=(200, 3)) + seed, path)
    return seed


def test_twenty_concurrent_writers_leave_one_complete_file(tmp_path):
    """20 processes write 5 trajectories each to one path at once: the file read afterwards is
    exactly one writer's last trajectory (its values tell which), and nothing else is left."""
    path = tmp_path / "shared.csv"
    with multiprocessing.get_context("fork").Pool(8) as pool:
        seeds = pool.map(_writer, [(str(path), seed) for seed in range(20)])
    y = load_trajectory(path)
    writer = int(round(float(np.mean(y))))
    assert writer in seeds
    expected = np.random.default_rng(writer)
    for _ in range(5):
        last = expected.normal(size=(200, 3)) + writer
    np.testing.assert_allclose(y, last, rtol=0, atol=1e-9 * max(1.0, np.abs(last).max()))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["shared.csv"]


FULL_DISK = textwrap.dedent("""
    import resource, signal, sys
    import numpy as np
    import bidmp
    from bidmp.io import save_trajectory
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # a write past the limit fails with EFBIG instead
    resource.setrlimit(resource.RLIMIT_FSIZE, (16384, 16384))
    try:
        save_trajectory(np.random.default_rng(0).normal(size=(20000, 3)), sys.argv[1])
    except OSError as exc:
        print("refused:", exc.errno)
        sys.exit(3)
    sys.exit(0)
""")


def test_a_disk_that_fills_up_mid_write_keeps_the_old_file(tmp_path):
    """The file size limit of the process (RLIMIT_FSIZE: what a full small file system does to a
    writer, without needing one) stops a write of ~1 MB at 16 kB: the write fails with an OSError,
    the old file is byte for byte as it was, and no temporary file is left."""
    path = tmp_path / "demo.csv"
    save_trajectory(np.linspace([0.0, 0.0, 0.0], [1.0, 2.0, 3.0], 50), path)
    before = path.read_bytes()
    result = subprocess.run(
        [sys.executable, "-c", FULL_DISK, str(path)], capture_output=True, text=True, timeout=120
    )
    assert result.returncode == 3, (result.stdout, result.stderr)
    assert path.read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["demo.csv"]


def test_a_full_disk_reaches_the_cli_as_one_line(tmp_path):
    """The same through the CLI: ``bidmp rollout ... -o`` under the size limit exits non-zero with
    an error line naming the file (after the fit's notes), and leaves no temporary file."""
    model = tmp_path / "m.npz"
    bidmp.save(
        bidmp.DMP(n_kernels=10).fit(
            np.linspace([0.0, 0.0], [1.0, 2.0], 50) + np.sin(np.linspace(0, 3, 50))[:, None]
        ),
        model,
    )
    script = textwrap.dedent("""
        import resource, signal, sys
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))
        from bidmp.cli import main
        sys.exit(main(sys.argv[1:]))
    """)
    out = tmp_path / "r.csv"
    result = subprocess.run(
        [sys.executable, "-c", script, "rollout", str(model), "--n-steps", "20000", "-o", str(out)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode != 0
    error = result.stderr.strip().splitlines()[-1]
    assert "r.csv" in error and "Traceback" not in result.stderr, result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["m.npz"]


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full on this system")
def test_dev_full_is_refused_as_an_output_without_writing():
    with pytest.raises(ValueError, match="not a regular file"):
        save_trajectory(np.zeros((10, 2)) + np.arange(10)[:, None], "/dev/full")


def test_the_size_limit_helper_is_what_the_tests_think():
    """Guard: RLIMIT_FSIZE exists here (Linux); the two tests above rely on it."""
    assert resource.RLIMIT_FSIZE >= 0 and signal.SIGXFSZ > 0
