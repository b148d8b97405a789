"""``bidmp fit --periodic`` and ``bidmp rollout`` of a rhythmic model: thin, read the files, call
:mod:`bidmp.primitives.rhythmic`, print."""

from __future__ import annotations

import argparse

from .inputs import demo_kind, read_input, refuse_options_not_taken

EXIT_OK = 0

# what a rhythmic model's rollout acts on; every other rollout option is refused, some with a pointer
_RHYTHM_TAKES = {
    "rate",
    "cycles",
    "frequency",
    "amplitude",
    "anchor",
    "from_rest",
    "plot",
    "output",
}
_RHYTHM_HINTS = {
    "goal": "a rhythm has an anchor: --anchor",
    "duration": "a rhythm runs --cycles",
    "n_steps": "use --rate",
}


def fit_periodic(args: argparse.Namespace) -> int:
    """Learn a rhythmic DMP (positions, joints or poses) from a recording of several periods."""
    import numpy as np

    from ..io.models import save_model
    from ..primitives.rhythmic import RhythmicDMP
    from ..primitives.rhythmic_pose import RhythmicPoseDMP

    if args.n_kernels is not None and args.n_kernels < 2:
        raise ValueError(f"--n-kernels must be at least 2, got {args.n_kernels}")
    settings = {"n_kernels": args.n_kernels or 50, "alpha": args.alpha or 25.0}
    poses = demo_kind(args) == "pose"
    recording, times, units, how, *rest = read_input(args.demo, args, poses=poses, timed=True)
    if times is None:
        raise ValueError(
            f"{args.demo} has no time stamps: a rhythm's frequency needs them (a t column, in seconds)"
        )
    if poses:
        model = RhythmicPoseDMP(**settings).fit(recording, times, units=units)
        inner = model.rhythm_
    else:
        names = rest[0] if rest else None
        model = RhythmicDMP(**settings).fit(recording, times, units=units, names=names)
        inner = model
    estimate = model.estimate_
    from ..io.runs import output_files

    with output_files() as outputs:  # -o and --plot together or not at all
        path = save_model(model, outputs.path(args.output))
        if args.plot:
            from ..plotting.trajectories import plot_rhythm

            motion = inner.trajectory(cycles=2, dt=min(0.001, 0.01 / estimate.frequency))
            shown = recording[:, :3] if poses else recording
            scale = model.scales_[0] if poses else 1.0
            figure = plot_rhythm(
                outputs.path(args.plot),
                shown,
                times,
                _scaled(motion, scale, 3 if poses else None),
                estimate.frequency,
                estimate.uncertainty,
                title=f"rhythm learned from {args.demo}",
                units=units,
            )
    unit = units or "units"
    kind = "pose " if poses else ""
    print(f"fitted a rhythmic {kind}DMP on {args.demo}, {how}")
    print(
        f"  frequency {estimate.frequency:.6g} Hz ± {estimate.uncertainty:.2g} (one standard error; "
        f"period {1 / estimate.frequency:.4g} s), {estimate.n_harmonics} harmonics"
    )
    print(
        f"  kept {estimate.periods} whole periods, {estimate.start:.3g}-{estimate.end:.3g} s of the motion "
        f"read (transients cut); period-to-period spread {100 * estimate.spread:.3g} % of the amplitude"
    )
    if poses:
        position = np.array2string(inner.amplitude_[:3] * model.scales_[0], precision=4)
        rotation = np.array2string(np.degrees(inner.amplitude_[3:] * model.scales_[1]), precision=3)
        print(
            f"  amplitude (half the peak-to-peak): position {position} {unit}, rotation vector "
            f"{rotation} deg about the mean orientation"
        )
    else:
        amplitude = np.array2string(inner.amplitude_, precision=4)
        print(f"  amplitude (half the peak-to-peak) {amplitude} {unit}")
    print(f"wrote {outputs.shown(path)}")
    if args.plot:
        print(f"wrote {outputs.shown(figure)}")
    return EXIT_OK


def _scaled(motion, scale: float, columns):
    from ..primitives.timing import Trajectory

    pick = slice(None) if columns is None else slice(0, columns)
    return Trajectory(
        motion.t, motion.y[:, pick] * scale, motion.yd[:, pick] * scale, motion.ydd[:, pick] * scale
    )


def rollout_periodic(args: argparse.Namespace, model) -> int:
    """``bidmp rollout`` of a rhythmic model: --cycles at --frequency, --amplitude, --anchor;
    --from-rest starts at rest at the anchor and ends there."""
    import numpy as np

    from ..io.poses import save_poses
    from ..io.trajectories import save_trajectory
    from ..primitives.registry import kind_of

    refuse_options_not_taken(
        args,
        _RHYTHM_TAKES,
        "a rhythmic model",
        "--cycles, --frequency, --amplitude, --anchor, --from-rest, --rate and --plot",
        _RHYTHM_HINTS,
    )
    poses = kind_of(model).poses
    rate = 1000.0 if args.rate is None else args.rate
    if not 0 < rate <= 100_000:
        raise ValueError(f"--rate must be in (0, 100000] Hz, got {rate:g}")
    cycles = 1.0 if args.cycles is None else args.cycles
    amplitude = 1.0 if args.amplitude is None else args.amplitude
    options = {"dt": 1.0 / rate, "frequency": args.frequency, "amplitude": amplitude}
    if args.anchor is not None:
        options["anchor"] = args.anchor
    if args.from_rest:
        if poses:
            raise ValueError("--from-rest is for position and joint rhythms (not poses yet)")
        trajectory = model.run(cycles, **options)
    else:
        trajectory = model.trajectory(cycles, **options)
    from ..io.runs import output_files

    with output_files() as outputs:  # -o and --plot together or not at all
        path = (save_poses if poses else save_trajectory)(trajectory, outputs.path(args.output))
        if args.plot:
            from ..plotting.trajectories import plot_rollout

            figure = plot_rollout(
                outputs.path(args.plot),
                trajectory.y,
                trajectory,
                title="rhythm",
                units=model.units_,
            )
    unit = model.units_ or "units"
    frequency = model.frequency_ if args.frequency is None else args.frequency
    print(
        f"rolled out {len(trajectory)} samples over {trajectory.duration:.4g} s ({rate:.4g} Hz): "
        f"{cycles:g} cycles at {frequency:.4g} Hz, amplitude x{amplitude:g}"
        + (", from rest and back to rest at the anchor" if args.from_rest else "")
    )
    print(
        f"  peak speed {trajectory.peak_speed():.4g} {unit}/s, peak acceleration "
        f"{trajectory.peak_acceleration():.4g} {unit}/s^2, span "
        f"{np.array2string(np.ptp(trajectory.y, axis=0), precision=4)} {unit}"
    )
    print(f"wrote {outputs.shown(path)} (columns {','.join(trajectory.columns()[0])})")
    if args.plot:
        print(f"wrote {outputs.shown(figure)}")
    return EXIT_OK
