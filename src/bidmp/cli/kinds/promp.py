"""``bidmp fit --promp`` and ``bidmp rollout`` of a ProMP: conditioned exactly on all at once — the
start at rest (``--start``, default the demonstrations' mean start), the via-points at their
phases (their time over the duration) and the goal at rest (``--goal``, default the mean end)."""

from __future__ import annotations

import argparse

import numpy as np

from . import Rolled, conditioned_on, conditioned_title, time_grid


class _ProMPAdapter:
    fit_takes = frozenset({"n_kernels"})
    rollout_takes = frozenset({"start", "via"})

    def learn(self, args: argparse.Namespace, cls, demos, stamps, units) -> tuple:
        """(model, mean (200, D), std (200, D), the mean's times, what it is)."""
        model = cls(n_basis=args.n_kernels or 20).fit(demos, stamps, units=units)
        mean, std = model.mean(n_steps=200), np.sqrt(model.var(n_steps=200))
        t = np.linspace(0.0, model.duration_, 200)
        return model, mean, std, t, f"a ProMP ({model.n_basis} basis functions per dimension)"

    def roll(self, args: argparse.Namespace, model, goal, via) -> Rolled:
        duration = model.duration_
        t = time_grid(duration, args.rate)
        end_time = float(t[-1])  # the duration, to the last whole step of the rate
        for when, _ in via:
            if not 0.0 <= when <= end_time:
                raise ValueError(f"--via at {when:g} s is outside the motion's {end_time:.4g} s")
        conditioned, what, marks = model, "the mean motion", None
        if goal is not None or args.start is not None or via:
            start = model.mean([0.0])[0] if args.start is None else np.asarray(args.start, float)
            end = model.mean([end_time / duration])[0] if goal is None else goal
            times = [0.0, *(when for when, _ in via), end_time]
            points = np.array([start, *(point for _, point in via), end])
            phases = np.array(times) / duration
            conditioned = model.condition(phases, points, 0.0, rest=phases[[0, -1]])
            what = conditioned_on(start, args.start is not None, via, end, goal is not None)
            marks = (np.array(times), points)
        trajectory = conditioned.trajectory(dt=t[1] - t[0])
        phase = trajectory.t / duration
        mean, std = conditioned.mean(phase), np.sqrt(conditioned.var(phase))
        base, base_std = model.mean(phase), np.sqrt(model.var(phase))
        times = {"demonstrations": [], "mean": trajectory.t, "conditioned": trajectory.t}
        title = what if conditioned is model else conditioned_title(via)
        return Rolled(
            trajectory, mean, std, base, base_std, marks, times, [], model.units_, what, title
        )


ADAPTER = _ProMPAdapter()
