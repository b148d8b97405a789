"""bidmp fit --periodic and bidmp rollout of a rhythmic model: a logger's recording in, the
printed frequency and the written motion checked against the signal that made the recording."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import numpy as np
import pytest

from bidmp.cli import main
from bidmp.io import load_trajectory, save_poses, save_trajectory

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "primitives"))
from test_rhythmic import _pose_recording, _recording  # noqa: E402


def run(argv, capsys):
    code = main(argv)
    out, err = capsys.readouterr()
    return code, out, err


def test_fit_periodic_then_rollout_cycles_frequency_amplitude(tmp_path, capsys):
    t, y, clean, _ = _recording(np.random.default_rng(21), frequency=0.9)
    csv = save_trajectory(y, tmp_path / "rocking.csv", t)
    model, figure = tmp_path / "rock.npz", tmp_path / "rock.png"
    code, out, _ = run(
        ["fit", str(csv), "--units", "mm", "--periodic", "-o", str(model), "--plot", str(figure)],
        capsys,
    )
    assert code == 0 and model.exists() and figure.stat().st_size > 10_000
    printed = float(re.search(r"frequency ([0-9.]+) Hz", out).group(1))
    assert printed == pytest.approx(0.9, rel=0.005)
    out_csv = tmp_path / "out.csv"
    code, out, _ = run(
        [
            "rollout",
            str(model),
            "--cycles",
            "3",
            "--frequency",
            "1.2",
            "--amplitude",
            "1.5",
            "-o",
            str(out_csv),
        ],
        capsys,
    )
    assert code == 0
    motion = load_trajectory(out_csv)
    y_out, t_out = motion if isinstance(motion, tuple) else (motion, None)
    # 3 cycles at 1.2 Hz: 2.5 s at 1 kHz; the oscillation 1.5x the recording's steady swing.
    assert y_out.shape[0] == 2501
    steady = clean[(t - t[0] > 2.0) & (t - t[0] < t[-1] - t[0] - 2.0)]
    np.testing.assert_allclose(np.ptp(y_out, axis=0), 1.5 * np.ptp(steady, axis=0), rtol=0.05)
    # it repeats every 1/1.2 s: the first cycle, one period later (interpolated between samples)
    stamps = np.arange(y_out.shape[0]) / 1000.0
    first = stamps <= 1.0 / 1.2
    later = np.column_stack([np.interp(stamps[first] + 1.0 / 1.2, stamps, c) for c in y_out.T])
    np.testing.assert_allclose(later, y_out[first], atol=0.01)


def test_a_pose_rhythm_and_one_line_refusals(tmp_path, capsys):
    t, poses, *_ = _pose_recording(np.random.default_rng(22))
    csv = save_poses(poses, tmp_path / "wrist.csv", t)
    model = tmp_path / "wrist.npz"
    code, out, _ = run(["fit", str(csv), "--units", "mm", "--periodic", "-o", str(model)], capsys)
    assert code == 0 and "rotation vector" in out
    code, _, _ = run(
        ["rollout", str(model), "--cycles", "2", "-o", str(tmp_path / "o.csv")], capsys
    )
    assert code == 0
    code, _, err = run(
        ["rollout", str(model), "--goal", "1", "2", "3", "-o", str(tmp_path / "x.csv")], capsys
    )
    assert code == 2 and "--goal" in err and len(err.strip().splitlines()) == 1
    code, _, err = run(
        ["fit", str(csv), "--periodic", "--beta", "3", "-o", str(tmp_path / "b.npz")], capsys
    )
    assert code == 2 and "--beta" in err and len(err.strip().splitlines()) == 1
