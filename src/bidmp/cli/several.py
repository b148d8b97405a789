"""``bidmp fit --promp A B …`` and ``bidmp fit --multi A B …``: a model from several
demonstrations; and ``bidmp rollout`` of one (a ProMP conditioned exactly on the goal). Thin: read
the files, call :mod:`bidmp.primitives.promp` / :mod:`bidmp.primitives.multi`, print."""

from __future__ import annotations

import argparse

from .inputs import demo_kind, read_input, refuse_options_not_taken

EXIT_OK = 0


def fit_several(args: argparse.Namespace) -> int:
    """Learn a ProMP (``--promp``) or a several-demonstration DMP (``--multi``)."""
    import numpy as np

    from ..io.models import save_model
    from ..primitives.dmp import DMP
    from ..primitives.multi import MultiDMP
    from ..primitives.promp import ProMP

    paths = args.promp or args.multi
    if args.demo is not None:
        paths = [args.demo, *paths]
    if len(paths) < 2:
        raise ValueError(
            "--promp/--multi learn from several demonstrations: give two or more files"
        )
    demos, times, units = [], [], None
    for path in paths:
        args.demo, args._bag = path, None  # read_input reads args.demo's bag, cached per file
        if demo_kind(args) == "pose":
            raise ValueError(f"{path} holds poses: --promp/--multi learn positions or joints")
        y, t, file_units, how, *_ = read_input(path, args, timed=True)
        if units is not None and file_units != units:
            raise ValueError(
                f"{path} is in {file_units or 'no unit'}, {paths[0]} in {units or 'no unit'}"
            )
        units = file_units
        demos.append(y)
        times.append(t)
    stamps = None if any(t is None for t in times) else times
    if args.promp:
        model = ProMP(n_basis=args.n_kernels or 20).fit(demos, stamps, units=units)
        mean, std = model.mean(n_steps=200), np.sqrt(model.var(n_steps=200))
        mean_t = np.linspace(0.0, model.duration_, 200)
        kind = f"a ProMP ({model.n_basis} basis functions per dimension)"
    else:
        dmp = DMP(n_kernels=args.n_kernels, alpha=args.alpha, protocol=args.protocol)
        model = MultiDMP(dmp=dmp).fit(demos, stamps, units=units)
        motion = model.trajectory()
        mean, std, mean_t = motion.y, model.std(n_steps=len(motion.t)), motion.t
        kind = f"a DMP from several demonstrations ({model.dmp_.protocol} protocol)"
    # the figure on time: each demonstration on its own (over 1 s without stamps, as fitted)
    own = [np.linspace(0.0, 1.0, len(y)) if t is None else t - t[0] for y, t in zip(demos, times)]
    path = save_model(model, args.output)
    unit = units or "units"
    lengths = ", ".join(str(len(y)) for y in demos)
    print(f"fitted {kind} on {len(demos)} demonstrations ({lengths} samples)")
    print(
        f"  spread along the mean motion: median standard deviation "
        f"{float(np.median(np.linalg.norm(std, axis=1))):.4g} {unit}, largest "
        f"{float(np.linalg.norm(std, axis=1).max()):.4g} {unit}"
    )
    print(f"wrote {path}")
    if args.plot:
        from ..plotting.trajectories import plot_distribution

        figure = plot_distribution(
            args.plot,
            demos,
            mean,
            std,
            title=f"{len(demos)} demonstrations",
            units=units or "",
            times={"demonstrations": own, "mean": mean_t},
        )
        print(f"wrote {figure}")
    return EXIT_OK


# What a ProMP's and a DMP of several demonstrations' rollouts act on: --goal, --start (a DMP of
# several demonstrations refuses it itself: it starts where they did), --rate, --plot, -o, and:
_SEVERAL_TAKES = {"ProMP": {"via"}, "MultiDMP": {"via", "duration"}}
_BOTH_TAKE = {"goal", "start", "rate", "plot", "output"}


def _refuse_unused(args: argparse.Namespace, model, promp_class) -> None:
    """Every rollout option a ProMP or a DMP of several demonstrations would not act on is refused,
    in one line (none is silently ignored); ``--goal``, ``--start`` (a ProMP), ``--rate`` and
    ``--plot`` act on both."""
    kind = "ProMP" if isinstance(model, promp_class) else "MultiDMP"
    takes = _BOTH_TAKE | _SEVERAL_TAKES[kind]
    refuse_options_not_taken(
        args,
        takes,
        f"a {type(model).__name__}",
        f"--goal, {'--start, ' if kind == 'ProMP' else ''}--rate, "
        f"{', '.join('--' + n for n in sorted(_SEVERAL_TAKES[kind]))} and --plot",
    )


def _via_pairs(args: argparse.Namespace, model) -> list:
    """``--via T X ...`` as (t seconds, point) pairs, each with the model's dimensions."""
    import numpy as np

    width = model.n_dims_ if hasattr(model, "n_dims_") else model.dmp_.n_dims_
    pairs = []
    for index, values in enumerate(args.via or []):
        if len(values) != 1 + width:
            raise ValueError(
                f"--via #{index + 1} needs T and {width} coordinates, got {len(values)} numbers"
            )
        pairs.append((float(values[0]), np.asarray(values[1:], dtype=float)))
    return pairs


def rollout_several(args: argparse.Namespace, model) -> int:
    """The mean motion to ``--goal`` (a ProMP: conditioned exactly on the goal and on ``--start``,
    by default the demonstrations' mean start) with its ±2σ band in ``--plot``."""
    import numpy as np

    from ..io.trajectories import save_trajectory
    from ..primitives.promp import ProMP

    _refuse_unused(args, model, ProMP)
    goal = None if args.goal is None else np.asarray(args.goal, dtype=float)
    via = _via_pairs(args, model)
    if isinstance(model, ProMP):
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
    else:
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
    path = save_trajectory(trajectory, args.output)
    unit = units or "units"
    print(
        f"rolled out the mean motion: {len(trajectory.t)} samples over {trajectory.duration:.4g} s, "
        f"ends at {np.array2string(trajectory.y[-1], precision=4)}"
    )
    print(
        f"  spread (one standard deviation) up to {float(np.linalg.norm(std, axis=1).max()):.4g} "
        f"{unit}; at the end {float(np.linalg.norm(std[-1])):.3g} {unit}"
    )
    print(f"wrote {path}")
    if args.plot:
        from ..plotting.trajectories import plot_distribution

        figure = plot_distribution(
            args.plot,
            demos or [base],
            base,
            base_std,
            conditioned=mean,
            conditioned_std=std,
            points=marks,
            title="conditioned on the goal" if goal is not None else "the mean motion",
            units=units,
            times=times if demos else {**times, "demonstrations": [times["mean"]]},
        )
        print(f"wrote {figure}")
    return EXIT_OK
