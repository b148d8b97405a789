"""Write the bundled rocking recording ``src/bidmp/data/recordings/rocking_cell.csv``: a person
rocking a gripped battery cell loose, as a logger writes it (``t,x,y,z``: jittered epoch stamps
at ~250 Hz, mm, idle ends, the rhythm ramping in and out, sensor noise).

    .venv/bin/python tools/rocking_recording.py [--out PATH]

The motion: a lateral sway of ±2 mm along x at 1.6 Hz, the cell tipping a little (0.3 mm up and
down at twice the frequency, a 0.2 mm wobble along y), 8 periods between 1 s of stillness at each
end, ramped in and out over 0.8 s; 0.05 mm Gaussian noise. Seeded: the same file every run.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from bidmp.io.atomic import atomic_write

OUT = (
    Path(__file__).resolve().parents[1]
    / "src"
    / "bidmp"
    / "data"
    / "recordings"
    / "rocking_cell.csv"
)
FREQUENCY_HZ, PERIODS, IDLE_S, RAMP_S = 1.6, 8, 1.0, 0.8
GRASP_MM = np.array([30.0, 0.0, 30.0])


def recording(seed: int = 16) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    duration = PERIODS / FREQUENCY_HZ + 2 * IDLE_S
    stamps = np.cumsum(rng.uniform(0.6, 1.4, int(duration * 250)) / 250.0)
    s = stamps - stamps[0]
    envelope = np.clip((s - IDLE_S) / RAMP_S, 0, 1) * np.clip((s[-1] - IDLE_S - s) / RAMP_S, 0, 1)
    envelope = envelope**2 * (3 - 2 * envelope)
    phase = 2 * np.pi * FREQUENCY_HZ * s
    sway = np.column_stack(
        [2.0 * np.sin(phase), 0.2 * np.sin(phase + 0.7), 0.3 * (1 - np.cos(2 * phase)) / 2]
    )
    y = GRASP_MM + envelope[:, None] * sway + rng.normal(0.0, 0.05, sway.shape)
    return stamps + 1_733_000_000.0, y


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=OUT)
    args = parser.parse_args()
    t, y = recording()
    lines = ["t,x,y,z"] + [f"{a:.6f},{b:.4f},{c:.4f},{d:.4f}" for a, (b, c, d) in zip(t, y)]
    with atomic_write(args.out, "w") as handle:
        handle.write("\n".join(lines) + "\n")
    print(f"wrote {args.out} ({len(t)} samples over {t[-1] - t[0]:.2f} s)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
