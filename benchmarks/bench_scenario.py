"""The nut-unscrewing task end to end (paper Table 4 run times), timed in-process.

    make bench            # runs every script in benchmarks/
    .venv/bin/python benchmarks/bench_scenario.py [--repeats N]

dmp + bidmp: DMP fit, 14 rollouts, segmentation, G-PRM, BLS learning and 14 Bi-DMP rollouts.
Target (issue #5): <= 100 ms in-process (after a warm-up run, so one-time imports and the numba
cache load are excluded). GMM and TP-GMM are timed beside them, as in the paper.
"""

from __future__ import annotations

import argparse

from _timing import median_time

from bidmp import scenarios
from bidmp.evaluation import evaluate


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=11)
    args = parser.parse_args()
    scenario = scenarios.load("nut-unscrewing")
    whole = median_time(lambda: evaluate(scenario, ["dmp", "bidmp"]), args.repeats)
    report = evaluate(scenario)
    print(f"nut-unscrewing, 14 targets (median of {args.repeats} runs, warm)")
    print(f"  {'dmp + bidmp, whole task':32s} {whole * 1e3:8.1f} ms   (target <= 100 ms)")
    for name, result in report.methods.items():
        print(f"  {name:32s} {result.runtime_s * 1e3:8.1f} ms   {result.successes}/14 within 1.75 mm")
    gmm, bidmp = report.methods["gmm"].runtime_s, report.methods["bidmp"].runtime_s
    print(f"  GMM / Bi-DMP run time ratio: {gmm / bidmp:.1f}  (paper Table 4: GMM-based methods are slower)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
