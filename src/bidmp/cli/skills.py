"""The skill commands of the ``bidmp`` command line: fit, rollout, segment, extend, learn, for
positions and poses alike. Thin: read the files, call the library, print. (``bidmp.cli`` holds
the parser's other commands and the error handling.)"""

from __future__ import annotations

import argparse

from .common import progress_bars
from .inputs import (
    TIMED_INPUT,
    bag_options,
    demo_kind,
    demo_options,
    model_dmp,
    read_input,
    scene_option,
)
from .rollout import _add_rollout_arguments, cmd_rollout

EXIT_OK = 0


def _skills_model(args: argparse.Namespace, command: str):
    """The model ``extend`` and ``learn`` grow, as a Bi-DMP (a DMP becomes its skill 0): a
    :class:`bidmp.BiDMP` or, for pose models, a :class:`bidmp.CartesianBiDMP` (the model kind's
    ``incremental``, :mod:`bidmp.primitives.registry`)."""
    from ..io.models import load_model
    from ..primitives.registry import kind_of

    if not args.output.lower().endswith(".npz"):
        hint = (
            "; use --save-demo to write the extended demonstration" if command == "extend" else ""
        )
        raise ValueError(
            f"-o must be the Bi-DMP model file to write (.npz), got {args.output}{hint}"
        )
    model = load_model(args.model)
    kind = kind_of(model)
    if kind.incremental is None:
        raise ValueError(
            f"{args.model} holds a {type(model).__name__}; {command} needs a DMP, a Bi-DMP or a "
            "pose model"
        )
    return kind.grow(model)


def _demo_for(model, args: argparse.Namespace):
    """The demonstration for ``model`` (poses for a pose model), checked against its D."""
    from ..primitives.registry import kind_of

    poses = kind_of(model).poses
    kind = demo_kind(args)
    if poses and kind != "pose":
        raise ValueError(
            f"{args.model} holds a pose model; {args.demo} is not a pose file (a CSV header with qx,qy,qz,qw)"
        )
    if not poses and kind == "pose":
        raise ValueError(
            f"{args.demo} holds poses; {args.model} holds a position model: fit a pose model on it first"
        )
    y, _, units, how, *_ = read_input(args.demo, args, poses=poses, model=model, what=args.model)
    if not poses and y.shape[1] != model.n_dims_:
        raise ValueError(
            f"{args.demo} has D = {y.shape[1]} but the model {args.model} has D = {model.n_dims_}"
        )
    return y, units, how


# -- fit ------------------------------------------------------------------------------------------
def _dmp_params(args: argparse.Namespace) -> dict:
    return dict(
        n_kernels=args.n_kernels,
        alpha=args.alpha,
        beta=args.beta,
        K=args.K,
        alpha_phase=args.alpha_phase,
        tau=args.tau,
        regression=args.regression,
        protocol=args.protocol,
        keep_approach=getattr(args, "keep_approach", None),
    )


def cmd_fit(args: argparse.Namespace) -> int:
    import numpy as np

    from .._trajectory import resample_time
    from ..io.models import save_model
    from ..primitives.dmp import DMP
    from ..tasks.metrics import path_extent
    from .several import several_flags

    given = [flag for flag in several_flags() if getattr(args, flag.replace("-", "_"))]
    if given:
        from .several import fit_several

        if args.periodic or len(given) > 1:
            flags = ", ".join("--" + flag for flag in several_flags())
            raise ValueError(f"give one of --periodic, {flags}")
        return fit_several(args, given[0])
    if args.demo is None:
        raise ValueError(
            "give the demonstration to learn (or several after "
            + "/".join("--" + flag for flag in several_flags())
            + ")"
        )
    if args.periodic:
        from .rhythm import fit_periodic

        _refuse_with_periodic(args)
        return fit_periodic(args)
    if args.plot:
        raise ValueError(
            "fit --plot draws a rhythm (--periodic); for a DMP: bidmp rollout MODEL --plot PNG"
        )
    if demo_kind(args) == "pose":
        return _fit_poses(args)
    demonstration, times, units, how, names, held = read_input(args.demo, args, timed=True)
    dmp = DMP(**_dmp_params(args)).fit(
        demonstration, times, units=units, names=names, held_orientation=held
    )
    path = save_model(dmp, args.output)
    reproduction = dmp.trajectory()
    reference = resample_time(demonstration, dmp.n_steps_)
    error = float(
        np.sqrt(np.mean(np.sum((dmp.rollout()[: dmp.n_steps_] - reference) ** 2, axis=1)))
    )
    extent = path_extent(demonstration)
    if not np.isfinite(error):  # never print a non-finite result as a success
        raise ValueError(
            f"the fitted DMP does not reproduce {args.demo} (RMSE {error}); the settings are out of range"
        )
    unit = dmp.units_ or "units"
    print(f"fitted a DMP ({dmp.protocol} protocol) on {args.demo}, {how}")
    print(
        f"  T = {dmp.n_steps_} samples over {dmp.duration_:.4g} s ({dmp.sample_rate_:.4g} Hz), D = {dmp.n_dims_}, "
        f"units {dmp.units_ or '(not given)'}"
        + (f", joints {', '.join(dmp.names_)}" if dmp.names_ else "")
    )
    print(
        f"  start {np.array2string(dmp.start_, precision=4)}  goal {np.array2string(dmp.goal_, precision=4)}"
    )
    print(
        f"  reproduction RMSE {error:.4g} {unit} ({100 * error / extent:.3g} % of the extent {extent:.4g})"
    )
    print(
        f"  rollouts last {reproduction.duration:.4g} s (tau = {dmp.tau:g}; peak speed "
        f"{reproduction.peak_speed():.4g} {unit}/s, "
        f"peak acceleration {reproduction.peak_acceleration():.4g} {unit}/s^2)"
    )
    if dmp.protocol == "paper":
        print(
            f"  end-point gain c = {dmp.endpoint_gain():.4g}: a goal moved by d is missed by "
            f"c*d after {dmp.default_n_steps()} samples"
        )
    print(f"wrote {path}")
    return EXIT_OK


def _refuse_with_periodic(args: argparse.Namespace) -> None:
    """The discrete DMP's options, refused with --periodic (one line naming the first)."""
    for name, flag in (
        ("beta", "--beta"),
        ("K", "--K"),
        ("alpha_phase", "--alpha-phase"),
        ("regression", "--regression"),
        ("keep_approach", "--keep-approach"),
    ):
        if getattr(args, name, None) is not None:
            raise ValueError(f"{flag} is a discrete DMP's option; a rhythm (--periodic) has none")
    if args.protocol == "paper" or args.tau != 1.0:
        raise ValueError(
            "--protocol paper and --tau are a discrete DMP's; a rhythm runs at its frequency "
            "(bidmp rollout --frequency)"
        )


def _fit_poses(args: argparse.Namespace) -> int:
    """``bidmp fit`` on a pose recording: a CartesianDMP (prepared like positions unless --raw)."""
    import numpy as np

    from ..io.models import save_model
    from ..primitives.cartesian import CartesianDMP, angle_between
    from ..primitives.dmp import DMP

    poses, times, units, how, *_ = read_input(args.demo, args, poses=True, timed=True)
    model = CartesianDMP(DMP(**_dmp_params(args))).fit(poses, times, units=units)
    path = save_model(model, args.output)
    reproduction = model.rollout()[: len(poses)]
    n = len(reproduction)
    angles = np.degrees(angle_between(reproduction[:, 3:], poses[:n, 3:]))
    unit = model.units_ or "units"
    print(
        f"fitted a pose DMP (CartesianDMP, {model.position_.protocol} protocol) on {args.demo}, {how}"
    )
    print(
        f"  T = {len(poses)} samples over {model.duration_:.4g} s; units {model.units_ or '(not given)'}"
    )
    print(
        f"  reproduction: position RMSE "
        f"{np.sqrt(np.mean(np.sum((reproduction[:, :3] - poses[:n, :3]) ** 2, axis=1))):.4g} "
        f"{unit}, orientation RMS {np.sqrt(np.mean(angles**2)):.3g} deg"
    )
    print(f"wrote {path}")
    return EXIT_OK


# -- segment, extend, learn -----------------------------------------------------------------------
def cmd_segment(args: argparse.Namespace) -> int:
    import numpy as np

    from .._trajectory import arclength, resample_arclength
    from ..extension.segmentation import curvature, segment
    from ..tasks._tables import text_table

    poses = demo_kind(args) == "pose"
    y, _, units, how, *_ = read_input(args.demo, args, poses=poses)
    y = y[:, :3] if poses else y
    result = segment(y, eps_frac=args.eps_frac, method=args.method)
    points, kinds = result.points, result.kinds
    s = arclength(y)
    print(
        f"{args.demo}: {y.shape[0]} samples, D = {y.shape[1]}, {how}; {len(points)} segmentation point(s)"
    )
    if len(points):
        rows = [
            [
                str(point),
                "max" if kind > 0 else "min",
                f"{100 * s[point] / s[-1]:.1f}",
                np.array2string(y[point], precision=3),
            ]
            for point, kind in zip(points, kinds)
        ]
        print(
            text_table(
                ["index", "curvature", "arc length %", f"position ({units or 'units'})"], rows
            )
        )
    if args.plot:
        from ..extension.segmentation import MAX_ANALYSIS_POINTS
        from ..plotting.extension import plot_segmentation

        kappa = curvature(resample_arclength(y, min(y.shape[0], MAX_ANALYSIS_POINTS)))
        from pathlib import Path

        title = f"1D-SEG of {Path(args.demo).name}"
        print(
            f"wrote {plot_segmentation(args.plot, y, points, kinds, curvature=kappa, units=units, title=title)}"
        )
    return EXIT_OK


def _pose_target(target, demonstration):
    """A pose target (7,) from --target: x y z (the demonstrated goal's orientation) or all 7."""
    import numpy as np

    target = np.asarray(target, dtype=float)
    if target.shape == (3,):
        return np.concatenate([target, demonstration[-1, 3:]])
    if target.shape != (7,):
        raise ValueError(
            f"--target for a pose model takes x y z or x y z qx qy qz qw, got {target.size} numbers"
        )
    return target


def cmd_extend(args: argparse.Namespace) -> int:
    import numpy as np

    from .._trajectory import resample_time
    from ..extension.extend import extend_demonstration, extend_pose_demonstration
    from ..io.models import save_model
    from ..io.poses import save_poses
    from ..io.trajectories import save_trajectory
    from ..primitives.registry import kind_of
    from ..tasks.metrics import path_extent, rmse

    model = _skills_model(args, "extend")
    y, units, how = _demo_for(model, args)
    scene = scene_option(args, units)
    poses = kind_of(model).poses
    if poses:
        if args.approach != "keep":
            raise ValueError(
                "--approach paper is for positions; a pose extension keeps the approach"
            )
        with progress_bars():
            extension = extend_pose_demonstration(
                y, _pose_target(args.target, y), seed=args.seed, scene=scene
            )
        learned = extension.poses
    else:
        with progress_bars():
            extension = extend_demonstration(
                y, args.target, seed=args.seed, approach=args.approach, scene=scene
            )
        learned = extension.complete
    target = learned[-1]
    history = extension.similarity_history
    print(f"{args.demo}: {how}")
    print(
        f"segmentation points {extension.segmentation_points.tolist()}; imitating piece {extension.piece.index} "
        f"(samples {extension.piece.start}-{extension.piece.end}) from seg = "
        f"{np.array2string(y[extension.seg_index, :3], precision=3)}"
    )
    if len(history):
        print(
            f"G-PRM similarity per iteration: {' '.join(f'{v:.3f}' for v in history)} (best {extension.similarity:.3f})"
        )
    before = np.linalg.norm(model.rollout(target)[-1, :3] - target[:3])
    dmp = model_dmp(model)
    model.learn(learned, duration=extension.duration_for(dmp))
    rollout = model.rollout(target)
    # The skill runs as long as the extension lasts: compare over that part of the rollout.
    n_motion = max(int(round(dmp.n_steps_ * extension.duration_for(dmp) / dmp.duration_)), 2)
    error = rmse(resample_time(rollout[:n_motion, :3], len(extension.complete)), extension.complete)
    unit = dmp.units_ or "units"
    print(
        f"learned skill {model.n_skills - 1}: rollout to the target reproduces the extended demonstration with "
        f"RMSE {error:.4g} {unit} ({100 * error / path_extent(extension.complete):.3g} % of its extent)"
    )
    print(
        f"end-point error at the target: {before:.4g} before, "
        f"{np.linalg.norm(rollout[-1, :3] - target[:3]):.4g} {unit} after"
    )
    from ..io.runs import output_files

    with output_files() as outputs:  # -o, --save-demo and --plot together or not at all
        path = save_model(model, outputs.path(args.output))
        if args.save_demo:
            complete = learned  # sampled at the demonstration's period, as long as it lasts
            stamps = np.arange(len(complete)) * dmp.duration_ / (dmp.n_steps_ - 1)
            if poses:
                written = save_poses(
                    complete, outputs.path(args.save_demo), times=stamps, units=dmp.units_
                )
            else:
                from ..primitives.timing import Trajectory

                velocity = np.gradient(complete, stamps, axis=0)
                written = save_trajectory(
                    Trajectory(
                        stamps,
                        complete,
                        velocity,
                        np.gradient(velocity, stamps, axis=0),
                        dmp.units_,
                    ),
                    outputs.path(args.save_demo),
                )
        if args.plot:
            from ..plotting.extension import plot_extension

            figure = plot_extension(outputs.path(args.plot), extension, units=dmp.units_)
    print(f"wrote {outputs.shown(path)} ({model.n_skills} skills)")
    if args.save_demo:
        print(f"wrote the extended demonstration ({stamps[-1]:.4g} s) to {outputs.shown(written)}")
    if args.plot:
        print(f"wrote {outputs.shown(figure)}")
    return EXIT_OK


def cmd_learn(args: argparse.Namespace) -> int:
    import numpy as np

    from .._trajectory import resample_time, rmse
    from ..io.models import save_model

    model = _skills_model(args, "learn")
    y, _, how = _demo_for(model, args)
    model.learn(y)
    dmp = model_dmp(model)
    rollout = model.rollout(y[-1], start=y[0])
    error = rmse(rollout[: dmp.n_steps_, :3], resample_time(y[:, :3], dmp.n_steps_))
    print(f"{args.demo}: {how}")
    print(
        f"learned it as skill {model.n_skills - 1} (goal {np.array2string(y[-1], precision=3)}): reproduction RMSE "
        f"{error:.4g} {dmp.units_ or 'units'}"
    )
    print(f"wrote {save_model(model, args.output)} ({model.n_skills} skills)")
    return EXIT_OK


# -- the parser -----------------------------------------------------------------------------------
def add_commands(commands, parse_K, allow_outside_files) -> None:
    """The subcommands fit, rollout, segment, extend and learn of ``bidmp``'s parser."""
    fit = commands.add_parser(
        "fit",
        help="learn a DMP from a demonstration",
        description="Learn a DMP from one demonstration and save it as a model file (.npz). Time is in seconds: a CSV "
        "with a t column (or a timed .npy) gives the motion its real duration; without one the samples "
        "are taken as 1 s in all (the paper's convention). Lengths are in the demonstration's unit "
        "(--units names it, e.g. mm); velocities are units/s, accelerations units/s^2.",
        epilog=TIMED_INPUT,
    )
    fit.add_argument(
        "demo",
        metavar="DEMO",
        nargs="?",
        help="demonstration (.csv, .npy, or a ROS bag: a .bag file or a ROS 2 bag folder)",
    )
    fit.add_argument(
        "-o", "--output", required=True, metavar="MODEL", help="model file to write (.npz)"
    )
    demo_options(fit)
    bag_options(fit)
    fit.add_argument(
        "--protocol",
        choices=("robot", "paper"),
        default="robot",
        help="robot (default: goals reached, smooth starts, real time) or paper (the paper's fixed horizon)",
    )
    fit.add_argument(
        "--n-kernels",
        type=int,
        default=None,
        help="kernels per dimension (default: robot 100, paper 50)",
    )
    fit.add_argument(
        "--alpha",
        type=float,
        default=None,
        help="spring-damper gain alpha (default: robot 50, paper 25)",
    )
    fit.add_argument("--beta", type=float, default=None, help="spring ratio beta (default alpha/4)")
    fit.add_argument(
        "--K",
        type=parse_K,
        default=None,
        help="forcing gain: paper (K=alpha), pastor (K=alpha*beta) or a number (default: robot pastor, paper paper)",
    )
    fit.add_argument(
        "--alpha-phase",
        type=float,
        default=None,
        help="phase decay alpha_phase (default: robot 4, paper 1)",
    )
    fit.add_argument(
        "--tau",
        type=float,
        default=1.0,
        help="temporal scaling: rollouts take tau times the demonstration's duration (default 1)",
    )
    fit.add_argument(
        "--regression",
        "--fit",
        dest="regression",
        choices=("lwr", "ridge"),
        default=None,
        help="weight regression (default: robot ridge, paper lwr)",
    )
    fit.add_argument(
        "--keep-approach",
        action=argparse.BooleanOptionalAction,
        default=None,
        help="robot protocol (default on): a moved goal's offset is complete before the final approach "
        "(the straight tail into the goal), which then is a translated copy of the demonstrated one; "
        "--no-keep-approach spreads it over the whole motion (the progress gate)",
    )
    fit.add_argument(
        "--periodic",
        action="store_true",
        help="learn a rhythmic DMP from a recording of several periods (frequency estimated, "
        "transients cut, all periods at once); --n-kernels (default 50) and --alpha (default 25) apply",
    )
    from .several import several_flags

    for flag, summary in several_flags().items():  # one per registered kind (the registry's)
        fit.add_argument(f"--{flag}", nargs="+", metavar="DEMO", help=f"learn {summary}")
    fit.add_argument(
        "--plot",
        metavar="PNG",
        help="with --periodic: the learned cycle, its phase portrait and the spectrum; with "
        "--promp/--multi/--prodmp: the mean with its ±2σ band over the demonstrations",
    )
    # every option's value when it is not given: a kind that acts on only some refuses the rest
    fit.set_defaults(
        handler=cmd_fit,
        unset_options={
            action.dest: action.default
            for action in fit._actions
            if action.option_strings and action.dest != "help"
        },
    )

    rollout = commands.add_parser(
        "rollout",
        help="generate a timed trajectory from a model",
        description="Roll a saved model out to a goal and write the timed trajectory: t (s), positions (the model's "
        "units), velocities (units/s) and accelerations (units/s^2), as CSV columns t,x,y,z,vx,vy,vz,ax,ay,az "
        "or a .npy structured array with those fields. The motion lasts the demonstration's duration "
        "(times tau, or --duration) plus 10 % to come to rest (robot protocol).",
    )
    _add_rollout_arguments(rollout)
    allow_outside_files(rollout, shown=False)
    rollout.set_defaults(handler=cmd_rollout)

    _add_extension_commands(commands, allow_outside_files)


def _add_extension_commands(commands, allow_outside_files) -> None:
    """The subcommands segment, extend and learn."""
    seg = commands.add_parser(
        "segment",
        help="find the segmentation points of a demonstration (1D-SEG)",
        description="Cut a 2-D or 3-D demonstration at its curvature extrema (1D-SEG).",
        epilog=TIMED_INPUT,
    )
    seg.add_argument(
        "demo",
        metavar="DEMO",
        help="demonstration (.csv or .npy; a pose file is segmented by its positions)",
    )
    demo_options(seg)
    seg.add_argument(
        "--eps-frac",
        type=float,
        default=0.1,
        help="pruning threshold, fraction of the curvature range (default 0.1)",
    )
    seg.add_argument(
        "--method",
        choices=("persistence", "paper"),
        default="persistence",
        help="pruning rule (default persistence)",
    )
    seg.add_argument(
        "--plot", metavar="PNG", help="also write a figure with the points and the curvature"
    )
    seg.set_defaults(handler=cmd_segment)

    extend = commands.add_parser(
        "extend",
        help="learn a new target incrementally (1D-SEG + G-PRM + Bi-DMP)",
        description="Segment DEMO, grow an extended demonstration to the new target with G-PRM, "
        "and learn it incrementally on top of MODEL (a DMP or a Bi-DMP) as a new skill. "
        "Coordinates are in the model's units.",
        epilog=TIMED_INPUT,
    )
    extend.add_argument(
        "model",
        metavar="MODEL",
        help="a DMP (from 'bidmp fit') or Bi-DMP (from 'bidmp extend') model file",
    )
    extend.add_argument("demo", metavar="DEMO", help="the demonstration to extend (.csv or .npy)")
    extend.add_argument(
        "--target",
        type=float,
        nargs="+",
        required=True,
        metavar="X",
        help="new target coordinates (pose models: x y z, or x y z qx qy qz qw)",
    )
    extend.add_argument(
        "-o", "--output", required=True, metavar="MODEL2", help="Bi-DMP model file to write (.npz)"
    )
    extend.add_argument(
        "--save-demo",
        metavar="OUT",
        help="also write the extended demonstration, timed like a rollout (.csv or .npy)",
    )
    demo_options(extend)
    extend.add_argument("--seed", type=int, default=0, help="G-PRM random seed (default 0)")
    extend.add_argument(
        "--approach",
        choices=("keep", "paper"),
        default="keep",
        help="keep: keep the demonstrated final approach, translated, and grow only the transfer (default); "
        "paper: imitate the nearest piece down to the target (the paper's protocol)",
    )
    extend.add_argument(
        "--scene",
        metavar="FILE|NAME",
        help="grow the extension around the parts of this scenario's scene",
    )
    allow_outside_files(extend, shown=False)
    extend.add_argument("--plot", metavar="PNG", help="also write a figure")
    extend.set_defaults(handler=cmd_extend)

    learn = commands.add_parser(
        "learn",
        help="learn a further demonstration as a new skill (Bi-DMP)",
        description="Learn DEMO (e.g. another operator's recording) directly as a new skill on top "
        "of MODEL (a DMP or a Bi-DMP), without retraining. Coordinates in the model's units.",
        epilog=TIMED_INPUT,
    )
    learn.add_argument("model", metavar="MODEL", help="a DMP or Bi-DMP model file")
    learn.add_argument("demo", metavar="DEMO", help="the demonstration to learn (.csv or .npy)")
    learn.add_argument(
        "-o", "--output", required=True, metavar="MODEL2", help="Bi-DMP model file to write (.npz)"
    )
    demo_options(learn)
    learn.set_defaults(handler=cmd_learn)
