"""``bidmp fit --prodmp`` and ``bidmp rollout`` of a ProDMP: from ``--start`` at rest (default the
demonstrations' mean start) through the ``--via`` points to ``--goal`` at rest (default where the
mean motion from that start ends), the weights conditioned on all of them at once: each via-point
at its time, the end at tau, the velocity there 0 and the goal weight (the attractor) the goal,
so the motion ends there at rest and stays."""

from __future__ import annotations

import argparse

import numpy as np

from . import Rolled, conditioned_on, conditioned_title, time_grid


class _ProDMPAdapter:
    fit_takes = frozenset({"n_kernels", "alpha", "alpha_phase"})
    rollout_takes = frozenset({"start", "via"})

    def learn(self, args: argparse.Namespace, cls, demos, stamps, units) -> tuple:
        """(model, mean (200, D), std (200, D), the mean's times, what it is)."""
        params = {"n_basis": args.n_kernels or 10}
        for name in ("alpha", "alpha_phase"):
            if getattr(args, name) is not None:
                params[name] = getattr(args, name)
        model = cls(**params).fit(demos, stamps, units=units)
        t = np.linspace(0.0, model.duration_, 200)
        mean, std = model.trajectory(times=t).y, model.std(times=t)
        return model, mean, std, t, f"a ProDMP ({model.n_basis} basis functions per dimension)"

    def roll(self, args: argparse.Namespace, model, goal, via) -> Rolled:
        t = time_grid(model.duration_, args.rate)
        end_time = float(t[-1])  # tau, to the last whole step of the rate
        for when, _ in via:
            if not 0.0 < when <= end_time:
                raise ValueError(
                    f"--via at {when:g} s is outside the motion's (0, {end_time:.4g}] s (its start "
                    "is --start)"
                )
        start = model.start_ if args.start is None else np.asarray(args.start, dtype=float)
        base = model.trajectory(start, times=t)
        conditioned, what, points = model, "the mean motion", [(0.0, start), *via]
        if goal is not None or args.start is not None or via:
            end = base.y[-1] if goal is None else goal
            conditioned = model.condition(
                [when for when, _ in via] + [end_time],
                np.array([point for _, point in via] + [end]),
                0.0,
                start=start,
                rest=[end_time],
                goal=end,
            )
            what = conditioned_on(start, args.start is not None, via, end, goal is not None)
            points.append((end_time, end))
        trajectory = conditioned.trajectory(start, times=t)
        marks = (np.array([p[0] for p in points]), np.array([p[1] for p in points]))
        times = {"demonstrations": [], "mean": t, "conditioned": t}
        std, base_std = conditioned.std(times=t), model.std(times=t)
        title = what if conditioned is model else conditioned_title(via)
        return Rolled(
            trajectory, trajectory.y, std, base.y, base_std, marks, times, [], model.units_, what,
            title,
        )  # fmt: skip


ADAPTER = _ProDMPAdapter()
