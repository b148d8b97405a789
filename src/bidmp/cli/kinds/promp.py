"""``bidmp fit --promp`` and ``bidmp rollout`` of a ProMP: conditioned exactly on the goal, the
start (by default the demonstrations' mean start) and the via-points at their phases."""

from __future__ import annotations

import argparse

import numpy as np


class _ProMPAdapter:
    fit_takes = frozenset({"n_kernels"})
    rollout_takes = frozenset({"start", "via"})

    def learn(self, args: argparse.Namespace, cls, demos, stamps, units) -> tuple:
        """(model, mean (200, D), std (200, D), the mean's times, what it is)."""
        model = cls(n_basis=args.n_kernels or 20).fit(demos, stamps, units=units)
        mean, std = model.mean(n_steps=200), np.sqrt(model.var(n_steps=200))
        t = np.linspace(0.0, model.duration_, 200)
        return model, mean, std, t, f"a ProMP ({model.n_basis} basis functions per dimension)"

    def roll(self, args: argparse.Namespace, model, goal, via) -> tuple:
        """(trajectory, mean, std, base, base_std, marks, times, demonstrations, units)."""
        points, values = [], []
        if args.start is not None or goal is not None:
            # the start held where it is asked (default: the demonstrations' mean start), so a
            # goal far off does not move it
            points.append(0.0)
            values.append(model.mean([0.0])[0] if args.start is None else args.start)
        if goal is not None:
            points.append(1.0)
            values.append(goal)
        for t, point in via:  # exact conditioning at the via-point's phase (its time / duration)
            if not 0.0 <= t <= model.duration_:
                raise ValueError(
                    f"--via at {t:g} s is outside the motion's {model.duration_:.4g} s"
                )
            points.append(t / model.duration_)
            values.append(point)
        conditioned = model.condition(points, np.asarray(values), 0.0) if points else model
        dt = 1.0 / (args.rate or 100.0)
        trajectory = conditioned.trajectory(dt=min(dt, conditioned.duration_))
        n = len(trajectory.t)
        mean, std = conditioned.mean(n_steps=n), np.sqrt(conditioned.var(n_steps=n))
        base, base_std = model.mean(n_steps=n), np.sqrt(model.var(n_steps=n))
        demos, units = [], model.units_
        marks = (np.array(points) * model.duration_, np.asarray(values)) if points else None
        times = {"demonstrations": [], "mean": trajectory.t, "conditioned": trajectory.t}
        return trajectory, mean, std, base, base_std, marks, times, demos, units


ADAPTER = _ProMPAdapter()
