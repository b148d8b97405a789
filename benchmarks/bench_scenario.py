"""The nut-unscrewing task end to end (paper Table 4 run times), timed in-process.

    make bench            # runs every script in benchmarks/
    .venv/bin/python benchmarks/bench_scenario.py [--repeats N]
dmp + bidmp: DMP fit, 14 rollouts, segmentation, G-PRM, BLS learning and 14 Bi-DMP rollouts, on
the paper's protocol and on the defaults a user meets (the robot protocol), interleaved.
Targets, in-process after a warm-up run (one-time imports and the numba cache load excluded):
without geometry (the scenario's scene removed) <= 100 ms (issue #5); with the geometry checks
(scene-aware G-PRM, clearance of all 28 rollouts to every part) <= 150 ms (issue #11), and the
ratio of the two. GMM and TP-GMM are timed beside them, as in the paper.

Fair timings (issue #8): the baselines' EM runs with one BLAS/OpenMP thread. The last lines time
scikit-learn's ``GaussianMixture`` on the same data with the machine's default thread pools and
with one thread, and print the ratio (thread contention on a 2-core machine).
"""

from __future__ import annotations

import argparse

import numpy as np
from _timing import interleaved_times, median_time
from threadpoolctl import threadpool_limits

from bidmp.baselines import augment
from bidmp.tasks import evaluate, scenarios


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=11)
    args = parser.parse_args()
    scenario = scenarios.load("nut-unscrewing")
    spec = scenario.to_dict()
    del spec["scene"], spec["job"]  # the job runs in the simulator, which needs the scene
    blind = scenarios.from_dict(spec, source="nut-unscrewing without its scene")
    # The paper's protocol (the scenario as built in) and the defaults a user meets (the robot
    # protocol: timed, settling at rest), the four sides interleaved round by round.
    robot, robot_blind = scenario.with_robot_protocol(), blind.with_robot_protocol()
    times = interleaved_times(
        {
            "paper, no geometry": lambda: evaluate(blind, ["dmp", "bidmp"]),
            "paper, geometry": lambda: evaluate(scenario, ["dmp", "bidmp"]),
            "robot, no geometry": lambda: evaluate(robot_blind, ["dmp", "bidmp"]),
            "robot, geometry": lambda: evaluate(robot, ["dmp", "bidmp"]),
        },
        args.repeats,
    )
    report = evaluate(scenario)
    print(f"nut-unscrewing, 14 targets (median of {args.repeats} interleaved runs, warm)")
    for protocol in ("paper", "robot"):
        without, whole = times[f"{protocol}, no geometry"], times[f"{protocol}, geometry"]
        label = "paper protocol" if protocol == "paper" else "robot protocol (defaults)"
        print(f"  {label}")
        print(f"  {'  dmp + bidmp, no geometry':32s} {without * 1e3:8.1f} ms   (target <= 100 ms)")
        print(
            f"  {'  dmp + bidmp, geometry checks':32s} {whole * 1e3:8.1f} ms   (target <= 150 ms; "
            f"{whole / without:.2f}x the run without)"
        )
    print(
        "  the defaults take "
        f"{times['robot, geometry'] / times['paper, geometry']:.2f}x the paper protocol's time "
        "(geometry checks)"
    )
    for name, result in report.methods.items():
        print(
            f"  {name:32s} {result.runtime_s * 1e3:8.1f} ms   {result.successes}/14 within 1.75 mm, "
            f"task success {result.task_successes}/14"
        )
    gmm, bidmp = report.methods["gmm"].runtime_s, report.methods["bidmp"].runtime_s
    print(
        f"  GMM / Bi-DMP run time ratio: {gmm / bidmp:.1f}  (paper Table 4: GMM-based methods are slower)"
    )

    from sklearn.mixture import GaussianMixture

    demos = augment(scenario.demonstration, 5, 1.5, 0)
    t = np.linspace(0.0, 1.0, demos.shape[1])
    data = np.concatenate([np.column_stack([t, demo]) for demo in demos])

    def em():
        GaussianMixture(16, covariance_type="full", reg_covar=1e-6, random_state=0).fit(data)

    repeats = max(3, args.repeats // 3)
    default = median_time(em, repeats)
    with threadpool_limits(limits=1):
        single = median_time(em, repeats)
    print(
        f"  GaussianMixture EM (16 components, {data.shape[0]} points): default threads {default * 1e3:.0f} ms, "
        f"one thread {single * 1e3:.0f} ms, ratio {default / single:.1f}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
