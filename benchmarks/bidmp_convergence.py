"""Bi-DMP on the nut task: convergence past the horizon and the block ridge.

    .venv/bin/python benchmarks/bidmp_convergence.py

For the extension target (150, 25, 0) mm: the miss of the plain DMP and of the learned skill
after 1, 2, 10 and 20 × T steps, and for two block ridges the largest output weight, the
reproduction RMSE against the extended demonstration and the skill's own end-point error.
"""

from __future__ import annotations

import numpy as np

from bidmp import DMP, BiDMP, extend_demonstration
from bidmp.demonstrations import minimum_jerk
from bidmp.experiments import BATTERY_APPROACH_VIA, BATTERY_EXTENSION_TARGET
from bidmp.tasks import rmse


def main() -> int:
    demo = minimum_jerk(BATTERY_APPROACH_VIA, 200)
    dmp = DMP(protocol="paper", alpha=100.0).fit(demo)
    extension = extend_demonstration(demo, BATTERY_EXTENSION_TARGET, seed=0)
    goal = np.asarray(BATTERY_EXTENSION_TARGET)
    model = BiDMP(dmp).learn(extension.complete)
    print("nut task, goal (150, 25, 0) mm: miss after k x T steps (default Bi-DMP)")
    for factor in (1, 2, 10, 20):
        n = factor * dmp.n_steps_
        print(
            f"  {factor:3d} x T   Bi-DMP {np.linalg.norm(model.rollout(goal, n_steps=n)[-1] - goal):10.3g} mm"
            f"   plain DMP {np.linalg.norm(dmp.rollout(goal, n_steps=n)[-1] - goal):10.3g} mm"
        )
    print("block ridge: largest output weight, reproduction RMSE, own end-point error")
    for reg in (1e-8, 1e-6, 1e-4, 1e-2):
        model = BiDMP(dmp, reg=reg).learn(extension.complete)
        rollout = model.rollout(goal)
        # the skill runs on its own (longer) time scale: compare on the rollout's samples
        share = np.linspace(0.0, 1.0, len(rollout))
        taught = np.linspace(0.0, 1.0, len(extension.complete))
        reference = np.column_stack([np.interp(share, taught, c) for c in extension.complete.T])
        weight = max(np.abs(block.output_weights_).max() for block in model.blocks_)
        print(
            f"  reg {reg:7.0e}   max |W| {weight:9.3g}   RMSE {rmse(rollout, reference):.3f} mm"
            f"   end {np.linalg.norm(rollout[-1] - goal):.3f} mm"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
