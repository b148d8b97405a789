"""``bidmp fit --multi`` and ``bidmp rollout`` of a DMP from several demonstrations: the mean
motion to the goal (it starts where the demonstrations did), through the via-points, stretched
to ``--duration``."""

from __future__ import annotations

import argparse

import numpy as np

from . import Rolled, shown


class _MultiDMPAdapter:
    fit_takes = frozenset({"n_kernels", "alpha", "protocol"})
    rollout_takes = frozenset({"via", "duration", "start"})
    refuses_itself = frozenset({"start"})  # it starts where the demonstrations did: said so

    def learn(self, args: argparse.Namespace, cls, demos, stamps, units) -> tuple:
        """(model, mean, std, the mean's times, what it is): at the DMP's own rate."""
        from ...primitives.dmp import DMP

        dmp = DMP(n_kernels=args.n_kernels, alpha=args.alpha, protocol=args.protocol)
        model = cls(dmp=dmp).fit(demos, stamps, units=units)
        motion = model.trajectory()
        std = model.std(n_steps=len(motion.t))
        what = f"a DMP from several demonstrations ({model.dmp_.protocol} protocol)"
        return model, motion.y, std, motion.t, what

    def roll(self, args: argparse.Namespace, model, goal, via) -> Rolled:
        if args.start is not None:
            raise ValueError("--start: a DMP from several demonstrations starts where they did")
        options = {}
        if args.rate is not None:
            options["dt"] = 1.0 / args.rate
        if args.duration is not None:
            options["duration"] = args.duration
        if via:
            options["via"] = via
        trajectory = model.trajectory(goal, **options)
        mean, std = trajectory.y, model.std(goal, n_steps=len(trajectory.t))
        plain = model.trajectory()
        base, base_std = plain.y, model.std(n_steps=len(plain.t))
        demos, units = (
            list(model.aligned_) if "aligned_" in model.__dict__ else [],
            model.dmp_.units_,
        )
        # the demonstrations as fitted: on the mean one's time (their mean duration)
        fitted = np.linspace(0.0, model.dmp_.duration_, len(demos[0])) if demos else None
        times = {
            "demonstrations": [fitted] * len(demos),
            "mean": plain.t,
            "conditioned": trajectory.t,
        }
        marks = None if goal is None else (trajectory.t[-1:], goal[None])
        what = "the mean motion" + ("" if goal is None else f" to the goal {shown(goal)}")
        if via:
            what += " through " + ", ".join(f"{shown(point)} at {t:g} s" for t, point in via)
        title = what if len(what) <= 120 else f"the mean motion through {len(via)} via-points"
        return Rolled(
            trajectory, mean, std, base, base_std, marks, times, demos, units, what, title
        )


ADAPTER = _MultiDMPAdapter()
