"""docs/recordings.png: the bundled recordings raw and prepared, the robot DMP's rollout to a nut
150 mm away, and the speed profiles in real time. Run: python tools/recordings_figure.py"""

from __future__ import annotations

from pathlib import Path

import numpy as np

import bidmp
from bidmp.plotting import plot_recordings

ROOT = Path(__file__).resolve().parent.parent
SHIFT = np.array([150.0, 25.0, 0.0]) * 150.0 / np.hypot(150.0, 25.0)


def main() -> Path:
    recordings = []
    for name in bidmp.demonstrations.recording_names():
        y, t = bidmp.demonstrations.recording(name)
        prepared, info = bidmp.prepare(y, t, units="mm")
        dmp = bidmp.DMP().fit(prepared.y, prepared.t, units="mm")
        recordings.append((name, y, t, prepared, info, dmp.trajectory(dmp.goal_ + SHIFT)))
    return plot_recordings(ROOT / "docs" / "recordings.png", recordings)


if __name__ == "__main__":
    print(f"wrote {main()}")
