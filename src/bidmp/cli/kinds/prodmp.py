"""``bidmp fit --prodmp`` and ``bidmp rollout`` of a ProDMP: from ``--start`` at rest (default the
demonstrations' mean start) to ``--goal``, where it ends at tau (the goal weight moved to put it
there, as a DMP generalises), its weights conditioned exactly on the via-points first."""

from __future__ import annotations

import argparse

import numpy as np


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

    def roll(self, args: argparse.Namespace, model, goal, via) -> tuple:
        """(trajectory, mean, std, base, base_std, marks, times, demonstrations, units)."""
        start = model.start_ if args.start is None else np.asarray(args.start, dtype=float)
        conditioned = model
        for t, _ in via:
            if not 0.0 <= t <= model.duration_:
                raise ValueError(
                    f"--via at {t:g} s is outside the motion's {model.duration_:.4g} s"
                )
        if via:
            conditioned = conditioned.condition(
                [t for t, _ in via], np.array([p for _, p in via]), 0.0, start=start
            )
        dt = min(1.0 / (args.rate or 100.0), model.duration_)
        t = np.arange(int(model.duration_ / dt + 1e-9) + 1) * dt
        # --goal is where the motion ends: the goal weight moved to put the end there at tau
        attractor = None if goal is None else conditioned.goal_for_end(goal, start)
        trajectory = conditioned.trajectory(start, attractor, times=t)
        base = model.trajectory(start, times=t).y
        points = [(0.0, start)] + ([(t[-1], goal)] if goal is not None else []) + list(via)
        marks = (np.array([p[0] for p in points]), np.array([p[1] for p in points]))
        times = {"demonstrations": [], "mean": t, "conditioned": t}
        std, base_std = conditioned.std(times=t), model.std(times=t)
        return trajectory, trajectory.y, std, base, base_std, marks, times, [], model.units_


ADAPTER = _ProDMPAdapter()
