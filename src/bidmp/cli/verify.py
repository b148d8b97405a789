"""``bidmp verify MOTION --robot panda|fr3``: a joint motion judged by the FCI's own limits
(:mod:`bidmp.sim.fci`), as the robot would judge its 1 kHz joint-position commands."""

from __future__ import annotations

import argparse

from .common import EXIT_OK, EXIT_TARGETS_FAILED

EXIT_REJECTED = EXIT_TARGETS_FAILED  # 3: the FCI would stop the motion with a reflex


def _cmd_verify(args: argparse.Namespace) -> int:
    import numpy as np

    from ..io.recordings import read_recording
    from ..sim.fci import COMMAND_PERIOD_S, judge_commands, match_joint_names

    if args.libfranka:
        raise ValueError(
            "--libfranka (streaming through libfranka to a simulated FCI) is not built yet; "
            "bidmp verify judges by the FCI's published tables"
        )
    recording = read_recording(args.motion)
    if recording.kind != "joints":
        raise ValueError(
            f"{args.motion}: holds {recording.kind}, not joints: verify judges joint commands "
            f"(t and the {args.robot}'s joint names)"
        )
    if recording.t is None:
        raise ValueError(f"{args.motion}: no time column: the FCI takes a command every 1 ms")
    steps = np.diff(recording.t)
    if steps.size and np.max(np.abs(steps - COMMAND_PERIOD_S)) > 1e-6:
        rate = 1.0 / float(np.median(steps))
        raise ValueError(
            f"{args.motion}: samples {1e3 * float(np.median(steps)):.4g} ms apart ({rate:.4g} Hz); "
            f"the FCI takes a command every 1 ms: roll it out at 1000 Hz (bidmp rollout --rate 1000)"
        )
    columns = match_joint_names(recording.names, args.robot)
    verdict = judge_commands(recording.values[:, columns], args.robot)
    seconds = len(recording.values) * COMMAND_PERIOD_S
    if verdict.ok:
        print(
            f"accepted: {len(recording.values)} commands ({seconds:.3f} s) within the {args.robot}'s "
            f"FCI limits (positions, position-based velocities, accelerations, jerks)"
        )
        return EXIT_OK
    print(f"rejected: {verdict.reason()}")
    return EXIT_REJECTED


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
        "3: rejected, naming the reflex as libfranka does, the joint, the sample and the value "
        "against the limit; 2: a bad file.",
    )
    verify.add_argument("motion", metavar="MOTION", help="joint motion file (.csv)")
    verify.add_argument(
        "--robot", choices=("panda", "fr3"), default="fr3", help="whose limits (default fr3)"
    )
    verify.add_argument(
        "--libfranka",
        action="store_true",
        help="stream the motion through libfranka to a simulated FCI (not built yet: refused)",
    )
    verify.set_defaults(handler=_cmd_verify)
