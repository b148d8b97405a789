"""ProMPs on LASA: bidmp's ProMP against movement_primitives' ProMP, the same demonstrations and
the same basis (20 normalised Gaussians per dimension, centres over [0, 1], overlap 0.7).

    .venv/bin/python benchmarks/bench_promp.py [--shapes N] [--repeats N] [--smoke]

For each LASA shape, the first 6 demonstrations are learned and the 7th is held out:
1. accuracy on the held-out demonstration: the RMSE of the mean, and of the mean conditioned
   exactly on its start and its goal (movement_primitives conditions one point at a time: start,
   then goal — the same posterior as both at once);
2. where the models are the same: the conditioned mean and variance of movement_primitives
   given bidmp's weight distribution (``from_weight_distribution``) against bidmp's (equal to
   rounding), and the two learned means against each other. What differs: bidmp learns each
   demonstration's weights by ridge regression and takes their mean and covariance (plus
   ``cov_reg`` times the mean variance); movement_primitives runs EM on a Bayesian multi-task
   model with a smoothness prior (Lazaric & Ghavamzadeh 2010, gamma 0.7), so its mean and
   covariance are smoothed;
3. speed, the sides interleaved: fit, and conditioning + the mean at 1000 phases.
"""

from __future__ import annotations

import argparse
import statistics
import sys

import numpy as np
from _timing import interleaved_times

from bidmp.demonstrations import lasa
from bidmp.demonstrations.datasets import lasa_names
from bidmp.primitives import ProMP

N_BASIS = 20


def rmse(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.sqrt(np.mean(np.sum((a - b) ** 2, axis=1))))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shapes", type=int, default=30)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--smoke", action="store_true", help="2 shapes, 1 repeat")
    args = parser.parse_args()
    if args.smoke:
        args.shapes, args.repeats = 2, 1
    try:
        from movement_primitives.promp import ProMP as PeerProMP
    except ImportError:  # pragma: no cover - optional peer
        print("movement_primitives is not installed: pip install movement-primitives")
        return 0
    rows = []
    for name in lasa_names()[: args.shapes]:
        demos = lasa(name)
        train, held = demos[:6], demos[6]
        T = np.linspace(0.0, 1.0, demos.shape[1])
        ours = ProMP(n_basis=N_BASIS).fit(list(train))
        peer = PeerProMP(n_dims=2, n_weights_per_dim=N_BASIS)
        peer.imitate(np.tile(T, (len(train), 1)), train)
        ends = np.stack([held[0], held[-1]])

        def ours_condition(model=ours):
            return model.condition([0.0, 1.0], ends, 0.0).mean(T)

        def peer_condition(model=peer):
            first = model.condition_position(held[0], t=0.0, t_max=1.0)
            return first.condition_position(held[-1], t=1.0, t_max=1.0).mean_trajectory(T)

        # the same distribution in both: conditioning and variance must agree
        same = PeerProMP(n_dims=2, n_weights_per_dim=N_BASIS)
        same.from_weight_distribution(ours.weight_mean_.copy(), ours.weight_cov_.copy())
        goal_only = ours.condition([1.0], held[-1][None], 0.0)
        theirs_same = same.condition_position(held[-1], t=1.0, t_max=1.0)
        row = {
            "shape": name,
            "ours_mean": rmse(ours.mean(T), held),
            "peer_mean": rmse(peer.mean_trajectory(T), held),
            "ours_cond": rmse(ours_condition(), held),
            "peer_cond": rmse(peer_condition(), held),
            "means_apart": rmse(ours.mean(T), peer.mean_trajectory(T)),
            "same_mean": float(np.abs(goal_only.mean(T) - theirs_same.mean_trajectory(T)).max()),
            "same_var": float(np.abs(goal_only.var(T) - theirs_same.var_trajectory(T)).max()),
        }
        seconds = interleaved_times(
            {
                "fit ours": lambda: ProMP(n_basis=N_BASIS).fit(list(train)),
                "fit peer": lambda: PeerProMP(n_dims=2, n_weights_per_dim=N_BASIS).imitate(
                    np.tile(T, (len(train), 1)), train
                ),
                "condition ours": ours_condition,
                "condition peer": peer_condition,
            },
            args.repeats,
        )
        row["fit_ratio"] = seconds["fit peer"] / seconds["fit ours"]
        row["cond_ratio"] = seconds["condition peer"] / seconds["condition ours"]
        row["fit_ours_ms"] = 1e3 * seconds["fit ours"]
        rows.append(row)

    def median(key):
        return statistics.median(row[key] for row in rows)

    print(
        f"LASA, {len(rows)} shapes, 6 demonstrations learned, the 7th held out, {N_BASIS} basis functions"
    )
    print("  held-out RMSE (mm, median over shapes)     bidmp ProMP   movement_primitives ProMP")
    print(
        f"    the mean                                  {median('ours_mean'):8.3f}      {median('peer_mean'):8.3f}"
    )
    print(
        f"    conditioned on its start and goal         {median('ours_cond'):8.3f}      {median('peer_cond'):8.3f}"
    )
    print(
        f"  the two learned means apart (RMSE, mm)      {median('means_apart'):8.3f}  (EM with "
        f"a smoothness prior vs ridge)"
    )
    worst = max(max(row["same_mean"], row["same_var"]) for row in rows)
    print(
        f"  the same distribution conditioned on the goal: largest difference of mean or variance {worst:.2e}"
    )
    print(
        f"  speed (movement_primitives / bidmp, interleaved): fit {median('fit_ratio'):.1f}x "
        f"(bidmp {median('fit_ours_ms'):.2f} ms), condition + mean {median('cond_ratio'):.1f}x"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
