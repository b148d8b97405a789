"""bidmp's ProDMP against MP_PyTorch's (``mp_pytorch`` 0.1.4 on torch's CPU build, float64) on
equal settings, in one run: equal trajectories, then the speed of 1000 batched and 1000
goal-conditioned rollouts side by side, with the floor of one basis product plus writing the
output.

    make mp-pytorch     # the side environment .venv-mpt: torch 2.13.0 (CPU), mp_pytorch, bidmp
    .venv-mpt/bin/python benchmarks/bench_prodmp.py [--rounds 7] [--goals 1000] [--steps 1000]

Equality: random weights, goals and boundary conditions (3 dimensions, 10 basis functions, tau
3 s, dt 0.01 s), positions and velocities of both, the largest difference over the motion's
extent (target 1e-6); and both learning from the same demonstration (sampled at dt, so their
start-velocity conventions agree). Speed: the sides interleaved round by round, medians, ratios.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np

from bidmp.primitives.prodmp import ProDMP

SETTINGS = {"n_basis": 10, "alpha": 25.0, "alpha_phase": 3.0, "bandwidth_factor": 3.0}
TAU, DT, DIMS = 3.0, 0.01, 3


def _mp_pytorch():
    try:
        import torch
        from mp_pytorch.mp import MPFactory
    except ImportError:
        sys.exit("needs torch and mp_pytorch: make mp-pytorch, then run with .venv-mpt/bin/python")
    args = {
        "num_basis": SETTINGS["n_basis"],
        "basis_bandwidth_factor": SETTINGS["bandwidth_factor"],
        "num_basis_outside": 0,
        "alpha": SETTINGS["alpha"],
        "alpha_phase": SETTINGS["alpha_phase"],
        "dt": DT,
        "relative_goal": False,
        "auto_scale_basis": False,
    }
    mp = MPFactory.init_mp(
        mp_type="prodmp", mp_args=args, num_dof=DIMS, tau=TAU, dtype=torch.float64
    )
    return torch, mp


def _ours(times: np.ndarray, demo: np.ndarray) -> ProDMP:
    return ProDMP(tau=TAU, dt=DT, **SETTINGS).fit(demo, [times])


def equality(torch, mp) -> list[str]:
    rng = np.random.default_rng(11)
    times = np.arange(0.0, TAU + 1e-9, DT)
    demo = np.cumsum(rng.normal(0.0, 1.0, (len(times), DIMS)), axis=0)
    demo = np.apply_along_axis(lambda c: np.convolve(c, np.ones(25) / 25, "same"), 0, demo)
    ours = _ours(times, demo)
    lines = []
    worst = 0.0
    for _ in range(5):
        params = rng.normal(0.0, 50.0, DIMS * (SETTINGS["n_basis"] + 1))
        start, velocity = rng.normal(0.0, 5.0, DIMS), rng.normal(0.0, 5.0, DIMS)
        query = np.linspace(0.0, TAU, 1000)
        theirs_pos = mp.get_traj_pos(
            times=torch.as_tensor(query),
            params=torch.as_tensor(params),
            init_time=torch.tensor(0.0, dtype=torch.float64),
            init_pos=torch.as_tensor(start),
            init_vel=torch.as_tensor(velocity),
        ).numpy()
        theirs_vel = mp.get_traj_vel().numpy()
        motion = ours.trajectory(start=start, start_velocity=velocity, times=query, weights=params)
        extent = np.ptp(theirs_pos, axis=0).max()
        worst = max(
            worst,
            np.abs(motion.y - theirs_pos).max() / extent,
            np.abs(motion.yd - theirs_vel).max() / np.ptp(theirs_vel, axis=0).max(),
        )
    lines.append(f"given weights: largest difference / extent {worst:.2e} (target 1e-6)")
    mp.learn_mp_params_from_trajs(torch.as_tensor(times)[None], torch.as_tensor(demo)[None])
    learned = mp.get_params().numpy()[0]
    theirs = mp.get_traj_pos().numpy()[0]
    mine = ours.trajectory(start=demo[0], start_velocity=(demo[1] - demo[0]) / DT, times=times).y
    extent = np.ptp(demo, axis=0).max()
    lines.append(
        f"learned from one demonstration: weights differ by "
        f"{np.abs(learned - ours.weights_[0]).max() / np.abs(learned).max():.2e} "
        f"of the largest, trajectories by {np.abs(mine - theirs).max() / extent:.2e} of the extent"
    )
    return lines


def speed(torch, mp, rounds: int, n_goals: int, n_steps: int) -> list[str]:
    rng = np.random.default_rng(3)
    times = np.arange(0.0, TAU + 1e-9, DT)
    demos = [
        np.cumsum(rng.normal(0.0, 1.0, (len(times), DIMS)), axis=0) + rng.normal(0, 3, DIMS)
        for _ in range(6)
    ]
    ours = ProDMP(tau=TAU, dt=DT, cov_reg=1e-6, **SETTINGS).fit(demos, [times] * 6)
    query = np.linspace(0.0, TAU, n_steps)
    goals = rng.normal(0.0, 10.0, (n_goals, DIMS))
    start = ours.start_[None]
    size = SETTINGS["n_basis"] + 1
    H = ours.basis_.boundary_maps(query, 0.0)[4]
    batch = np.repeat(ours.weight_mean_.reshape(1, DIMS, size), n_goals, axis=0)

    def floor():  # one basis product over every goal and dimension, written out (B, T, D)
        out = np.empty((n_goals, n_steps, DIMS))
        out[...] = (
            (batch.reshape(-1, size) @ H.T).reshape(n_goals, DIMS, n_steps).transpose(0, 2, 1)
        )
        return out

    mean = torch.as_tensor(ours.weight_mean_)
    cov = torch.as_tensor(ours.weight_cov_)
    goal_index = torch.arange(DIMS) * size + size - 1
    t_query = torch.as_tensor(query).expand(n_goals, -1)
    t_goals = torch.as_tensor(goals)
    init = dict(
        init_time=torch.zeros(n_goals, dtype=torch.float64),
        init_pos=torch.as_tensor(start).expand(n_goals, -1),
        init_vel=torch.zeros(n_goals, DIMS, dtype=torch.float64),
    )

    def theirs_batched():
        params = mean.expand(n_goals, -1).clone()
        params[:, goal_index] = t_goals
        mp.reset()
        return mp.get_traj_pos(times=t_query, params=params, **init)

    def theirs_conditioned():  # the same exact conditioning on the goal, in torch
        gain = torch.linalg.solve(cov[goal_index][:, goal_index], cov[goal_index]).T
        params = mean[None] + (t_goals - mean[goal_index]) @ gain.T
        mp.reset()
        return mp.get_traj_pos(times=t_query, params=params, **init)

    sides = {
        "floor (one product + output)": floor,
        "bidmp batched": lambda: ours.rollouts(start, goals, query),
        "mp_pytorch batched": theirs_batched,
        "bidmp conditioned": lambda: ours.rollouts(start, goals, query, conditioned=True),
        "mp_pytorch conditioned": theirs_conditioned,
    }
    check = np.abs(ours.rollouts(start, goals, query) - theirs_batched().numpy()).max()
    samples = {name: [] for name in sides}
    for function in sides.values():
        function()
    for _ in range(rounds):
        for name, function in sides.items():
            began = time.perf_counter()
            function()
            samples[name].append(time.perf_counter() - began)
    med = {name: statistics.median(v) for name, v in samples.items()}
    lines = [
        f"{n_goals} goals, T = {n_steps}, D = {DIMS}, {rounds} rounds (batched sides agree to {check:.1e})"
    ]
    for name, value in med.items():
        lines.append(f"  {name:30s} {1e3 * value:8.2f} ms")
    lines.append(
        f"  bidmp batched / floor {med['bidmp batched'] / med['floor (one product + output)']:.2f}x; "
        f"conditioned / floor {med['bidmp conditioned'] / med['floor (one product + output)']:.2f}x; "
        f"mp_pytorch / bidmp: batched {med['mp_pytorch batched'] / med['bidmp batched']:.1f}x, "
        f"conditioned {med['mp_pytorch conditioned'] / med['bidmp conditioned']:.1f}x"
    )
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--goals", type=int, default=1000)
    parser.add_argument("--steps", type=int, default=1000)
    args = parser.parse_args()
    torch, mp = _mp_pytorch()
    from threadpoolctl import threadpool_limits

    torch.set_num_threads(1)  # both sides on one thread: torch's and NumPy's BLAS
    print(f"load average {os.getloadavg()}; torch {torch.__version__}; one thread each")
    with threadpool_limits(1):
        for line in equality(torch, mp) + speed(torch, mp, args.rounds, args.goals, args.steps):
            print(line)


if __name__ == "__main__":
    main()
