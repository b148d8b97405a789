"""The libfranka side of ``bidmp verify --libfranka``: run by the side environment's Python
(``make franka``: franka-sim, pylibfranka and MuJoCo at their pins, NumPy 1.26), never imported by
bidmp — so it imports nothing of bidmp, only the standard library, NumPy and those packages.

Three commands:

``build-model OUT``
    The FR3's MuJoCo model, offline: franka-sim's own URDF (the one it serves to libfranka) with
    its meshes stripped (franka-sim would otherwise fetch a meshed model at run time) and every
    joint given an armature (the motor's inertia through its gear) of 0.5 kg·m² and a damping of
    1 N·m·s/rad. franka-sim's servo applies its damping (up to 450 N·m·s/rad) explicitly, once per
    1 ms step, which is stable only about an inertia above 450 × 0.001 / 2 = 0.225 kg·m²: with
    0.1, where joints 1 and 3 line up (joint 2 near 0) their opposite turn, held by the armatures
    alone, rang at ±0.37 rad/s (measured) and the safety controller stopped the arm.
``serve HOST MODEL``
    franka-sim's FCI server on ``HOST``:1337 with the motion limits enforced (a breach aborts the
    motion as the real controller does), no gripper.
``stream STREAMS.npz MODEL``
    Start a server on a free loopback address, then for each stream ``q`` (T, 7) rad of the file
    (arrays ``stream_0``, ``stream_1``, ...), in one joint-position motion: a quintic move from
    where the arm stands to ``q[0]`` (within 0.4 of the FR3's limits), 3 ms held there,
    the stream one command per millisecond, 3 ms held at its last command (the motion finishes
    at rest). One JSON line per stream on stdout: ``accepted``, the ``reflexes`` libfranka's
    ControlException named, the ``phase`` it came in (``approach``, ``motion``), the ``sample``
    of the stream, and ``retries``: how often it was streamed again because this client had
    missed a 1 ms cycle just before a reflex (up to 3). The server is stopped at the end, and dies with this process
    (Linux's parent-death signal).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import re
import signal
import socket
import subprocess
import sys
import time
from pathlib import Path

# Run as a script (the side environment's python), this file's folder is sys.path[0]: bidmp.sim's
# own `mujoco` subpackage (the MuJoCo backend) would then shadow the real MuJoCo franka-sim needs.
if __name__ == "__main__":
    _HERE = Path(__file__).resolve().parent
    sys.path[:] = [p for p in sys.path if Path(p or ".").resolve() != _HERE]

COMMAND_PORT = 1337  # libfranka's fixed FCI command port: a free address is chosen instead
_HOLD = 3  # ms held at rest before and after each stream
_APPROACH_SHARE = 0.4  # of the FR3's velocity, acceleration and jerk limits, for the approach
_FR3_VELOCITY, _FR3_ACCELERATION, _FR3_JERK = 2.62, 10.0, 5000.0
_LATE_S = 1.5e-3  # a read this long after the last: a command cycle was missed
_LATE_WINDOW = 5  # cycles before a reflex in which a missed one makes it the host's doing
_RETRIES = 3
_ARMATURE, _DAMPING = 0.5, 1.0  # kg·m², N·m·s/rad: build-model's joints (module docstring)


def build_model(out: Path) -> None:
    import franka_sim
    import mujoco

    urdf = Path(franka_sim.__file__).parent / "models" / "fr3.urdf"
    text = urdf.read_text()
    for element in ("visual", "collision"):
        text = re.sub(rf"<{element}\b.*?</{element}>", "", text, flags=re.S)
    model = mujoco.MjModel.from_xml_string(text)
    raw = out.with_suffix(".raw.xml")
    mujoco.mj_saveLastXML(str(raw), model)
    spec = mujoco.MjSpec.from_file(str(raw))
    for joint in spec.joints:
        joint.armature, joint.damping = _ARMATURE, _DAMPING
    spec.compile()
    temporary = out.with_suffix(".tmp")
    temporary.write_text(spec.to_xml())
    os.replace(temporary, out)
    raw.unlink()


def serve(host: str, model: str) -> None:
    os.environ["FR3_MJCF"] = model
    from franka_sim import FrankaSimServer

    server = FrankaSimServer(
        host=host, port=COMMAND_PORT, enable_gripper=False, enforce_motion_limits=True
    )
    try:
        server.start()
    finally:
        server.stop()


def _free_loopback() -> str:
    """A loopback address (127.0.0.0/8) whose port 1337 is free now."""
    chooser = random.Random(os.getpid())
    for _ in range(200):
        host = f"127.{chooser.randrange(1, 255)}.{chooser.randrange(0, 256)}.{chooser.randrange(1, 255)}"
        with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as probe:
            try:
                probe.bind((host, COMMAND_PORT))
            except OSError:
                continue
        return host
    raise RuntimeError("no loopback address with port 1337 free")


def _die_with_parent() -> None:
    try:  # Linux: the server goes when this process goes, however it goes
        import ctypes

        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG
    except (OSError, AttributeError):  # pragma: no cover - not Linux
        pass


def _start_server(model: str):
    import pylibfranka

    host = _free_loopback()
    log = open(os.devnull, "w")  # noqa: SIM115 - the server's chatter is not read
    server = subprocess.Popen(
        [sys.executable, __file__, "serve", host, model],
        stdout=log,
        stderr=log,
        preexec_fn=_die_with_parent,
    )
    deadline = time.monotonic() + 90.0
    while True:
        if server.poll() is not None:
            raise RuntimeError(f"the franka-sim server exited with {server.returncode} on start")
        try:
            return server, pylibfranka.Robot(host, pylibfranka.RealtimeConfig.kIgnore)
        except Exception:  # noqa: BLE001 - libfranka's NetworkException while the server boots
            if time.monotonic() > deadline:
                _stop(server)
                raise RuntimeError("the franka-sim server did not answer within 90 s") from None
            time.sleep(0.25)


def _stop(server) -> None:
    if server.poll() is None:
        server.send_signal(signal.SIGINT)
        try:
            server.wait(timeout=10.0)
        except subprocess.TimeoutExpired:
            server.kill()
            server.wait()


def _approach(start, goal):
    """A quintic move from ``start`` to ``goal`` (lists of 7 rad), 1 ms apart, within 0.4 of
    the FR3's velocity, acceleration and jerk limits, ending at rest (``_HOLD`` samples held)."""
    import numpy as np

    start, goal = np.asarray(start), np.asarray(goal)
    distance = float(np.max(np.abs(goal - start)))
    # quintic peaks: 1.875 d / T, 5.774 d / T², 60 d / T³
    duration = max(
        0.05,
        1.875 * distance / (_APPROACH_SHARE * _FR3_VELOCITY),
        np.sqrt(5.774 * distance / (_APPROACH_SHARE * _FR3_ACCELERATION)),
        np.cbrt(60.0 * distance / (_APPROACH_SHARE * _FR3_JERK)),
    )
    u = np.arange(1, int(np.ceil(duration / 1e-3)) + 1) / np.ceil(duration / 1e-3)
    share = 10 * u**3 - 15 * u**4 + 6 * u**5
    move = start + share[:, None] * (goal - start)
    return np.vstack([move, np.repeat(goal[None], _HOLD, axis=0)])


def _stream_one(robot, q) -> dict:
    import numpy as np
    import pylibfranka

    state = robot.read_once()
    approach = _approach(state.q_d, q[0])
    commands = np.vstack([approach, q, np.repeat(q[-1:], _HOLD, axis=0)])
    first_of_stream = approach.shape[0]
    control = robot.start_joint_position_control(pylibfranka.ControllerMode.JointImpedance)
    sent, late_at = 0, -_LATE_WINDOW - 1
    try:
        for index, command in enumerate(commands):
            _, period = control.readOnce()
            if period.to_sec() > _LATE_S:
                late_at = index
            positions = pylibfranka.JointPositions(command.tolist())
            positions.motion_finished = index == len(commands) - 1
            control.writeOnce(positions)
            sent = index + 1
    except pylibfranka.ControlException as exc:
        message = str(exc)
        # This motion's reflexes: the robot's current errors, read before the recovery clears
        # them. Not the exception's list: that is the state's last_motion_errors, which
        # franka-sim only ever adds to (it named every reflex since the server started).
        reflexes = _current_errors(robot)
        robot.automatic_error_recovery()
        # the reflex came with the last command sent, or with the one before it was read
        at = max(sent - 1, 0)
        return {
            "accepted": False,
            "reflexes": reflexes,
            "phase": "approach" if at < first_of_stream else "motion",
            "sample": at - first_of_stream,
            "message": message[:500],
            "late": at - late_at <= _LATE_WINDOW,
        }
    return {"accepted": True, "reflexes": [], "phase": "", "sample": -1, "message": ""}


def _current_errors(robot) -> list:
    """The names of the robot's current errors (libfranka's ``franka::Errors`` flags)."""
    errors = robot.read_once().current_errors
    return sorted(
        name for name in dir(errors) if not name.startswith("_") and getattr(errors, name) is True
    )


def stream(streams_file: str, model: str) -> None:
    import numpy as np

    with np.load(streams_file) as archive:
        streams = [archive[f"stream_{index}"] for index in range(len(archive.files))]
    server, robot = _start_server(model)
    try:
        for index, q in enumerate(streams):
            # A reflex right after this client missed its 1 ms (a loaded machine) is the host's,
            # not the motion's: franka-sim extrapolates a missed command, and the late one then
            # jumps. Such a stream is streamed again (the count is reported).
            retries, outcome = 0, _stream_one(robot, np.asarray(q, dtype=float))
            while outcome.pop("late", False) and retries < _RETRIES:
                retries, outcome = retries + 1, _stream_one(robot, np.asarray(q, dtype=float))
            outcome["retries"] = retries
            # the wire to bidmp (a line per stream, read as it comes), not a message to a person
            sys.stdout.write(json.dumps({"index": index, **outcome}) + "\n")
            sys.stdout.flush()
    finally:
        del robot
        _stop(server)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    commands = parser.add_subparsers(dest="command", required=True)
    build = commands.add_parser("build-model")
    build.add_argument("out", type=Path)
    serving = commands.add_parser("serve")
    serving.add_argument("host")
    serving.add_argument("model")
    streaming = commands.add_parser("stream")
    streaming.add_argument("streams")
    streaming.add_argument("model")
    args = parser.parse_args()
    if args.command == "build-model":
        build_model(args.out)
    elif args.command == "serve":
        serve(args.host, args.model)
    else:
        stream(args.streams, args.model)


if __name__ == "__main__":
    main()
