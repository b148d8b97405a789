"""``bidmp fit --promp A B …``, ``--multi``, ``--prodmp``: a model from several demonstrations
(one flag per kind of :mod:`bidmp.primitives.registry` learned so); and ``bidmp rollout`` of one
(its mean, conditioned on the goal, the start and via-points as the kind can). Thin: read the
files, call the primitive, print."""

from __future__ import annotations

import argparse

from .inputs import demo_kind, read_input, refuse_options_not_taken

EXIT_OK = 0

# The DMP's fit options (the rest of bidmp fit's options are the demonstration's, read by
# read_input, or choose what is learned): a kind refuses those its adapter does not take
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


def _refuse_unused_fit_options(args: argparse.Namespace, kind, takes) -> None:
    for name in sorted(_DMP_FIT_OPTIONS - takes):
        if getattr(args, name, None) != args.unset_options.get(name):
            shown = ", ".join("--" + n.replace("_", "-") for n in sorted(takes)) or "no options"
            raise ValueError(
                f"--{name.replace('_', '-')} does not apply to --{kind.fit_flag}; it takes {shown}"
            )


def fit_several(args: argparse.Namespace, flag: str) -> int:
    """Learn the kind of ``--flag`` from several demonstrations."""
    import numpy as np

    from ..io.models import save_model

    kind = _kind_for(flag)
    if kind.cli is None:
        raise ValueError(
            f"--{kind.fit_flag}: the command line has no adapter for a {kind.name} (its options "
            "and its report); learn it in Python and save it with bidmp.io.save_model"
        )
    adapter = kind.adapter()
    _refuse_unused_fit_options(args, kind, adapter.fit_takes)
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
    model, mean, std, mean_t, what = adapter.learn(args, kind.load(), demos, stamps, units)
    # the figure on time: each demonstration on its own (over 1 s without stamps, as fitted)
    own = [np.linspace(0.0, 1.0, len(y)) if t is None else t - t[0] for y, t in zip(demos, times)]
    from ..io.runs import output_files

    with output_files() as outputs:  # -o and --plot together or not at all
        path = save_model(model, outputs.path(args.output))
        if args.plot:
            from ..plotting.trajectories import plot_distribution

            figure = plot_distribution(
                outputs.path(args.plot),
                demos,
                mean,
                std,
                title=f"{len(demos)} demonstrations",
                units=units or "",
                times={"demonstrations": own, "mean": mean_t},
            )
    unit = units or "units"
    lengths = ", ".join(str(len(y)) for y in demos)
    print(f"fitted {what} on {len(demos)} demonstrations ({lengths} samples)")
    print(
        f"  spread along the mean motion: median standard deviation "
        f"{float(np.median(np.linalg.norm(std, axis=1))):.4g} {unit}, largest "
        f"{float(np.linalg.norm(std, axis=1).max()):.4g} {unit}"
    )
    print(f"wrote {outputs.shown(path)}")
    if args.plot:
        print(f"wrote {outputs.shown(figure)}")
    return EXIT_OK


# What every kind's rollout acts on; the rest is its adapter's (rollout_takes)
_ALL_TAKE = {"goal", "rate", "plot", "output"}


def _refuse_unused(args: argparse.Namespace, kind, adapter) -> None:
    """Every rollout option the kind would not act on is refused, in one line (none is silently
    ignored); ``--goal``, ``--rate`` and ``--plot`` act on every kind."""
    # (an adapter may take an option only to refuse it with its own reason: not shown as taken)
    refuses_itself = getattr(adapter, "refuses_itself", frozenset())
    own = sorted(adapter.rollout_takes - refuses_itself)
    refuse_options_not_taken(
        args,
        _ALL_TAKE | adapter.rollout_takes,
        f"a {kind.name}",
        "--goal, --rate, " + ", ".join("--" + n for n in own) + " and --plot",
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
    """The mean motion, or the mean conditioned on ``--start``, ``--via`` and ``--goal`` as the
    kind's adapter conditions it (:mod:`bidmp.cli.kinds`), printed as what it is, with its ±2σ
    band in ``--plot``."""
    import numpy as np

    from ..io.trajectories import save_trajectory
    from ..primitives.registry import kind_of

    kind = kind_of(model)
    if kind.cli is None:
        raise ValueError(
            f"{args.model} holds a {kind.name}: the command line has no rollout adapter for it; "
            "roll it out in Python"
        )
    adapter = kind.adapter()
    _refuse_unused(args, kind, adapter)
    goal = None if args.goal is None else np.asarray(args.goal, dtype=float)
    via = _via_pairs(args, model)
    rolled = adapter.roll(args, model, goal, via)
    trajectory, std, units = rolled.trajectory, rolled.std, rolled.units
    from ..io.runs import output_files

    with output_files() as outputs:  # -o and --plot together or not at all
        path = save_trajectory(trajectory, outputs.path(args.output))
        if args.plot:
            from ..plotting.trajectories import plot_distribution

            times = rolled.times
            figure = plot_distribution(
                outputs.path(args.plot),
                rolled.demonstrations or [rolled.base],
                rolled.base,
                rolled.base_std,
                conditioned=rolled.mean,
                conditioned_std=std,
                points=rolled.marks,
                title=rolled.title or rolled.what,
                units=units,
                times=times
                if rolled.demonstrations
                else {**times, "demonstrations": [times["mean"]]},
            )
    unit = units or "units"
    rate = (len(trajectory.t) - 1) / trajectory.duration if trajectory.duration > 0 else 0.0
    print(
        f"rolled out {rolled.what}: {len(trajectory.t)} samples over {trajectory.duration:.4g} s "
        f"({rate:.4g} Hz), ends at {np.array2string(trajectory.y[-1], precision=4)}"
    )
    print(
        f"  spread (one standard deviation) up to {float(np.linalg.norm(std, axis=1).max()):.4g} "
        f"{unit}; at the end {float(np.linalg.norm(std[-1])):.3g} {unit}"
    )
    print(f"wrote {outputs.shown(path)}")
    if args.plot:
        print(f"wrote {outputs.shown(figure)}")
    return EXIT_OK
