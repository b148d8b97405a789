"""Execution in MuJoCo: the PyBullet backend's 1 kHz loops (open loop: a planned joint path;
closed loop: a DMP stepper's commands on the measured tool-centre point at 100 Hz) with MuJoCo's
physics, recording the measured motion and every contact with a part."""

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
from ..pybullet.execute import _disturbed, _holding, _tracked
from ..robots import GAIN, IK_TOLERANCE
from .world import _OFF, CONTACT_SLACK, PART_GROUP

__all__ = []


def _ignore(cell, exclude, enable: bool) -> None:
    """Switch contacts between the robot and the parts in ``exclude`` off (the target enters the
    tool) or back on."""
    m = cell.m
    for geom, owner in cell._geom_owner.items():
        if owner in exclude:
            m.geom_contype[geom], m.geom_conaffinity[geom] = PART_GROUP if enable else _OFF


def _contacts_into(cell, found: dict) -> None:
    """Add the robot's contacts now to ``found`` (part label -> deepest penetration, m)."""
    d = cell.d
    if not d.ncon:
        return
    arm, labels = cell._arm_geoms, cell._geom_label
    geoms, dists = d.contact.geom, d.contact.dist
    for k in np.flatnonzero(dists < -CONTACT_SLACK).tolist():
        g1, g2 = int(geoms[k, 0]), int(geoms[k, 1])
        other = g2 if g1 in arm else g1 if g2 in arm else None
        label = labels.get(other)
        if label is not None:
            found[label] = max(found.get(label, 0.0), -float(dists[k]))


def _step(cell, q, qd) -> None:
    """One physics step of the arm's position control to joints ``q`` (rad) at velocities ``qd``
    (rad/s): Bullet's position motor law with gains ``GAIN`` — the joint velocity after the step
    brought to ``qd + GAIN (q - q_now) / dt`` — solved for the torque by the arm's mass matrix
    and bias forces (gravity, Coriolis) and the joints' passive forces, clamped to the joints'
    efforts; then MuJoCo's step (contacts, a held part's weld and joint limits on top). The
    1 kHz loop's cost: every array is a view made once per model (``cell._views``)."""
    mujoco, m, d = cell.mj, cell.m, cell.d
    position, velocity, bias, passive, applied, dv, force, effort, wanted = cell._views
    h = m.opt.timestep
    mujoco.mj_step1(m, d)
    np.subtract(q, position, out=wanted)
    wanted *= GAIN / h
    wanted += qd
    wanted -= velocity
    np.divide(wanted, h, out=dv[: len(wanted)])
    mujoco.mj_mulM(m, d, force, dv)
    n = len(wanted)
    np.add(force[:n], bias, out=applied)
    applied -= passive
    np.clip(applied, -effort, effort, out=applied)
    mujoco.mj_step2(m, d)


def _execute(
    cell, plan: MotionPlan, exclude=(), hold: Hold | None = None, frames: int = 0, on_record=None
) -> Execution:
    """Run ``plan`` under position control at 1 kHz, the parts in ``exclude`` ignored; a
    ``hold`` keeps one joint still for a while (its command runs on: open loop). ``on_record``
    is called with the time (s) after every recorded step (a part that follows the tool)."""
    n_steps = int(math.ceil((plan.duration + SETTLE) / SIM_STEP))
    positions, velocities = plan.command(np.arange(n_steps) * SIM_STEP)
    cell._set_joints(positions[0])
    record = _Recorder(cell, n_steps, frames, focus=plan.points[-1] / cell.unit)
    _ignore(cell, exclude, False)
    held = None
    visit = np.zeros(n_steps, dtype=bool)
    visit[::RECORD_EVERY] = True
    visit[-1] = True
    visit[list(record.frame_steps)] = True
    try:
        for step in range(n_steps):
            t = step * SIM_STEP
            q, qd = positions[step], velocities[step]
            if _holding(hold, t):
                held = _held_angle(cell, hold, t, held)
                q, qd = q.copy(), qd.copy()
                q[hold.joint], qd[hold.joint] = held, 0.0
            _step(cell, q, qd)
            _contacts_into(cell, record.contacts)
            if visit[step]:
                record.sample(step, t + SIM_STEP, positions[step])
                if on_record is not None:
                    on_record(t + SIM_STEP)
    finally:
        _ignore(cell, exclude, True)
    run = record.finish()
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
    """Run a DMP/Bi-DMP ``stepper`` (scene units) on the measured TCP at 100 Hz: the PyBullet
    backend's loop (:func:`bidmp.sim.pybullet.execute._execute_closed_loop`, where the commands'
    making is explained) with MuJoCo's physics."""
    duration, max_factor = span
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
    unheld = _RateLimiter(q, cell.limits, LIMIT_MARGIN) if hold is not None else None
    planned = [] if hold is not None else sent
    try:
        for step in range(n_steps):
            t = step * SIM_STEP
            if step % every == 0:
                previous, previous_rate = target, target_rate
                if settle_from is not None and step - settle_from >= SETTLE / SIM_STEP:
                    break
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
            wanted = _hermite(previous, previous_rate, target, target_rate, share, CONTROL_STEP)
            if unheld is not None:
                planned.append(unheld(*wanted))
            holding = _holding(hold, t)
            held = _held_angle(cell, hold, t, held)
            if holding:
                for value, at in zip(wanted, (held, 0.0, 0.0)):
                    value[hold.joint] = at
            command = limited(*wanted)
            sent.append(command)
            q, qd = command.copy(), limited.velocity.copy()
            if holding:
                q[hold.joint], qd[hold.joint] = held, 0.0
            _step(cell, q, qd)
            _contacts_into(cell, record.contacts)
            record.sample(step, t + SIM_STEP, command)
    finally:
        _ignore(cell, exclude, True)
        if moved:
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


def _perceive(cell, stepper, goal_update, labels) -> bool:
    """:func:`bidmp.sim.pybullet.execute._perceive` in the MuJoCo world."""
    if goal_update is None or stepper.time < goal_update.time:
        return False
    stepper.set_goal(stepper.target + np.asarray(goal_update.offset))
    return _move_parts(cell, labels, np.asarray(goal_update.offset) * cell.unit)


def _move_parts(cell, labels, offset_m: np.ndarray) -> bool:
    """Move every body of the parts ``labels`` in place by ``offset_m`` (3,) metres."""
    m, d = cell.m, cell.d
    for name, (_, owner) in cell._part_bodies.items():
        body = m.body(name)
        if owner in labels and body.mocapid[0] >= 0:
            d.mocap_pos[body.mocapid[0]] += offset_m
    cell.mj.mj_forward(m, d)
    return True


def _held_angle(cell, hold: Hold | None, t: float, held: float | None) -> float | None:
    """The angle (rad) the hold keeps its joint at: where the joint was when the hold began."""
    if held is None and _holding(hold, t):
        held = float(cell.d.qpos[hold.joint])
    return held


class _Recorder:
    """Measured samples of one execution (every ``RECORD_EVERY``-th step and the last) and
    optional frames: :class:`bidmp.sim.pybullet.execute._Recorder`'s, from MuJoCo's state."""

    def __init__(self, cell, n_steps: int, frames: int, focus=None):
        self.cell = cell
        self.focus = focus
        self.n_steps = n_steps
        n_records, n_joints = (n_steps - 1) // RECORD_EVERY + 1, len(cell.arm)
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

    def sample(self, step: int, t: float, commanded_joints) -> None:
        """Record step ``step`` if it is a recorded one, render it if it is a frame's."""
        cell = self.cell
        recorded = not (step % RECORD_EVERY and step != self.n_steps - 1)
        if not recorded and step not in self.frame_steps:
            return
        # the state after the step: MuJoCo's positions are those its step started from
        cell.mj.mj_kinematics(cell.m, cell.d)
        if step in self.frame_steps:
            self.frames.append(
                cell.render() if self.focus is None else cell.keyframe(t, self.focus)
            )
        if not recorded:
            return
        row = min(step // RECORD_EVERY + (step % RECORD_EVERY > 0), len(self.times) - 1)
        self.filled = row + 1
        d, n = cell.d, len(cell.arm)
        w, x, y, z = d.xquat[cell._tcp_body]
        values = self.rows[row]
        values[0] = t
        values[1:4] = d.xpos[cell._tcp_body]
        values[4:8] = (x, y, z, w)
        values[8 : 8 + n] = d.qpos[:n]
        values[8 + n :] = d.qvel[:n]
        if row % 10 == 0 or step == self.n_steps - 1:
            self.commanded.append((row, np.asarray(commanded_joints, dtype=float).copy()))

    def finish(self) -> Execution:
        """The execution (cut to the rows recorded when the run ended early)."""
        from ..pybullet.execute import _Recorder as BulletRecorder

        return BulletRecorder.finish(self)
