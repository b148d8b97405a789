"""Bi-DMP on the nut task: convergence past the horizon and the block ridge.

    .venv/bin/python benchmarks/bidmp_convergence.py

For the extension target (150, 25, 0) mm: the miss of the plain DMP and of the learned skill
after 1, 2, 10 and 20 × T steps, and for four block ridges the largest output weight, the
reproduction RMSE and Fréchet distance against the extended demonstration and the skill's own end-point error; on the
paper's protocol and on the defaults a user meets (the robot protocol).
"""

from __future__ import annotations

import numpy as np

from bidmp import DMP, BiDMP, extend_demonstration, frechet_distance
from bidmp.demonstrations import minimum_jerk
from bidmp.experiments import BATTERY_APPROACH_VIA, BATTERY_EXTENSION_TARGET
from bidmp.tasks import rmse


def dense(path: np.ndarray, n_samples: int = 2000) -> np.ndarray:
    """``path`` (T, D) linearly interpolated to ``n_samples``: the discrete Fréchet distance of two
    paths is at least about half their samples' spacing (1.6 mm at 200 samples here)."""
    share = np.linspace(0.0, 1.0, n_samples)
    taught = np.linspace(0.0, 1.0, len(path))
    return np.column_stack([np.interp(share, taught, column) for column in path.T])


def main() -> int:
    demo = minimum_jerk(BATTERY_APPROACH_VIA, 200)
    # The paper's protocol and the defaults a user meets (the robot protocol: the same samples
    # over 2 s in mm, its trajectory settling at rest past the horizon).
    dmps = {
        "paper protocol": DMP(protocol="paper", alpha=100.0).fit(demo),
        "robot protocol (defaults)": DMP().fit(demo, np.linspace(0.0, 2.0, 200), units="mm"),
    }
    extension = extend_demonstration(demo, BATTERY_EXTENSION_TARGET, seed=0)
    goal = np.asarray(BATTERY_EXTENSION_TARGET)
    for protocol, dmp in dmps.items():
        model = BiDMP(dmp).learn(extension.complete)
        print(f"nut task, goal (150, 25, 0) mm, {protocol}: miss after k x T steps")
        for factor in (1, 2, 10, 20):
            n = factor * dmp.n_steps_
            print(
                f"  {factor:3d} x T   Bi-DMP {np.linalg.norm(model.rollout(goal, n_steps=n)[-1] - goal):10.3g} mm"
                f"   plain DMP {np.linalg.norm(dmp.rollout(goal, n_steps=n)[-1] - goal):10.3g} mm"
            )
        print(
            f"block ridge, {protocol}: largest output weight, reproduction RMSE, own end-point error"
        )
        for reg in (1e-8, 1e-6, 1e-4, 1e-2):
            model = BiDMP(dmp, reg=reg).learn(extension.complete)
            rollout = model.rollout(goal)
            # the skill runs on its own (longer) time scale: compare on the rollout's samples
            share = np.linspace(0.0, 1.0, len(rollout))
            taught = np.linspace(0.0, 1.0, len(extension.complete))
            reference = np.column_stack([np.interp(share, taught, c) for c in extension.complete.T])
            weight = max(np.abs(block.output_weights_).max() for block in model.blocks_)
            # RMSE compares sample by sample (the robot protocol's rollout runs 1.1x the time,
            # settling at rest): the Fréchet distance compares the paths whatever their timing.
            print(
                f"  reg {reg:7.0e}   max |W| {weight:9.3g}   RMSE {rmse(rollout, reference):.3f} mm"
                f"   Frechet {frechet_distance(dense(rollout), dense(extension.complete)):.3f} mm"
                f"   end {np.linalg.norm(rollout[-1] - goal):.3f} mm"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
