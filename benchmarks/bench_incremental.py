"""Incremental learning speed: adding enhancement nodes against refitting with the same nodes,
and Bi-DMP learn + rollout, timed in one run (ratios, not seconds).

    make bench            # runs every script in benchmarks/
    .venv/bin/python benchmarks/bench_incremental.py [--repeats N]

Target (issue #4): adding nodes >= 10x faster than refitting with the same nodes, equal to 1e-8.
An addition of m nodes to c hidden nodes costs O(N·c·m); a refit O(N·c²) plus the autoencoders:
the ratio grows with c / m, so it is shown for two base sizes.
"""

from __future__ import annotations

import argparse
import copy

import numpy as np
from _timing import interleaved_times, median_time

from bidmp import BLS, DMP, BiDMP, extend_demonstration
from bidmp.demonstrations import minimum_jerk
from bidmp.experiments import BATTERY_APPROACH_VIA, BATTERY_EXTENSION_TARGET
from bidmp.incremental import block_pinv_update
from bidmp.incremental.linalg import PINV_RCOND


def bidmp_like_problem(n_rows: int = 1000):
    """BLS input and target as in Bi-DMP: DMP basis rows -> a forcing increment."""
    demo = minimum_jerk(BATTERY_APPROACH_VIA, n_rows)
    dmp = DMP(protocol="paper", alpha=100.0).fit(demo)
    phase = dmp.phase()
    basis = dmp.basis(phase)
    target = np.column_stack([np.sin(3 * phase), np.cos(5 * phase), phase**2]) * 100.0
    return basis, target


def bench_bls(n_nodes: int, repeats: int, n_enhance: int = 300) -> None:
    X, Y = bidmp_like_problem()
    reg = 1e-3  # a moderate ridge so that "equal" is well defined (the hidden matrix is rank-deficient)
    base = BLS(n_enhance=n_enhance, reg=reg, seed=0).fit(X, Y)

    copies = [copy.deepcopy(base) for _ in range(repeats + 1)]

    def incremental():
        return copies.pop().add_enhancement_nodes(n_nodes)

    def refit():  # retraining from scratch with the same nodes
        return BLS(n_enhance=n_enhance, reg=reg, seed=0).fit(X, Y).add_enhancement_nodes(n_nodes)

    added = copy.deepcopy(base).add_enhancement_nodes(n_nodes)
    A = added.hidden(X)
    scratch = np.linalg.solve(A.T @ A + reg * np.eye(A.shape[1]), A.T @ Y)
    difference = np.abs(added.output_weights_ - scratch).max() / np.abs(scratch).max()

    def solve_only():
        hidden = added.hidden(X)
        return np.linalg.solve(hidden.T @ hidden + reg * np.eye(hidden.shape[1]), hidden.T @ Y)

    t_incremental = median_time(incremental, repeats)  # each call on its own prepared copy
    t_refit = median_time(refit, max(3, repeats // 3))
    t_solve = median_time(solve_only, repeats)
    print(
        f"\n  BLS, N = {X.shape[0]}, {A.shape[1] - n_nodes} hidden nodes + {n_nodes} added (exact_ridge, reg = {reg:g})"
    )
    print(f"    {'add_enhancement_nodes':44s} {t_incremental * 1e3:9.3f} ms")
    print(
        f"    {'refit BLS from scratch with the same nodes':44s} {t_refit * 1e3:9.3f} ms   "
        f"incremental is {t_refit / t_incremental:6.1f}x faster"
    )
    print(
        f"    {'ridge solve of the output weights alone':44s} {t_solve * 1e3:9.3f} ms   "
        f"incremental is {t_solve / t_incremental:6.1f}x faster"
    )
    print(f"    max |W_incremental - W_scratch| / max |W| = {difference:.1e}")


def bench_block_pinv(n_nodes: int, repeats: int) -> None:
    # A BLS's feature matrix is 2000 x 400 here, past the default limit on a trajectory's
    # dimensions (256) that block_pinv_update checks A and its pseudo-inverse (400 x 2000) against:
    # raised for this run.
    from bidmp import get_limits, set_limits

    set_limits(max_dims=max(get_limits().max_dims, 4096))
    rng = np.random.default_rng(0)
    A = rng.normal(size=(2000, 400))
    A_pinv = np.linalg.pinv(A, rcond=PINV_RCOND)
    E = rng.normal(size=(2000, n_nodes))
    D, Bt, case = block_pinv_update(A, A_pinv, E)
    updated = np.vstack([A_pinv - D @ Bt, Bt])
    scratch = np.linalg.pinv(np.hstack([A, E]), rcond=PINV_RCOND)
    t_update = median_time(lambda: block_pinv_update(A, A_pinv, E), repeats)
    t_scratch = median_time(
        lambda: np.linalg.pinv(np.hstack([A, E]), rcond=PINV_RCOND), max(3, repeats // 3)
    )
    print(f"\n  Eq. 23-26 block pseudo-inverse, A 2000 x 400, E 2000 x {n_nodes} (case {case})")
    print(f"    {'block_pinv_update':44s} {t_update * 1e3:9.3f} ms")
    print(
        f"    {'numpy.linalg.pinv([A | E]) from scratch':44s} {t_scratch * 1e3:9.3f} ms   "
        f"update is {t_scratch / t_update:6.1f}x faster"
    )
    print(
        f"    max |difference| / max |pinv| = {np.abs(updated - scratch).max() / np.abs(scratch).max():.1e}"
    )


def bench_bidmp(repeats: int) -> None:
    """Bi-DMP learn and rollout on both protocols (the sides interleaved): the paper's (200 samples
    on normalised time, alpha = 100) and the defaults a user meets (the robot protocol, the same
    samples over 2 s in mm)."""
    demo = minimum_jerk(BATTERY_APPROACH_VIA, 200)
    stamps = np.linspace(0.0, 2.0, demo.shape[0])
    dmps = {
        "paper protocol": DMP(protocol="paper", alpha=100.0).fit(demo),
        "robot protocol (defaults)": DMP().fit(demo, stamps, units="mm"),
    }
    extension = extend_demonstration(demo, BATTERY_EXTENSION_TARGET, seed=0)
    models = {name: BiDMP(dmp).learn(extension.complete) for name, dmp in dmps.items()}
    sides = {}
    for name, dmp in dmps.items():
        sides[f"learn, {name}"] = lambda dmp=dmp: BiDMP(dmp).learn(extension.complete)
        model = models[name]
        sides[f"rollout, {name}"] = lambda model=model: model.rollout(BATTERY_EXTENSION_TARGET)
    times = interleaved_times(sides, repeats)
    print("\n  Bi-DMP on the 200-point 3-D battery approach, one extended demonstration")
    for name, elapsed in times.items():
        print(f"    {'BiDMP.' + name:44s} {elapsed * 1e3:9.3f} ms")
    for step in ("learn", "rollout"):
        paper, robot = times[f"{step}, paper protocol"], times[f"{step}, robot protocol (defaults)"]
        print(f"    {step}: the defaults take {robot / paper:.2f}x the paper protocol's time")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=15)
    args = parser.parse_args()
    # An addition costs O(N·c·m) against O(N·c²) for a refit: the ratio grows with c / m.
    for n_enhance in (300, 900):
        for n_nodes in (20, 50):
            bench_bls(n_nodes, args.repeats, n_enhance)
    for n_nodes in (20, 50):
        bench_block_pinv(n_nodes, args.repeats)
    bench_bidmp(args.repeats)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
