"""``bidmp verify MOTION --robot panda|fr3 [--libfranka]``: a joint motion judged by the FCI's own
limits (:mod:`bidmp.sim.fci`), as the robot would judge its 1 kHz joint-position commands, or
streamed through libfranka to a simulated FR3 (:mod:`bidmp.sim.libfranka`)."""

from __future__ import annotations

import argparse

from .common import EXIT_OK, EXIT_TARGETS_FAILED

EXIT_REJECTED = EXIT_TARGETS_FAILED  # 3: the FCI would stop the motion with a reflex


def _cmd_verify(args: argparse.Namespace) -> int:
    if args.libfranka and args.robot != "fr3":
        raise ValueError(
            f"--libfranka streams to franka-sim, which simulates an FR3 only (robot protocol 10; "
            f"libfranka speaks the {args.robot}'s only up to 0.9): judge a {args.robot} motion "
            f"without --libfranka (its FCI tables)"
        )
    _refuse_mixed_runs(args.motion)
    verdicts = [(path, _verdict(path, args.robot)) for path in args.motion]
    if args.libfranka:
        return _through_libfranka(verdicts)
    from ..sim.fci import COMMAND_PERIOD_S

    for path, (verdict, count, _) in verdicts:
        seconds = count * COMMAND_PERIOD_S
        if verdict.ok:
            print(
                f"accepted: {path}: {count} commands ({seconds:.3f} s) within the {args.robot}'s "
                f"FCI limits (positions, position-based velocities, accelerations, jerks)"
            )
        else:
            print(f"rejected: {path}: {verdict.reason()}")
    rejected = sum(not verdict.ok for _, (verdict, _, _) in verdicts)
    if len(verdicts) > 1:
        print(f"{len(verdicts) - rejected} of {len(verdicts)} motions accepted")
    return EXIT_REJECTED if rejected else EXIT_OK


def _refuse_mixed_runs(paths) -> None:
    """A file inside a run folder (``bidmp job --commands``' DIR/commands/*.csv) is judged only if
    that run wrote it as it is: its manifest.json lists it with this SHA-256. A command file an
    earlier run left beside a newer one's, or one changed since, is refused by name before any
    is judged (a robot is never sent a stale command)."""
    from ..io.runs import check_run_files

    check_run_files(paths, "motion")


def _through_libfranka(verdicts) -> int:
    """Each motion streamed through libfranka to a simulated FR3: its outcome is the verdict
    (exit 3 if any was stopped by a reflex); bidmp's own judge printed beside it where the two
    differ."""
    from ..sim.libfranka import stream_fr3

    outcomes = stream_fr3([commands for _, (_, _, commands) in verdicts])
    for (path, (verdict, count, _)), outcome in zip(verdicts, outcomes):
        again = (
            f" (streamed {outcome.retries + 1} times: this machine missed a 1 ms cycle right "
            f"before a reflex)"
            if outcome.retries
            else ""
        )
        if outcome.accepted:
            print(
                f"accepted by libfranka: {path}: {count} commands streamed at 1 kHz, no reflex{again}"
            )
        else:
            print(f"rejected by libfranka: {path}: {outcome.reason()}{again}")
        if verdict.ok != outcome.accepted:
            print(
                f"  bidmp's FCI judge disagrees: "
                f"{'accepted' if verdict.ok else 'rejected: ' + verdict.reason()}"
            )
    rejected = sum(not outcome.accepted for outcome in outcomes)
    if len(outcomes) > 1:
        print(f"{len(outcomes) - rejected} of {len(outcomes)} motions accepted by libfranka")
    return EXIT_REJECTED if rejected else EXIT_OK


def _verdict(path, robot: str):
    """(the FCI's verdict, the number of commands, the commands (T, 7) rad in the robot's joint
    order) of one motion file."""

    from .._checks import check_path, short_token
    from ..io.recordings import read_recording
    from ..sim.fci import judge_commands, match_joint_names

    if not check_path(path, f"motion {short_token(path, 24)}").exists():
        raise ValueError(f"motion file {path} does not exist")
    recording = read_recording(path)
    if recording.kind != "joints":
        raise ValueError(
            f"{path}: holds {recording.kind}, not joints: verify judges joint commands "
            f"(t and the {robot}'s joint names)"
        )
    if recording.t is None:
        raise ValueError(f"{path}: no time column: the FCI takes a command every 1 ms")
    _check_period(path, recording)
    commands = recording.values[:, match_joint_names(recording.names, robot)]
    return judge_commands(commands, robot), len(commands), commands


def _check_period(path, recording) -> None:
    """Refuse a stream that is not one command per millisecond, saying what it is: a stamp
    repeated (its data row), a rollout at another rate (its rate), or one step off the 1 ms
    (the data rows around it and how far apart they are)."""
    import numpy as np

    from ..sim.fci import COMMAND_PERIOD_S

    if recording.repeated:
        row, stamp = recording.repeated[0]
        more = len(recording.repeated) - 1
        raise ValueError(
            f"{path}: data row {row} repeats the stamp {stamp:.6g} s of the row before"
            + (f" ({more} more repeated stamp{'s' if more != 1 else ''})" if more else "")
            + ": the FCI takes one command per stamp, every 1 ms"
        )
    steps = np.diff(recording.t)
    off = np.flatnonzero(np.abs(steps - COMMAND_PERIOD_S) > 1e-6)
    if not off.size:
        return
    median = float(np.median(steps))
    if abs(median - COMMAND_PERIOD_S) > 1e-6:
        raise ValueError(
            f"{path}: samples {1e3 * median:.4g} ms apart ({1.0 / median:.4g} Hz); "
            f"the FCI takes a command every 1 ms: roll it out at 1000 Hz (bidmp rollout --rate 1000)"
        )
    step = int(off[0])
    raise ValueError(
        f"{path}: data rows {step + 1} and {step + 2} are {1e3 * float(steps[step]):.6g} ms apart "
        f"(t = {recording.t[step]:.6g} s and {recording.t[step + 1]:.6g} s; {off.size} step"
        f"{'s' if off.size != 1 else ''} off 1 ms in all): the FCI takes a command every 1 ms"
    )


def add_commands(commands) -> None:
    """``bidmp verify MOTION --robot panda|fr3``."""
    verify = commands.add_parser(
        "verify",
        help="judge a joint motion by the Franka robot's own (FCI) limits",
        description="Judge a joint motion file (t and the robot's joint names, panda_joint1..7 or "
        "fr3_joint1..7, one sample per millisecond: what 'bidmp rollout --rate 1000' writes of a "
        "joint-space model) as the Franka Control Interface judges joint-position commands: "
        "positions within the ranges, velocities within the (FR3: position-based) limits, "
        "accelerations and jerks within theirs, the motion starting and ending at rest. Exit 0: accepted; "
        "3: rejected (any of the files), naming the reflex as libfranka does, the joint, the sample "
        "and the value against the limit; 2: a bad file. 'bidmp job --commands' writes every "
        "motion of a job as such a file.",
    )
    verify.add_argument("motion", metavar="MOTION", nargs="+", help="joint motion file(s) (.csv)")
    verify.add_argument(
        "--robot", choices=("panda", "fr3"), default="fr3", help="whose limits (default fr3)"
    )
    verify.add_argument(
        "--libfranka",
        action="store_true",
        help="stream the motions through libfranka (pylibfranka) at 1 kHz to franka-sim, a "
        "simulated FR3 with the FCI's motion limits enforced: libfranka's outcome is the verdict "
        "(needs 'make franka'; the server is started and stopped here)",
    )
    verify.set_defaults(handler=_cmd_verify)
