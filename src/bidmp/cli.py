"""The ``bidmp`` command line: a thin shell over the library.

Parse, call the library, print, exit. Bad input of any kind ends with a one-line message on
stderr and exit code 2, never a traceback (``--debug`` shows it). NumPy and the library are
imported inside the command handlers so that ``bidmp --help`` starts fast.
"""

from __future__ import annotations

import argparse
import json
import logging
import sys
from collections.abc import Sequence

from . import __version__

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_BAD_INPUT = 2
_MAX_SEEDS = 200  # = bidmp.reproduce.MAX_SEEDS (not imported: --help must not load NumPy)


class _Parser(argparse.ArgumentParser):
    """argparse, but usage errors are one line (plus a pointer to --help), exit code 2."""

    def error(self, message: str):  # noqa: D401 - argparse API
        self.exit(EXIT_BAD_INPUT, _one_line(f"{self.prog}: error: {message} (see '{self.prog} --help')") + "\n")


def _parse_K(text: str):
    if text in ("paper", "pastor"):
        return text
    try:
        return float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be 'paper', 'pastor' or a number, got {text!r}") from None


# ---------------------------------------------------------------------------------------------
# Command handlers
# ---------------------------------------------------------------------------------------------
def _read_demo(path: str, args: argparse.Namespace):
    """A demonstration file as the library wants it: (y, t or None, how it was read). Timed input
    is prepared (idle ends trimmed, noise filtered, uniform time) unless ``--raw``."""
    from .io import read_trajectory
    from .timing import prepare

    y, t = read_trajectory(path)
    if t is None or args.raw:
        how = "as recorded" if t is None else f"as recorded ({t[-1] - t[0]:.3f} s)"
        return y, t, how
    prepared, info = prepare(y, t, cutoff_hz=args.cutoff)
    how = (f"prepared: kept {info.start_s:.2f}-{info.end_s:.2f} s of {t[-1] - t[0]:.2f} s, low-pass {info.cutoff_hz:g} Hz "
           f"at {info.rate_hz:.1f} Hz, peak speed {info.peak_speed:.4g} {args.units or 'units'}/s")
    return prepared.y, prepared.t, how


def _bidmp_and_demo(args: argparse.Namespace, command: str):
    """What ``extend`` and ``learn`` start from: the model as a Bi-DMP (a DMP becomes its skill
    0) and the demonstration read as ``fit`` reads it, checked against the model's units and D.
    Returns (model, y, how it was read)."""
    from .dmp import DMP
    from .incremental import BiDMP
    from .io import load_model

    if not args.output.lower().endswith(".npz"):
        hint = "; use --save-demo to write the extended demonstration" if command == "extend" else ""
        raise ValueError(f"-o must be the Bi-DMP model file to write (.npz), got {args.output}{hint}")
    model = load_model(args.model)
    from .cartesian import CartesianDMP

    if isinstance(model, CartesianDMP):
        return _rollout_poses(model, args)
    if isinstance(model, DMP):
        model = BiDMP(model)
    elif not isinstance(model, BiDMP):
        raise ValueError(f"{args.model} holds a {type(model).__name__}; {command} needs a DMP or a Bi-DMP model")
    dmp = model.dmp if model.dmp is not None else model.dmp_
    if args.units and dmp.units_ and args.units != dmp.units_:
        raise ValueError(f"{args.demo} is in {args.units} but the model {args.model} is in {dmp.units_}: "
                         f"convert one of them first")
    y, _, how = _read_demo(args.demo, args)
    if y.shape[1] != model.n_dims_:
        raise ValueError(f"{args.demo} has D = {y.shape[1]} but the model {args.model} has D = {model.n_dims_}")
    return model, y, how


def _cmd_fit(args: argparse.Namespace) -> int:
    import numpy as np

    from ._trajectory import resample_time
    from .dmp import DMP
    from .io import save_model
    from .metrics import path_extent

    if _is_pose_file(args.demo):
        return _fit_poses(args)
    demonstration, times, how = _read_demo(args.demo, args)
    dmp = DMP(
        n_kernels=args.n_kernels, alpha=args.alpha, beta=args.beta, K=args.K,
        alpha_phase=args.alpha_phase, tau=args.tau, regression=args.regression, protocol=args.protocol,
    ).fit(demonstration, times, units=args.units)
    path = save_model(dmp, args.output)
    reproduction = dmp.trajectory()
    reference = resample_time(demonstration, dmp.n_steps_)
    error = float(np.sqrt(np.mean(np.sum((dmp.rollout()[: dmp.n_steps_] - reference) ** 2, axis=1))))
    extent = path_extent(demonstration)
    if not np.isfinite(error):  # never print a non-finite result as a success
        raise ValueError(f"the fitted DMP does not reproduce {args.demo} (RMSE {error}); the settings are out of range")
    unit = dmp.units_ or "units"
    print(f"fitted a DMP ({dmp.protocol} protocol) on {args.demo}, {how}")
    print(f"  T = {dmp.n_steps_} samples over {dmp.duration_:.4g} s ({dmp.sample_rate_:.4g} Hz), D = {dmp.n_dims_}, "
          f"units {dmp.units_ or '(not given)'}")
    print(f"  start {np.array2string(dmp.start_, precision=4)}  goal {np.array2string(dmp.goal_, precision=4)}")
    print(f"  reproduction RMSE {error:.4g} {unit} ({100 * error / extent:.3g} % of the extent {extent:.4g})")
    print(f"  rollouts last {reproduction.duration:.4g} s (tau = {dmp.tau:g}; peak speed {reproduction.peak_speed():.4g} {unit}/s, "
          f"peak acceleration {reproduction.peak_acceleration():.4g} {unit}/s^2)")
    if dmp.protocol == "paper":
        print(f"  end-point gain c = {dmp.endpoint_gain():.4g}: a goal moved by d is missed by c*d after {dmp.default_n_steps()} samples")
    print(f"wrote {path}")
    return EXIT_OK


def _is_pose_file(path) -> bool:
    """Whether ``path`` is a CSV whose header names a pose (``...,qx,qy,qz,qw``)."""
    if not str(path).lower().endswith((".csv", ".txt")):
        return False
    try:
        with open(path, encoding="utf-8-sig") as handle:
            header = handle.readline(4096)
    except OSError:
        return False
    names = {name.strip().lower() for name in header.replace(";", ",").split(",")}
    return {"qx", "qy", "qz", "qw"} <= names


def _fit_poses(args: argparse.Namespace) -> int:
    """``bidmp fit`` on a pose recording: a CartesianDMP (prepared like positions unless --raw)."""
    import numpy as np

    from .cartesian import CartesianDMP, angle_between, prepare_poses
    from .io import read_poses, save_model

    poses, times = read_poses(args.demo)
    how = "raw samples" if times is None else "timestamps as recorded"
    if times is not None and not args.raw:
        poses, times, info = prepare_poses(poses, times, cutoff_hz=args.cutoff, units=args.units or "")
        how = (f"prepared: {info.rate_hz:.4g} Hz, low-pass {info.cutoff_hz:g} Hz, motion {info.start_s:.3g}-{info.end_s:.3g} s "
               f"of the recording")
    model = CartesianDMP(
        n_kernels=args.n_kernels, alpha=args.alpha, beta=args.beta, K=args.K,
        alpha_phase=args.alpha_phase, tau=args.tau, regression=args.regression, protocol=args.protocol,
    ).fit(poses, times, units=args.units)
    path = save_model(model, args.output)
    reproduction = model.rollout()[: len(poses)]
    n = len(reproduction)
    angles = np.degrees(angle_between(reproduction[:, 3:], poses[:n, 3:]))
    unit = model.units_ or "units"
    print(f"fitted a pose DMP (CartesianDMP, {model.protocol} protocol) on {args.demo}, {how}")
    print(f"  T = {len(poses)} samples over {model.duration_:.4g} s; units {model.units_ or '(not given)'}")
    print(f"  reproduction: position RMSE {np.sqrt(np.mean(np.sum((reproduction[:, :3] - poses[:n, :3]) ** 2, axis=1))):.4g} "
          f"{unit}, orientation RMS {np.sqrt(np.mean(angles ** 2)):.3g} deg")
    print(f"wrote {path}")
    return EXIT_OK


def _rollout_poses(model, args: argparse.Namespace) -> int:
    import numpy as np

    from .cartesian import angle_between
    from .io import save_poses

    if args.skill is not None:
        raise ValueError(f"--skill needs a Bi-DMP model; {args.model} holds a pose DMP")
    if args.max_speed is not None or args.max_acc is not None:
        limits = {"max_velocity": args.max_speed, "max_acceleration": args.max_acc}
    else:
        limits = None
    dt = None if args.rate is None else 1.0 / args.rate
    trajectory = model.trajectory(goal=args.goal, start=args.start, duration=args.duration, dt=dt, limits=limits)
    path = save_poses(trajectory, args.output)
    goal = model.goal_ if args.goal is None else np.asarray(args.goal, dtype=float)
    print(f"rolled out {len(trajectory.t)} poses over {trajectory.t[-1]:.4g} s to goal {np.array2string(goal, precision=4)}")
    print(f"  end point {np.linalg.norm(trajectory.y[-1] - goal[:3]):.4g} {model.units_ or 'units'} and "
          f"{np.degrees(angle_between(trajectory.q[-1:], goal[None, 3:] / np.linalg.norm(goal[3:])))[0]:.3g} deg "
          f"from the goal")
    print(f"wrote {path} (columns {','.join(trajectory.columns()[0])})")
    return EXIT_OK


def _rollout_goal(model, goal):
    """The goal a rollout went to: the one given, else the model's default (a Bi-DMP's latest skill)."""
    if goal is not None:
        return goal
    return model.skill_goals_[-1] if hasattr(model, "skill_goals_") else model.goal_


def _timing_options(args: argparse.Namespace, dmp) -> dict:
    """trajectory() keywords from --rate/--n-steps/--duration/--max-speed/--max-acc."""
    options = {"duration": args.duration}
    if args.rate is not None and args.n_steps is not None:
        raise ValueError("give --rate or --n-steps, not both")
    if args.rate is not None:
        if not 0 < args.rate <= 100_000:
            raise ValueError(f"--rate must be in (0, 100000] Hz, got {args.rate:g}")
        options["dt"] = 1.0 / args.rate
    elif args.n_steps is not None:
        from ._checks import check_int

        check_int(args.n_steps, "--n-steps", minimum=2, limit="max_steps")
        motion = dmp.tau * dmp.duration_ if args.duration is None else args.duration
        settle = dmp._params().settle
        options["dt"] = settle * motion / (args.n_steps - 1)  # the same motion, sampled more finely
    if args.max_speed is not None or args.max_acc is not None:
        options["limits"] = {"max_velocity": args.max_speed, "max_acceleration": args.max_acc}
        options.pop("duration")
    return options


def _cmd_rollout(args: argparse.Namespace) -> int:
    import numpy as np

    from .dmp import DMP
    from .incremental import BiDMP
    from .io import load_model, save_trajectory

    model = load_model(args.model)
    from .cartesian import CartesianDMP

    if isinstance(model, CartesianDMP):
        return _rollout_poses(model, args)
    if isinstance(model, DMP):
        if args.skill is not None:
            raise ValueError(f"--skill needs a Bi-DMP model; {args.model} holds a plain DMP")
        dmp = model
        trajectory = model.trajectory(goal=args.goal, start=args.start, **_timing_options(args, dmp))
    elif isinstance(model, BiDMP):
        skill = "nearest" if args.skill is None else (int(args.skill) if args.skill.lstrip("-").isdigit() else args.skill)
        query = _rollout_goal(model, args.goal)
        index = model.select_skill(query, skill)
        dmp = model.dmp_
        trajectory = model.trajectory(goal=query, skill=skill, start=args.start, **_timing_options(args, dmp))
        print(f"Bi-DMP with {model.n_skills} skills: using skill {index} (training goal "
              f"{np.array2string(model.skill_goals_[index], precision=3)})")
    else:
        raise ValueError(f"{args.model} holds a {type(model).__name__}, which cannot be rolled out")
    path = save_trajectory(trajectory, args.output)
    goal = np.asarray(_rollout_goal(model, args.goal), dtype=float)
    unit = dmp.units_ or "units"
    rate = 1.0 / (trajectory.t[1] - trajectory.t[0]) if len(trajectory) > 1 else float("nan")
    print(f"rolled out {len(trajectory)} samples over {trajectory.duration:.4g} s ({rate:.4g} Hz) to goal "
          f"{np.array2string(goal, precision=4)}")
    print(f"  end point {np.array2string(trajectory.y[-1], precision=4)}, distance to goal "
          f"{np.linalg.norm(trajectory.y[-1] - goal):.4g} {unit}")
    print(f"  peak speed {trajectory.peak_speed():.4g} {unit}/s, peak acceleration {trajectory.peak_acceleration():.4g} "
          f"{unit}/s^2, initial acceleration {np.linalg.norm(trajectory.ydd[0]):.4g} {unit}/s^2")
    print(f"wrote {path} (columns {','.join(trajectory.columns()[0])})")
    if args.plot:
        from .plotting import plot_trajectories

        figure = plot_trajectories(args.plot, dmp.rollout(), [trajectory.y], ["rollout"], goals=goal[None], title="rollout",
                                   units=dmp.units_)
        print(f"wrote {figure}")
    return EXIT_OK


def _cmd_lasa(args: argparse.Namespace) -> int:
    from .datasets import lasa, lasa_names

    if args.lasa_command == "list":
        for name in lasa_names():
            print(name)
        return EXIT_OK
    from .io import save_trajectory

    demos = lasa(args.name)
    if not 0 <= args.demo < demos.shape[0]:
        raise ValueError(f"--demo must be 0-{demos.shape[0] - 1}, got {args.demo}")
    path = save_trajectory(demos[args.demo], args.output)
    print(f"wrote {args.name} demonstration {args.demo} ({demos.shape[1]} x {demos.shape[2]}) to {path}")
    return EXIT_OK


def _run_scenario(scenario, out, methods=None):
    """Evaluate a scenario with a progress bar, print its report, write results and figures."""
    from tqdm import tqdm

    from .evaluation import evaluate, write_report

    names = list(scenario.methods if methods is None else methods)
    with tqdm(total=len(names), desc=scenario.name, unit="method", disable=None) as bar:
        def progress(method):  # called as each method starts
            bar.set_postfix_str(method)
            bar.update(1)

        report = evaluate(scenario, names, progress=progress)
    print()
    print(report.summary())
    written = write_report(report, out)
    print(f"\nwrote {', '.join(str(path) for path in written)}")
    return report


def _run_sim(scenario, out, methods, *, closed_loop=False, hold=None, workers=None, pictures=True, targets=None,
             report=None):
    """Execute a scenario on the simulated Panda with a progress bar; print and write the results."""
    from tqdm import tqdm

    from .sim import simulate, write_sim_report

    methods = list(methods)
    labels = scenario.labels if targets is None else targets
    frames = {}
    if pictures:
        origin = scenario.targets[scenario.demonstrated]
        far = max(labels, key=lambda label: float(((scenario.targets[label] - origin) ** 2).sum()))
        frames = {(method, far): 30 for method in methods}
    with tqdm(total=len(methods) * len(labels), desc=f"{scenario.name} (sim)", unit="motion", disable=None) as bar:
        def progress(method, label):
            bar.set_postfix_str(f"{method} {label}")
            bar.update(1)

        result = simulate(scenario, methods, closed_loop=closed_loop, hold=hold, workers=workers, targets=targets,
                          frames=frames, progress=progress, report=report)
    print()
    print(result.summary())
    written = write_sim_report(result, out)
    print(f"\nwrote {', '.join(str(path) for path in written)}")
    return result


def _cmd_sim(args: argparse.Namespace) -> int:
    from pathlib import Path

    from .scenarios import load
    from .sim import Hold, _pybullet

    _pybullet()  # without the extra: the install command, before any work
    scenario = load(args.scenario, allow_outside_files=args.allow_outside_files)
    methods = [m.strip() for m in args.methods.split(",") if m.strip()]
    if not methods:
        raise ValueError(f"--methods names no method: {args.methods!r}")
    hold = None
    if args.hold is not None:
        joint, start, duration = args.hold
        if joint != int(joint) or not 1 <= joint <= 7:
            raise ValueError(f"--hold: the joint must be 1-7, got {joint:g}")
        if not (start >= 0 and duration > 0):
            raise ValueError("--hold: START must be >= 0 s and DURATION > 0 s")
        hold = Hold(int(joint) - 1, start, duration)
    targets = None if args.targets is None else [t.strip() for t in args.targets.split(",") if t.strip()]
    _run_sim(scenario, Path(args.out), methods, closed_loop=args.closed_loop, hold=hold, workers=args.workers,
             pictures=not args.no_pictures, targets=targets)
    return EXIT_OK


def _cmd_benchmark(args: argparse.Namespace) -> int:
    from pathlib import Path

    from tqdm import tqdm

    from .benchmark import _validate, lasa

    shapes = None if args.shapes is None else [s.strip() for s in args.shapes.split(",") if s.strip()]
    methods = None if args.methods is None else [m.strip() for m in args.methods.split(",") if m.strip()]
    shapes_checked, _, indices = _validate(shapes, methods, args.demos, args.every)  # before starting a cluster
    if args.workers is not None and not 1 <= args.workers <= 256:
        raise ValueError(f"--workers must be 1-256, got {args.workers}")
    with tqdm(total=len(shapes_checked) * len(indices), desc="LASA", unit="cell", disable=None) as bar:
        result = lasa(Path(args.out), shapes=shapes, methods=methods, demos=args.demos, every=args.every,
                      workers=args.workers, scheduler=args.scheduler, resume=args.resume, output_format=args.format,
                      progress=lambda key: bar.update(1))
    print(f"LASA benchmark: {len(result.computed)} cells computed, {len(result.resumed)} resumed, "
          f"{result.workers} worker(s), {result.wall_s:.1f} s")
    print((Path(args.out) / "lasa.md").read_text())
    print(f"wrote {', '.join(str(path) for path in result.written)}")
    return EXIT_OK


def _cmd_demo(args: argparse.Namespace) -> int:
    from pathlib import Path

    out = Path(args.out)
    if args.lasa:
        return _lasa_demo(args.lasa, out)
    from .scenarios import load

    scenario = load(args.scenario, allow_outside_files=args.allow_outside_files)
    if args.approach is not None:
        from .scenarios import from_dict

        spec = scenario.to_dict()
        spec["extension"] = {**spec.get("extension", {}), "approach": args.approach}
        scenario = from_dict(spec, source=args.scenario, base_dir=scenario.base_dir,
                             allow_outside_files=args.allow_outside_files)
    methods = None
    if args.methods is not None:
        methods = [m.strip() for m in args.methods.split(",") if m.strip()]
        if not methods:
            raise ValueError(f"--methods names no method: {args.methods!r}")
    if args.sim:
        from .sim import _pybullet

        _pybullet()
    report = _run_scenario(scenario, out, methods)
    if args.sim:
        sim_methods = [m for m in (methods or scenario.methods) if m in ("dmp", "bidmp")] or ["dmp", "bidmp"]
        _run_sim(scenario, out, sim_methods, report=report if set(sim_methods) <= set(report.methods) else None)
    return EXIT_OK


def _lasa_demo(shape: str, out) -> int:
    from .io import atomic_write
    from .plotting import plot_generalisation
    from .reproduce import lasa_generalisation

    out.mkdir(parents=True, exist_ok=True)
    result = lasa_generalisation(shape)
    print("bidmp demo --lasa: " + result.summary())
    with atomic_write(out / "lasa_generalisation.json", "w") as handle:
        json.dump(result.to_dict(), handle, indent=2)
    figure = plot_generalisation(out / "lasa_generalisation.png", result)
    print(f"wrote {out / 'lasa_generalisation.json'} and {figure}")
    return EXIT_OK


def _cmd_scenario(args: argparse.Namespace) -> int:
    from .scenarios import builtin_names, builtin_text, load

    if args.scenario_command == "list":
        for name in builtin_names():
            scenario = load(name)
            print(f"{name:16s} {len(scenario.targets):3d} targets  {scenario.description[:90]}")
        return EXIT_OK
    if args.scenario_command == "show":
        sys.stdout.write(builtin_text(args.name))
        return EXIT_OK
    scenario = load(args.file, allow_outside_files=args.allow_outside_files)  # what demo validates
    print(f"{args.file}: valid scenario '{scenario.name}' with {len(scenario.targets)} targets, "
          f"demonstration of {scenario.demonstration.shape[0]} samples in {scenario.demonstration.shape[1]}-D")
    return EXIT_OK


def _cmd_segment(args: argparse.Namespace) -> int:
    import numpy as np

    from ._tables import text_table
    from ._trajectory import arclength, resample_arclength
    from .io import load_trajectory
    from .segmentation import curvature, segment

    y = load_trajectory(args.demo)
    result = segment(y, eps_frac=args.eps_frac, method=args.method)
    points, kinds = result.points, result.kinds
    s = arclength(y)
    print(f"{args.demo}: {y.shape[0]} samples, D = {y.shape[1]}, {len(points)} segmentation point(s)")
    if len(points):
        rows = [
            [str(point), "max" if kind > 0 else "min", f"{100 * s[point] / s[-1]:.1f}", np.array2string(y[point], precision=3)]
            for point, kind in zip(points, kinds)
        ]
        print(text_table(["index", "curvature", "arc length %", "position"], rows))
    if args.plot:
        from .plotting import plot_segmentation

        from .segmentation import MAX_ANALYSIS_POINTS

        kappa = curvature(resample_arclength(y, min(y.shape[0], MAX_ANALYSIS_POINTS)))
        print(f"wrote {plot_segmentation(args.plot, y, points, kinds, curvature=kappa, title=f'1D-SEG of {args.demo}')}")
    return EXIT_OK


def _cmd_extend(args: argparse.Namespace) -> int:
    import numpy as np

    from ._trajectory import resample_time
    from .extension import extend_demonstration
    from .io import save_model, save_trajectory
    from .metrics import path_extent, rmse
    from .timing import Trajectory

    scene = None
    if args.scene is not None:
        from .scenarios import load

        scene = load(args.scene, allow_outside_files=args.allow_outside_files).scene
        if scene is None:
            raise ValueError(f"--scene: scenario {args.scene} has no \"scene\" key")
    model, y, how = _bidmp_and_demo(args, "extend")
    extension = extend_demonstration(y, args.target, seed=args.seed, approach=args.approach, scene=scene)
    target = extension.new_target
    history = extension.similarity_history
    print(f"{args.demo}: {how}")
    print(f"segmentation points {extension.segmentation_points.tolist()}; imitating piece {extension.piece.index} "
          f"(samples {extension.piece.start}-{extension.piece.end}) from seg = {np.array2string(y[extension.seg_index], precision=3)}")
    if len(history):
        print(f"G-PRM similarity per iteration: {' '.join(f'{v:.3f}' for v in history)} (best {extension.similarity:.3f})")
    before = np.linalg.norm(model.rollout(target)[-1] - target)
    model.learn(extension.complete)
    rollout = model.rollout(target)
    dmp = model.dmp_
    scale = path_extent(extension.complete)
    error = rmse(rollout[: dmp.n_steps_], resample_time(extension.complete, dmp.n_steps_))
    unit = dmp.units_ or "units"
    print(f"learned skill {model.n_skills - 1}: rollout to the target reproduces the extended demonstration with "
          f"RMSE {error:.4g} {unit} ({100 * error / scale:.3g} % of its extent)")
    print(f"end-point error at the target: {before:.4g} before, {np.linalg.norm(rollout[-1] - target):.4g} {unit} after")
    print(f"wrote {save_model(model, args.output)} ({model.n_skills} skills)")
    if args.save_demo:
        complete = resample_time(extension.complete, dmp.n_steps_)
        period = dmp.duration_ / (dmp.n_steps_ - 1)
        velocity = np.gradient(complete, period, axis=0)
        timed = Trajectory(np.arange(dmp.n_steps_) * period, complete, velocity, np.gradient(velocity, period, axis=0),
                           dmp.units_)
        print(f"wrote the extended demonstration ({timed.duration:.4g} s) to {save_trajectory(timed, args.save_demo)}")
    if args.plot:
        from .plotting import plot_extension

        print(f"wrote {plot_extension(args.plot, extension, units=dmp.units_)}")
    return EXIT_OK


def _cmd_learn(args: argparse.Namespace) -> int:
    import numpy as np

    from ._trajectory import resample_time, rmse
    from .io import save_model

    model, y, how = _bidmp_and_demo(args, "learn")
    model.learn(y)
    dmp = model.dmp_
    rollout = model.rollout(y[-1], start=y[0])
    error = rmse(rollout[: dmp.n_steps_], resample_time(y, dmp.n_steps_))
    print(f"{args.demo}: {how}")
    print(f"learned it as skill {model.n_skills - 1} (goal {np.array2string(y[-1], precision=3)}): reproduction RMSE "
          f"{error:.4g} {dmp.units_ or 'units'}")
    print(f"wrote {save_model(model, args.output)} ({model.n_skills} skills)")
    return EXIT_OK


def _cmd_reproduce(args: argparse.Namespace) -> int:
    from functools import partial
    from pathlib import Path

    from tqdm import tqdm

    from . import reproduce

    out = Path(args.out)
    if not 1 <= args.seeds <= _MAX_SEEDS:
        raise ValueError(f"--seeds must be 1-{_MAX_SEEDS}, got {args.seeds}")
    if args.what == "table4":
        with tqdm(total=len(reproduce.TABLE4_SCENARIOS), desc="table4", unit="scenario", disable=None) as bar:
            result = reproduce.run_table4(progress=lambda name: (bar.set_postfix_str(name), bar.update(1)))
    elif args.what == "figures":
        result = reproduce.run_figures(progress=partial(tqdm, desc="figures", unit="shape", disable=None))
    else:
        result = reproduce.run_table5(args.seeds, progress=partial(tqdm, desc="table5", unit="case", disable=None))
    print(result.summary())
    written = reproduce.write_results(result, args.what, out)
    print(f"\nwrote {', '.join(str(path) for path in written)}")
    return EXIT_OK


# ---------------------------------------------------------------------------------------------
# Parser
# ---------------------------------------------------------------------------------------------
_TIMED_INPUT = ("A timed DEMO (a CSV t column in seconds, or a timed .npy) is prepared unless --raw: the idle start "
                "and end are trimmed (speed below 5 %% of the peak), the noise is removed by a zero-phase low-pass "
                "filter (--cutoff, default 6 Hz) and the samples are resampled to uniform time.")


def _demo_options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--units", default="", metavar="UNIT", help="length unit of the demonstration, e.g. mm (kept in the model)")
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--prepare", action="store_true", help="prepare timed input: trim idle ends, filter, uniform time (the default)")
    mode.add_argument("--raw", action="store_true", help="use a timed demonstration as recorded (no trimming or filtering)")
    parser.add_argument("--cutoff", type=float, default=6.0, metavar="HZ", help="low-pass cutoff for timed input in Hz (default 6)")


def _allow_outside_files(parser, shown: bool = True) -> None:
    """The --allow-outside-files flag of every command that reads a scenario file."""
    parser.add_argument("--allow-outside-files", action="store_true",
                        help="let the scenario read demonstration files outside its own folder" if shown else argparse.SUPPRESS)


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="bidmp",
        description="Learn robot movements from one demonstration: DMP, extended demonstrations, Bi-DMP.",
        epilog="Trajectory files are .csv (optional header x,y[,z] or t,x,y[,z]) or .npy of shape (T, D).",
    )
    parser.add_argument("--version", action="version", version=f"bidmp {__version__}")
    parser.add_argument("--debug", action="store_true", help="show tracebacks and debug logging")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)

    fit = commands.add_parser(
        "fit", help="learn a DMP from a demonstration",
        description="Learn a DMP from one demonstration and save it as a model file (.npz). Time is in seconds: a CSV "
                    "with a t column (or a timed .npy) gives the motion its real duration; without one the samples "
                    "are taken as 1 s in all (the paper's convention). Lengths are in the demonstration's unit "
                    "(--units names it, e.g. mm); velocities are units/s, accelerations units/s^2.",
        epilog=_TIMED_INPUT)
    fit.add_argument("demo", metavar="DEMO", help="demonstration (.csv or .npy)")
    fit.add_argument("-o", "--output", required=True, metavar="MODEL", help="model file to write (.npz)")
    _demo_options(fit)
    fit.add_argument("--protocol", choices=("robot", "paper"), default="robot",
                     help="robot (default: goals reached, smooth starts, real time) or paper (the paper's fixed horizon)")
    fit.add_argument("--n-kernels", type=int, default=None, help="kernels per dimension (default: robot 100, paper 50)")
    fit.add_argument("--alpha", type=float, default=None, help="spring-damper gain alpha (default: robot 50, paper 25)")
    fit.add_argument("--beta", type=float, default=None, help="spring ratio beta (default alpha/4)")
    fit.add_argument("--K", type=_parse_K, default=None,
                     help="forcing gain: paper (K=alpha), pastor (K=alpha*beta) or a number (default: robot pastor, paper paper)")
    fit.add_argument("--alpha-phase", type=float, default=None, help="phase decay alpha_phase (default: robot 4, paper 1)")
    fit.add_argument("--tau", type=float, default=1.0, help="temporal scaling: rollouts take tau times the demonstration's duration (default 1)")
    fit.add_argument("--regression", "--fit", dest="regression", choices=("lwr", "ridge"), default="lwr", help="weight regression (default lwr)")
    fit.set_defaults(handler=_cmd_fit)

    rollout = commands.add_parser(
        "rollout", help="generate a timed trajectory from a model",
        description="Roll a saved model out to a goal and write the timed trajectory: t (s), positions (the model's "
                    "units), velocities (units/s) and accelerations (units/s^2), as CSV columns t,x,y,z,vx,vy,vz,ax,ay,az "
                    "or a .npy structured array with those fields. The motion lasts the demonstration's duration "
                    "(times tau, or --duration) plus 10 %% to come to rest (robot protocol).")
    rollout.add_argument("model", metavar="MODEL", help="model file (.npz) written by 'bidmp fit' or 'bidmp extend'")
    rollout.add_argument("--goal", type=float, nargs="+", metavar="X", help="goal coordinates in the model's units (default: the demonstrated goal)")
    rollout.add_argument("--start", type=float, nargs="+", metavar="X", help="start coordinates (default: the demonstrated start)")
    rollout.add_argument("--duration", type=float, default=None, metavar="S", help="duration of the motion in seconds (temporal scaling; default: the demonstration's)")
    rollout.add_argument("--rate", type=float, default=None, metavar="HZ", help="sample rate in Hz (default: the demonstration's)")
    rollout.add_argument("--n-steps", type=int, default=None, help="instead of --rate: this many samples over the same motion")
    rollout.add_argument("--max-speed", type=float, default=None, metavar="V", help="slow the motion (uniformly) to keep the speed <= V units/s")
    rollout.add_argument("--max-acc", type=float, default=None, metavar="A", help="slow the motion (uniformly) to keep the acceleration <= A units/s^2")
    rollout.add_argument("-o", "--output", required=True, metavar="OUT", help="trajectory file to write (.csv or .npy)")
    rollout.add_argument("--skill", default=None, help="Bi-DMP models: nearest (default), latest or a skill number (0 = plain DMP)")
    rollout.add_argument("--plot", metavar="PNG", help="also write a figure of the rollout")
    rollout.set_defaults(handler=_cmd_rollout)

    seg = commands.add_parser("segment", help="find the segmentation points of a demonstration (1D-SEG)",
                              description="Cut a 2-D or 3-D demonstration at its curvature extrema (1D-SEG).")
    seg.add_argument("demo", metavar="DEMO", help="demonstration (.csv or .npy)")
    seg.add_argument("--eps-frac", type=float, default=0.1, help="pruning threshold, fraction of the curvature range (default 0.1)")
    seg.add_argument("--method", choices=("persistence", "paper"), default="persistence", help="pruning rule (default persistence)")
    seg.add_argument("--plot", metavar="PNG", help="also write a figure with the points and the curvature")
    seg.set_defaults(handler=_cmd_segment)

    extend = commands.add_parser("extend", help="learn a new target incrementally (1D-SEG + G-PRM + Bi-DMP)",
                                 description="Segment DEMO, grow an extended demonstration to the new target with G-PRM, "
                                             "and learn it incrementally on top of MODEL (a DMP or a Bi-DMP) as a new skill. "
                                             "Coordinates are in the model's units.",
                                 epilog=_TIMED_INPUT)
    extend.add_argument("model", metavar="MODEL", help="a DMP (from 'bidmp fit') or Bi-DMP (from 'bidmp extend') model file")
    extend.add_argument("demo", metavar="DEMO", help="the demonstration to extend (.csv or .npy)")
    extend.add_argument("--target", type=float, nargs="+", required=True, metavar="X", help="new target coordinates")
    extend.add_argument("-o", "--output", required=True, metavar="MODEL2", help="Bi-DMP model file to write (.npz)")
    extend.add_argument("--save-demo", metavar="OUT", help="also write the extended demonstration, timed like a rollout (.csv or .npy)")
    _demo_options(extend)
    extend.add_argument("--seed", type=int, default=0, help="G-PRM random seed (default 0)")
    extend.add_argument("--approach", choices=("keep", "paper"), default="keep",
                        help="keep: keep the demonstrated final approach, translated, and grow only the transfer (default); "
                             "paper: imitate the nearest piece down to the target (the paper's protocol)")
    extend.add_argument("--scene", metavar="FILE|NAME", help="grow the extension around the parts of this scenario's scene")
    _allow_outside_files(extend, shown=False)
    extend.add_argument("--plot", metavar="PNG", help="also write a figure")
    extend.set_defaults(handler=_cmd_extend)

    learn = commands.add_parser("learn", help="learn a further demonstration as a new skill (Bi-DMP)",
                                description="Learn DEMO (e.g. another operator's recording) directly as a new skill on top "
                                            "of MODEL (a DMP or a Bi-DMP), without retraining. Coordinates in the model's units.",
                                epilog=_TIMED_INPUT)
    learn.add_argument("model", metavar="MODEL", help="a DMP or Bi-DMP model file")
    learn.add_argument("demo", metavar="DEMO", help="the demonstration to learn (.csv or .npy)")
    learn.add_argument("-o", "--output", required=True, metavar="MODEL2", help="Bi-DMP model file to write (.npz)")
    _demo_options(learn)
    learn.set_defaults(handler=_cmd_learn)

    reproduce = commands.add_parser("reproduce", help="reproduce a table of the paper",
                                    description="Reproduce the paper's comparisons. table4: the three case studies (nut "
                                                "unscrewing, cell removal before/after the second extension, pick-and-place with "
                                                "three operators). table5: G-PRM vs classic PRM similarity "
                                                "per iteration over many seeds (LASA shapes and the battery approach path). "
                                                "figures: Bi-DMP on LASA shapes, three new targets each (Fig. 11), "
                                                "with reproduction errors and forgetting.")
    reproduce.add_argument("what", choices=("table4", "table5", "figures"), help="which result")
    reproduce.add_argument("--out", default="bidmp-out", help="output folder (default ./bidmp-out)")
    reproduce.add_argument("--seeds", type=int, default=20, help="number of seeds (default 20)")
    reproduce.set_defaults(handler=_cmd_reproduce)

    lasa = commands.add_parser("lasa", help="the bundled LASA handwriting data", description="List or export the LASA handwriting shapes.")
    lasa_commands = lasa.add_subparsers(dest="lasa_command", metavar="{list,export}", required=True, parser_class=_Parser)
    lasa_commands.add_parser("list", help="list the shape names")
    export = lasa_commands.add_parser("export", help="write one demonstration of a shape")
    export.add_argument("name", metavar="NAME", help="shape name, e.g. Sshape")
    export.add_argument("--demo", type=int, default=0, help="which of the 7 demonstrations (0-6, default 0)")
    export.add_argument("-o", "--output", required=True, metavar="OUT", help="file to write (.csv or .npy)")
    lasa.set_defaults(handler=_cmd_lasa)

    demo = commands.add_parser("demo", help="run a scenario with every method (default: nut unscrewing)",
                               description="Run a scenario (default: the built-in EV-battery nut-unscrewing task) with every "
                                           "method, print the paper's Table 4 and per-target errors, write results.json and figures.")
    demo.add_argument("--scenario", default="nut-unscrewing", metavar="FILE|NAME", help="scenario file or built-in name (see 'bidmp scenario list')")
    demo.add_argument("--methods", default=None, help="comma-separated subset of dmp,dmp-converged,bidmp,bidmp-latest,gmm,tpgmm")
    demo.add_argument("--out", default="bidmp-out", help="output folder (default ./bidmp-out)")
    demo.add_argument("--approach", choices=("keep", "paper"), default=None,
                      help="how Bi-DMP's extensions are grown (default: the scenario's, else keep); paper = the paper's protocol")
    demo.add_argument("--sim", action="store_true",
                      help="then execute dmp and bidmp on the simulated Franka Panda (see 'bidmp sim'; needs bidmp[sim])")
    demo.add_argument("--lasa", metavar="SHAPE", help="instead: the LASA fit-and-generalise example on SHAPE (e.g. Sshape)")
    _allow_outside_files(demo)
    demo.set_defaults(handler=_cmd_demo)

    sim = commands.add_parser("sim", help="execute a scenario on a simulated Franka Panda (PyBullet)",
                              description="Execute every method's motion to every target of a scenario on a simulated "
                                          "Franka Panda (PyBullet, headless): inverse kinematics, timing to the Panda's joint "
                                          "limits, 1 kHz position control, contacts with the parts. Prints the Table 4 analogue "
                                          "in simulation and writes sim_results.json, keyframe strips and a GIF. Needs the "
                                          "sim extra: pip install 'bidmp[sim]'.")
    sim.add_argument("--scenario", default="nut-unscrewing", metavar="FILE|NAME", help="scenario with a \"scene\" (default nut-unscrewing)")
    sim.add_argument("--methods", default="dmp,bidmp", help="comma-separated methods to execute (default dmp,bidmp)")
    sim.add_argument("--targets", default=None, help="comma-separated subset of the targets (default all)")
    sim.add_argument("--closed-loop", action="store_true",
                     help="run the DMP/Bi-DMP stepper on the measured tool position with phase stopping (dmp, bidmp)")
    sim.add_argument("--hold", type=float, nargs=3, metavar=("JOINT", "START", "DURATION"),
                     help="a scripted disturbance: hold joint JOINT (1-7) still from START for DURATION seconds")
    sim.add_argument("--workers", type=int, default=None, help="worker processes (default: one per core, at most 2)")
    sim.add_argument("--no-pictures", action="store_true", help="skip the keyframe strips and the GIF")
    sim.add_argument("--out", default="bidmp-sim", help="output folder (default ./bidmp-sim)")
    _allow_outside_files(sim)
    sim.set_defaults(handler=_cmd_sim)

    benchmark = commands.add_parser("benchmark", help="the full LASA benchmark with the standard metrics, on Dask",
                                    description="Sweep every LASA shape x demonstration with every method (reproduction, "
                                                "near and far goals): RMSE, DTW, swept area, Fréchet, end-point error, "
                                                "times. Runs on an embedded Dask LocalCluster (one worker per core) or on "
                                                "--scheduler ADDRESS. Needs bidmp[benchmark].")
    bench_commands = benchmark.add_subparsers(dest="benchmark_command", metavar="{lasa}", required=True, parser_class=_Parser)
    bench = bench_commands.add_parser("lasa", help="the LASA handwriting benchmark")
    bench.add_argument("--shapes", default=None, help="comma-separated shapes (default all 30)")
    bench.add_argument("--methods", default=None, help="comma-separated methods (default dmp-paper,dmp-robot,bidmp,gmm,tpgmm,mp-dmp)")
    bench.add_argument("--demos", choices=("all", "first3"), default="all", help="all 7 demonstrations or the first 3")
    bench.add_argument("--every", type=int, default=1, metavar="K", help="use every K-th sample (papers use 1 or 10)")
    bench.add_argument("--workers", type=int, default=None, help="worker processes of the embedded cluster (default: one per core)")
    bench.add_argument("--scheduler", default=None, metavar="ADDRESS", help="run on an existing Dask scheduler (tcp://host:8786)")
    bench.add_argument("--resume", action="store_true", help="skip the cells a previous run into --out finished")
    bench.add_argument("--format", choices=("parquet", "csv"), default="parquet", help="results table format (default parquet)")
    bench.add_argument("--out", default="bidmp-lasa", help="output folder (default ./bidmp-lasa)")
    benchmark.set_defaults(handler=_cmd_benchmark)

    scenario = commands.add_parser("scenario", help="built-in scenarios: list, show, check a file",
                                   description="List the built-in scenarios, print one as JSON to copy and edit "
                                               "('bidmp scenario show nut-unscrewing > my.json'), or validate a scenario file.")
    scenario_commands = scenario.add_subparsers(dest="scenario_command", metavar="{list,show,check}", required=True, parser_class=_Parser)
    scenario_commands.add_parser("list", help="list the built-in scenarios")
    show = scenario_commands.add_parser("show", help="print a built-in scenario as JSON")
    show.add_argument("name", metavar="NAME")
    check = scenario_commands.add_parser("check", help="validate a scenario file")
    check.add_argument("file", metavar="FILE")
    _allow_outside_files(check)
    scenario.set_defaults(handler=_cmd_scenario)
    return parser


EXIT_BROKEN_PIPE = 141  # 128 + SIGPIPE, what a tool killed by a closed pipe reports
_MAX_MESSAGE = 600  # characters of one error line


class _BufferedLog(logging.Handler):
    """Holds the library's log records while a command runs: they are printed (one line each)
    if it succeeds and dropped if it fails, so that a failure is exactly one line on stderr."""

    def __init__(self) -> None:
        super().__init__(logging.WARNING)
        self.records: list[logging.LogRecord] = []
        self.setFormatter(logging.Formatter("bidmp: %(levelname)s: %(message)s"))

    def emit(self, record: logging.LogRecord) -> None:
        self.records.append(record)

    def flush_to(self, stream) -> None:
        for record in self.records:
            stream.write(" ".join(self.format(record).split())[:_MAX_MESSAGE] + "\n")
        self.records.clear()


def _one_line(text: str) -> str:
    """One printable line: whitespace runs collapsed, control characters (a file name or argument
    may carry terminal escapes) shown as '?', at most _MAX_MESSAGE characters."""
    text = "".join(c if c.isprintable() else "?" for c in " ".join(str(text).split()))
    return text if len(text) <= _MAX_MESSAGE else text[: _MAX_MESSAGE - 1] + "…"


def _quiet_stdout() -> None:
    """After a closed pipe: point stdout at /dev/null so that Python's final flush is silent."""
    import os

    try:
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())
    except (OSError, ValueError, AttributeError):  # a replaced sys.stdout (tests) has no file number
        pass


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line; return the exit code.

    Every failure is one line on stderr: exit 2 for bad input of any kind (including sizes over
    the limits and settings that would overflow), 1 for an internal error, 130 on Ctrl-C, 141
    when stdout is a closed pipe (``bidmp lasa list | head -1``), silently.
    """
    import warnings

    parser = build_parser()
    args = parser.parse_args(argv)
    if args.command is None:
        parser.print_help()
        print("bidmp: error: no command given (see 'bidmp --help')", file=sys.stderr)
        return EXIT_BAD_INPUT
    from ._checks import MissingExtraError

    buffered = _BufferedLog()
    root = logging.getLogger()
    debug_handler = None
    if args.debug:
        debug_handler = logging.StreamHandler(sys.stderr)
        debug_handler.setFormatter(logging.Formatter("%(levelname)s %(name)s: %(message)s"))
        root.addHandler(debug_handler)
        root.setLevel(logging.DEBUG)
    else:
        root.addHandler(buffered)
    try:
        with warnings.catch_warnings():
            # A numerical warning means a non-finite result is on its way: never report it as a
            # success. Other warnings go to the log (one line each, printed on success).
            warnings.simplefilter("error", RuntimeWarning)
            logging.captureWarnings(True)
            code = args.handler(args)
        sys.stdout.flush()
    except BrokenPipeError:
        _quiet_stdout()
        return EXIT_BROKEN_PIPE
    except KeyboardInterrupt:
        print("bidmp: interrupted", file=sys.stderr)
        return 130
    except (ValueError, TypeError, OSError, ArithmeticError, RuntimeWarning, RecursionError, MemoryError,
            MissingExtraError) as exc:
        if args.debug:
            raise
        if isinstance(exc, MemoryError):
            message = "out of memory; lower the sizes (see the limits in the README)"
        elif isinstance(exc, RecursionError):
            message = "input nested too deeply"
        elif isinstance(exc, (ArithmeticError, RuntimeWarning)):
            message = f"numerical failure ({exc}): the input's scale or the settings are out of range"
        elif isinstance(exc, OSError) and exc.strerror:
            message = f"{exc.strerror}: {exc.filename}" if exc.filename else exc.strerror
        else:
            message = str(exc) or type(exc).__name__
        print(f"bidmp {args.command}: error: {_one_line(message)}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except Exception as exc:  # noqa: BLE001 - the CLI promises no tracebacks
        if args.debug:
            raise
        print(_one_line(f"bidmp {args.command}: internal error: {type(exc).__name__}: {exc} (rerun with --debug for details)"),
              file=sys.stderr)
        return EXIT_INTERNAL
    finally:
        logging.captureWarnings(False)
        root.removeHandler(buffered)
        if debug_handler is not None:
            root.removeHandler(debug_handler)
    buffered.flush_to(sys.stderr)
    return code


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
