"""Execution: 1 kHz position control of a planned joint path (open loop) or of a DMP stepper's
commands on the measured tool-centre point (closed loop, 100 Hz), recording the measured motion
and every contact with a part."""

from __future__ import annotations

import math

import numpy as np

from ..backend import (
    CONTROL_STEP,
    LIMIT_MARGIN,
    RECORD_EVERY,
    SETTLE,
    SIM_STEP,
    Execution,
    Hold,
    MotionPlan,
    SimError,
)
from ..limits import _hermite, _joint_velocity, _RateLimiter
from ..robots import IK_TOLERANCE

__all__ = []


# -- execution -------------------------------------------------------------------------
def _ignore(cell, exclude, enable: bool) -> None:
    """Switch contacts between the robot and the parts in ``exclude`` off (the target enters
    the tool) or back on."""
    p = cell.p
    links = list(range(-1, p.getNumJoints(cell.robot, physicsClientId=cell.client)))
    for body, owner in cell._owners.items():
        if owner in exclude:
            for link in links:
                p.setCollisionFilterPair(
                    cell.robot, body, link, -1, int(enable), physicsClientId=cell.client
                )


def _contacts_into(cell, found: dict) -> None:
    """Add the robot's contacts now to ``found`` (part label -> deepest penetration, m)."""
    for contact in cell.p.getContactPoints(bodyA=cell.robot, physicsClientId=cell.client):
        depth = -contact[8]
        if depth > 0.0 and contact[2] in cell._bodies:
            label = cell._bodies[contact[2]]
            found[label] = max(found.get(label, 0.0), depth)


def _drive(cell, q, qd) -> None:
    """Hand joint targets (rad) and velocities (rad/s) to the position control."""
    cell.p.setJointMotorControlArray(
        cell.robot,
        cell.arm,
        cell.p.POSITION_CONTROL,
        targetPositions=q,
        targetVelocities=qd,
        forces=list(cell.model.effort),
        positionGains=cell.gains,
        velocityGains=cell.gains,
        physicsClientId=cell.client,
    )


def _execute(
    cell, plan: MotionPlan, exclude=(), hold: Hold | None = None, frames: int = 0, on_record=None
) -> Execution:
    """Run ``plan`` under position control at 1 kHz, the parts in ``exclude`` ignored; a
    ``hold`` keeps one joint still for a while (its command runs on: open loop). ``on_record``
    is called with the time (s) after every recorded step (a part that follows the tool)."""
    p = cell.p
    n_steps = int(math.ceil((plan.duration + SETTLE) / SIM_STEP))
    positions, velocities = plan.command(np.arange(n_steps) * SIM_STEP)
    cell._set_joints(positions[0])
    position_list, velocity_list = positions.tolist(), velocities.tolist()
    record = _Recorder(cell, n_steps, frames, focus=plan.points[-1] / cell.unit)
    _ignore(cell, exclude, False)
    held = None
    # The 1 kHz loop is most of a simulation's cost: PyBullet's calls bound once, the
    # recorder visited only on the steps it records.
    robot, client, arm, mode, step_simulation = (
        cell.robot,
        cell.client,
        cell.arm,
        p.POSITION_CONTROL,
        p.stepSimulation,
    )
    motors, contact_points, contacts = (
        p.setJointMotorControlArray,
        p.getContactPoints,
        record.contacts,
    )
    bodies, effort, gains = cell._bodies, list(cell.model.effort), cell.gains
    visit = np.zeros(n_steps, dtype=bool)
    visit[::RECORD_EVERY] = True
    visit[-1] = True
    visit[list(record.frame_steps)] = True
    try:
        for step in range(n_steps):
            t = step * SIM_STEP
            q, qd = position_list[step], velocity_list[step]
            if _holding(hold, t):
                held = _held_angle(cell, hold, t, held)
                q, qd = list(q), list(qd)
                q[hold.joint], qd[hold.joint] = held, 0.0
            motors(
                robot,
                arm,
                mode,
                targetPositions=q,
                targetVelocities=qd,
                forces=effort,
                positionGains=gains,
                velocityGains=gains,
                physicsClientId=client,
            )
            step_simulation(physicsClientId=client)
            for contact in contact_points(bodyA=robot, physicsClientId=client):
                if contact[8] < 0.0 and contact[2] in bodies:
                    label = bodies[contact[2]]
                    contacts[label] = max(contacts.get(label, 0.0), -contact[8])
            if visit[step]:
                record.sample(step, t + SIM_STEP, positions[step])
                if on_record is not None:
                    on_record(t + SIM_STEP)
    finally:
        _ignore(cell, exclude, True)
    run = record.finish()
    # what the position control was sent, every 1 ms (a hold is the world's doing)
    run.commands = positions
    run.disturbed = _disturbed(hold)
    return run


def _execute_closed_loop(
    cell,
    stepper,
    span: tuple[float, float],
    exclude=(),
    hold: Hold | None = None,
    frames: int = 0,
    goal_update=None,
) -> Execution:
    """Run a DMP/Bi-DMP ``stepper`` (scene units) on the measured TCP at 100 Hz.

    Each control step asks the stepper for the command given where the TCP is, solves IK for its
    position and maps its velocity to the joints through the arm's Jacobian (the tool's orientation
    held); every 1 ms the position control gets the joints on the cubic (Hermite) segment between the
    last two control steps' joints and joint velocities, passed through a jerk-limited rate limiter
    (:class:`bidmp.sim.limits.RateLimiter`) with the segment's velocity and acceleration fed forward,
    so every command is within the velocity, acceleration and jerk limits, starts and stops at rest,
    and follows a monotone approach without overshoot (straight segments between the 100 Hz targets
    step the velocity every 10 ms, and the limiter then overshot a fast final descent by 1 mm).
    With phase stopping the motion's own time stands still while the robot is held. The run
    ends when the stepper's time has reached ``duration`` (at most ``max_factor`` times that in
    wall time; ``span`` = (duration s, max_factor)) plus the settling. ``goal_update``: see
    :func:`_perceive`.
    """
    duration, max_factor = span
    p = cell.p
    q, error = cell.solve_ik(np.asarray(stepper.y) * cell.unit, cell.model.rest)
    if error > IK_TOLERANCE:
        raise SimError(f"the start {np.round(stepper.y, 2).tolist()} is unreachable")
    cell._set_joints(q)
    every = int(round(CONTROL_STEP / SIM_STEP))
    complete = float(getattr(stepper, "horizon", duration))
    longest = max_factor * max(duration, complete) + (0.0 if hold is None else hold.duration)
    n_steps = int(math.ceil((longest + SETTLE) / SIM_STEP))
    record = _Recorder(cell, n_steps, frames, focus=np.asarray(stepper.target, dtype=float))
    _ignore(cell, exclude, False)
    target, previous, held, settle_from, moved = q, q, None, None, False
    target_rate = previous_rate = np.zeros_like(q)
    times, targets, clock, sent = [], [], [], []
    limited = _RateLimiter(q, cell.limits, LIMIT_MARGIN)
    # With a hold, what the arm would have been sent had nothing held it: the phase stopping
    # compares the measured tool with it (with the commands themselves, brought to rest where
    # the joint is held, the arm would seem to follow and the motion would run on)
    unheld = _RateLimiter(q, cell.limits, LIMIT_MARGIN) if hold is not None else None
    planned = [] if hold is not None else sent
    step = 0
    try:
        for step in range(n_steps):
            t = step * SIM_STEP
            if step % every == 0:
                previous, previous_rate = target, target_rate
                if settle_from is not None and step - settle_from >= SETTLE / SIM_STEP:
                    break
                # (settling: the limiter brings the joints to rest at the last IK target)
                if settle_from is None:
                    moved = moved or _perceive(cell, stepper, goal_update, exclude)
                    y, yd, _ = stepper.step(CONTROL_STEP, _tracked(cell, stepper, planned))
                    point = np.asarray(y) * cell.unit
                    target, _ = cell.solve_ik(point, target)
                    target_rate = _joint_velocity(cell, target, point, np.asarray(yd) * cell.unit)
                else:
                    target_rate = np.zeros_like(target)
                times.append(t)
                targets.append(target)
                clock.append(stepper.time)
                if settle_from is None and stepper.time >= complete:
                    settle_from = step
            share = (step % every + 1) / every
            # The cubic between the 100 Hz targets, then the 1 kHz limiter: jerk-limited commands.
            wanted = _hermite(previous, previous_rate, target, target_rate, share, CONTROL_STEP)
            if unheld is not None:
                planned.append(unheld(*wanted))
            holding = _holding(hold, t)
            held = _held_angle(cell, hold, t, held)
            if holding:  # the generator, told the joint is held, brings its command
                # to rest where it is held and resumes from there: the arm's own motion stays
                # within the limits across the hold (a command run on meanwhile would yank the
                # joint at the release)
                for value, at in zip(wanted, (held, 0.0, 0.0)):
                    value[hold.joint] = at
            command = limited(*wanted)
            sent.append(command)
            q, qd = command.tolist(), limited.velocity.tolist()
            if holding:  # held: the joint stays where it is, whatever it is sent
                q[hold.joint], qd[hold.joint] = held, 0.0
            _drive(cell, q, qd)
            p.stepSimulation(physicsClientId=cell.client)
            record.sample(step, t + SIM_STEP, command, contacts=True)
    finally:
        _ignore(cell, exclude, True)
        if moved:  # the world is kept for the next job: the parts back where they were
            _move_parts(cell, exclude, -np.asarray(goal_update.offset) * cell.unit)
    run = record.finish()
    run.command_times, run.command_joints, run.motion_clock = (
        np.array(times),
        np.array(targets),
        np.array(clock),
    )
    run.commands = np.array(sent)
    run.disturbed = _disturbed(hold)
    return run


def _disturbed(hold: Hold | None) -> tuple | None:
    return None if hold is None else (hold.start, hold.start + hold.duration)


def _tracked(cell, stepper, sent: list) -> np.ndarray:
    """What the stepper's phase stopping compares its command with: that command moved by the arm's
    tracking error — the measured tool against the tool of the joints it was sent last (scene
    units). The measured tool alone lags the stepper's newest command by the pipeline's own delay
    (a control step of interpolation and the limiter's lag, 1 mm at 130 mm/s), and phase stopping
    slowed and warped every fast motion for it; an arm held back still lags its commands."""
    measured = cell.tcp_position() / cell.unit
    if not sent:
        return measured
    return stepper.position + measured - cell.forward(sent[-1]) / cell.unit


def _perceive(cell, stepper, goal_update, labels) -> bool:
    """Apply ``goal_update`` (:class:`bidmp.sim.backend.GoalUpdate`) once the motion's time has
    reached its time: the parts ``labels`` (the target's) and the stepper's goal move by its offset
    (the run moves the parts back when it ends). Whether it was applied now."""
    if goal_update is None or stepper.time < goal_update.time:
        return False
    stepper.set_goal(stepper.target + np.asarray(goal_update.offset))
    return _move_parts(cell, labels, np.asarray(goal_update.offset) * cell.unit)


def _move_parts(cell, labels, offset_m: np.ndarray) -> bool:
    """Move every body of the parts ``labels`` by ``offset_m`` (3,) metres (a perception update:
    the part was there all along)."""
    p = cell.p
    for body, owner in cell._owners.items():
        if owner in labels:
            position, orientation = p.getBasePositionAndOrientation(
                body, physicsClientId=cell.client
            )
            p.resetBasePositionAndOrientation(
                body,
                (np.asarray(position) + offset_m).tolist(),
                orientation,
                physicsClientId=cell.client,
            )
    return True


def _holding(hold: Hold | None, t: float) -> bool:
    """Whether ``hold`` holds its joint at ``t`` (s of the run)."""
    return hold is not None and hold.start <= t < hold.start + hold.duration


def _held_angle(cell, hold: Hold | None, t: float, held: float | None) -> float | None:
    """The angle (rad) the hold keeps its joint at: where the joint was when the hold began
    (None before it)."""
    if held is None and _holding(hold, t):
        held = cell.p.getJointState(cell.robot, cell.arm[hold.joint], physicsClientId=cell.client)[
            0
        ]
    return held


class _Recorder:
    """Measured samples of one execution (every step) and optional frames."""

    def __init__(self, cell, n_steps: int, frames: int, focus=None):
        self.cell = cell
        self.focus = focus  # the target (scene units) the keyframes' close-up looks at
        self.n_steps = n_steps
        n_records, n_joints = (n_steps - 1) // RECORD_EVERY + 1, len(cell.arm)
        # One row per record, written in one assignment (the loop's cost is per call): time,
        # TCP position (3), TCP orientation (4), joint positions, joint velocities.
        self.rows = np.empty((n_records, 8 + 2 * n_joints))
        self.times, self.tcp, self.tcp_orientation = (
            self.rows[:, 0],
            self.rows[:, 1:4],
            self.rows[:, 4:8],
        )
        self.joints, self.velocities = self.rows[:, 8 : 8 + n_joints], self.rows[:, 8 + n_joints :]
        self.commanded = []
        self.contacts = {}
        self.frame_steps = (
            set(np.linspace(0, n_steps - 1, frames).astype(int).tolist()) if frames else set()
        )
        self.frames = []
        self.filled = 0

    def sample(
        self,
        step: int,
        t: float,
        commanded_joints,
        contacts: bool = False,
    ) -> None:
        """Record step ``step`` if it is a recorded one (every ``RECORD_EVERY``-th and the last),
        and render it if it is a frame's: a loop may call it on every step, or on those only."""
        cell = self.cell
        p = cell.p
        if contacts:
            _contacts_into(cell, self.contacts)
        if step in self.frame_steps:
            self.frames.append(
                cell.render() if self.focus is None else cell.keyframe(t, self.focus)
            )
        # A frame's step between two records only renders: recorded, it had written its state
        # and its command into the next record's place, and the command's path took both (the
        # motion's tracking error measured 0.32 mm with its frames and 0.23 mm without).
        if step % RECORD_EVERY and step != self.n_steps - 1:
            return
        row = min(step // RECORD_EVERY + (step % RECORD_EVERY > 0), len(self.times) - 1)
        self.filled = row + 1
        state = p.getLinkState(
            cell.robot, cell.tcp, computeForwardKinematics=1, physicsClientId=cell.client
        )
        states = p.getJointStates(cell.robot, cell.arm, physicsClientId=cell.client)
        self.rows[row] = (
            t,
            *state[4],
            *state[5],
            *[s[0] for s in states],
            *[s[1] for s in states],
        )
        # the command's TCP, 50 Hz (forward kinematics)
        if row % 10 == 0 or step == self.n_steps - 1:
            self.commanded.append((row, np.asarray(commanded_joints, dtype=float).copy()))

    def finish(self) -> Execution:
        """The execution (cut to the rows recorded when the run ended early)."""
        cell = self.cell
        n_rows = self.filled
        rows = [r for r, _ in self.commanded if r < n_rows]
        commanded = np.array([cell._tcp_at(q) for r, q in self.commanded if r < n_rows])
        full = np.column_stack(
            [np.interp(np.arange(n_rows), rows, commanded[:, k]) for k in range(3)]
        )
        run = Execution(
            self.times[:n_rows].copy(),
            self.tcp[:n_rows].copy(),
            self.joints[:n_rows].copy(),
            self.velocities[:n_rows].copy(),
            full,
            self.contacts,
            self.frames,
        )
        run.tcp_orientation = self.tcp_orientation[:n_rows].copy()
        return run
