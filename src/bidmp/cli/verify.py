"""``bidmp verify MOTION --robot panda|fr3``: a joint motion judged by the FCI's own limits
(:mod:`bidmp.sim.fci`), as the robot would judge its 1 kHz joint-position commands."""

from __future__ import annotations

import argparse

from .common import EXIT_OK, EXIT_TARGETS_FAILED

EXIT_REJECTED = EXIT_TARGETS_FAILED  # 3: the FCI would stop the motion with a reflex


def _cmd_verify(args: argparse.Namespace) -> int:
    if args.libfranka:
        raise ValueError(
            "--libfranka (streaming through libfranka to a simulated FCI) is not built yet; "
            "bidmp verify judges by the FCI's published tables"
        )
    verdicts = [(path, _verdict(path, args.robot)) for path in args.motion]
    from ..sim.fci import COMMAND_PERIOD_S

    for path, (verdict, count) in verdicts:
        seconds = count * COMMAND_PERIOD_S
        if verdict.ok:
            print(
                f"accepted: {path}: {count} commands ({seconds:.3f} s) within the {args.robot}'s "
                f"FCI limits (positions, position-based velocities, accelerations, jerks)"
            )
        else:
            print(f"rejected: {path}: {verdict.reason()}")
    rejected = sum(not verdict.ok for _, (verdict, _) in verdicts)
    if len(verdicts) > 1:
        print(f"{len(verdicts) - rejected} of {len(verdicts)} motions accepted")
    return EXIT_REJECTED if rejected else EXIT_OK


def _verdict(path, robot: str):
    """(the FCI's verdict, the number of commands) of one motion file."""
    import numpy as np

    from ..io.recordings import read_recording
    from ..sim.fci import COMMAND_PERIOD_S, judge_commands, match_joint_names

    recording = read_recording(path)
    if recording.kind != "joints":
        raise ValueError(
            f"{path}: holds {recording.kind}, not joints: verify judges joint commands "
            f"(t and the {robot}'s joint names)"
        )
    if recording.t is None:
        raise ValueError(f"{path}: no time column: the FCI takes a command every 1 ms")
    steps = np.diff(recording.t)
    if steps.size and np.max(np.abs(steps - COMMAND_PERIOD_S)) > 1e-6:
        rate = 1.0 / float(np.median(steps))
        raise ValueError(
            f"{path}: samples {1e3 * float(np.median(steps)):.4g} ms apart ({rate:.4g} Hz); "
            f"the FCI takes a command every 1 ms: roll it out at 1000 Hz (bidmp rollout --rate 1000)"
        )
    columns = match_joint_names(recording.names, robot)
    return judge_commands(recording.values[:, columns], robot), len(recording.values)


def add_commands(commands) -> None:
    """``bidmp verify MOTION --robot panda|fr3``."""
    verify = commands.add_parser(
        "verify",
        help="judge a joint motion by the Franka robot's own (FCI) limits",
        description="Judge a joint motion file (t and the robot's joint names, panda_joint1..7 or "
        "fr3_joint1..7, one sample per millisecond: what 'bidmp rollout --rate 1000' writes of a "
        "joint-space model) as the Franka Control Interface judges joint-position commands: "
        "positions within the ranges, velocities within the (FR3: position-based) limits, "
        "accelerations and jerks within theirs, the motion starting at rest. Exit 0: accepted; "
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
        help="stream the motion through libfranka to a simulated FCI (not built yet: refused)",
    )
    verify.set_defaults(handler=_cmd_verify)
