"""Rhythmic DMPs: bidmp's RhythmicDMP against pydmps' DMPs_rhythmic on the same recordings,
accuracy and speed in one run (the sides interleaved).

    .venv/bin/python benchmarks/bench_rhythmic.py [--recordings N] [--repeats N] [--smoke]

Each recording (seeded): a 3-D sum of sines at a random frequency (0.4-1.8 Hz), 6 periods, idle
ends and the rhythm ramping in and out, 0.3 mm noise, jittered stamps at a random rate (100-1000
Hz). bidmp learns from the whole recording (frequency estimated, transients cut, all periods at
once). pydmps fits exactly one period: it is given the true period, cut from the middle of the
recording (resampled to uniform time, which it assumes) — its best case; it has no frequency
estimate. Both use 50 basis functions. Accuracy: the RMSE of one steady period against the clean
signal at the same phase, over the amplitude; speed: fit + one period's rollout at 1 kHz.
pydmps needs Python < 3.12 (it imports ``imp``): without it only bidmp's side runs.
"""

from __future__ import annotations

import argparse
import sys
import warnings

import numpy as np
from _timing import interleaved_times

from bidmp.primitives import RhythmicDMP

AMPLITUDE = 20.0


def signal(phase: np.ndarray) -> np.ndarray:
    return 100.0 + np.column_stack(
        [
            AMPLITUDE * np.sin(phase) + 0.3 * AMPLITUDE * np.sin(2 * phase + 0.5),
            0.6 * AMPLITUDE * np.cos(phase) + 0.2 * AMPLITUDE * np.sin(3 * phase),
            0.25 * AMPLITUDE * np.sin(phase + 1.0),
        ]
    )


def recording(rng: np.random.Generator):
    frequency = rng.uniform(0.4, 1.8)
    rate = rng.uniform(100.0, 1000.0)
    idle, ramp, periods = 1.0, 0.6, 6
    duration = periods / frequency + 2 * idle
    t = np.cumsum(rng.uniform(0.6, 1.4, int(duration * rate)) / rate)
    envelope = np.clip((t - idle) / ramp, 0, 1) * np.clip((t[-1] - idle - t) / ramp, 0, 1)
    envelope = envelope**2 * (3 - 2 * envelope)
    clean = 100.0 + envelope[:, None] * (signal(2 * np.pi * frequency * t) - 100.0)
    return frequency, t, clean + rng.normal(0.0, 0.3, clean.shape)


def bidmp_side(frequency, t, y):
    """Fit on the whole recording; one steady period at 1 kHz; its RMSE against the clean
    signal at the same phase (the phase origin is the kept part's start)."""
    model = RhythmicDMP(n_kernels=50).fit(y, t, units="mm")
    motion = model.trajectory(cycles=1.0, dt=0.001)
    start = model.estimate_.start
    clean = signal(2 * np.pi * frequency * (t[0] + start + motion.t))
    return model, motion.y, clean


def pydmps_side(frequency, t, y, dmp_class):
    """One true period cut from the middle, resampled uniform; rollout of 3 periods, the last."""
    period = 1.0 / frequency
    start = t[0] + 0.5 * (t[-1] - t[0]) - 0.5 * period
    n = max(int(round(period * 1000)), 10)
    uniform = start + np.arange(n) * period / n
    cut = np.column_stack([np.interp(uniform, t, column) for column in y.T])
    dmp = dmp_class(n_dmps=3, n_bfs=50, dt=2 * np.pi / n)  # pydmps' cycle lasts 2π of its time
    dmp.imitate_path(y_des=cut.T)
    track, _, _ = dmp.rollout(timesteps=3 * n)
    last = track[2 * n : 3 * n]
    clean = signal(2 * np.pi * frequency * uniform)
    return last, clean


def rmse(a, b) -> float:
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1))))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--recordings", type=int, default=20)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--smoke", action="store_true", help="2 recordings, 1 repeat")
    args = parser.parse_args()
    if args.smoke:
        args.recordings, args.repeats = 2, 1
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            from pydmps.dmp_rhythmic import DMPs_rhythmic
    except ImportError:  # pragma: no cover - Python >= 3.12, or not installed
        DMPs_rhythmic = None
        print("pydmps is not importable here (it needs Python < 3.12): bidmp's side only")
    rng = np.random.default_rng(0)
    ours_err, theirs_err, ours_f, ours_t, theirs_t = [], [], [], [], []
    for _ in range(args.recordings):
        frequency, t, y = recording(rng)
        model, motion, clean = bidmp_side(frequency, t, y)
        ours_err.append(rmse(motion, clean) / AMPLITUDE)
        ours_f.append(abs(model.frequency_ - frequency) / frequency)
        sides = {"bidmp": lambda: bidmp_side(frequency, t, y)}
        if DMPs_rhythmic is not None:
            last, clean_p = pydmps_side(frequency, t, y, DMPs_rhythmic)
            theirs_err.append(rmse(last, clean_p) / AMPLITUDE)
            sides["pydmps"] = lambda: pydmps_side(frequency, t, y, DMPs_rhythmic)
        medians = interleaved_times(sides, args.repeats)
        ours_t.append(medians["bidmp"])
        if "pydmps" in medians:
            theirs_t.append(medians["pydmps"])
    print(f"{args.recordings} recordings, 50 basis functions, medians (worst)")
    print(
        f"  bidmp  RhythmicDMP     RMSE/amplitude {100 * np.median(ours_err):6.3f} % "
        f"({100 * np.max(ours_err):.3f} %), frequency error {100 * np.median(ours_f):.4f} % "
        f"({100 * np.max(ours_f):.4f} %), fit + period {1e3 * np.median(ours_t):7.2f} ms"
    )
    if theirs_t:
        print(
            f"  pydmps DMPs_rhythmic   RMSE/amplitude {100 * np.median(theirs_err):6.3f} % "
            f"({100 * np.max(theirs_err):.3f} %), given the true period,    "
            f"fit + period {1e3 * np.median(theirs_t):7.2f} ms"
        )
        ratio = np.median(np.array(theirs_t) / np.array(ours_t))
        print(f"  speed: pydmps / bidmp {ratio:.2f}x (median over recordings, sides interleaved)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
