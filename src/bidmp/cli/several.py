"""``bidmp fit --promp A B …``, ``--multi``, ``--prodmp``: a model from several demonstrations
(one flag per kind of :mod:`bidmp.primitives.registry` learned so); and ``bidmp rollout`` of one
(its mean, conditioned on the goal, the start and via-points as the kind can). Thin: read the
files, call the primitive, print."""

from __future__ import annotations

import argparse

from .inputs import demo_kind, read_input, refuse_options_not_taken

EXIT_OK = 0

# The fit options each kind acts on besides the demonstrations' own (units, columns, stamps …,
# what read_input reads) and -o/--plot: every other one is refused, in one line.
_FIT_TAKES = {
    "ProMP": {"n_kernels"},
    "MultiDMP": {"n_kernels", "alpha", "protocol"},
    "ProDMP": {"n_kernels", "alpha", "alpha_phase"},
}
# The DMP's fit options (the rest of bidmp fit's options are the demonstration's, read by
# read_input, or choose what is learned)
_DMP_FIT_OPTIONS = {
    "protocol", "n_kernels", "alpha", "beta", "K", "alpha_phase", "tau", "regression",
    "keep_approach",
}  # fmt: skip


def several_flags() -> dict[str, str]:
    """``bidmp fit``'s flags for the kinds learned from several demonstrations: flag -> what it
    learns (from the model kinds' registry)."""
    from ..primitives.registry import MODEL_KINDS

    return {kind.fit_flag: kind.summary for kind in MODEL_KINDS.values() if kind.fit_flag}


def _kind_for(flag: str):
    from ..primitives.registry import MODEL_KINDS

    return next(kind for kind in MODEL_KINDS.values() if kind.fit_flag == flag)


def _refuse_unused_fit_options(args: argparse.Namespace, kind) -> None:
    takes = _FIT_TAKES.get(kind.name, set())
    for name in sorted(_DMP_FIT_OPTIONS - takes):
        if getattr(args, name, None) != args.unset_options.get(name):
            shown = ", ".join("--" + n.replace("_", "-") for n in sorted(takes)) or "no options"
            raise ValueError(
                f"--{name.replace('_', '-')} does not apply to --{kind.fit_flag}; it takes {shown}"
            )


def _learn(kind, args: argparse.Namespace, demos, stamps, units):
    """(model, mean (200, D), std (200, D), the mean's times, what it is) of ``kind``."""
    import numpy as np

    cls = kind.load()
    if kind.name == "MultiDMP":
        from ..primitives.dmp import DMP

        dmp = DMP(n_kernels=args.n_kernels, alpha=args.alpha, protocol=args.protocol)
        model = cls(dmp=dmp).fit(demos, stamps, units=units)
        motion = model.trajectory()
        std = model.std(n_steps=len(motion.t))
        return (
            model,
            motion.y,
            std,
            motion.t,
            (f"a DMP from several demonstrations ({model.dmp_.protocol} protocol)"),
        )
    if kind.name == "ProDMP":
        params = {"n_basis": args.n_kernels or 10}
        for name in ("alpha", "alpha_phase"):
            if getattr(args, name) is not None:
                params[name] = getattr(args, name)
        model = cls(**params).fit(demos, stamps, units=units)
        t = np.linspace(0.0, model.duration_, 200)
        mean, std = model.trajectory(times=t).y, model.std(times=t)
        return model, mean, std, t, f"a ProDMP ({model.n_basis} basis functions per dimension)"
    model = cls(n_basis=args.n_kernels or 20).fit(demos, stamps, units=units)
    mean, std = model.mean(n_steps=200), np.sqrt(model.var(n_steps=200))
    return (
        model,
        mean,
        std,
        np.linspace(0.0, model.duration_, 200),
        (f"a ProMP ({model.n_basis} basis functions per dimension)"),
    )


def fit_several(args: argparse.Namespace, flag: str) -> int:
    """Learn the kind of ``--flag`` from several demonstrations."""
    import numpy as np

    from ..io.models import save_model

    kind = _kind_for(flag)
    if kind.name not in _FIT_TAKES:
        raise ValueError(
            f"--{kind.fit_flag}: the command line has no adapter for a {kind.name} (its options "
            "and its report); learn it in Python and save it with bidmp.io.save_model"
        )
    _refuse_unused_fit_options(args, kind)
    paths = getattr(args, flag.replace("-", "_"))
    if args.demo is not None:
        paths = [args.demo, *paths]
    if len(paths) < 2:
        raise ValueError(f"--{flag} learns from several demonstrations: give two or more files")
    demos, times, units = [], [], None
    for path in paths:
        args.demo, args._bag = path, None  # read_input reads args.demo's bag, cached per file
        if demo_kind(args) == "pose":
            raise ValueError(f"{path} holds poses: --{flag} learns positions or joints")
        y, t, file_units, how, *_ = read_input(path, args, timed=True)
        if units is not None and file_units != units:
            raise ValueError(
                f"{path} is in {file_units or 'no unit'}, {paths[0]} in {units or 'no unit'}"
            )
        units = file_units
        demos.append(y)
        times.append(t)
    stamps = None if any(t is None for t in times) else times
    model, mean, std, mean_t, what = _learn(kind, args, demos, stamps, units)
    # the figure on time: each demonstration on its own (over 1 s without stamps, as fitted)
    own = [np.linspace(0.0, 1.0, len(y)) if t is None else t - t[0] for y, t in zip(demos, times)]
    path = save_model(model, args.output)
    unit = units or "units"
    lengths = ", ".join(str(len(y)) for y in demos)
    print(f"fitted {what} on {len(demos)} demonstrations ({lengths} samples)")
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


# What a rollout of each kind acts on besides --goal, --rate, --plot and -o: --start where the
# kind can start anywhere (a DMP of several demonstrations starts where they did), --via where it
# conditions on via-points, --duration where it can be stretched.
_SEVERAL_TAKES = {
    "ProMP": {"start", "via"},
    "MultiDMP": {"via", "duration"},
    "ProDMP": {"start", "via"},
}
_ALL_TAKE = {"goal", "rate", "plot", "output"}


def _refuse_unused(args: argparse.Namespace, kind) -> None:
    """Every rollout option the kind would not act on is refused, in one line (none is silently
    ignored); ``--goal``, ``--rate`` and ``--plot`` act on every kind."""
    own = _SEVERAL_TAKES[kind.name]
    refuse_options_not_taken(
        args,
        _ALL_TAKE | own | ({"start"} if kind.name == "MultiDMP" else set()),
        f"a {kind.name}",
        "--goal, --rate, " + ", ".join("--" + n for n in sorted(own)) + " and --plot",
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
    from ..primitives.registry import kind_of

    kind = kind_of(model)
    if kind.name not in _SEVERAL_TAKES:
        raise ValueError(
            f"{args.model} holds a {kind.name}: the command line has no rollout adapter for it; "
            "roll it out in Python"
        )
    _refuse_unused(args, kind)
    goal = None if args.goal is None else np.asarray(args.goal, dtype=float)
    via = _via_pairs(args, model)
    if kind.name == "ProDMP":
        trajectory, mean, std, base, base_std, marks, times = _prodmp_rollout(
            args, model, goal, via
        )
        demos, units = [], model.units_
    elif kind.name == "ProMP":
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


def _prodmp_rollout(args: argparse.Namespace, model, goal, via) -> tuple:
    """A ProDMP's mean motion from ``--start`` (default the demonstrations' mean start, at rest)
    to ``--goal`` (its end at tau: the goal weight moved to put it there, as a DMP generalises),
    its weights conditioned exactly on the via-points first; with the spread."""
    import numpy as np

    start = model.start_ if args.start is None else np.asarray(args.start, dtype=float)
    conditioned = model
    for t, _ in via:
        if not 0.0 <= t <= model.duration_:
            raise ValueError(f"--via at {t:g} s is outside the motion's {model.duration_:.4g} s")
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
    return (
        trajectory,
        trajectory.y,
        conditioned.std(times=t),
        base,
        model.std(times=t),
        marks,
        times,
    )
